//! Per-tooth data computed from the mesh: mass properties, crown centre, long axis, local frame,
//! apex, root length and the centres of resistance and rotation.

use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

use crate::geometry::{MassProperties, TriMesh};

/// Where the centres of resistance and rotation lie, as fractions of the root length measured from
/// the apex towards the cervical line.
///
/// The source paper places the centre of rotation for tipping at one third of the root length from
/// the apex; the orthodontic literature places the centre of resistance of a single-rooted tooth
/// between one third and one half of the root length below the alveolar crest, that is between one
/// half and two thirds from the apex. Both are parameters; the defaults are the paper's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CentreParameters {
    /// Centre of resistance, fraction of the root length from the apex (paper: 1/3).
    pub resistance_from_apex: f32,
    /// Centre of rotation under a round wire (tipping), fraction from the apex (paper: 1/3).
    pub tipping_rotation_from_apex: f32,
}

impl Default for CentreParameters {
    fn default() -> Self {
        Self {
            resistance_from_apex: 1.0 / 3.0,
            tipping_rotation_from_apex: 1.0 / 3.0,
        }
    }
}

/// Anatomical data of one tooth mesh, in the tooth's local frame (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToothFrame {
    /// Volume (mm³).
    pub volume_mm3: f64,
    /// Centre of mass (uniform density).
    pub centre_of_mass: Vec3,
    /// Inertia tensor about the centre of mass for unit density (mm⁵).
    pub inertia: Mat3,
    /// Area-weighted centroid of the crown surface (the part above the cervical plane): the
    /// "geometric centre of the crown" of the paper's distance measure.
    pub crown_centre: Vec3,
    /// Unit long axis, from the apex towards the crown (the principal axis of inertia closest to
    /// the occlusal direction).
    pub long_axis: Vec3,
    /// Unit mesiodistal axis (x of the frame, `long_axis × buccolingual`).
    pub mesiodistal: Vec3,
    /// Unit buccolingual axis, pointing buccally (z of the frame).
    pub buccolingual: Vec3,
    /// Point on the long axis at the level of the deepest root point.
    pub apex: Vec3,
    /// Point on the long axis at the cervical plane.
    pub cervical_centre: Vec3,
    /// Distance along the long axis from the cervical plane to the apex.
    pub root_length: f32,
    /// Distance along the long axis from the cervical plane to the highest crown point.
    pub crown_length: f32,
    /// Centre of resistance (see [`CentreParameters`]).
    pub centre_of_resistance: Vec3,
    /// Centre of rotation for tipping under a round wire.
    pub centre_of_tipping: Vec3,
}

impl ToothFrame {
    /// Computes the frame of a closed tooth mesh whose cervical plane passes through `cervical` with
    /// `occlusal` (unit) as the design occlusal direction and `buccal` (unit) as the design buccal
    /// direction.
    pub fn from_mesh(
        mesh: &TriMesh,
        cervical: Vec3,
        occlusal: Vec3,
        buccal: Vec3,
        params: CentreParameters,
    ) -> Self {
        let mp = MassProperties::of(mesh);
        let (_, axes) = mp.principal_axes();
        let long_axis = [axes.x_axis, axes.y_axis, axes.z_axis]
            .into_iter()
            .max_by(|a, b| a.dot(occlusal).abs().total_cmp(&b.dot(occlusal).abs()))
            .map(|a| if a.dot(occlusal) < 0.0 { -a } else { a })
            .unwrap_or(occlusal);
        let buccolingual = (buccal - long_axis * buccal.dot(long_axis)).normalize_or(buccal);
        let mesiodistal = long_axis.cross(buccolingual);
        // The axis passes through the centre of mass; levels are measured from the cervical plane.
        let level = |p: Vec3| (p - cervical).dot(long_axis);
        let (lowest, highest) = mesh
            .vertices
            .iter()
            .map(|&v| level(v))
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l), hi.max(l))
            });
        let com = mp.centre_of_mass;
        let on_axis = |l: f32| com + long_axis * (l - level(com));
        let root_length = (-lowest).max(0.0);
        let apex = on_axis(lowest);
        let (mut area, mut weighted) = (0.0f64, glam::DVec3::ZERO);
        for i in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.triangle(i);
            let centroid = (a + b + c) / 3.0;
            if level(centroid) > 0.0 {
                let w = 0.5 * (b - a).cross(c - a).length() as f64;
                area += w;
                weighted += centroid.as_dvec3() * w;
            }
        }
        let crown_centre = if area > 0.0 {
            (weighted / area).as_vec3()
        } else {
            on_axis(highest * 0.5)
        };
        Self {
            volume_mm3: mp.volume,
            centre_of_mass: com,
            inertia: mp.inertia,
            crown_centre,
            long_axis,
            mesiodistal,
            buccolingual,
            apex,
            cervical_centre: on_axis(0.0),
            root_length,
            crown_length: highest.max(0.0),
            centre_of_resistance: apex + long_axis * (root_length * params.resistance_from_apex),
            centre_of_tipping: apex + long_axis * (root_length * params.tipping_rotation_from_apex),
        }
    }
}
