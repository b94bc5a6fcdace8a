//! Exact contact: the continuous stage, then conservative advancement (Mirtich 1996) on the
//! candidate triangles, the triangles under the leaf pairs whose swept spheres meet.
//!
//! Why the candidates suffice: a contact point of the two surfaces lies in some leaf of each tree
//! (coverage invariant) and its triangle touches that leaf, and those two leaves' swept spheres meet
//! at the contact time; so every pair of triangles that can touch during the step is a candidate
//! pair, and no other pair touches at all.
//!
//! Windows: the search starts at the earliest leaf time (no contact can happen before it). When no
//! point moves more than 1 mm in the rest of the step (short steps near contact) the rest is
//! searched at once; otherwise in windows of doubling length (1/32 of the step first), each with
//! only the leaf pairs whose swept spheres meet within it, so a long step does not drag every leaf
//! pair of its whole sweep into the triangle stage.
//!
//! Advancement: from the earliest leaf time in the window, a lower bound d on
//! the distance between the contact-capable parts (the surface inside each meeting leaf pair) is
//! computed at the current poses: the exact distance between candidate triangles, visiting leaf
//! pairs nearest first and skipping a leaf pair once its spheres are farther apart than the best
//! distance so far (its in-sphere surface cannot be closer); no point of the candidates
//! moves faster than μ = Σ (origin travel + rotation angle × farthest candidate vertex from the
//! origin) per unit time ([`Motion::speed_bound`]), so the gap cannot close before t + d/μ. Each
//! step advances by (d − tolerance/2)/μ, leaving at least half the tolerance, and stops when
//! d ≤ [`GAP_TOLERANCE_MM`]: the reported time is never after the first contact and the gap left
//! there is within the tolerance. Between steps each triangle pair keeps its last distance: it
//! cannot have shrunk by more than μ·Δt, so pairs whose carried bound exceeds the best distance of
//! the step are not measured again (the minimum is unchanged, only cheaper). Teeth already interpenetrating at t = 0 report time 0 and the
//! penetration depth of the whole meshes. After [`MAX_STEPS`] steps (slow convergence under large
//! rotations) the current, still conservative, time is reported with its gap.
//!
//! [`Motion::speed_bound`]: crate::collision::motion::Motion::speed_bound

use glam::Vec3;

use super::{Body, PairContact, continuous};
use crate::collision::motion::Motion;
use crate::geometry::{MeshRef, closest_points_triangle_triangle, mesh_separation};

/// Largest gap left between teeth reported as touching (mm).
pub const GAP_TOLERANCE_MM: f32 = 0.01;
/// Largest relative travel (mm, bound on any point's) for which the rest of the step is searched
/// in one window.
const WHOLE_STEP_TRAVEL_MM: f64 = 1.0;
/// Most advancement steps per query.
pub const MAX_STEPS: u32 = 1000;
/// Allowance (mm) for the f32 rounding of a stored triangle-pair distance and of the poses it was
/// measured at, far above either, when it is carried forward as a bound.
const LIPSCHITZ_SLACK_MM: f64 = 1e-4;

/// A meeting leaf pair (nodes of a and b) with its candidate triangle pairs.
type LeafPair = (u32, u32, Vec<(u32, u32)>);

/// Triangles of one side placed at the current time, on demand.
struct Placed<'m> {
    mesh: &'m crate::geometry::TriMesh,
    ids: Vec<u32>,
    tris: Vec<[Vec3; 3]>,
    bound: Vec<(Vec3, f32)>,
    stamp: Vec<u32>,
    now: u32,
}

impl<'m> Placed<'m> {
    fn new(mesh: &'m crate::geometry::TriMesh, ids: Vec<u32>) -> Self {
        let n = ids.len();
        Self {
            mesh,
            ids,
            tris: vec![[Vec3::ZERO; 3]; n],
            bound: vec![(Vec3::ZERO, 0.0); n],
            stamp: vec![0; n],
            now: 0,
        }
    }

    fn get(&mut self, k: usize, pose: &crate::geometry::Pose) -> (&[Vec3; 3], (Vec3, f32)) {
        if self.stamp[k] != self.now {
            let tri = self
                .mesh
                .triangle(self.ids[k] as usize)
                .map(|v| pose.transform_point(v));
            let c = (tri[0] + tri[1] + tri[2]) / 3.0;
            let r = tri.iter().map(|v| v.distance(c)).fold(0.0f32, f32::max);
            self.tris[k] = tri;
            self.bound[k] = (c, r);
            self.stamp[k] = self.now;
        }
        (&self.tris[k], self.bound[k])
    }
}

/// The exact query.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    // The earliest leaf time bounds the first contact from below; from there the step is searched
    // in windows of growing length, each with only the leaf pairs that meet within it (a slerp and
    // lerp restricted to a sub-interval is the slerp and lerp between its end poses).
    let first = continuous::query(a, b, false)?;
    let mut t = first
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    // Short steps (no point moves more than WHOLE_STEP_TRAVEL_MM in the rest of the step): the
    // rest at once; longer ones in doubling windows.
    let travel = (a.motion.speed_bound(a.shape.max_rho as f64)
        + b.motion.speed_bound(b.shape.max_rho as f64))
        * (1.0 - t);
    let mut window = if travel <= WHOLE_STEP_TRAVEL_MM {
        1.0 - t
    } else {
        1.0 / 32.0
    };
    loop {
        let end = (t + window).min(1.0);
        let sub = |x: &Body<'_>| Motion {
            start: x.motion.at(t as f32),
            end: x.motion.at(end as f32),
        };
        let (sa, sb) = (
            Body {
                motion: sub(a),
                ..*a
            },
            Body {
                motion: sub(b),
                ..*b
            },
        );
        if let Some(swept) = continuous::query(&sa, &sb, true)
            && let Some(mut c) = advance(&sa, &sb, &swept)
        {
            c.time_of_contact = (t + c.time_of_contact as f64 * (end - t)) as f32;
            return Some(c);
        }
        if end >= 1.0 {
            return None;
        }
        t = end;
        window *= 2.0;
    }
}

/// Conservative advancement over the bodies' whole motion, from the earliest meeting leaf time of
/// `swept` (which must list every meeting leaf pair).
fn advance(a: &Body, b: &Body, swept: &continuous::SweptContact) -> Option<PairContact> {
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
    // Per leaf pair, its triangle pairs (indices into ids_a / ids_b).
    let leaf_pairs: Vec<LeafPair> = swept
        .leaf_times
        .iter()
        .map(|&(i, j, _)| {
            let mut tp = Vec::new();
            for &x in &ta.triangles[i as usize] {
                let xi = ids_a.binary_search(&x).expect("collected above") as u32;
                for &y in &tb.triangles[j as usize] {
                    tp.push((xi, ids_b.binary_search(&y).expect("collected above") as u32));
                }
            }
            (i, j, tp)
        })
        .collect();
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
    let mut pa = Placed::new(ma, ids_a);
    let mut pb = Placed::new(mb, ids_b);
    let mut order: Vec<(f32, usize)> = Vec::with_capacity(leaf_pairs.len());
    let ny = pb.ids.len();
    // Per triangle pair: the step it was last looked at (leaf pairs share triangles), and its
    // last measured distance with the time of it: no pair's distance shrinks faster than μ, so
    // d − μ·(t − t_then) bounds it now and pairs that cannot beat the best are skipped.
    let mut seen = vec![(0u32, f32::INFINITY, 0.0f64); pa.ids.len() * ny];
    let mut step = 0u32;
    for round in 0..=MAX_STEPS {
        let (pose_a, pose_b) = (a.motion.at(t as f32), b.motion.at(t as f32));
        pa.now += 1;
        pb.now += 1;
        // Leaf pairs nearest first: a pair whose spheres are farther apart than the best distance
        // found cannot hold a closer contact-capable pair (see the module doc).
        order.clear();
        for (k, (i, j, _)) in leaf_pairs.iter().enumerate() {
            let (sa, sb) = (ta.spheres[*i as usize], tb.spheres[*j as usize]);
            let gap = pose_a
                .transform_point(sa.centre)
                .distance(pose_b.transform_point(sb.centre))
                - sa.radius
                - sb.radius;
            order.push((gap, k));
        }
        order.sort_by(|x, y| x.0.total_cmp(&y.0));
        step += 1;
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO);
        for &(gap, k) in &order {
            if gap >= best.0 {
                break;
            }
            for &(x, y) in &leaf_pairs[k].2 {
                let key = x as usize * ny + y as usize;
                let (last_step, then_d, then_t) = seen[key];
                if last_step == step {
                    continue;
                }
                seen[key].0 = step;
                if then_d.is_finite()
                    && then_d as f64 - mu * (t - then_t) - LIPSCHITZ_SLACK_MM >= best.0 as f64
                {
                    continue;
                }
                let (tx, (cx, rx)) = pa.get(x as usize, &pose_a);
                let tx = *tx;
                let (ty, (cy, ry)) = pb.get(y as usize, &pose_b);
                if cx.distance(cy) - rx - ry >= best.0 {
                    continue;
                }
                let p = closest_points_triangle_triangle(&tx, ty);
                seen[key] = (step, p.distance, t);
                if p.distance < best.0 {
                    best = (p.distance, p.on_first, p.on_second);
                }
            }
        }
        let (d, qa, qb) = best;
        if !d.is_finite() {
            return None;
        }
        let d = d as f64;
        // Within the tolerance, or out of steps: report here (still never after the contact).
        if d <= tol || round == MAX_STEPS {
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
    None
}
