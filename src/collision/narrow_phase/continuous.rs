//! Continuous sphere trees (Redon's conservative test, the paper's Eq. 2), made conservative for
//! rotating teeth.
//!
//! Over a step every sphere centre is replaced by the chord between its start and end positions and
//! its radius inflated by the arc–chord bound of [`Motion::arc_factor`] (times the centre's distance
//! from the local origin), so the inflated sphere moving linearly always contains the real one. For
//! a node pair the relative centre is A + B·t (A = start offset, B = change over the step):
//!
//! 1. **Interval test.** |A + B·[0, 1]|² is bounded below component by component (each component
//!    of A + B·t lies between its values at t = 0 and t = 1); if the bound exceeds (r₁ + r₂)² the
//!    spheres cannot meet during the step. It runs on eight sibling spheres at once, in f32, with
//!    the contact distance widened by the rounding slack of `super::lanes`.
//! 2. **First time (Eq. 2)**, for every node pair that passes, inner or leaf:
//!    t = (|A|² − R²) / (−A·B + √((A·B)² − |B|²(|A|² − R²))), the conjugate form of the paper's
//!    root, which has no cancellation; overlap at t = 0 gives 0; |B|² = 0, A·B ≥ 0 or a negative
//!    discriminant give no contact (the spheres are apart at t = 0 and never approach). Every
//!    coefficient is bracketed by a forward error bound and the root taken from the bounds that
//!    make it smallest, so for the given A, B and R the time is never after the true one (see
//!    [`first_contact`]); R carries the f32 slack of the mapped centres, so the same holds for the
//!    real motion.
//!
//! 3. **Descent.** A pair of inner nodes with up to eight children each is split on both sides at
//!    once: the children of each side whose swept spheres meet the other node, then all pairs of
//!    those (an 8 × 8 block of interval tests, `Lanes::swept_block`), and Eq. 2 for the pairs
//!    that pass. Dropping children that miss the other node is safe: where the surfaces touch at
//!    time t, the contact point lies in a leaf of each tree and, by the coverage invariant, in
//!    every ancestor of either at time t, so all those ancestors' swept spheres meet. Other pairs
//!    (a leaf against an inner node, wider branching) split the larger sphere.
//!
//! A node pair's time bounds its descendants' from below, so the search visits pairs earliest first
//! and, for the continuous method, skips pairs that cannot beat the earliest leaf time found. The
//! pair's time of contact is the least leaf time in [0, 1). ([`may_meet`], the interval test plus
//! the exact minimum of the quadratic in f64, serves the broad phase; [`interval_may_meet`] is its
//! outward-rounded f64 interval test.)
//!
//! [`Motion::arc_factor`]: crate::collision::motion::Motion::arc_factor

use glam::{DVec3, Vec3};

use super::{
    Body, PairContact,
    lanes::{self, Affine32, LaneTask, Lanes, SweptChunk, bits, f32_slack},
};
use crate::{
    collision::{
        motion::{DPose, NodeCache},
        shape::{Chunk, CompactTree},
    },
    geometry::interval::Interval,
};

/// A continuous result: the contact at the earliest time, and every leaf pair whose swept spheres
/// meet during the step with its time.
#[derive(Clone, Debug)]
pub struct SweptContact {
    /// Contact at the earliest leaf time.
    pub contact: PairContact,
    /// (leaf of a, leaf of b, first time) for every meeting leaf pair.
    pub leaf_times: Vec<(u32, u32, f64)>,
}

impl SweptContact {
    /// The earliest time any leaf pair meets (infinite when none is listed): no contact of the
    /// meshes can happen before it.
    pub fn earliest(&self) -> f64 {
        (self.leaf_times.iter())
            .map(|x| x.2)
            .fold(f64::INFINITY, f64::min)
    }
}

/// The interval test alone: false only when |A + B·t|² provably exceeds r² on all of [0, 1].
#[inline]
pub fn interval_may_meet(a: DVec3, b: DVec3, r: f64) -> bool {
    // Each component of A + B·t over t ∈ [0, 1] spans [A, A + B] (linear), the end rounded outward.
    let mut lo = Interval::point(0.0);
    for k in 0..3 {
        let end = Interval::point(a[k]).add(Interval::point(b[k]));
        let x = Interval::new(a[k].min(end.lo), a[k].max(end.hi));
        lo = lo.add(x.sqr());
    }
    lo.lo <= Interval::point(r).sqr().hi
}

/// False only when the relative centre A + B·t stays farther than `r` for every t in [0, 1]: the
/// interval test, then the exact minimum of the quadratic.
#[inline]
pub fn may_meet(a: DVec3, b: DVec3, r: f64) -> bool {
    if !interval_may_meet(a, b, r) {
        return false;
    }
    let rr = Interval::point(r).sqr().hi;
    let bb = b.length_squared();
    let t = if bb > 0.0 {
        (-a.dot(b) / bb).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let m = (a + b * t).length_squared();
    m - 1e-12 * (a.length_squared() + bb) - 1e-300 <= rr
}

/// First time in [0, 1) at which spheres with relative centre A + B·t come within `r`, rounded
/// down; None if they do not during the step.
///
/// Guarantee, for finite inputs below 10¹⁵⁰: if |A + B·t| ≤ r for some t in [0, 1), the result is
/// Some(t') with t' ≤ the first such t (exactly, not only up to rounding). Each coefficient —
/// c = |A|² − r², A·B, |B|² and the discriminant (A·B)² − |B|²·c — is computed in f64 with a
/// forward error bound (8 unit roundoffs of the sum of the magnitudes it adds, well above the
/// γ₃ of a three-term dot product, plus a little for underflow), which brackets the true value;
/// the root c / (−A·B + √disc), which grows with c and shrinks with −A·B and disc, is evaluated
/// from the bounds that make it smallest and rounded down. A result may be a little early, or
/// Some when the spheres pass within a few ulps of touching (conservative).
#[inline]
pub fn first_contact(a: DVec3, b: DVec3, r: f64) -> Option<f64> {
    // 8 unit roundoffs, and an absolute term far above the error of an underflowing product.
    const K: f64 = 8.0 * f64::EPSILON / 2.0;
    const TINY: f64 = 8.0 * f64::MIN_POSITIVE;
    let aa = a.length_squared();
    let rr = r * r;
    let c_lo = (aa - rr) - (K * (aa + rr) + TINY);
    if c_lo <= 0.0 {
        return Some(0.0);
    }
    let ab = a.dot(b);
    let e_ab = K * ((a.x * b.x).abs() + (a.y * b.y).abs() + (a.z * b.z).abs()) + TINY;
    let ab_lo = ab - e_ab;
    if ab_lo >= 0.0 {
        // Not approaching: |A + B·t|² ≥ c > 0 for all t ≥ 0.
        return None;
    }
    let ab_max = (-ab_lo).max((ab + e_ab).abs());
    let bb_lo = (b.length_squared() * (1.0 - K) - TINY).max(0.0);
    let square = ab_max * ab_max;
    let product = bb_lo * c_lo;
    let disc_hi = (square - product) + (K * (square + product) + TINY);
    if disc_hi < 0.0 {
        return None;
    }
    let denominator = ((-ab_lo) + disc_hi.sqrt()) * (1.0 + K);
    let t = (c_lo / denominator) * (1.0 - K);
    (t < 1.0).then_some(t.max(0.0))
}

/// Calls `leaf(i, j, t)` for every leaf pair whose swept (inflated) spheres meet during the step;
/// with `earliest_only`, node pairs that cannot meet before the earliest leaf time found so far are
/// skipped (the earliest time is still exact; later pairs may be left out).
///
/// Centres are mapped in f32 relative to the first tooth's start position, a group of siblings at
/// a time and once per query (`super::lanes`); the interval test runs on whole groups, and the
/// time (Eq. 2, in f64) only for the lanes that pass it. The contact distance carries the f32
/// slack of [`f32_slack`], so the time stays conservative for the real motion.
pub fn swept_leaves(
    a: &Body,
    b: &Body,
    earliest_only: bool,
    mut leaf: impl FnMut(usize, usize, f64),
) {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    if ta.is_empty() || tb.is_empty() {
        return;
    }
    let origin = a.motion.start.translation.as_dvec3();
    let map = |p: &crate::geometry::Pose| {
        let d = DPose::from_pose(p);
        Affine32::new(d.rotation, d.translation - origin)
    };
    let maps = [
        map(&a.motion.start),
        map(&a.motion.end),
        map(&b.motion.start),
        map(&b.motion.end),
    ];
    // Arc–chord factors rounded up to f32.
    let up = |k: f64| (k as f32).next_up() * super::lanes::GROW;
    let k = [up(a.motion.arc_factor()), up(b.motion.arc_factor())];
    let reach = maps.iter().map(Affine32::reach).fold(0.0, f32::max);
    let slack = f32_slack(reach + ta.max_rho + tb.max_rho);
    CACHE.with_borrow_mut(|scratch| {
        let (cache_a, cache_b, stack) = scratch;
        cache_a.begin(ta.chunks.len());
        cache_b.begin(tb.chunks.len());
        stack.clear();
        lanes::run(Descent {
            ta,
            tb,
            maps,
            k,
            slack,
            earliest_only,
            cache_a,
            cache_b,
            stack,
            leaf: &mut leaf,
        });
    });
}

/// A node pair on the descent stack: nodes, first time, and each node's start and end centre
/// and inflated radius.
#[derive(Clone, Copy)]
struct Item {
    i: u32,
    j: u32,
    t: f64,
    a: (Vec3, Vec3, f32),
    b: (Vec3, Vec3, f32),
}

type Scratch = (NodeCache<SweptChunk>, NodeCache<SweptChunk>, Vec<Item>);

thread_local! {
    static CACHE: std::cell::RefCell<Scratch> =
        const { std::cell::RefCell::new((NodeCache::new(), NodeCache::new(), Vec::new())) };
}

/// One query's descent.
struct Descent<'q, F> {
    ta: &'q CompactTree,
    tb: &'q CompactTree,
    /// Start and end maps of a, then of b.
    maps: [Affine32; 4],
    /// Arc–chord factors of a and b.
    k: [f32; 2],
    slack: f32,
    earliest_only: bool,
    cache_a: &'q mut NodeCache<SweptChunk>,
    cache_b: &'q mut NodeCache<SweptChunk>,
    stack: &'q mut Vec<Item>,
    leaf: &'q mut F,
}

/// The first time (Eq. 2) of a node pair that passed the interval test, from f32 centres: the
/// contact distance carries the slack and the growth of `super::lanes`, so the time is not
/// after the real one.
#[inline]
fn pair_time(a: (Vec3, Vec3, f32), b: (Vec3, Vec3, f32), slack: f32) -> Option<f64> {
    let start = a.0.as_dvec3() - b.0.as_dvec3();
    let change = (a.1.as_dvec3() - b.1.as_dvec3()) - start;
    let r = (a.2 as f64 + b.2 as f64 + slack as f64) * super::lanes::GROW as f64;
    first_contact(start, change, r)
}

/// Calls `push(node, lane, time)` for each lane of a chunk whose swept sphere meets `other`'s
/// during the step, with the pair's first time. (The time is symmetric in the two spheres.)
#[inline(always)]
fn meeting_lanes(
    lanes: impl Lanes,
    ch: &Chunk,
    sw: &SweptChunk,
    other: (Vec3, Vec3, f32),
    slack: f32,
    mut push: impl FnMut(u32, (Vec3, Vec3, f32), f64),
) {
    for l in bits(lanes.swept_mask(sw, other.0, other.1, other.2, slack, ch.used())) {
        let lane = sw.lane(l);
        if let Some(t) = pair_time(lane, other, slack) {
            push(ch.node[l], lane, t);
        }
    }
}

impl<F: FnMut(usize, usize, f64)> LaneTask for Descent<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) {
        let Descent {
            ta,
            tb,
            maps: [a0, a1, b0, b1],
            k: [ka, kb],
            slack,
            earliest_only,
            cache_a,
            cache_b,
            stack,
            leaf,
        } = self;
        let mut best = f64::INFINITY;
        let root_a = cache_a.get(0, || SweptChunk::new(&ta.chunks[0], &a0, &a1, ka));
        let root_b = cache_b.get(0, || SweptChunk::new(&tb.chunks[0], &b0, &b1, kb));
        let (ra, rb) = (root_a.lane(0), root_b.lane(0));
        if lanes.swept_mask(&root_a, rb.0, rb.1, rb.2, slack, 1) != 0
            && let Some(t) = pair_time(ra, rb, slack)
        {
            stack.push(Item {
                i: 0,
                j: 0,
                t,
                a: ra,
                b: rb,
            });
        }
        // Depth first, the children of a pair visited earliest first, so that with
        // `earliest_only` a good bound is found early and later subtrees are cut.
        while let Some(it) = stack.pop() {
            if earliest_only && it.t >= best {
                continue;
            }
            let (i, j) = (it.i as usize, it.j as usize);
            let (la, lb) = (ta.is_leaf(i), tb.is_leaf(j));
            if la && lb {
                best = best.min(it.t);
                leaf(i, j, it.t);
                continue;
            }
            let first = stack.len();
            let (rca, rcb) = (ta.child_chunks[i].clone(), tb.child_chunks[j].clone());
            if !la && !lb && rca.len() == 1 && rcb.len() == 1 {
                // Both inner with up to eight children each: all pairs of children at once,
                // keeping children of each side that meet the other node (see the module doc).
                let (ca, cb) = (
                    &ta.chunks[rca.start as usize],
                    &tb.chunks[rcb.start as usize],
                );
                let sa = cache_a.get_ref(rca.start as usize, || SweptChunk::new(ca, &a0, &a1, ka));
                let sb = cache_b.get_ref(rcb.start as usize, || SweptChunk::new(cb, &b0, &b1, kb));
                let ma = lanes.swept_mask(sa, it.b.0, it.b.1, it.b.2, slack, ca.used());
                let mb = lanes.swept_mask(sb, it.a.0, it.a.1, it.a.2, slack, cb.used());
                let block = lanes.swept_block(sa, sb, slack, mb);
                for x in bits(block.any & ma) {
                    let a = sa.lane(x);
                    for y in bits(block.rows[x]) {
                        let b = sb.lane(y);
                        if let Some(t) = pair_time(a, b, slack) {
                            stack.push(Item {
                                i: ca.node[x],
                                j: cb.node[y],
                                t,
                                a,
                                b,
                            });
                        }
                    }
                }
            } else if !la && (lb || ta.spheres[i].radius >= tb.spheres[j].radius) {
                for c in rca {
                    let ch = &ta.chunks[c as usize];
                    let sw = cache_a.get_ref(c as usize, || SweptChunk::new(ch, &a0, &a1, ka));
                    meeting_lanes(lanes, ch, sw, it.b, slack, |i, a, t| {
                        stack.push(Item { i, t, a, ..it })
                    });
                }
            } else {
                for c in rcb {
                    let ch = &tb.chunks[c as usize];
                    let sw = cache_b.get_ref(c as usize, || SweptChunk::new(ch, &b0, &b1, kb));
                    meeting_lanes(lanes, ch, sw, it.a, slack, |j, b, t| {
                        stack.push(Item { j, t, b, ..it })
                    });
                }
            }
            if earliest_only {
                stack[first..].sort_unstable_by(|x, y| y.t.total_cmp(&x.t));
            }
        }
    }
}

/// The continuous query; with `all_pairs` every meeting leaf pair is listed (the exact stage needs
/// them), else only those found on the way to the earliest time.
pub fn query(a: &Body, b: &Body, all_pairs: bool) -> Option<SweptContact> {
    let mut leaf_times = Vec::new();
    swept_leaves(a, b, !all_pairs, |i, j, t| {
        // One allocation for the usual few dozen pairs, none for a query without any.
        if leaf_times.is_empty() {
            leaf_times.reserve(32);
        }
        leaf_times.push((i as u32, j as u32, t))
    });
    let &(i, j, t) = leaf_times
        .iter()
        .min_by(|x, y| x.2.total_cmp(&y.2).then((x.0, x.1).cmp(&(y.0, y.1))))?;
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
    let (pa, pb) = (a.motion.at(t as f32), b.motion.at(t as f32));
    let (ca, cb) = (
        pa.transform_point(sa.centre).as_dvec3(),
        pb.transform_point(sb.centre).as_dvec3(),
    );
    let n = (cb - ca).try_normalize().unwrap_or(DVec3::X);
    let (ra, rb) = (sa.radius as f64, sb.radius as f64);
    Some(SweptContact {
        contact: PairContact {
            time_of_contact: t as f32,
            points: [(ca + n * ra).as_vec3(), (cb - n * rb).as_vec3()],
            normal: n.as_vec3(),
            depth_mm: (ra + rb - ca.distance(cb)) as f32,
            leaf_pairs: leaf_times.iter().map(|&(i, j, _)| (i, j)).collect(),
            end_overlap: None,
        },
        leaf_times,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq2_edge_cases() {
        // Head-on: gap 1 closed at t = 0.5.
        let t = first_contact(DVec3::new(3.0, 0.0, 0.0), DVec3::new(-2.0, 0.0, 0.0), 2.0).unwrap();
        assert!((t - 0.5).abs() < 1e-9 && t <= 0.5);
        // Already overlapping.
        assert_eq!(first_contact(DVec3::X, DVec3::ZERO, 2.0), Some(0.0));
        // No relative motion, apart.
        assert_eq!(
            first_contact(DVec3::new(3.0, 0.0, 0.0), DVec3::ZERO, 2.0),
            None
        );
        // Moving apart.
        assert_eq!(
            first_contact(DVec3::new(3.0, 0.0, 0.0), DVec3::X, 2.0),
            None
        );
        // Passing by (negative discriminant).
        assert_eq!(
            first_contact(DVec3::new(3.0, 5.0, 0.0), DVec3::new(-6.0, 0.0, 0.0), 2.0),
            None
        );
        // Grazing tangency: passes at exactly distance r.
        let t = first_contact(DVec3::new(3.0, 2.0, 0.0), DVec3::new(-6.0, 0.0, 0.0), 2.0);
        assert!(t.is_some_and(|t| (t - 0.5).abs() < 1e-6), "{t:?}");
        // Tunnelling: 100 × the radius in one step is still caught.
        let t = first_contact(
            DVec3::new(50.0, 0.0, 0.0),
            DVec3::new(-100.0, 0.0, 0.0),
            0.5,
        )
        .unwrap();
        assert!((t - 0.495).abs() < 1e-9 && t <= 0.495);
        // Near-cancellation: starting just outside contact, approaching slowly.
        let t = first_contact(
            DVec3::new(1.0 + 1e-9, 0.0, 0.0),
            DVec3::new(-1e-3, 0.0, 0.0),
            1.0,
        )
        .unwrap();
        assert!((0.0..=1e-6 * (1.0 + 1e-6)).contains(&t), "{t}");
        // Touching exactly at the start while moving apart is a contact at t = 0.
        assert_eq!(
            first_contact(DVec3::new(3.0, 4.0, 0.0), DVec3::new(3.0, 4.0, 0.0), 5.0),
            Some(0.0)
        );
        // Contact only after the step.
        assert_eq!(
            first_contact(DVec3::new(5.0, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0), 2.0),
            None
        );
    }

    #[test]
    fn may_meet_is_never_wrong_when_they_do_meet() {
        let cases = [
            (
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(-6.0, 0.0, 0.0),
                1.0,
                true,
            ),
            (
                DVec3::new(3.0, 5.0, 0.0),
                DVec3::new(-6.0, 0.0, 0.0),
                1.0,
                false,
            ),
            (DVec3::new(0.5, 0.0, 0.0), DVec3::ZERO, 1.0, true),
            (
                DVec3::new(1e4, 1e4, 1e4),
                DVec3::new(-1e4, -1e4, -1e4),
                1.0,
                true,
            ),
        ];
        for (a, b, r, meet) in cases {
            assert_eq!(may_meet(a, b, r), meet, "{a} {b} {r}");
        }
    }
}
