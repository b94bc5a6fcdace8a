//! `orthosim report`: every case under every collision method, measured and written as JSON, CSV,
//! plots and one self-contained HTML page. Every figure is computed by the run.
//!
//! Per case: a run to rest under each method (block response), the distances of its adjacent
//! teeth, an extra run under the `ipr` response (continuous) for the interproximal reduction, and
//! the occlusal contacts of the exact run's final poses with the bite closed again (the upper arch
//! lowered by the case's bite opening). Once: the sphere-tree fit table (octree and medial at the
//! asked depths, on the `normal` case) and the Bolton analysis (anatomy widths, `normal` arches);
//! unless turned off, the exact stage's run time against error on the `normal` case's teeth at the
//! asked resolution (`orthosim bench --sweep`).

use std::{collections::BTreeMap, fmt::Write as _, path::Path};

use serde::Serialize;

use super::{
    AnalysisError,
    measures::{
        Bolton, GAP_FLAG_MM, IprEntry, OCCLUSAL_CONTACT_MM, OcclusalContact, Posed, arch_positions,
        bolton, ipr_entries, occlusal_contacts,
    },
    plot,
};
use crate::{
    collision::{Method, bench, bench::ParetoPoint},
    geometry::Pose,
    io::{OutputError, check_output, write_atomic},
    movement::{MovementSettings, Response, run_case},
    sphere_tree::{TreeCache, TreeMethod, TreeSettings, trees_report},
    teeth::{Arch, Case, Dentition},
};

/// What a report runs.
#[derive(Clone, Debug)]
pub struct ReportOptions {
    /// Case names or paths.
    pub cases: Vec<String>,
    /// Trees for the simulations.
    pub trees: TreeSettings,
    /// Depths of the fit table.
    pub fit_depths: Vec<u32>,
    /// Tree cache, if any.
    pub cache: Option<TreeCache>,
    /// Movement settings (the response is set per run).
    pub settings: MovementSettings,
    /// Step limit per run.
    pub max_steps: u64,
    /// Vertices per procedural tooth of the exact stage's run time against error (`None`: the
    /// sweep is left out).
    pub sweep_vertices: Option<u32>,
    /// Near-contact pair steps of that sweep.
    pub sweep_pairs: usize,
}

/// The exact stage's run time against error on the normal case (`orthosim bench --sweep`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepSummary {
    /// Vertices per procedural tooth.
    pub vertices: u32,
    /// Mean triangles per tooth.
    pub triangles_per_tooth: usize,
    /// Near-contact pair steps.
    pub pairs: usize,
    /// Timed passes per tolerance.
    pub passes: usize,
    /// Per tolerance.
    pub pareto: Vec<ParetoPoint>,
}

/// The sweep of the normal case's teeth at `vertices` per tooth.
fn sweep_summary(opts: &ReportOptions, vertices: u32) -> Result<SweepSummary, AnalysisError> {
    let mut loaded = Case::resolve("normal")?;
    loaded.case.resolution = Some(vertices);
    let dentition = Dentition::build(loaded)?;
    let teeth = bench::bench_teeth(&dentition, opts.trees, opts.cache.as_ref())?;
    let near = bench::near_contact_pairs(&teeth, opts.sweep_pairs, 0x5eed);
    let pareto = bench::sweep(
        &teeth,
        &near,
        &bench::SWEEP_TOLERANCES_MM,
        bench::SWEEP_PASSES,
        &|_| {},
    );
    Ok(SweepSummary {
        vertices,
        triangles_per_tooth: teeth
            .iter()
            .map(|t| t.shape.geometry.mesh.triangles.len())
            .sum::<usize>()
            / teeth.len().max(1),
        pairs: near.len(),
        passes: bench::SWEEP_PASSES,
        pareto,
    })
}

/// One method's outcome on one case.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AlgorithmSummary {
    /// Sum of adjacent centre distances (mm).
    pub total_centre_distance_mm: f32,
    /// Largest exact penetration at the end (mm).
    pub max_penetration_mm: f32,
    /// Teeth that moved more than 0.1 mm.
    pub moved: Vec<crate::teeth::Fdi>,
    /// Steps to rest.
    pub steps: u64,
    /// Came to rest.
    pub at_rest: bool,
    /// Sum of adjacent centre distances per arch: upper, lower (mm).
    pub arch_centre_distance_mm: [f32; 2],
    /// Adjacent pairs whose surface gap is above 1 mm.
    pub gaps_over_1mm: Vec<String>,
    /// Mean time per step (µs).
    pub step_us: f64,
}

/// A row of the sphere-tree fit table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitRow {
    /// Builder.
    pub method: TreeMethod,
    /// Levels including the root.
    pub depth: u32,
    /// Mean relative outside volume.
    pub sov_sum_mean: f64,
    /// Least.
    pub sov_sum_min: f64,
    /// Largest.
    pub sov_sum_max: f64,
    /// Mean leaves per tooth.
    pub leaves_mean: f64,
    /// Every tree covers its tooth.
    pub all_covered: bool,
}

/// `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Per case, per method.
    pub cases: BTreeMap<String, BTreeMap<String, AlgorithmSummary>>,
    /// Sphere-tree fit.
    pub tree_fit: Vec<FitRow>,
    /// Bolton analysis of the anatomy's widths and the normal arches.
    pub bolton: Bolton,
    /// IPR per contact under the `ipr` response, per case.
    pub ipr: BTreeMap<String, Vec<IprEntry>>,
    /// Occlusal contacts per tooth at the end of the exact run with the bite closed, per case.
    pub occlusion: BTreeMap<String, Vec<OcclusalContact>>,
    /// The PDL model beside published biomechanics (`orthosim validate`).
    pub biomechanics: super::Validation,
    /// The built-in normal case's bite, settled (`orthosim occlusion --settle`).
    pub bite: super::Bite,
    /// The exact stage's run time against error, if asked for.
    pub sweep: Option<SweepSummary>,
}

/// A row of `distances.csv`.
struct DistanceRow {
    case: String,
    algorithm: &'static str,
    a: u8,
    b: u8,
    centre: f32,
    gap: f32,
}

/// The built-in treatment cases (`--case all`).
pub const ALL_CASES: [&str; 3] = ["case1", "case2", "case3"];

/// Runs the report and writes its files into `out` (created if needed). `progress(what, done,
/// total)` is called as work finishes.
pub fn run_report(
    opts: &ReportOptions,
    out: &Path,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<Summary, AnalysisError> {
    std::fs::create_dir_all(out).map_err(|source| OutputError::CreateFolder {
        path: out.to_owned(),
        source,
    })?;
    // Outputs never replace inputs: refuse before any work if a file to be written is a case file
    // being read.
    let mut outputs: Vec<std::path::PathBuf> = [
        "summary.json",
        "distances.csv",
        "index.html",
        "occlusion_upper.svg",
        "occlusion_lower.svg",
        "occlusion_upper.png",
        "occlusion_lower.png",
    ]
    .iter()
    .map(|n| out.join(n))
    .collect();
    let mut resolved = Vec::new();
    for case in &opts.cases {
        let loaded = Case::resolve(case)?;
        outputs.push(out.join(format!("{}.svg", loaded.case.name)));
        outputs.push(out.join(format!("{}.png", loaded.case.name)));
        resolved.push(loaded);
    }
    if opts.sweep_vertices.is_some() {
        outputs.push(out.join("pareto.svg"));
        outputs.push(out.join("pareto.png"));
    }
    let inputs: Vec<&Path> = opts.cases.iter().map(Path::new).collect();
    for o in &outputs {
        check_output(o, &inputs)?;
    }
    let total = opts.cases.len() * (Method::ALL.len() + 1) + 2 * opts.fit_depths.len();
    let mut done = 0;
    let mut cases = BTreeMap::new();
    let mut rows = Vec::new();
    let mut ipr = BTreeMap::new();
    let mut occlusion = BTreeMap::new();
    let mut plots = Vec::new();
    for (case, loaded) in opts.cases.iter().zip(resolved) {
        let name = loaded.case.name.clone();
        let opening = loaded.case.bite_opening_mm.0;
        let mut per_method = BTreeMap::new();
        let mut series_data = Vec::new();
        let mut labels = Vec::new();
        for method in Method::ALL {
            progress(&format!("{name} {}", method.name()), done, total);
            let settings = MovementSettings {
                response: Response::Block,
                ..opts.settings
            };
            let run = run_case(
                case,
                method,
                settings,
                opts.trees,
                opts.cache.as_ref(),
                opts.max_steps,
                |_| {},
            )?;
            done += 1;
            let r = &run.report;
            let mut arch_total = [0.0f32; 2];
            for d in &r.distances {
                let k = if d.a.arch() == Arch::Upper { 0 } else { 1 };
                arch_total[k] += d.centre_distance_mm;
                rows.push(DistanceRow {
                    case: name.clone(),
                    algorithm: method.name(),
                    a: d.a.number(),
                    b: d.b.number(),
                    centre: d.centre_distance_mm,
                    gap: d.surface_gap_mm,
                });
            }
            labels = r
                .distances
                .iter()
                .map(|d| format!("{}-{}", d.a, d.b))
                .collect();
            series_data.push((
                method.name(),
                r.distances
                    .iter()
                    .map(|d| d.centre_distance_mm)
                    .collect::<Vec<_>>(),
                r.distances
                    .iter()
                    .map(|d| d.surface_gap_mm)
                    .collect::<Vec<_>>(),
            ));
            per_method.insert(
                method.name().to_owned(),
                AlgorithmSummary {
                    total_centre_distance_mm: r.total_centre_distance_mm,
                    max_penetration_mm: r.max_penetration_mm,
                    moved: r.moved.clone(),
                    steps: r.steps,
                    at_rest: r.at_rest,
                    arch_centre_distance_mm: arch_total,
                    gaps_over_1mm: r
                        .distances
                        .iter()
                        .filter(|d| d.surface_gap_mm > GAP_FLAG_MM)
                        .map(|d| format!("{}-{}", d.a, d.b))
                        .collect(),
                    step_us: r.step_us,
                },
            );
            if method == Method::Exact {
                let teeth: Vec<Posed> = run
                    .simulation
                    .teeth
                    .iter()
                    .map(|t| Posed {
                        fdi: t.fdi,
                        geometry: &t.shape.geometry,
                        pose: if t.fdi.arch() == Arch::Upper {
                            Pose::new(
                                t.pose.rotation,
                                t.pose.translation - glam::Vec3::Y * opening,
                            )
                        } else {
                            t.pose
                        },
                    })
                    .collect();
                occlusion.insert(name.clone(), occlusal_contacts(&teeth, OCCLUSAL_CONTACT_MM));
            }
        }
        progress(&format!("{name} ipr"), done, total);
        let settings = MovementSettings {
            response: Response::Ipr,
            ..opts.settings
        };
        let run = run_case(
            case,
            Method::Continuous,
            settings,
            opts.trees,
            opts.cache.as_ref(),
            opts.max_steps,
            |_| {},
        )?;
        done += 1;
        ipr.insert(
            name.clone(),
            ipr_entries(run.simulation.ipr.iter().map(|((a, b), mm)| (*a, *b, *mm))),
        );
        let series: Vec<plot::Series> = series_data
            .iter()
            .map(|(n, c, g)| plot::Series {
                name: n,
                centre: c.clone(),
                gap: g.clone(),
            })
            .collect();
        let title = format!("{name}: adjacent teeth at rest, per algorithm");
        let svg = plot::svg(&title, &labels, &series)?;
        write_atomic(&out.join(format!("{name}.svg")), &svg)?;
        plot::png(&out.join(format!("{name}.png")), &title, &labels, &series)?;
        plots.push((name.clone(), svg));
        cases.insert(name, per_method);
    }
    let normal = Dentition::build(Case::resolve("normal")?)?;
    let mut tree_fit = Vec::new();
    for method in [TreeMethod::Octree, TreeMethod::Medial] {
        for &depth in &opts.fit_depths {
            progress(&format!("trees {method:?} depth {depth}"), done, total);
            let settings = TreeSettings {
                method,
                branching: 8,
                depth,
            };
            let (r, _) = trees_report(&normal, settings, opts.cache.as_ref(), &|_, _| {})?;
            done += 1;
            tree_fit.push(FitRow {
                method,
                depth,
                sov_sum_mean: r.summary.sov_sum_mean,
                sov_sum_min: r.summary.sov_sum_min,
                sov_sum_max: r.summary.sov_sum_max,
                leaves_mean: r.summary.leaves_mean,
                all_covered: r.summary.all_covered,
            });
        }
    }
    progress("writing", done, total);
    let posed = Posed::of_dentition(&normal);
    let arches = arch_positions(&posed);
    let width = |f| {
        normal
            .tooth(f)
            .map_or(f32::NAN, |t| t.geometry.anatomy.mesiodistal)
    };
    let biomechanics = super::validate(&opts.settings, crate::teeth::ToothResolution::default())?;
    progress("bite", total, total);
    let normal_teeth = Posed::of_dentition(&normal);
    let bite = super::bite("normal", &normal_teeth, true, 0.0);
    let settled: Vec<Posed> = normal_teeth
        .iter()
        .map(|t| Posed {
            pose: if t.fdi.arch() == crate::teeth::Arch::Lower {
                bite.lower_pose.mul(&t.pose)
            } else {
                t.pose
            },
            ..*t
        })
        .collect();
    let mut maps = Vec::new();
    for (arch, file, title) in [
        (
            crate::teeth::Arch::Upper,
            "occlusion_upper.svg",
            "upper arch, settled bite",
        ),
        (
            crate::teeth::Arch::Lower,
            "occlusion_lower.svg",
            "lower arch, settled bite",
        ),
    ] {
        let svg = super::occlusal_map::occlusal_map_svg(&settled, arch, title)?;
        write_atomic(&out.join(file), &svg)?;
        super::occlusal_map::occlusal_map_png(
            &out.join(file).with_extension("png"),
            &settled,
            arch,
            title,
        )?;
        maps.push((title.to_owned(), svg));
    }
    let mut pareto_svg = None;
    let sweep = match opts.sweep_vertices {
        Some(n) => {
            progress("run time against error", total, total);
            let sweep = sweep_summary(opts, n)?;
            let title = format!(
                "exact stage, run time against error ({} triangles per tooth, {} near-contact steps)",
                sweep.triangles_per_tooth, sweep.pairs
            );
            let svg = super::pareto_plot::pareto_svg(&title, &sweep.pareto)?;
            write_atomic(&out.join("pareto.svg"), &svg)?;
            super::pareto_plot::pareto_png(&out.join("pareto.png"), &title, &sweep.pareto)?;
            pareto_svg = Some(svg);
            Some(sweep)
        }
        None => None,
    };
    let summary = Summary {
        cases,
        tree_fit,
        bolton: bolton(width, [&arches[0], &arches[1]]),
        ipr,
        occlusion,
        biomechanics,
        bite,
        sweep,
    };
    write_atomic(
        &out.join("summary.json"),
        serde_json::to_string_pretty(&summary).map_err(|e| AnalysisError::Json(e.to_string()))?,
    )?;
    let mut csv =
        String::from("case,algorithm,tooth_a,tooth_b,centre_distance_mm,surface_gap_mm\n");
    for r in &rows {
        // Writing to a String cannot fail.
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.4},{:.4}",
            r.case, r.algorithm, r.a, r.b, r.centre, r.gap
        );
    }
    write_atomic(&out.join("distances.csv"), &csv)?;
    write_atomic(
        &out.join("index.html"),
        html(&summary, &plots, &maps, pareto_svg.as_deref()),
    )?;
    progress("done", total, total);
    Ok(summary)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The self-contained page: tables and the plots inlined as SVG (the files beside it are linked).
fn html(
    s: &Summary,
    plots: &[(String, String)],
    maps: &[(String, String)],
    pareto: Option<&str>,
) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>orthosim report</title>\
<style>body{{font-family:sans-serif;margin:2em;max-width:1200px}}table{{border-collapse:collapse;margin:1em 0}}\
td,th{{border:1px solid #bbb;padding:3px 8px;text-align:right}}th{{background:#eee}}\
td.l,th.l{{text-align:left}}figure svg{{max-width:100%;height:auto;border:1px solid #ddd}}</style></head><body>\n\
<h1>orthosim report</h1>\n<p>Every figure below was computed by this run. Raw data: \
<a href=\"summary.json\">summary.json</a>, <a href=\"distances.csv\">distances.csv</a>.</p>\n"
    );
    h.push_str("<h2>Cases</h2>\n<table><tr><th class=\"l\">case</th><th class=\"l\">algorithm</th><th>steps</th><th>at rest</th><th class=\"l\">moved (&gt; 0.1 mm)</th><th>total centre distance mm</th><th>upper / lower mm</th><th>max penetration mm</th><th class=\"l\">gaps &gt; 1 mm</th><th>µs per step</th></tr>\n");
    for (case, methods) in &s.cases {
        for (m, a) in methods {
            let moved: Vec<String> = a.moved.iter().map(|f| f.to_string()).collect();
            let _ = writeln!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td><td>{:.3}</td><td>{:.3} / {:.3}</td><td>{:.4}</td><td class=\"l\">{}</td><td>{:.0}</td></tr>",
                escape(case),
                m,
                a.steps,
                a.at_rest,
                moved.join(" "),
                a.total_centre_distance_mm,
                a.arch_centre_distance_mm[0],
                a.arch_centre_distance_mm[1],
                a.max_penetration_mm,
                a.gaps_over_1mm.join(" "),
                a.step_us
            );
        }
    }
    h.push_str("</table>\n");
    for (p, svg) in plots {
        // The SVG is inlined (its XML declaration dropped) so the page stands alone.
        let body = svg.find("<svg").map_or(svg.as_str(), |i| &svg[i..]);
        let _ = writeln!(
            h,
            "<h3>{0}</h3>\n<figure>{1}<figcaption>{0}: centre distance and surface gap per \
adjacent pair, one series per algorithm. <a href=\"{0}.png\">PNG</a> · \
<a href=\"{0}.svg\">SVG</a></figcaption></figure>",
            escape(p),
            body
        );
    }
    h.push_str("<h2>Sphere-tree fit (relative outside volume, the paper's measure; branching 8)</h2>\n<table><tr><th class=\"l\">builder</th><th>depth</th><th>mean</th><th>min</th><th>max</th><th>leaves (mean)</th><th>covered</th></tr>\n");
    for r in &s.tree_fit {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{:?}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:.3}</td><td>{:.0}</td><td>{}</td></tr>",
            r.method,
            r.depth,
            r.sov_sum_mean,
            r.sov_sum_min,
            r.sov_sum_max,
            r.leaves_mean,
            r.all_covered
        );
    }
    h.push_str("</table>\n<p>The paper: Bradshaw's trees (4 levels) mean 0.16 (0.07–0.51); octree (6 levels) mean 1.25 (0.89–2.12).</p>\n");
    let b = &s.bolton;
    let _ = write!(
        h,
        "<h2>Bolton analysis and arch length</h2>\n<table>\
<tr><th class=\"l\">anterior ratio</th><td>{:.1} % (norm {:.1} %, mandibular excess {:+.2} mm)</td></tr>\
<tr><th class=\"l\">overall ratio</th><td>{:.1} % (norm {:.1} %, mandibular excess {:+.2} mm)</td></tr>\
<tr><th class=\"l\">arch-length discrepancy, upper</th><td>{:+.2} mm</td></tr>\
<tr><th class=\"l\">arch-length discrepancy, lower</th><td>{:+.2} mm</td></tr></table>\n",
        b.anterior_ratio_pct,
        b.anterior_norm_pct,
        b.anterior_excess_mm,
        b.overall_ratio_pct,
        b.overall_norm_pct,
        b.overall_excess_mm,
        b.arch_length_discrepancy_upper_mm,
        b.arch_length_discrepancy_lower_mm
    );
    h.push_str("<h2>Interproximal reduction (ipr response)</h2>\n<table><tr><th class=\"l\">case</th><th class=\"l\">contact</th><th>IPR mm</th><th class=\"l\">over 0.5 mm per contact</th><th class=\"l\">over 0.25 mm per surface</th></tr>\n");
    for (case, list) in &s.ipr {
        for e in list {
            let _ = writeln!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}-{}</td><td>{:.3}</td><td class=\"l\">{}</td><td class=\"l\">{}</td></tr>",
                escape(case),
                e.a,
                e.b,
                e.ipr_mm,
                e.over_contact_limit,
                e.over_surface_limit
            );
        }
    }
    h.push_str("</table>\n<h2>Occlusal contacts (exact run, bite closed; surface within 0.05 mm of the opposing arch)</h2>\n<table><tr><th class=\"l\">case</th><th class=\"l\">tooth</th><th>area mm²</th><th>least gap mm</th><th class=\"l\">antagonists</th></tr>\n");
    for (case, list) in &s.occlusion {
        for c in list.iter().filter(|c| c.area_mm2 > 0.0) {
            let ants: Vec<String> = c.antagonists.iter().map(|f| f.to_string()).collect();
            let _ = writeln!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.2}</td><td>{:.3}</td><td class=\"l\">{}</td></tr>",
                escape(case),
                c.fdi,
                c.area_mm2,
                c.min_gap_mm.unwrap_or(f32::NAN),
                ants.join(" ")
            );
        }
    }
    let b = &s.bite;
    let _ = write!(
        h,
        "</table>\n<h2>The bite (normal case, settled: <code>orthosim occlusion --settle</code>)</h2>\n<p>{}; contacting upper teeth right {}, left {}; incisor gap {:.3} mm; max penetration {:.4} mm.</p>\n<table><tr><th class=\"l\">pair</th><th>area mm²</th><th>gap mm</th></tr>\n",
        if b.stable {
            "stable".to_owned()
        } else {
            format!("not stable: {}", escape(b.why.as_deref().unwrap_or("")))
        },
        b.contact_teeth.right,
        b.contact_teeth.left,
        b.incisor_gap_mm,
        b.max_penetration_mm
    );
    for c in &b.contacts {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}-{}</td><td>{:.3}</td><td>{:.4}</td></tr>",
            c.upper, c.lower, c.area_mm2, c.min_gap_mm
        );
    }
    h.push_str("</table>\n<p>Occlusal contact maps (red at contact, yellow, green, blue at 0.5 mm, grey beyond):</p>\n");
    for ((title, svg), file) in maps.iter().zip(["occlusion_upper", "occlusion_lower"]) {
        let _ = writeln!(
            h,
            "<figure>{svg}<figcaption>{} (<a href=\"{file}.png\">PNG</a>, <a href=\"{file}.svg\">SVG</a>)</figcaption></figure>",
            escape(title)
        );
    }
    h.push_str("<h2>Tooth movement beside published biomechanics (PDL model, <code>orthosim validate</code>)</h2>\n<table><tr><th class=\"l\">quantity</th><th>tooth</th><th>M/F mm</th><th>value</th><th>accepted</th><th class=\"l\">unit</th><th class=\"l\">source</th><th class=\"l\">inside</th></tr>\n");
    for r in &s.biomechanics.rows {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td></tr>",
            r.name,
            r.tooth,
            r.mf.map_or(String::new(), |m| format!("{m:.0}")),
            r.value,
            r.reference
                .map_or("—".to_owned(), |[lo, hi]| format!("{lo:.3}–{hi:.3}")),
            escape(r.unit),
            escape(r.source),
            if r.passes() { "yes" } else { "no" }
        );
    }
    h.push_str("</table>\n");
    if let (Some(sw), Some(svg)) = (&s.sweep, pareto) {
        let _ = write!(
            h,
            "<h2>Exact contact: run time against error (<code>orthosim bench --sweep</code>)</h2>\n\
<p>Normal case at {} vertices per tooth ({} triangles), {} near-contact pair steps, median of {} \
passes on one core; errors are the exact gap or penetration of the meshes at the reported contact.</p>\n\
<table><tr><th>tolerance mm</th><th>µs per pair</th><th>range</th><th>contacts</th><th>max error mm</th>\
<th>mean error mm</th><th>false negatives</th></tr>\n",
            sw.vertices, sw.triangles_per_tooth, sw.pairs, sw.passes
        );
        for p in &sw.pareto {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{:.1}</td><td>{:.1}–{:.1}</td><td>{}</td><td>{:.4}</td><td>{:.4}</td><td>{}</td></tr>",
                p.tolerance_mm,
                p.us_per_pair,
                p.range_us[0],
                p.range_us[1],
                p.contacts,
                p.max_error_mm,
                p.mean_error_mm,
                p.false_negatives
            );
        }
        let body = svg.find("<svg").map_or(svg, |i| &svg[i..]);
        let _ = writeln!(
            h,
            "</table>\n<figure>{body}<figcaption>Run time and largest error per tolerance \
(<a href=\"pareto.png\">PNG</a>, <a href=\"pareto.svg\">SVG</a>)</figcaption></figure>"
        );
    }
    h.push_str("</body></html>\n");
    h
}
