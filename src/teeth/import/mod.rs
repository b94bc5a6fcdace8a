//! Real patients: tooth meshes from segmentation software (STL, OBJ, PLY), one file per tooth.
//!
//! A case names a file per tooth in `meshes` (paths relative to the case file), each with its
//! units (millimetres by default; metres and inches are converted) and an optional transform
//! (rotation in degrees about x, then y, then z, then translation in mm) that brings the scan into
//! orthosim's frame: millimetres, y towards the upper arch, z forwards (labial at the incisors), x
//! towards the patient's left, the origin between the arches at the midline.
//!
//! Each mesh is checked and repaired as real scans need ([`repair`]: welding, degenerate and
//! duplicated triangles, fins on non-manifold edges, bow-tie vertices, spikes, winding, loose
//! pieces; then every hole closed but the cervical margin, and places where the surface meets
//! itself cut out and closed again), and refused with the reason and a position only when it is
//! not one tooth (empty, NaN, several large pieces, a twisted surface, wrong units, or a
//! self-intersection that the repair cannot remove). A scanned crown (its longest opening is the
//! gum line) gets a generated root that by construction meets neither the crown nor itself
//! ([`root`]). Every repair is reported ([`Repairs`]). The tooth's frame then comes from the mesh
//! where the scan put it:
//!
//! - long axis (local y): the principal axis of inertia closest to the arch's occlusal direction
//!   (+y for the lower arch, −y for the upper), pointing occlusally;
//! - buccal axis (local z): the outward normal of the case's arch curve at the tooth, made
//!   perpendicular to the long axis; local x = y × z;
//! - origin: the cervical centre: the centroid of the margin for a scanned crown, else the point of
//!   the long axis one crown length (anatomy table) below the crown's highest point.
//!
//! So loads, wire models, constraints and the analysis work on imported teeth as on procedural
//! ones; the tooth stands exactly where the scan has it (its pose maps the local mesh back).

mod close;
mod error;
mod export;
mod fill;
mod mend;
mod read;
pub mod repair;
pub mod root;

use std::path::Path;

use glam::{Mat3, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use super::{
    anatomy::anatomy,
    arch::ArchCurve,
    case::Finite,
    fdi::{Arch, Fdi, ToothKind},
    tooth_shape::ToothGeometry,
};
use crate::geometry::{MassProperties, Pose, TriMesh};

pub use error::{ImportError, Near, PlyProblem};
pub use export::{ExportMeshes, ExportReport, export_case, export_case_as};
pub use read::{MeshFormat, read_mesh, write_stl};
pub use repair::{RepairLimits, Repairs};

/// Units of a mesh file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Units {
    /// Millimetres (what segmentation software usually writes).
    #[default]
    Millimetres,
    /// Metres.
    Metres,
    /// Inches.
    Inches,
}

impl Units {
    /// Millimetres per unit.
    pub fn mm(self) -> f32 {
        match self {
            Units::Millimetres => 1.0,
            Units::Metres => 1000.0,
            Units::Inches => 25.4,
        }
    }
}

/// A rigid transform applied to a mesh after unit conversion: rotation (degrees about x, then y,
/// then z), then translation (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshTransform {
    /// Translation (mm).
    #[serde(default)]
    pub translation: (Finite, Finite, Finite),
    /// Rotation (degrees) about x, y and z, applied in that order.
    #[serde(default)]
    pub rotation_deg: (Finite, Finite, Finite),
}

impl MeshTransform {
    /// The transform as a pose.
    pub fn pose(&self) -> Pose {
        let (rx, ry, rz) = self.rotation_deg;
        let rotation = Quat::from_rotation_z(rz.0.to_radians())
            * Quat::from_rotation_y(ry.0.to_radians())
            * Quat::from_rotation_x(rx.0.to_radians());
        let (x, y, z) = self.translation;
        Pose::new(rotation, Vec3::new(x.0, y.0, z.0))
    }
}

/// A tooth's mesh file in a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToothMeshFile {
    /// Path, relative to the case file.
    pub file: String,
    /// Units of the file's coordinates.
    #[serde(default)]
    pub units: Units,
    /// Transform into orthosim's frame.
    #[serde(default)]
    pub transform: MeshTransform,
}

/// The least extent of a tooth mesh (mm): smaller ones are refused (wrong units, or not a tooth).
pub const MIN_SPAN_MM: f32 = 2.0;
/// The largest extent of a tooth mesh (mm), loose pieces dropped.
pub const MAX_SPAN_MM: f32 = 80.0;
/// A file spanning more than this (mm), loose pieces included, is refused before any repair.
pub const ABSURD_SPAN_MM: f32 = 10_000.0;

/// The longest opening is taken for a crown's cervical margin (and closed by a generated root)
/// only when the direction away from the crown through it is within 90° of the arch's apical
/// direction (a scan's frame is rarely exact, so the test is loose).
pub const MARGIN_COS: f32 = 0.0;

/// An imported tooth: its geometry in its own frame and where the scan put it.
#[derive(Debug)]
pub struct ImportedTooth {
    /// Geometry in the tooth's local frame.
    pub geometry: ToothGeometry,
    /// Pose of the local frame (orthosim's world frame).
    pub pose: Pose,
    /// What was repaired.
    pub repairs: Repairs,
}

/// Reads, repairs and frames the mesh of tooth `fdi` from `path`; `curve` is the arch curve of
/// the tooth's arch (for its buccal direction).
///
/// # Errors
/// What is wrong and where, without the path ([`ImportError`]).
pub fn import_tooth(
    path: &Path,
    spec: &ToothMeshFile,
    fdi: Fdi,
    curve: &ArchCurve,
    limits: &RepairLimits,
) -> Result<ImportedTooth, ImportError> {
    let raw = read_mesh(path)?;
    let transform = spec.transform.pose();
    let scale = spec.units.mm();
    let world = raw.map_vertices(|v| transform.transform_point(v * scale));
    import_mesh(&world, fdi, curve, limits)
}

/// [`import_tooth`] for a mesh already read, in orthosim's frame (mm).
///
/// # Errors
/// What is wrong and where ([`ImportError`]).
pub fn import_mesh(
    world: &TriMesh,
    fdi: Fdi,
    curve: &ArchCurve,
    limits: &RepairLimits,
) -> Result<ImportedTooth, ImportError> {
    let an = anatomy(fdi.arch(), fdi.kind());
    // Absurd sizes (far beyond any unit mix-up with debris) are refused before any repair.
    if world.vertices.iter().all(|v| v.is_finite()) && !world.vertices.is_empty() {
        let span = world.aabb().extent().max_element();
        if span > ABSURD_SPAN_MM {
            return Err(ImportError::Span {
                span_mm: span,
                min_mm: MIN_SPAN_MM,
                max_mm: MAX_SPAN_MM,
            });
        }
    }
    let mut repairs = Repairs::default();
    let crown = repair::clean(world, limits, &mut repairs)?;
    // The span of the tooth itself, loose pieces dropped: wrong units show here.
    let span = repair::used_span(&crown);
    if !(MIN_SPAN_MM..=MAX_SPAN_MM).contains(&span) {
        return Err(ImportError::Span {
            span_mm: span,
            min_mm: MIN_SPAN_MM,
            max_mm: MAX_SPAN_MM,
        });
    }
    let close::Closed { mesh, cervical } =
        close::close(crown, fdi, an.root_length, limits, &mut repairs)?;
    let pose = tooth_pose(&mesh, fdi, curve, cervical, an.crown_length);
    let inverse = pose.inverse();
    let local = mesh.map_vertices(|v| inverse.transform_point(v));
    let geometry = ToothGeometry::imported(fdi.arch(), fdi.kind(), local);
    Ok(ImportedTooth {
        geometry,
        pose,
        repairs,
    })
}

/// The occlusal direction of an arch in orthosim's frame.
pub fn occlusal_direction(arch: Arch) -> Vec3 {
    match arch {
        Arch::Upper => Vec3::NEG_Y,
        Arch::Lower => Vec3::Y,
    }
}

/// The frame of a tooth mesh placed in the world (see the module doc).
fn tooth_pose(
    mesh: &TriMesh,
    fdi: Fdi,
    curve: &ArchCurve,
    cervical: Option<Vec3>,
    crown_length: f32,
) -> Pose {
    let occlusal = occlusal_direction(fdi.arch());
    let mass = MassProperties::of(mesh);
    let (_, axes) = mass.principal_axes();
    let mut y = [axes.x_axis, axes.y_axis, axes.z_axis]
        .into_iter()
        .max_by(|a, b| a.dot(occlusal).abs().total_cmp(&b.dot(occlusal).abs()))
        .unwrap_or(occlusal);
    if y.dot(occlusal) < 0.0 {
        y = -y;
    }
    let com = mass.centre_of_mass;
    let origin = cervical.unwrap_or_else(|| {
        let top = mesh
            .vertices
            .iter()
            .map(|v| v.dot(y))
            .fold(f32::NEG_INFINITY, f32::max);
        com + y * (top - crown_length - com.dot(y))
    });
    let s = curve.project(Vec2::new(com.x, com.z));
    let (_, tangent) = curve.at(s);
    let outward = Vec3::new(-tangent.y, 0.0, tangent.x);
    let z = (outward - y * outward.dot(y)).normalize_or(Vec3::Z);
    let x = y.cross(z).normalize();
    let z = x.cross(y);
    Pose::new(
        Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize(),
        origin,
    )
}

/// Cusp tips (local frame) of an imported tooth: the highest vertex of each of the type's cusp
/// regions (one for incisors and canines, buccal and lingual halves for premolars, four quadrants
/// for molars).
pub(super) fn cusp_tips(mesh: &TriMesh, kind: ToothKind) -> Vec<Vec3> {
    let regions: &[fn(Vec3) -> bool] = match kind {
        ToothKind::CentralIncisor | ToothKind::LateralIncisor | ToothKind::Canine => &[|_| true],
        ToothKind::FirstPremolar | ToothKind::SecondPremolar => {
            &[|v: Vec3| v.z >= 0.0, |v: Vec3| v.z < 0.0]
        }
        _ => &[
            |v: Vec3| v.z >= 0.0 && v.x >= 0.0,
            |v: Vec3| v.z >= 0.0 && v.x < 0.0,
            |v: Vec3| v.z < 0.0 && v.x >= 0.0,
            |v: Vec3| v.z < 0.0 && v.x < 0.0,
        ],
    };
    regions
        .iter()
        .filter_map(|inside| {
            mesh.vertices
                .iter()
                .copied()
                .filter(|v| inside(*v))
                .max_by(|a, b| a.y.total_cmp(&b.y))
        })
        .collect()
}
