//! Real patients: tooth meshes from segmentation software (STL, OBJ, PLY), one file per tooth or
//! one labelled mesh per arch ([`Labels`]).
//!
//! A case names a file per tooth in `meshes` and labelled whole-arch scans in `scans` (paths
//! relative to the case file), each with its units (millimetres by default; metres and inches are
//! converted) and a [`Placement`]: `Auto` (the default) lets orthosim find the frame from the
//! labelled teeth ([`orient`]), `Identity` keeps the file's coordinates, and a transform (rotation
//! in degrees about x, then y, then z, then translation in mm) brings the file into orthosim's
//! frame: millimetres, y towards the upper arch, z forwards (labial at the incisors), x towards the
//! patient's left, the origin between the arches at the midline.
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
//! - buccal axis (local z): the outward normal of the arch curve at the tooth (the arrangement's
//!   form fitted to the teeth present), made perpendicular to the long axis; local x = y × z;
//! - origin: the cervical centre: the centroid of the margin for a scanned crown, else the point of
//!   the long axis one crown length (anatomy table) below the crown's highest point.
//!
//! So loads, wire models, constraints and the analysis work on imported teeth as on procedural
//! ones; the tooth stands exactly where the scan has it (its pose maps the local mesh back).

pub mod apart;
mod bone;
mod close;
mod error;
mod export;
mod fill;
mod labels;
mod mend;
pub mod orient;
mod read;
pub mod rebuild;
pub mod repair;
pub mod root;
pub mod segments;
pub mod sweep;
pub mod template;

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

pub use bone::read_bone;
pub use error::{ImportError, Near, PlyProblem};
pub use export::{
    ExportMeshes, ExportReport, export_case, export_case_as, export_labelled_scans,
    export_labelled_scans_with,
};
pub use labels::{LabelledMesh, Labels, check_raw, check_scan, read_labelled, split};
pub use read::{MeshFormat, read_mesh, write_stl};
pub use rebuild::{Rebuilt, rebuild};
pub use repair::{RepairLimits, Repairs, RootReport};
pub use segments::{CrownAxis, LabelFix, tidy_labels, trim_bleed};

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

/// Where a mesh file's coordinates are: found by orthosim from the labelled teeth (`Auto`, the
/// default), already orthosim's frame (`Identity`), or brought there by a given transform
/// (`(translation: (x, y, z), rotation_deg: (x, y, z))`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Placement {
    /// Placed by orthosim: see [`orient`].
    #[default]
    Auto,
    /// The file is in orthosim's frame (after units).
    Identity,
    /// This transform brings the file (after units) into orthosim's frame.
    Rigid(MeshTransform),
}

impl Placement {
    /// The transform, `None` for `Auto`.
    pub fn pose(&self) -> Option<Pose> {
        match self {
            Placement::Auto => None,
            Placement::Identity => Some(Pose::IDENTITY),
            Placement::Rigid(t) => Some(t.pose()),
        }
    }
}

impl Serialize for Placement {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Placement::Auto => s.serialize_unit_variant("Placement", 0, "Auto"),
            Placement::Identity => s.serialize_unit_variant("Placement", 1, "Identity"),
            Placement::Rigid(t) => t.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Placement {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        #[derive(Deserialize)]
        #[serde(
            untagged,
            expecting = "a transform: Auto, Identity or (translation: (x, y, z), rotation_deg: (x, y, z))"
        )]
        enum Raw {
            Word(String),
            Fields(std::collections::BTreeMap<String, (f64, f64, f64)>),
        }
        match Raw::deserialize(d)? {
            Raw::Word(w) if w == "Auto" => Ok(Placement::Auto),
            Raw::Word(w) if w == "Identity" => Ok(Placement::Identity),
            Raw::Word(w) => Err(D::Error::custom(format!(
                "unknown transform `{w}`: Auto, Identity or (translation: (x, y, z), rotation_deg: (x, y, z))"
            ))),
            Raw::Fields(fields) => {
                let mut t = MeshTransform::default();
                for (name, (a, b, c)) in fields {
                    let mut triple = (Finite(0.0), Finite(0.0), Finite(0.0));
                    for (slot, v) in [&mut triple.0, &mut triple.1, &mut triple.2]
                        .into_iter()
                        .zip([a, b, c])
                    {
                        if !v.is_finite() || v.abs() > f32::MAX as f64 {
                            return Err(D::Error::custom(format!(
                                "number must be finite, got {v}"
                            )));
                        }
                        *slot = Finite(v as f32);
                    }
                    match name.as_str() {
                        "translation" => t.translation = triple,
                        "rotation_deg" => t.rotation_deg = triple,
                        other => {
                            return Err(D::Error::custom(format!(
                                "unknown field `{other}` of a transform, expected `translation` or `rotation_deg`"
                            )));
                        }
                    }
                }
                Ok(Placement::Rigid(t))
            }
        }
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
    /// Where the file's frame is.
    #[serde(default)]
    pub transform: Placement,
}

/// A labelled whole-arch scan in a case: each labelled tooth becomes a scanned crown.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanFile {
    /// Path of the mesh, relative to the case file.
    pub file: String,
    /// How its teeth are labelled.
    pub labels: Labels,
    /// Units of the file's coordinates.
    #[serde(default)]
    pub units: Units,
    /// Where the file's frame is.
    #[serde(default)]
    pub transform: Placement,
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

/// Reads a tooth's or scan's mesh file, in millimetres, in the file's own frame.
///
/// # Errors
/// What is wrong and where, without the path ([`ImportError`]).
pub fn read_in_mm(path: &Path, units: Units) -> Result<TriMesh, ImportError> {
    let raw = read_mesh(path)?;
    let scale = units.mm();
    Ok(raw.map_vertices(|v| v * scale))
}

/// Reads, repairs and frames the mesh of tooth `fdi` from `path`, placed by its own transform
/// (`Auto` is taken as `Identity` here: automatic placement needs the case's other teeth, see
/// [`orient`]); `curve` is the arch curve of the tooth's arch (for its buccal direction).
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
    let transform = spec.transform.pose().unwrap_or(Pose::IDENTITY);
    let world = read_in_mm(path, spec.units)?.map_vertices(|v| transform.transform_point(v));
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
    Ok(prepare(world, fdi, limits)?.frame(fdi, curve))
}

/// A tooth mesh repaired and closed where the scan put it, not yet framed.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The closed mesh in orthosim's frame.
    pub mesh: TriMesh,
    /// The centroid of the cervical margin, for a scanned crown.
    pub cervical: Option<Vec3>,
    /// The generated root's apical direction (unit), for a scanned crown.
    pub apical: Option<Vec3>,
    /// The crown's anatomical orientation (world) from its fitted template, when it has one.
    pub crown_rotation: Option<Quat>,
    /// What was repaired.
    pub repairs: Repairs,
}

/// Checks and repairs a tooth mesh in orthosim's frame (mm), and closes a scanned crown with a
/// generated root.
///
/// # Errors
/// What is wrong and where ([`ImportError`]).
pub fn prepare(world: &TriMesh, fdi: Fdi, limits: &RepairLimits) -> Result<Prepared, ImportError> {
    prepare_guided(world, fdi, limits, RootGuide::default())
}

/// The share of a crown's triangles the untrimmed retry of [`prepare_guided`] may cut out.
pub const UNTRIMMED_CUT_FRACTION: f32 = 0.25;

/// How a scanned crown's template root is placed: where the fit starts, and how the fitted root
/// is then turned and shortened (to keep it out of its neighbours' roots).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RootGuide {
    /// The pose of the tooth's local frame in the arrangement, where the fit starts (it also
    /// starts from the crown's margin).
    pub guess: Option<Pose>,
    /// A turn (rotation vector, radians, world) of the root about its cervical centre.
    pub tilt: Vec3,
    /// Share of the template's root length taken off (0–1).
    pub shorten: f32,
    /// How far (radians) [`apart::keep_roots_apart`] has turned the root so far (part of `tilt`).
    pub turned_apart: f32,
}

impl RootGuide {
    /// The fit turned and shortened as this guide says.
    pub(super) fn applied_to(&self, mut fit: template::Fit) -> template::Fit {
        fit.rotation = (Quat::from_scaled_axis(self.tilt) * fit.rotation).normalize();
        fit.scale.y *= 1.0 - self.shorten.clamp(0.0, 0.9);
        fit
    }
}

/// [`prepare`], a scanned crown's template root fitted and placed as `guide` says. A crown whose
/// template root cannot be closed gets the cone root, and the report says why.
///
/// # Errors
/// What is wrong and where ([`ImportError`]).
pub fn prepare_guided(
    world: &TriMesh,
    fdi: Fdi,
    limits: &RepairLimits,
    guide: RootGuide,
) -> Result<Prepared, ImportError> {
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
    let crown = clean_tooth(world, limits, &mut repairs)?;
    let cleaned = repairs.clone();
    let template = close::RootChoice::Template(guide);
    // The template root, then the cone; a steep, folded margin that its trimming leaves crossing
    // the root gets both again on its whole margin, untrimmed. The cone's error is reported.
    let attempts = [
        (template, close::MAX_TRIMS),
        (close::RootChoice::Cone, close::MAX_TRIMS),
        (template, 0),
        (close::RootChoice::Cone, 0),
    ];
    // The template's own error (for the cone's report), and the cone's (for the caller).
    let (mut template_error, mut reported): (Option<String>, Option<ImportError>) = (None, None);
    let mut closed = None;
    // Untrimmed, the crossings are cut out instead: at most a quarter of the crown, so a crown
    // that would lose more is rebuilt from its whole scanned surface.
    let untrimmed = RepairLimits {
        max_cut_fraction: limits.max_cut_fraction.min(UNTRIMMED_CUT_FRACTION),
        ..*limits
    };
    for (k, (choice, trims)) in attempts.into_iter().enumerate() {
        let mut tried = cleaned.clone();
        let l = if trims == 0 { &untrimmed } else { limits };
        match close::close(
            crown.clone(),
            fdi,
            an.root_length,
            l,
            &mut tried,
            choice,
            trims,
        ) {
            Ok(c) => {
                if k > 0
                    && let Some(r) = &mut tried.root
                    && r.kind == "cone"
                    && let Some(e) = &template_error
                {
                    r.fallback = Some(format!("the template root could not be closed: {e}"));
                }
                repairs = tried;
                closed = Some(c);
                break;
            }
            Err(e) => {
                // Only a mesh that crosses itself gets the later attempts.
                let crossing = matches!(e, ImportError::SelfIntersecting { .. });
                if k == 0 {
                    template_error = Some(e.to_string());
                }
                if k <= 1 {
                    reported = Some(e);
                }
                if !crossing && k >= 1 {
                    break;
                }
            }
        }
    }
    let Some(close::Closed {
        mesh,
        cervical,
        apical,
        crown_rotation,
    }) = closed
    else {
        return Err(reported.expect("the first attempts failed"));
    };
    Ok(Prepared {
        mesh,
        cervical,
        apical,
        crown_rotation,
        repairs,
    })
}

/// The tooth's surface cleaned ([`repair::clean`]) and its span checked: the span of the tooth
/// itself, loose pieces dropped, is where wrong units show.
fn clean_tooth(
    world: &TriMesh,
    limits: &RepairLimits,
    repairs: &mut Repairs,
) -> Result<TriMesh, ImportError> {
    let crown = repair::clean(world, limits, repairs)?;
    let span = repair::used_span(&crown);
    if !(MIN_SPAN_MM..=MAX_SPAN_MM).contains(&span) {
        return Err(ImportError::Span {
            span_mm: span,
            min_mm: MIN_SPAN_MM,
            max_mm: MAX_SPAN_MM,
        });
    }
    Ok(crown)
}

/// [`prepare`], and when the repair cannot make a valid solid, the tooth [`rebuild()`]t instead.
///
/// # Errors
/// What makes the mesh no tooth at all (see [`rebuild()`]); the repair's own error when the
/// rebuild fails too.
pub fn prepare_or_rebuild(
    world: &TriMesh,
    fdi: Fdi,
    limits: &RepairLimits,
    guide: RootGuide,
) -> Result<Prepared, ImportError> {
    match prepare_guided(world, fdi, limits, guide) {
        Ok(p) => Ok(p),
        Err(e) if !e.is_repairable() => Err(e),
        Err(e) => rebuild::rebuild_guided(world, fdi, limits, &e, guide).map_err(|_| e),
    }
}

impl Prepared {
    /// The pose of the tooth's frame on the arch `curve` (see the module doc), without building
    /// its geometry.
    pub fn pose(&self, fdi: Fdi, curve: &ArchCurve) -> Pose {
        let an = anatomy(fdi.arch(), fdi.kind());
        tooth_pose(&self.mesh, fdi, curve, self.cervical, an.crown_length)
    }

    /// The tooth framed on the arch `curve` (see the module doc).
    pub fn frame(&self, fdi: Fdi, curve: &ArchCurve) -> ImportedTooth {
        let pose = self.pose(fdi, curve);
        let inverse = pose.inverse();
        let local = self.mesh.map_vertices(|v| inverse.transform_point(v));
        let mut geometry = ToothGeometry::imported(fdi.arch(), fdi.kind(), local);
        if let Some(mut r) = self.crown_rotation {
            // Premolar and molar crowns fit their template about as well turned half round
            // their long axis; the crown's buccal side is the one facing out of the arch.
            if (r * Vec3::Z).dot(pose.rotation * Vec3::Z) < 0.0 {
                r = Quat::from_axis_angle(r * Vec3::Y, std::f32::consts::PI) * r;
            }
            geometry.axes = (pose.rotation.inverse() * r).normalize();
        }
        ImportedTooth {
            geometry,
            pose,
            repairs: self.repairs.clone(),
        }
    }
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
