//! Seeded motions for the collision benchmark and the tests: random steps of a tooth near its rest
//! pose ([`Rng`] is geometry's). Internal: the tests reach it through
//! `orthosim::internals`.

use glam::{Quat, Vec3};

use super::Motion;
use crate::geometry::Pose;
pub use crate::geometry::rng::Rng;

/// A random step near the rest pose heading roughly towards `target`: 0.01–5 mm (log-uniform),
/// up to ±15° of rotation; one in ten without translation, one in ten without rotation.
pub fn random_motion(rng: &mut Rng, rest: &Pose, target: Vec3) -> Motion {
    let start = rng.perturb(rest, 2.0, 0.3);
    let kind = rng.uniform();
    let length = rng.log_uniform(0.01, 5.0);
    let dir = ((target - start.translation).normalize_or_zero() + rng.vec(0.6)).normalize_or_zero();
    let travel = if kind < 0.1 { Vec3::ZERO } else { dir * length };
    let angle = if kind > 0.9 {
        0.0
    } else {
        rng.vec(15f32.to_radians()).x
    };
    Motion {
        start,
        end: Pose::new(
            (Quat::from_axis_angle(rng.unit(), angle) * start.rotation).normalize(),
            start.translation + travel,
        ),
    }
}
