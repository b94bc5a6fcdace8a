//! Phase 7 of the medial builder: the leaves grouped into a balanced hierarchy whose inner spheres
//! hold their leaves' pieces.

use glam::Vec3;

use super::padded;
use crate::{
    geometry::{Aabb, MeshRef, Sphere},
    sphere_tree::tree::{SphereTree, triangles_touching_bvh},
};

/// Places `group` (leaf indices) at slot `node` of `level`: a single leaf sits in the slot itself;
/// a larger group gets the smallest sphere around its leaves' pieces and is split among the
/// children. Groups never exceed what the levels below can hold (balanced splits of at most
/// B^(levels−1) leaves).
pub(super) fn place(
    tree: &mut SphereTree,
    node: usize,
    level: u32,
    mut group: Vec<usize>,
    leaves: &[Sphere],
    corners: &[Vec<Vec3>],
    m: MeshRef,
) {
    if group.len() == 1 || level + 1 >= tree.levels {
        let i = group[0];
        tree.nodes[node] = Some(leaves[i]);
        tree.triangles[node] = triangles_touching_bvh(m.mesh, m.bvh, &leaves[i]);
        return;
    }
    let points: Vec<Vec3> = group
        .iter()
        .flat_map(|&i| corners[i].iter().copied())
        .collect();
    let s = Sphere::enclosing(&points);
    tree.nodes[node] = Some(Sphere::new(s.centre, padded(s.radius)));
    let parts = split_balanced(&mut group, leaves, tree.branching as usize);
    let first = tree.children(node).start;
    for (k, part) in parts.into_iter().enumerate() {
        if !part.is_empty() {
            place(tree, first + k, level + 1, part, leaves, corners, m);
        }
    }
}

/// Splits a group into `b` parts of nearly equal size along the longest axis of the leaf centres,
/// recursively (so that each part holds at most ⌈n/b⌉ leaves).
pub(super) fn split_balanced(group: &mut [usize], leaves: &[Sphere], b: usize) -> Vec<Vec<usize>> {
    if b <= 1 || group.len() <= 1 {
        let mut v = vec![group.to_vec()];
        v.resize(b.max(1), Vec::new());
        return v;
    }
    let bounds = Aabb::from_points(group.iter().map(|&i| leaves[i].centre));
    let e = bounds.extent();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    group.sort_by(|&x, &y| leaves[x].centre[axis].total_cmp(&leaves[y].centre[axis]));
    let left_parts = b / 2;
    let cut = group.len() * left_parts / b;
    let (l, r) = group.split_at_mut(cut);
    let mut out = split_balanced(l, leaves, left_parts);
    out.extend(split_balanced(r, leaves, b - left_parts));
    out
}
