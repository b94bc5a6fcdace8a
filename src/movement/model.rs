//! The quasi-static motion model: from a load and a wire model to one step's motion.
//!
//! | wire | load | motion (paper, section 3) |
//! |---|---|---|
//! | rectangular | force | bodily translation along the force (x, y and z) |
//! | rectangular | torque | rotation about the crown centre |
//! | round | force | tipping: rotation about the centre of tipping (1/3 of the root length from the apex, [`crate::teeth::CentreParameters`]) by the force's moment about it; the component along the long axis still extrudes or intrudes |
//! | round | torque | added to the tipping moment |
//!
//! Speeds follow [`MovementSettings`]: mobility × (magnitude − threshold) along the load, zero
//! below the threshold. Constraints keep only the allowed components: translations along the arch
//! (mesial–distal), buccal–lingual and vertical (occlusal) directions of the [`ArchFrame`],
//! rotations about the tooth's own mesial, buccal and occlusal axes. The along-arch part of a
//! translation slides the tooth along its arch curve ([`slide`]), so translation into an extraction
//! space follows the arch.

use glam::{Quat, Vec3};

use super::{
    arch_path::{ArchFrame, slide},
    settings::MovementSettings,
};
use crate::{
    geometry::Pose,
    teeth::{Fdi, WireModel, arch::ArchCurve, case::Freedoms},
};

/// Allowed movements of a tooth (from the case's constraints).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ToothConstraint {
    /// Allowed translations: along the arch, buccal–lingual, vertical.
    pub translate: Freedoms,
    /// Allowed rotations about the tooth's mesial, buccal and occlusal axes.
    pub rotate: Freedoms,
    /// Largest crown-centre travel from the initial pose (mm).
    pub max_translation_mm: Option<f32>,
    /// Largest rotation from the initial pose (radians).
    pub max_rotation_rad: Option<f32>,
}

/// Linear and angular velocity of a tooth (mm/s, rad/s) and the point it rotates about (world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Linear velocity (mm/s).
    pub velocity: Vec3,
    /// Angular velocity (rad/s).
    pub angular: Vec3,
    /// Centre of rotation (world).
    pub pivot: Vec3,
}

impl Drive {
    /// True when nothing moves.
    pub fn is_zero(&self) -> bool {
        self.velocity == Vec3::ZERO && self.angular == Vec3::ZERO
    }
}

/// `v` shortened by `threshold` (zero when shorter).
pub fn excess(v: Vec3, threshold: f32) -> Vec3 {
    let m = v.length();
    if !m.is_finite() || m <= threshold || m == 0.0 {
        Vec3::ZERO
    } else {
        v * ((m - threshold) / m)
    }
}

/// The velocity a load gives a tooth at `pose` under `wire` (before constraints).
#[cfg(test)]
pub fn drive(
    force: Vec3,
    torque: Vec3,
    wire: WireModel,
    pose: &Pose,
    frame: &crate::teeth::ToothFrame,
    settings: &MovementSettings,
) -> Drive {
    drive_at(
        force,
        torque,
        wire,
        Centres {
            crown: pose.transform_point(frame.crown_centre),
            tipping: pose.transform_point(frame.centre_of_tipping),
            long_axis: pose.transform_vector(frame.long_axis),
        },
        settings,
    )
}

/// Where a load acts on a tooth or a block of teeth (world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Centres {
    /// Crown centre (the bracket, where forces act; the centre of rotation under torque).
    pub crown: Vec3,
    /// Centre of tipping (round wire).
    pub tipping: Vec3,
    /// Long axis, apex to crown.
    pub long_axis: Vec3,
}

/// [`drive`] for given centres (a single tooth's or a group's).
pub fn drive_at(
    force: Vec3,
    torque: Vec3,
    wire: WireModel,
    c: Centres,
    settings: &MovementSettings,
) -> Drive {
    match wire {
        WireModel::Rectangular => Drive {
            velocity: excess(force, settings.force_threshold_n) * settings.translational_mobility,
            angular: excess(torque, settings.torque_threshold_nmm) * settings.rotational_mobility,
            pivot: c.crown,
        },
        WireModel::Round => {
            let axis = c.long_axis.normalize_or(Vec3::Y);
            let axial = axis * force.dot(axis);
            let moment = (c.crown - c.tipping).cross(force - axial) + torque;
            Drive {
                velocity: excess(axial, settings.force_threshold_n)
                    * settings.translational_mobility,
                angular: excess(moment, settings.torque_threshold_nmm)
                    * settings.rotational_mobility,
                pivot: c.tipping,
            }
        }
    }
}

fn keep(v: Vec3, axes: [Vec3; 3], allowed: Freedoms) -> Vec3 {
    let flags = [allowed.mesial, allowed.buccal, allowed.occlusal];
    axes.iter()
        .zip(flags)
        .filter(|(_, on)| *on)
        .map(|(a, _)| *a * v.dot(*a))
        .sum()
}

/// The drive with only the constraint's allowed components.
pub fn constrain(d: Drive, c: &ToothConstraint, arch: &ArchFrame, pose: &Pose, fdi: Fdi) -> Drive {
    let anatomical = [
        pose.transform_vector(Vec3::X * fdi.local_x_mesial_sign()),
        pose.transform_vector(Vec3::Z),
        pose.transform_vector(Vec3::Y),
    ];
    Drive {
        velocity: keep(
            d.velocity,
            [arch.tangent, arch.buccal, arch.up],
            c.translate,
        ),
        angular: keep(d.angular, anatomical, c.rotate),
        pivot: d.pivot,
    }
}

/// One step of rigid motion: a turn about a pivot, a slide along the arch, a further translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepMove {
    /// Rotation (world).
    pub turn: Quat,
    /// Centre of the rotation (world).
    pub pivot: Vec3,
    /// Arc length slid along the curve (mm).
    pub along: f32,
    /// Translation after the slide (mm).
    pub across: Vec3,
}

impl StepMove {
    /// The step of a drive over `dt`, scaled by `fraction`, split along the arch frame.
    pub fn of(d: &Drive, arch: &ArchFrame, dt: f32, fraction: f32) -> Self {
        let h = dt * fraction;
        let step = d.velocity * h;
        let along = step.dot(arch.tangent);
        Self {
            turn: Quat::from_scaled_axis(d.angular * h),
            pivot: d.pivot,
            along,
            across: step - arch.tangent * along,
        }
    }

    /// The pose of a tooth at `pose` (arc length `s` on `curve`) after the step: the turn about the
    /// pivot, then the slide along the curve, then the translation across it.
    pub fn apply(&self, curve: &ArchCurve, pose: &Pose, s: f32) -> Pose {
        let rotated = Pose::new(
            (self.turn * pose.rotation).normalize(),
            self.pivot + self.turn * (pose.translation - self.pivot),
        );
        let slid = slide(curve, &rotated, s, self.along);
        Pose::new(slid.rotation, slid.translation + self.across)
    }
}

/// One step of a drive applied to a pose on an arch (see [`StepMove`]); `fraction` scales the
/// whole step (for limits).
#[cfg(test)]
pub fn advance(
    curve: &ArchCurve,
    pose: &Pose,
    s: f32,
    d: &Drive,
    arch: &ArchFrame,
    dt: f32,
    fraction: f32,
) -> Pose {
    StepMove::of(d, arch, dt, fraction).apply(curve, pose, s)
}

/// The largest fraction in [0, 1] of a step whose end pose `ok` accepts (bisection, assuming the
/// accepted fractions form an interval from 0); 1 when the whole step is accepted.
pub fn largest_fraction(ok: impl Fn(f32) -> bool) -> f32 {
    if ok(1.0) {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Angle between two rotations (radians, in [0, π]).
pub fn angle_between(a: Quat, b: Quat) -> f32 {
    2.0 * a.dot(b).abs().min(1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{Arch, ToothGeometry, ToothKind, ToothResolution, arch::BetaArch};

    fn tooth() -> ToothGeometry {
        ToothGeometry::procedural(Arch::Lower, ToothKind::Canine, ToothResolution::PAPER)
    }

    #[test]
    fn below_the_threshold_nothing_moves() {
        let g = tooth();
        let s = MovementSettings::default();
        let d = drive(
            Vec3::X * 0.4,
            Vec3::Y * 4.0,
            WireModel::Rectangular,
            &Pose::IDENTITY,
            &g.frame,
            &s,
        );
        assert!(d.is_zero());
        assert_eq!(
            excess(Vec3::new(3.0, 4.0, 0.0), 1.0),
            Vec3::new(2.4, 3.2, 0.0)
        );
        assert_eq!(excess(Vec3::NAN, 1.0), Vec3::ZERO);
    }

    #[test]
    fn wire_models_move_as_the_paper_says() {
        let g = tooth();
        let s = MovementSettings::default();
        let curve = ArchCurve::new(&BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        });
        // A straight stretch of the curve, so the slide is a translation.
        let arc = 60.0;
        let (p, _) = curve.at(arc);
        let frame = crate::movement::arch_path::frame_at(&curve, arc);
        let pose = Pose::from_translation(Vec3::new(p.x, 0.0, p.y));
        let crown = pose.transform_point(g.frame.crown_centre);
        let tip = pose.transform_point(g.frame.centre_of_tipping);
        let run = |force: Vec3, torque: Vec3, wire| {
            let d = drive(force, torque, wire, &pose, &g.frame, &s);
            advance(&curve, &pose, arc, &d, &frame, 1.0, 1.0)
        };
        // Rectangular + force: bodily, no rotation.
        let bodily = run(
            Vec3::new(0.0, 0.0, -1.5),
            Vec3::ZERO,
            WireModel::Rectangular,
        );
        assert!(angle_between(bodily.rotation, pose.rotation) < 1e-5);
        let moved = bodily.transform_point(g.frame.crown_centre) - crown;
        assert!((moved.length() - 0.5).abs() < 1e-3, "{moved}");
        // Rectangular + torque: rotation about the crown centre.
        let turned = run(
            Vec3::ZERO,
            Vec3::new(0.0, 15.0, 0.0),
            WireModel::Rectangular,
        );
        assert!(angle_between(turned.rotation, pose.rotation) > 0.04);
        assert!(turned.transform_point(g.frame.crown_centre).distance(crown) < 1e-4);
        // Round + horizontal force: tipping about the centre of tipping, crown moves with it.
        let tipped = run(Vec3::new(1.5, 0.0, 0.0), Vec3::ZERO, WireModel::Round);
        assert!(angle_between(tipped.rotation, pose.rotation) > 0.01);
        assert!(
            tipped
                .transform_point(g.frame.centre_of_tipping)
                .distance(tip)
                < 1e-4
        );
        let crown_move = tipped.transform_point(g.frame.crown_centre) - crown;
        assert!(crown_move.x > 0.05, "{crown_move}");
        // Round + vertical force: extrusion along the long axis.
        let extruded = run(Vec3::new(0.0, 1.5, 0.0), Vec3::ZERO, WireModel::Round);
        assert!(extruded.translation.y - pose.translation.y > 0.4);
    }

    #[test]
    fn constraints_keep_only_allowed_components() {
        let g = tooth();
        let s = MovementSettings::default();
        let frame = ArchFrame {
            tangent: Vec3::X,
            buccal: Vec3::Z,
            up: Vec3::Y,
        };
        let d = drive(
            Vec3::new(1.5, 1.5, 1.5),
            Vec3::new(20.0, 20.0, 20.0),
            WireModel::Rectangular,
            &Pose::IDENTITY,
            &g.frame,
            &s,
        );
        let only_mesial = ToothConstraint {
            translate: Freedoms {
                mesial: true,
                buccal: false,
                occlusal: false,
            },
            rotate: Freedoms {
                mesial: false,
                buccal: false,
                occlusal: false,
            },
            ..Default::default()
        };
        let c = constrain(
            d,
            &only_mesial,
            &frame,
            &Pose::IDENTITY,
            Fdi::new(33).unwrap(),
        );
        assert_eq!(c.angular, Vec3::ZERO);
        assert!(c.velocity.x > 0.0 && c.velocity.y == 0.0 && c.velocity.z == 0.0);
        assert!((largest_fraction(|f| f <= 0.3) - 0.3).abs() < 1e-6);
        assert_eq!(largest_fraction(|_| true), 1.0);
    }
}
