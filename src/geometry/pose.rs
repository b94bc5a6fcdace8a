//! Rigid poses (rotation then translation) in the engine-free core.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

/// A rigid transform: `p_world = rotation * p_local + translation`. No scale, no reflection, so
/// meshes keep their outward winding under every pose.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Rotation from the local frame to the world frame.
    pub rotation: Quat,
    /// Position of the local origin in the world frame (mm).
    pub translation: Vec3,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Self = Self {
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// A pose from a rotation and a translation.
    pub fn new(rotation: Quat, translation: Vec3) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// A pure translation.
    pub fn from_translation(translation: Vec3) -> Self {
        Self::new(Quat::IDENTITY, translation)
    }

    /// The turn `rotation` about the point `pivot` (which stays where it is).
    pub fn turn_about(pivot: Vec3, rotation: Quat) -> Self {
        Self::new(rotation, pivot - rotation * pivot)
    }

    /// Maps a point from the local frame to the world frame.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// Maps a direction from the local frame to the world frame.
    #[inline]
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// The inverse pose (world to local).
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self::new(r, -(r * self.translation))
    }

    /// Composition: `self * other` applies `other` first, then `self`.
    pub fn mul(&self, other: &Self) -> Self {
        Self::new(
            (self.rotation * other.rotation).normalize(),
            self.transform_point(other.translation),
        )
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation.is_finite() && self.translation.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_undoes_the_pose() {
        let pose = Pose::new(
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(1.0, -2.0, 3.5),
        );
        let p = Vec3::new(0.25, 4.0, -7.0);
        let back = pose.inverse().transform_point(pose.transform_point(p));
        assert!((back - p).length() < 1e-5, "{back} != {p}");
        let composed = pose.mul(&pose.inverse());
        assert!(composed.translation.length() < 1e-5);
        assert!(composed.rotation.angle_between(Quat::IDENTITY) < 1e-3);
    }
}
