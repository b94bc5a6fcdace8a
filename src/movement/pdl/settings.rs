//! The PDL model's parameters: the ligament's elasticity and thickness, where the alveolar crest
//! lies, where the bracket sits, the wire's engagement, and bone remodelling in clinical time.
//! Defaults and their sources are in the guide's chapter on tooth movement (`docs/movement.md`).

use serde::{Deserialize, Serialize};

use crate::teeth::ToothKind;

/// Depth of the alveolar crest below the cervical line (cementoenamel junction) per tooth type
/// (mm). The ligament holds the root only below the crest.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CrestDepths {
    /// Central and lateral incisors.
    pub incisor: f32,
    /// Canines.
    pub canine: f32,
    /// Premolars.
    pub premolar: f32,
    /// Molars.
    pub molar: f32,
}

impl Default for CrestDepths {
    fn default() -> Self {
        Self {
            incisor: 1.5,
            canine: 1.5,
            premolar: 1.5,
            molar: 1.5,
        }
    }
}

impl CrestDepths {
    /// The crest depth of a tooth type (mm).
    pub fn of(&self, kind: ToothKind) -> f32 {
        match kind {
            ToothKind::CentralIncisor | ToothKind::LateralIncisor => self.incisor,
            ToothKind::Canine => self.canine,
            k if k.is_molar() => self.molar,
            _ => self.premolar,
        }
    }
}

/// Parameters of the periodontal-ligament model (part of
/// [`crate::movement::MovementSettings`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PdlSettings {
    /// Young's modulus of the ligament below the knee (MPa).
    pub youngs_modulus_mpa: f32,
    /// Young's modulus past the knee (MPa); equal to `youngs_modulus_mpa` for a linear ligament.
    pub youngs_modulus_past_knee_mpa: f32,
    /// Strain at the knee of the bilinear law (fraction).
    pub knee_strain: f32,
    /// Poisson's ratio, below 0.5.
    pub poisson_ratio: f32,
    /// Thickness of the ligament (mm).
    pub thickness_mm: f32,
    /// Depth of the alveolar crest below the cervical line, per tooth type (mm).
    pub crest_mm: CrestDepths,
    /// Height of the bracket above the cervical line, as a fraction of the crown height (0.5:
    /// mid-crown), on the buccal surface.
    pub bracket_height: f32,
    /// Fraction of the couple that would stop a tooth rotating that a rectangular wire supplies
    /// (1: full engagement, bodily movement; 0: as loose as a round wire).
    pub wire_engagement: f32,
    /// Whether the archwire holds each bracket on its path (the bracket slides along the arch but
    /// not across it); false: loads move teeth freely, the wire only supplies couples.
    pub wire_holds_brackets: bool,
    /// Mean ligament pressure below which bone does not remodel (kPa).
    pub threshold_kpa: f32,
    /// Bone remodelling rate β: the tooth moves by β × its initial (elastic) displacement per
    /// day, above the threshold (1/day).
    pub remodelling_per_day: f32,
    /// Mean ligament pressure above which a heavier load moves the tooth no faster (kPa): past
    /// an optimal force the rate of movement levels off (hyalinised ligament; Quinn & Yoshikawa,
    /// AJO 1985;88:252–60). The default, 10 kPa, is about 2 N on a canine, above every
    /// optimal force.
    pub saturation_kpa: f32,
    /// Clinical time per simulation step (hours).
    pub step_hours: f32,
    /// Whether the alveolar envelope's buccal and lingual cortical plates hold the roots
    /// ([`crate::appliance::bone`]).
    pub bone_plates: bool,
}

impl Default for PdlSettings {
    fn default() -> Self {
        Self {
            youngs_modulus_mpa: 0.05,
            youngs_modulus_past_knee_mpa: 0.2,
            knee_strain: 0.07,
            poisson_ratio: 0.49,
            thickness_mm: 0.2,
            crest_mm: CrestDepths::default(),
            bracket_height: 0.5,
            wire_engagement: 1.0,
            wire_holds_brackets: true,
            threshold_kpa: 2.0,
            remodelling_per_day: 18.0,
            saturation_kpa: 10.0,
            step_hours: 24.0,
            bone_plates: true,
        }
    }
}

impl PdlSettings {
    /// Normal and shear stiffness of the ligament per unit root area (N/mm³) for Young's modulus
    /// `e` (MPa): a thin elastic layer, `E(1−ν)/((1+ν)(1−2ν)t)` and `E/(2(1+ν)t)`.
    pub fn layer_stiffness(&self, e: f32) -> (f64, f64) {
        let (e, nu, t) = (
            e as f64,
            self.poisson_ratio as f64,
            self.thickness_mm as f64,
        );
        (
            e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu) * t),
            e / (2.0 * (1.0 + nu) * t),
        )
    }

    /// Clinical days per step.
    pub fn step_days(&self) -> f64 {
        self.step_hours as f64 / 24.0
    }

    /// Each parameter with its accepted range (name as in the settings file, value, min, max).
    pub fn ranges(&self) -> [(&'static str, f32, f32, f32); 15] {
        let c = &self.crest_mm;
        [
            ("youngs_modulus_mpa", self.youngs_modulus_mpa, 1e-4, 100.0),
            (
                "youngs_modulus_past_knee_mpa",
                self.youngs_modulus_past_knee_mpa,
                1e-4,
                100.0,
            ),
            ("knee_strain", self.knee_strain, 1e-4, 1.0),
            ("poisson_ratio", self.poisson_ratio, 0.0, 0.499),
            ("thickness_mm", self.thickness_mm, 0.01, 2.0),
            ("incisor", c.incisor, 0.0, 10.0),
            ("canine", c.canine, 0.0, 10.0),
            ("premolar", c.premolar, 0.0, 10.0),
            ("molar", c.molar, 0.0, 10.0),
            ("bracket_height", self.bracket_height, 0.05, 0.95),
            ("wire_engagement", self.wire_engagement, 0.0, 1.0),
            ("threshold_kpa", self.threshold_kpa, 0.0, 1e3),
            ("remodelling_per_day", self.remodelling_per_day, 0.0, 1e3),
            ("saturation_kpa", self.saturation_kpa, 0.0, 1e4),
            ("step_hours", self.step_hours, 1e-3, 24.0 * 30.0),
        ]
    }
}
