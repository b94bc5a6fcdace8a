//! Loads and motion: each tooth's (or group's) net load and the motion it proposes for the step,
//! within its constraints and limits.

use glam::Vec3;

use super::Simulation;
use crate::movement::settings::MovementModel;
use crate::{
    collision::Motion,
    geometry::Pose,
    movement::model::{
        Centres, Drive, StepMove, angle_between, constrain, drive_at, largest_fraction,
    },
};

impl Simulation {
    pub(super) fn within_limits(&self, i: usize, pose: &Pose) -> bool {
        let t = &self.teeth[i];
        let c = &t.constraint;
        if let Some(max) = c.max_translation_mm {
            let p = t.shape.geometry.frame.crown_centre;
            if pose
                .transform_point(p)
                .distance(t.initial.transform_point(p))
                > max + 1e-6
            {
                return false;
            }
        }
        if let Some(max) = c.max_rotation_rad
            && angle_between(pose.rotation, t.initial.rotation) > max + 1e-7
        {
            return false;
        }
        true
    }

    /// Moves `members` by the drive `d` (constrained in the first member's frames), as far as the
    /// limits of all of them allow.
    fn move_block(&mut self, members: &[usize], d: Drive) {
        let lead = members[0];
        let frame = self.arch_frame(lead);
        let d = constrain(
            d,
            &self.teeth[lead].constraint,
            &frame,
            &self.teeth[lead].pose,
            self.teeth[lead].fdi,
        );
        let dt = self.settings.step_s;
        if d.is_zero() {
            return;
        }
        let end = |sim: &Self, i: usize, f: f32| {
            StepMove::of(&d, &frame, dt, f).apply(
                sim.curve(i),
                &sim.teeth[i].pose,
                sim.teeth[i].arc,
            )
        };
        let f = largest_fraction(|f| {
            members
                .iter()
                .all(|&i| self.within_limits(i, &end(self, i, f)))
        });
        if f <= 1e-6 {
            return;
        }
        for &i in members {
            let to = end(self, i, f);
            if to.is_finite() {
                self.motions[i] = Motion {
                    start: self.teeth[i].pose,
                    end: to,
                };
            }
        }
    }

    /// Loads and motion: each tooth's (or group's) net load and the motion it proposes this step.
    pub fn propose(&mut self) {
        let n = self.teeth.len();
        self.passed = std::mem::replace(&mut self.next_passed, vec![Vec3::ZERO; n]);
        self.motions = self.teeth.iter().map(|t| Motion::still(t.pose)).collect();
        self.ipr_over.clear();
        if self.settings.model == MovementModel::Pdl {
            self.propose_pdl();
            return;
        }
        for i in 0..n {
            if self.teeth[i].group.is_some() {
                continue;
            }
            let t = &self.teeth[i];
            let force = t.load.force + self.passed[i];
            self.effective[i] = force;
            let d = drive_at(force, t.load.torque, t.wire, t.centres(), &self.settings);
            self.move_block(&[i], d);
        }
        for g in 0..self.groups.len() {
            let members = self.groups[g].members.clone();
            if members.is_empty() {
                continue;
            }
            let load = self.groups[g].load;
            let force = load.force + members.iter().map(|&i| self.passed[i]).sum::<Vec3>();
            let k = members.len() as f32;
            let centres = members.iter().map(|&i| self.teeth[i].centres());
            let mean = centres.fold(
                Centres {
                    crown: Vec3::ZERO,
                    tipping: Vec3::ZERO,
                    long_axis: Vec3::ZERO,
                },
                |a, c| Centres {
                    crown: a.crown + c.crown / k,
                    tipping: a.tipping + c.tipping / k,
                    long_axis: a.long_axis + c.long_axis,
                },
            );
            for &i in &members {
                self.effective[i] = force;
            }
            let wire = self.teeth[members[0]].wire;
            let d = drive_at(force, load.torque, wire, mean, &self.settings);
            self.move_block(&members, d);
        }
    }
}
