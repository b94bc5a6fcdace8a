//! Exact contact: the continuous stage, then conservative advancement (Mirtich 1996) on the
//! candidate triangles, the triangles under the leaf pairs whose swept spheres meet.
//!
//! Why the candidates suffice: a contact point of the two surfaces lies in some leaf of each tree
//! (coverage invariant) and its triangle touches that leaf, and those two leaves' swept spheres meet
//! at the contact time; so every pair of triangles that can touch during the step is a candidate
//! pair, and no other pair touches at all. The same argument narrows them further, which the
//! hierarchical search does (its leaves hold dozens of triangles at scan resolution): a triangle
//! of a leaf can only touch the other tooth at a point inside one of the other's leaves that meets
//! this leaf, so only the triangles whose bounding spheres reach such a partner's sphere, swept
//! over the rest of the motion (placed at the middle of the time left and grown by both teeth's
//! travel over half of it), are listed.
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
//! other instead of testing every vertex; the hierarchical search first narrows them to those
//! near a candidate of the other tooth, which still holds every crossing one). A contact at the
//! start of the motion also carries the meshes' overlap at its end when asked
//! ([`query_knowing`], which a simulation's steps use; [`PairContact::end_overlap`]), which a
//! response needs to tell whether the contact deepens: every
//! triangle pair that meets at the end touches during the motion, so it is a candidate pair, and
//! the walk goes from the candidates that meet at the end placement instead of the whole meshes'
//! meeting triangles, which cost a search of both meshes' hierarchies. A known overlap that kept
//! the samples it found inside ([`EndOverlap::inside`]) spares the walk at a nearby placement of
//! the same meshes, at the start or the end of the motion: only the samples that can still be the
//! deepest are tested ([`crate::geometry::InsideSamples::rewalk`]; the same depth), and the
//! candidates that meet are not listed. After [`MAX_STEPS`] steps (slow convergence under large rotations) the current, still
//! conservative, time is reported with its gap.
//!
//! Two ways to search the candidates, the same pairs and the same guarantees. **Flat**
//! (`flat.rs`, the steps above): every candidate pair listed once and looked at each step, for
//! sets up to `FLAT_PAIRS` pairs (the paper's resolution). **Hierarchical** (`tree.rs`, teeth
//! at scan resolution, where the leaf pairs hold up to millions of triangle pairs): each tooth's
//! candidates form a patch with a hierarchy of its own (the part of the tooth's triangle
//! hierarchy above them, `patch.rs`), whose boxes are refitted to the candidates alone in a frame
//! whose third axis is the search direction (the closest direction of the last step) whenever
//! that direction or the second tooth's placement changes. Each step searches the two patches
//! together, nearest node pairs first, starting from the previous step's nearest pair; a node
//! pair is opened only when its boxes do not show it farther than the best so far, and a
//! triangle pair counts only if its triangles lie in a meeting leaf pair (each candidate keeps the
//! list of its meeting leaves), as in the flat search. The directional step descends the same
//! way, a node pair being left closed when its plain bound or its drift along the direction (the
//! boxes' extent along the frame's third axis) already allows
//! the step. All node bounds are computed in f32 and lowered by far more than their rounding.
//! The hierarchical search prunes a little (`NEAREST_SLACK`, 2 %) below its best so far, so it
//! does not spend most of its node pairs proving that nothing is slightly nearer: the pair it
//! finds is within that fraction of the least, and the plain step is taken from the pruning
//! limit, which nothing left unmeasured is nearer than.
//! Once the motion is under way (t > 0) the teeth cannot interpenetrate, so the hierarchical
//! search stops at the first triangle pair within the tolerance and reports it: its gap is within
//! the tolerance, the true least gap lies between half the tolerance and it, and the time is the
//! same conservative one (at t = 0 it searches for the least distance, which may be 0).
//!
//! [`Motion::speed_bound_of`]: crate::collision::motion::Motion::speed_bound_of

use std::sync::Arc;

use glam::Vec3;

use super::lanes::Affine32;
use super::{Body, EndOverlap, KnownInside, PairContact, continuous};
use crate::collision::motion::{DPose, Motion};
use crate::geometry::{
    FacePlane, Penetration, mesh_penetration_near, mesh_penetration_near_from, sample_depth,
};

/// Largest gap left between teeth reported as touching (mm).
pub const GAP_TOLERANCE_MM: f32 = 0.01;
/// Largest relative travel (mm, bound on any point's) for which the rest of the step is searched
/// in one window.
const WHOLE_STEP_TRAVEL_MM: f64 = 1.0;
/// Most advancement steps per query.
pub const MAX_STEPS: u32 = 1000;
/// Distance (mm) within which two candidates count as meeting, when the searches list those
/// that meet ([`Candidates::touching`], [`Candidates::meeting_at`]): far above the rounding of
/// the boxes, spheres and planes (f64), so no meeting pair is missed (more are allowed).
const MEETING_MM: f32 = 1e-4;

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

/// The exact query at [`GAP_TOLERANCE_MM`].
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    query_with(a, b, GAP_TOLERANCE_MM)
}

/// The exact query leaving a gap of at most `tolerance` (mm, positive) at the reported contact.
pub fn query_with(a: &Body, b: &Body, tolerance: f32) -> Option<PairContact> {
    let aim = Aim {
        tol: tolerance.max(1e-6) as f64,
        known: None,
        end: false,
    };
    query_at(a, b, aim)
}

/// [`query`] for a simulation's steps: a contact at the start of the step also carries the
/// meshes' overlap at its end ([`PairContact::end_overlap`], which a response asks for; [`query`]
/// leaves it out, as it costs a walk), and the overlap at the start poses may already be
/// `known`: the overlap a contact carried from the end of the step before, used when its poses
/// are the start poses (the same depth and points the search would find, without walking the
/// meshes again), and its samples inside at other nearby poses (the same depth, without a walk);
/// ignored when it was found for other geometries than these bodies'.
pub fn query_knowing(a: &Body, b: &Body, known: Option<&EndOverlap>) -> Option<PairContact> {
    // Only an overlap of these meshes.
    let known = known.filter(|k| k.is_for(&a.shape.geometry, &b.shape.geometry));
    let aim = Aim {
        tol: GAP_TOLERANCE_MM as f64,
        known,
        end: true,
    };
    query_at(a, b, aim)
}

fn query_at(a: &Body, b: &Body, aim: Aim) -> Option<PairContact> {
    // The earliest leaf time bounds the first contact from below; from there the step is searched
    // in windows of growing length, each with only the leaf pairs that meet within it (a slerp and
    // lerp restricted to a sub-interval is the slerp and lerp between its end poses).
    // Short steps (no point moves more than WHOLE_STEP_TRAVEL_MM): the whole step at once,
    // from the earliest leaf time; longer ones in doubling windows from there.
    let whole =
        a.motion.speed_bound(a.shape.max_rho as f64) + b.motion.speed_bound(b.shape.max_rho as f64);
    if whole <= WHOLE_STEP_TRAVEL_MM {
        let swept = continuous::query(a, b, true)?;
        return advance(a, b, &swept, aim);
    }
    let first = continuous::query(a, b, false)?;
    let mut t = first.earliest();
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
            // Only a window that ends with the motion can carry the overlap at its end.
            && let Some(mut c) = advance(&sa, &sb, &swept, Aim { end: aim.end && end >= 1.0, ..aim })
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

/// Candidate triangle pairs (counted with repeats over the leaf pairs) up to which the flat
/// advancement is used; larger sets go through the hierarchies.
const FLAT_PAIRS: usize = 4096;

/// Conservative advancement over the bodies' whole motion, from the earliest meeting leaf time of
/// `swept` (which must list every meeting leaf pair): flat for few candidates, hierarchical for
/// many.
fn advance(a: &Body, b: &Body, swept: &continuous::SweptContact, aim: Aim) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let pairs: usize = swept
        .leaf_times
        .iter()
        .map(|&(i, j, _)| ta.triangles(i as usize).len() * tb.triangles(j as usize).len())
        .sum();
    if pairs <= FLAT_PAIRS {
        flat::advance(a, b, swept, aim)
    } else {
        tree::advance(a, b, swept, aim)
    }
}

/// What the advancement aims at: the gap it may leave (mm), the overlap already known at some
/// poses, and whether a contact at the start carries the overlap at the end (see
/// [`query_knowing`]).
#[derive(Clone, Copy)]
struct Aim<'k> {
    tol: f64,
    known: Option<&'k EndOverlap>,
    end: bool,
}

impl<'k> Aim<'k> {
    /// The known overlap, when it was found at the poses of `frame`.
    fn known_at(&self, frame: &Frame) -> Option<&'k EndOverlap> {
        (self.known).filter(|k| k.poses == [frame.pose_a, frame.pose_b])
    }

    /// The meshes' overlap at the poses of `frame` (depth, and the points as
    /// [`PairContact::points`]) when the known overlap tells it without a walk: found at these
    /// poses, or from the samples it kept ([`rewalk_known`]).
    fn overlap_at(&self, a: &Body, b: &Body, frame: &Frame) -> Option<Overlap> {
        if let Some(k) = self.known_at(frame) {
            return Some((k.depth_mm, k.points));
        }
        let poses = [frame.pose_a, frame.pose_b];
        let floor = floor_of(a, b, poses, self.known);
        rewalk_known(a, b, poses, self.known, floor).map(|p| (p.depth, p.points))
    }
}

/// An overlap of the meshes: its depth (mm) and points (world, as [`PairContact::points`]).
type Overlap = (f32, [Vec3; 2]);

/// What a step's search leads to.
enum Settled {
    /// The contact to report.
    Report(Box<PairContact>),
    /// Nothing moves: no contact.
    Stuck,
    /// Advance: half the tolerance and the plain step.
    Step { h: f64, plain: f64 },
}

/// What decides, after each step's search, whether the advancement stops.
struct Settle<'x, 'y> {
    a: &'x Body<'y>,
    b: &'x Body<'y>,
    swept: &'x continuous::SweptContact,
    aim: Aim<'x>,
    mu: f64,
}

impl Settle<'_, '_> {
    /// The search found the gap `d` between `q` (first tooth's frame) at time `t`, and that no
    /// candidate pair is nearer than `low` (at most d), and for teeth touching maybe their
    /// overlap (depth and points, world): within the tolerance, or at the `last`
    /// step, the contact is reported here (still never after the meshes' contact); otherwise
    /// every pair is at least `low` apart and closes at most μ per unit time, so a plain step of
    /// (low − h)/μ keeps h, half the tolerance (the searches keep `low` above three quarters of d,
    /// so above h). The pairs near the contact, which limit that step, usually separate along
    /// the closest direction much more slowly than μ: the caller extends it as far as every pair
    /// allows (see [`drift::Drift`]).
    fn settle(
        &self,
        t: f64,
        ([d, low], q, overlap): ([f32; 2], [Vec3; 2], Option<Overlap>),
        frame: &Frame,
        ids: [&[u32]; 2],
        last: bool,
    ) -> Settled {
        let q = q.map(|p| frame.pose_a.transform_point(p));
        let d = d as f64;
        if d <= self.aim.tol || last {
            let c = report(self.a, self.b, self.swept, t, d, q, frame, ids, overlap);
            return Settled::Report(Box::new(c));
        }
        if self.mu <= 0.0 {
            return Settled::Stuck;
        }
        let h = 0.5 * self.aim.tol;
        Settled::Step {
            h,
            plain: (low as f64 - h) / self.mu,
        }
    }
}

/// The contact found at time `t`, gap `d` between the closest points `q` (world):
/// for teeth touching or interpenetrating, the depth of the whole meshes near the candidates.
#[allow(clippy::too_many_arguments)]
fn report(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    t: f64,
    d: f64,
    q: [Vec3; 2],
    frame: &Frame,
    [ids_a, ids_b]: [&[u32]; 2],
    // The overlap at these poses when already known (depth and points).
    overlap: Option<Overlap>,
) -> PairContact {
    let [qa, qb] = q;
    let mut contact = PairContact {
        time_of_contact: t as f32,
        points: [qa, qb],
        normal: (qb - qa).try_normalize().unwrap_or(swept.contact.normal),
        depth_mm: -(d as f32),
        leaf_pairs: swept.contact.leaf_pairs.clone(),
        end_overlap: None,
    };
    if d == 0.0 {
        // Touching or interpenetrating (only possible at the start): the candidates already
        // touch, so only the depth is left to find (or the known overlap tells it).
        let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
        let (depth, pa, pb) = match overlap {
            Some((depth, [pa, pb])) => (depth, pa, pb),
            None => {
                mesh_penetration_near(ga.near(ids_a), &frame.pose_a, gb.near(ids_b), &frame.pose_b)
            }
        };
        if depth > 0.0 {
            contact.depth_mm = depth;
            contact.points = [pa, pb];
            if let Some(n) = (pb - pa).try_normalize() {
                contact.normal = -n;
            }
        }
    }
    contact
}

/// A search of the candidate triangle pairs, flat or hierarchical: what the advancement loop
/// ([`advance_over`]) asks of it at each step.
trait Candidates {
    /// Places the second tooth's candidates at time `t` (`frame`).
    fn place(&mut self, t: f64, frame: &Frame);
    /// The least distance between the candidates now (the search may instead stop at the first
    /// pair found within `enough`), measured first along `axis`: the gap of the nearest pair
    /// found, a lower bound of every candidate pair's distance (at most that gap), and the pair's
    /// closest points (first tooth's frame); `None` when there are no candidates.
    fn least(&mut self, axis: Vec3, enough: f32) -> Option<(f32, f32, Vec3, Vec3)>;
    /// How long the pair [`Self::least`] found stays apart along the drift's direction.
    fn nearest_drift(&mut self, drift: &drift::Drift) -> f64;
    /// The longest step, from `plain` (every pair allows it) up to `first`, that every candidate
    /// pair allows: its own plain bound (distance less h, over μ) or its drift along the
    /// direction.
    fn extend(&mut self, drift: &drift::Drift, mu: f64, h: f64, plain: f64, first: f64) -> f64;
    /// After [`Self::least`] found the teeth touching: a part of each tooth's candidates (mesh
    /// triangle numbers) that holds every candidate meeting the other's candidates, from which
    /// the penetration depth is searched; `None` to search from all the candidates.
    fn touching(&mut self) -> Option<[Vec<u32>; 2]> {
        None
    }
    /// With the second tooth placed by `frame`: a part of each tooth's candidates that holds
    /// every candidate meeting the other's candidates there, as [`Self::touching`] does at the
    /// current placement; `None` when the search does not list them (the caller then leaves
    /// the question to whoever asks it).
    fn meeting_at(&mut self, _frame: &Frame) -> Option<[Vec<u32>; 2]> {
        None
    }
}

/// The advancement loop from time `t`, the first search along `axis`: search, stop or step
/// (plainly, then as far as the drift along the closest direction allows), until the contact
/// is reported or the motion ends. `ids` are the candidate triangles of each tooth.
fn advance_over(
    ctx: &Settle,
    mut t: f64,
    mut axis: Vec3,
    ids: [&[u32]; 2],
    search: &mut impl Candidates,
) -> Option<PairContact> {
    let (a, b) = (ctx.a, ctx.b);
    let motions = drift::Relative::new(&a.motion, &b.motion, b.shape.max_rho as f64);
    for round in 0..=MAX_STEPS {
        // Work in a's frame: a's triangles as stored, b's mapped by pose_a⁻¹ ∘ pose_b.
        let frame = relative(&a.motion, &b.motion, t);
        search.place(t, &frame);
        // After the start of the motion the teeth cannot interpenetrate (no leaf pair met
        // before the earliest leaf time, and each step keeps half the tolerance), so any pair
        // within the tolerance is a contact to report. At the start they may already
        // interpenetrate, which only the least distance (0) shows.
        let enough = if t > 0.0 { ctx.aim.tol as f32 } else { -1.0 };
        let (d, low, qa, qb) = search.least(axis, enough)?;
        axis = (qb - qa).normalize_or(axis);
        // Touching: the depth is searched from the candidates that meet, unless the known
        // overlap tells it.
        let overlap = (d == 0.0)
            .then(|| ctx.aim.overlap_at(a, b, &frame))
            .flatten();
        let touching = if d == 0.0 && overlap.is_none() {
            search.touching()
        } else {
            None
        };
        let ids = touching.as_ref().map_or(ids, |[x, y]| [x, y]);
        let found = ([d, low], [qa, qb], overlap);
        let (h, plain) = match ctx.settle(t, found, &frame, ids, round == MAX_STEPS) {
            Settled::Report(mut c) => {
                if t == 0.0 && ctx.aim.end {
                    c.end_overlap = end_overlap(a, b, search, ctx.aim.known);
                }
                return Some(*c);
            }
            Settled::Stuck => return None,
            Settled::Step { h, plain } => (h, plain),
        };
        let mut step = plain;
        if let Some(drift) = motions.drift(t, frame.to_a, axis, &frame.rel, h) {
            let first = search.nearest_drift(&drift).min(1.0 - t).max(plain);
            if first > plain {
                step = search.extend(&drift, ctx.mu, h, plain, first);
            }
        }
        t += step;
        if t >= 1.0 {
            return None;
        }
    }
    None
}

/// For a contact at the start of the motion: the meshes' overlap at its end, walked
/// ([`mesh_penetration_near`]) from the candidates that meet there. That holds every triangle
/// that meets the other mesh at the end: a triangle pair meeting then touches during the motion,
/// so it is a candidate pair (see the module doc). So the depth is the one the walk finds from
/// the whole meshes' meeting triangles, without searching the whole meshes for them. `None` when
/// the search does not list the meeting candidates.
///
/// The deepest sample of an overlap `known` before (the last step's, for a resting contact),
/// placed at the end, reaches a depth the overlap there reaches too: the walk is told it and
/// skips the samples that cannot be deeper (the result is the same). When that overlap kept its
/// samples inside and the teeth moved little since, no walk is needed: only the samples that
/// can still reach that depth are tested ([`crate::geometry::InsideSamples::rewalk`], the same
/// depth), and the candidates that meet need not be listed either.
fn end_overlap(
    a: &Body,
    b: &Body,
    search: &mut impl Candidates,
    known: Option<&EndOverlap>,
) -> Option<EndOverlap> {
    let poses = [a.motion.end, b.motion.end];
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let floor = floor_of(a, b, poses, known);
    let found = match rewalk_known(a, b, poses, known, floor) {
        Some(found) => found,
        None => {
            let [near_a, near_b] = search.meeting_at(&frame_at(poses[0], poses[1]))?;
            mesh_penetration_near_from(
                ga.near(&near_a),
                &poses[0],
                gb.near(&near_b),
                &poses[1],
                floor,
            )
        }
    };
    let side = usize::from(found.on_b);
    let deepest = (found.depth > 0.0).then(|| {
        let sample = found.points[side];
        (side, poses[side].inverse().transform_point(sample))
    });
    let inside = KnownInside {
        geometry: [Arc::clone(ga), Arc::clone(gb)],
        samples: (found.depth > 0.0).then(|| Arc::new(found.inside)),
    };
    Some(EndOverlap {
        poses,
        depth_mm: found.depth,
        points: found.points,
        deepest,
        inside,
    })
}

/// The depth that the deepest sample of the overlap `known` reaches with the teeth at `poses`,
/// less [`FLOOR_SLACK_MM`]: one the overlap there reaches (0 when none is known).
fn floor_of(
    a: &Body,
    b: &Body,
    poses: [crate::geometry::Pose; 2],
    known: Option<&EndOverlap>,
) -> f32 {
    let geometry = [&a.shape.geometry, &b.shape.geometry];
    known
        .and_then(|k| k.deepest)
        .and_then(|(side, local)| {
            let other = geometry[1 - side].mesh_ref();
            sample_depth(local, &poses[side], other, &poses[1 - side])
        })
        .map_or(0.0, |d| d - FLOOR_SLACK_MM)
}

/// The meshes' overlap at `poses`, found from the samples the overlap `known` kept inside
/// ([`crate::geometry::InsideSamples::rewalk`], told `floor`): the walk's depth, without a walk
/// or a list of the candidates that meet. `None` when it kept none, or the teeth moved too far
/// since. (Known overlaps are of these meshes: [`query_knowing`] drops any other.)
fn rewalk_known(
    a: &Body,
    b: &Body,
    poses: [crate::geometry::Pose; 2],
    known: Option<&EndOverlap>,
    floor: f32,
) -> Option<Penetration> {
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let samples = known?.inside.samples.as_ref()?;
    samples.rewalk(ga.mesh_ref(), &poses[0], gb.mesh_ref(), &poses[1], floor)
}

/// What a known deepest sample's depth is lowered by before it bounds a new search from below
/// (mm): its place, mapped back from the world, differs from the sample's by single-precision
/// rounding (about 10⁻⁶ mm at a tooth's size), which this covers many times over.
const FLOOR_SLACK_MM: f32 = 1e-4;

/// The candidates (mesh triangle numbers `ids`) whose `hit` flag is set, in order.
fn marked(hit: &[bool], ids: &[u32]) -> Vec<u32> {
    (hit.iter().zip(ids))
        .filter_map(|(&h, &id)| h.then_some(id))
        .collect()
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
    frame_at(a.at(t as f32), b.at(t as f32))
}

/// Both teeth at the given poses.
fn frame_at(pose_a: crate::geometry::Pose, pose_b: crate::geometry::Pose) -> Frame {
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

mod drift;
mod flat;
mod patch;
mod tree;

#[cfg(test)]
mod tests;
