//! Continuous sphere trees (Redon's conservative test, the paper's Eq. 2), made conservative for
//! rotating teeth.
//!
//! Over a step every sphere centre is replaced by the chord between its start and end positions and
//! its radius inflated by the arc–chord bound of [`Motion::arc_factor`] (times the centre's distance
//! from the local origin), so the inflated sphere moving linearly always contains the real one. For
//! a node pair the relative centre is A + B·t (A = start offset, B = change over the step):
//!
//! 1. **Interval test.** |A + B·[0, 1]|² is bounded below with outward-rounded interval arithmetic;
//!    if the bound exceeds (r₁ + r₂)² the spheres cannot meet during the step.
//! 2. **First time (Eq. 2)**, for every node pair that passes, inner or leaf:
//!    t = (|A|² − R²) / (−A·B + √((A·B)² − |B|²(|A|² − R²))), the conjugate form of the paper's
//!    root, which has no cancellation; overlap at t = 0 gives 0; |B|² = 0, A·B ≥ 0 or a negative
//!    discriminant give no contact (the spheres are apart at t = 0 and never approach). Every
//!    coefficient is bracketed by a forward error bound and the root taken from the bounds that
//!    make it smallest, so for the given A, B and R the time is never after the true one (see
//!    [`first_contact`]); R carries a slack above the rounding of the transformed centres, so the
//!    same holds for the real motion.
//!
//! A node pair's time bounds its descendants' from below, so the search visits pairs earliest first
//! and, for the continuous method, skips pairs that cannot beat the earliest leaf time found. The
//! pair's time of contact is the least leaf time in [0, 1). ([`may_meet`], the interval test plus
//! the exact minimum of the quadratic, serves the broad phase.)
//!
//! [`Motion::arc_factor`]: crate::collision::motion::Motion::arc_factor

use glam::DVec3;

use super::{Body, PairContact};
use crate::{
    collision::motion::{DPose, NodeCache},
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

/// What the contact distance is widened by when sphere centres are computed (in f64) from
/// coordinates up to `scale` mm: far above the rounding of the relative centres A and B.
pub fn rounding_slack(scale: f64) -> f64 {
    1e-13 * scale + 1e-9
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
pub fn swept_leaves(
    a: &Body,
    b: &Body,
    earliest_only: bool,
    mut leaf: impl FnMut(usize, usize, f64),
) {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (a0, a1) = (
        DPose::from_pose(&a.motion.start),
        DPose::from_pose(&a.motion.end),
    );
    let (b0, b1) = (
        DPose::from_pose(&b.motion.start),
        DPose::from_pose(&b.motion.end),
    );
    let (ka, kb) = (a.motion.arc_factor(), b.motion.arc_factor());
    // Slack for the rounding of transformed centres: far above f64's error at these coordinates.
    let scale = [a.motion.start, a.motion.end, b.motion.start, b.motion.end]
        .iter()
        .map(|p| p.translation.abs().max_element() as f64)
        .fold(0.0, f64::max)
        + a.shape.max_rho as f64
        + b.shape.max_rho as f64
        + 100.0;
    let slack = rounding_slack(scale);
    CACHE.with_borrow_mut(|(cache_a, cache_b)| {
        cache_a.begin(ta.spheres.len());
        cache_b.begin(tb.spheres.len());
        descend(
            DescentInput {
                a,
                b,
                poses: [a0, a1, b0, b1],
                k: [ka, kb],
                slack,
                earliest_only,
            },
            cache_a,
            cache_b,
            &mut leaf,
        );
    });
}

thread_local! {
    static CACHE: std::cell::RefCell<(EndCache, EndCache)> =
        const { std::cell::RefCell::new((NodeCache::new(), NodeCache::new())) };
}

/// Each node's start and end centre (world), per query.
type EndCache = NodeCache<[DVec3; 2]>;

struct DescentInput<'q, 'a> {
    a: &'q Body<'a>,
    b: &'q Body<'a>,
    poses: [DPose; 4],
    k: [f64; 2],
    slack: f64,
    earliest_only: bool,
}

fn descend(
    q: DescentInput,
    cache_a: &mut EndCache,
    cache_b: &mut EndCache,
    leaf: &mut impl FnMut(usize, usize, f64),
) {
    let (ta, tb) = (&*q.a.shape.tree, &*q.b.shape.tree);
    let [a0, a1, b0, b1] = q.poses;
    let [ka, kb] = q.k;
    let (slack, earliest_only) = (q.slack, q.earliest_only);
    let mut best = f64::INFINITY;
    // The node pair's first time (inflated spheres, linear centres), or None if they cannot meet
    // during the step; it bounds the times of every pair of their descendants from below.
    let mut time = |i: usize, j: usize| {
        let (sa, sb) = (&ta.spheres[i], &tb.spheres[j]);
        let [ca0, ca1] = cache_a.get(i, || [a0.apply(sa.centre), a1.apply(sa.centre)]);
        let [cb0, cb1] = cache_b.get(j, || [b0.apply(sb.centre), b1.apply(sb.centre)]);
        let start = ca0 - cb0;
        let change = (ca1 - cb1) - start;
        let r = sa.radius as f64
            + sb.radius as f64
            + ka * ta.rho[i] as f64
            + kb * tb.rho[j] as f64
            + slack;
        // The interval test, then Eq. 2 itself (which already answers "not in [0, 1)").
        if !interval_may_meet(start, change, r) {
            return None;
        }
        first_contact(start, change, r)
    };
    // Depth first, the children of a pair visited earliest first, so that with `earliest_only`
    // a good bound is found early and later subtrees are cut.
    let mut stack: Vec<(u32, u32, f64)> = Vec::with_capacity(64);
    if let Some(t) = time(0, 0) {
        stack.push((0, 0, t));
    }
    while let Some((i, j, t)) = stack.pop() {
        if earliest_only && t >= best {
            continue;
        }
        let (i, j) = (i as usize, j as usize);
        let (la, lb) = (ta.is_leaf(i), tb.is_leaf(j));
        if la && lb {
            best = best.min(t);
            leaf(i, j, t);
            continue;
        }
        let first = stack.len();
        if !la && (lb || ta.spheres[i].radius >= tb.spheres[j].radius) {
            for c in ta.children(i) {
                if let Some(t) = time(c, j) {
                    stack.push((c as u32, j as u32, t));
                }
            }
        } else {
            for c in tb.children(j) {
                if let Some(t) = time(i, c) {
                    stack.push((i as u32, c as u32, t));
                }
            }
        }
        if earliest_only {
            stack[first..].sort_unstable_by(|x, y| y.2.total_cmp(&x.2));
        }
    }
}

/// The continuous query; with `all_pairs` every meeting leaf pair is listed (the exact stage needs
/// them), else only those found on the way to the earliest time.
pub fn query(a: &Body, b: &Body, all_pairs: bool) -> Option<SweptContact> {
    let mut leaf_times = Vec::new();
    swept_leaves(a, b, !all_pairs, |i, j, t| {
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
