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
    fdi::{Arch, Fdi, ToothKind},
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
    labelled_arch_with(d, arch, triangles, seed, &LabelFaults::NONE)
}

/// How a generated labelled arch fails the way real segmentations do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LabelFaults {
    /// Crowns whose label runs into the gum: a flap of gum 1.5–3 mm apical and 2.5–5 mm outward
    /// of the margin carries the tooth's label, joined to the crown along its margin, with a
    /// strip of gum-labelled surface beyond it.
    pub gum_bleed: usize,
    /// Neighbouring pairs where the label of one tooth covers a fragment of the other's crown
    /// near their contact.
    pub fragments: usize,
    /// Islands: a few gum triangles labelled with a nearby tooth.
    pub islands: usize,
    /// Lower incisors whose gum line is scalloped 4–6.5 mm deep (high papillae on a thin crown,
    /// so a long, steep neck and a margin that folds seen from the root).
    pub steep_necks: usize,
    /// Thin incisors (then other teeth, lower arch first in a lower scan) whose incisal half is
    /// turned through the rest of the crown, so the surface crosses itself more than the repair
    /// can usually cut out.
    pub crossed: usize,
}

impl LabelFaults {
    /// Labels as a perfect segmentation gives them.
    pub const NONE: Self = Self {
        gum_bleed: 0,
        fragments: 0,
        islands: 0,
        steep_necks: 0,
        crossed: 0,
    };

    /// Every failure mode of real labelled scans, a few times each.
    pub const REAL: Self = Self {
        gum_bleed: 3,
        fragments: 3,
        islands: 3,
        steep_necks: 4,
        crossed: 2,
    };
}

/// [`labelled_arch`] with the label `faults` of real segmentations, drawn from `seed`.
pub fn labelled_arch_with(
    d: &Dentition,
    arch: Arch,
    triangles: usize,
    seed: u64,
    faults: &LabelFaults,
) -> LabelledArch {
    let mut rng = Rng(seed.wrapping_mul(0xA24B_AED4_963E_E407) | 1);
    let teeth: Vec<_> = d.visible().filter(|t| t.fdi.arch() == arch).collect();
    let mut crowns: Vec<(u32, TriMesh, Vec<u32>)> = Vec::new();
    let mut steep = faults.steep_necks;
    for t in &teeth {
        let s = seed
            .wrapping_mul(100)
            .wrapping_add(u64::from(t.fdi.number()));
        let mut defects = ScanDefects::typical(s);
        let incisor = matches!(
            t.fdi.kind(),
            ToothKind::CentralIncisor | ToothKind::LateralIncisor
        );
        if steep > 0 && arch == Arch::Lower && incisor {
            steep -= 1;
            defects.scallop_mm = 4.0 + 2.5 * rng.uniform();
        }
        let crown = scan_like_crown(arch, t.fdi.kind(), &t.pose, triangles, &defects, s);
        let n = u32::from(t.fdi.number());
        let labels = vec![n; crown.mesh.vertices.len()];
        crowns.push((n, crown.mesh, labels));
    }
    // Incisors first: the thinnest crowns cross themselves most readily.
    let mut order: Vec<usize> = (0..teeth.len()).collect();
    order.sort_by_key(|&i| (teeth[i].fdi.kind() as u8, teeth[i].fdi.number()));
    for &i in order.iter().take(faults.crossed) {
        let pose = teeth[i].pose;
        cross_incisal_part(&mut crowns[i].1, &pose);
    }
    for _ in 0..faults.gum_bleed.min(teeth.len()) {
        let i = (rng.uniform() * teeth.len() as f32) as usize % teeth.len();
        let flare = 2.5 + 2.5 * rng.uniform();
        let drop = 1.5 + 1.5 * rng.uniform();
        let (_, mesh, labels) = &mut crowns[i];
        bleed_into_gum(mesh, labels, &teeth[i].pose, drop, flare);
    }
    for _ in 0..faults.fragments.min(teeth.len().saturating_sub(1)) {
        let i = (rng.uniform() * (teeth.len() - 1) as f32) as usize % (teeth.len() - 1);
        // The pair next to each other along the arch.
        let mut by_place: Vec<usize> = (0..teeth.len()).collect();
        by_place.sort_by_key(|&k| teeth[k].fdi.arch_index());
        let (a, b) = (by_place[i], by_place[i + 1]);
        let (a, b) = if rng.uniform() < 0.5 { (a, b) } else { (b, a) };
        let label = crowns[a].0;
        let near = vertices_near(&crowns[b].1, &crowns[a].1, 0.8);
        for v in near {
            crowns[b].2[v] = label;
        }
    }
    let mut mesh = TriMesh::default();
    let mut labels = Vec::new();
    for (_, crown, crown_labels) in &crowns {
        append(&mut mesh, &mut labels, crown, crown_labels);
    }
    let gum = gum_band(&teeth.iter().map(|t| t.pose).collect::<Vec<_>>(), arch);
    let start = mesh.vertices.len();
    append(&mut mesh, &mut labels, &gum, &vec![0; gum.vertices.len()]);
    for _ in 0..faults.islands {
        if gum.triangles.is_empty() {
            break;
        }
        // Two corners of a gum triangle take the nearest tooth's label: a few triangles.
        let t = gum.triangles
            [(rng.uniform() * gum.triangles.len() as f32) as usize % gum.triangles.len()];
        let at = gum.vertices[t[0] as usize];
        let nearest = teeth
            .iter()
            .min_by(|p, q| {
                p.pose
                    .translation
                    .distance(at)
                    .total_cmp(&q.pose.translation.distance(at))
            })
            .map_or(0, |p| u32::from(p.fdi.number()));
        labels[start + t[0] as usize] = nearest;
        labels[start + t[1] as usize] = nearest;
    }
    LabelledArch { arch, mesh, labels }
}

/// Turns the incisal half of a crown placed by `pose` a quarter about its buccal axis through
/// the crown's middle, so the two halves cross along the whole crown.
fn cross_incisal_part(mesh: &mut TriMesh, pose: &Pose) {
    let inverse = pose.inverse();
    let local = mesh.map_vertices(|v| inverse.transform_point(v));
    let c = local.aabb().centre();
    let turn = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    for (v, l) in mesh.vertices.iter_mut().zip(&local.vertices) {
        if l.y > c.y {
            *v = pose.transform_point(c + turn * (*l - c));
        }
    }
}

/// Joins a flap to the crown's margin (its longest opening): a ring `drop` mm apical and `flare`
/// mm outward labelled with the tooth, then a ring beyond it labelled gum.
fn bleed_into_gum(mesh: &mut TriMesh, labels: &mut Vec<u32>, pose: &Pose, drop: f32, flare: f32) {
    let Some(margin) = longest_opening(mesh) else {
        return;
    };
    let apical = pose.rotation * Vec3::NEG_Y;
    let axis = pose.translation;
    let label = labels.first().copied().unwrap_or(0);
    let out_of = |p: Vec3| {
        let d = p - axis;
        (d - apical * d.dot(apical)).normalize_or(Vec3::X)
    };
    let ring =
        |mesh: &mut TriMesh, labels: &mut Vec<u32>, from: &[u32], down: f32, out: f32, l: u32| {
            let base = mesh.vertices.len() as u32;
            for &v in from {
                let p = mesh.vertices[v as usize];
                mesh.vertices.push(p + apical * down + out_of(p) * out);
                labels.push(l);
            }
            (0..from.len() as u32)
                .map(|k| base + k)
                .collect::<Vec<u32>>()
        };
    let first = ring(mesh, labels, &margin, drop, flare, label);
    let second = ring(mesh, labels, &first, 1.5, 1.5, 0);
    // The margin runs in its triangles' direction (a → b); the flap runs it the other way.
    for (upper, lower) in [(&margin, &first), (&first, &second)] {
        let n = upper.len();
        for k in 0..n {
            let (a, b) = (upper[k], upper[(k + 1) % n]);
            let (a1, b1) = (lower[k], lower[(k + 1) % n]);
            mesh.triangles.push([b, a, a1]);
            mesh.triangles.push([b, a1, b1]);
        }
    }
}

/// The longest loop of open edges, in its triangles' direction.
fn longest_opening(mesh: &TriMesh) -> Option<Vec<u32>> {
    use std::collections::{HashMap, HashSet};
    let mut used: HashSet<(u32, u32)> = HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            used.insert((t[k], t[(k + 1) % 3]));
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &used {
        if !used.contains(&(b, a)) {
            next.entry(a).or_insert(b);
        }
    }
    let mut seen: HashSet<u32> = HashSet::new();
    let mut best: Option<Vec<u32>> = None;
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    for start in starts {
        if seen.contains(&start) {
            continue;
        }
        let mut l = vec![start];
        seen.insert(start);
        let mut v = next[&start];
        while v != start && l.len() <= next.len() {
            if !seen.insert(v) {
                l.clear();
                break;
            }
            l.push(v);
            match next.get(&v) {
                Some(&w) => v = w,
                None => {
                    l.clear();
                    break;
                }
            }
        }
        if v == start && l.len() >= 3 && best.as_ref().is_none_or(|b| l.len() > b.len()) {
            best = Some(l);
        }
    }
    best
}

/// Vertices of `of` within `reach` mm beyond their least distance to a vertex of `to`.
fn vertices_near(of: &TriMesh, to: &TriMesh, reach: f32) -> Vec<usize> {
    let distance = |p: Vec3| {
        to.vertices
            .iter()
            .map(|q| q.distance_squared(p))
            .fold(f32::INFINITY, f32::min)
            .sqrt()
    };
    let d: Vec<f32> = of.vertices.iter().map(|&p| distance(p)).collect();
    let least = d.iter().copied().fold(f32::INFINITY, f32::min);
    (0..d.len()).filter(|&i| d[i] <= least + reach).collect()
}

fn append(mesh: &mut TriMesh, labels: &mut Vec<u32>, part: &TriMesh, part_labels: &[u32]) {
    let base = mesh.vertices.len() as u32;
    mesh.vertices.extend(&part.vertices);
    mesh.triangles
        .extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
    labels.extend(part_labels);
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
