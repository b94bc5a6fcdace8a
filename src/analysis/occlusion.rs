//! Overjet, overbite and molar relation measured on the teeth a case has where they stand:
//! procedural, imported or scanned, with offsets, extractions and the bite opening applied.
//!
//! Each measure is the mean of the sides whose two teeth are present (not extracted): overjet and
//! overbite from the central incisors (11 over 41, 21 over 31), molar relation from the first
//! molars (16 over 46, 26 over 36). A measure with no side left is `null`, and `unmeasured` says
//! which teeth it lacks.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::teeth::{
    Dentition, Fdi, PlacedTooth,
    arch::{Placed, incisor_relation, molar_relation},
};

/// The occlusion measures of a dentition (mm).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasuredOcclusion {
    /// Horizontal distance from the lower central incisors' labial surface to the upper incisal
    /// edges (mean of the sides measured).
    pub overjet_mm: Option<f32>,
    /// Vertical overlap of the upper incisal edges over the lower ones (mean).
    pub overbite_mm: Option<f32>,
    /// Sagittal distance from the lower first molars' buccal groove to the upper first molars'
    /// mesiobuccal cusp tip (mean; 0 is class I, positive is mesial of the groove).
    pub molar_relation_mm: Option<f32>,
    /// Why a measure is missing, by its key.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub unmeasured: BTreeMap<&'static str, String>,
}

/// Measures overjet, overbite and molar relation on `d`'s present teeth.
pub fn measure_occlusion(d: &Dentition) -> MeasuredOcclusion {
    let present = |n: u8| -> Option<&PlacedTooth> {
        d.tooth(Fdi::new(i64::from(n)).ok()?)
            .filter(|t| !t.extracted)
    };
    fn placed(t: &PlacedTooth) -> Placed<'_> {
        (t.geometry.as_ref(), &t.pose)
    }
    let mut jets = Vec::new();
    let mut bites = Vec::new();
    let mut molars = Vec::new();
    let mut missing_incisors = Vec::new();
    let mut missing_molars = Vec::new();
    let mut no_overlap = Vec::new();
    for (ui, li, um, lm) in [(11u8, 41u8, 16u8, 46u8), (21, 31, 26, 36)] {
        match (present(ui), present(li)) {
            (Some(u), Some(l)) => {
                let (jet, bite) = incisor_relation(placed(u), placed(l));
                bites.push(bite);
                match jet {
                    Some(j) => jets.push(j),
                    None => no_overlap.push(format!("{ui}/{li}")),
                }
            }
            (u, l) => missing_incisors.extend(
                [(ui, u.is_none()), (li, l.is_none())]
                    .into_iter()
                    .filter(|(_, gone)| *gone)
                    .map(|(n, _)| n),
            ),
        }
        match (present(um), present(lm)) {
            (Some(u), Some(l)) => {
                molars.push(molar_relation(placed(u), placed(l)));
            }
            (u, l) => missing_molars.extend(
                [(um, u.is_none()), (lm, l.is_none())]
                    .into_iter()
                    .filter(|(_, gone)| *gone)
                    .map(|(n, _)| n),
            ),
        }
    }
    let mean = |v: &[f32]| (!v.is_empty()).then(|| v.iter().sum::<f32>() / v.len() as f32);
    let teeth = |v: &[u8]| {
        v.iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut unmeasured = BTreeMap::new();
    let incisors_gone = format!(
        "needs 11 with 41 or 21 with 31; missing or extracted: {}",
        teeth(&missing_incisors)
    );
    if bites.is_empty() {
        unmeasured.insert("overbite_mm", incisors_gone.clone());
    }
    if jets.is_empty() {
        let why = if bites.is_empty() {
            incisors_gone
        } else {
            format!(
                "the lower incisor ({}) has no surface at the height of the upper incisal edge",
                no_overlap.join(", ")
            )
        };
        unmeasured.insert("overjet_mm", why);
    }
    if molars.is_empty() {
        unmeasured.insert(
            "molar_relation_mm",
            format!(
                "needs 16 with 46 or 26 with 36; missing or extracted: {}",
                teeth(&missing_molars)
            ),
        );
    }
    MeasuredOcclusion {
        overjet_mm: mean(&jets),
        overbite_mm: mean(&bites),
        molar_relation_mm: mean(&molars),
        unmeasured,
    }
}
