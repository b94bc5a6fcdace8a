//! Scan-like test data: crowns made from the procedural teeth the way an intraoral scan and its
//! segmentation deliver them, with the defects real scans have.
//!
//! Real patients' scans cannot ship with orthosim (their licences forbid it), so the import is
//! tested on these instead. A crown is the procedural tooth at a chosen resolution, with scanner
//! noise on every vertex, cut at a scalloped gum line (higher between the teeth, lower buccally
//! and lingually, with a jitter per triangle so the margin is jagged as a segmentation's is), and
//! given any of: small holes, spikes, bow-tie (non-manifold) vertices, fins on non-manifold edges,
//! small self-intersecting folds near the margin, and loose pieces of debris. The result says
//! where each defect is ([`ScanLikeCrown::sites`]) so a test can check the import changes the
//! surface only there.

use std::collections::HashSet;

use glam::Vec3;

use super::{
    anatomy::anatomy,
    fdi::{Arch, ToothKind},
    shape::{ToothResolution, ToothSolid},
};
use crate::geometry::{Pose, TriMesh, rng::Rng};

/// How many of each defect a crown gets, and its noise and gum line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanDefects {
    /// Small holes (a patch of triangles missing).
    pub holes: usize,
    /// Spikes (a vertex pulled out along its normal).
    pub spikes: usize,
    /// Bow-tie vertices (two triangles of a vertex's fan missing, so two holes meet there).
    pub bowties: usize,
    /// Fins (an extra triangle on an edge already shared by two).
    pub fins: usize,
    /// Folds near the margin (a vertex moved past its neighbour, so the surface crosses itself).
    pub folds: usize,
    /// Loose pieces (a few triangles floating near the crown).
    pub debris: usize,
    /// Scanner noise: each coordinate moves by up to this much (mm).
    pub noise_mm: f32,
    /// Height of the gum line's scallop (mm): the margin is this much higher between the teeth.
    pub scallop_mm: f32,
}

impl ScanDefects {
    /// A clean crown: noise and a scalloped margin, nothing else.
    pub const CLEAN: Self = Self {
        holes: 0,
        spikes: 0,
        bowties: 0,
        fins: 0,
        folds: 0,
        debris: 0,
        noise_mm: 0.003,
        scallop_mm: 1.0,
    };

    /// What real scans typically hold: up to two of each defect, drawn from `seed`.
    pub fn typical(seed: u64) -> Self {
        let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let mut count = || (rng.uniform() * 3.0) as usize;
        let (holes, spikes, bowties, fins, folds, debris) =
            (count(), count(), count(), count(), count(), count());
        Self {
            holes,
            spikes,
            bowties,
            fins,
            folds,
            debris,
            noise_mm: 0.002 + 0.008 * rng.uniform(),
            scallop_mm: 0.5 + 2.0 * rng.uniform(),
        }
    }
}

/// A scan-like crown and what went into it.
#[derive(Clone, Debug)]
pub struct ScanLikeCrown {
    /// The crown as a scan delivers it, defects included, placed by the pose given.
    pub mesh: TriMesh,
    /// The same crown before the defects (noise and margin included): the surface the import must
    /// keep outside the defects' sites.
    pub reference: TriMesh,
    /// Each defect's centre and the radius (mm) within which it changes the surface.
    pub sites: Vec<(Vec3, f32)>,
    /// Defects actually placed (a defect is skipped when no room is left for it).
    pub placed: ScanDefects,
}

/// A scan-like crown of the tooth type, with about `triangles` triangles (300–50,000 are
/// realistic), its defects drawn from `seed`, placed in the world by `pose` (the tooth's local
/// frame: origin at the cervical centre, y occlusal, z buccal).
pub fn scan_like_crown(
    arch: Arch,
    kind: ToothKind,
    pose: &Pose,
    triangles: usize,
    defects: &ScanDefects,
    seed: u64,
) -> ScanLikeCrown {
    let mut rng = Rng(seed.wrapping_mul(0xD1B5_4A32_D192_ED03) | 1);
    let solid = ToothSolid::new(arch, kind, anatomy(arch, kind));
    // About 45 % of a tooth's surface is crown; a closed mesh has two triangles per vertex.
    let vertices = ((triangles as f32 / 0.9) as u32).max(120);
    let full = solid.mesh(ToothResolution { vertices });
    let mut mesh = full;
    for v in &mut mesh.vertices {
        *v += rng.vec(defects.noise_mm);
    }
    let jitter = mesh.mean_edge_length().min(0.2);
    cut_at_gum_line(&mut mesh, defects.scallop_mm, jitter, &mut rng);
    let mut mesh = largest_piece(mesh).without_unused_vertices();
    let reference = mesh.clone();
    let mut sites: Vec<(Vec3, f32)> = Vec::new();
    // Counted up as each defect finds room.
    let mut placed = ScanDefects {
        noise_mm: defects.noise_mm,
        scallop_mm: defects.scallop_mm,
        ..ScanDefects::CLEAN
    };
    let edge = mesh.mean_edge_length();
    for _ in 0..defects.holes {
        if let Some(v) = pick_vertex(&mesh, &sites, &mut rng, 3.0 * edge + 0.5, 6.0 * edge) {
            let centre = mesh.vertices[v];
            let r = 1.2 * edge;
            let before = mesh.triangles.len();
            let verts = mesh.vertices.clone();
            mesh.triangles.retain(|t| {
                let c = (verts[t[0] as usize] + verts[t[1] as usize] + verts[t[2] as usize]) / 3.0;
                c.distance(centre) > r
            });
            if mesh.triangles.len() < before {
                sites.push((centre, r + 2.0 * edge));
                placed.holes += 1;
            }
        }
    }
    for _ in 0..defects.spikes {
        if let Some(v) = pick_vertex(&mesh, &sites, &mut rng, 3.0 * edge, 4.0 * edge) {
            let ring = neighbours(&mesh, v as u32);
            let p = mesh.vertices[v];
            let radius = ring
                .iter()
                .map(|&n| mesh.vertices[n as usize].distance(p))
                .sum::<f32>()
                / ring.len() as f32;
            let normal = vertex_normal(&mesh, v as u32);
            let height = radius * (6.0 + 3.0 * rng.uniform());
            mesh.vertices[v] = p + normal * height;
            sites.push((p, height + edge));
            placed.spikes += 1;
        }
    }
    for _ in 0..defects.bowties {
        if let Some(v) = pick_vertex(&mesh, &sites, &mut rng, 3.0 * edge, 4.0 * edge) {
            let fan = ordered_fan(&mesh, v as u32);
            if fan.len() >= 6 {
                let (a, b) = (fan[0], fan[fan.len() / 2]);
                let p = mesh.vertices[v];
                let (a, b) = (a.max(b), a.min(b));
                mesh.triangles.remove(a);
                mesh.triangles.remove(b);
                sites.push((p, 3.0 * edge));
                placed.bowties += 1;
            }
        }
    }
    for _ in 0..defects.fins {
        if let Some(v) = pick_vertex(&mesh, &sites, &mut rng, 3.0 * edge, 4.0 * edge) {
            let n = neighbours(&mesh, v as u32)[0];
            let (p, q) = (mesh.vertices[v], mesh.vertices[n as usize]);
            let normal = vertex_normal(&mesh, v as u32);
            let tip = (p + q) / 2.0 + normal * p.distance(q);
            mesh.vertices.push(tip);
            let tip = (mesh.vertices.len() - 1) as u32;
            mesh.triangles.push([v as u32, n, tip]);
            sites.push(((p + q) / 2.0, 3.0 * edge));
            placed.fins += 1;
        }
    }
    for _ in 0..defects.folds {
        // Near the margin: within a few edges of the gum line.
        for _attempt in 0..20 {
            let Some(v) = pick_near_margin(&mesh, &sites, &mut rng, 4.0 * edge) else {
                break;
            };
            let ring = neighbours(&mesh, v as u32);
            let n = ring[(rng.uniform() * ring.len() as f32) as usize % ring.len()];
            let (p, q) = (mesh.vertices[v], mesh.vertices[n as usize]);
            let mut trial = mesh.clone();
            trial.vertices[v] = q + (q - p) * 0.7;
            if trial.find_self_intersection().is_some() {
                mesh = trial;
                sites.push((p, 4.0 * edge + 2.0 * p.distance(q)));
                placed.folds += 1;
                break;
            }
        }
    }
    for _ in 0..defects.debris {
        let t = (rng.uniform() * mesh.triangles.len() as f32) as usize % mesh.triangles.len();
        let tri = mesh.triangle(t);
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
        let shift = normal * (1.0 + rng.uniform()) + rng.vec(0.3);
        let base = mesh.vertices.len() as u32;
        // A little pyramid-shaped patch, open underneath.
        let centre = (tri[0] + tri[1] + tri[2]) / 3.0 + shift;
        mesh.vertices.extend(tri.iter().map(|&p| p + shift));
        mesh.vertices.push(centre + normal * edge);
        mesh.triangles.push([base, base + 1, base + 3]);
        mesh.triangles.push([base + 1, base + 2, base + 3]);
        mesh.triangles.push([base + 2, base, base + 3]);
        placed.debris += 1;
    }
    ScanLikeCrown {
        mesh: mesh.map_vertices(|v| pose.transform_point(v)),
        reference: reference.map_vertices(|v| pose.transform_point(v)),
        sites: sites
            .into_iter()
            .map(|(c, r)| (pose.transform_point(c), r))
            .collect(),
        placed,
    }
}

/// Keeps the triangles above a scalloped gum line: `scallop` mm higher mesially and distally (x)
/// than buccally and lingually (z), with a jitter of up to `jitter` mm per triangle (about an
/// edge: a segmentation's boundary is ragged at the scale of the mesh).
fn cut_at_gum_line(mesh: &mut TriMesh, scallop: f32, jitter: f32, rng: &mut Rng) {
    let verts = mesh.vertices.clone();
    mesh.triangles.retain(|t| {
        let c = (verts[t[0] as usize] + verts[t[1] as usize] + verts[t[2] as usize]) / 3.0;
        let phi = c.z.atan2(c.x);
        let level = 0.5 * scallop * (2.0 * phi).cos() + jitter * (rng.uniform() - 0.5);
        c.y > level
    });
}

/// The piece with the most triangles (pieces joined along edges).
fn largest_piece(mesh: TriMesh) -> TriMesh {
    let (piece, count) = mesh.edge_pieces();
    let mut sizes = vec![0usize; count];
    for &p in &piece {
        sizes[p as usize] += 1;
    }
    let main = (0..count).max_by_key(|&i| sizes[i]).unwrap_or(0) as u32;
    mesh.keeping_piece(&piece, main)
}

/// Vertices on the open boundary.
fn boundary_vertices(mesh: &TriMesh) -> HashSet<u32> {
    mesh.open_edges()
        .into_iter()
        .flat_map(|(a, b)| [a, b])
        .collect()
}

/// A random interior vertex at least `margin_gap` from the boundary and `room` from every site.
fn pick_vertex(
    mesh: &TriMesh,
    sites: &[(Vec3, f32)],
    rng: &mut Rng,
    margin_gap: f32,
    room: f32,
) -> Option<usize> {
    let boundary: Vec<Vec3> = boundary_vertices(mesh)
        .iter()
        .map(|&v| mesh.vertices[v as usize])
        .collect();
    let used: HashSet<u32> = mesh.triangles.iter().flatten().copied().collect();
    for _ in 0..200 {
        let v = (rng.uniform() * mesh.vertices.len() as f32) as usize % mesh.vertices.len();
        let p = mesh.vertices[v];
        if !used.contains(&(v as u32))
            || boundary.iter().any(|b| b.distance(p) < margin_gap)
            || sites.iter().any(|(c, r)| c.distance(p) < r + room)
        {
            continue;
        }
        return Some(v);
    }
    None
}

/// A random interior vertex within `within` of the boundary, clear of the sites.
fn pick_near_margin(
    mesh: &TriMesh,
    sites: &[(Vec3, f32)],
    rng: &mut Rng,
    within: f32,
) -> Option<usize> {
    let boundary = boundary_vertices(mesh);
    let points: Vec<Vec3> = boundary
        .iter()
        .map(|&v| mesh.vertices[v as usize])
        .collect();
    let candidates: Vec<usize> = mesh
        .triangles
        .iter()
        .flatten()
        .map(|&v| v as usize)
        .collect::<HashSet<_>>()
        .into_iter()
        .filter(|&v| {
            let p = mesh.vertices[v];
            !boundary.contains(&(v as u32))
                && points.iter().any(|b| b.distance(p) < within)
                && sites.iter().all(|(c, r)| c.distance(p) > r + within)
        })
        .collect();
    if candidates.is_empty() {
        return None;
    }
    let mut sorted = candidates;
    sorted.sort_unstable();
    Some(sorted[(rng.uniform() * sorted.len() as f32) as usize % sorted.len()])
}

fn neighbours(mesh: &TriMesh, v: u32) -> Vec<u32> {
    let mut out: Vec<u32> = mesh
        .triangles
        .iter()
        .filter(|t| t.contains(&v))
        .flat_map(|t| t.iter().copied().filter(|&x| x != v).collect::<Vec<_>>())
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

fn vertex_normal(mesh: &TriMesh, v: u32) -> Vec3 {
    let mut n = Vec3::ZERO;
    for (i, t) in mesh.triangles.iter().enumerate() {
        if t.contains(&v) {
            let [a, b, c] = mesh.triangle(i);
            n += (b - a).cross(c - a);
        }
    }
    n.normalize_or(Vec3::Y)
}

/// The triangles around an interior vertex, in order around it.
fn ordered_fan(mesh: &TriMesh, v: u32) -> Vec<usize> {
    let fan: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&i| mesh.triangles[i].contains(&v))
        .collect();
    // Next triangle: the one whose edge leaving v starts where this one's edge into v ends.
    let leaving = |i: usize| {
        let t = mesh.triangles[i];
        let k = t.iter().position(|&x| x == v).unwrap_or(0);
        (t[(k + 1) % 3], t[(k + 2) % 3])
    };
    let mut order = vec![fan[0]];
    while order.len() < fan.len() {
        let (_, last) = leaving(*order.last().unwrap_or(&fan[0]));
        match fan.iter().find(|&&j| leaving(j).0 == last) {
            Some(&j) if !order.contains(&j) => order.push(j),
            _ => break,
        }
    }
    order
}
