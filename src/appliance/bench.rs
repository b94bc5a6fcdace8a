//! `orthosim bench`'s appliance line: the archwire's equilibrium on a 14-bracket arch, as each
//! simulation step asks for it.

use std::time::Instant;

use glam::DVec3;
use serde::Serialize;

use super::archwire::{ArchForm, ArchSize, lay};
use super::bracket::{Bracket, Slot, ToothAxes};
use super::prescription::Prescription;
use super::rod::{Holder, Rod, STEP_ITERATIONS, STEP_TOLERANCE_N, STOP_PLAY_MM, Settings};
use super::{WireMaterial, WireSize};
use crate::teeth::{Arch, Fdi};

/// Timings of the appliance solve (µs: least, median, most).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ApplianceBench {
    /// Brackets on the arch.
    pub brackets: usize,
    /// Nodes of the wire.
    pub nodes: usize,
    /// Runs each timing covers.
    pub runs: usize,
    /// From the passive wire to equilibrium with the brackets up to 1 mm out of the form (a wire
    /// just engaged).
    pub engage_us: [f64; 3],
    /// From the last equilibrium after every bracket moved 0.02 mm (one simulation step), to the
    /// simulation's step tolerance ([`super::rod::STEP_TOLERANCE_N`]).
    pub step_us: [f64; 3],
    /// Newton iterations of a step's solve (median).
    pub step_iterations: usize,
    /// True when every solve converged.
    pub converged: bool,
}

fn spread(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    [v[0], v[v.len() / 2], v[v.len() - 1]]
}

/// Times the solve of a 0.014" NiTi wire in 0.022" slots through 14 lower brackets (second molar
/// to second molar), `runs` times each.
pub fn appliance_bench(runs: usize) -> ApplianceBench {
    appliance_bench_with(runs, WireMaterial::NiTi, WireSize::Round(0.014), false)
}

/// [`appliance_bench`] with another wire; `tight` closes every slot's play (the solve then meets
/// no change of which slots bear, which is what its Newton iterations mostly go to).
pub fn appliance_bench_with(
    runs: usize,
    material: WireMaterial,
    wire: WireSize,
    tight: bool,
) -> ApplianceBench {
    let runs = runs.max(1);
    let size = ArchSize {
        molar_width_mm: 52.0,
        depth_mm: 30.0,
    };
    let form = ArchForm::Ovoid;
    // Slot centres spaced along the form, each up to 1 mm off it in a fixed pattern.
    let along = lay(form, &size, 0.0, 0.0, &[], &[]);
    let n = along.nodes.len();
    let fdis: Vec<Fdi> = (1..=7)
        .rev()
        .map(|p| Fdi::from_parts(4, p))
        .chain((1..=7).map(|p| Fdi::from_parts(3, p)))
        .filter_map(Result::ok)
        .collect();
    let mut points = Vec::new();
    let mut brackets = Vec::new();
    for (k, fdi) in fdis.iter().enumerate() {
        let i = 3 + (n - 7) * k / (fdis.len() - 1);
        let node = along.nodes[i];
        let buccal = node.q * DVec3::Z;
        let off = buccal * (0.9 * (k as f64 * 1.7).sin()) + DVec3::Y * (0.4 * (k as f64).cos());
        points.push(node.x + off);
        let axes = ToothAxes {
            buccal,
            along: node.q * DVec3::X,
            along_is_mesial: k < 7,
        };
        let mut b = Bracket::place(
            Arch::Lower,
            fdi.kind(),
            DVec3::ZERO,
            &axes,
            Prescription::Mbt,
            Slot::S022,
        );
        // Placed in the world directly: the tooth frame is the world here.
        b.centre = node.x + off;
        brackets.push(b);
    }
    let laid = lay(form, &size, 0.0, 0.0, &points, &[]);
    let holders = |shift: f64| -> Vec<Holder> {
        brackets
            .iter()
            .zip(&laid.held)
            .enumerate()
            .map(|(k, (b, &node))| {
                let mut h = b.holder(
                    node,
                    glam::DQuat::IDENTITY,
                    DVec3::new(0.0, 0.0, shift),
                    wire,
                );
                // The simulation's crimped stop on a central incisor's bracket.
                if k == 7 {
                    h.play[0] = STOP_PLAY_MM;
                }
                if tight {
                    for p in &mut h.play[1..] {
                        if p.is_finite() {
                            *p = 0.0;
                        }
                    }
                }
                h
            })
            .collect()
    };
    let settings = Settings::default();
    // A step's solve as the simulation asks for it.
    let step_settings = Settings {
        tolerance_n: STEP_TOLERANCE_N,
        max_iterations: STEP_ITERATIONS,
    };
    let mut engage = Vec::new();
    let mut step = Vec::new();
    let mut iterations = Vec::new();
    let mut converged = true;
    for _ in 0..runs {
        let mut rod = Rod::new(laid.nodes.clone(), wire, material);
        let t = Instant::now();
        converged &= rod.solve(&holders(0.0), &[], &settings).converged;
        engage.push(t.elapsed().as_secs_f64() * 1e6);
        let t = Instant::now();
        let e = rod.solve(&holders(0.02), &[], &step_settings);
        step.push(t.elapsed().as_secs_f64() * 1e6);
        converged &= e.converged;
        iterations.push(e.iterations as f64);
    }
    ApplianceBench {
        brackets: brackets.len(),
        nodes: laid.nodes.len(),
        runs,
        engage_us: spread(engage),
        step_us: spread(step),
        step_iterations: spread(iterations)[1] as usize,
        converged,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_bench_solves_its_arch() {
        let b = super::appliance_bench(1);
        assert_eq!(b.brackets, 14);
        assert!(
            b.converged && b.nodes > 40 && b.step_iterations >= 1,
            "{b:?}"
        );
        assert!(b.engage_us[0] > 0.0 && b.step_us[0] > 0.0);
    }
}
