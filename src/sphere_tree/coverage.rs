//! The coverage invariant of a sphere tree, checked exactly (see the module doc of
//! [`crate::sphere_tree`]).

use glam::Vec3;

use super::tree::SphereTree;
use crate::geometry::TriMesh;

/// Default limit on recursive triangle splits: pieces down to 1/65536 of a triangle's size.
pub const DEFAULT_SPLIT_DEPTH: u32 = 16;

/// Where the invariant fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoverageFailure {
    /// A piece of this triangle around `point` lies in no leaf sphere (invariant 1).
    Uncovered {
        /// Triangle index.
        triangle: usize,
        /// A point of the uncovered piece.
        point: Vec3,
    },
    /// A leaf covers a piece of this triangle but one of its ancestors does not (invariant 2).
    AncestorMisses {
        /// Triangle index.
        triangle: usize,
        /// The covering leaf.
        leaf: usize,
        /// A point of the piece.
        point: Vec3,
    },
}

/// Result of [`check_coverage`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coverage {
    /// True when both invariants hold for the whole surface.
    pub covered: bool,
    /// Triangle pieces checked.
    pub pieces: usize,
    /// Deepest split that was needed.
    pub deepest_split: u32,
    /// The first failure found, if any.
    pub failure: Option<CoverageFailure>,
}

/// A leaf containing the three points whose ancestors all contain them too.
fn covering_leaf(tree: &SphereTree, piece: &[Vec3; 3]) -> Option<usize> {
    let holds = |n: usize| tree.nodes[n].is_some_and(|s| piece.iter().all(|&p| s.contains(p)));
    let mut stack = vec![0usize];
    while let Some(n) = stack.pop() {
        if !holds(n) {
            continue;
        }
        if tree.is_leaf(n) {
            return Some(n);
        }
        stack.extend(tree.children(n).filter(|&c| tree.nodes[c].is_some()));
    }
    None
}

/// Checks both invariants on every triangle of `mesh` (the mesh the tree was built for), splitting
/// pieces at most `max_depth` times.
pub fn check_coverage(tree: &SphereTree, mesh: &TriMesh, max_depth: u32) -> Coverage {
    let mut report = Coverage {
        covered: true,
        pieces: 0,
        deepest_split: 0,
        failure: None,
    };
    if tree.root().is_none() {
        report.covered = mesh.triangles.is_empty();
        return report;
    }
    for triangle in 0..mesh.triangles.len() {
        let mut stack = vec![(mesh.triangle(triangle), 0u32)];
        while let Some((piece, depth)) = stack.pop() {
            report.pieces += 1;
            report.deepest_split = report.deepest_split.max(depth);
            if covering_leaf(tree, &piece).is_some() {
                continue;
            }
            if depth >= max_depth {
                let point = (piece[0] + piece[1] + piece[2]) / 3.0;
                // Tell a missing leaf from an ancestor that fails to contain a covered piece.
                let leaf = tree
                    .leaves()
                    .find(|&n| tree.nodes[n].is_some_and(|s| piece.iter().all(|&p| s.contains(p))));
                report.covered = false;
                report.failure = Some(match leaf {
                    Some(leaf) => CoverageFailure::AncestorMisses {
                        triangle,
                        leaf,
                        point,
                    },
                    None => CoverageFailure::Uncovered { triangle, point },
                });
                return report;
            }
            for sub in split4(piece) {
                stack.push((sub, depth + 1));
            }
        }
    }
    report
}

/// The four halves-of-edges pieces of a triangle piece. Builders that split triangles use this too,
/// so that their pieces are bit-for-bit the ones the check visits.
pub fn split4(piece: [Vec3; 3]) -> [[Vec3; 3]; 4] {
    let [a, b, c] = piece;
    let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::{
        geometry::{Sphere, trimesh::tests::cuboid},
        sphere_tree::octree::build_octree,
    };

    #[test]
    fn a_shrunken_leaf_leaves_surface_uncovered() {
        let mesh = cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        let mut tree = build_octree(&mesh, 3);
        assert!(check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH).covered);
        let leaf = tree.leaves().next().unwrap();
        let s = tree.nodes[leaf].unwrap();
        tree.nodes[leaf] = Some(Sphere::new(s.centre, s.radius * 0.7));
        let c = check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH);
        assert!(!c.covered);
        assert!(
            matches!(c.failure, Some(CoverageFailure::Uncovered { .. })),
            "{c:?}"
        );
    }

    #[test]
    fn an_ancestor_that_misses_its_leaves_fails() {
        let mesh = cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        let mut tree = build_octree(&mesh, 3);
        let leaf = tree.leaves().next().unwrap();
        let parent = tree.parent(leaf).unwrap();
        let s = tree.nodes[parent].unwrap();
        tree.nodes[parent] = Some(Sphere::new(s.centre, s.radius * 0.3));
        let c = check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH);
        assert!(!c.covered);
        assert!(
            matches!(c.failure, Some(CoverageFailure::AncestorMisses { .. })),
            "{c:?}"
        );
    }

    #[test]
    fn an_empty_tree_covers_nothing() {
        let mesh = cuboid(Vec3::ZERO, Vec3::ONE);
        let tree = SphereTree::empty(8, 2);
        assert!(!check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH).covered);
    }
}
