//! Movement settings: the quasi-static tooth mobility model, the collision response and their
//! parameters (RON-serialisable).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{MovementError, pdl::PdlSettings};
use crate::teeth::{Arch, ToothKind, anatomy::anatomy};

/// What happens when a moving tooth meets another.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Response {
    /// The paper's: the moving tooth stops at the first contact and passes part of its load to the
    /// tooth it hit, and from there on along the arch.
    #[default]
    Block,
    /// Rigid-body impact (momentum conserved, coefficient of restitution), then blocked like
    /// `block` so that nothing interpenetrates.
    Impulse,
    /// Teeth may overlap up to a limit per contact; the overlap is recorded as interproximal
    /// reduction (enamel to strip), as planning software does.
    Ipr,
}

impl Response {
    /// Every response.
    pub const ALL: [Response; 3] = [Response::Block, Response::Impulse, Response::Ipr];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Response::Block => "block",
            Response::Impulse => "impulse",
            Response::Ipr => "ipr",
        }
    }
}

impl std::fmt::Display for Response {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How a load moves a tooth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MovementModel {
    /// The periodontal ligament: a layer of springs over the root below the alveolar crest, loads
    /// at the bracket, contact forces solved between touching teeth, bone remodelling in
    /// clinical time ([`crate::movement::pdl`]).
    #[default]
    #[serde(alias = "Pdl")]
    Pdl,
    /// The source paper's: velocity = mobility × (|load| − threshold), bodily under a rectangular
    /// wire, tipping about a third of the root from the apex under a round one, half the load
    /// passed to a blocking neighbour, 1/64 s steps.
    #[serde(alias = "Paper")]
    Paper,
}

impl MovementModel {
    /// Both models.
    pub const ALL: [MovementModel; 2] = [MovementModel::Pdl, MovementModel::Paper];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            MovementModel::Pdl => "pdl",
            MovementModel::Paper => "paper",
        }
    }
}

impl std::fmt::Display for MovementModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Parameters of tooth movement (with feature `ecs`, also the movement plugin's resource).
///
/// Teeth in the periodontal ligament are overdamped: a tooth's velocity follows its net load, not
/// its history. Above a threshold, velocity = mobility × (|load| − threshold) along the load; below
/// it the tooth rests. One step advances simulated time by `step_s`. The defaults move a tooth
/// under 1.5 N about 0.01 mm per step (0.5 mm per simulated second), so an extraction space of 7 mm
/// closes in under 1,000 steps; the threshold (0.5 N) and the passed fraction (1/2) let a pushed
/// neighbour move under a 1.5 N load but not the neighbour after it, the paper's observation that
/// the push dies out along the arch.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ecs", derive(bevy::prelude::Resource))]
#[serde(default, deny_unknown_fields)]
pub struct MovementSettings {
    /// How loads move teeth.
    pub model: MovementModel,
    /// The PDL model's parameters (`model: Pdl`).
    pub pdl: PdlSettings,
    /// Simulated seconds per step (`model: Paper`).
    pub step_s: f32,
    /// Translational mobility (mm per second per newton above the threshold).
    pub translational_mobility: f32,
    /// Rotational mobility (radians per second per N·mm above the threshold).
    pub rotational_mobility: f32,
    /// Force below which a tooth does not translate (N).
    pub force_threshold_n: f32,
    /// Moment below which a tooth does not rotate (N·mm).
    pub torque_threshold_nmm: f32,
    /// Fraction of a blocked tooth's load passed to the tooth it pushes (`block`).
    pub passed_fraction: f32,
    /// Collision response.
    pub response: Response,
    /// Coefficient of restitution (`impulse`), 0 (plastic) to 1 (elastic).
    pub restitution: f32,
    /// Tooth density (kg/mm³) for masses and inertias (`impulse`); 2.1 g/cm³, about dentine's.
    pub density_kg_per_mm3: f32,
    /// Largest overlap a contact may reach under `ipr` before it blocks (mm); 0.5 mm per contact
    /// is the usual clinical limit of enamel stripping.
    pub ipr_limit_mm: f32,
}

impl Default for MovementSettings {
    fn default() -> Self {
        Self {
            model: MovementModel::Pdl,
            pdl: PdlSettings::default(),
            step_s: 1.0 / 64.0,
            translational_mobility: 0.5,
            rotational_mobility: 0.005,
            force_threshold_n: 0.5,
            torque_threshold_nmm: 5.0,
            passed_fraction: 0.5,
            response: Response::Block,
            restitution: 0.2,
            density_kg_per_mm3: 2.1e-6,
            ipr_limit_mm: 0.5,
        }
    }
}

impl MovementSettings {
    /// Reads settings from a RON file (missing fields keep their defaults).
    ///
    /// # Errors
    /// [`MovementError::SettingsUnreadable`], or [`MovementError::SettingsInvalid`] naming the
    /// file, line and column of a syntax error, an unknown field or a value out of range.
    pub fn load(path: &Path) -> Result<Self, MovementError> {
        let text =
            std::fs::read_to_string(path).map_err(|e| MovementError::SettingsUnreadable {
                path: path.to_owned(),
                message: e.to_string(),
            })?;
        let s: Self = ron::Options::default().from_str(&text).map_err(|e| {
            MovementError::SettingsInvalid {
                path: path.to_owned(),
                line: e.span.start.line,
                column: e.span.start.col,
                message: e.code.to_string(),
            }
        })?;
        if let Err(e) = s.validate() {
            let MovementError::Setting { field, .. } = e else {
                return Err(e);
            };
            // Point at the offending field.
            let (line, column) = text
                .lines()
                .enumerate()
                .find_map(|(i, l)| l.find(field).map(|c| (i + 1, c + 1)))
                .unwrap_or((1, 1));
            return Err(MovementError::SettingsInvalid {
                path: path.to_owned(),
                line,
                column,
                message: e.to_string(),
            });
        }
        Ok(s)
    }

    /// Checks that every parameter is finite and in range.
    ///
    /// # Errors
    /// [`MovementError::Setting`] naming the first parameter out of range.
    pub fn validate(&self) -> Result<(), MovementError> {
        let checks: [(&'static str, f32, f32, f32); 9] = [
            ("step_s", self.step_s, 1e-6, 10.0),
            (
                "translational_mobility",
                self.translational_mobility,
                0.0,
                1e3,
            ),
            ("rotational_mobility", self.rotational_mobility, 0.0, 10.0),
            ("force_threshold_n", self.force_threshold_n, 0.0, 50.0),
            (
                "torque_threshold_nmm",
                self.torque_threshold_nmm,
                0.0,
                500.0,
            ),
            ("passed_fraction", self.passed_fraction, 0.0, 1.0),
            ("restitution", self.restitution, 0.0, 1.0),
            ("density_kg_per_mm3", self.density_kg_per_mm3, 1e-9, 1e-3),
            ("ipr_limit_mm", self.ipr_limit_mm, 0.0, 5.0),
        ];
        let shortest_root = |kinds: &[ToothKind]| {
            kinds
                .iter()
                .flat_map(|&k| [Arch::Upper, Arch::Lower].map(|a| anatomy(a, k).root_length))
                .fold(f32::INFINITY, f32::min)
        };
        let mut pdl = self.pdl.ranges();
        // A crest must leave at least 2 mm of the type's shortest average root below it.
        for (field, _, _, max) in &mut pdl {
            let kinds: &[ToothKind] = match *field {
                "incisor" => &[ToothKind::CentralIncisor, ToothKind::LateralIncisor],
                "canine" => &[ToothKind::Canine],
                "premolar" => &[ToothKind::FirstPremolar, ToothKind::SecondPremolar],
                "molar" => &[
                    ToothKind::FirstMolar,
                    ToothKind::SecondMolar,
                    ToothKind::ThirdMolar,
                ],
                _ => continue,
            };
            *max = shortest_root(kinds) - 2.0;
        }
        for (field, value, min, max) in checks.into_iter().chain(pdl) {
            if !value.is_finite() || value < min || value > max {
                return Err(MovementError::Setting {
                    field,
                    value,
                    min,
                    max,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert_eq!(MovementSettings::default().validate(), Ok(()));
        let bad = MovementSettings {
            restitution: f32::NAN,
            ..Default::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("restitution")
        );
        let bad = MovementSettings {
            passed_fraction: 1.5,
            ..Default::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("passed_fraction")
        );
    }

    #[test]
    fn a_bad_settings_file_is_named_with_the_line_and_column() {
        let path =
            std::env::temp_dir().join(format!("orthosim-settings-{}.ron", std::process::id()));
        std::fs::write(&path, "(\n    step_s: 0.02,\n    restitution: 7.0,\n)\n").unwrap();
        let e = MovementSettings::load(&path).unwrap_err().to_string();
        let _ = std::fs::remove_file(&path);
        assert!(e.contains(":3:5: movement setting restitution"), "{e}");
        assert!(e.starts_with(&path.display().to_string()), "{e}");
    }

    #[test]
    fn settings_round_trip_through_ron() {
        let s = MovementSettings {
            response: Response::Ipr,
            ..Default::default()
        };
        let text = ron::to_string(&s).unwrap();
        assert_eq!(ron::from_str::<MovementSettings>(&text).unwrap(), s);
    }
}
