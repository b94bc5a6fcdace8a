//! The paper's bounding circles (Eq. 1): two teeth collide when |c1 − c2| ≤ r1 + r2 in the x–z
//! plane, tested at the end pose.

use glam::Vec3;

use super::{Body, PairContact};

/// Eq. 1 at the end pose.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    let (ca, cb) = (
        a.circle.centre_at(&a.motion.end),
        b.circle.centre_at(&b.motion.end),
    );
    let d = ca.distance(cb);
    let r = a.circle.radius + b.circle.radius;
    if d > r {
        return None;
    }
    let dir = (cb - ca).try_normalize().unwrap_or(glam::Vec2::X);
    let y = 0.5 * (a.motion.end.translation.y + b.motion.end.translation.y);
    let pa = ca + dir * a.circle.radius;
    let pb = cb - dir * b.circle.radius;
    Some(PairContact {
        time_of_contact: 1.0,
        points: [Vec3::new(pa.x, y, pa.y), Vec3::new(pb.x, y, pb.y)],
        normal: Vec3::new(dir.x, 0.0, dir.y),
        depth_mm: r - d,
        leaf_pairs: Vec::new(),
        end_overlap: None,
    })
}
