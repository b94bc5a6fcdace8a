//! What a plan may do: per-stage movement limits, the means of gaining space and their limits,
//! the contacts of the target, the collision tolerance, and how the teeth are sequenced. The
//! defaults are those of clear-aligner planning (`appliances.md`: 0.25 mm mesio-distal and
//! bucco-lingual, 0.15 mm vertical, 2° rotation and tip, 1° torque per stage; IPR in 0.05 mm
//! steps); a RON file overrides any of them, e.g. `(mesiodistal_mm: 0.2, sequence: VPattern,
//! wait: {13: 4}, anchorage: (upper: Maximum))`. The retraction limit (7 mm) is about a first
//! premolar's width: the most an extraction space lets the incisors go back.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::PlanError;
use crate::teeth::{
    Fdi, ToothKind,
    case::{NonNegative, ToothMap},
};

/// In which order the teeth start moving.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Sequence {
    /// Every tooth starts at the first stage.
    #[default]
    AllAtOnce,
    /// Incisors and canines first; premolars and molars start when the anterior teeth are done.
    AnteriorsFirst,
    /// From the back: molars first, then premolars, canines and incisors, each group starting
    /// when the group behind it is half-way (the V-pattern of distalization).
    VPattern,
}

impl Sequence {
    /// The name written in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Sequence::AllAtOnce => "all at once",
            Sequence::AnteriorsFirst => "anteriors first",
            Sequence::VPattern => "V-pattern",
        }
    }
}

/// The arch form the automatic target aligns the teeth on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TargetForm {
    /// The beta arch fitted to the teeth as they stand.
    #[default]
    Fitted,
    /// A preformed ovoid form, sized to the fitted arch's width at the second molars and depth.
    Ovoid,
    /// A preformed tapered form, sized the same way.
    Tapered,
    /// A preformed square form, sized the same way.
    Square,
}

impl TargetForm {
    /// The preformed form, or None for the fitted one.
    pub fn preformed(self) -> Option<crate::teeth::case::appliance::ArchForm> {
        use crate::teeth::case::appliance::ArchForm;
        match self {
            TargetForm::Fitted => None,
            TargetForm::Ovoid => Some(ArchForm::Ovoid),
            TargetForm::Tapered => Some(ArchForm::Tapered),
            TargetForm::Square => Some(ArchForm::Square),
        }
    }

    /// The name written in reports.
    pub fn name(self) -> &'static str {
        match self {
            TargetForm::Fitted => "fitted",
            TargetForm::Ovoid => "ovoid",
            TargetForm::Tapered => "tapered",
            TargetForm::Square => "square",
        }
    }
}

/// Which teeth close an arch's spaces (extraction spaces, spacing): the anterior teeth
/// retracting, the posterior teeth coming forward, or both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Anchorage {
    /// The share that brings canines and first molars nearest class I with the opposing arch's
    /// target, keeping the incisors' overjet (see [`super::anchorage`]).
    #[default]
    Auto,
    /// The posterior teeth close the spaces; the anterior teeth stay.
    Minimum,
    /// Half each.
    Moderate,
    /// The anterior teeth retract to close the spaces (within `retraction_mm`); the molars stay.
    Maximum,
}

impl Anchorage {
    /// The share of the spaces closed by anterior retraction, or None for [`Anchorage::Auto`].
    pub fn retraction_share(self) -> Option<f32> {
        match self {
            Anchorage::Auto => None,
            Anchorage::Minimum => Some(0.0),
            Anchorage::Moderate => Some(0.5),
            Anchorage::Maximum => Some(1.0),
        }
    }

    /// The name written in reports.
    pub fn name(self) -> &'static str {
        match self {
            Anchorage::Auto => "auto",
            Anchorage::Minimum => "minimum",
            Anchorage::Moderate => "moderate",
            Anchorage::Maximum => "maximum",
        }
    }
}

/// The anchorage of each arch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArchAnchorage {
    /// Upper arch.
    pub upper: Anchorage,
    /// Lower arch.
    pub lower: Anchorage,
}

impl ArchAnchorage {
    /// The anchorage of `arch`.
    pub fn of(&self, arch: crate::teeth::Arch) -> Anchorage {
        if arch == crate::teeth::Arch::Upper {
            self.upper
        } else {
            self.lower
        }
    }
}

/// Interproximal reduction allowed per contact (mm of enamel, both teeth together).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IprLimits {
    /// Between lower incisors (thin enamel: 0.2 mm a surface).
    pub lower_incisors_mm: NonNegative,
    /// Any other contact from canine to canine, and canine to first premolar.
    pub anterior_mm: NonNegative,
    /// Between premolars and molars.
    pub posterior_mm: NonNegative,
}

impl Default for IprLimits {
    fn default() -> Self {
        Self {
            lower_incisors_mm: NonNegative(0.4),
            anterior_mm: NonNegative(0.5),
            posterior_mm: NonNegative(0.6),
        }
    }
}

impl IprLimits {
    /// The limit for the contact between `a` and `b`.
    pub fn between(&self, a: Fdi, b: Fdi) -> f32 {
        let incisor = |f: Fdi| f.position() <= 2;
        let anterior = |f: Fdi| f.position() <= 3;
        if a.arch() == crate::teeth::Arch::Lower && incisor(a) && incisor(b) {
            self.lower_incisors_mm.0
        } else if anterior(a) || anterior(b) {
            self.anterior_mm.0
        } else {
            self.posterior_mm.0
        }
    }
}

/// Everything a plan may do (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlanLimits {
    /// Crown-centre movement along the arch per stage (mm).
    pub mesiodistal_mm: NonNegative,
    /// Crown-centre movement across the arch per stage (mm).
    pub buccolingual_mm: NonNegative,
    /// Intrusion or extrusion per stage (mm).
    pub vertical_mm: NonNegative,
    /// Rotation about the vertical per stage (degrees).
    pub rotation_deg: NonNegative,
    /// Tip (about the bucco-lingual axis) per stage (degrees).
    pub tip_deg: NonNegative,
    /// Torque (about the mesio-distal axis) per stage (degrees).
    pub torque_deg: NonNegative,
    /// IPR is scheduled in multiples of this (mm).
    pub ipr_step_mm: NonNegative,
    /// IPR allowed per contact.
    pub ipr: IprLimits,
    /// The arch form the automatic target aligns the teeth on.
    pub arch_form: TargetForm,
    /// How much wider the automatic target's arch form may be than the teeth's (mm, at the
    /// second molars) to relieve crowding.
    pub expansion_mm: NonNegative,
    /// How far forward the automatic target's incisors may come to relieve crowding (mm).
    pub proclination_mm: NonNegative,
    /// How far back the automatic target's incisors may go to close spaces (mm).
    pub retraction_mm: NonNegative,
    /// Which teeth close each arch's spaces in the automatic target.
    pub anchorage: ArchAnchorage,
    /// The gap between neighbours in the automatic target (mm, 0–0.05).
    pub contact_gap_mm: NonNegative,
    /// Penetration allowed between two teeth at any measured instant of the plan (mm), beyond
    /// the enamel an IPR removed and what a pair already overlapped in the scan.
    pub tolerance_mm: NonNegative,
    /// The sequencing of the teeth.
    pub sequence: Sequence,
    /// Stages a tooth waits before it starts, on top of the sequence.
    pub wait: ToothMap<u32>,
}

impl Default for PlanLimits {
    fn default() -> Self {
        Self {
            mesiodistal_mm: NonNegative(0.25),
            buccolingual_mm: NonNegative(0.25),
            vertical_mm: NonNegative(0.15),
            rotation_deg: NonNegative(2.0),
            tip_deg: NonNegative(2.0),
            torque_deg: NonNegative(1.0),
            ipr_step_mm: NonNegative(0.05),
            ipr: IprLimits::default(),
            arch_form: TargetForm::Fitted,
            expansion_mm: NonNegative(2.0),
            proclination_mm: NonNegative(1.0),
            retraction_mm: NonNegative(7.0),
            anchorage: ArchAnchorage::default(),
            contact_gap_mm: NonNegative(0.04),
            tolerance_mm: NonNegative(0.0),
            sequence: Sequence::AllAtOnce,
            wait: ToothMap::default(),
        }
    }
}

/// The longest wait accepted (stages).
const MAX_WAIT: u32 = 200;

impl PlanLimits {
    /// Per-stage limits as (mesio-distal, bucco-lingual, vertical mm; rotation, tip, torque
    /// degrees), the order of a tooth's movement components.
    pub fn per_stage(&self) -> [f32; 6] {
        [
            self.mesiodistal_mm.0,
            self.buccolingual_mm.0,
            self.vertical_mm.0,
            self.rotation_deg.0,
            self.tip_deg.0,
            self.torque_deg.0,
        ]
    }

    /// Reads a limits file.
    ///
    /// # Errors
    /// [`PlanError::Invalid`] with the file, line and column of the first problem.
    pub fn load(path: &Path) -> Result<Self, PlanError> {
        let name = path.display().to_string();
        let source = std::fs::read_to_string(path).map_err(|e| PlanError::Invalid {
            path: name.clone(),
            line: 1,
            column: 1,
            message: format!("cannot read: {e}"),
        })?;
        Self::parse(&source, &name)
    }

    /// Parses and checks limits text; `origin` names it in errors.
    ///
    /// # Errors
    /// [`PlanError::Invalid`] with the position of the first problem.
    pub fn parse(source: &str, origin: &str) -> Result<Self, PlanError> {
        let err = |line: usize, column: usize, message: String| PlanError::Invalid {
            path: origin.to_owned(),
            line,
            column,
            message,
        };
        let limits: PlanLimits = ron::from_str(source)
            .map_err(|e| err(e.span.start.line, e.span.start.col, e.code.to_string()))?;
        let at = |field: &str| crate::teeth::case::locate(source, field, None);
        let names = [
            "mesiodistal_mm",
            "buccolingual_mm",
            "vertical_mm",
            "rotation_deg",
            "tip_deg",
            "torque_deg",
        ];
        for (name, v) in names.iter().zip(limits.per_stage()) {
            if v <= 0.0 {
                let (l, c) = at(name);
                return Err(err(l, c, format!("{name} must be above 0, got {v}")));
            }
        }
        if limits.ipr_step_mm.0 < 0.01 {
            let (l, c) = at("ipr_step_mm");
            return Err(err(l, c, "ipr_step_mm must be at least 0.01 mm".into()));
        }
        if limits.contact_gap_mm.0 > 0.05 {
            let (l, c) = at("contact_gap_mm");
            return Err(err(l, c, "contact_gap_mm must be 0 to 0.05 mm".into()));
        }
        if let Some((f, w)) = limits.wait.0.iter().find(|(_, w)| **w > MAX_WAIT) {
            let (l, c) = at("wait");
            return Err(err(
                l,
                c,
                format!("tooth {f} waits {w} stages, more than the {MAX_WAIT} accepted"),
            ));
        }
        Ok(limits)
    }

    /// The stage a tooth starts at under the sequence, given how many stages each group needs
    /// (incisors, canines, premolars, molars: the most any tooth of the group needs).
    pub fn start_stage(&self, fdi: Fdi, group_stages: [u32; 4]) -> u32 {
        let g = group(fdi.kind());
        let start = match self.sequence {
            Sequence::AllAtOnce => 0,
            Sequence::AnteriorsFirst if g >= 2 => group_stages[0].max(group_stages[1]),
            Sequence::AnteriorsFirst => 0,
            Sequence::VPattern => {
                // Each group starts when the one behind it is half-way.
                group_stages[g + 1..].iter().map(|s| s.div_ceil(2)).sum()
            }
        };
        start + self.wait.0.get(&fdi).copied().unwrap_or(0)
    }
}

/// The sequencing group of a tooth kind: incisors 0, canines 1, premolars 2, molars 3.
pub fn group(kind: ToothKind) -> usize {
    match kind.position() {
        1 | 2 => 0,
        3 => 1,
        4 | 5 => 2,
        _ => 3,
    }
}
