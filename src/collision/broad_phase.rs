//! Broad phase: the pairs worth a narrow-phase test.
//!
//! Each tooth is paired with its neighbours along its arch (extracted teeth skipped, so the teeth on
//! both sides of an extraction space are neighbours) and with every tooth of the opposing arch; a
//! pair is kept only if at least one of the two moves, their swept world boxes overlap, and their
//! root spheres, swept over the step (with the rotation bound of the continuous method), can meet. Conservative: a pair that can
//! touch during the step is never dropped... except pairs of non-neighbours in the same arch, which
//! the arch order rules out (teeth do not pass each other along the arch).

use crate::{
    collision::{motion::Motion, narrow_phase::continuous::may_meet},
    geometry::{Aabb, Sphere},
    teeth::{Arch, Fdi},
};

/// One tooth as the broad phase sees it.
#[derive(Clone, Copy, Debug)]
pub struct BroadItem {
    /// FDI number.
    pub fdi: Fdi,
    /// Root sphere of its tree (local frame).
    pub root: Sphere,
    /// Bounding box of its mesh (local frame).
    pub local_box: Aabb,
    /// Motion over the step.
    pub motion: Motion,
}

impl BroadItem {
    /// A world box holding the tooth throughout the step: the union of the start and end boxes of
    /// the local box (chord positions of its corners lie between them), grown by the arc–chord bound
    /// of the farthest corner.
    pub fn swept_box(&self) -> Aabb {
        let b = &self.local_box;
        let boxed = |p: &crate::geometry::Pose| {
            b.transformed(&glam::Mat3::from_quat(p.rotation), p.translation)
        };
        let u = boxed(&self.motion.start).union(boxed(&self.motion.end));
        let far = b.min.abs().max(b.max.abs()).length() as f64;
        let grow = (self.motion.arc_factor() * far) as f32 + 1e-4 * (1.0 + far as f32);
        Aabb {
            min: u.min - glam::Vec3::splat(grow),
            max: u.max + glam::Vec3::splat(grow),
        }
    }
}

fn boxes_overlap(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Position along the arch from the patient's right distal end to the left distal end.
fn arch_position(fdi: Fdi) -> i32 {
    let q = fdi.number() / 10;
    let p = (fdi.number() % 10) as i32;
    match q {
        1 | 4 => -p,
        _ => p,
    }
}

/// Whether two items' root spheres can meet during the step.
pub fn swept_roots_meet(a: &BroadItem, b: &BroadItem) -> bool {
    use crate::collision::motion::DPose;
    let (a0, a1) = (
        DPose::from_pose(&a.motion.start),
        DPose::from_pose(&a.motion.end),
    );
    let (b0, b1) = (
        DPose::from_pose(&b.motion.start),
        DPose::from_pose(&b.motion.end),
    );
    let start = a0.apply(a.root.centre) - b0.apply(b.root.centre);
    let end = a1.apply(a.root.centre) - b1.apply(b.root.centre);
    let r = a.root.radius as f64
        + b.root.radius as f64
        + a.motion.arc_factor() * a.root.centre.length() as f64
        + b.motion.arc_factor() * b.root.centre.length() as f64
        + 1e-6;
    may_meet(start, end - start, r)
}

/// Candidate pairs (indices into `items`, lower index first, sorted). Nothing moves: no pairs.
pub fn candidate_pairs(items: &[BroadItem], out: &mut Vec<(usize, usize)>) {
    out.clear();
    if items.iter().all(|i| i.motion.is_still()) {
        return;
    }
    for arch in [Arch::Upper, Arch::Lower] {
        let mut order: Vec<usize> = (0..items.len())
            .filter(|&i| items[i].fdi.arch() == arch)
            .collect();
        order.sort_by_key(|&i| arch_position(items[i].fdi));
        for w in order.windows(2) {
            out.push((w[0].min(w[1]), w[0].max(w[1])));
        }
    }
    for i in 0..items.len() {
        for j in i + 1..items.len() {
            if items[i].fdi.arch() != items[j].fdi.arch() {
                out.push((i, j));
            }
        }
    }
    let boxes: Vec<Aabb> = items.iter().map(BroadItem::swept_box).collect();
    out.retain(|&(i, j)| {
        !(items[i].motion.is_still() && items[j].motion.is_still())
            && boxes_overlap(&boxes[i], &boxes[j])
            && swept_roots_meet(&items[i], &items[j])
    });
    out.sort_unstable();
    out.dedup();
}
