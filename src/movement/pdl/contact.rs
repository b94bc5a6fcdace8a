//! Contact forces between touching teeth, solved for all contacts of a step together: each
//! contact pushes along its normal with a force λ ≥ 0, and the teeth's twists under their loads
//! plus these forces must not close any contact (relative normal velocity ≥ the contact's
//! `bias`), with λ = 0 wherever a contact opens (complementarity).
//!
//! Method: projected Gauss–Seidel on λ. The twists are the gradient of a convex function of
//! the wrenches ([`super::body`]), so these conditions are the optimality conditions of a convex
//! minimisation over λ ≥ 0; each update is a projected Newton step with the elastic (threshold-
//! free) curvature, an upper bound of the true one, so every update lowers the objective and the
//! sweeps converge. The solve stops when no update changes a relative velocity by more than
//! `tolerance` (mm per step), or after `max_sweeps`. A push dies out along the arch where the
//! ligaments' thresholds hold it: past that tooth the forces are zero.

use glam::DVec3;

use super::body::PdlBody;
use crate::geometry::Vec6;

/// A contact between bodies `a` and `b`: a point (world) and the unit normal from `a` to `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRow {
    /// First body.
    pub a: usize,
    /// Second body.
    pub b: usize,
    /// Contact point (world).
    pub point: DVec3,
    /// Unit normal from `a` towards `b`.
    pub normal: DVec3,
    /// Least relative normal velocity asked of this contact (mm per step; 0: merely no closing).
    pub bias: f64,
}

/// What the solve did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactSolve {
    /// Force at each contact (N), ≥ 0.
    pub forces: Vec<f64>,
    /// Net wrench on each body (applied plus contacts).
    pub wrenches: Vec<Vec6>,
    /// Twist of each body per step.
    pub twists: Vec<Vec6>,
    /// Sweeps run.
    pub sweeps: usize,
    /// Largest violation left: most negative relative normal velocity below `bias` (mm/step).
    pub residual: f64,
}

/// Parameters of the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveParams {
    /// Twist per step per elastic twist (β × days per step).
    pub rate: f64,
    /// Ligament pressure threshold (kPa).
    pub threshold_kpa: f64,
    /// Pressure past which movement is no faster (kPa; infinite: none).
    pub saturation_kpa: f64,
    /// Convergence tolerance on relative velocities (mm per step).
    pub tolerance: f64,
    /// Most sweeps.
    pub max_sweeps: usize,
}

fn axpy(w: &mut Vec6, s: f64, x: &Vec6) {
    for (a, b) in w.iter_mut().zip(x) {
        *a += s * b;
    }
}

/// Solves the contact forces (see the module doc), starting from `warm` forces when given.
pub fn solve_contacts(
    bodies: &[PdlBody],
    contacts: &[ContactRow],
    warm: Option<&[f64]>,
    p: &SolveParams,
) -> ContactSolve {
    let mut wrenches: Vec<Vec6> = bodies.iter().map(|b| b.applied).collect();
    let mut forces = vec![0.0; contacts.len()];
    // Unit wrenches of each contact on b (+) and a (−), and the elastic curvature of each row.
    let rows: Vec<(Vec6, Vec6, f64)> = contacts
        .iter()
        .map(|c| {
            let (ba, bb) = (&bodies[c.a], &bodies[c.b]);
            let ja = ba.unit_wrench(c.normal, c.point);
            let jb = bb.unit_wrench(c.normal, c.point);
            let h = p.rate * (ba.compliance.quadratic(&ja) + bb.compliance.quadratic(&jb));
            (ja, jb, h)
        })
        .collect();
    if let Some(warm) = warm.filter(|w| w.len() == contacts.len()) {
        for (k, c) in contacts.iter().enumerate() {
            let f = warm[k].max(0.0);
            if f.is_finite() && f > 0.0 && rows[k].2 > 0.0 {
                forces[k] = f;
                axpy(&mut wrenches[c.a], -f, &rows[k].0);
                axpy(&mut wrenches[c.b], f, &rows[k].1);
            }
        }
    }
    let mut twists: Vec<Vec6> = bodies
        .iter()
        .zip(&wrenches)
        .map(|(b, w)| b.twist(w, p.rate, p.threshold_kpa, p.saturation_kpa))
        .collect();
    let normal_velocity = |twists: &[Vec6], c: &ContactRow| {
        let va = bodies[c.a].point_velocity(&twists[c.a], c.point);
        let vb = bodies[c.b].point_velocity(&twists[c.b], c.point);
        c.normal.dot(vb - va)
    };
    let mut sweeps = 0;
    while sweeps < p.max_sweeps && !contacts.is_empty() {
        sweeps += 1;
        let mut largest = 0.0f64;
        for (k, c) in contacts.iter().enumerate() {
            let (ja, jb, h) = &rows[k];
            if *h <= 0.0 || c.a == c.b {
                continue;
            }
            let vn = normal_velocity(&twists, c);
            let next = (forces[k] - (vn - c.bias) / h).max(0.0);
            let delta = next - forces[k];
            if delta == 0.0 {
                continue;
            }
            largest = largest.max((delta * h).abs());
            forces[k] = next;
            axpy(&mut wrenches[c.a], -delta, ja);
            axpy(&mut wrenches[c.b], delta, jb);
            for i in [c.a, c.b] {
                twists[i] =
                    bodies[i].twist(&wrenches[i], p.rate, p.threshold_kpa, p.saturation_kpa);
            }
        }
        if largest <= p.tolerance {
            break;
        }
    }
    let residual = contacts
        .iter()
        .map(|c| (c.bias - normal_velocity(&twists, c)).max(0.0))
        .fold(0.0, f64::max);
    ContactSolve {
        forces,
        wrenches,
        twists,
        sweeps,
        residual,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Mat6, vec6};

    /// A row of point-like teeth along x, each with compliance 1 mm/N in translation.
    fn row(n: usize, push: f64) -> Vec<PdlBody> {
        (0..n)
            .map(|i| PdlBody {
                centre: DVec3::new(i as f64, 0.0, 0.0),
                compliance: Mat6::identity(),
                area: 1.0,
                mean_spring: 1.0,
                applied: vec6(DVec3::X * if i == 0 { push } else { 0.0 }, DVec3::ZERO),
                appliance_stiffness: None,
            })
            .collect()
    }

    fn contacts(n: usize) -> Vec<ContactRow> {
        (0..n - 1)
            .map(|i| ContactRow {
                a: i,
                b: i + 1,
                point: DVec3::new(i as f64 + 0.5, 0.0, 0.0),
                normal: DVec3::X,
                bias: 0.0,
            })
            .collect()
    }

    fn params(threshold_kpa: f64) -> SolveParams {
        SolveParams {
            rate: 1.0,
            threshold_kpa,
            saturation_kpa: f64::INFINITY,
            tolerance: 1e-12,
            max_sweeps: 10_000,
        }
    }

    #[test]
    fn without_thresholds_a_push_moves_the_whole_row_together() {
        let bodies = row(4, 4.0);
        let s = solve_contacts(&bodies, &contacts(4), None, &params(0.0));
        // Four equal compliances share the push: 1 N each, forces 3, 2, 1 N down the row.
        for (f, want) in s.forces.iter().zip([3.0, 2.0, 1.0]) {
            assert!((f - want).abs() < 1e-6, "{:?}", s.forces);
        }
        for t in &s.twists {
            assert!((t[0] - 1.0).abs() < 1e-6, "{t:?}");
        }
        assert!(s.residual < 1e-9);
    }

    #[test]
    fn thresholds_stop_the_push_along_the_row() {
        // Pressure = force here (k̄/A = 1, compliance 1): a threshold of 1 N (1e-3 kPa units).
        let bodies = row(4, 2.5);
        let s = solve_contacts(&bodies, &contacts(4), None, &params(1.0e3));
        // 2.5 N: the first two teeth hold 1 N each, the third 0.5 N: nothing moves.
        assert!(
            s.twists.iter().all(|t| t.iter().all(|v| v.abs() < 1e-9)),
            "{s:?}"
        );
        assert!(
            s.forces[2] < 1e-6,
            "the fourth tooth feels nothing: {:?}",
            s.forces
        );
        assert!(s.residual < 1e-9);
        // 4 N: the row moves, and it moves slower than without thresholds.
        let s = solve_contacts(&row(4, 4.0), &contacts(4), None, &params(0.5e3));
        assert!(s.twists[0][0] > 1e-3 && s.twists[0][0] < 1.0, "{s:?}");
        for t in &s.twists {
            assert!((t[0] - s.twists[0][0]).abs() < 1e-6);
        }
    }

    #[test]
    fn separating_teeth_feel_no_force() {
        let mut bodies = row(2, 1.0);
        bodies[1].applied = vec6(DVec3::X * 3.0, DVec3::ZERO);
        let s = solve_contacts(&bodies, &contacts(2), Some(&[5.0]), &params(0.0));
        assert_eq!(s.forces, vec![0.0]);
        assert!(s.twists[1][0] > s.twists[0][0]);
    }
}
