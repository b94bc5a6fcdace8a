//! A small deterministic random generator (xorshift64) for seeded test data, benchmarks and
//! scan-like meshes: the same seed gives the same numbers on every machine.

use glam::{Quat, Vec3};

use super::Pose;

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
