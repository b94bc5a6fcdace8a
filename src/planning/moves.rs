//! One tooth's movement from its initial pose to its target, split into stages.
//!
//! The movement is a screw about the crown centre: the crown centre moves on the straight line
//! to its target place while the tooth turns at a constant rate about one fixed axis (the
//! rotation from the initial to the target orientation), so every component of the movement
//! grows linearly with the fraction done. Its six components are taken in the arch's frame at the
//! tooth's initial place: along the arch (mesial positive), across it (buccal positive) and
//! vertically (world up), then the rotation vector's parts about the vertical (rotation), the
//! bucco-lingual axis (tip) and the mesio-distal axis (torque). A tooth needs as many stages as
//! its most limiting component asks: ⌈|component| / limit⌉; each of its stages then moves every
//! component by exactly its total over the number of stages, within every limit.

use glam::{Quat, Vec3};

use crate::geometry::Pose;
use crate::teeth::Fdi;

/// Components closer to zero than this (mm or degrees) need no stage.
const NEGLIGIBLE: f32 = 1e-4;

/// One tooth's movement.
#[derive(Clone, Debug)]
pub struct ToothMove {
    /// The tooth.
    pub fdi: Fdi,
    /// Initial pose (the scan's).
    pub start: Pose,
    /// Target pose.
    pub end: Pose,
    /// The crown centre in the tooth's local frame (the pivot of the movement).
    pub pivot: Vec3,
    /// The rotation from the initial to the target orientation, as a rotation vector (world,
    /// radians).
    pub turn: Vec3,
    /// Components (mesio-distal, bucco-lingual, vertical mm; rotation, tip, torque degrees).
    pub components: [f32; 6],
    /// Stages it needs within the limits (0 for a tooth that does not move).
    pub steps: u32,
    /// The stage it starts at.
    pub start_stage: u32,
}

impl ToothMove {
    /// The movement of a tooth from `start` to `end`, with `pivot` its crown centre (local) and
    /// `mesial`, `buccal` the arch's unit directions at its initial place.
    pub fn new(
        fdi: Fdi,
        start: Pose,
        end: Pose,
        pivot: Vec3,
        [mesial, buccal]: [Vec3; 2],
        limits: &[f32; 6],
    ) -> Self {
        let shift = end.transform_point(pivot) - start.transform_point(pivot);
        let mut q = end.rotation * start.rotation.inverse();
        if q.w < 0.0 {
            q = -q;
        }
        let turn = q.normalize().to_scaled_axis();
        let deg = |v: Vec3| turn.dot(v).to_degrees();
        let components = [
            shift.dot(mesial),
            shift.dot(buccal),
            shift.y,
            deg(Vec3::Y),
            deg(buccal),
            deg(mesial),
        ];
        let steps = components
            .iter()
            .zip(limits)
            .map(|(c, l)| {
                if c.abs() < NEGLIGIBLE {
                    0
                } else {
                    // A hair's tolerance so a movement of exactly k limits takes k stages.
                    (c.abs() / l - 1e-4).ceil().max(1.0) as u32
                }
            })
            .max()
            .unwrap_or(0);
        Self {
            fdi,
            start,
            end,
            pivot,
            turn,
            components,
            steps,
            start_stage: 0,
        }
    }

    /// The pose after the fraction `f` (0–1) of the movement.
    pub fn at_fraction(&self, f: f32) -> Pose {
        if f <= 0.0 {
            return self.start;
        }
        if f >= 1.0 {
            return self.end;
        }
        let rotation = (Quat::from_scaled_axis(self.turn * f) * self.start.rotation).normalize();
        let c0 = self.start.transform_point(self.pivot);
        let c1 = self.end.transform_point(self.pivot);
        let centre = c0.lerp(c1, f);
        Pose::new(rotation, centre - rotation * self.pivot)
    }

    /// The fraction done at plan stage `k`.
    pub fn fraction_at(&self, k: u32) -> f32 {
        if self.steps == 0 {
            return 1.0;
        }
        (k.saturating_sub(self.start_stage) as f32 / self.steps as f32).min(1.0)
    }

    /// The pose at plan stage `k`.
    pub fn pose_at(&self, k: u32) -> Pose {
        self.at_fraction(self.fraction_at(k))
    }

    /// The last stage at which it moves (its start when it does not move).
    pub fn end_stage(&self) -> u32 {
        self.start_stage + self.steps
    }

    /// Total crown-centre travel (mm) and rotation (degrees).
    pub fn totals(&self) -> (f32, f32) {
        let c = &self.components;
        (
            Vec3::new(c[0], c[1], c[2]).length(),
            self.turn.length().to_degrees(),
        )
    }

    /// The six components of stage `k` alone (from stage k − 1 to k).
    pub fn stage_components(&self, k: u32) -> [f32; 6] {
        if k == 0 {
            return [0.0; 6];
        }
        let d = self.fraction_at(k) - self.fraction_at(k - 1);
        self.components.map(|c| c * d)
    }
}
