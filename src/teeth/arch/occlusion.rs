//! Overjet, overbite and molar relation, measured on teeth where they stand.
//!
//! The same measures serve the procedural arrangement (while the arches are solved) and any case's
//! placed teeth, procedural or imported (the analysis measures a dentition with them):
//!
//! - overbite: how far the upper central incisor's incisal point lies below the lower one's;
//! - overjet: from the lower incisor's labial surface, at the height of the upper incisal point,
//!   forwards to that point;
//! - molar relation: from the lower first molar's central groove forwards to the upper first
//!   molar's mesiobuccal cusp tip (0 is class I, positive is mesial of the groove);
//! - canine relation: from the embrasure between the lower canine and the next lower tooth
//!   distally, mesially along the lower arch, to the upper canine's cusp tip (0 is class I,
//!   positive is mesial of the embrasure, as in class II).

use glam::Vec3;

use super::OcclusionMeasures;
use crate::{
    geometry::Pose,
    teeth::{fdi::Fdi, tooth_shape::ShapeSet, tooth_shape::ToothGeometry},
};

/// A tooth's geometry where it stands.
pub type Placed<'a> = (&'a ToothGeometry, &'a Pose);

/// Overjet and overbite (mm) of an upper central incisor over its lower antagonist; the overjet is
/// None when no part of the lower incisor's surface lies within 1 mm of the height of the upper
/// incisal point and 2 mm of it sideways.
pub fn incisor_relation(upper: Placed, lower: Placed) -> (Option<f32>, f32) {
    let (su, pu) = upper;
    let (sl, pl) = lower;
    let edge = pu.transform_point(su.cusp_tips.first().copied().unwrap_or(Vec3::ZERO));
    let lower_edge = pl.transform_point(sl.cusp_tips.first().copied().unwrap_or(Vec3::ZERO));
    let overbite = lower_edge.y - edge.y;
    // The lower incisor's labial surface at the height of the upper edge.
    let labial = sl
        .mesh
        .vertices
        .iter()
        .map(|&v| pl.transform_point(v))
        .filter(|v| (v.y - edge.y).abs() < 1.0 && (v.x - edge.x).abs() < 2.0)
        .map(|v| v.z)
        .fold(f32::NEG_INFINITY, f32::max);
    (labial.is_finite().then_some(edge.z - labial), overbite)
}

/// Molar relation (mm) of an upper first molar over its lower antagonist.
pub fn molar_relation(upper: Placed, lower: Placed) -> f32 {
    let (su, pu) = upper;
    let (sl, pl) = lower;
    let mesiobuccal = su
        .cusp_tips
        .iter()
        .map(|&c| pu.transform_point(c))
        .filter(|c| (*c - pu.translation).dot(pu.transform_vector(Vec3::Z)) > 0.0)
        .max_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap_or(pu.translation);
    let groove = pl.transform_point(Vec3::new(0.0, sl.frame.crown_length, 0.0));
    mesiobuccal.z - groove.z
}

/// Canine relation (mm, see the module doc) of an upper canine over the lower canine and the
/// next lower tooth distally (the first premolar, or the second where the first is extracted).
pub fn canine_relation(upper: Placed, lower: Placed, distal: Placed) -> f32 {
    let (su, pu) = upper;
    let (sl, pl) = lower;
    let (sd, pd) = distal;
    // The cusp tip farthest towards occlusal (the crown's local +y).
    let tip = su
        .cusp_tips
        .iter()
        .copied()
        .max_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap_or(Vec3::new(0.0, su.frame.crown_length, 0.0));
    let tip = pu.transform_point(tip);
    let sep = crate::geometry::mesh_separation(sl.mesh_ref(), pl, sd.mesh_ref(), pd);
    let embrasure = 0.5 * (sep.point_a + sep.point_b);
    let mesial = (pl.translation - pd.translation) * Vec3::new(1.0, 0.0, 1.0);
    (tip - embrasure).dot(mesial.normalize_or_zero())
}

/// Overjet, overbite and molar relation of an arrangement (means of both sides).
pub fn measure_occlusion(shapes: &ShapeSet, poses: &[(Fdi, Pose)]) -> OcclusionMeasures {
    let shape = |n: i64| {
        let f = Fdi::new(n).expect("valid FDI");
        (
            shapes.get(f.arch(), f.kind()),
            poses
                .iter()
                .find(|(g, _)| *g == f)
                .map_or(Pose::IDENTITY, |x| x.1),
        )
    };
    let mut overjet = 0.0;
    let mut overbite = 0.0;
    let mut molar = 0.0;
    for (upper_incisor, lower_incisor, upper_molar, lower_molar) in
        [(11, 41, 16, 46), (21, 31, 26, 36)]
    {
        let (su, pu) = shape(upper_incisor);
        let (sl, pl) = shape(lower_incisor);
        let (jet, bite) = incisor_relation((&su, &pu), (&sl, &pl));
        overjet += jet.unwrap_or(f32::NAN);
        overbite += bite;
        let (su, pu) = shape(upper_molar);
        let (sl, pl) = shape(lower_molar);
        molar += molar_relation((&su, &pu), (&sl, &pl));
    }
    OcclusionMeasures {
        overjet_mm: overjet / 2.0,
        overbite_mm: overbite / 2.0,
        molar_relation_mm: molar / 2.0,
    }
}
