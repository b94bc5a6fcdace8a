//! Rays against a closed mesh, through its bounding-volume hierarchy: the first point where one
//! meets the surface, and the parity of its crossings (the inside test of `mesh_distance`).

use glam::Vec3;

use super::{Aabb, MeshRef};

/// The nearest point where the ray `origin + t·dir` (mesh frame, t > `t_min`) meets the
/// mesh surface: its t, or None if the ray leaves the mesh's box without meeting a triangle.
/// Exact up to rounding; a hit within 10⁻⁶ (barycentric) of a triangle's edge counts.
pub fn ray_first_hit(m: MeshRef, origin: Vec3, dir: Vec3, t_min: f32) -> Option<f32> {
    let inv = dir.recip();
    let mut best = f32::INFINITY;
    let (mut stack, mut top) = ([0u32; 64], 1);
    while top > 0 {
        top -= 1;
        let node = m.bvh.nodes[stack[top] as usize];
        if ray_box_entry(origin, inv, &node.aabb).is_none_or(|t| t > best) {
            continue;
        }
        if node.is_leaf() {
            for &t in m.bvh.leaf_triangles(&node) {
                if let Some(t) = ray_triangle_t(origin, dir, &m.mesh.triangle(t as usize))
                    && t > t_min
                    && t < best
                {
                    best = t;
                }
            }
        } else {
            let l = node.start as usize;
            let t0 = ray_box_entry(origin, inv, &m.bvh.nodes[l].aabb).unwrap_or(f32::INFINITY);
            let t1 = ray_box_entry(origin, inv, &m.bvh.nodes[l + 1].aabb).unwrap_or(f32::INFINITY);
            let (near, far) = if t0 <= t1 { (l, l + 1) } else { (l + 1, l) };
            stack[top] = far as u32;
            stack[top + 1] = near as u32;
            top += 2;
        }
    }
    best.is_finite().then_some(best)
}

/// Parity of ray crossings, or None when the ray passes too close to an edge to be trusted.
pub(super) fn ray_parity(m: MeshRef, origin: Vec3, dir: Vec3) -> Option<bool> {
    let inv = dir.recip();
    let mut crossings = 0u32;
    // Depth-first, at most one pending sibling per level: the tree is balanced (median splits),
    // so a fixed stack of 64 serves any mesh that fits in memory.
    let (mut stack, mut top) = ([0u32; 64], 1);
    while top > 0 {
        top -= 1;
        let node = m.bvh.nodes[stack[top] as usize];
        if ray_box_entry(origin, inv, &node.aabb).is_none() {
            continue;
        }
        if node.is_leaf() {
            for &t in m.bvh.leaf_triangles(&node) {
                match crossing(origin, dir, &m.mesh.triangle(t as usize)) {
                    Some((u, v, dist)) if dist >= 0.0 && inside_by(u, v, -EDGE_EPS) => {
                        if !inside_by(u, v, EDGE_EPS) {
                            return None;
                        }
                        crossings += 1;
                    }
                    _ => {}
                }
            }
        } else {
            stack[top] = node.start;
            stack[top + 1] = node.start + 1;
            top += 2;
        }
    }
    Some(crossings % 2 == 1)
}

/// Triangles that segments are tested against ([`SegmentTargets::parity`]), ordered so that each
/// run of [`Self::RUN`] lies close together (a median split of their centres along the widest
/// extent, repeated), each run under one box: a short segment meets few runs' boxes.
pub(super) struct SegmentTargets {
    triangles: Vec<([Vec3; 3], Aabb)>,
    runs: Vec<Aabb>,
}

impl SegmentTargets {
    const RUN: usize = 8;

    pub(super) fn new(mut triangles: Vec<([Vec3; 3], Aabb)>) -> Self {
        fn order(list: &mut [([Vec3; 3], Aabb)]) {
            if list.len() <= SegmentTargets::RUN {
                return;
            }
            let bound = (list.iter()).fold(Aabb::EMPTY, |b, t| {
                b.union(Aabb::from_points([t.1.centre()]))
            });
            let axis = (bound.max - bound.min).max_position();
            let mid = (list.len() / 2).div_ceil(SegmentTargets::RUN) * SegmentTargets::RUN;
            list.select_nth_unstable_by(mid, |x, y| {
                x.1.centre()[axis].total_cmp(&y.1.centre()[axis])
            });
            let (left, right) = list.split_at_mut(mid);
            order(left);
            order(right);
        }
        order(&mut triangles);
        let runs = (triangles.chunks(Self::RUN))
            .map(|run| run.iter().fold(Aabb::EMPTY, |b, t| b.union(t.1)))
            .collect();
        Self { triangles, runs }
    }

    /// Parity of the crossings of the segment from `p` to `q` with the triangles, or None when
    /// it passes within 10⁻⁶ (barycentric) of one's edge, ends within 10⁻⁴ of its length from
    /// one's plane, or runs parallel to one's plane across its box: cases the parity cannot be
    /// trusted in. The same answer as [`segment_parity`] over the triangles in any order.
    pub(super) fn parity(&self, p: Vec3, q: Vec3) -> Option<bool> {
        let span = Aabb {
            min: p.min(q),
            max: p.max(q),
        };
        let mut odd = false;
        for (k, run) in self.runs.iter().enumerate() {
            if run.distance_squared(&span) > 0.0 {
                continue;
            }
            let end = (Self::RUN * (k + 1)).min(self.triangles.len());
            odd ^= segment_parity(p, q, &self.triangles[Self::RUN * k..end])?;
        }
        Some(odd)
    }
}

/// Parity of the crossings of the segment from `p` to `q` with `triangles` (each with its box),
/// or None when it passes within 10⁻⁶ (barycentric) of one's edge, ends within 10⁻⁴ of its
/// length from one's plane, or runs parallel to one's plane across its box: cases the parity
/// cannot be trusted in.
pub(super) fn segment_parity(p: Vec3, q: Vec3, triangles: &[([Vec3; 3], Aabb)]) -> Option<bool> {
    const ENDS: f32 = 1e-4;
    let d = q - p;
    let span = Aabb {
        min: p.min(q),
        max: p.max(q),
    };
    let mut odd = false;
    for (t, b) in triangles {
        if b.distance_squared(&span) > 0.0 {
            continue;
        }
        let (u, v, s) = crossing(p, d, t)?;
        if !inside_by(u, v, -EDGE_EPS) || !(-ENDS..=1.0 + ENDS).contains(&s) {
            continue;
        }
        if !inside_by(u, v, EDGE_EPS) || !(ENDS..=1.0 - ENDS).contains(&s) {
            return None;
        }
        odd = !odd;
    }
    Some(odd)
}

/// Where the ray enters the box (0 if it starts inside), or None if it misses it.
fn ray_box_entry(o: Vec3, inv: Vec3, b: &Aabb) -> Option<f32> {
    let t1 = (b.min - o) * inv;
    let t2 = (b.max - o) * inv;
    let tmin = t1.min(t2).max_element().max(0.0);
    let tmax = t1.max(t2).min_element();
    (tmin <= tmax).then_some(tmin)
}

/// How near an edge a crossing may pass (barycentric) and still count as a clean hit.
const EDGE_EPS: f32 = 1e-6;

/// True when all three barycentric coordinates (u, v, 1 − u − v) are at least `margin`.
fn inside_by(u: f32, v: f32, margin: f32) -> bool {
    u >= margin && v >= margin && 1.0 - u - v >= margin
}

/// The ray parameter where `o + t·d` meets the triangle, edges included within 10⁻⁶
/// (barycentric), for any sign of t; None when it misses or runs parallel to the plane.
fn ray_triangle_t(o: Vec3, d: Vec3, t: &[Vec3; 3]) -> Option<f32> {
    crossing(o, d, t)
        .filter(|&(u, v, _)| inside_by(u, v, -EDGE_EPS))
        .map(|(_, _, dist)| dist)
}

/// Where the line `o + t·d` crosses the triangle's plane (Möller–Trumbore): barycentric u, v and
/// the ray parameter t; None when the line runs parallel to the plane.
fn crossing(o: Vec3, d: Vec3, t: &[Vec3; 3]) -> Option<(f32, f32, f32)> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-12 * e1.length() * e2.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = inv * s.dot(h);
    let q = s.cross(e1);
    let v = inv * d.dot(q);
    Some((u, v, inv * e2.dot(q)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{TriangleBvh, trimesh::tests::cuboid};

    /// A segment's crossings with a box's faces: one face flips the parity, two leave it, none
    /// leave it; a segment ending on a face, or running in a face's plane, is not trusted.
    #[test]
    fn segments_count_their_crossings() {
        let m = cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        let faces: Vec<_> = (0..m.triangles.len())
            .map(|i| {
                let v = m.triangle(i);
                (v, Aabb::from_points(v))
            })
            .collect();
        let parity = |p: Vec3, q: Vec3| segment_parity(p, q, &faces);
        let inside = Vec3::new(1.1, 0.7, 0.3);
        assert_eq!(parity(inside, Vec3::new(1.3, 0.6, 1.7)), Some(true));
        assert_eq!(
            parity(Vec3::new(-1.0, 0.7, 0.3), Vec3::new(5.0, 0.9, 0.4)),
            Some(false)
        );
        assert_eq!(parity(inside, Vec3::new(2.9, 1.2, 0.6)), Some(false));
        assert_eq!(parity(inside, Vec3::new(1.3, 0.6, 1.0)), None);
        assert_eq!(
            parity(Vec3::new(0.5, 0.5, 1.0), Vec3::new(3.5, 0.5, 1.0)),
            None
        );
    }

    /// The grouped targets give the plain parity of every segment, trusted or not, over a
    /// closed mesh of many small triangles (segments of all lengths, from inside and outside).
    #[test]
    fn grouped_targets_count_as_the_plain_list() {
        use crate::teeth::{Arch, ToothGeometry, ToothKind, ToothResolution};
        let g =
            ToothGeometry::procedural(Arch::Upper, ToothKind::FirstMolar, ToothResolution::PAPER);
        let faces: Vec<_> = (0..g.mesh.triangles.len())
            .map(|i| {
                let v = g.mesh.triangle(i);
                (v, Aabb::from_points(v))
            })
            .collect();
        assert!(faces.len() > 8 * SegmentTargets::RUN);
        let grouped = SegmentTargets::new(faces.clone());
        let bound = g.bvh.root_aabb();
        let mut n = crate::geometry::test_numbers(7);
        let mut point = || bound.centre() + Vec3::new(n(), n(), n()) * (bound.max - bound.min);
        let (mut odd, mut untrusted) = (0, 0);
        for k in 0..4000 {
            let p = point();
            // Short segments as the walk's, and long ones across the whole mesh.
            let q = if k % 2 == 0 {
                p + (point() - p) * 0.05
            } else {
                point()
            };
            let plain = segment_parity(p, q, &faces);
            assert_eq!(grouped.parity(p, q), plain, "segment {p} to {q}");
            odd += (plain == Some(true)) as usize;
            untrusted += plain.is_none() as usize;
        }
        assert!(odd > 100, "{odd} odd");
        eprintln!("{odd} odd, {untrusted} untrusted");
    }

    /// The first hit is the nearest face along the ray, past `t_min`; a ray from a face
    /// inwards meets the opposite face; a ray away from the box meets nothing.
    #[test]
    fn rays_meet_the_nearest_face() {
        let m = cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        let bvh = TriangleBvh::build(&m);
        let r = MeshRef {
            mesh: &m,
            bvh: &bvh,
        };
        let inside = Vec3::new(1.0, 0.5, 0.25);
        let hit = |o: Vec3, d: Vec3, t_min: f32| ray_first_hit(r, o, d, t_min);
        assert!((hit(inside, Vec3::X, 0.0).unwrap() - 3.0).abs() < 1e-5);
        assert!((hit(inside, Vec3::NEG_Y, 0.0).unwrap() - 0.5).abs() < 1e-5);
        let slant = Vec3::new(1.0, 0.0, 1.0).normalize();
        let expect = 0.75 * 2f32.sqrt();
        assert!((hit(inside, slant, 0.0).unwrap() - expect).abs() < 1e-5);
        // From a point on the bottom face, inwards: the top face, not the start.
        let on_face = Vec3::new(2.3, 1.1, 0.0);
        assert!((hit(on_face, Vec3::Z, 1e-4).unwrap() - 1.0).abs() < 1e-5);
        // Through the middle of a face, on the edge its two triangles share: still a hit.
        assert!((hit(Vec3::new(-1.0, 1.0, 0.5), Vec3::X, 0.0).unwrap() - 1.0).abs() < 1e-5);
        assert_eq!(hit(Vec3::new(5.0, 1.0, 0.5), Vec3::X, 0.0), None);
        assert_eq!(hit(inside, Vec3::Z, 10.0), None);
    }
}
