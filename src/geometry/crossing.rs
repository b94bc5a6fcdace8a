//! The triangles where two posed meshes meet: every triangle of each that comes within a small
//! distance of a triangle of the other. They are what [`super::mesh_penetration_near`] needs to
//! walk the part of each surface inside the other, so that the depth of an overlap is found
//! without sampling the whole meshes.

use super::aabb::Aabb;
use super::closest::closest_points_triangle_triangle;
use super::mesh_distance::{InFirst, MeshRef};
use crate::geometry::Pose;

/// The triangles of `a` (posed by `pose_a`) and of `b` (by `pose_b`) within `within` mm (≥ 0) of
/// a triangle of the other mesh, each listed once, in increasing order.
///
/// Guarantee: every triangle that touches or crosses the other surface is listed, with a margin
/// of `within` for rounding (the hierarchies' boxes are compared with that margin, the triangle
/// pairs by their exact closest points); some triangles up to `within` away may be listed too.
pub fn crossing_triangles(
    a: MeshRef,
    pose_a: &Pose,
    b: MeshRef,
    pose_b: &Pose,
    within: f32,
) -> (Vec<u32>, Vec<u32>) {
    let (mut near_a, mut near_b) = (Vec::new(), Vec::new());
    if a.bvh.nodes.is_empty() || b.bvh.nodes.is_empty() {
        return (near_a, near_b);
    }
    // Work in a's frame.
    let in_a = InFirst::new(pose_a, b, pose_b);
    let within = within.max(0.0);
    let reach = within * within;
    let mut stack: Vec<(u32, u32, Aabb)> = vec![(0, 0, in_a.node_box(0))];
    while let Some((na, nb, box_b)) = stack.pop() {
        let (node_a, node_b) = (a.bvh.nodes[na as usize], b.bvh.nodes[nb as usize]);
        if node_a.aabb.distance_squared(&box_b) > reach {
            continue;
        }
        if node_a.is_leaf() && node_b.is_leaf() {
            for &i in a.bvh.leaf_triangles(&node_a) {
                let ta = a.mesh.triangle(i as usize);
                let box_a = Aabb::from_points(ta);
                for &j in b.bvh.leaf_triangles(&node_b) {
                    let tb = in_a.triangle(j);
                    if box_a.distance_squared(&Aabb::from_points(tb)) > reach {
                        continue;
                    }
                    if closest_points_triangle_triangle(&ta, &tb).distance <= within {
                        near_a.push(i);
                        near_b.push(j);
                    }
                }
            }
            continue;
        }
        let split_a = !node_a.is_leaf()
            && (node_b.is_leaf() || node_a.aabb.extent().length() >= box_b.extent().length());
        if split_a {
            let l = node_a.start;
            stack.extend([l, l + 1].map(|c| (c, nb, box_b)));
        } else {
            let l = node_b.start;
            stack.extend([l, l + 1].map(|c| (na, c, in_a.node_box(c))));
        }
    }
    for list in [&mut near_a, &mut near_b] {
        list.sort_unstable();
        list.dedup();
    }
    (near_a, near_b)
}
