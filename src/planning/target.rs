//! The target of a plan: where each tooth should end.
//!
//! **From a file**: each listed tooth moved from where it stands by a case offset (translation
//! along its mesial, buccal and occlusal axes, rotation about them through its crown centre);
//! unlisted teeth stay ([`from_offsets`]).
//!
//! **Automatic** ([`automatic`]), per arch:
//! 1. *Arch form*: the beta arch fitted to the present teeth's cervical centres (the case's
//!    fitted form), or the preformed form `arch_form` names (ovoid, tapered, square) sized to its
//!    width at the second molars and depth; the teeth's local origins placed on it as the normal
//!    arrangement places them.
//! 2. *Axes*: each tooth turned to the arrangement's axes at its place on the curve (occlusal
//!    axis vertical, buccal axis along the curve's outward normal, then the arrangement's crown
//!    inclination for its position), which corrects rotations, tips and torques. A tooth within
//!    [`KEEP_DEG`] of those axes keeps its own orientation.
//! 3. *Levelling*: the curve of Spee levelled: each tooth's level (its cervical centre's height
//!    plus its crown length, the arrangement's measure of a tip's height) brought onto the plane
//!    fitted through the arch's levels less each position's step above the premolars and molars
//!    in the normal arrangement (the steps of a levelled arch that occludes), so the arch's mean
//!    height is kept. A tooth within [`KEEP_LEVEL_MM`] of its level keeps its height.
//! 4. *Along the arch*: the two teeth either side of the midline placed symmetrically about the
//!    midline point as it stands (the midline is kept), then each tooth outward in turn with the
//!    exact gap to its mesial neighbour set to `contact_gap_mm` (bisection on its place along the
//!    curve; exact mesh distance), so spaces close and crowding shows as the last teeth going
//!    distally.
//! 5. *Crowding*, when the last tooth of a side would go distally by more than
//!    [`CROWDING_SLACK_MM`], relieved in this order, each within its limit: expansion (the arch
//!    form widened, up to `expansion_mm` at the second molars), proclination (the curve's front
//!    brought forward, up to `proclination_mm`), then IPR (in `ipr_step_mm` steps, shared
//!    round-robin among the contacts from the midline to the canine–premolar contacts, each
//!    within its per-contact limit; a reduced contact's target gap is less by its IPR). What is
//!    left is reported as unresolved, and the last teeth go distally by it.
//!
//! 6. *Spaces* (the last teeth of the sides going mesially by more than the slack on average)
//!    closed as the arch's anchorage says: a share of them by retracting the anterior teeth (the
//!    arch form's front brought back, within `retraction_mm`, its molar end kept), the rest by
//!    the posterior teeth coming forward. `Auto` picks the share, per arch, that brings the
//!    canines and first molars nearest class I with the opposing arch's target while the
//!    incisors keep their overjet ([`super::anchorage`]).
//!
//! The arches are set up in [`super::setup`]. Not done: a whole arch is not moved sagittally
//! (distalization, elastics), so an arch without spaces keeps its relation to the other; the
//! target reports it ([`Target::relations`]).

use std::collections::BTreeMap;

use serde::Serialize;

use super::anchorage::{AUTO_SHARES, Candidate, Relations, choose};
use super::limits::PlanLimits;
use super::setup::{ArchSetter, arrangement_steps};
use crate::geometry::Pose;
use crate::teeth::{
    Arch, Dentition, Fdi, PlacedTooth,
    case::{CaseOffset, ToothMap},
};

pub use super::setup::{CROWDING_SLACK_MM, KEEP_DEG, KEEP_LEVEL_MM};

/// IPR a target needs at one contact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TargetIpr {
    /// Mesial-side tooth of the contact (nearer the patient's right).
    pub a: Fdi,
    /// The other tooth.
    pub b: Fdi,
    /// Enamel removed (mm, both teeth together).
    pub mm: f32,
}

/// How the automatic target set up one arch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArchSetup {
    /// `upper` or `lower`.
    pub arch: &'static str,
    /// How far the last teeth would go distally with no relief (mm; patient's right, left;
    /// negative: spaces to close).
    pub crowding_mm: [f32; 2],
    /// Expansion used (mm at the second molars).
    pub expansion_mm: f32,
    /// Proclination used (mm).
    pub proclination_mm: f32,
    /// IPR used (mm, sum over the arch's contacts).
    pub ipr_mm: f32,
    /// Crowding left (mm; right, left): the last teeth go distally by this.
    pub unresolved_mm: [f32; 2],
    /// The anchorage asked for (`auto`, `minimum`, `moderate`, `maximum`).
    pub anchorage: &'static str,
    /// How far the front of the arch went back to close spaces (mm).
    pub retraction_mm: f32,
    /// The share of the spaces the anterior teeth closed (0–1; 0 without spaces).
    pub retraction_share: f32,
}

impl ArchSetup {
    /// One line: the crowding, the means used and what is left.
    pub fn summary(&self) -> String {
        format!(
            "{} arch: crowding {:.2} / {:.2} mm (right / left); expansion {:.2} mm, proclination {:.2} mm, IPR {:.2} mm; unresolved {:.2} / {:.2} mm; anchorage {}, {:.0} % of spaces closed by the anterior teeth ({:.2} mm retraction)",
            self.arch,
            self.crowding_mm[0],
            self.crowding_mm[1],
            self.expansion_mm,
            self.proclination_mm,
            self.ipr_mm,
            self.unresolved_mm[0],
            self.unresolved_mm[1],
            self.anchorage,
            100.0 * self.retraction_share,
            self.retraction_mm
        )
    }
}

/// Where each tooth should end.
#[derive(Clone, Debug)]
pub struct Target {
    /// Target pose of every present tooth (extracted teeth stay where they are).
    pub poses: BTreeMap<Fdi, Pose>,
    /// IPR the target needs.
    pub ipr: Vec<TargetIpr>,
    /// `automatic` or `file`.
    pub source: &'static str,
    /// The automatic set-up per arch (empty for a target from a file).
    pub arches: Vec<ArchSetup>,
    /// Canine and molar relations and the overjet at the target.
    pub relations: Relations,
}

/// A target from per-tooth movements (see the module doc).
pub fn from_offsets(d: &Dentition, offsets: &ToothMap<CaseOffset>) -> Target {
    let poses = d
        .teeth
        .iter()
        .map(|t| {
            let pose = match offsets.0.get(&t.fdi) {
                Some(o) if !t.extracted => t.offset_pose(o),
                _ => t.pose,
            };
            (t.fdi, pose)
        })
        .collect();
    let relations = Relations::measure(d, &poses);
    Target {
        poses,
        ipr: Vec::new(),
        source: "file",
        arches: Vec::new(),
        relations,
    }
}

/// The automatic target (see the module doc).
pub fn automatic(d: &Dentition, limits: &PlanLimits) -> Target {
    let mut poses: BTreeMap<Fdi, Pose> = d.teeth.iter().map(|t| (t.fdi, t.pose)).collect();
    let mut candidates: [Vec<Candidate>; 2] = [Vec::new(), Vec::new()];
    for (k, arch) in [Arch::Upper, Arch::Lower].into_iter().enumerate() {
        let mut row: Vec<&PlacedTooth> = d.visible().filter(|t| t.fdi.arch() == arch).collect();
        row.sort_by_key(|t| t.fdi.arch_index());
        if row.len() < 2 {
            continue;
        }
        let form = d.arch_forms[k];
        let setter = ArchSetter::new(arch, &row, form, limits, arrangement_steps(d, arch));
        let relieved = setter.relieve();
        let anchorage = limits.anchorage.of(arch);
        let shares: &[f32] = match anchorage.retraction_share() {
            Some(s) => &[s][..],
            None if relieved.has_spaces() => &AUTO_SHARES,
            None => &[0.0],
        };
        let fdis: Vec<Fdi> = row.iter().map(|t| t.fdi).collect();
        candidates[k] = shares
            .iter()
            .map(|&share| {
                let (poses, setup, ipr) = setter.close(&relieved, share, anchorage.name());
                Candidate {
                    fdis: fdis.clone(),
                    poses,
                    setup,
                    ipr,
                }
            })
            .collect();
    }
    let ([i, j], relations) = choose(d, &poses, &candidates[0], &candidates[1]);
    let mut ipr = Vec::new();
    let mut arches = Vec::new();
    for c in [candidates[0].get(i), candidates[1].get(j)]
        .into_iter()
        .flatten()
    {
        for (f, p) in c.fdis.iter().zip(&c.poses) {
            poses.insert(*f, *p);
        }
        ipr.extend(c.ipr.iter().copied());
        arches.push(c.setup.clone());
    }
    Target {
        poses,
        ipr,
        source: "automatic",
        arches,
        relations,
    }
}

/// Reads a target file: a map from tooth to its movement, as a case's `target`
/// (`{11: (translation: (0.5, 0.0, 0.0), rotation_deg: (0.0, 0.0, 10.0))}`), checked against the
/// teeth present in `d`.
///
/// # Errors
/// [`super::PlanError::Invalid`] naming the file, line and column of the first problem.
pub fn read_target(
    path: &std::path::Path,
    d: &Dentition,
) -> Result<ToothMap<CaseOffset>, super::PlanError> {
    let origin = path.display().to_string();
    let err = |line: usize, column: usize, message: String| super::PlanError::Invalid {
        path: origin.clone(),
        line,
        column,
        message,
    };
    let source =
        std::fs::read_to_string(path).map_err(|e| err(1, 1, format!("cannot read: {e}")))?;
    let map: ToothMap<CaseOffset> = ron::from_str(&source)
        .map_err(|e| err(e.span.start.line, e.span.start.col, e.code.to_string()))?;
    for (f, o) in &map.0 {
        let (line, column) = source
            .lines()
            .enumerate()
            .find_map(|(i, l)| l.find(&format!("{f}:")).map(|c| (i + 1, c + 1)))
            .unwrap_or((1, 1));
        match d.tooth(*f) {
            None => return Err(err(line, column, format!("tooth {f} is not in the case"))),
            Some(t) if t.extracted => {
                return Err(err(line, column, format!("tooth {f} is extracted")));
            }
            _ => {}
        }
        let (t, r) = (o.translation, o.rotation_deg);
        let (mm, deg) = (
            crate::teeth::case::MAX_OFFSET_MM,
            crate::teeth::case::MAX_OFFSET_DEG,
        );
        if [t.0, t.1, t.2].iter().any(|c| c.0.abs() > mm)
            || [r.0, r.1, r.2].iter().any(|c| c.0.abs() > deg)
        {
            let m = format!("movement of tooth {f} is beyond {mm} mm or {deg}° per axis");
            return Err(err(line, column, m));
        }
    }
    Ok(map)
}
