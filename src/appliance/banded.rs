//! A symmetric positive-definite banded matrix and its Cholesky solve: the rod's stiffness, where
//! each node couples only with its neighbours.

/// A symmetric matrix of order `n` whose entries vanish more than `band` places off the diagonal,
/// stored as its upper band (row `i`, columns `i..=i + band`).
#[derive(Clone, Debug)]
pub struct Banded {
    n: usize,
    band: usize,
    upper: Vec<f64>,
}

impl Banded {
    /// The zero matrix of order `n` and half bandwidth `band`.
    pub fn zeros(n: usize, band: usize) -> Self {
        Self {
            n,
            band,
            upper: vec![0.0; n * (band + 1)],
        }
    }

    /// Order.
    pub fn order(&self) -> usize {
        self.n
    }

    /// Adds `v` to entry (`i`, `j`) and its mirror; entries outside the band are ignored (callers
    /// keep their couplings within it).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        if j - i <= self.band && j < self.n {
            self.upper[i * (self.band + 1) + (j - i)] += v;
        }
    }

    /// Adds `other` (of the same order and band) entry by entry.
    pub fn add_matrix(&mut self, other: &Banded) {
        debug_assert!(self.n == other.n && self.band == other.band);
        for (a, b) in self.upper.iter_mut().zip(&other.upper) {
            *a += b;
        }
    }

    /// Entry (`i`, `j`).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        if j - i <= self.band && j < self.n {
            self.upper[i * (self.band + 1) + (j - i)]
        } else {
            0.0
        }
    }

    /// Solves `self · x = b` by banded Cholesky, in place of `b`. Returns false (and leaves `b`
    /// unspecified) when the matrix is not positive definite.
    pub fn solve(self, b: &mut [f64]) -> bool {
        match self.factor() {
            Some(f) => {
                f.solve(b);
                true
            }
            None => false,
        }
    }

    /// The Cholesky factor `self = Uᵀ·U`, to solve with many right-hand sides; `None` when the
    /// matrix is not positive definite.
    pub fn factor(mut self) -> Option<Factor> {
        let (n, w) = (self.n, self.band + 1);
        for i in 0..n {
            let d = self.upper[i * w];
            if !(d > 0.0 && d.is_finite()) {
                return None;
            }
            let d = d.sqrt();
            self.upper[i * w] = d;
            let last = (i + self.band).min(n - 1);
            for j in i + 1..=last {
                self.upper[i * w + (j - i)] /= d;
            }
            for j in i + 1..=last {
                let uij = self.upper[i * w + (j - i)];
                if uij == 0.0 {
                    continue;
                }
                for k in j..=last {
                    self.upper[j * w + (k - j)] -= uij * self.upper[i * w + (k - i)];
                }
            }
        }
        Some(Factor(self))
    }
}

/// A banded Cholesky factor (see [`Banded::factor`]).
#[derive(Clone, Debug)]
pub struct Factor(Banded);

impl Factor {
    /// Order of the factored matrix.
    pub fn order(&self) -> usize {
        self.0.n
    }

    /// Solves `Uᵀ·U·x = b` in place of `b` (`b` as long as the order).
    pub fn solve(&self, b: &mut [f64]) {
        let u = &self.0;
        let (n, w) = (u.n, u.band + 1);
        for i in 0..n {
            let first = i.saturating_sub(u.band);
            let mut s = b[i];
            for k in first..i {
                s -= u.upper[k * w + (i - k)] * b[k];
            }
            b[i] = s / u.upper[i * w];
        }
        for i in (0..n).rev() {
            let last = (i + u.band).min(n - 1);
            let mut s = b[i];
            for k in i + 1..=last {
                s -= u.upper[i * w + (k - i)] * b[k];
            }
            b[i] = s / u.upper[i * w];
        }
    }

    /// The inverse of the factored matrix within its band (exact: Takahashi's recurrence on the
    /// factor, `U·Z = U⁻ᵀ` row by row from the last, which needs no entry of `Z` outside the
    /// band). Costs one factorisation, against a full solve per column for the same diagonal
    /// blocks.
    pub fn inverse_band(&self) -> Banded {
        let u = &self.0;
        let (n, b, w) = (u.n, u.band, u.band + 1);
        let mut z = Banded::zeros(n, b);
        for i in (0..n).rev() {
            let last = (i + b).min(n - 1);
            let d = u.upper[i * w];
            // Off the diagonal first (j > i), then the diagonal, which needs row i's others.
            for j in (i..=last).rev() {
                let mut s = if j == i { 1.0 / d } else { 0.0 };
                for k in i + 1..=last {
                    let (r, c) = if k <= j { (k, j) } else { (j, k) };
                    s -= u.upper[i * w + (k - i)] * z.upper[r * w + (c - r)];
                }
                z.upper[i * w + (j - i)] = s / d;
            }
        }
        z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_banded_system_and_refuses_an_indefinite_one() {
        // Tridiagonal 2, −1: the second-difference matrix.
        let n = 7;
        let mut m = Banded::zeros(n, 2);
        for i in 0..n {
            m.add(i, i, 2.0);
            if i + 1 < n {
                m.add(i, i + 1, -1.0);
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| m.get(i, j) * x[j]).sum())
            .collect();
        assert!(m.solve(&mut b));
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        let mut bad = Banded::zeros(2, 1);
        bad.add(0, 0, 1.0);
        bad.add(1, 1, 1.0);
        bad.add(0, 1, 2.0);
        assert!(!bad.solve(&mut [1.0, 1.0]));
    }

    #[test]
    fn the_band_of_the_inverse_matches_solves_column_by_column() {
        // A pentadiagonal matrix, diagonally dominant, with an unsymmetric-looking pattern of
        // values (symmetric storage).
        let (n, band) = (9, 2);
        let mut m = Banded::zeros(n, band);
        for i in 0..n {
            m.add(i, i, 5.0 + i as f64 * 0.3);
            if i + 1 < n {
                m.add(i, i + 1, -1.0 - 0.1 * i as f64);
            }
            if i + 2 < n {
                m.add(i, i + 2, 0.4 + 0.05 * i as f64);
            }
        }
        let f = m.clone().factor().unwrap();
        let z = f.inverse_band();
        for j in 0..n {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            f.solve(&mut e);
            for (i, want) in e.iter().enumerate() {
                if i.abs_diff(j) <= band {
                    assert!((z.get(i, j) - want).abs() < 1e-13, "{i} {j}");
                }
            }
        }
        // Outside the band the inverse is not zero; the recurrence never claims it.
        assert_eq!(z.get(0, n - 1), 0.0);
    }
}
