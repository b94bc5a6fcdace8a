//! `SphereTree`: the flat B-ary sphere hierarchy in Bradshaw's index layout.

use crate::geometry::{Aabb, Sphere, TriMesh, closest_point_triangle};

/// A sphere hierarchy over one mesh (local frame). Node n's children are n·B+1 … n·B+B.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereTree {
    /// Branching factor B (≥ 2).
    pub branching: u32,
    /// Number of levels including the root ("depth").
    pub levels: u32,
    /// Every slot of the full tree; `None` marks an unused slot.
    pub nodes: Vec<Option<Sphere>>,
    /// For each node, the triangles it touches (filled for leaves; empty for inner nodes).
    pub triangles: Vec<Vec<u32>>,
}

impl SphereTree {
    /// An empty tree (every slot unused) of the given shape.
    pub fn empty(branching: u32, levels: u32) -> Self {
        let n = Self::slot_count(branching, levels);
        Self {
            branching,
            levels,
            nodes: vec![None; n],
            triangles: vec![Vec::new(); n],
        }
    }

    /// Slots in a full tree: 1 + B + … + B^(levels−1).
    pub fn slot_count(branching: u32, levels: u32) -> usize {
        (0..levels).map(|l| (branching as usize).pow(l)).sum()
    }

    /// Index of the first slot of `level`.
    pub fn level_start(&self, level: u32) -> usize {
        Self::slot_count(self.branching, level)
    }

    /// Level of slot `n`.
    pub fn level_of(&self, n: usize) -> u32 {
        (0..self.levels)
            .rev()
            .find(|&l| self.level_start(l) <= n)
            .unwrap_or(0)
    }

    /// Child slots of `n` (empty range on the last level).
    pub fn children(&self, n: usize) -> std::ops::Range<usize> {
        let b = self.branching as usize;
        let first = n * b + 1;
        if first >= self.nodes.len() {
            return 0..0;
        }
        first..(first + b).min(self.nodes.len())
    }

    /// Parent slot of `n` (None for the root).
    pub fn parent(&self, n: usize) -> Option<usize> {
        (n > 0).then(|| (n - 1) / self.branching as usize)
    }

    /// True when slot `n` holds a sphere and no child of it does.
    pub fn is_leaf(&self, n: usize) -> bool {
        self.nodes[n].is_some() && self.children(n).all(|c| self.nodes[c].is_none())
    }

    /// Indices of the leaves.
    pub fn leaves(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.nodes.len()).filter(|&n| self.is_leaf(n))
    }

    /// The root sphere.
    pub fn root(&self) -> Option<Sphere> {
        self.nodes.first().copied().flatten()
    }

    /// Spheres of one level.
    pub fn level(&self, level: u32) -> impl Iterator<Item = Sphere> + '_ {
        let start = self.level_start(level);
        let end = self.level_start(level + 1).min(self.nodes.len());
        self.nodes[start..end].iter().flatten().copied()
    }
}

/// The triangles of `mesh` that touch sphere `s` (exact: the triangle's closest point to the centre
/// lies in the sphere). Triangles whose bounding box is clearly out of reach are passed over
/// without the exact test (the box test has a relative slack of 10⁻⁴ against rounding).
pub fn triangles_touching(mesh: &TriMesh, s: &Sphere) -> Vec<u32> {
    let reach2 = s.radius * s.radius * (1.0 + 1e-4) + 1e-12;
    (0..mesh.triangles.len() as u32)
        .filter(|&t| {
            let [a, b, c] = mesh.triangle(t as usize);
            Aabb::from_points([a, b, c]).distance_squared_to_point(s.centre) <= reach2
                && s.contains(closest_point_triangle(s.centre, a, b, c))
        })
        .collect()
}

/// [`triangles_touching`] through the mesh's triangle hierarchy (the same triangles, in the same
/// ascending order), for trees of large meshes.
pub fn triangles_touching_bvh(
    mesh: &TriMesh,
    bvh: &crate::geometry::TriangleBvh,
    s: &Sphere,
) -> Vec<u32> {
    let reach2 = s.radius * s.radius * (1.0 + 1e-4) + 1e-12;
    let mut out = Vec::new();
    let mut stack = Vec::with_capacity(64);
    if !bvh.nodes.is_empty() {
        stack.push(0usize);
    }
    while let Some(n) = stack.pop() {
        let node = &bvh.nodes[n];
        if node.aabb.distance_squared_to_point(s.centre) > reach2 {
            continue;
        }
        if node.is_leaf() {
            for &t in bvh.leaf_triangles(node) {
                let [a, b, c] = mesh.triangle(t as usize);
                if Aabb::from_points([a, b, c]).distance_squared_to_point(s.centre) <= reach2
                    && s.contains(closest_point_triangle(s.centre, a, b, c))
                {
                    out.push(t);
                }
            }
        } else {
            stack.push(node.start as usize);
            stack.push(node.start as usize + 1);
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bradshaw_index_layout() {
        let t = SphereTree::empty(8, 4);
        assert_eq!(t.nodes.len(), 1 + 8 + 64 + 512);
        assert_eq!(t.children(0), 1..9);
        assert_eq!(t.children(1), 9..17);
        assert_eq!(t.children(8), 65..73);
        assert_eq!(t.parent(72), Some(8));
        assert_eq!(t.level_of(0), 0);
        assert_eq!(t.level_of(8), 1);
        assert_eq!(t.level_of(9), 2);
        assert_eq!(t.level_of(584), 3);
        assert_eq!(t.children(584), 0..0);
        let b3 = SphereTree::empty(3, 3);
        assert_eq!(b3.children(1), 4..7);
        assert_eq!(b3.level_start(2), 4);
    }
}
