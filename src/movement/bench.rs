//! What the PDL model costs: the ligament's stiffness per tooth shape, and the loads, contact
//! solve and motion of a full-mouth step beside its collision detection (`orthosim bench`'s
//! `pdl` section).

use std::time::Instant;

use serde::Serialize;

use super::{MovementError, MovementModel, MovementSettings, Simulation, pdl::PdlStiffness};
use crate::{
    collision::{Method, collision_shapes},
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Arch, Case, Dentition, ToothGeometry, ToothKind, ToothResolution},
};

/// The stiffness of one tooth shape.
#[derive(Clone, Debug, Serialize)]
pub struct StiffnessTiming {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Median time of one stiffness (ms) over `runs`.
    pub ms: f64,
    /// Fastest and slowest run (ms).
    pub range_ms: [f64; 2],
    /// Runs timed.
    pub runs: usize,
}

/// One model's full-mouth steps.
#[derive(Clone, Debug, Serialize)]
pub struct StepTiming {
    /// Movement model.
    pub model: &'static str,
    /// Steps timed.
    pub steps: u64,
    /// Loads and motion per step (µs): under the PDL model the bodies, the contact solve and
    /// the motions.
    pub motion_us_per_step: f64,
    /// Of which the contact solve (µs per step).
    pub contact_solve_us_per_step: f64,
    /// Collision detection and response in the same steps (µs per step).
    pub collision_us_per_step: f64,
    /// Mean touching contacts in the solve.
    pub mean_contacts: f64,
}

/// The `pdl` section of `orthosim bench`.
#[derive(Clone, Debug, Serialize)]
pub struct PdlBench {
    /// The upper first molar at the case's resolution.
    pub stiffness_case_resolution: StiffnessTiming,
    /// The upper first molar at about 30,000 triangles.
    pub stiffness_scan_resolution: StiffnessTiming,
    /// Case 1 (four molars pushing premolars), continuous detection, octree trees, both models
    /// in the same run.
    pub steps: Vec<StepTiming>,
}

fn time_stiffness(g: &ToothGeometry, runs: usize) -> Result<StiffnessTiming, MovementError> {
    let settings = MovementSettings::default().pdl;
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let t = Instant::now();
        let p = PdlStiffness::of(g, &settings).map_err(|source| MovementError::Pdl {
            fdi: crate::teeth::Fdi::new(16).expect("16 is a tooth"),
            source,
        })?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
        std::hint::black_box(p);
    }
    times.sort_by(f64::total_cmp);
    Ok(StiffnessTiming {
        triangles: g.mesh.triangles.len(),
        ms: times[times.len() / 2],
        range_ms: [times[0], times[times.len() - 1]],
        runs,
    })
}

/// Measures the stiffness at the case's resolution (`vertices`) and at scan resolution, and
/// `steps` steps of case 1 under each model.
///
/// # Errors
/// Case 1 cannot be built or simulated.
pub fn pdl_bench(vertices: Option<u32>, steps: u64) -> Result<PdlBench, MovementError> {
    let res = ToothResolution {
        vertices: vertices.unwrap_or(ToothResolution::default().vertices),
    };
    let molar = |r| ToothGeometry::procedural(Arch::Upper, ToothKind::FirstMolar, r);
    let stiffness_case_resolution = time_stiffness(&molar(res), 9)?;
    let stiffness_scan_resolution =
        time_stiffness(&molar(ToothResolution { vertices: 15_000 }), 5)?;
    let mut loaded = Case::resolve("case1")?;
    loaded.case.resolution = vertices;
    let d = Dentition::build(loaded)?;
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None)?;
    let mut timings = Vec::new();
    for model in MovementModel::ALL {
        let settings = MovementSettings {
            model,
            ..Default::default()
        };
        let mut sim = Simulation::new(&d, shapes.clone(), Method::Continuous, settings)?;
        let (mut motion, mut solve, mut collision, mut contacts) = (0u64, 0u64, 0u64, 0usize);
        for _ in 0..steps {
            contacts += sim.pdl.touching.len();
            let out = sim.step();
            motion += out.motion_ns;
            solve += out.contact_solve_ns;
            collision += out.collision_ns;
        }
        let n = steps.max(1) as f64;
        timings.push(StepTiming {
            model: model.name(),
            steps,
            motion_us_per_step: motion as f64 / 1e3 / n,
            contact_solve_us_per_step: solve as f64 / 1e3 / n,
            collision_us_per_step: collision as f64 / 1e3 / n,
            mean_contacts: contacts as f64 / n,
        });
    }
    Ok(PdlBench {
        stiffness_case_resolution,
        stiffness_scan_resolution,
        steps: timings,
    })
}
