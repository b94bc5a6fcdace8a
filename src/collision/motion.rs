//! The motion of a tooth over one step, and the bounds the continuous methods need.
//!
//! A step moves a tooth from its start pose to its end pose with the translation linear in t and the
//! rotation slerped in t (t ∈ [0, 1]), i.e. a rotation at constant angular speed about a fixed axis
//! through the tooth's local origin while that origin moves on a straight line. A point p of the
//! tooth (local frame) then moves on a circular arc plus a line, not on the chord between its start
//! and end positions. [`Motion::arc_factor`] bounds the gap: for a rotation by θ ≤ π,
//! |arc(t) − chord(t)| ≤ |p| (1 − cos(θ/2) + θ³/48) for every t (the first term is the sagitta, the
//! second bounds the difference in parameter, |sin(θs) − 2s sin(θ/2)| ≤ θ³/48 for |s| ≤ ½), and
//! |p| bounds the distance from the axis. Inflating every sphere by that amount makes the linear
//! (chord) motion of its centre conservative for the real one.

use glam::{DQuat, DVec3, Quat, Vec3};

use crate::geometry::Pose;

/// Start and end pose of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Pose at t = 0.
    pub start: Pose,
    /// Pose at t = 1.
    pub end: Pose,
}

impl Motion {
    /// A tooth that does not move.
    pub fn still(pose: Pose) -> Self {
        Self {
            start: pose,
            end: pose,
        }
    }

    /// True when start and end are the same pose.
    pub fn is_still(&self) -> bool {
        self.start == self.end
    }

    /// The pose at time t (translation linear, rotation slerped).
    pub fn at(&self, t: f32) -> Pose {
        if t <= 0.0 {
            return self.start;
        }
        if t >= 1.0 {
            return self.end;
        }
        Pose::new(
            self.start.rotation.slerp(self.end.rotation, t).normalize(),
            self.start.translation.lerp(self.end.translation, t),
        )
    }

    /// Rotation angle of the step (radians, in [0, π]).
    pub fn angle(&self) -> f64 {
        let q0 = dquat(self.start.rotation);
        let q1 = dquat(self.end.rotation);
        let d = q0.dot(q1).abs().min(1.0);
        2.0 * d.acos()
    }

    /// Translation of the local origin over the step (mm).
    pub fn travel(&self) -> f64 {
        (self.end.translation.as_dvec3() - self.start.translation.as_dvec3()).length()
    }

    /// k such that a point at distance ρ from the local origin stays within k·ρ of its chord
    /// (see the module doc); 2 for rotations beyond π (never happens with slerp's shortest path,
    /// kept as a safe fallback).
    pub fn arc_factor(&self) -> f64 {
        let theta = self.angle();
        if theta <= 0.0 {
            return 0.0;
        }
        if theta > std::f64::consts::PI {
            return 2.0;
        }
        // Slightly enlarged for the rounding of the terms themselves.
        ((1.0 - (0.5 * theta).cos()) + theta.powi(3) / 48.0) * (1.0 + 1e-9) + 1e-15
    }

    /// Bound on the speed (mm per unit t) of any point within ρ of the local origin.
    pub fn speed_bound(&self, rho: f64) -> f64 {
        self.travel() + self.angle() * rho
    }

    /// The rotation's world axis (unit; any unit vector when the step does not rotate).
    pub fn axis(&self) -> DVec3 {
        let (q0, q1) = (dquat(self.start.rotation), dquat(self.end.rotation));
        // Shortest path, as slerp takes it.
        let q1 = if q0.dot(q1) < 0.0 { -q1 } else { q1 };
        let d = q1 * q0.inverse();
        DVec3::new(d.x, d.y, d.z)
            .try_normalize()
            .unwrap_or(DVec3::X)
    }

    /// Bound on the speed (mm per unit t) of the given points (local frame) over the step: the
    /// rotation turns about a fixed world axis through the moving origin, so a point's speed is at
    /// most the origin's plus the angle times the point's distance from that axis, which the
    /// rotation does not change. Never above [`Motion::speed_bound`] of the points' largest |p|.
    pub fn speed_bound_of(&self, points: impl Iterator<Item = Vec3>) -> f64 {
        let theta = self.angle();
        if theta <= 0.0 {
            return self.travel();
        }
        // |k × R₀p| = |R₀⁻¹k × p|: the axis taken into the local frame once.
        let k = dquat(self.start.rotation).inverse() * self.axis();
        let far = points
            .map(|p| k.cross(p.as_dvec3()).length_squared())
            .fold(0.0, f64::max)
            .sqrt();
        // The axis is rounded in f64: widen by far more than its error.
        self.travel() + theta * far * (1.0 + 1e-9)
    }
}

/// f64 copy of a pose, for the conservative stages.
#[derive(Clone, Copy, Debug)]
pub struct DPose {
    /// Rotation.
    pub rotation: DQuat,
    /// Translation.
    pub translation: DVec3,
}

impl DPose {
    /// From an f32 pose (rotation renormalised in f64).
    pub fn from_pose(p: &Pose) -> Self {
        Self {
            rotation: dquat(p.rotation),
            translation: p.translation.as_dvec3(),
        }
    }

    /// Maps a local point to the world.
    #[inline]
    pub fn apply(&self, p: Vec3) -> DVec3 {
        self.rotation * p.as_dvec3() + self.translation
    }
}

fn dquat(q: Quat) -> DQuat {
    DQuat::from_xyzw(q.x as f64, q.y as f64, q.z as f64, q.w as f64).normalize()
}

/// Per-thread scratch for per-node values computed once per query: a value is valid when its stamp
/// equals the current query's stamp, so nothing is cleared or allocated between queries. Each
/// value sits beside its stamp, so a look-up touches one place in memory.
#[derive(Default)]
pub(crate) struct NodeCache<T: Copy + Default> {
    slots: Vec<(u32, T)>,
    now: u32,
}

impl<T: Copy + Default> NodeCache<T> {
    pub(crate) const fn new() -> Self {
        Self {
            slots: Vec::new(),
            now: 0,
        }
    }

    /// Starts a query over `n` nodes.
    pub(crate) fn begin(&mut self, n: usize) {
        if self.slots.len() < n {
            self.slots.resize(n, (0, T::default()));
        }
        self.now = self.now.wrapping_add(1);
        if self.now == 0 {
            self.slots.iter_mut().for_each(|s| s.0 = 0);
            self.now = 1;
        }
    }

    /// Sets the value of node `i` for this query.
    #[inline]
    pub(crate) fn set(&mut self, i: usize, v: T) {
        self.slots[i] = (self.now, v);
    }

    /// True when node `i` has a value in this query.
    #[inline]
    pub(crate) fn has(&self, i: usize) -> bool {
        self.slots[i].0 == self.now
    }

    /// The value of node `i` by reference, computed by `f` on first use in this query.
    #[inline]
    pub(crate) fn get_ref(&mut self, i: usize, f: impl FnOnce() -> T) -> &T {
        let now = self.now;
        let slot = &mut self.slots[i];
        if slot.0 != now {
            *slot = (now, f());
        }
        &slot.1
    }

    /// The value of node `i`, computed by `f` on first use in this query.
    #[inline]
    pub(crate) fn get(&mut self, i: usize, f: impl FnOnce() -> T) -> T {
        *self.get_ref(i, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_stay_within_the_arc_bound_of_their_chord() {
        for (axis, angle) in [
            (Vec3::Z, 0.3f32),
            (Vec3::new(1.0, 2.0, -0.5).normalize(), 1.2),
            (Vec3::Y, 3.0),
        ] {
            let m = Motion {
                start: Pose::new(Quat::from_rotation_x(0.2), Vec3::new(1.0, 2.0, 3.0)),
                end: Pose::new(
                    Quat::from_axis_angle(axis, angle) * Quat::from_rotation_x(0.2),
                    Vec3::new(4.0, -1.0, 3.5),
                ),
            };
            let k = m.arc_factor();
            let p = Vec3::new(3.0, -7.0, 2.0);
            let (a, b) = (m.start.transform_point(p), m.end.transform_point(p));
            for i in 0..=200 {
                let t = i as f32 / 200.0;
                let real = m.at(t).transform_point(p);
                let chord = a.lerp(b, t);
                assert!(
                    (real.distance(chord) as f64) <= k * p.length() as f64 + 1e-4,
                    "angle {angle} t {t}: {} > {}",
                    real.distance(chord),
                    k * p.length() as f64
                );
            }
        }
        assert_eq!(Motion::still(Pose::IDENTITY).arc_factor(), 0.0);
    }

    #[test]
    fn point_speeds_stay_within_the_axis_bound() {
        let p = [
            Vec3::new(3.0, -7.0, 2.0),
            Vec3::new(-1.0, 0.5, 4.0),
            Vec3::ZERO,
        ];
        for (axis, angle) in [
            (Vec3::Z, 0.3f32),
            (Vec3::new(1.0, 2.0, -0.5).normalize(), -1.2),
            (Vec3::Y, 3.0),
        ] {
            let m = Motion {
                start: Pose::new(Quat::from_rotation_x(0.7), Vec3::new(1.0, 2.0, 3.0)),
                end: Pose::new(
                    Quat::from_axis_angle(axis, angle) * Quat::from_rotation_x(0.7),
                    Vec3::new(1.5, 2.0, 2.5),
                ),
            };
            let bound = m.speed_bound_of(p.iter().copied());
            let loose = m.speed_bound(p.iter().map(|q| q.length() as f64).fold(0.0, f64::max));
            assert!(bound <= loose + 1e-12, "{bound} > {loose}");
            // Finite differences of the real motion never exceed the bound.
            for q in p {
                for i in 0..400 {
                    let (t0, t1) = (i as f32 / 400.0, (i + 1) as f32 / 400.0);
                    let d = m
                        .at(t1)
                        .transform_point(q)
                        .distance(m.at(t0).transform_point(q));
                    assert!(
                        (d / (t1 - t0)) as f64 <= bound * (1.0 + 1e-3) + 1e-4,
                        "angle {angle}: speed {} > {bound}",
                        d / (t1 - t0)
                    );
                }
            }
        }
        // Points on the axis move only with the origin.
        let m = Motion {
            start: Pose::IDENTITY,
            end: Pose::new(Quat::from_rotation_z(0.5), Vec3::new(0.2, 0.0, 0.0)),
        };
        assert!((m.speed_bound_of([Vec3::new(0.0, 0.0, 9.0)].into_iter()) - 0.2).abs() < 1e-6);
    }
}
