//! Volume, centre of mass and inertia tensor of a closed triangle mesh.
//!
//! Exact for a closed, outward-wound mesh of uniform density (up to f64 rounding): the solid is
//! split into tetrahedra from a reference point to each triangle, and each tetrahedron's second
//! moments are added using the canonical tetrahedron covariance (Tonon 2004; Blow and Binstock 2004).

use glam::{DMat3, DVec3, Mat3, Vec3};

use super::trimesh::TriMesh;

/// Mass properties of a solid of unit density (1 per mm³); scale by a density for real masses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Enclosed volume (mm³).
    pub volume: f64,
    /// Centre of mass (mm), in the mesh's frame.
    pub centre_of_mass: Vec3,
    /// Inertia tensor about the centre of mass for unit density (mm⁵); multiply by a density
    /// (g/mm³) for g·mm².
    pub inertia: Mat3,
}

impl MassProperties {
    /// Computes the mass properties of a closed mesh.
    pub fn of(mesh: &TriMesh) -> Self {
        let origin = mesh.aabb().centre().as_dvec3();
        // Covariance of the canonical tetrahedron (0, e1, e2, e3), divided by its determinant.
        let canonical = DMat3::from_cols(
            DVec3::new(2.0, 1.0, 1.0),
            DVec3::new(1.0, 2.0, 1.0),
            DVec3::new(1.0, 1.0, 2.0),
        ) * (1.0 / 120.0);
        let mut volume = 0.0;
        let mut first = DVec3::ZERO;
        let mut covariance = DMat3::ZERO;
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize].as_dvec3() - origin);
            let m = DMat3::from_cols(a, b, c);
            let det = m.determinant();
            volume += det / 6.0;
            first += det / 24.0 * (a + b + c);
            covariance += det * (m * canonical * m.transpose());
        }
        let com = if volume.abs() > 0.0 {
            first / volume
        } else {
            DVec3::ZERO
        };
        // Covariance about the centre of mass (parallel-axis theorem for covariance).
        let shifted = covariance - volume * outer(com, com);
        let inertia = DMat3::IDENTITY * trace(&shifted) - shifted;
        Self {
            volume,
            centre_of_mass: (com + origin).as_vec3(),
            inertia: inertia.as_mat3(),
        }
    }

    /// Principal moments (ascending) and the matching unit axes (columns), by Jacobi rotations.
    pub fn principal_axes(&self) -> (Vec3, Mat3) {
        let (values, vectors) = symmetric_eigen(self.inertia.as_dmat3());
        (values.as_vec3(), vectors.as_mat3())
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn trace(m: &DMat3) -> f64 {
    m.x_axis.x + m.y_axis.y + m.z_axis.z
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations: eigenvalues ascending,
/// eigenvectors as the columns of the returned matrix (a proper rotation).
pub fn symmetric_eigen(m: DMat3) -> (DVec3, DMat3) {
    let (values, v) = jacobi_eigen(m.to_cols_array_2d());
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let mut cols = idx.map(|i| DVec3::from(v[i]));
    if cols[0].cross(cols[1]).dot(cols[2]) < 0.0 {
        cols[2] = -cols[2];
    }
    (
        DVec3::new(values[idx[0]], values[idx[1]], values[idx[2]]),
        DMat3::from_cols(cols[0], cols[1], cols[2]),
    )
}

/// Eigenvalues and unit eigenvectors (`vectors[i]` belongs to `values[i]`, unsorted) of a symmetric
/// N×N matrix by cyclic Jacobi rotations, until the off-diagonal part is below 10⁻¹⁵ of the
/// diagonal (relative) or after 64 sweeps.
pub fn jacobi_eigen<const N: usize>(mut a: [[f64; N]; N]) -> ([f64; N], [[f64; N]; N]) {
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..64 {
        let mut off = 0.0;
        let mut diagonal = 0.0;
        for p in 0..N {
            diagonal += a[p][p].powi(2);
            for q in p + 1..N {
                off += a[p][q].powi(2);
            }
        }
        if off <= 1e-30 * f64::max(diagonal, 1e-300) {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A' = Jᵀ A J with J the rotation in the (p, q) plane.
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                for k in 0..N {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for k in 0..N {
                    let (vkp, vkq) = (v[p][k], v[q][k]);
                    v[p][k] = c * vkp - s * vkq;
                    v[q][k] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut values = [0.0; N];
    for (i, value) in values.iter_mut().enumerate() {
        *value = a[i][i];
    }
    (values, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trimesh::tests::cuboid;

    #[test]
    fn box_mass_properties_match_the_formulas() {
        let (w, h, d) = (2.0f32, 4.0f32, 6.0f32);
        let mesh = cuboid(
            Vec3::new(1.0, -1.0, 3.0),
            Vec3::new(1.0 + w, -1.0 + h, 3.0 + d),
        );
        let mp = MassProperties::of(&mesh);
        let vol = (w * h * d) as f64;
        assert!((mp.volume - vol).abs() < 1e-9);
        assert!((mp.centre_of_mass - Vec3::new(2.0, 1.0, 6.0)).length() < 1e-5);
        let m = vol as f32;
        let expected = Vec3::new(
            m / 12.0 * (h * h + d * d),
            m / 12.0 * (w * w + d * d),
            m / 12.0 * (w * w + h * h),
        );
        let diag = Vec3::new(
            mp.inertia.x_axis.x,
            mp.inertia.y_axis.y,
            mp.inertia.z_axis.z,
        );
        assert!(
            (diag - expected).length() < 1e-3 * expected.length(),
            "{diag} vs {expected}"
        );
        assert!(mp.inertia.x_axis.y.abs() < 1e-3);
        let (moments, axes) = mp.principal_axes();
        assert!((moments.x - expected.z).abs() < 1e-2, "{moments}");
        assert!(
            axes.x_axis.z.abs() > 0.999,
            "smallest moment is about the long (z) axis"
        );
    }

    #[test]
    fn jacobi_diagonalises_a_rotated_tensor() {
        let r = DMat3::from_quat(glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, 1.0, -0.3));
        let d = DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0));
        let m = r * d * r.transpose();
        let (values, vectors) = symmetric_eigen(m);
        assert!((values - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-9);
        let back = vectors * DMat3::from_diagonal(values) * vectors.transpose();
        assert!((back - m).to_cols_array().iter().all(|x| x.abs() < 1e-9));
        assert!((vectors.determinant() - 1.0).abs() < 1e-9);
    }
}
