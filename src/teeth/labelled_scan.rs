//! Scan-like labelled whole arches: what segmentation software exports for a patient, made from
//! a case's teeth so it can ship with orthosim and be used in tests.
//!
//! An arch is the scan-like crowns of its teeth ([`super::scan_like`]: open at a scalloped gum
//! line, with noise, holes, spikes, non-manifold spots, folds and debris) where the case places
//! them, plus a gum: a wavy band along the arch below the crowns, labelled 0. Every vertex
//! carries its tooth's FDI number. The whole is then moved into a random scanner frame (random
//! rotation, translation and units), and written as PLY with a per-vertex `label` property, as
//! PLY with per-vertex colours, or as OBJ with a JSON label file (the public segmentation
//! benchmarks' convention).

use std::fmt::Write as _;

use glam::{Quat, Vec3};

use super::{
    Dentition,
    fdi::{Arch, Fdi},
    import::Units,
    scan_like::{ScanDefects, scan_like_crown},
};
use crate::geometry::{Pose, TriMesh, rng::Rng};

/// A whole-arch scan with a label per vertex (FDI number, 0 for gum).
#[derive(Clone, Debug)]
pub struct LabelledArch {
    /// The arch.
    pub arch: Arch,
    /// The mesh (crowns and gum, separate pieces).
    pub mesh: TriMesh,
    /// FDI number or 0 per vertex.
    pub labels: Vec<u32>,
}

/// A scanner's frame: where it puts orthosim's frame, and its units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScannerFrame {
    /// From orthosim's frame (mm) to the scanner's (mm, before units).
    pub pose: Pose,
    /// Units of the written coordinates.
    pub units: Units,
}

impl ScannerFrame {
    /// A random frame: any rotation, a translation of up to 100 mm per axis, and millimetres,
    /// metres or inches.
    pub fn random(seed: u64) -> Self {
        let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let axis = rng.unit();
        let angle = rng.uniform() * std::f32::consts::PI;
        let translation = rng.vec(100.0);
        let units = match (rng.uniform() * 3.0) as u32 {
            0 => Units::Millimetres,
            1 => Units::Metres,
            _ => Units::Inches,
        };
        Self {
            pose: Pose::new(Quat::from_axis_angle(axis, angle), translation),
            units,
        }
    }

    /// A mesh from orthosim's frame into this one (coordinates in its units).
    pub fn apply(&self, mesh: &TriMesh) -> TriMesh {
        let scale = 1.0 / self.units.mm();
        mesh.map_vertices(|v| self.pose.transform_point(v) * scale)
    }
}

/// The colour a generated colour-labelled scan gives a tooth (distinct for all 32).
pub fn tooth_colour(fdi: Fdi) -> (u8, u8, u8) {
    let n = u32::from(fdi.number());
    (
        (40 + (n * 53) % 200) as u8,
        (30 + (n * 97) % 210) as u8,
        (20 + (n * 151) % 220) as u8,
    )
}

/// The gum's colour in a generated colour-labelled scan.
pub const GUM_COLOUR: (u8, u8, u8) = (230, 150, 160);

/// The labelled arch of `d`'s visible teeth of `arch` in orthosim's frame: scan-like crowns of
/// about `triangles` triangles each, with typical defects drawn from `seed`, and a gum band.
pub fn labelled_arch(d: &Dentition, arch: Arch, triangles: usize, seed: u64) -> LabelledArch {
    let mut mesh = TriMesh::default();
    let mut labels = Vec::new();
    let teeth: Vec<_> = d.visible().filter(|t| t.fdi.arch() == arch).collect();
    for t in &teeth {
        let s = seed
            .wrapping_mul(100)
            .wrapping_add(u64::from(t.fdi.number()));
        let crown = scan_like_crown(
            arch,
            t.fdi.kind(),
            &t.pose,
            triangles,
            &ScanDefects::typical(s),
            s,
        );
        append(
            &mut mesh,
            &mut labels,
            &crown.mesh,
            u32::from(t.fdi.number()),
        );
    }
    let gum = gum_band(&teeth.iter().map(|t| t.pose).collect::<Vec<_>>(), arch);
    append(&mut mesh, &mut labels, &gum, 0);
    LabelledArch { arch, mesh, labels }
}

fn append(mesh: &mut TriMesh, labels: &mut Vec<u32>, part: &TriMesh, label: u32) {
    let base = mesh.vertices.len() as u32;
    mesh.vertices.extend(&part.vertices);
    mesh.triangles
        .extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
    labels.extend(std::iter::repeat_n(label, part.vertices.len()));
}

/// A gum band: a wavy strip 3 mm below to 8 mm below the cervical centres, along the arch.
fn gum_band(poses: &[Pose], arch: Arch) -> TriMesh {
    let mut centres: Vec<Vec3> = poses.iter().map(|p| p.translation).collect();
    centres.sort_by(|a, b| a.x.total_cmp(&b.x));
    let mut mesh = TriMesh::default();
    if centres.len() < 2 {
        return mesh;
    }
    let apical = match arch {
        Arch::Upper => Vec3::Y,
        Arch::Lower => Vec3::NEG_Y,
    };
    let n = centres.len();
    for (i, c) in centres.iter().enumerate() {
        let along = centres[(i + 1).min(n - 1)] - centres[i.saturating_sub(1)];
        let outward = along.cross(Vec3::Y).normalize_or(Vec3::Z) * 6.0;
        for (depth, side) in [(3.0, 1.0), (8.0, 1.0), (8.0, -1.0), (3.0, -1.0)] {
            let wave = 0.4 * (i as f32 * 1.7 + depth).sin();
            mesh.vertices
                .push(*c + apical * (depth + wave) + outward * side);
        }
    }
    for i in 0..n - 1 {
        let (a, b) = (4 * i as u32, 4 * (i + 1) as u32);
        for k in 0..3 {
            mesh.triangles.push([a + k, b + k, b + k + 1]);
            mesh.triangles.push([a + k, b + k + 1, a + k + 1]);
        }
    }
    mesh
}

/// How a generated scan carries its labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanFormat {
    /// PLY (binary little-endian) with an integer `label` per vertex.
    PlyProperty,
    /// PLY (ASCII) with `red`, `green`, `blue` per vertex ([`tooth_colour`], [`GUM_COLOUR`]).
    PlyColours,
    /// OBJ with a JSON label file beside it.
    ObjJson,
}

/// The bytes of a scan written in `format`: the mesh file, and for [`ScanFormat::ObjJson`] the
/// label file.
pub fn write_scan(
    scan: &LabelledArch,
    mesh: &TriMesh,
    format: ScanFormat,
) -> (Vec<u8>, Option<Vec<u8>>) {
    match format {
        ScanFormat::PlyProperty => {
            let mut out = format!(
                "ply\nformat binary_little_endian 1.0\ncomment orthosim scan-like arch\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty int label\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
                mesh.vertices.len(),
                mesh.triangles.len()
            )
            .into_bytes();
            for (v, l) in mesh.vertices.iter().zip(&scan.labels) {
                for c in v.to_array() {
                    out.extend(c.to_le_bytes());
                }
                out.extend((*l as i32).to_le_bytes());
            }
            for t in &mesh.triangles {
                out.push(3);
                for i in t {
                    out.extend((*i as i32).to_le_bytes());
                }
            }
            (out, None)
        }
        ScanFormat::PlyColours => {
            let mut out = format!(
                "ply\nformat ascii 1.0\ncomment orthosim scan-like arch\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
                mesh.vertices.len(),
                mesh.triangles.len()
            );
            for (v, l) in mesh.vertices.iter().zip(&scan.labels) {
                let (r, g, b) = Fdi::new(i64::from(*l)).map_or(GUM_COLOUR, tooth_colour);
                let _ = writeln!(out, "{} {} {} {r} {g} {b}", v.x, v.y, v.z);
            }
            for t in &mesh.triangles {
                let _ = writeln!(out, "3 {} {} {}", t[0], t[1], t[2]);
            }
            (out.into_bytes(), None)
        }
        ScanFormat::ObjJson => {
            let mut out = String::from("# orthosim scan-like arch\n");
            for v in &mesh.vertices {
                let _ = writeln!(out, "v {} {} {}", v.x, v.y, v.z);
            }
            for t in &mesh.triangles {
                let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
            }
            let json = serde_json::json!({
                "jaw": match scan.arch { Arch::Upper => "upper", Arch::Lower => "lower" },
                "labels": scan.labels,
            });
            (out.into_bytes(), Some(json.to_string().into_bytes()))
        }
    }
}
