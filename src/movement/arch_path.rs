//! Movement along the arch: sliding a tooth along its arch curve (translation into extraction
//! spaces follows the arch, as a bracket slides along the archwire) and the "next tooth" search.

use glam::{Quat, Vec2, Vec3};

use crate::{
    geometry::Pose,
    teeth::{Arch, Fdi, arch::ArchCurve},
};

/// The arch frame at a tooth: unit tangent (direction of increasing arc length, from the patient's
/// right to left), unit buccal normal (horizontal, away from the arch centre) and up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArchFrame {
    /// Tangent (horizontal).
    pub tangent: Vec3,
    /// Buccal (labial) normal (horizontal).
    pub buccal: Vec3,
    /// World up.
    pub up: Vec3,
}

/// A curve in 3D terms.
fn horizontal(v: Vec2) -> Vec3 {
    Vec3::new(v.x, 0.0, v.y)
}

/// The arch frame at arc length `s`.
pub fn frame_at(curve: &ArchCurve, s: f32) -> ArchFrame {
    let (_, t) = curve.at(s);
    let tangent = horizontal(t).normalize_or(Vec3::X);
    ArchFrame {
        tangent,
        buccal: Vec3::new(-tangent.z, 0.0, tangent.x),
        up: Vec3::Y,
    }
}

/// The pose after sliding `ds` along the curve: the tooth is carried by the curve's frame, so its
/// offset from the curve point and its orientation relative to the tangent are kept (its local
/// origin moves from the curve point at `s` to the one at `s + ds`, turning with the tangent).
pub fn slide(curve: &ArchCurve, pose: &Pose, s: f32, ds: f32) -> Pose {
    if ds == 0.0 {
        return *pose;
    }
    let (p0, t0) = curve.at(s);
    let (p1, t1) = curve.at(s + ds);
    let turn = Quat::from_rotation_arc(
        horizontal(t0).normalize_or(Vec3::X),
        horizontal(t1).normalize_or(Vec3::X),
    );
    let c0 = Vec3::new(p0.x, pose.translation.y, p0.y);
    let c1 = Vec3::new(p1.x, pose.translation.y, p1.y);
    Pose::new(
        (turn * pose.rotation).normalize(),
        c1 + turn * (pose.translation - c0),
    )
}

/// Arc length of a tooth's local origin (its cervical centre) on the curve.
pub fn arc_of(curve: &ArchCurve, pose: &Pose) -> f32 {
    curve.project(Vec2::new(pose.translation.x, pose.translation.z))
}

/// The next present tooth from `from` along its arch in the direction of `direction` (its
/// component along the arch tangent `tangent` decides which way): the neighbour in that direction,
/// or past it the nearest present one (`present` says which teeth are in the mouth and not
/// extracted). The walk crosses the midline (from 11 mesially to 21, then on to 22).
pub fn next_present_tooth(
    from: Fdi,
    direction: Vec3,
    tangent: Vec3,
    present: impl Fn(Fdi) -> bool,
) -> Option<Fdi> {
    let along = direction.dot(tangent);
    if along == 0.0 || !along.is_finite() {
        return None;
    }
    let step: i8 = if along > 0.0 { 1 } else { -1 };
    let arch = from.arch();
    let mut index = from.arch_index();
    loop {
        index += step;
        if index == 0 {
            index += step;
        }
        if !(-8..=8).contains(&index) {
            return None;
        }
        let f = fdi_at(arch, index);
        if present(f) {
            return Some(f);
        }
    }
}

/// The tooth at a signed arch index (see [`Fdi::arch_index`]).
fn fdi_at(arch: Arch, index: i8) -> Fdi {
    let quadrant = match (arch, index < 0) {
        (Arch::Upper, true) => 1,
        (Arch::Upper, false) => 2,
        (Arch::Lower, false) => 3,
        (Arch::Lower, true) => 4,
    };
    Fdi::from_parts(quadrant, index.unsigned_abs()).expect("index within 1–8")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::arch::BetaArch;

    fn curve() -> ArchCurve {
        ArchCurve::new(&BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        })
    }

    fn f(n: i64) -> Fdi {
        Fdi::new(n).unwrap()
    }

    #[test]
    fn the_next_tooth_skips_extracted_teeth_and_crosses_the_midline() {
        let t = Vec3::X;
        let all = |_: Fdi| true;
        // Quadrant 1 sits at negative arch indices: +tangent is mesial there.
        assert_eq!(next_present_tooth(f(16), t, t, all), Some(f(15)));
        assert_eq!(next_present_tooth(f(16), -t, t, all), Some(f(17)));
        assert_eq!(next_present_tooth(f(16), t, t, |x| x != f(15)), Some(f(14)));
        assert_eq!(next_present_tooth(f(11), t, t, all), Some(f(21)));
        assert_eq!(next_present_tooth(f(11), t, t, |x| x != f(21)), Some(f(22)));
        assert_eq!(next_present_tooth(f(18), -t, t, all), None);
        assert_eq!(next_present_tooth(f(36), -t, t, all), Some(f(35)));
        assert_eq!(next_present_tooth(f(16), Vec3::Y, t, all), None);
    }

    #[test]
    fn sliding_keeps_the_offset_from_the_curve_and_follows_its_turn() {
        let c = curve();
        let s = -20.0;
        let (p, _) = c.at(s);
        let fr = frame_at(&c, s);
        // A tooth 1 mm buccal of the curve, turned with the tangent.
        let pose = Pose::new(
            Quat::from_rotation_arc(Vec3::X, fr.tangent),
            Vec3::new(p.x, 2.0, p.y) + fr.buccal,
        );
        let moved = slide(&c, &pose, s, 5.0);
        let (p1, _) = c.at(s + 5.0);
        let fr1 = frame_at(&c, s + 5.0);
        let expect = Vec3::new(p1.x, 2.0, p1.y) + fr1.buccal;
        assert!(moved.translation.distance(expect) < 1e-3, "{moved:?}");
        assert!((moved.rotation * Vec3::X).distance(fr1.tangent) < 1e-3);
        assert!((arc_of(&c, &moved) - (s + 5.0)).abs() < 0.05);
        // Sliding back returns to the start.
        let back = slide(&c, &moved, s + 5.0, -5.0);
        assert!(back.translation.distance(pose.translation) < 1e-3);
        assert_eq!(slide(&c, &pose, s, 0.0), pose);
    }
}
