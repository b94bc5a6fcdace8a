//! Seeded motions for the collision benchmark and the tests: a small deterministic generator and
//! random steps of a tooth near its rest pose. Internal: the tests reach it through
//! `orthosim::internals`.

use glam::{Quat, Vec3};

use super::Motion;
use crate::geometry::Pose;

/// A small deterministic generator (xorshift64).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f32 / (1u64 << 53) as f32
    }

    /// Uniform in the cube [−scale, scale]³.
    pub fn vec(&mut self, scale: f32) -> Vec3 {
        Vec3::new(
            self.uniform() - 0.5,
            self.uniform() - 0.5,
            self.uniform() - 0.5,
        ) * 2.0
            * scale
    }

    /// Log-uniform in [lo, hi).
    pub fn log_uniform(&mut self, lo: f32, hi: f32) -> f32 {
        (lo.ln() + self.uniform() * (hi.ln() - lo.ln())).exp()
    }

    /// `rest` turned by up to ±`degrees` about a random axis and shifted by up to ±`mm` per axis.
    pub fn perturb(&mut self, rest: &Pose, degrees: f32, mm: f32) -> Pose {
        let rotation = Quat::from_axis_angle(self.unit(), self.vec(degrees.to_radians()).x);
        Pose::new(
            (rotation * rest.rotation).normalize(),
            rest.translation + self.vec(mm),
        )
    }

    /// A uniform unit vector.
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let p = self.vec(1.0);
            if p.length_squared() > 0.01 && p.length_squared() <= 1.0 {
                return p.normalize();
            }
        }
    }
}

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
