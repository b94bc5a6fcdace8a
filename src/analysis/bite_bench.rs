//! What the bite costs: a settle of the normal case and a 6 mm lateral excursion from it, with
//! measuring the bite as it stands as the same run's reference (`orthosim bench`'s `bite`
//! section).

use std::time::Instant;

use serde::Serialize;

use super::{AnalysisError, ExcursionKind, bite, excursion, measures::Posed};
use crate::teeth::{Case, Dentition};

/// Times of the bite's stages (ms), median of `runs`, with their range.
#[derive(Clone, Debug, Serialize)]
pub struct BiteBench {
    /// Triangles per tooth (mean).
    pub triangles_per_tooth: usize,
    /// Measuring the bite as the case places it (contacts and areas), ms.
    pub measure_ms: [f64; 2],
    /// Settling the lower arch from where the case places it, ms (contacts and areas included).
    pub settle_ms: [f64; 2],
    /// A 6 mm right excursion in 0.5 mm steps from the settled bite, ms.
    pub excursion_ms: [f64; 2],
    /// Runs timed.
    pub runs: usize,
}

/// Times the normal case's bite at `vertices` per tooth (None: the case's), `runs` times each.
///
/// # Errors
/// The normal case cannot be built.
pub fn bite_bench(vertices: Option<u32>, runs: usize) -> Result<BiteBench, AnalysisError> {
    let mut loaded = Case::resolve("normal")?;
    loaded.case.resolution = vertices;
    let d = Dentition::build(loaded)?;
    let teeth = Posed::of_dentition(&d);
    let range = |mut t: Vec<f64>| {
        t.sort_by(f64::total_cmp);
        [t[0], t[t.len() - 1]]
    };
    let (mut measure, mut settle, mut slide) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        std::hint::black_box(bite("normal", &teeth, false, 0.0));
        measure.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let b = bite("normal", &teeth, true, 0.0);
        settle.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        std::hint::black_box(excursion(&teeth, &b.lower_pose, ExcursionKind::Right, 6.0));
        slide.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(BiteBench {
        triangles_per_tooth: teeth
            .iter()
            .map(|t| t.geometry.mesh.triangles.len())
            .sum::<usize>()
            / teeth.len().max(1),
        measure_ms: range(measure),
        settle_ms: range(settle),
        excursion_ms: range(slide),
        runs: runs.max(1),
    })
}
