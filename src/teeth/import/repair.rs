//! Checking and cleaning imported tooth meshes.
//!
//! In order: refuse empty meshes, non-finite coordinates and bad indices; weld vertices closer
//! than [`RepairLimits::weld_mm`]; drop degenerate triangles (a repeated vertex, or an area below
//! 10⁻¹² of the squared mesh size) and duplicated triangles; drop the triangles of edges shared by
//! more than two (fins, `mend`); keep the largest connected piece when the others are
//! debris (each under [`RepairLimits::debris_fraction`] of the triangles), refuse several pieces
//! otherwise (more than one tooth); make the winding consistent (flipping triangles to agree with
//! their neighbours, refusing non-orientable surfaces); give each fan of a bow-tie vertex its own
//! vertex; and smooth spikes. Closing follows in `close`: every hole but the cervical
//! margin is filled, the margin gets a generated root ([`super::root`]), the surface is turned
//! outward, and places where it meets itself are cut out and closed again until the exact check
//! ([`TriMesh::validate_solid`]) passes.

use std::collections::{HashMap, HashSet, VecDeque};

use glam::{DVec3, IVec3, Vec3};
use serde::Serialize;

use super::{
    error::{ImportError, Near},
    mend,
};
use crate::geometry::TriMesh;

/// Limits of what is repaired rather than refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RepairLimits {
    /// Vertices closer than this are one vertex (mm).
    pub weld_mm: f32,
    /// Openings whose boundary is at most this long (mm) are always holes, and closed. A longer
    /// one is a crown's cervical margin when it is the longest and at least as long as the crown
    /// is wide; every other opening is closed as a hole too.
    pub max_hole_mm: f32,
    /// Pieces with fewer than this fraction of the triangles are dropped as debris.
    pub debris_fraction: f32,
    /// Self-intersecting patches are cut out and closed while the cuts remove at most this
    /// fraction of the surface's triangles; beyond it the mesh is refused (it is not one tooth).
    pub max_cut_fraction: f32,
}

impl Default for RepairLimits {
    fn default() -> Self {
        Self {
            weld_mm: 1e-5,
            max_hole_mm: 6.0,
            debris_fraction: 0.25,
            max_cut_fraction: 0.5,
        }
    }
}

/// What the repair did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Repairs {
    /// Vertices merged into others.
    pub welded_vertices: usize,
    /// Degenerate triangles dropped.
    pub degenerate_triangles: usize,
    /// Duplicated triangles dropped.
    pub duplicate_triangles: usize,
    /// Small separate pieces dropped (and their triangles).
    pub debris_pieces: usize,
    /// Triangles dropped from edges shared by more than two triangles (fins).
    pub fin_triangles: usize,
    /// Vertices split where separate fans of triangles met at one point.
    pub split_vertices: usize,
    /// Spike tips moved back onto the surface.
    pub spikes_smoothed: usize,
    /// Places where the surface met itself, cut out and closed again.
    pub self_intersections_cut: usize,
    /// Triangles removed by those cuts.
    pub triangles_cut: usize,
    /// Triangles removed where the cervical margin folded over itself (seen from the root's
    /// side), so the generated root could hang straight from it.
    pub margin_trimmed: usize,
    /// Where the surface was changed (cuts, a folded margin's trim, split vertices, spikes):
    /// centre (x, y, z, in the mesh's frame after units and transform) and radius (mm) of each
    /// place. Elsewhere every vertex of the file is kept where it was; closing holes and the root
    /// only add triangles.
    pub changed_areas: Vec<[f32; 4]>,
    /// Triangles flipped to agree with their neighbours.
    pub flipped_triangles: usize,
    /// The whole surface faced inward and was turned.
    pub turned_outward: bool,
    /// Boundary length (mm) of each hole closed.
    pub holes_closed_mm: Vec<f32>,
    /// Length (mm) of the cervical margin closed by a generated root, if one was generated.
    pub root_generated_margin_mm: Option<f32>,
    /// The repair could not make a valid solid, so the tooth was rebuilt from the solid its
    /// surface encloses ([`super::rebuild()`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rebuilt: Option<super::rebuild::Rebuilt>,
    /// Which root a scanned crown got, when it got one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub root: Option<RootReport>,
}

/// The root generated for a scanned crown.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RootReport {
    /// "template" (the tooth type's procedural root, fitted to the crown) or "cone" (a cone along
    /// the margin's normal, the fallback).
    pub kind: &'static str,
    /// From the cervical centre to the apex (mm).
    pub length_mm: f32,
    /// Separate roots below the furcation (1 for a single root or a cone).
    pub roots: usize,
    /// Angle (degrees) between the root's axis and the margin's apical normal.
    pub axis_deg: f32,
    /// How far (mm, root mean square) the crown lies from the fitted template's surface.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit_rms_mm: Option<f32>,
    /// How far (degrees) the root was turned away from its neighbours' roots.
    pub tilt_deg: f32,
    /// How much (mm) the root was shortened so that it does not reach into a neighbour's.
    pub shortened_mm: f32,
    /// Why the template root was not used, for a cone.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
}

impl Repairs {
    /// True when nothing had to be repaired.
    pub fn is_clean(&self) -> bool {
        *self == Repairs::default()
    }

    /// One line saying what was repaired ("nothing" when clean).
    pub fn summary(&self) -> String {
        let mut parts = Vec::new();
        let mut say = |n: usize, what: &str| {
            if n > 0 {
                parts.push(format!("{n} {what}"));
            }
        };
        say(self.welded_vertices, "duplicate vertices welded");
        say(self.degenerate_triangles, "degenerate triangles dropped");
        say(self.duplicate_triangles, "duplicated triangles dropped");
        say(self.debris_pieces, "loose pieces dropped");
        say(
            self.fin_triangles,
            "triangles dropped from non-manifold edges",
        );
        say(self.split_vertices, "non-manifold vertices split");
        say(self.spikes_smoothed, "spikes smoothed");
        say(
            self.flipped_triangles,
            "triangles flipped to a consistent winding",
        );
        if !self.holes_closed_mm.is_empty() {
            let lengths: Vec<String> = self
                .holes_closed_mm
                .iter()
                .map(|l| format!("{l:.2}"))
                .collect();
            parts.push(format!(
                "{} holes closed (boundaries {} mm)",
                self.holes_closed_mm.len(),
                lengths.join(", ")
            ));
        }
        if self.self_intersections_cut > 0 {
            parts.push(format!(
                "{} self-intersecting patches cut out and closed ({} triangles)",
                self.self_intersections_cut, self.triangles_cut
            ));
        }
        if self.margin_trimmed > 0 {
            parts.push(format!(
                "{} triangles trimmed where the margin folded",
                self.margin_trimmed
            ));
        }
        if self.turned_outward {
            parts.push("surface turned outward".into());
        }
        if let Some(l) = self.root_generated_margin_mm {
            let root = match &self.root {
                Some(r) if r.kind == "template" && r.roots > 1 => format!(
                    "template roots ({}, {:.1} mm, {:.0}° from the margin's normal)",
                    r.roots, r.length_mm, r.axis_deg
                ),
                Some(r) if r.kind == "template" => format!(
                    "template root ({:.1} mm, {:.0}° from the margin's normal)",
                    r.length_mm, r.axis_deg
                ),
                Some(r) => format!(
                    "cone root ({:.1} mm{})",
                    r.length_mm,
                    r.fallback
                        .as_deref()
                        .map(|f| format!("; no template root: {f}"))
                        .unwrap_or_default()
                ),
                None => "root".into(),
            };
            parts.push(format!(
                "{root} generated below a {l:.1} mm cervical margin"
            ));
        }
        if let Some(r) = &self.rebuilt {
            parts.push(format!(
                "rebuilt on a {} mm grid as the repair could not make a solid ({}): the scan lies {:.3} mm from it on average, {:.3} mm at the 95th percentile, {:.3} mm at most",
                r.cell_mm, r.reason, r.mean_mm, r.p95_mm, r.max_mm
            ));
        }
        if parts.is_empty() {
            "nothing".into()
        } else {
            parts.join("; ")
        }
    }
}

/// Checks, welds, cleans and orients; the result may still be open.
pub(super) fn clean(
    mesh: &TriMesh,
    limits: &RepairLimits,
    repairs: &mut Repairs,
) -> Result<TriMesh, ImportError> {
    super::labels::check_raw(mesh)?;
    let (mut vertices, triangles) = weld(mesh, limits.weld_mm, repairs);
    let mut triangles = drop_degenerate(&vertices, triangles, repairs);
    repairs.fin_triangles += mend::drop_fins(&mut triangles);
    let triangles = keep_main_piece(&vertices, triangles, limits, repairs)?;
    let mut triangles = orient(&vertices, triangles, repairs)?;
    let split = mend::split_bowties(&mut vertices, &mut triangles);
    repairs.split_vertices += split.len();
    repairs.changed_areas.extend(split);
    let spikes = mend::smooth_spikes(&mut vertices, &triangles);
    repairs.spikes_smoothed += spikes.len();
    repairs.changed_areas.extend(spikes);
    Ok(TriMesh::new(vertices, triangles))
}

/// Merges vertices within `tol` of each other (first come keeps its position) and drops the
/// vertices no triangle uses.
pub(super) fn weld(mesh: &TriMesh, tol: f32, repairs: &mut Repairs) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let cell = tol.max(1e-9);
    let key = |v: Vec3| (v / cell).floor().as_ivec3();
    let mut grid: HashMap<IVec3, Vec<u32>> = HashMap::new();
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut map = vec![u32::MAX; mesh.vertices.len()];
    let mut used = vec![false; mesh.vertices.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    for (i, &v) in mesh.vertices.iter().enumerate() {
        if !used[i] {
            continue;
        }
        let k = key(v);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&k.saturating_add(IVec3::new(dx, dy, dz))) {
                        for &j in list {
                            if vertices[j as usize].distance(v) <= tol {
                                found = Some(j);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        map[i] = match found {
            Some(j) => {
                repairs.welded_vertices += 1;
                j
            }
            None => {
                let j = vertices.len() as u32;
                vertices.push(v);
                grid.entry(k).or_default().push(j);
                j
            }
        };
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| map[v as usize]))
        .collect();
    (vertices, triangles)
}

fn drop_degenerate(
    vertices: &[Vec3],
    triangles: Vec<[u32; 3]>,
    repairs: &mut Repairs,
) -> Vec<[u32; 3]> {
    let (lo, hi) = vertices.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    );
    let scale = (hi - lo).max_element().max(f32::MIN_POSITIVE) as f64;
    let mut seen = HashSet::new();
    let mut kept = Vec::with_capacity(triangles.len());
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize].as_dvec3());
        let area = 0.5 * (b - a).cross(c - a).length();
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area <= 1e-12 * scale * scale {
            repairs.degenerate_triangles += 1;
            continue;
        }
        let mut sorted = t;
        sorted.sort_unstable();
        if !seen.insert(sorted) {
            repairs.duplicate_triangles += 1;
            continue;
        }
        kept.push(t);
    }
    kept
}

fn undirected(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Triangles around each undirected edge; refuses edges with more than two.
fn edge_map(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
) -> Result<HashMap<(u32, u32), Vec<usize>>, ImportError> {
    let mut edges: HashMap<(u32, u32), Vec<usize>> = HashMap::with_capacity(triangles.len() * 2);
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edges
                .entry(undirected(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(i);
        }
    }
    let mut bad: Vec<_> = edges.iter().filter(|(_, l)| l.len() > 2).collect();
    bad.sort_unstable_by_key(|(e, _)| **e);
    if let Some(((a, b), list)) = bad.first() {
        let mid = (vertices[*a as usize] + vertices[*b as usize]) / 2.0;
        return Err(ImportError::SharedEdge {
            at: Near(mid),
            triangles: list.len(),
            edges: bad.len(),
        });
    }
    Ok(edges)
}

pub(super) fn keep_main_piece(
    vertices: &[Vec3],
    triangles: Vec<[u32; 3]>,
    limits: &RepairLimits,
    repairs: &mut Repairs,
) -> Result<Vec<[u32; 3]>, ImportError> {
    if triangles.is_empty() {
        return Err(ImportError::NoArea);
    }
    let edges = edge_map(vertices, &triangles)?;
    let mut piece = vec![usize::MAX; triangles.len()];
    let mut sizes = Vec::new();
    for start in 0..triangles.len() {
        if piece[start] != usize::MAX {
            continue;
        }
        let id = sizes.len();
        let mut size = 0;
        let mut queue = VecDeque::from([start]);
        piece[start] = id;
        while let Some(i) = queue.pop_front() {
            size += 1;
            let t = triangles[i];
            for k in 0..3 {
                for &j in &edges[&undirected(t[k], t[(k + 1) % 3])] {
                    if piece[j] == usize::MAX {
                        piece[j] = id;
                        queue.push_back(j);
                    }
                }
            }
        }
        sizes.push(size);
    }
    if sizes.len() == 1 {
        return Ok(triangles);
    }
    let main = (0..sizes.len()).max_by_key(|&i| sizes[i]).unwrap_or(0);
    let limit = (limits.debris_fraction * triangles.len() as f32).ceil() as usize;
    let big: Vec<usize> = (0..sizes.len())
        .filter(|&i| i != main && sizes[i] >= limit)
        .collect();
    if !big.is_empty() {
        return Err(ImportError::SeveralPieces {
            pieces: big.len() + 1,
            limit,
        });
    }
    repairs.debris_pieces += sizes.len() - 1;
    // Each dropped piece's place: the centre of its vertices and the farthest one.
    let mut sums = vec![(Vec3::ZERO, 0usize); sizes.len()];
    for (t, &id) in triangles.iter().zip(&piece) {
        for &v in t {
            sums[id].0 += vertices[v as usize];
            sums[id].1 += 1;
        }
    }
    let mut reach = vec![0.0f32; sizes.len()];
    for (t, &id) in triangles.iter().zip(&piece) {
        let centre = sums[id].0 / sums[id].1 as f32;
        for &v in t {
            reach[id] = reach[id].max(vertices[v as usize].distance(centre));
        }
    }
    for id in (0..sizes.len()).filter(|&i| i != main) {
        let c = sums[id].0 / sums[id].1 as f32;
        repairs.changed_areas.push([c.x, c.y, c.z, reach[id]]);
    }
    Ok(triangles
        .into_iter()
        .enumerate()
        .filter(|(i, _)| piece[*i] == main)
        .map(|(_, t)| t)
        .collect())
}

/// Makes neighbouring triangles run their shared edges in opposite directions, flipping the fewer.
fn orient(
    vertices: &[Vec3],
    mut triangles: Vec<[u32; 3]>,
    repairs: &mut Repairs,
) -> Result<Vec<[u32; 3]>, ImportError> {
    let edges = edge_map(vertices, &triangles)?;
    let runs = |t: &[u32; 3], a: u32, b: u32| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b);
    let mut flip = vec![None::<bool>; triangles.len()];
    flip[0] = Some(false);
    let mut queue = VecDeque::from([0usize]);
    while let Some(i) = queue.pop_front() {
        let fi = flip[i].unwrap_or(false);
        let mut t = triangles[i];
        if fi {
            t.swap(1, 2);
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            for &j in &edges[&undirected(a, b)] {
                if j == i {
                    continue;
                }
                // j must run b→a; it runs a→b as stored if it needs flipping.
                let want = runs(&triangles[j], a, b);
                match flip[j] {
                    None => {
                        flip[j] = Some(want);
                        queue.push_back(j);
                    }
                    Some(f) if f != want => {
                        let mid = (vertices[a as usize] + vertices[b as usize]) / 2.0;
                        return Err(ImportError::Twisted(Near(mid)));
                    }
                    Some(_) => {}
                }
            }
        }
    }
    let flips = flip.iter().filter(|f| **f == Some(true)).count();
    // Keep the orientation of the majority; the outward check comes once the surface is closed.
    let invert_all = flips * 2 > triangles.len();
    for (t, f) in triangles.iter_mut().zip(&flip) {
        if f.unwrap_or(false) != invert_all {
            t.swap(1, 2);
        }
    }
    repairs.flipped_triangles += if invert_all {
        triangles.len() - flips
    } else {
        flips
    };
    Ok(triangles)
}

/// Boundary loops of a consistently wound surface, each in its edges' direction.
pub(super) fn boundary_loops(mesh: &TriMesh) -> Result<Vec<Vec<u32>>, ImportError> {
    let mut directed = HashSet::with_capacity(mesh.triangles.len() * 3);
    for t in &mesh.triangles {
        for k in 0..3 {
            directed.insert((t[k], t[(k + 1) % 3]));
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut boundary: Vec<(u32, u32)> = directed
        .iter()
        .filter(|(a, b)| !directed.contains(&(*b, *a)))
        .copied()
        .collect();
    boundary.sort_unstable();
    for &(a, b) in &boundary {
        if next.insert(a, b).is_some() {
            return Err(ImportError::HolesMeet(Near(mesh.vertices[a as usize])));
        }
    }
    let mut loops = Vec::new();
    let mut done = HashSet::new();
    for &(start, _) in &boundary {
        if done.contains(&start) {
            continue;
        }
        let mut l = vec![start];
        done.insert(start);
        let mut cur = next[&start];
        while cur != start {
            if !done.insert(cur) {
                return Err(ImportError::NonManifoldVertex(Near(
                    mesh.vertices[cur as usize],
                )));
            }
            l.push(cur);
            cur = *next
                .get(&cur)
                .ok_or(ImportError::OpenBoundary(Near(mesh.vertices[cur as usize])))?;
        }
        loops.push(l);
    }
    Ok(loops)
}

/// The largest extent (mm) of the vertices the triangles use.
pub(super) fn used_span(mesh: &TriMesh) -> f32 {
    crate::geometry::Aabb::from_points(
        mesh.triangles
            .iter()
            .flatten()
            .map(|&v| mesh.vertices[v as usize]),
    )
    .extent()
    .max_element()
}

pub(super) fn loop_length(mesh: &TriMesh, l: &[u32]) -> f32 {
    (0..l.len())
        .map(|i| {
            mesh.vertices[l[i] as usize].distance(mesh.vertices[l[(i + 1) % l.len()] as usize])
        })
        .sum()
}

/// Length-weighted centroid of a loop.
pub(super) fn loop_centroid(mesh: &TriMesh, l: &[u32]) -> Vec3 {
    let mut sum = DVec3::ZERO;
    let mut total = 0.0;
    for i in 0..l.len() {
        let a = mesh.vertices[l[i] as usize].as_dvec3();
        let b = mesh.vertices[l[(i + 1) % l.len()] as usize].as_dvec3();
        let w = a.distance(b);
        sum += (a + b) * 0.5 * w;
        total += w;
    }
    if total > 0.0 {
        (sum / total).as_vec3()
    } else {
        mesh.vertices[l[0] as usize]
    }
}
