//! `inspect`: per-tooth mesh data and exact gaps and penetrations of a case's teeth.
//!
//! Every figure is computed from the meshes: `closed` is [`TriMesh::validate_solid`]'s verdict,
//! gaps and penetrations come from the exact mesh–mesh query
//! ([`crate::geometry::mesh_separation`]).

use glam::Vec3;
use serde::Serialize;

use crate::{
    analysis::occlusion::{MeasuredOcclusion, measure_occlusion},
    geometry::{MeshError, TriMesh, mesh_separation},
    teeth::{Dentition, PlacedTooth},
};

/// One tooth's line of the report.
#[derive(Clone, Debug, Serialize)]
pub struct ToothReport {
    /// FDI number.
    pub fdi: u8,
    /// Kind (snake_case).
    pub kind: &'static str,
    /// "upper" or "lower".
    pub arch: &'static str,
    /// Mesh vertices.
    pub vertices: usize,
    /// Mesh triangles.
    pub triangles: usize,
    /// True when the mesh is closed, manifold, outward, finite and free of self-intersection.
    pub closed: bool,
    /// Why it is not, when it is not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_error: Option<String>,
    /// Enclosed volume (mm³).
    pub volume_mm3: f64,
    /// Crown centre, world frame (mm).
    pub crown_centre: [f32; 3],
    /// Extracted tooth.
    pub extracted: bool,
    /// The root generated for a scanned crown: which kind, its length and its axis's angle to the
    /// margin's normal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub root: Option<crate::teeth::import::RootReport>,
}

/// The exact gap between two adjacent teeth.
#[derive(Clone, Debug, Serialize)]
pub struct NeighbourGap {
    /// First tooth.
    pub a: u8,
    /// Second tooth.
    pub b: u8,
    /// Minimal surface distance (mm), negative when they overlap (minus the penetration depth).
    pub gap_mm: f32,
    /// Where two overlapping teeth meet deepest, when they overlap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overlap: Option<Overlap>,
}

/// Where two neighbours overlap: the deepest point and, on each tooth, whether it lies in the
/// crown or the root (above or below the tooth's cervical line, along its long axis).
#[derive(Clone, Debug, Serialize)]
pub struct Overlap {
    /// Midpoint of the deepest points of the two surfaces, world frame (mm).
    pub at: [f32; 3],
    /// "crown" or "root" on the first tooth.
    pub level_a: &'static str,
    /// "crown" or "root" on the second tooth.
    pub level_b: &'static str,
}

/// "crown" when world point `p` lies above tooth `t`'s cervical line along its long axis, else
/// "root".
fn level(t: &PlacedTooth, p: Vec3) -> &'static str {
    let f = &t.geometry.frame;
    let local = t.pose.inverse().transform_point(p);
    if (local - f.cervical_centre).dot(f.long_axis) >= 0.0 {
        "crown"
    } else {
        "root"
    }
}

/// The whole report of `orthosim inspect`.
#[derive(Clone, Debug, Serialize)]
pub struct InspectReport {
    /// Case name.
    pub case: String,
    /// Where the case came from.
    pub origin: String,
    /// Target vertices per tooth.
    pub resolution: u32,
    /// Teeth in FDI order.
    pub teeth: Vec<ToothReport>,
    /// Adjacent visible teeth along each arch (extracted ones skipped).
    pub neighbour_gaps_mm: Vec<NeighbourGap>,
    /// Deepest penetration between any two visible teeth of the same arch (mm, 0 when none).
    pub max_penetration_mm: f32,
    /// Deepest penetration between an upper and a lower visible tooth (mm, 0 when none).
    pub occlusal_max_penetration_mm: f32,
    /// Least gap between the arches (mm; negative when they overlap).
    pub occlusal_min_gap_mm: f32,
    /// Overjet, overbite and molar relation measured on the teeth present, where they stand.
    pub occlusion: MeasuredOcclusion,
    /// Little's irregularity index and arch-length discrepancy, upper then lower arch.
    pub alignment: [ArchAlignment; 2],
    /// Teeth read from mesh files, with what was repaired in each.
    pub imported: Vec<ImportedMesh>,
    /// Where the case's mesh and scan files were placed (empty without them).
    pub orientation: Vec<crate::teeth::OrientationReport>,
    /// What the import of each labelled scan changed in its labels or left out (empty without
    /// scans).
    pub scans: Vec<crate::teeth::ScanReport>,
}

/// How aligned an arch's teeth stand.
#[derive(Clone, Debug, Serialize)]
pub struct ArchAlignment {
    /// "upper" or "lower".
    pub arch: &'static str,
    /// Little's irregularity index (mm; None when an anterior tooth is missing).
    pub irregularity_mm: Option<f32>,
    /// Its five displacements, canine to canine: `(a, b, mm)`.
    pub contacts: Vec<(u8, u8, f32)>,
    /// Space available minus space required, first molar to first molar (mm; negative:
    /// crowding; None without both first molars).
    pub arch_length_discrepancy_mm: Option<f32>,
}

fn alignment(d: &Dentition) -> [ArchAlignment; 2] {
    use crate::teeth::{
        Arch,
        arch::irregularity::{Anterior, displacements},
    };
    let anteriors: Vec<Anterior> = d
        .visible()
        .map(|t| Anterior {
            fdi: t.fdi,
            geometry: &t.geometry,
            pose: t.pose,
        })
        .collect();
    let posed = super::measures::Posed::of_dentition(d);
    let arches = super::measures::arch_positions(&posed);
    let width = |f: crate::teeth::Fdi| {
        d.tooth(f)
            .map_or(f32::NAN, |t| t.geometry.anatomy.mesiodistal)
    };
    let bolton = super::measures::bolton(width, [&arches[0], &arches[1]]);
    let one = |arch: Arch, name: &'static str, discrepancy: f32| {
        let pairs = displacements(&anteriors, &d.contact_points, arch);
        ArchAlignment {
            arch: name,
            irregularity_mm: pairs.map(|p| p.iter().map(|c| c.mm).sum()),
            contacts: pairs.map_or_else(Vec::new, |p| {
                p.iter()
                    .map(|c| (c.a.number(), c.b.number(), c.mm))
                    .collect()
            }),
            arch_length_discrepancy_mm: discrepancy.is_finite().then_some(discrepancy),
        }
    };
    [
        one(
            Arch::Upper,
            "upper",
            bolton.arch_length_discrepancy_upper_mm,
        ),
        one(
            Arch::Lower,
            "lower",
            bolton.arch_length_discrepancy_lower_mm,
        ),
    ]
}

/// A tooth read from a mesh file.
#[derive(Clone, Debug, Serialize)]
pub struct ImportedMesh {
    /// FDI number.
    pub fdi: u8,
    /// One line: what was repaired ("nothing" when the mesh was clean).
    pub summary: String,
    /// The repairs in detail.
    pub repairs: crate::teeth::import::Repairs,
}

fn signed_gap(a: &PlacedTooth, b: &PlacedTooth) -> f32 {
    separation(a, b).signed_gap()
}

fn separation(a: &PlacedTooth, b: &PlacedTooth) -> crate::geometry::MeshSeparation {
    mesh_separation(
        a.geometry.mesh_ref(),
        &a.pose,
        b.geometry.mesh_ref(),
        &b.pose,
    )
}

/// Reports on mesh `m`'s validity.
fn validity(m: &TriMesh) -> Result<(), MeshError> {
    m.validate_solid().map(|_| ())
}

/// Computes the report of a dentition.
pub fn inspect(d: &Dentition) -> InspectReport {
    // Teeth of one type share a mesh: validate each distinct mesh once.
    let mut verdicts: std::collections::HashMap<usize, Result<(), MeshError>> = Default::default();
    let teeth = d
        .teeth
        .iter()
        .map(|t| {
            let m = &t.geometry.mesh;
            let valid = verdicts
                .entry(std::sync::Arc::as_ptr(&t.geometry) as usize)
                .or_insert_with(|| validity(m))
                .clone();
            ToothReport {
                fdi: t.fdi.number(),
                kind: t.fdi.kind().name(),
                arch: match t.fdi.arch() {
                    crate::teeth::Arch::Upper => "upper",
                    crate::teeth::Arch::Lower => "lower",
                },
                vertices: m.vertices.len(),
                triangles: m.triangles.len(),
                closed: valid.is_ok(),
                mesh_error: valid.err().map(|e| e.to_string()),
                volume_mm3: t.geometry.frame.volume_mm3,
                crown_centre: t.crown_centre().to_array(),
                extracted: t.extracted,
                root: d.imported.get(&t.fdi).and_then(|r| r.root.clone()),
            }
        })
        .collect();
    let neighbour_gaps_mm = d
        .neighbour_pairs()
        .into_iter()
        .filter_map(|(a, b)| Some((d.tooth(a)?, d.tooth(b)?)))
        .map(|(a, b)| {
            let s = separation(a, b);
            let gap_mm = s.signed_gap();
            let overlap = (gap_mm < 0.0).then(|| {
                let at = 0.5 * (s.point_a + s.point_b);
                Overlap {
                    at: at.to_array(),
                    level_a: level(a, at),
                    level_b: level(b, at),
                }
            });
            NeighbourGap {
                a: a.fdi.number(),
                b: b.fdi.number(),
                gap_mm,
                overlap,
            }
        })
        .collect();
    let visible: Vec<&PlacedTooth> = d.visible().collect();
    let (mut same_arch, mut occlusal, mut occlusal_gap) = (0.0f32, 0.0f32, f32::INFINITY);
    for (i, a) in visible.iter().enumerate() {
        for b in &visible[i + 1..] {
            // Teeth whose bounding spheres are apart cannot touch.
            let (ra, rb) = (bounding_radius(a), bounding_radius(b));
            let (ca, cb) = (a.pose.translation, b.pose.translation);
            let same = a.fdi.arch() == b.fdi.arch();
            if ca.distance(cb) > ra + rb {
                continue;
            }
            let g = signed_gap(a, b);
            if same {
                same_arch = same_arch.max(-g);
            } else {
                occlusal = occlusal.max(-g);
                occlusal_gap = occlusal_gap.min(g);
            }
        }
    }
    InspectReport {
        case: d.case.case.name.clone(),
        origin: d.case.origin.clone(),
        resolution: d.case.case.tooth_resolution().vertices,
        teeth,
        neighbour_gaps_mm,
        max_penetration_mm: same_arch,
        occlusal_max_penetration_mm: occlusal,
        occlusal_min_gap_mm: occlusal_gap,
        occlusion: measure_occlusion(d),
        alignment: alignment(d),
        imported: d
            .imported
            .iter()
            .map(|(f, r)| ImportedMesh {
                fdi: f.number(),
                summary: r.summary(),
                repairs: r.clone(),
            })
            .collect(),
        orientation: d.orientation.clone(),
        scans: d.scans.clone(),
    }
}

/// Radius about the local origin that bounds the tooth.
fn bounding_radius(t: &PlacedTooth) -> f32 {
    t.geometry
        .mesh
        .vertices
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max)
}
