//! Phase 2 of the medial builder: the maximal inscribed ball tangent at a seed, whose centre lies
//! on the medial axis.

use glam::Vec3;

use crate::geometry::{Aabb, MeshRef, Sphere, closest_point_triangle, ray::ray_first_hit};

/// How far the medial balls may cross the surface, in mm: the candidates grow each ball by at
/// least 2.5 % of the leaf spacing.
pub(super) const BALL_SLACK: f32 = 2e-3;

/// The maximal inscribed ball tangent at `p` (outward normal `n`), by the shrinking-ball method
/// in one pass over the triangle tree. It starts from `start`, or from half the distance to the
/// surface straight inwards if that is less (the ball's diameter along −n runs inside the mesh,
/// so that is an upper bound and the first ball is nearly tight). Balls tangent at `p` are
/// nested as they shrink, so a box or triangle clear of the ball stays clear of every later one:
/// each node is tested against the ball as it is when the node is reached, and each triangle
/// that reaches into the ball shrinks it (to the ball through `p` and the triangle's point
/// nearest the centre) until it no longer does, or 16 times (each shrink closes most of the
/// excess, so the cap is not reached in practice). The result then has no surface nearer its
/// centre than the radius less `BALL_SLACK` (tested against a brute-force scan). The candidates do
/// not rely on it: coverage is established by the cover and made exact in step 6.
pub(super) fn medial_ball(mesh: MeshRef, p: Vec3, n: Vec3, start: f32) -> Sphere {
    let t_min = 1e-4 * start;
    let mut r = ray_first_hit(mesh, p, -n, t_min).map_or(start, |t| (0.5 * t).min(start));
    let bvh = mesh.bvh;
    let mut c = p - n * r;
    // Squared radius below which surface counts as inside the ball.
    let mut inner2 = (r - BALL_SLACK).max(0.0).powi(2);
    let (mut stack, mut top) = ([0u32; 64], usize::from(!bvh.nodes.is_empty()));
    while top > 0 {
        top -= 1;
        let node = bvh.nodes[stack[top] as usize];
        if node.aabb.distance_squared_to_point(c) >= inner2 {
            continue;
        }
        if node.is_leaf() {
            for &t in bvh.leaf_triangles(&node) {
                let [a, b, d] = mesh.mesh.triangle(t as usize);
                let bounds = Aabb::from_points([a, b, d]);
                for _ in 0..16 {
                    if bounds.distance_squared_to_point(c) >= inner2 {
                        break;
                    }
                    let q = closest_point_triangle(c, a, b, d);
                    let pq = p - q;
                    let along = pq.dot(n);
                    if q.distance_squared(c) >= inner2
                        || along <= 1e-9
                        || pq.length_squared() < 1e-10
                    {
                        break;
                    }
                    let next = pq.length_squared() / (2.0 * along);
                    if next >= r {
                        break;
                    }
                    r = next;
                    c = p - n * r;
                    inner2 = (r - BALL_SLACK).max(0.0).powi(2);
                }
            }
        } else {
            let l = node.start as usize;
            let d0 = bvh.nodes[l].aabb.distance_squared_to_point(c);
            let d1 = bvh.nodes[l + 1].aabb.distance_squared_to_point(c);
            let (near, far) = if d0 < d1 { (l, l + 1) } else { (l + 1, l) };
            stack[top] = far as u32;
            stack[top + 1] = near as u32;
            top += 2;
        }
    }
    Sphere::new(c, r)
}
