//! The parts of a case: loads, wires, movement constraints, offsets and which teeth are present.

use serde::{Deserialize, Serialize};

use super::values::{Finite, NonNegative, ToothList, ToothMap};

/// A vector given in the world frame or in a tooth's anatomical frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CaseVector {
    /// World frame: +x patient's left, +y up, +z anterior.
    World(Finite, Finite, Finite),
    /// Components along the tooth's mesial, buccal and occlusal directions (for a torque: about
    /// those axes, right-handed). Missing components are zero.
    Anatomical {
        /// Towards the midline along the arch.
        #[serde(default)]
        mesial: Finite,
        /// Towards the cheeks / lips.
        #[serde(default)]
        buccal: Finite,
        /// Towards the occlusal plane (extrusion).
        #[serde(default)]
        occlusal: Finite,
    },
}

impl Default for CaseVector {
    fn default() -> Self {
        Self::World(Finite(0.0), Finite(0.0), Finite(0.0))
    }
}

impl CaseVector {
    /// Length of the vector.
    pub fn magnitude(&self) -> f32 {
        let (a, b, c) = match *self {
            Self::World(a, b, c) => (a, b, c),
            Self::Anatomical {
                mesial,
                buccal,
                occlusal,
            } => (mesial, buccal, occlusal),
        };
        glam::Vec3::new(a.0, b.0, c.0).length()
    }
}

/// A force system on a tooth or a group of teeth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseLoad {
    /// The loaded teeth.
    pub teeth: ToothList,
    /// Force (N).
    #[serde(default)]
    pub force: CaseVector,
    /// Torque (N·mm).
    #[serde(default)]
    pub torque: CaseVector,
    /// True: the teeth move as one block (a segment on a wire); false: each tooth gets the load.
    #[serde(default)]
    pub as_group: bool,
    /// Moment-to-force ratio at the bracket (mm): the bracket adds a couple of M/F × the force
    /// across the long axis, against the force's tipping (PDL model, rectangular wire; none:
    /// the wire's engagement decides).
    #[serde(default)]
    pub mf: Option<Finite>,
}

/// Archwire cross-section, which decides how a tooth responds to a load (paper, section 3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum WireModel {
    /// Rectangular wire: torque rotates about the crown centre, force translates bodily.
    #[default]
    Rectangular,
    /// Round wire: force tips the tooth about a centre at 1/3 of the root length from the apex.
    Round,
}

/// Wire models per arch, with optional per-tooth exceptions.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseWires {
    /// Upper arch wire.
    #[serde(default)]
    pub upper: WireModel,
    /// Lower arch wire.
    #[serde(default)]
    pub lower: WireModel,
    /// Per-tooth exceptions.
    #[serde(default)]
    pub teeth: ToothMap<WireModel>,
}

/// Degrees of freedom along or about the anatomical axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Freedoms {
    /// Along / about the mesiodistal axis.
    #[serde(default = "yes")]
    pub mesial: bool,
    /// Along / about the buccolingual axis.
    #[serde(default = "yes")]
    pub buccal: bool,
    /// Along / about the long (occlusal) axis.
    #[serde(default = "yes")]
    pub occlusal: bool,
}

fn yes() -> bool {
    true
}

impl Default for Freedoms {
    fn default() -> Self {
        Self {
            mesial: true,
            buccal: true,
            occlusal: true,
        }
    }
}

/// Movement constraints on some teeth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseConstraint {
    /// The constrained teeth.
    pub teeth: ToothList,
    /// Allowed translations.
    #[serde(default)]
    pub translate: Freedoms,
    /// Allowed rotations.
    #[serde(default)]
    pub rotate: Freedoms,
    /// Largest total translation from the start pose (mm).
    #[serde(default)]
    pub max_translation_mm: Option<NonNegative>,
    /// Largest total rotation from the start pose (degrees).
    #[serde(default)]
    pub max_rotation_deg: Option<NonNegative>,
}

/// A tooth's displacement from its place in the normal arch, in its anatomical frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseOffset {
    /// Translation (mm) along mesial, buccal, occlusal.
    #[serde(default)]
    pub translation: (Finite, Finite, Finite),
    /// Rotation (degrees) about the mesial (torque), buccal (tip) and occlusal (rotation) axes,
    /// about the crown centre.
    #[serde(default)]
    pub rotation_deg: (Finite, Finite, Finite),
}

/// Which teeth the patient has.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum PresentTeeth {
    /// All 32.
    #[default]
    All,
    /// Only these (others are absent: not modelled at all).
    Only(ToothList),
    /// All but these.
    AllBut(ToothList),
}

/// Bone meshes per arch, as CBCT segmentations give the maxilla and the mandible: closed
/// surfaces whose inside is bone, each a file like a tooth's in `meshes` (path relative to the
/// case file, units, transform; `Auto` takes the placement found for the case's other
/// automatically placed files, or the file's own frame without any). A root stays inside its
/// arch's bone where the segmentation covers it; an arch without one keeps the alveolar envelope.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseBone {
    /// The maxilla.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<crate::teeth::import::ToothMeshFile>,
    /// The mandible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<crate::teeth::import::ToothMeshFile>,
}

impl CaseBone {
    /// True when the case names no bone mesh.
    pub fn is_empty(&self) -> bool {
        self.upper.is_none() && self.lower.is_none()
    }
}
