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
//! searched at once, with the leaf pairs of one continuous query over the whole step; otherwise
//! in windows of doubling length (1/32 of the step first), each with
//! only the leaf pairs whose swept spheres meet within it, so a long step does not drag every leaf
//! pair of its whole sweep into the triangle stage.
//!
//! Advancement: from the earliest leaf time in the window, a lower bound d on
//! the distance between the contact-capable parts (the surface inside each meeting leaf pair) is
//! computed at the current poses: the exact distance between candidate triangles, visiting leaf
//! pairs nearest first and skipping a leaf pair once its spheres are farther apart than the best
//! distance so far (its in-sphere surface cannot be closer), and measuring a triangle pair only
//! when neither the triangles' bounding spheres nor their planes (one triangle wholly beyond the
//! other's plane, a lower bound that is nearly exact for the facing triangles of teeth in contact)
//! already show it farther than the best; no point of the candidates
//! moves faster than μ = Σ (origin travel + rotation angle × farthest candidate vertex from the
//! rotation axis) per unit time ([`Motion::speed_bound_of`]), so the gap cannot close before
//! t + d/μ. Each
//! step advances by (d − tolerance/2)/μ, leaving at least half the tolerance, and stops when
//! d ≤ [`GAP_TOLERANCE_MM`]: the reported time is never after the first contact and the gap left
//! there is within the tolerance. Between steps each triangle pair keeps its last distance: it
//! cannot have shrunk by more than μ·Δt, so pairs whose carried bound exceeds the best distance of
//! the step are not measured again (the minimum is unchanged, only cheaper). Teeth already
//! interpenetrating at t = 0 report time 0 and the penetration depth of the whole meshes. After [`MAX_STEPS`] steps (slow convergence under large
//! rotations) the current, still conservative, time is reported with its gap.
//!
//! [`Motion::speed_bound_of`]: crate::collision::motion::Motion::speed_bound_of

use glam::Vec3;

use super::lanes::Affine32;
use super::{Body, PairContact, continuous};
use crate::collision::motion::{DPose, Motion, NodeCache};
use crate::geometry::{FacePlane, MeshRef, closest_points_triangle_triangle, mesh_penetration};

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

/// One candidate triangle placed at the current time: vertices, bounding sphere and plane.
#[derive(Clone, Copy, Default)]
struct PlacedTri {
    v: [Vec3; 3],
    centre: Vec3,
    radius: f32,
    plane: FacePlane,
}

impl PlacedTri {
    fn new(v: [Vec3; 3]) -> Self {
        let centre = (v[0] + v[1] + v[2]) / 3.0;
        let radius = v.iter().map(|p| p.distance(centre)).fold(0.0f32, f32::max);
        Self {
            v,
            centre,
            radius,
            plane: FacePlane::of(&v),
        }
    }

    /// A lower bound of the distance to `o`: the plane gap of [`crate::geometry::plane_gap`],
    /// with each plane computed once per step and its rounding margin taken from the bounding
    /// spheres (which bound the triangles' spread and their distance from the origin).
    #[inline]
    fn gap_to(&self, o: &PlacedTri) -> f32 {
        let m = self.plane.beyond(&o.v).max(o.plane.beyond(&self.v));
        if m <= 0.0 {
            return 0.0;
        }
        let near = (self.centre.distance(o.centre) + self.radius + o.radius) as f64;
        let far = (self.centre.length() + o.centre.length()) as f64 + near;
        let margin = 1e-8 * near + 1e-14 * far;
        ((m - margin).max(0.0) as f32) * (1.0 - 1e-6)
    }
}

/// Triangles of one side placed in the first tooth's frame, on demand (the first tooth's own once,
/// the second's once per step).
struct Placed<'m> {
    mesh: &'m crate::geometry::TriMesh,
    ids: Vec<u32>,
    tris: Vec<PlacedTri>,
    stamp: Vec<u32>,
    now: u32,
}

impl<'m> Placed<'m> {
    fn new(mesh: &'m crate::geometry::TriMesh, ids: Vec<u32>) -> Self {
        let n = ids.len();
        Self {
            mesh,
            ids,
            tris: vec![PlacedTri::default(); n],
            stamp: vec![0; n],
            now: 1,
        }
    }

    #[inline]
    fn get(&mut self, k: usize, map: Option<&Affine32>) -> &PlacedTri {
        if self.stamp[k] != self.now {
            let [p, q, r] = self.mesh.triangle(self.ids[k] as usize);
            let tri = match map {
                Some(m) => [m.apply(p), m.apply(q), m.apply(r)],
                None => [p, q, r],
            };
            self.tris[k] = PlacedTri::new(tri);
            self.stamp[k] = self.now;
        }
        &self.tris[k]
    }
}

/// Per-thread scratch of the advancement: each mesh triangle's index among the candidates, and
/// per candidate triangle pair its carried bound (see [`advance`]).
struct Scratch {
    slot_a: NodeCache<u32>,
    slot_b: NodeCache<u32>,
    seen: Vec<Seen>,
    generation: u32,
}

/// A candidate triangle pair's record: the query (generation) and step it was last looked at,
/// and its last measured distance (or lower bound) with the time of it.
#[derive(Clone, Copy, Default)]
struct Seen {
    generation: u32,
    step: u32,
    d: f32,
    t: f64,
}

/// Candidate pair tables up to this many entries are kept per thread between queries; larger
/// ones (scan-resolution teeth in deep contact) are allocated for the query.
const KEEP_SEEN: usize = 1 << 18;

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = const {
        std::cell::RefCell::new(Scratch {
            slot_a: NodeCache::new(),
            slot_b: NodeCache::new(),
            seen: Vec::new(),
            generation: 0,
        })
    };
}

/// The exact query.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    // The earliest leaf time bounds the first contact from below; from there the step is searched
    // in windows of growing length, each with only the leaf pairs that meet within it (a slerp and
    // lerp restricted to a sub-interval is the slerp and lerp between its end poses).
    // Short steps (no point moves more than WHOLE_STEP_TRAVEL_MM): the whole step at once,
    // from the earliest leaf time; longer ones in doubling windows from there.
    let whole =
        a.motion.speed_bound(a.shape.max_rho as f64) + b.motion.speed_bound(b.shape.max_rho as f64);
    if whole <= WHOLE_STEP_TRAVEL_MM {
        let swept = continuous::query(a, b, true)?;
        return advance(a, b, &swept);
    }
    let first = continuous::query(a, b, false)?;
    let mut t = first
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    let travel = whole * (1.0 - t);
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
    SCRATCH.with_borrow_mut(|scratch| advance_with(a, b, swept, scratch))
}

fn advance_with(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    scratch: &mut Scratch,
) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ma, mb) = (&a.shape.geometry.mesh, &b.shape.geometry.mesh);
    // Candidate triangles of each side (ids_a / ids_b) and, per leaf pair, its triangle pairs
    // as indices into them (a flat list with one range per leaf pair).
    let Scratch {
        slot_a,
        slot_b,
        seen,
        generation,
    } = scratch;
    slot_a.begin(ma.triangles.len());
    slot_b.begin(mb.triangles.len());
    let mut ids_a: Vec<u32> = Vec::new();
    let mut ids_b: Vec<u32> = Vec::new();
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut leaf_pairs: Vec<(u32, u32, std::ops::Range<usize>)> =
        Vec::with_capacity(swept.leaf_times.len());
    let mut local_b: Vec<u32> = Vec::new();
    for &(i, j, _) in &swept.leaf_times {
        local_b.clear();
        for &y in &tb.triangles[j as usize] {
            local_b.push(slot_b.get(y as usize, || {
                ids_b.push(y);
                ids_b.len() as u32 - 1
            }));
        }
        let first = pairs.len();
        for &x in &ta.triangles[i as usize] {
            let xi = slot_a.get(x as usize, || {
                ids_a.push(x);
                ids_a.len() as u32 - 1
            });
            pairs.extend(local_b.iter().map(|&yi| (xi, yi)));
        }
        leaf_pairs.push((i, j, first..pairs.len()));
    }
    let speed = |motion: &Motion, mesh: &crate::geometry::TriMesh, ids: &[u32]| {
        motion.speed_bound_of(ids.iter().flat_map(|&t| mesh.triangle(t as usize)))
    };
    let mu = (speed(&a.motion, ma, &ids_a) + speed(&b.motion, mb, &ids_b)) * (1.0 + 1e-6);
    let tol = GAP_TOLERANCE_MM as f64;
    let mut t = swept
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    let ny = ids_b.len();
    let table = ids_a.len() * ny;
    let mut pa = Placed::new(ma, ids_a);
    let mut pb = Placed::new(mb, ids_b);
    let mut order: Vec<(f32, usize)> = Vec::with_capacity(leaf_pairs.len());
    // Per triangle pair (leaf pairs share triangles): the step it was last looked at, and its
    // last measured distance (or lower bound) with the time of it: no pair's distance shrinks
    // faster than μ, so d − μ·(t − t_then) bounds it now and pairs that cannot beat the best
    // are skipped. Small tables live on in the thread's scratch, told apart by generation.
    let mut own: Vec<Seen>;
    let seen: &mut [Seen] = if table <= KEEP_SEEN {
        if seen.len() < table {
            seen.resize(table, Seen::default());
        }
        *generation = generation.wrapping_add(1);
        if *generation == 0 {
            seen.iter_mut().for_each(|s| s.generation = 0);
            *generation = 1;
        }
        &mut seen[..table]
    } else {
        *generation = generation.wrapping_add(1).max(1);
        own = vec![Seen::default(); table];
        &mut own
    };
    let now = *generation;
    let mut step = 0u32;
    for round in 0..=MAX_STEPS {
        let (pose_a, pose_b) = (a.motion.at(t as f32), b.motion.at(t as f32));
        // Work in a's frame: a's triangles as stored, b's mapped by pose_a⁻¹ ∘ pose_b.
        let (da, db) = (DPose::from_pose(&pose_a), DPose::from_pose(&pose_b));
        let inv = da.rotation.inverse();
        let rel = Affine32::new(inv * db.rotation, inv * (db.translation - da.translation));
        pb.now += 1;
        // Leaf pairs nearest first: a pair whose spheres are farther apart than the best distance
        // found cannot hold a closer contact-capable pair (see the module doc).
        order.clear();
        for (k, (i, j, _)) in leaf_pairs.iter().enumerate() {
            let (sa, sb) = (ta.spheres[*i as usize], tb.spheres[*j as usize]);
            let gap = sa.centre.distance(rel.apply(sb.centre)) - sa.radius - sb.radius;
            order.push((gap, k));
        }
        order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        step += 1;
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO);
        for &(gap, k) in &order {
            if gap >= best.0 {
                break;
            }
            for &(x, y) in &pairs[leaf_pairs[k].2.clone()] {
                let key = x as usize * ny + y as usize;
                let record = &mut seen[key];
                if record.generation == now {
                    if record.step == step {
                        continue;
                    }
                    if record.d as f64 - mu * (t - record.t) - LIPSCHITZ_SLACK_MM >= best.0 as f64 {
                        record.step = step;
                        continue;
                    }
                }
                *record = Seen {
                    generation: now,
                    step,
                    d: f32::INFINITY,
                    t,
                };
                let tx = *pa.get(x as usize, None);
                let ty = pb.get(y as usize, Some(&rel));
                let spheres = tx.centre.distance(ty.centre) - tx.radius - ty.radius;
                if spheres >= best.0 {
                    record.d = spheres.max(0.0);
                    continue;
                }
                // Facing triangles: the plane gap is nearly the distance and far cheaper.
                let lb = tx.gap_to(ty);
                if lb >= best.0 {
                    record.d = lb;
                    continue;
                }
                let p = closest_points_triangle_triangle(&tx.v, &ty.v);
                record.d = p.distance;
                if p.distance < best.0 {
                    best = (p.distance, p.on_first, p.on_second);
                }
            }
        }
        let (d, qa, qb) = best;
        if !d.is_finite() {
            return None;
        }
        let (qa, qb) = (pose_a.transform_point(qa), pose_a.transform_point(qb));
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
                // The candidates already touch: only the depth is left to find.
                let (depth, pa, pb) = mesh_penetration(
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
                if depth > 0.0 {
                    contact.depth_mm = depth;
                    contact.points = [pa, pb];
                    if let Some(n) = (pb - pa).try_normalize() {
                        contact.normal = -n;
                    }
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
