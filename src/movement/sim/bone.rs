//! The alveolar bone in the PDL step: the cortical plates of [`crate::appliance::bone`] (or,
//! for the teeth a case's bone meshes cover, the walls of [`crate::appliance::bone_mesh`]) as
//! contacts with a body that never moves.
//!
//! The envelope is made from the teeth's initial poses and the case's extraction sites when the
//! simulation is made (a simulation remade for an extraction keeps it). Each step, the root samples of every moving tooth are
//! checked against the plates; the nearest (at most [`MOST_PER_TOOTH`]) within [`LOOKAHEAD_MM`]
//! of a plate, or past it, become contact rows of the step's solve, so the plate resists like a
//! contact: the tooth may slide along it or leave it, not move into it. A point still short of
//! the plate by a gap may close that gap in the step (a speculative contact); a point already
//! past it is asked back at half its depth per step, at most [`RETURN_MM_PER_STEP`]. Guarantee:
//! the sampled points of a root that start a step within the look-ahead do not pass the plate in
//! it, to first order in the step's rotation; others can pass it by at most how far they move in
//! one step beyond the look-ahead, and are brought back from there.
//!
//! Every root reaching a plate is recorded ([`CorticalContact`]): tooth, plate, first and last
//! day, deepest point and depth; a root back at the same plate within [`EPISODE_GAP_DAYS`]
//! continues the same record.

use glam::Vec3;
use serde::Serialize;

use super::Simulation;
use crate::{
    appliance::{
        bone::{AlveolarEnvelope, Plate, RootedTooth},
        bone_mesh::BoneMeshes,
    },
    geometry::Pose,
    movement::pdl::ContactRow,
    teeth::Fdi,
};

/// A root point this near a plate (mm) is in contact with it.
pub const PLATE_CONTACT_MM: f32 = 0.02;
/// Most speed (mm per step) at which a root past a plate is asked back.
pub const RETURN_MM_PER_STEP: f64 = 0.01;
/// Root points this near a plate (mm) are held by it in the coming step.
pub const LOOKAHEAD_MM: f32 = 0.5;
/// A root back at the same plate within this many days continues the same contact.
pub const EPISODE_GAP_DAYS: f64 = 7.0;
/// Most plate contacts per tooth and step (the nearest).
pub const MOST_PER_TOOTH: usize = 16;

/// A root at a cortical plate over a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CorticalContact {
    /// The tooth.
    pub fdi: Fdi,
    /// Clinical day it reached the plate.
    pub day: f64,
    /// Last day it was at the plate.
    pub until_day: f64,
    /// Deepest it went past the plate (mm; 0: it touched it).
    pub depth_mm: f32,
    /// Which plate.
    pub plate: Plate,
    /// Where (world, mm), at the deepest.
    pub point: [f32; 3],
}

impl Simulation {
    /// Makes the envelope from the teeth's initial poses and the roots of `extracted` teeth
    /// (number, pose, root samples in the tooth's frame), when the plates are on.
    pub(super) fn make_bone(&mut self, extracted: &[(Fdi, Pose, Vec<Vec3>)]) {
        if !self.settings.pdl.bone_plates {
            return;
        }
        let rooted: Vec<RootedTooth> = self
            .teeth
            .iter()
            .filter_map(|t| {
                Some(RootedTooth {
                    fdi: t.fdi,
                    pose: t.initial,
                    roots: &t.pdl.as_ref()?.root_samples,
                })
            })
            .chain(extracted.iter().map(|(fdi, pose, roots)| RootedTooth {
                fdi: *fdi,
                pose: *pose,
                roots,
            }))
            .collect();
        let curves = [&self.curves[0], &self.curves[1]];
        // The meshes hold the teeth present (an extraction site is the envelope's to know).
        let present = rooted.len() - extracted.len();
        self.bone_meshes = BoneMeshes::new(&self.bone_files, &rooted[..present], curves);
        self.bone = Some(AlveolarEnvelope::new(&rooted, curves));
    }

    /// Makes the envelope when the PDL model starts without one (its settings changed to it).
    pub(super) fn ensure_bone(&mut self) {
        if self.bone.is_none() {
            self.make_bone(&[]);
        }
    }

    /// The plate contacts of the bodies made of `members` (body index, tooth indices), as rows
    /// against body `fixed`; records each root that reached a plate.
    pub(super) fn plate_rows(&mut self, members: &[Vec<usize>], fixed: usize) -> Vec<ContactRow> {
        let Some(bone) = &self.bone else {
            return Vec::new();
        };
        let meshes = self.bone_meshes.as_ref();
        let mut rows = Vec::new();
        let mut reached = Vec::new();
        for (u, group) in members.iter().enumerate() {
            for &i in group {
                let t = &self.teeth[i];
                let Some(p) = t.pdl.as_ref() else {
                    continue;
                };
                let mut found = match meshes.filter(|m| m.holds(t.fdi)) {
                    Some(m) => m.contacts(t.fdi, &t.pose, &p.root_samples, LOOKAHEAD_MM),
                    None => bone.contacts(t.fdi, &t.pose, &p.root_samples, LOOKAHEAD_MM),
                };
                found.sort_by(|a, b| b.depth.total_cmp(&a.depth));
                found.truncate(MOST_PER_TOOTH);
                for c in &found {
                    rows.push(ContactRow {
                        a: fixed,
                        b: u,
                        point: c.point.as_dvec3(),
                        normal: c.inward.as_dvec3(),
                        bias: if c.depth > 0.0 {
                            (f64::from(c.depth) * 0.5).min(RETURN_MM_PER_STEP)
                        } else {
                            f64::from(c.depth)
                        },
                    });
                }
                if let Some(c) = found.first().filter(|c| c.depth >= -PLATE_CONTACT_MM) {
                    reached.push((t.fdi, c.plate, c.depth.max(0.0), c.point));
                }
            }
        }
        for (fdi, plate, depth, point) in reached {
            self.record_cortical(fdi, plate, depth, point);
        }
        rows
    }

    fn record_cortical(&mut self, fdi: Fdi, plate: Plate, depth: f32, point: Vec3) {
        let day = self.elapsed_days;
        let gap = self.settings.pdl.step_days().max(EPISODE_GAP_DAYS);
        let ongoing = self
            .cortical
            .iter_mut()
            .rev()
            .find(|c| c.fdi == fdi && c.plate == plate && c.until_day >= day - gap - 1e-9);
        match ongoing {
            Some(c) => {
                c.until_day = day;
                if depth > c.depth_mm {
                    c.depth_mm = depth;
                    c.point = point.to_array();
                }
            }
            None => self.cortical.push(CorticalContact {
                fdi,
                day,
                until_day: day,
                depth_mm: depth,
                plate,
                point: point.to_array(),
            }),
        }
    }
}
