//! Nickel–titanium coil springs hooked between two brackets: a closed coil pulls them together,
//! an open coil pushes them apart, each with the superelastic plateau's nearly constant force
//! over its working range.
//!
//! The force is the plateau force (default [`DEFAULT_FORCE_N`], 150 g, a common nominal
//! size; Maganzini et al., Angle Orthod 2010;80:182–7 measured 147–474 g peaks at 12 mm across
//! 9 mm closed coils) while the coil is activated, falling linearly to zero over the last
//! [`RAMP_MM`] as it comes back to its relaxed length, and zero beyond: a coil never pulls once
//! closed, nor pushes once open. It acts along the straight line between the two slots.

use glam::DVec3;

pub use crate::teeth::case::appliance::CoilKind;

/// The plateau force when a case names none (N).
pub const DEFAULT_FORCE_N: f64 = 1.5;
/// The activation over which the force falls to zero at the relaxed length (mm).
pub const RAMP_MM: f64 = 0.5;

/// The force (N, ≥ 0) of a coil of `kind` with plateau `force` and relaxed length `relaxed`,
/// its ends `length` mm apart.
pub fn force_n(kind: CoilKind, force: f64, relaxed: f64, length: f64) -> f64 {
    let activation = match kind {
        CoilKind::Closed => length - relaxed,
        CoilKind::Open => relaxed - length,
    };
    force * (activation / RAMP_MM).clamp(0.0, 1.0)
}

/// The forces on the two ends `a` and `b` of a coil of `kind` carrying `force` (N).
pub fn end_forces(kind: CoilKind, a: DVec3, b: DVec3, force: f64) -> [DVec3; 2] {
    let d = b - a;
    let len = d.length();
    if len < 1e-9 {
        return [DVec3::ZERO; 2];
    }
    let towards_b = d / len * force;
    match kind {
        CoilKind::Closed => [towards_b, -towards_b],
        CoilKind::Open => [-towards_b, towards_b],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_coil_pulls_its_plateau_until_it_closes_and_an_open_one_pushes() {
        // Activated 3 mm: the plateau, whatever the activation.
        assert_eq!(force_n(CoilKind::Closed, 1.5, 10.0, 13.0), 1.5);
        assert_eq!(force_n(CoilKind::Closed, 1.5, 10.0, 11.0), 1.5);
        // Within the ramp, less; closed, nothing.
        assert!((force_n(CoilKind::Closed, 1.5, 10.0, 10.25) - 0.75).abs() < 1e-12);
        assert_eq!(force_n(CoilKind::Closed, 1.5, 10.0, 9.0), 0.0);
        assert_eq!(force_n(CoilKind::Open, 2.0, 10.0, 8.0), 2.0);
        assert_eq!(force_n(CoilKind::Open, 2.0, 10.0, 11.0), 0.0);
        let a = DVec3::ZERO;
        let b = DVec3::X * 8.0;
        let [fa, fb] = end_forces(CoilKind::Closed, a, b, 1.5);
        assert!(fa.x > 0.0 && (fa + fb).length() < 1e-12);
        let [fa, fb] = end_forces(CoilKind::Open, a, b, 1.5);
        assert!(fa.x < 0.0 && (fa + fb).length() < 1e-12);
    }
}
