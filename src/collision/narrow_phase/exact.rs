//! Exact contact: the continuous stage, then conservative advancement (Mirtich 1996) on the
//! candidate triangles, the triangles under the leaf pairs whose swept spheres meet.
//!
//! Why the candidates suffice: a contact point of the two surfaces lies in some leaf of each tree
//! (coverage invariant) and its triangle touches that leaf, and those two leaves' swept spheres meet
//! at the contact time; so every pair of triangles that can touch during the step is a candidate
//! pair, and no other pair touches at all.
//!
//! Advancement: from the earliest leaf time (no contact can happen before it), the exact minimum
//! distance d over the candidate pairs is computed at the current poses; no point of the candidates
//! moves faster than μ = Σ (origin travel + rotation angle × farthest candidate vertex from the
//! origin) per unit time ([`Motion::speed_bound`]), so the gap cannot close before t + d/μ. Each
//! step advances by (d − tolerance/2)/μ, leaving at least half the tolerance, and stops when
//! d ≤ [`GAP_TOLERANCE_MM`]: the reported time is never after the first contact and the gap left
//! there is within the tolerance. Teeth already interpenetrating at t = 0 report time 0 and the
//! penetration depth of the whole meshes. After [`MAX_STEPS`] steps (slow convergence under large
//! rotations) the current, still conservative, time is reported with its gap.
//!
//! [`Motion::speed_bound`]: crate::collision::motion::Motion::speed_bound

use glam::Vec3;

use super::{Body, PairContact, continuous};
use crate::geometry::{MeshRef, closest_points_triangle_triangle, mesh_separation};

/// Largest gap left between teeth reported as touching (mm).
pub const GAP_TOLERANCE_MM: f32 = 0.01;
/// Most advancement steps per query.
pub const MAX_STEPS: u32 = 1000;

/// Triangles of one side in world coordinates, with bounding spheres for culling.
struct Placed {
    tris: Vec<[Vec3; 3]>,
    bound: Vec<(Vec3, f32)>,
}

fn place(
    mesh: &crate::geometry::TriMesh,
    ids: &[u32],
    pose: &crate::geometry::Pose,
    out: &mut Placed,
) {
    out.tris.clear();
    out.bound.clear();
    for &t in ids {
        let tri = mesh.triangle(t as usize).map(|v| pose.transform_point(v));
        let c = (tri[0] + tri[1] + tri[2]) / 3.0;
        let r = tri.iter().map(|v| v.distance(c)).fold(0.0f32, f32::max);
        out.tris.push(tri);
        out.bound.push((c, r));
    }
}

/// The exact query.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    let swept = continuous::query(a, b)?;
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    // Candidate triangles of each side and candidate pairs (as indices into them).
    let mut ids_a: Vec<u32> = Vec::new();
    let mut ids_b: Vec<u32> = Vec::new();
    for &(i, j, _) in &swept.leaf_times {
        ids_a.extend_from_slice(&ta.triangles[i as usize]);
        ids_b.extend_from_slice(&tb.triangles[j as usize]);
    }
    ids_a.sort_unstable();
    ids_a.dedup();
    ids_b.sort_unstable();
    ids_b.dedup();
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for &(i, j, _) in &swept.leaf_times {
        for &x in &ta.triangles[i as usize] {
            let xi = ids_a.binary_search(&x).expect("collected above") as u32;
            for &y in &tb.triangles[j as usize] {
                pairs.push((xi, ids_b.binary_search(&y).expect("collected above") as u32));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let (ma, mb) = (&a.shape.geometry.mesh, &b.shape.geometry.mesh);
    let rho = |mesh: &crate::geometry::TriMesh, ids: &[u32]| {
        ids.iter()
            .flat_map(|&t| mesh.triangle(t as usize))
            .map(|v| v.length() as f64)
            .fold(0.0, f64::max)
    };
    let mu = (a.motion.speed_bound(rho(ma, &ids_a)) + b.motion.speed_bound(rho(mb, &ids_b)))
        * (1.0 + 1e-6);
    let tol = GAP_TOLERANCE_MM as f64;
    let mut t = swept
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    let (mut pa, mut pb) = (
        Placed {
            tris: Vec::new(),
            bound: Vec::new(),
        },
        Placed {
            tris: Vec::new(),
            bound: Vec::new(),
        },
    );
    for _ in 0..MAX_STEPS {
        let (pose_a, pose_b) = (a.motion.at(t as f32), b.motion.at(t as f32));
        place(ma, &ids_a, &pose_a, &mut pa);
        place(mb, &ids_b, &pose_b, &mut pb);
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO);
        for &(x, y) in &pairs {
            let (cx, rx) = pa.bound[x as usize];
            let (cy, ry) = pb.bound[y as usize];
            if cx.distance(cy) - rx - ry >= best.0 {
                continue;
            }
            let p = closest_points_triangle_triangle(&pa.tris[x as usize], &pb.tris[y as usize]);
            if p.distance < best.0 {
                best = (p.distance, p.on_first, p.on_second);
            }
        }
        let (d, qa, qb) = best;
        if !d.is_finite() {
            return None;
        }
        let d = d as f64;
        if d <= tol {
            let mut contact = PairContact {
                time_of_contact: t as f32,
                points: [qa, qb],
                normal: (qb - qa).try_normalize().unwrap_or(swept.contact.normal),
                depth_mm: -(d as f32),
                leaf_pairs: swept.contact.leaf_pairs.clone(),
            };
            if d == 0.0 {
                // Touching or interpenetrating (only possible at the start): measure the depth.
                let sep = mesh_separation(
                    MeshRef {
                        mesh: ma,
                        bvh: &a.shape.geometry.bvh,
                    },
                    &pose_a,
                    MeshRef {
                        mesh: mb,
                        bvh: &b.shape.geometry.bvh,
                    },
                    &pose_b,
                );
                contact.depth_mm = sep.penetration;
                contact.points = [sep.point_a, sep.point_b];
                if let Some(n) = (sep.point_b - sep.point_a).try_normalize() {
                    contact.normal = if sep.penetration > 0.0 { -n } else { n };
                }
            }
            return Some(contact);
        }
        if mu <= 0.0 {
            return None;
        }
        t += (d - 0.5 * tol) / mu;
        if t >= 1.0 {
            return None;
        }
    }
    let (pose_a, pose_b) = (a.motion.at(t as f32), b.motion.at(t as f32));
    place(ma, &ids_a, &pose_a, &mut pa);
    place(mb, &ids_b, &pose_b, &mut pb);
    let best = pairs
        .iter()
        .map(|&(x, y)| closest_points_triangle_triangle(&pa.tris[x as usize], &pb.tris[y as usize]))
        .min_by(|p, q| p.distance.total_cmp(&q.distance))?;
    Some(PairContact {
        time_of_contact: t as f32,
        points: [best.on_first, best.on_second],
        normal: (best.on_second - best.on_first)
            .try_normalize()
            .unwrap_or(swept.contact.normal),
        depth_mm: -best.distance,
        leaf_pairs: swept.contact.leaf_pairs,
    })
}
