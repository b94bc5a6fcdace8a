//! The `orthosim trees` report: a tree per tooth, its build time and fit.

use std::time::Instant;

use serde::Serialize;

use super::{
    build::TreeSettings,
    cache::{TreeCache, TreeSource},
    metrics::tree_fit,
    tree::SphereTree,
};
use crate::teeth::Dentition;

/// One tooth's line.
#[derive(Clone, Debug, Serialize)]
pub struct ToothTreeReport {
    /// FDI number.
    pub fdi: u8,
    /// Leaf spheres.
    pub leaves: usize,
    /// Relative outside volume, overlaps counted twice (the paper's measure).
    pub sov_sum: f64,
    /// Relative outside volume of the union of the leaves.
    pub sov_union: f64,
    /// Largest overhang of a leaf outside the tooth (mm).
    pub max_overhang_mm: f32,
    /// The coverage invariant holds.
    pub covered: bool,
    /// Time to build this shape's tree (ms); teeth sharing a shape share the build.
    pub build_ms: f64,
    /// The tree was read from the cache rather than built.
    pub from_cache: bool,
}

/// Means and extremes over the teeth.
#[derive(Clone, Debug, Serialize)]
pub struct TreeSummary {
    /// Mean of `sov_sum`.
    pub sov_sum_mean: f64,
    /// Least `sov_sum`.
    pub sov_sum_min: f64,
    /// Largest `sov_sum`.
    pub sov_sum_max: f64,
    /// Mean of `sov_union`.
    pub sov_union_mean: f64,
    /// Mean of `max_overhang_mm`.
    pub max_overhang_mm_mean: f64,
    /// Mean number of leaves.
    pub leaves_mean: f64,
    /// Every tree satisfies the invariant.
    pub all_covered: bool,
    /// Total build time of the distinct shapes' trees (ms, summed over threads).
    pub build_ms_total: f64,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct TreesReport {
    /// Builder name.
    pub method: super::build::TreeMethod,
    /// Branching factor.
    pub branching: u32,
    /// Levels including the root.
    pub depth: u32,
    /// Teeth in FDI order (extracted ones left out).
    pub teeth: Vec<ToothTreeReport>,
    /// Summary over the teeth.
    pub summary: TreeSummary,
}

/// A distinct shape's tree with its build time and fit.
struct ShapeResult {
    tree: SphereTree,
    build_ms: f64,
    from_cache: bool,
    fit: super::metrics::TreeFit,
}

/// Builds (or reads from `cache`) and measures the trees of a dentition's visible teeth (each
/// distinct shape once, on all cores); `progress` is called with (done, total) as shapes finish.
pub fn trees_report(
    d: &Dentition,
    settings: TreeSettings,
    cache: Option<&TreeCache>,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(TreesReport, Vec<(u8, SphereTree)>), super::build::TreeBuildError> {
    settings.validate()?;
    let mut shapes: Vec<std::sync::Arc<crate::teeth::ToothGeometry>> = Vec::new();
    for t in d.visible() {
        if !shapes
            .iter()
            .any(|s| std::sync::Arc::ptr_eq(s, &t.geometry))
        {
            shapes.push(t.geometry.clone());
        }
    }
    let total = shapes.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<ShapeResult> = crate::parallel::parallel_map(&shapes, |g| {
        let start = Instant::now();
        let (tree, source) = match cache {
            Some(cache) => cache.load_or_build(&settings, &g.mesh, &g.bvh),
            None => settings
                .build(&g.mesh, &g.bvh)
                .map(|t| (t, TreeSource::Built)),
        }
        .expect("settings validated above");
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let fit = tree_fit(&tree, g.mesh_ref(), g.frame.volume_mm3);
        progress(
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            total,
        );
        ShapeResult {
            tree,
            build_ms,
            from_cache: source == TreeSource::Cached,
            fit,
        }
    });
    let result_of = |t: &crate::teeth::PlacedTooth| {
        let i = shapes
            .iter()
            .position(|s| std::sync::Arc::ptr_eq(s, &t.geometry))
            .expect("every visible shape was built");
        &results[i]
    };
    let teeth: Vec<ToothTreeReport> = d
        .visible()
        .map(|t| {
            let r = result_of(t);
            ToothTreeReport {
                fdi: t.fdi.number(),
                leaves: r.fit.leaves,
                sov_sum: r.fit.sov_sum,
                sov_union: r.fit.sov_union,
                max_overhang_mm: r.fit.max_overhang_mm,
                covered: r.fit.covered,
                build_ms: r.build_ms,
                from_cache: r.from_cache,
            }
        })
        .collect();
    let n = teeth.len().max(1) as f64;
    let summary = TreeSummary {
        sov_sum_mean: teeth.iter().map(|t| t.sov_sum).sum::<f64>() / n,
        sov_sum_min: teeth
            .iter()
            .map(|t| t.sov_sum)
            .fold(f64::INFINITY, f64::min),
        sov_sum_max: teeth
            .iter()
            .map(|t| t.sov_sum)
            .fold(f64::NEG_INFINITY, f64::max),
        sov_union_mean: teeth.iter().map(|t| t.sov_union).sum::<f64>() / n,
        max_overhang_mm_mean: teeth.iter().map(|t| t.max_overhang_mm as f64).sum::<f64>() / n,
        leaves_mean: teeth.iter().map(|t| t.leaves as f64).sum::<f64>() / n,
        all_covered: teeth.iter().all(|t| t.covered),
        build_ms_total: results.iter().map(|r| r.build_ms).sum(),
    };
    let trees = d
        .visible()
        .map(|t| (t.fdi.number(), result_of(t).tree.clone()))
        .collect();
    Ok((
        TreesReport {
            method: settings.method,
            branching: settings.branching,
            depth: settings.depth,
            teeth,
            summary,
        },
        trees,
    ))
}
