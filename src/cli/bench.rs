//! `orthosim bench`: collision detection measured on seeded motions of real tooth pairs, per
//! method, and one full-mouth step.

use anyhow::Result;
use clap::Args;
use orthosim::{
    analysis::bite_bench::{BiteBench, bite_bench},
    collision::bench::{self, MethodReport},
    movement::bench::{PdlBench, pdl_bench},
    teeth::{Case, Dentition},
};

use super::{
    terminal::{print_json, progress_wanted},
    tree_args::TreeArgs,
};

/// `bench`'s arguments.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Number of pair motions.
    #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u64).range(1..=10_000_000))]
    pub pairs: u64,
    #[command(flatten)]
    pub trees: TreeArgs,
    /// Seed of the motions.
    #[arg(long, default_value_t = 0x5eed)]
    pub seed: u64,
    /// Tooth mesh resolution: `default` (the case's), `high` (scan resolution: 10,100
    /// vertices, about 20,000 triangles per tooth) or a number of vertices per tooth.
    #[arg(long, default_value = "default")]
    pub resolution: BenchResolution,
    /// Run time against error instead: the exact stage on the near-contact set at tolerances
    /// 0.001, 0.002, 0.005, 0.01, 0.02 and 0.05 mm (the pareto table).
    #[arg(long)]
    pub sweep: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `bench --resolution`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchResolution {
    /// The case's own.
    Default,
    /// Vertices per procedural tooth.
    Vertices(u32),
}

impl std::str::FromStr for BenchResolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "default" => Ok(Self::Default),
            "high" => Ok(Self::Vertices(10_100)),
            _ => match s.parse::<u32>() {
                Ok(n) if (20..=200_000).contains(&n) => Ok(Self::Vertices(n)),
                _ => Err(format!(
                    "'{s}': use default, high or a number of vertices per tooth (20–200000)"
                )),
            },
        }
    }
}

/// Builds the teeth and their trees, measures and prints the report.
pub fn run(args: BenchArgs) -> Result<()> {
    let mut loaded = Case::resolve(&args.case)?;
    if let BenchResolution::Vertices(n) = args.resolution {
        loaded.case.resolution = Some(n);
    }
    let dentition = Dentition::build(loaded)?;
    let progress = progress_wanted();
    if progress {
        eprint!("building trees…");
    }
    let teeth = bench::bench_teeth(
        &dentition,
        args.trees.settings(),
        args.trees.cache().as_ref(),
    )?;
    let pairs = args.pairs as usize;
    let near = bench::near_contact_pairs(&teeth, pairs, args.seed);
    if args.sweep {
        return sweep(&teeth, &near, args.json, progress);
    }
    let stress = bench::stress_pairs(&teeth, pairs, args.seed);
    let bar = |done: usize, total: usize| {
        if progress {
            eprint!("\rmeasuring {done}/{total}          ");
            if done == total {
                eprintln!();
            }
        }
    };
    let report = bench::run(&teeth, &near, &stress, &bar);
    if progress {
        eprint!("timing the PDL model…");
    }
    let vertices = match args.resolution {
        BenchResolution::Vertices(n) => Some(n),
        BenchResolution::Default => None,
    };
    let pdl = pdl_bench(vertices, 200)?;
    let bite = bite_bench(vertices, 3)?;
    let appliance = orthosim::appliance::bench::appliance_bench(20);
    let plan = orthosim::planning::bench::plan_bench(vertices, 3)?;
    if progress {
        eprintln!();
    }
    // The exact stage's single query on the near-contact set of this run.
    let exact_us = report
        .methods
        .iter()
        .find(|m| m.method == "exact")
        .map_or(f64::NAN, |m| m.us_per_pair);
    if args.json {
        #[derive(serde::Serialize)]
        struct Output<'a> {
            #[serde(flatten)]
            report: &'a bench::BenchReport,
            pdl: &'a PdlBench,
            bite: &'a BiteBench,
            appliance: &'a orthosim::appliance::bench::ApplianceBench,
            plan: PlanLine<'a>,
        }
        #[derive(serde::Serialize)]
        struct PlanLine<'a> {
            #[serde(flatten)]
            bench: &'a orthosim::planning::bench::PlanBench,
            exact_query_us: f64,
            ratio_to_exact_query: f64,
        }
        return print_json(&Output {
            report: &report,
            pdl: &pdl,
            bite: &bite,
            appliance: &appliance,
            plan: PlanLine {
                bench: &plan,
                exact_query_us: exact_us,
                ratio_to_exact_query: plan.total_ms[1] * 1e3 / exact_us.max(1e-9),
            },
        });
    }
    let tree = args.trees.tree;
    table(
        format!(
            "{} near-contact pair steps, {tree:?} trees (depth 4)",
            report.pairs
        ),
        &report.methods,
    );
    table(
        format!(
            "{} stress pair steps (0.01–5 mm, ±15°), {tree:?} trees (depth 4)",
            report.stress.pairs
        ),
        &report.stress.methods,
    );
    println!(
        "full-mouth step (continuous): {:.1} µs",
        report.full_mouth_step_us
    );
    for (what, t) in [
        ("case resolution", &pdl.stiffness_case_resolution),
        ("scan resolution", &pdl.stiffness_scan_resolution),
    ] {
        println!(
            "PDL stiffness, upper first molar at {what} ({} triangles): {:.2} ms (median of {}, {:.2}–{:.2})",
            t.triangles, t.ms, t.runs, t.range_ms[0], t.range_ms[1]
        );
    }
    for s in &pdl.steps {
        println!(
            "case 1 step ({}, {} steps): loads and motion {:.1} µs, of which contact solve {:.1} µs ({:.1} contacts); collision {:.1} µs",
            s.model,
            s.steps,
            s.motion_us_per_step,
            s.contact_solve_us_per_step,
            s.mean_contacts,
            s.collision_us_per_step
        );
    }
    println!(
        "bite of the normal case ({} triangles per tooth, {} runs): measuring it {:.0}–{:.0} ms, settling it {:.0}–{:.0} ms, a 6 mm right excursion {:.0}–{:.0} ms",
        bite.triangles_per_tooth,
        bite.runs,
        bite.measure_ms[0],
        bite.measure_ms[1],
        bite.settle_ms[0],
        bite.settle_ms[1],
        bite.excursion_ms[0],
        bite.excursion_ms[1]
    );
    let a = &appliance;
    println!(
        "appliance ({} brackets, {}-node 0.014\" NiTi wire, {} runs{}): a step's solve {:.0} µs (median; {:.0}–{:.0}, {} Newton iterations), {:.1}× the full-mouth step; engaging the wire {:.0} µs",
        a.brackets,
        a.nodes,
        a.runs,
        if a.converged { "" } else { ", NOT CONVERGED" },
        a.step_us[1],
        a.step_us[0],
        a.step_us[2],
        a.step_iterations,
        a.step_us[1] / report.full_mouth_step_us.max(1e-9),
        a.engage_us[1]
    );
    println!(
        "plan ({} teeth of the crowded lower arch, {} triangles per tooth, {} stages, {} runs): set-up and staging {:.0} ms (median; {:.0}–{:.0}; target {:.0} ms, stages and checks {:.0} ms, {} exact distance queries), {:.0}× the exact stage's single query ({:.1} µs)",
        plan.teeth,
        plan.triangles_per_tooth,
        plan.stages,
        plan.runs,
        plan.total_ms[1],
        plan.total_ms[0],
        plan.total_ms[2],
        plan.target_ms[1],
        plan.plan_ms[1],
        plan.measures,
        plan.total_ms[1] * 1e3 / exact_us.max(1e-9),
        exact_us
    );
    Ok(())
}

/// `bench --sweep`: the pareto table of the exact stage.
fn sweep(
    teeth: &[bench::BenchTooth],
    near: &[(
        usize,
        usize,
        orthosim::collision::Motion,
        orthosim::collision::Motion,
    )],
    json: bool,
    progress: bool,
) -> Result<()> {
    let triangles = teeth
        .iter()
        .map(|t| t.shape.geometry.mesh.triangles.len())
        .sum::<usize>()
        / teeth.len().max(1);
    let passes = bench::SWEEP_PASSES;
    let bar = |done: usize| {
        if progress {
            eprint!("\rsweeping: pass {done}/{passes}          ");
            if done == passes {
                eprintln!();
            }
        }
    };
    let pareto = bench::sweep(teeth, near, &bench::SWEEP_TOLERANCES_MM, passes, &bar);
    if json {
        #[derive(serde::Serialize)]
        struct Output<'a> {
            pairs: usize,
            triangles_per_tooth: usize,
            passes: usize,
            pareto: &'a [bench::ParetoPoint],
        }
        return print_json(&Output {
            pairs: near.len(),
            triangles_per_tooth: triangles,
            passes,
            pareto: &pareto,
        });
    }
    println!(
        "exact stage, {} near-contact pair steps, {triangles} triangles per tooth (median of {passes} passes)",
        near.len()
    );
    println!(
        "{:>12} {:>10} {:>17} {:>9} {:>13} {:>14} {:>9}",
        "tolerance mm",
        "µs/pair",
        "range",
        "contacts",
        "max error mm",
        "mean error mm",
        "false neg"
    );
    for p in &pareto {
        println!(
            "{:>12} {:>10.1} {:>17} {:>9} {:>13.4} {:>14.4} {:>9}",
            p.tolerance_mm,
            p.us_per_pair,
            format!("{:.1}–{:.1}", p.range_us[0], p.range_us[1]),
            p.contacts,
            p.max_error_mm,
            p.mean_error_mm,
            p.false_negatives
        );
    }
    Ok(())
}

fn table(title: String, methods: &[MethodReport]) {
    println!("{title}");
    println!(
        "{:>11} {:>11} {:>9} {:>9} {:>14} {:>13}",
        "method", "µs/pair", "false neg", "false pos", "mean error mm", "max error mm"
    );
    for m in methods {
        println!(
            "{:>11} {:>11.2} {:>9} {:>9} {:>14.4} {:>13.4}",
            m.method,
            m.us_per_pair,
            m.false_negatives,
            m.false_positives,
            m.mean_error_mm,
            m.max_error_mm
        );
    }
}
