//! Discrete sphere trees: simultaneous descent of both trees at the end pose, collecting every
//! overlapping leaf pair. Conservative at that pose: surfaces that touch lie in overlapping leaves
//! (the coverage invariant), and node tests are in f64 with a relative slack of 10⁻¹².

use glam::DVec3;

use super::{Body, PairContact};
use crate::collision::{
    motion::{DPose, NodeCache},
    shape::CompactTree,
};

/// Calls `leaf(i, j, ca, cb)` for every overlapping leaf pair of the two trees at the given poses.
pub fn overlapping_leaves(
    ta: &CompactTree,
    pa: &DPose,
    tb: &CompactTree,
    pb: &DPose,
    mut leaf: impl FnMut(usize, usize, DVec3, DVec3),
) {
    CACHE.with_borrow_mut(|(cache_a, cache_b)| {
        cache_a.begin(ta.spheres.len());
        cache_b.begin(tb.spheres.len());
        descend(ta, pa, tb, pb, cache_a, cache_b, &mut leaf);
    });
}

thread_local! {
    static CACHE: std::cell::RefCell<(NodeCache<DVec3>, NodeCache<DVec3>)> =
        const { std::cell::RefCell::new((NodeCache::new(), NodeCache::new())) };
}

fn descend(
    ta: &CompactTree,
    pa: &DPose,
    tb: &CompactTree,
    pb: &DPose,
    cache_a: &mut NodeCache<DVec3>,
    cache_b: &mut NodeCache<DVec3>,
    leaf: &mut impl FnMut(usize, usize, DVec3, DVec3),
) {
    let mut stack: Vec<(u32, u32)> = Vec::with_capacity(64);
    stack.push((0, 0));
    while let Some((i, j)) = stack.pop() {
        let (i, j) = (i as usize, j as usize);
        let (sa, sb) = (&ta.spheres[i], &tb.spheres[j]);
        let ca = cache_a.get(i, || pa.apply(sa.centre));
        let cb = cache_b.get(j, || pb.apply(sb.centre));
        let r = (sa.radius as f64 + sb.radius as f64) * (1.0 + 1e-12) + 1e-12;
        if ca.distance_squared(cb) > r * r {
            continue;
        }
        let (la, lb) = (ta.is_leaf(i), tb.is_leaf(j));
        if la && lb {
            leaf(i, j, ca, cb);
        } else if !la && (lb || sa.radius >= sb.radius) {
            stack.extend(ta.children(i).map(|c| (c as u32, j as u32)));
        } else {
            stack.extend(tb.children(j).map(|c| (i as u32, c as u32)));
        }
    }
}

/// Overlapping leaves at the end pose; the contact is reported at the deepest leaf pair.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    let (pa, pb) = (
        DPose::from_pose(&a.motion.end),
        DPose::from_pose(&b.motion.end),
    );
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let mut pairs = Vec::new();
    let mut deepest: Option<(f64, DVec3, DVec3, f64, f64)> = None;
    overlapping_leaves(ta, &pa, tb, &pb, |i, j, ca, cb| {
        pairs.push((i as u32, j as u32));
        let (ra, rb) = (ta.spheres[i].radius as f64, tb.spheres[j].radius as f64);
        let depth = ra + rb - ca.distance(cb);
        if deepest.is_none_or(|d| depth > d.0) {
            deepest = Some((depth, ca, cb, ra, rb));
        }
    });
    let (depth, ca, cb, ra, rb) = deepest?;
    let n = (cb - ca).try_normalize().unwrap_or(DVec3::X);
    Some(PairContact {
        time_of_contact: 1.0,
        points: [(ca + n * ra).as_vec3(), (cb - n * rb).as_vec3()],
        normal: n.as_vec3(),
        depth_mm: depth as f32,
        leaf_pairs: pairs,
    })
}
