//! A tooth (or a block of teeth) on its ligament for one step, in the world frame: the effective
//! compliance under its wire and constraints, and the twist a wrench gives it in clinical time.
//!
//! Guarantees: every effective compliance is symmetric positive semi-definite, and the twist map
//! `w ↦ rate · C w · max(0, 1 − p₀/p(w))` is the gradient of the convex function
//! `rate/2 · (‖w‖_C − a)₊²`, with `p(w)` the mean ligament pressure (proportional to ‖w‖_C).
//! So the contact problem of [`super::contact`] is a convex minimisation and its solve
//! converges.

use glam::{DMat3, DVec3};

use super::stiffness::PdlStiffness;

use crate::geometry::{Mat6, Vec6, halves, jacobi_eigen, vec6};

/// The length rotations are weighed at when a twist's speed is held to the saturated
/// ligament's ([`PdlBody::twist`]): about a root's length (mm).
pub const TWIST_ARM_MM: f64 = 10.0;

/// `diag(R, R) · M · diag(R, R)ᵀ`: a 6×6 stiffness or compliance turned by `r`.
pub fn rotated(m: &Mat6, r: DMat3) -> Mat6 {
    let mut out = Mat6::ZERO;
    for bi in 0..2 {
        for bj in 0..2 {
            let b = r * m.block(bi, bj) * r.transpose();
            for j in 0..3 {
                for i in 0..3 {
                    out.0[3 * bi + i][3 * bj + j] = b.col(j)[i];
                }
            }
        }
    }
    out
}

/// A stiffness about `from` re-expressed about `to`: `Tᵀ K T` with the twist at `from` equal to
/// `T` times the twist at `to`.
pub fn shifted(k: &Mat6, from: DVec3, to: DVec3) -> Mat6 {
    // u_from = u_to + θ × (from − to) = u_to − [from − to]× θ.
    let d = from - to;
    let mut t = Mat6::identity();
    let x = [[0.0, -d.z, d.y], [d.z, 0.0, -d.x], [-d.y, d.x, 0.0]];
    for (i, row) in x.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            t.0[i][3 + j] = -v;
        }
    }
    t.transpose().mul(&k.mul(&t))
}

/// The compliance of stiffness `k` when the body may only move along `allowed` (orthonormal
/// twists): `U (Uᵀ K U)⁻¹ Uᵀ`. All six allowed: `K⁻¹`.
pub fn constrained_compliance(k: &Mat6, allowed: &[Vec6]) -> Option<Mat6> {
    let n = allowed.len();
    if n == 6 {
        return k.inverse();
    }
    let mut reduced = Mat6::identity();
    for (i, ui) in allowed.iter().enumerate() {
        let kui = k.mul_vec(ui);
        for (j, uj) in allowed.iter().enumerate() {
            reduced.0[j][i] = uj.iter().zip(&kui).map(|(a, b)| a * b).sum();
        }
    }
    let inv = reduced.inverse()?;
    let mut out = Mat6::ZERO;
    for (i, ui) in allowed.iter().enumerate() {
        for (j, uj) in allowed.iter().enumerate() {
            let s = inv.0[i][j];
            for r in 0..6 {
                for c in 0..6 {
                    out.0[r][c] += ui[r] * s * uj[c];
                }
            }
        }
    }
    Some(out)
}

/// The compliance when motions along `rows` (twist directions `g`, each blocking `gᵀ q`) are
/// held back by `fraction` (0–1): `C − f · C Gᵀ (G C Gᵀ)⁺ G C`. With f = 1 every twist it gives
/// has `G q = 0`; rows already blocked stay blocked (pseudo-inverse). Symmetric PSD for f in
/// [0, 1].
pub fn blocked(c: &Mat6, rows: &[Vec6], fraction: f64) -> Mat6 {
    if fraction <= 0.0 || rows.is_empty() {
        return *c;
    }
    // C Gᵀ: one column per row.
    let cg: Vec<Vec6> = rows.iter().map(|g| c.mul_vec(g)).collect();
    let mut m = [[0.0; 6]; 6];
    for (i, gi) in rows.iter().enumerate().take(6) {
        for (j, cgj) in cg.iter().enumerate().take(6) {
            m[i][j] = gi.iter().zip(cgj).map(|(a, b)| a * b).sum();
        }
    }
    let (values, vectors) = jacobi_eigen(m);
    let top = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut pinv = [[0.0; 6]; 6];
    for (k, &v) in values.iter().enumerate() {
        if v <= 1e-12 * top || v <= 0.0 {
            continue;
        }
        for i in 0..6 {
            for j in 0..6 {
                pinv[i][j] += vectors[k][i] * vectors[k][j] / v;
            }
        }
    }
    let mut out = *c;
    let n = rows.len().min(6);
    for r in 0..6 {
        for s in 0..6 {
            let mut x = 0.0;
            for i in 0..n {
                for j in 0..n {
                    x += cg[i][r] * pinv[i][j] * cg[j][s];
                }
            }
            out.0[r][s] -= fraction * x;
        }
    }
    out
}

/// A rectangular wire's engagement: the compliance when the wire supplies `engagement` (0–1) of
/// the couple that would stop the rotation ([`blocked`] on the three rotations).
pub fn engaged(c: &Mat6, engagement: f64) -> Mat6 {
    let rotations: [Vec6; 3] = std::array::from_fn(|k| {
        let mut g = [0.0; 6];
        g[3 + k] = 1.0;
        g
    });
    blocked(c, &rotations, engagement)
}

/// One moving unit for a step: a tooth, or a group moving as one block (world frame).
#[derive(Clone, Debug, PartialEq)]
pub struct PdlBody {
    /// Centre of resistance (world).
    pub centre: DVec3,
    /// Effective compliance about the centre (wire and constraints applied).
    pub compliance: Mat6,
    /// Root area held by the ligament (mm²).
    pub area: f64,
    /// Mean spring stiffness per area (N/mm³).
    pub mean_spring: f64,
    /// Applied wrench about the centre (N, N·mm).
    pub applied: Vec6,
    /// The stiffness K about the centre of an appliance whose force falls as the body moves
    /// (N/mm, N·mm/rad): a step then moves the body as the load at the step's end drives it
    /// (backward Euler, see [`PdlBody::twist`]), so that no stiff wire makes it overshoot; None:
    /// no such appliance.
    pub appliance_stiffness: Option<Mat6>,
}

impl PdlBody {
    /// A body that never moves (the bone): no compliance, no load.
    pub fn fixed(centre: DVec3) -> Self {
        Self {
            centre,
            compliance: Mat6::ZERO,
            area: 1.0,
            mean_spring: 1.0,
            applied: [0.0; 6],
            appliance_stiffness: None,
        }
    }

    /// Mean ligament pressure (kPa) under wrench `w` (see [`PdlStiffness::pressure_kpa`]).
    pub fn pressure_kpa(&self, w: &Vec6) -> f64 {
        PdlStiffness::pressure_kpa(&self.compliance, self.mean_spring, self.area, w)
    }

    /// The twist per step (mm, rad about the centre) under wrench `w`: `rate` × the elastic
    /// twist, shrunk so that the pressure drops by the threshold (zero below it) and no faster
    /// than at `saturation_kpa`.
    ///
    /// With an appliance's stiffness K the step is backward Euler for the linear part,
    /// v = (I + g·C·K)⁻¹ g·C·w with g = rate·(p − threshold)/p, so that no stiff wire makes the
    /// tooth overshoot where its force falls; that twist is then held to the speed of the
    /// saturated ligament (its size, rotations weighed at `TWIST_ARM_MM`, at most that of the
    /// undamped twist at `saturation_kpa`). A stiff wire far from passive so moves a tooth at the
    /// ligament's saturated speed, not at the crawl its stiffness alone would allow.
    pub fn twist(&self, w: &Vec6, rate: f64, threshold_kpa: f64, saturation_kpa: f64) -> Vec6 {
        let p = self.pressure_kpa(w);
        if p.is_nan() || p <= threshold_kpa {
            return [0.0; 6];
        }
        let cw = self.compliance.mul_vec(w);
        let cap = rate * (saturation_kpa - threshold_kpa).max(0.0) / p;
        let linear = rate * (p - threshold_kpa) / p;
        let Some(k) = &self.appliance_stiffness else {
            let g = linear.min(cap);
            return cw.map(|v| v * g);
        };
        let damped = Mat6::identity()
            .add_scaled(&self.compliance.mul(k), linear)
            .solve(&cw.map(|v| v * linear))
            .unwrap_or([0.0; 6]);
        let size = |t: &Vec6| {
            let (v, r) = halves(t);
            (v.length_squared() + (r * TWIST_ARM_MM).length_squared()).sqrt()
        };
        let most = size(&cw) * cap;
        let s = size(&damped);
        if s > most && s > 0.0 {
            damped.map(|v| v * most / s)
        } else {
            damped
        }
    }

    /// Velocity (per step) of world point `p` under twist `t`.
    pub fn point_velocity(&self, t: &Vec6, p: DVec3) -> DVec3 {
        let (u, theta) = halves(t);
        u + theta.cross(p - self.centre)
    }

    /// The wrench about the centre of a unit force along `n` at `p`.
    pub fn unit_wrench(&self, n: DVec3, p: DVec3) -> Vec6 {
        vec6(n, (p - self.centre).cross(n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spd() -> Mat6 {
        let mut next = crate::geometry::test_numbers(3);
        let mut a = Mat6::ZERO;
        for row in &mut a.0 {
            for x in row.iter_mut() {
                *x = next() as f64;
            }
        }
        a.transpose().mul(&a).add_scaled(&Mat6::identity(), 0.5)
    }

    #[test]
    fn shifting_a_stiffness_keeps_the_energy_of_a_motion() {
        let k = spd();
        let (from, to) = (DVec3::new(1.0, -2.0, 0.5), DVec3::new(-0.3, 4.0, 1.0));
        let k2 = shifted(&k, from, to);
        // A twist at `to` seen at `from`.
        let (u, th) = (DVec3::new(0.2, -0.1, 0.4), DVec3::new(0.05, 0.3, -0.2));
        let at_to = vec6(u, th);
        let at_from = vec6(u + th.cross(from - to), th);
        assert!((k2.quadratic(&at_to) - k.quadratic(&at_from)).abs() < 1e-9);
    }

    #[test]
    fn constraints_and_engagement_block_what_they_should() {
        let k = spd();
        let c = k.inverse().unwrap();
        // Only x translation and z rotation allowed.
        let allowed = [
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        ];
        let cc = constrained_compliance(&k, &allowed).unwrap();
        let t = cc.mul_vec(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert!(t[1].abs() < 1e-12 && t[2].abs() < 1e-12 && t[3].abs() < 1e-12);
        assert!(t[4].abs() < 1e-12 && t[0].abs() > 1e-6);
        // Full engagement: no rotation at all; half: half the rotation.
        let full = engaged(&c, 1.0);
        let w = [0.3, -1.0, 0.2, 2.0, 0.0, -1.0];
        let (_, rot) = halves(&full.mul_vec(&w));
        assert!(rot.length() < 1e-10, "{rot}");
        let (_, half) = halves(&engaged(&c, 0.5).mul_vec(&w));
        let (_, free) = halves(&c.mul_vec(&w));
        assert!((half - free * 0.5).length() < 1e-10);
        // Symmetric.
        for r in 0..6 {
            for s in 0..6 {
                assert!((full.0[r][s] - full.0[s][r]).abs() < 1e-10);
            }
        }
        let r = DMat3::from_rotation_y(0.7);
        let turned = rotated(&c, r);
        let w2 = vec6(r * DVec3::X, r * DVec3::Y);
        assert!((turned.quadratic(&w2) - c.quadratic(&vec6(DVec3::X, DVec3::Y))).abs() < 1e-10);
    }
}
