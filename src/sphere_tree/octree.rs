//! The octree builder (Hubbard 1993): recursive subdivision of the mesh's bounding cube; each
//! occupied cell gets the smallest sphere bounding the parts of the triangles inside it.
//!
//! Guarantee: the cells of a level partition the cube and every cell's sphere bounds the clipped
//! triangle parts in it (grown by [`MARGIN_MM`]), and a parent's parts contain its children's, so
//! the coverage invariant holds by construction ([`super::check_coverage`] verifies it).

use glam::Vec3;

use super::tree::SphereTree;
use crate::geometry::{Sphere, TriMesh};

/// Radius added to every sphere so that pieces straddling a cell boundary fit in one sphere.
pub const MARGIN_MM: f32 = 1e-3;

/// Clips a convex polygon to the half-space where `sign * (p[axis] - value) <= 0`.
fn clip(poly: &[Vec3], axis: usize, value: f32, sign: f32) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (sign * (a[axis] - value), sign * (b[axis] - value));
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let t = da / (da - db);
            let mut p = a + (b - a) * t;
            p[axis] = value;
            out.push(p);
        }
    }
    out
}

/// The part of a polygon inside the box [min, max].
fn clip_to_box(poly: &[Vec3], min: Vec3, max: Vec3) -> Vec<Vec3> {
    let mut p = poly.to_vec();
    for axis in 0..3 {
        if p.is_empty() {
            break;
        }
        p = clip(&p, axis, max[axis], 1.0);
        if p.is_empty() {
            break;
        }
        p = clip(&p, axis, min[axis], -1.0);
    }
    p
}

/// Builds an octree sphere tree of `levels` levels (branching 8) over `mesh`.
pub fn build_octree(mesh: &TriMesh, levels: u32) -> SphereTree {
    let mut tree = SphereTree::empty(8, levels.max(1));
    if mesh.triangles.is_empty() {
        return tree;
    }
    let bounds = mesh.aabb();
    let size = bounds.extent().max_element().max(1e-6) * (1.0 + 1e-5);
    let min = bounds.centre() - Vec3::splat(size * 0.5);
    let parts: Vec<(u32, Vec<Vec3>)> = (0..mesh.triangles.len())
        .map(|t| (t as u32, mesh.triangle(t).to_vec()))
        .collect();
    fill(&mut tree, 0, 0, min, size, &parts);
    tree
}

fn fill(
    tree: &mut SphereTree,
    node: usize,
    level: u32,
    min: Vec3,
    size: f32,
    parts: &[(u32, Vec<Vec3>)],
) {
    let points: Vec<Vec3> = parts.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    let s = Sphere::enclosing(&points);
    tree.nodes[node] = Some(Sphere::new(s.centre, s.radius + MARGIN_MM));
    if level + 1 >= tree.levels {
        let mut tris: Vec<u32> = parts.iter().map(|(t, _)| *t).collect();
        tris.dedup();
        tree.triangles[node] = tris;
        return;
    }
    let half = size * 0.5;
    let first = tree.children(node).start;
    for k in 0..8usize {
        let offset = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32) * half;
        let (cmin, cmax) = (min + offset, min + offset + Vec3::splat(half));
        let child_parts: Vec<(u32, Vec<Vec3>)> = parts
            .iter()
            .filter_map(|(t, poly)| {
                let p = clip_to_box(poly, cmin, cmax);
                (!p.is_empty()).then_some((*t, p))
            })
            .collect();
        if !child_parts.is_empty() {
            fill(tree, first + k, level + 1, cmin, half, &child_parts);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere_tree::{check_coverage, coverage::DEFAULT_SPLIT_DEPTH};

    #[test]
    fn clipping_a_triangle_to_a_box() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let p = clip_to_box(&tri, Vec3::splat(-1.0), Vec3::splat(1.0));
        // The unit square's corner region of the triangle: a quadrilateral.
        assert_eq!(p.len(), 4, "{p:?}");
        assert!(p.iter().all(|v| v.max_element() <= 1.0 + 1e-6));
        assert!(clip_to_box(&tri, Vec3::splat(5.0), Vec3::splat(6.0)).is_empty());
    }

    #[test]
    fn octree_of_a_box_covers_it() {
        let mesh = crate::geometry::trimesh::tests::cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        for levels in 1..=4 {
            let tree = build_octree(&mesh, levels);
            let c = check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH);
            assert!(c.covered, "levels {levels}: {c:?}");
            assert!(tree.leaves().all(|n| !tree.triangles[n].is_empty()));
        }
    }
}
