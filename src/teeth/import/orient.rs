//! Automatic placement of labelled teeth that come in a scanner's or segmentation tool's own frame.
//!
//! Every file of a case without a `transform` (or with `transform: Auto`) is taken to share one
//! frame (both arches of a bite, or all tooth files of one CBCT segmentation), so the teeth keep
//! their relative pose. The rigid motion that brings them into orthosim's frame (+y occlusal
//! towards the upper arch, +x the patient's left, +z anterior, origin at the midline on the
//! occlusal plane) is found from their labels: each tooth is matched with the same tooth of the
//! normal arrangement ([`super::super::arch`]), whose frame is orthosim's by construction.
//!
//! 1. **Coarse**: the area centroid of each tooth's surface against the centroid of the arranged
//!    tooth's crown (or whole tooth, for a closed mesh with its root), matched by least squares
//!    over rotations and translations (Horn's quaternion method: always a proper rotation).
//! 2. **Refined** three times: in the current placement, each tooth's occlusal cap (its surface
//!    within [`CAP_DEPTH_MM`] of its occlusal end, the end taken below the top 0.5 % of its area so
//!    spikes do not count) against the arranged tooth's cap, matched again. Caps are where crowns
//!    agree whatever the gum line, holes or loose pieces of a scan.
//!    In the last round, teeth whose caps stay more than [`OUTLIER_MM`] (and three times the
//!    median) from their place are left out and the rest fitted again: a mislabelled tooth or one
//!    far out of line does not tilt the whole patient.
//! 3. **Checked**: every crown's own occlusal direction (from its margin to its surface, or from
//!    root to crown for a closed tooth) must point to the other arch after placement. A mirrored
//!    scan (left and right swapped relative to its labels) can only be matched by turning the arch
//!    over, so its crowns point away: it is refused, not placed. A fit whose caps stay more than
//!    [`MAX_RMS_MM`] from the arrangement's is refused as labels that do not describe an arch.
//!
//! Guarantee (tested on scan-like arches in 100 random frames): within 0.5 mm and 2° of the true
//! placement. On a real patient the teeth land where the arrangement's teeth would be in the least
//! squares sense: the occlusal plane at y = 0, the midline at x = 0.

use glam::{DMat3, DQuat, DVec3, Quat, Vec3};

use crate::{
    geometry::{Pose, TriMesh, jacobi_eigen, symmetric_eigen},
    teeth::{fdi::Fdi, shape::ToothResolution},
};

/// Resolution of the arranged teeth the scans are matched with: fine enough that the facets of
/// the reference do not shift its caps (at the default 125 vertices, a crown's flattened top moves
/// its cap by tenths of a millimetre).
pub const REFERENCE_RESOLUTION: ToothResolution = ToothResolution { vertices: 1500 };

/// Depth of the occlusal cap matched in the refinement (mm).
pub const CAP_DEPTH_MM: f32 = 1.5;
/// The largest root-mean-square distance (mm) between matched caps accepted for a placement.
pub const MAX_RMS_MM: f32 = 6.0;
/// A tooth whose cap stays farther than this (and than three times the median) from its place
/// after the fit is left out of the last fit (mm).
pub const OUTLIER_MM: f32 = 1.5;
/// Fewest teeth a frame can be found from.
pub const MIN_TEETH: usize = 3;

/// Why the teeth could not be placed automatically.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OrientError {
    /// Too few teeth, or all in a line.
    #[error(
        "automatic placement needs at least {MIN_TEETH} labelled teeth from one frame, not all in a row ({teeth} given): write each file's transform, or `transform: Identity` for files already in orthosim's frame"
    )]
    TooFew {
        /// Teeth given.
        teeth: usize,
    },
    /// The teeth match the arrangement only turned over: left and right are swapped.
    #[error(
        "the scan looks mirrored: matched to its labels, {away} of {teeth} crowns point away from the other arch, as when the patient's left and right are swapped (a mirrored export, or labels of the wrong side); mirror the mesh or fix the labels"
    )]
    Mirrored {
        /// Crowns pointing away.
        away: usize,
        /// Teeth checked.
        teeth: usize,
    },
    /// The labelled teeth do not form an arch like the arrangement's.
    #[error(
        "the labelled teeth do not match a dental arch: after the best placement their crowns are {rms_mm:.1} mm (root mean square) from where those teeth stand in an arch (most accepted {MAX_RMS_MM} mm); are the labels FDI numbers, and the units right?"
    )]
    NoMatch {
        /// Root-mean-square distance of the matched caps (mm).
        rms_mm: f32,
    },
}

/// A placement found for the teeth of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientation {
    /// From the files' frame (mm) to orthosim's.
    pub pose: Pose,
    /// Root-mean-square distance between the matched caps (mm).
    pub rms_mm: f32,
}

/// An arranged tooth: its closed mesh in its local frame (cervical centre at the origin, y
/// occlusal) and its pose in the normal arrangement.
#[derive(Clone, Copy, Debug)]
pub struct Arranged<'a> {
    /// Local mesh.
    pub mesh: &'a TriMesh,
    /// Pose in the arrangement.
    pub pose: Pose,
}

/// Finds where the teeth of one frame go: `teeth` are the raw meshes in the files' frame, in
/// millimetres, with valid indices and finite coordinates ([`super::check_raw`]); `arranged`
/// gives each tooth of the normal arrangement.
///
/// # Errors
/// [`OrientError`]: too few teeth, a mirrored scan, labels that do not describe an arch.
pub fn orient<'a>(
    teeth: &[(Fdi, &TriMesh)],
    arranged: impl Fn(Fdi) -> Arranged<'a>,
) -> Result<Orientation, OrientError> {
    // Welded as the import welds (files that repeat each corner per triangle, as STL does, then
    // show their openings), loose pieces left out.
    let weld_mm = super::RepairLimits::default().weld_mm;
    let welded: Vec<(Fdi, TriMesh)> = teeth
        .iter()
        .filter(|(_, m)| area_centroid(m, |_| true).is_some())
        .map(|(f, m)| {
            let (vertices, triangles) = super::repair::weld(m, weld_mm, &mut Default::default());
            (*f, largest_piece(&TriMesh::new(vertices, triangles)))
        })
        .collect();
    let teeth: Vec<(Fdi, &TriMesh)> = welded.iter().map(|(f, m)| (*f, m)).collect();
    if teeth.len() < MIN_TEETH {
        return Err(OrientError::TooFew { teeth: teeth.len() });
    }
    let references: Vec<Arranged> = teeth.iter().map(|(f, _)| arranged(*f)).collect();
    // Coarse: surface centroids.
    let mut pairs = Vec::with_capacity(teeth.len());
    for ((_, mesh), r) in teeth.iter().zip(&references) {
        let crown = is_crown(mesh);
        let c = area_centroid(mesh, |_| true).unwrap_or_default();
        let rc = area_centroid(r.mesh, |p| !crown || p.y > 0.0).unwrap_or_default();
        pairs.push((c, r.pose.transform_point(rc)));
    }
    if !spread(&pairs.iter().map(|p| p.1).collect::<Vec<_>>()) {
        return Err(OrientError::TooFew { teeth: teeth.len() });
    }
    let mut pose = fit(&pairs);
    let mut rms = 0.0;
    for round in 0..3 {
        pairs.clear();
        for ((fdi, mesh), r) in teeth.iter().zip(&references) {
            let up = super::occlusal_direction(fdi.arch());
            let world = pose.rotation.inverse() * up;
            let local_up = r.pose.rotation.inverse() * up;
            let (Some(c), Some(rc)) = (cap(mesh, world), cap(r.mesh, local_up)) else {
                continue;
            };
            pairs.push((c, r.pose.transform_point(rc)));
        }
        pose = fit(&pairs);
        // Last round: teeth far off the others' fit (a mislabelled or half-segmented tooth, a
        // patient's tooth out of line) are left out and the rest fitted again.
        if round == 2 && pairs.len() > MIN_TEETH + 1 {
            let residual = |p: &(Vec3, Vec3)| pose.transform_point(p.0).distance(p.1);
            let mut sorted: Vec<f32> = pairs.iter().map(residual).collect();
            sorted.sort_by(f32::total_cmp);
            let limit = (3.0 * sorted[sorted.len() / 2]).max(OUTLIER_MM);
            let kept: Vec<(Vec3, Vec3)> = pairs
                .iter()
                .copied()
                .filter(|p| residual(p) <= limit)
                .collect();
            if kept.len() >= MIN_TEETH
                && kept.len() < pairs.len()
                && spread(&kept.iter().map(|p| p.1).collect::<Vec<_>>())
            {
                pairs = kept;
                pose = fit(&pairs);
            }
        }
        rms = (pairs
            .iter()
            .map(|(a, b)| pose.transform_point(*a).distance_squared(*b))
            .sum::<f32>()
            / pairs.len().max(1) as f32)
            .sqrt();
    }
    // Every crown's own occlusal direction, placed, against its arch's.
    let mut away = 0;
    let mut checked = 0;
    for (fdi, mesh) in &teeth {
        if let Some(o) = own_occlusal(mesh) {
            checked += 1;
            if (pose.rotation * o).dot(super::occlusal_direction(fdi.arch())) < 0.0 {
                away += 1;
            }
        }
    }
    if checked > 0 && 2 * away > checked {
        return Err(OrientError::Mirrored {
            away,
            teeth: checked,
        });
    }
    if rms > MAX_RMS_MM || !rms.is_finite() {
        return Err(OrientError::NoMatch { rms_mm: rms });
    }
    Ok(Orientation { pose, rms_mm: rms })
}

/// The piece (triangles joined along edges) of largest area: loose pieces of a scan (debris)
/// would otherwise pull the features.
fn largest_piece(mesh: &TriMesh) -> TriMesh {
    let (piece, count) = mesh.edge_pieces();
    let mut area = vec![0.0f32; count];
    for (t, &p) in mesh.triangles.iter().zip(&piece) {
        let corner = |i: u32| mesh.vertices.get(i as usize).copied().unwrap_or(Vec3::NAN);
        let [a, b, c] = t.map(corner);
        let t_area = (b - a).cross(c - a).length() * 0.5;
        if t_area.is_finite() {
            area[p as usize] += t_area;
        }
    }
    let main = (0..count)
        .max_by(|&a, &b| area[a].total_cmp(&area[b]))
        .unwrap_or(0) as u32;
    TriMesh::new(
        mesh.vertices.clone(),
        mesh.triangles
            .iter()
            .zip(&piece)
            .filter(|(_, p)| **p == main)
            .map(|(t, _)| *t)
            .collect(),
    )
}

/// True for an open crown: its openings together are at least a small margin long.
fn is_crown(mesh: &TriMesh) -> bool {
    boundary(mesh).0 >= 8.0
}

/// Total boundary length (mm) and the length-weighted centroid of the boundary edges.
fn boundary(mesh: &TriMesh) -> (f32, Vec3) {
    let (mut length, mut sum) = (0.0f32, Vec3::ZERO);
    for (a, b) in mesh.open_edges() {
        let (Some(&p), Some(&q)) = (mesh.vertices.get(a as usize), mesh.vertices.get(b as usize))
        else {
            continue;
        };
        let l = p.distance(q);
        length += l;
        sum += (p + q) * 0.5 * l;
    }
    (
        length,
        if length > 0.0 {
            sum / length
        } else {
            Vec3::ZERO
        },
    )
}

/// Area-weighted centroid of the triangles whose centroid passes `keep`.
fn area_centroid(mesh: &TriMesh, keep: impl Fn(Vec3) -> bool) -> Option<Vec3> {
    let (mut area, mut sum) = (0.0f64, DVec3::ZERO);
    for t in triangles(mesh) {
        let c = (t[0] + t[1] + t[2]) / 3.0;
        if !keep(c) {
            continue;
        }
        let a = f64::from((t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5);
        area += a;
        sum += c.as_dvec3() * a;
    }
    (area > 0.0 && sum.is_finite()).then(|| (sum / area).as_vec3())
}

/// The finite triangles of a mesh with valid indices.
fn triangles(mesh: &TriMesh) -> impl Iterator<Item = [Vec3; 3]> + '_ {
    mesh.triangles.iter().filter_map(|t| {
        let p = [
            *mesh.vertices.get(t[0] as usize)?,
            *mesh.vertices.get(t[1] as usize)?,
            *mesh.vertices.get(t[2] as usize)?,
        ];
        p.iter().all(|v| v.is_finite()).then_some(p)
    })
}

/// Centroid of the occlusal cap along `up`: the surface within [`CAP_DEPTH_MM`] below the height
/// under which 99.5 % of the area lies. Triangles with an edge over four times the mesh's median
/// edge are left out: a scan's spikes (a vertex pulled millimetres out) are made of such.
fn cap(mesh: &TriMesh, up: Vec3) -> Option<Vec3> {
    let mut edges: Vec<f32> = triangles(mesh)
        .map(|t| longest_edge(&t))
        .filter(|l| l.is_finite())
        .collect();
    if edges.is_empty() {
        return None;
    }
    let mid = edges.len() / 2;
    let median = *edges.select_nth_unstable_by(mid, f32::total_cmp).1;
    let limit = 4.0 * median;
    let kept: Vec<[Vec3; 3]> = triangles(mesh)
        .filter(|t| longest_edge(t) <= limit)
        .collect();
    let mut heights: Vec<(f32, f32)> = kept
        .iter()
        .map(|t| {
            (
                ((t[0] + t[1] + t[2]) / 3.0).dot(up),
                (t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5,
            )
        })
        .filter(|(h, a)| h.is_finite() && *a > 0.0)
        .collect();
    let total: f32 = heights.iter().map(|h| h.1).sum();
    if total <= 0.0 {
        return None;
    }
    heights.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut above = 0.0;
    let mut top = heights[0].0;
    for (h, a) in &heights {
        above += a;
        top = *h;
        if above >= 0.005 * total {
            break;
        }
    }
    let floor = top - CAP_DEPTH_MM;
    let (mut area, mut sum) = (0.0f64, DVec3::ZERO);
    for t in &kept {
        let c = (t[0] + t[1] + t[2]) / 3.0;
        if c.dot(up) < floor {
            continue;
        }
        let a = f64::from((t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5);
        area += a;
        sum += c.as_dvec3() * a;
    }
    (area > 0.0 && sum.is_finite()).then(|| (sum / area).as_vec3())
}

fn longest_edge(t: &[Vec3; 3]) -> f32 {
    t[0].distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]))
}

/// The crown's own occlusal direction: from its margin to its surface for an open crown; for a
/// closed tooth, along its longest extent towards the end the volume crowds to (the crown).
fn own_occlusal(mesh: &TriMesh) -> Option<Vec3> {
    let centroid = area_centroid(mesh, |_| true)?;
    let (length, margin) = boundary(mesh);
    if length >= 8.0 {
        return (centroid - margin).try_normalize();
    }
    // Closed: principal direction of the vertices, signed by the centroid's offset from the
    // middle of the extent (the crown is the bulky end).
    let n = mesh.vertices.len() as f64;
    if n < 4.0 {
        return None;
    }
    let mean = mesh.vertices.iter().map(|v| v.as_dvec3()).sum::<DVec3>() / n;
    let mut cov = DMat3::ZERO;
    for v in &mesh.vertices {
        let d = v.as_dvec3() - mean;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    // Eigenvalues ascending: the last column is the longest extent.
    let (_, vectors) = symmetric_eigen(cov);
    let axis = vectors.z_axis.as_vec3();
    let (lo, hi) = mesh
        .vertices
        .iter()
        .map(|v| v.dot(axis))
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), h| {
            (a.min(h), b.max(h))
        });
    let offset = centroid.dot(axis) - 0.5 * (lo + hi);
    (offset.abs() > 1e-3).then(|| axis * offset.signum())
}

/// True when the points do not all lie near one line (their second principal spread ≥ 1 mm).
fn spread(points: &[Vec3]) -> bool {
    let n = points.len() as f64;
    if n < 3.0 {
        return false;
    }
    let mean = points.iter().map(|v| v.as_dvec3()).sum::<DVec3>() / n;
    let mut cov = DMat3::ZERO;
    for v in points {
        let d = v.as_dvec3() - mean;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z) / n;
    }
    // Eigenvalues ascending: the middle one is the second spread.
    symmetric_eigen(cov).0.y >= 1.0
}

/// The rigid motion taking the first points of the pairs onto the second in the least-squares
/// sense (Horn 1987, unit quaternions: always a proper rotation).
fn fit(pairs: &[(Vec3, Vec3)]) -> Pose {
    let n = pairs.len().max(1) as f64;
    let ca = pairs.iter().map(|p| p.0.as_dvec3()).sum::<DVec3>() / n;
    let cb = pairs.iter().map(|p| p.1.as_dvec3()).sum::<DVec3>() / n;
    let mut s = [[0.0f64; 3]; 3];
    for (a, b) in pairs {
        let (a, b) = (a.as_dvec3() - ca, b.as_dvec3() - cb);
        for (i, ai) in a.to_array().into_iter().enumerate() {
            for (j, bj) in b.to_array().into_iter().enumerate() {
                s[i][j] += ai * bj;
            }
        }
    }
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = s;
    let m = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (values, vectors) = jacobi_eigen(m);
    let k = (0..4)
        .max_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    let [w, x, y, z] = vectors[k];
    let q = DQuat::from_xyzw(x, y, z, w);
    let q = if q.length() > 0.0 {
        q.normalize()
    } else {
        DQuat::IDENTITY
    };
    let rotation: Quat = q.as_quat().normalize();
    let t = cb - q * ca;
    Pose::new(rotation, t.as_vec3())
}

/// A transform as the case file writes it: rotation in degrees about x, then y, then z, and the
/// translation (mm).
pub fn as_euler_deg(pose: &Pose) -> ([f32; 3], [f32; 3]) {
    let (z, y, x) = pose.rotation.to_euler(glam::EulerRot::ZYX);
    (
        [x.to_degrees(), y.to_degrees(), z.to_degrees()],
        pose.translation.to_array(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horn_recovers_a_rotation_and_translation() {
        let points = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::new(-1.0, -1.0, 0.5),
        ];
        let truth = Pose::new(
            Quat::from_euler(glam::EulerRot::XYZ, 2.0, -0.7, 2.9),
            Vec3::new(10.0, -4.0, 7.0),
        );
        let pairs: Vec<_> = points
            .iter()
            .map(|p| (*p, truth.transform_point(*p)))
            .collect();
        let found = fit(&pairs);
        for p in points {
            let e = found.transform_point(p).distance(truth.transform_point(p));
            assert!(e < 1e-4, "{e}");
        }
        // The transform as written back in a case file gives the same motion.
        let (r, t) = as_euler_deg(&found);
        let back = Pose::new(
            Quat::from_rotation_z(r[2].to_radians())
                * Quat::from_rotation_y(r[1].to_radians())
                * Quat::from_rotation_x(r[0].to_radians()),
            Vec3::from_array(t),
        );
        for p in points {
            let e = back.transform_point(p).distance(truth.transform_point(p));
            assert!(e < 1e-4, "{e}");
        }
    }

    #[test]
    fn points_in_a_row_are_not_enough() {
        let row: Vec<Vec3> = (0..5).map(|i| Vec3::X * i as f32 * 8.0).collect();
        assert!(!spread(&row));
        let mut arch = row.clone();
        arch.push(Vec3::new(10.0, 0.0, 6.0));
        assert!(spread(&arch));
    }
}
