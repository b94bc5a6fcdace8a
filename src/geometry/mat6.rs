//! A 6×6 matrix in f64 for spatial stiffness and compliance (a twist or wrench is translation
//! then rotation), with a solve by Gaussian elimination with partial pivoting.

use glam::{DMat3, DVec3};

/// A 6×6 matrix, row-major: `m[row][column]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mat6(pub [[f64; 6]; 6]);

/// A 6-vector: translation (or force) components, then rotation (or moment) components.
pub type Vec6 = [f64; 6];

/// The 6-vector of two 3-vectors.
pub fn vec6(a: DVec3, b: DVec3) -> Vec6 {
    [a.x, a.y, a.z, b.x, b.y, b.z]
}

/// The two halves of a 6-vector.
pub fn halves(v: &Vec6) -> (DVec3, DVec3) {
    (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]))
}

impl Mat6 {
    /// The zero matrix.
    pub const ZERO: Self = Self([[0.0; 6]; 6]);

    /// The identity.
    pub fn identity() -> Self {
        let mut m = Self::ZERO;
        for i in 0..6 {
            m.0[i][i] = 1.0;
        }
        m
    }

    /// `self + s · other`.
    pub fn add_scaled(&self, other: &Self, s: f64) -> Self {
        let mut m = *self;
        for (row, o) in m.0.iter_mut().zip(&other.0) {
            for (x, y) in row.iter_mut().zip(o) {
                *x += s * y;
            }
        }
        m
    }

    /// Matrix product `self · other`.
    pub fn mul(&self, other: &Self) -> Self {
        Self(std::array::from_fn(|r| {
            std::array::from_fn(|c| (0..6).map(|k| self.0[r][k] * other.0[k][c]).sum())
        }))
    }

    /// The transpose.
    pub fn transpose(&self) -> Self {
        Self(std::array::from_fn(|r| {
            std::array::from_fn(|c| self.0[c][r])
        }))
    }

    /// Matrix times vector.
    pub fn mul_vec(&self, v: &Vec6) -> Vec6 {
        let mut out = [0.0; 6];
        for (o, row) in out.iter_mut().zip(&self.0) {
            *o = row.iter().zip(v).map(|(a, b)| a * b).sum();
        }
        out
    }

    /// `vᵀ M v`.
    pub fn quadratic(&self, v: &Vec6) -> f64 {
        self.mul_vec(v).iter().zip(v).map(|(a, b)| a * b).sum()
    }

    /// The 3×3 block at block row `r` and block column `c` (each 0: translation, 1: rotation).
    pub fn block(&self, r: usize, c: usize) -> DMat3 {
        let m = &self.0;
        let (i, j) = (3 * r, 3 * c);
        DMat3::from_cols(
            DVec3::new(m[i][j], m[i + 1][j], m[i + 2][j]),
            DVec3::new(m[i][j + 1], m[i + 1][j + 1], m[i + 2][j + 1]),
            DVec3::new(m[i][j + 2], m[i + 1][j + 2], m[i + 2][j + 2]),
        )
    }

    /// The solution x of `M x = b`, or None when M is singular (a pivot below 10⁻¹⁴ of the
    /// largest entry).
    pub fn solve(&self, b: &Vec6) -> Option<Vec6> {
        let mut a = self.0;
        let mut x = *b;
        let scale = a
            .iter()
            .flatten()
            .fold(0.0f64, |s, v| s.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for col in 0..6 {
            let pivot = (col..6).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
            if a[pivot][col].abs() <= 1e-14 * scale || !a[pivot][col].is_finite() {
                return None;
            }
            a.swap(col, pivot);
            x.swap(col, pivot);
            for row in col + 1..6 {
                let f = a[row][col] / a[col][col];
                for k in col..6 {
                    a[row][k] -= f * a[col][k];
                }
                x[row] -= f * x[col];
            }
        }
        for col in (0..6).rev() {
            let s: f64 = (col + 1..6).map(|k| a[col][k] * x[k]).sum();
            x[col] = (x[col] - s) / a[col][col];
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// The inverse, or None when singular.
    pub fn inverse(&self) -> Option<Self> {
        let mut inv = Self::ZERO;
        for c in 0..6 {
            let mut e = [0.0; 6];
            e[c] = 1.0;
            let col = self.solve(&e)?;
            for r in 0..6 {
                inv.0[r][c] = col[r];
            }
        }
        Some(inv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_and_inverse_undo_a_well_conditioned_matrix() {
        let mut next = crate::geometry::test_numbers(7);
        let mut m = Mat6::identity();
        for row in &mut m.0 {
            for x in row.iter_mut() {
                *x += 0.3 * next() as f64;
            }
        }
        let b = [1.0, -2.0, 0.5, 3.0, 0.0, -1.0];
        let x = m.solve(&b).unwrap();
        let back = m.mul_vec(&x);
        for (u, v) in back.iter().zip(&b) {
            assert!((u - v).abs() < 1e-12);
        }
        let inv = m.inverse().unwrap();
        let id = m.mul(&inv);
        assert_eq!(m.transpose().transpose(), m);
        for r in 0..6 {
            for c in 0..6 {
                let want = if r == c { 1.0 } else { 0.0 };
                assert!((id.0[r][c] - want).abs() < 1e-12);
            }
        }
        assert!(Mat6::ZERO.solve(&b).is_none());
        let (t, r) = halves(&vec6(DVec3::X, DVec3::Z));
        assert_eq!((t, r), (DVec3::X, DVec3::Z));
        assert_eq!(m.block(1, 0).x_axis.x, m.0[3][0]);
    }
}
