//! A generated root for a scanned crown.
//!
//! Intraoral scans see crowns only: the segmented mesh is open along the gum line. Roots matter
//! for collisions (and for where a tooth tips), so the opening is closed by a root built from the
//! anatomy table: rings that follow the cervical margin and shrink towards an apex one root length
//! (the table's value for the tooth type) beyond the margin's centroid, along the margin's normal
//! pointing away from the crown. Ring `k` of [`RINGS`] at `t = k / RINGS` keeps the margin's shape
//! scaled by `(1 − t)^0.7`, its scallop (height along the normal) fading out linearly, so the root
//! is a smooth tapered cone that starts exactly on the margin; the last ring closes on the apex.
//! The root is a stand-in for the real one, documented as such in the import report.

use glam::{DVec3, Vec3};

use super::{error::ImportError, repair::loop_centroid};
use crate::geometry::TriMesh;

/// Rings between the margin and the apex.
pub const RINGS: usize = 10;

/// Unit normal of a closed polygon (Newell's method), or None when it has no area.
fn polygon_normal(points: &[Vec3]) -> Option<Vec3> {
    let mut n = DVec3::ZERO;
    for i in 0..points.len() {
        let a = points[i].as_dvec3();
        let b = points[(i + 1) % points.len()].as_dvec3();
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    (n.length() > 1e-12).then(|| n.normalize().as_vec3())
}

/// Area-weighted centroid of a surface.
fn surface_centroid(mesh: &TriMesh) -> Vec3 {
    let mut sum = DVec3::ZERO;
    let mut total = 0.0;
    for i in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle(i).map(|v| v.as_dvec3());
        let w = 0.5 * (b - a).cross(c - a).length();
        sum += (a + b + c) / 3.0 * w;
        total += w;
    }
    if total > 0.0 {
        (sum / total).as_vec3()
    } else {
        Vec3::ZERO
    }
}

/// Closes the margin `l` (in its edges' direction) of `mesh` with a root `root_length` mm long.
/// Returns the margin's centroid (the cervical centre) and the unit apical direction.
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn close_with_root(
    mesh: &mut TriMesh,
    l: &[u32],
    root_length: f32,
) -> Result<(Vec3, Vec3), ImportError> {
    let points: Vec<Vec3> = l.iter().map(|&i| mesh.vertices[i as usize]).collect();
    let centre = loop_centroid(mesh, l);
    let crown = surface_centroid(mesh);
    let mut apical = polygon_normal(&points).ok_or(ImportError::FlatMargin)?;
    if apical.dot(centre - crown) < 0.0 {
        apical = -apical;
    }
    let mut prev: Vec<u32> = l.to_vec();
    for k in 1..RINGS {
        let t = k as f32 / RINGS as f32;
        let scale = (1.0 - t).powf(0.7);
        let base = mesh.vertices.len() as u32;
        for &p in &points {
            let offset = p - centre;
            let height = offset.dot(apical);
            let planar = offset - apical * height;
            mesh.vertices
                .push(centre + apical * (root_length * t + height * (1.0 - t)) + planar * scale);
        }
        let ring: Vec<u32> = (0..points.len() as u32).map(|i| base + i).collect();
        join(mesh, &prev, &ring);
        prev = ring;
    }
    let apex = mesh.vertices.len() as u32;
    mesh.vertices.push(centre + apical * root_length);
    for i in 0..prev.len() {
        let (a, b) = (prev[i], prev[(i + 1) % prev.len()]);
        mesh.triangles.push([b, a, apex]);
    }
    Ok((centre, apical))
}

/// Quads between two rings of equal size: `upper` runs in its triangles' edge direction, so the
/// new triangles run each of its edges the other way.
fn join(mesh: &mut TriMesh, upper: &[u32], lower: &[u32]) {
    let n = upper.len();
    for i in 0..n {
        let j = (i + 1) % n;
        mesh.triangles.push([upper[j], upper[i], lower[i]]);
        mesh.triangles.push([upper[j], lower[i], lower[j]]);
    }
}
