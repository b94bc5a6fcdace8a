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
//! Advancement: the candidate triangle pairs are listed once each (leaf pairs share triangles,
//! so each leaf pair marks its pairs in a bit matrix), the triangles numbered in the order of
//! their leaf pairs' distance at the start of the window. From the earliest leaf
//! time, each step computes a lower bound d on the distance between the candidate triangles at the
//! current poses: the exact distance of every candidate pair that three cheap lower bounds cannot
//! already show farther than the best so far: the triangles' bounding spheres, their projections
//! on the direction between the previous step's closest points (or between the nearest leaf
//! pair's centres), and the plane gap (one triangle wholly beyond the other's plane, nearly exact
//! for the facing triangles of teeth in contact). The previous step's nearest pair (in the first
//! step, the pair with the nearest centres) is measured first, so the best is small from the
//! start and the bounds cull the rest. The minimum over all
//! candidate pairs is a lower bound on the distance of whichever pair touches first (that pair
//! is a candidate). No point of the candidates
//! moves faster than μ = Σ (origin travel + rotation angle × farthest candidate vertex from the
//! rotation axis) per unit time ([`Motion::speed_bound_of`]), so the gap cannot close before
//! t + d/μ: a step of (d − tolerance/2)/μ leaves at least half the tolerance. Teeth that slide
//! along each other or turn about their contact close far more slowly than μ, so the step is
//! extended directionally (`Relative`): along the direction n between the closest points, the
//! speed of the other tooth's points in the first tooth's frame is an affine function of the point
//! and its change is bounded, so each candidate pair apart along n provably stays more than half
//! the tolerance apart for a time that is often several plain steps; the step is the least such
//! time over the candidate pairs (a pair not apart along n keeps its plain bound). The advancement
//! stops when d ≤ [`GAP_TOLERANCE_MM`]: the reported time is never after the first contact and
//! the gap left there is within the tolerance. Between steps each candidate pair keeps its last distance (or
//! lower bound): it cannot have shrunk by more than μ·Δt, so pairs whose carried bound exceeds
//! the best distance of the step are not measured again (the minimum is unchanged, only cheaper).
//! Teeth already interpenetrating at t = 0 report time 0 and the penetration depth of the whole
//! meshes ([`mesh_penetration_near`]: the candidate triangles hold every triangle that crosses
//! the other surface, so the search walks from them over the part of each surface inside the
//! other instead of testing every vertex). After [`MAX_STEPS`] steps (slow convergence under large rotations) the current, still
//! conservative, time is reported with its gap.
//!
//! [`Motion::speed_bound_of`]: crate::collision::motion::Motion::speed_bound_of

use glam::Vec3;

use super::lanes::Affine32;
use super::{Body, PairContact, continuous};
use crate::collision::motion::{DPose, Motion, NodeCache};
use crate::geometry::{
    FacePlane, NearContact, closest_points_facing_triangles, mesh_penetration_near,
};

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
    /// |centre| + radius: no vertex is farther from the origin.
    reach: f32,
    plane: FacePlane,
}

impl PlacedTri {
    fn new(v: [Vec3; 3]) -> Self {
        let centre = (v[0] + v[1] + v[2]) / 3.0;
        let radius = v
            .iter()
            .map(|p| p.distance_squared(centre))
            .fold(0.0f32, f32::max)
            .sqrt();
        Self {
            v,
            centre,
            radius,
            reach: centre.length() + radius,
            plane: FacePlane::of(&v),
        }
    }

    /// A lower bound of the distance to `o`: how far apart the two triangles' projections on the
    /// unit axis `n` lie (0 when they overlap), less the f32 rounding of the projections (each
    /// within 5.2u·|v| of exact, u = 2⁻²⁴, and |v| ≤ |centre| + radius) and a relative 10⁻⁶ for
    /// the difference and the axis length.
    #[inline]
    fn axis_gap(&self, o: &PlacedTri, n: Vec3) -> f32 {
        let p = self.v.map(|v| n.dot(v));
        let q = o.v.map(|v| n.dot(v));
        let (p_lo, p_hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        let (q_lo, q_hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        let g = (q_lo - p_hi).max(p_lo - q_hi);
        let margin = 4e-7 * (self.reach + o.reach);
        (g - margin).max(0.0) * (1.0 - 1e-6)
    }

    /// A lower bound of the distance to `o`: the plane gap of [`crate::geometry::plane_gap`],
    /// with each plane computed once per step and its rounding margin taken from the bounding
    /// spheres (which bound the triangles' spread and their distance from the origin).
    #[inline]
    fn gap_to(&self, o: &PlacedTri, between: f32) -> f32 {
        let m = self.plane.beyond(&o.v).max(o.plane.beyond(&self.v));
        let near = (between + self.radius + o.radius) as f64;
        let far = (self.reach + o.reach) as f64 + near;
        let margin = 1e-8 * near + 1e-14 * far;
        ((m - margin).max(0.0) as f32) * (1.0 - 1e-6)
    }
}

/// Per-thread scratch of the advancement: each mesh triangle's index among the candidates, the
/// triangle pairs already listed (one bit per pair of candidates) and the candidate pairs.
struct Scratch {
    slot_a: NodeCache<u32>,
    slot_b: NodeCache<u32>,
    leaf_a: NodeCache<(u32, u32)>,
    leaf_b: NodeCache<(u32, u32)>,
    local_a: Vec<u32>,
    local_b: Vec<u32>,
    listed: Vec<u64>,
    candidates: Vec<Candidate>,
}

/// A candidate triangle pair (indices among the candidate triangles of each side) and its last
/// measured distance or lower bound `d` with the time `t` of it (−∞ before the first look).
#[derive(Clone, Copy)]
struct Candidate {
    x: u32,
    y: u32,
    d: f32,
    t: f64,
}

/// Candidate lists up to this many entries (and listed-pair bit sets up to this many words) are
/// kept per thread between queries.
const KEEP_CANDIDATES: usize = 1 << 16;

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = const {
        std::cell::RefCell::new(Scratch {
            slot_a: NodeCache::new(),
            slot_b: NodeCache::new(),
            leaf_a: NodeCache::new(),
            leaf_b: NodeCache::new(),
            local_a: Vec::new(),
            local_b: Vec::new(),
            listed: Vec::new(),
            candidates: Vec::new(),
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
    SCRATCH.with_borrow_mut(|scratch| {
        let contact = advance_with(a, b, swept, scratch);
        // Scan-resolution teeth in deep contact list millions of pairs: their lists are not kept.
        if scratch.candidates.capacity() > KEEP_CANDIDATES {
            scratch.candidates = Vec::new();
        }
        if scratch.listed.capacity() > KEEP_CANDIDATES {
            scratch.listed = Vec::new();
        }
        contact
    })
}

fn advance_with(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    scratch: &mut Scratch,
) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ma, mb) = (&a.shape.geometry.mesh, &b.shape.geometry.mesh);
    let Scratch {
        slot_a,
        slot_b,
        leaf_a,
        leaf_b,
        local_a,
        local_b,
        listed,
        candidates,
    } = scratch;
    let mut t = swept
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    // Leaf pairs nearest first at the start, so that the first triangle pairs measured are near
    // ones and the bounds cull the rest.
    let start_rel = relative(&a.motion, &b.motion, t).rel;
    let mut order: Vec<(f32, usize)> = swept
        .leaf_times
        .iter()
        .enumerate()
        .map(|(k, &(i, j, _))| {
            let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
            let gap = sa.centre.distance(start_rel.apply(sb.centre)) - sa.radius - sb.radius;
            (gap, k)
        })
        .collect();
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    // Candidate triangles of each side (ids_a / ids_b), numbered in order of first use; each
    // leaf's triangles as those numbers, once per leaf (leaves recur in many leaf pairs), in
    // `local_a` / `local_b` at the span its cache holds.
    slot_a.begin(ma.triangles.len());
    slot_b.begin(mb.triangles.len());
    leaf_a.begin(ta.spheres.len());
    leaf_b.begin(tb.spheres.len());
    let (mut ids_a, mut ids_b) = (Vec::new(), Vec::new());
    local_a.clear();
    local_b.clear();
    let number = |tree: &crate::collision::CompactTree,
                  leaf: usize,
                  slot: &mut NodeCache<u32>,
                  ids: &mut Vec<u32>,
                  local: &mut Vec<u32>| {
        let at = local.len();
        for &x in tree.triangles(leaf) {
            local.push(slot.get(x as usize, || {
                ids.push(x);
                ids.len() as u32 - 1
            }));
        }
        (at as u32, local.len() as u32)
    };
    let mut spans: Vec<((u32, u32), (u32, u32))> = Vec::with_capacity(order.len());
    for &(_, k) in &order {
        let (i, j, _) = swept.leaf_times[k];
        let xs = leaf_a.get(i as usize, || {
            number(ta, i as usize, slot_a, &mut ids_a, local_a)
        });
        let ys = leaf_b.get(j as usize, || {
            number(tb, j as usize, slot_b, &mut ids_b, local_b)
        });
        spans.push((xs, ys));
    }
    // Candidate triangle pairs, each once (leaf pairs share triangles): marked in a bit matrix
    // (a row of b's numbers for each of a's), then listed row by row; near leaf pairs' triangles
    // have the low numbers, so they come first. Rows of up to 64 take one word per leaf pair and
    // triangle of a.
    let (nx, ny) = (ids_a.len(), ids_b.len());
    let row_words = ny.div_ceil(64);
    let words = nx * row_words;
    if listed.len() < words {
        listed.resize(words, 0);
    }
    listed[..words].fill(0);
    for &((x0, x1), (y0, y1)) in &spans {
        let (xs, ys) = (
            &local_a[x0 as usize..x1 as usize],
            &local_b[y0 as usize..y1 as usize],
        );
        if row_words == 1 {
            let mask = ys.iter().fold(0u64, |m, &yi| m | 1 << yi);
            for &xi in xs {
                listed[xi as usize] |= mask;
            }
        } else {
            for &xi in xs {
                let row = &mut listed[xi as usize * row_words..][..row_words];
                for &yi in ys {
                    row[yi as usize / 64] |= 1u64 << (yi % 64);
                }
            }
        }
    }
    candidates.clear();
    for (w, &word) in listed[..words].iter().enumerate() {
        let (xi, base) = (w / row_words, (w % row_words) * 64);
        let mut bits = word;
        while bits != 0 {
            let yi = base + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            candidates.push(Candidate {
                x: xi as u32,
                y: yi as u32,
                d: f32::NEG_INFINITY,
                t,
            });
        }
    }
    let speed = |motion: &Motion, mesh: &crate::geometry::TriMesh, ids: &[u32]| {
        motion.speed_bound_of(ids.iter().flat_map(|&t| mesh.triangle(t as usize)))
    };
    let mu = (speed(&a.motion, ma, &ids_a) + speed(&b.motion, mb, &ids_b)) * (1.0 + 1e-6);
    let tol = GAP_TOLERANCE_MM as f64;
    // The first tooth's candidate triangles as stored, the second's placed anew each step.
    let place = |mesh: &crate::geometry::TriMesh, id: u32, map: Option<&Affine32>| {
        let [p, q, r] = mesh.triangle(id as usize);
        PlacedTri::new(match map {
            Some(m) => [m.apply(p), m.apply(q), m.apply(r)],
            None => [p, q, r],
        })
    };
    let tris_a: Vec<PlacedTri> = ids_a.iter().map(|&x| place(ma, x, None)).collect();
    let mut tris_b: Vec<PlacedTri> = Vec::with_capacity(ids_b.len());
    let motions = Relative::new(&a.motion, &b.motion, b.shape.max_rho as f64);
    // The nearest pair of the previous step, measured first in the next, and the direction
    // between its closest points (a's frame): projections on it bound most pairs near the contact.
    // Before the first step, the direction between the nearest leaf pair's centres.
    let mut nearest: Option<usize> = None;
    let mut axis = order.first().map_or(Vec3::X, |&(_, k)| {
        let (i, j, _) = swept.leaf_times[k];
        let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
        (start_rel.apply(sb.centre) - sa.centre).normalize_or(Vec3::X)
    });
    for round in 0..=MAX_STEPS {
        // Work in a's frame: a's triangles as stored, b's mapped by pose_a⁻¹ ∘ pose_b.
        let Frame {
            pose_a,
            pose_b,
            to_a,
            rel,
        } = relative(&a.motion, &b.motion, t);
        tris_b.clear();
        tris_b.extend(ids_b.iter().map(|&y| place(mb, y, Some(&rel))));
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO);
        let mut best_k = None;
        // No pair's distance shrinks faster than μ, so its last distance d, measured at t₀,
        // bounds it now by d − μ·(t − t₀): pairs that cannot beat the best are not measured.
        let mut look = |k: usize, c: &mut Candidate| {
            if c.d as f64 - mu * (t - c.t) - LIPSCHITZ_SLACK_MM >= best.0 as f64 {
                return;
            }
            c.t = t;
            let (tx, ty) = (&tris_a[c.x as usize], &tris_b[c.y as usize]);
            let between = tx.centre.distance(ty.centre);
            let lb = (between - tx.radius - ty.radius).max(tx.axis_gap(ty, axis));
            if lb >= best.0 {
                c.d = lb.max(0.0);
                return;
            }
            // Facing triangles: the plane gap is nearly the distance and far cheaper.
            let lb = tx.gap_to(ty, between);
            if lb >= best.0 {
                c.d = lb;
                return;
            }
            // The pairs measured are the nearest candidates, mostly facing each other.
            let p = closest_points_facing_triangles(&tx.v, &ty.v);
            c.d = p.distance;
            if p.distance < best.0 {
                best = (p.distance, p.on_first, p.on_second);
                best_k = Some(k);
            }
        };
        if nearest.is_none() {
            // First step: the pair whose bounding spheres are nearest is measured first.
            nearest = candidates
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let (tx, ty) = (&tris_a[c.x as usize], &tris_b[c.y as usize]);
                    (tx.centre.distance_squared(ty.centre), k)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .map(|x| x.1);
        }
        if let Some(k) = nearest {
            look(k, &mut candidates[k]);
        }
        for (k, c) in candidates.iter_mut().enumerate() {
            if Some(k) != nearest {
                look(k, c);
            }
        }
        nearest = best_k;
        let (d, qa, qb) = best;
        axis = (qb - qa).normalize_or(axis);
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
                // Touching or interpenetrating (only possible at the start): the candidates
                // already touch, so only the depth is left to find.
                let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
                let (depth, pa, pb) = mesh_penetration_near(
                    NearContact {
                        mesh: ga.mesh_ref(),
                        stars: &ga.stars,
                        near: &ids_a,
                    },
                    &pose_a,
                    NearContact {
                        mesh: gb.mesh_ref(),
                        stars: &gb.stars,
                        near: &ids_b,
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
        // Every pair is at least d apart and closes at most μ per unit time; the pairs near the
        // contact, which limit that step, usually separate along the closest direction much more
        // slowly than μ: extend the step as far as every pair allows (see [`Drift`]).
        let h = 0.5 * tol;
        let plain = (d - h) / mu;
        let mut step = plain;
        if let (Some(k), Some(drift)) = (nearest, motions.drift(t, to_a, axis, &rel)) {
            let c = &candidates[k];
            let first = drift.step(&tris_a[c.x as usize], &tris_b[c.y as usize]);
            step = first.min(1.0 - t).max(plain);
            for c in candidates.iter() {
                if step <= plain {
                    break;
                }
                // Pairs whose own distance bound already allows the step need no more.
                let bound = c.d as f64 - mu * (t - c.t) - LIPSCHITZ_SLACK_MM;
                if bound - h >= mu * step {
                    continue;
                }
                let own = drift.step(&tris_a[c.x as usize], &tris_b[c.y as usize]);
                step = step.min(own.max((bound - h) / mu)).max(plain);
            }
        }
        t += step;
        if t >= 1.0 {
            return None;
        }
    }
    None
}

/// Directional steps: how fast the second tooth's points drift along a direction of the first
/// tooth's frame.
///
/// In the first tooth's frame a point y of the second moves with velocity
/// ẏ = U + W × (y − o) − Ω × y, where U = Rₐᵀ(V_b − V_a), W = Rₐᵀω_b, Ω = Rₐᵀω_a (V the origins'
/// velocities, ω the world angular velocities of the slerps, Rₐ the first tooth's rotation and
/// o the second tooth's origin, all at the current time). So its speed along a fixed unit n is
/// the affine function n·ẏ = c₀ + y·m with c₀ = n·U − o·(n × W) and m = n × (W − Ω). Its
/// acceleration is Rₐᵀü − 2Ω × Rₐᵀu̇ + Ω × (Ω × y) (u = w − Tₐ, w the world point), so
/// |ÿ| ≤ A = θ_b²ρ_b + 2θₐ(|V_b − V_a| + θ_bρ_b) + θₐ²Y, with θ the rotation angles, ρ_b the
/// second tooth's largest vertex radius and Y a bound on |y| over the rest of the step. A
/// candidate pair whose triangles are g apart along n (every vertex of the second beyond every
/// vertex of the first) stays at least g + sΔ − AΔ²/2 apart along n after Δ, s the least speed of
/// its vertices along n, hence at least that far apart; the step keeps that above half the
/// tolerance plus [`DRIFT_SLACK_MM`] for every candidate pair (or uses the pair's plain bound
/// (d − tolerance/2)/μ when larger), so it never passes a contact.
struct Relative {
    /// Origins' relative velocity, world (mm per unit time).
    v: glam::DVec3,
    /// Angular velocities, world.
    omega_a: glam::DVec3,
    omega_b: glam::DVec3,
    /// Rotation angles and speeds of the origins.
    theta_a: f64,
    theta_b: f64,
    travel: f64,
    /// Largest vertex radius of the second tooth.
    rho_b: f64,
}

/// Allowance (mm) for the difference between the poses the motions produce (f32 slerp and lerp)
/// and the constant-velocity model of [`Relative`], and for the f32 projections, per mm of
/// distance from the first tooth's origin (plus a constant): far above both.
const DRIFT_SLACK_MM: f64 = 1e-4;

impl Relative {
    fn new(a: &Motion, b: &Motion, rho_b: f64) -> Self {
        let (theta_a, theta_b) = (a.angle(), b.angle());
        let velocity = |m: &Motion| m.end.translation.as_dvec3() - m.start.translation.as_dvec3();
        Self {
            v: velocity(b) - velocity(a),
            omega_a: a.axis() * theta_a,
            omega_b: b.axis() * theta_b,
            theta_a,
            theta_b,
            travel: velocity(a).length() + velocity(b).length(),
            rho_b,
        }
    }

    /// The drift along the unit `n` (first tooth's frame) at time `t`, with the first tooth's
    /// inverse rotation and the second's map into its frame then; `None` when nothing useful can
    /// be said.
    fn drift(&self, t: f64, to_a: glam::DQuat, n: Vec3, rel: &Affine32) -> Option<Drift> {
        let (u, w, omega) = (to_a * self.v, to_a * self.omega_b, to_a * self.omega_a);
        let o = rel.t.as_dvec3();
        let nd = n.as_dvec3();
        let c0 = nd.dot(u) - o.dot(nd.cross(w));
        let m = nd.cross(w - omega);
        // |y| over the rest of the step: now within |o| + ρ_b, and no point moves away from
        // the first origin faster than the two origins and the second's rotation.
        let y = o.length() + self.rho_b + (1.0 - t) * (self.travel + self.theta_b * self.rho_b);
        let accel = self.theta_b * self.theta_b * self.rho_b
            + 2.0 * self.theta_a * (self.v.length() + self.theta_b * self.rho_b)
            + self.theta_a * self.theta_a * y;
        (c0.is_finite() && m.is_finite() && accel.is_finite()).then_some(Drift {
            n,
            c0,
            m,
            accel: accel * (1.0 + 1e-6),
            margin: DRIFT_SLACK_MM * (1.0 + y),
        })
    }
}

/// The drift of [`Relative::drift`]: speed along `n` of a point y is `c0 + y·m`, acceleration at
/// most `accel`.
struct Drift {
    n: Vec3,
    c0: f64,
    m: glam::DVec3,
    accel: f64,
    margin: f64,
}

impl Drift {
    /// How long (in step time) the triangles provably stay more than half the tolerance plus the
    /// margin apart along ±n; 0 when they are not that far apart along it.
    fn step(&self, x: &PlacedTri, y: &PlacedTri) -> f64 {
        let n = self.n;
        let p = x.v.map(|v| n.dot(v) as f64);
        let q = y.v.map(|v| n.dot(v) as f64);
        let (p_lo, p_hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        let (q_lo, q_hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        let speed = y.v.map(|v| self.c0 + v.as_dvec3().dot(self.m));
        let keep = 0.5 * GAP_TOLERANCE_MM as f64 + self.margin;
        let (s_lo, s_hi) = (
            speed[0].min(speed[1]).min(speed[2]),
            speed[0].max(speed[1]).max(speed[2]),
        );
        // The second beyond the first along n, its vertices moving at least s_lo along n; or
        // along −n, moving at least −s_hi along −n.
        let side = |gap: f64, s: f64| {
            // The positive root of AΔ²/2 − sΔ − e, written without cancellation.
            let e = gap - keep;
            if e <= 0.0 {
                return 0.0;
            }
            let root = (s * s + 2.0 * self.accel * e).sqrt();
            if s < 0.0 {
                2.0 * e / (root - s)
            } else if self.accel > 0.0 {
                (s + root) / self.accel
            } else {
                f64::INFINITY
            }
        };
        side(q_lo - p_hi, s_lo).max(side(p_lo - q_hi, -s_hi))
    }
}

/// Both teeth at one time, seen from the first tooth.
struct Frame {
    pose_a: crate::geometry::Pose,
    pose_b: crate::geometry::Pose,
    /// The first tooth's rotation, inverted (world to its frame).
    to_a: glam::DQuat,
    /// The second tooth's map into the first's frame, pose_a⁻¹ ∘ pose_b.
    rel: Affine32,
}

/// Both teeth at time `t`.
fn relative(a: &Motion, b: &Motion, t: f64) -> Frame {
    let (pose_a, pose_b) = (a.at(t as f32), b.at(t as f32));
    let (da, db) = (DPose::from_pose(&pose_a), DPose::from_pose(&pose_b));
    let to_a = da.rotation.inverse();
    let rel = Affine32::new(to_a * db.rotation, to_a * (db.translation - da.translation));
    Frame {
        pose_a,
        pose_b,
        to_a,
        rel,
    }
}

#[cfg(test)]
mod tests;
