//! Overjet, overbite and molar relation of placed arches.

use glam::Vec3;

use super::OcclusionMeasures;
use crate::{
    geometry::Pose,
    teeth::{fdi::Fdi, tooth_shape::ShapeSet},
};

/// Overjet, overbite and molar relation of an arrangement.
pub fn measure_occlusion(shapes: &ShapeSet, poses: &[(Fdi, Pose)]) -> OcclusionMeasures {
    let pose = |n: i64| {
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
        let (su, pu) = pose(upper_incisor);
        let (sl, pl) = pose(lower_incisor);
        let edge = pu.transform_point(su.cusp_tips[0]);
        let lower_edge = pl.transform_point(sl.cusp_tips[0]);
        overbite += lower_edge.y - edge.y;
        // The lower incisor's labial surface at the height of the upper edge.
        let labial = sl
            .mesh
            .vertices
            .iter()
            .map(|&v| pl.transform_point(v))
            .filter(|v| (v.y - edge.y).abs() < 1.0 && (v.x - edge.x).abs() < 2.0)
            .map(|v| v.z)
            .fold(f32::NEG_INFINITY, f32::max);
        overjet += if labial.is_finite() {
            edge.z - labial
        } else {
            f32::NAN
        };
        let (su, pu) = pose(upper_molar);
        let (sl, pl) = pose(lower_molar);
        let mesiobuccal = su
            .cusp_tips
            .iter()
            .map(|&c| pu.transform_point(c))
            .filter(|c| (*c - pu.translation).dot(pu.transform_vector(Vec3::Z)) > 0.0)
            .max_by(|a, b| a.z.total_cmp(&b.z))
            .unwrap_or(pu.translation);
        let groove = pl.transform_point(Vec3::new(0.0, sl.frame.crown_length, 0.0));
        molar += mesiobuccal.z - groove.z;
    }
    OcclusionMeasures {
        overjet_mm: overjet / 2.0,
        overbite_mm: overbite / 2.0,
        molar_relation_mm: molar / 2.0,
    }
}
