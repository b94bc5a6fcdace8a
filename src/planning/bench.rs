//! `orthosim bench`'s plan line: a 14-tooth arch (the crowded case's lower arch, second molar to
//! second molar) set up and staged at a given resolution, every transition checked.

use std::time::Instant;

use serde::Serialize;

use super::{PlanLimits, automatic, plan};
use crate::teeth::{Case, CaseError, Dentition};

/// Timings of planning one arch (ms: least, median, most).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanBench {
    /// Teeth planned.
    pub teeth: usize,
    /// Triangles per tooth (mean; crown and root).
    pub triangles_per_tooth: usize,
    /// Runs each timing covers.
    pub runs: usize,
    /// Stages of the plan.
    pub stages: u32,
    /// Exact distance queries of one plan.
    pub measures: u64,
    /// Setting up the target.
    pub target_ms: [f64; 3],
    /// Staging and checking every transition.
    pub plan_ms: [f64; 3],
    /// Both.
    pub total_ms: [f64; 3],
}

fn spread(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    [v[0], v[v.len() / 2], v[v.len() - 1]]
}

/// Plans the crowded lower arch `runs` times at `vertices` per procedural tooth (the case's own
/// resolution when None).
///
/// # Errors
/// [`CaseError`] when the case cannot be built (never for the built-in case).
pub fn plan_bench(vertices: Option<u32>, runs: usize) -> Result<PlanBench, CaseError> {
    let mut loaded = Case::resolve("crowded")?;
    loaded.case.teeth = Some(crate::teeth::case::PresentTeeth::Only(
        crate::teeth::case::ToothList(
            [31, 32, 33, 34, 35, 36, 37, 41, 42, 43, 44, 45, 46, 47]
                .into_iter()
                .filter_map(|n| crate::teeth::Fdi::new(n).ok())
                .collect(),
        ),
    ));
    loaded.case.appliance = Default::default();
    if let Some(n) = vertices {
        loaded.case.resolution = Some(n);
    }
    let d = Dentition::build(loaded)?;
    let limits = PlanLimits::default();
    let (mut target_ms, mut plan_ms, mut total_ms) = (Vec::new(), Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let target = automatic(&d, &limits);
        let t = t0.elapsed().as_secs_f64() * 1e3;
        let p = plan(&d, &target, &limits, t);
        target_ms.push(t);
        plan_ms.push(p.plan_ms);
        total_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        last = Some(p);
    }
    let p = last.expect("at least one run");
    let teeth = d.visible().count();
    let triangles = d
        .visible()
        .map(|t| t.geometry.mesh.triangles.len())
        .sum::<usize>();
    Ok(PlanBench {
        teeth,
        triangles_per_tooth: triangles / teeth.max(1),
        runs: runs.max(1),
        stages: p.stages,
        measures: p.measures,
        target_ms: spread(target_ms),
        plan_ms: spread(plan_ms),
        total_ms: spread(total_ms),
    })
}
