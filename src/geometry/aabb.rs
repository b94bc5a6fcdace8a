//! Axis-aligned bounding boxes.

use glam::{Mat3, Vec3};

/// An axis-aligned box; empty when `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    /// The empty box.
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The smallest box containing the points.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    /// This box grown to contain `p`.
    #[inline]
    pub fn grow(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(self, o: Self) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// Centre point.
    #[inline]
    pub fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths (zero for an empty box).
    #[inline]
    pub fn extent(&self) -> Vec3 {
        (self.max - self.min).max(Vec3::ZERO)
    }

    /// Squared distance between two boxes (0 when they overlap). Exact.
    #[inline]
    pub fn distance_squared(&self, o: &Self) -> f32 {
        let gap = (self.min - o.max).max(o.min - self.max).max(Vec3::ZERO);
        gap.length_squared()
    }

    /// Squared distance from a point to the box (0 inside). Exact.
    #[inline]
    pub fn distance_squared_to_point(&self, p: Vec3) -> f32 {
        let gap = (self.min - p).max(p - self.max).max(Vec3::ZERO);
        gap.length_squared()
    }

    /// The box of this box after the affine map `x -> rotation * x + translation`: conservative (it
    /// contains every transformed point), exact for axis-aligned rotations (Arvo's method).
    pub fn transformed(&self, rotation: &Mat3, translation: Vec3) -> Self {
        let c = *rotation * self.centre() + translation;
        let h = self.extent() * 0.5;
        let abs = Mat3::from_cols(
            rotation.x_axis.abs(),
            rotation.y_axis.abs(),
            rotation.z_axis.abs(),
        );
        let r = abs * h;
        Self {
            min: c - r,
            max: c + r,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_between_boxes() {
        let a = Aabb::from_points([Vec3::ZERO, Vec3::ONE]);
        let b = Aabb::from_points([Vec3::new(3.0, 0.5, 0.5), Vec3::new(4.0, 5.0, 5.0)]);
        assert_eq!(a.distance_squared(&b), 4.0);
        assert_eq!(a.distance_squared(&a), 0.0);
        assert_eq!(a.distance_squared_to_point(Vec3::new(1.0, 4.0, 0.5)), 9.0);
    }

    #[test]
    fn transformed_box_contains_the_transformed_corners() {
        let a = Aabb::from_points([Vec3::new(-1.0, 2.0, 0.0), Vec3::new(3.0, 4.0, 1.5)]);
        let rot = Mat3::from_quat(glam::Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.4, 1.9));
        let t = Vec3::new(5.0, -1.0, 2.0);
        let b = a.transformed(&rot, t);
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { a.min.x } else { a.max.x },
                if i & 2 == 0 { a.min.y } else { a.max.y },
                if i & 4 == 0 { a.min.z } else { a.max.z },
            );
            let q = rot * p + t;
            assert!(b.distance_squared_to_point(q) < 1e-9, "{q} outside {b:?}");
        }
    }
}
