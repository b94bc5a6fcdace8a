//! The `orthosim` command: the viewer by default, headless subcommands for everything else.

use std::{io::IsTerminal, process::ExitCode};

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use orthosim::{
    analysis::inspect,
    collision::Method,
    movement::{MovementSettings, Response, run_case},
    sphere_tree::{
        TreeCache, TreeMethod, TreeSettings,
        report::{trees_report, write_atomic},
    },
    teeth::{Case, Dentition},
};

/// orthosim: interactive orthodontic simulation with fast, exact tooth collision detection.
#[derive(Parser, Debug)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Open the 3D viewer (the default when no subcommand is given).
    View {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Camera view at start-up (keys 1–5 switch views in the window).
        #[cfg(feature = "viewer")]
        #[arg(long, value_enum, default_value_t = orthosim::occlusion_view::CameraPreset::Frontal)]
        camera: orthosim::occlusion_view::CameraPreset,
    },
    /// Open the real window, simulate a case for some frames and save a screenshot (PNG).
    Screenshot {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Camera view.
        #[cfg(feature = "viewer")]
        #[arg(long, value_enum, default_value_t = orthosim::occlusion_view::CameraPreset::Frontal)]
        view: orthosim::occlusion_view::CameraPreset,
        /// Frames to run once the simulation is ready (trees built).
        #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
        frames: u32,
        /// Sphere-tree builder (depth 4, branching 8; medial from the user's tree cache).
        #[arg(long, value_enum, default_value_t = TreeMethod::Medial)]
        tree: TreeMethod,
        /// Overlays: `spheres:LEVEL` (a sphere-tree level, 0 = root), `contacts` (overlapping leaf
        /// spheres and contact points of the step), `occlusion-map` (surfaces coloured by their
        /// distance to the opposing arch) or `circles` (bounding circles, with `--algorithm
        /// circles`); repeat for several.
        #[cfg(feature = "viewer")]
        #[arg(long)]
        overlay: Vec<orthosim::occlusion_view::Overlay>,
        /// Narrow-phase method of the simulation.
        #[arg(long, value_enum, default_value_t = Method::Continuous)]
        algorithm: Method,
        /// How roots are drawn: translucent, solid or hidden.
        #[cfg(feature = "viewer")]
        #[arg(long, default_value = "translucent")]
        roots: orthosim::occlusion_view::Roots,
        /// Hide an arch (`upper` or `lower`), e.g. to see the other one's occlusal surface.
        #[arg(long, value_parser = ["upper", "lower"])]
        hide: Vec<String>,
        /// The PNG file to write.
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// List the built-in cases, one line each.
    Cases,
    /// Run a case headless until the teeth come to rest and report where they went.
    Simulate {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "case1")]
        case: String,
        /// Narrow-phase method.
        #[arg(long, value_enum, default_value_t = Method::Continuous)]
        algorithm: Method,
        /// Collision response.
        #[arg(long, value_enum, default_value_t = Response::Block)]
        response: Response,
        /// Most steps to run.
        #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
        max_steps: u64,
        /// Sphere-tree builder (depth 4, branching 8).
        #[arg(long, value_enum, default_value_t = TreeMethod::Medial)]
        tree: TreeMethod,
        /// Build every tree afresh instead of using the user's tree cache.
        #[arg(long)]
        no_cache: bool,
        /// Movement settings (a RON `MovementSettings`; missing fields keep their defaults);
        /// `--response` overrides the file's response.
        #[arg(long)]
        settings: Option<std::path::PathBuf>,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Run cases under every collision method and write a report: summary.json, distances.csv,
    /// one plot per case (PNG and SVG) and index.html.
    Report {
        /// `all` (case1, case2, case3), a built-in case name or a path to a .ron case file.
        #[arg(long, default_value = "all")]
        case: String,
        /// Folder to write into (created if needed).
        #[arg(long)]
        out: std::path::PathBuf,
        /// Sphere-tree builder for the simulations (depth 4, branching 8).
        #[arg(long, value_enum, default_value_t = TreeMethod::Medial)]
        tree: TreeMethod,
        /// Depths of the sphere-tree fit table (octree and medial), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "3,4,5,6", value_parser = clap::value_parser!(u32).range(1..=7))]
        fit_depths: Vec<u32>,
        /// Most steps per run.
        #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
        max_steps: u64,
        /// Build every tree afresh instead of using the user's tree cache.
        #[arg(long)]
        no_cache: bool,
    },
    /// Print per-tooth mesh data and exact gaps and penetrations of a case.
    Inspect {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Vertices per procedural tooth, overriding the case (125 is the paper's; 10100 gives
        /// about 20,000 triangles per tooth).
        #[arg(long, value_parser = clap::value_parser!(u32).range(20..=200_000))]
        resolution: Option<u32>,
    },
    /// Write a case as one STL file per tooth plus a RON case file that names them (a template
    /// for patient cases, and the import path's round trip).
    ExportCase {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Folder to write into (created if needed).
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// Build each tooth's sphere tree and report its fit (the paper's relative outside volume).
    Trees {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Tree builder.
        #[arg(long, value_enum, default_value_t = TreeMethod::Octree)]
        method: TreeMethod,
        /// Levels including the root.
        #[arg(long, default_value_t = 4)]
        depth: u32,
        /// Children per node.
        #[arg(long, default_value_t = 8)]
        branching: u32,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Write one Bradshaw .sph file per tooth into this folder.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Read trees from, and store new ones in, this cache folder (build_ms is then the time to
        /// read and check a cached tree).
        #[arg(long)]
        cache: Option<std::path::PathBuf>,
        /// Vertices per procedural tooth, overriding the case (125 is the paper's; 10100 gives
        /// about 20,000 triangles per tooth).
        #[arg(long, value_parser = clap::value_parser!(u32).range(20..=200_000))]
        resolution: Option<u32>,
    },
    /// Measure collision detection: µs per pair query and errors of each method on seeded
    /// near-contact motions of real teeth, and the cost of one full-mouth step.
    Bench {
        /// Built-in case name or path to a .ron case file.
        #[arg(long, default_value = "normal")]
        case: String,
        /// Number of pair motions.
        #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u64).range(1..=10_000_000))]
        pairs: u64,
        /// Sphere-tree builder for the teeth (depth 4, branching 8).
        #[arg(long, value_enum, default_value_t = TreeMethod::Medial)]
        tree: TreeMethod,
        /// Seed of the motions.
        #[arg(long, default_value_t = 0x5eed)]
        seed: u64,
        /// Tooth mesh resolution: `default` (the case's), `high` (scan resolution: 10,100
        /// vertices, about 20,000 triangles per tooth) or a number of vertices per tooth.
        #[arg(long, default_value = "default")]
        resolution: BenchResolution,
        /// Build every tree afresh instead of using the user's tree cache.
        #[arg(long)]
        no_cache: bool,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // No subcommand: the viewer on the default case.
    let command = cli.command.unwrap_or(Command::View {
        case: "normal".into(),
        #[cfg(feature = "viewer")]
        camera: Default::default(),
    });
    let result = match command {
        #[cfg(feature = "viewer")]
        Command::View { case, camera } => view(&case, camera),
        #[cfg(not(feature = "viewer"))]
        Command::View { case } => view(&case),
        Command::Trees {
            case,
            method,
            depth,
            branching,
            json,
            out,
            cache,
            resolution,
        } => run_trees(
            &case,
            TreeSettings {
                method,
                branching,
                depth,
            },
            json,
            out.as_deref(),
            cache.map(TreeCache::new).as_ref(),
            resolution,
        ),
        Command::Bench {
            case,
            pairs,
            tree,
            seed,
            resolution,
            no_cache,
            json,
        } => run_bench(
            &case,
            pairs as usize,
            tree,
            (seed, resolution),
            no_cache,
            json,
        ),
        Command::Simulate {
            case,
            algorithm,
            response,
            max_steps,
            tree,
            no_cache,
            settings,
            json,
        } => run_simulate(
            &case,
            algorithm,
            response,
            max_steps,
            tree,
            no_cache,
            settings.as_deref(),
            json,
        ),
        Command::Report {
            case,
            out,
            tree,
            fit_depths,
            max_steps,
            no_cache,
        } => run_report_command(&case, &out, tree, fit_depths, max_steps, no_cache),
        #[cfg(feature = "viewer")]
        Command::Screenshot {
            case,
            view,
            frames,
            tree,
            overlay,
            algorithm,
            roots,
            hide,
            out,
        } => screenshot(
            &case,
            view,
            frames,
            tree,
            &overlay,
            (algorithm, roots),
            &hide,
            &out,
        ),
        #[cfg(not(feature = "viewer"))]
        Command::Screenshot { .. } => view("none"),
        Command::ExportCase { case, out } => run_export_case(&case, &out),
        Command::Cases => {
            list_cases();
            Ok(())
        }
        Command::Inspect {
            case,
            json,
            resolution,
        } => run_inspect(&case, json, resolution),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("orthosim: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// `bench --resolution`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BenchResolution {
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

fn run_bench(
    case: &str,
    pairs: usize,
    tree: TreeMethod,
    (seed, resolution): (u64, BenchResolution),
    no_cache: bool,
    json: bool,
) -> Result<()> {
    use orthosim::collision::bench;
    let mut loaded = Case::resolve(case)?;
    if let BenchResolution::Vertices(n) = resolution {
        loaded.case.resolution = Some(n);
    }
    let dentition = Dentition::build(loaded)?;
    let settings = TreeSettings {
        method: tree,
        branching: 8,
        depth: 4,
    };
    let cache = if no_cache {
        None
    } else {
        TreeCache::user_default()
    };
    let progress = std::io::stderr().is_terminal();
    if progress {
        eprint!("building trees…");
    }
    let teeth = bench::bench_teeth(&dentition, settings, cache.as_ref());
    let near = bench::near_contact_pairs(&teeth, pairs, seed);
    let stress = bench::stress_pairs(&teeth, pairs, seed);
    let bar = |done: usize, total: usize| {
        if progress {
            eprint!("\rmeasuring {done}/{total}          ");
            if done == total {
                eprintln!();
            }
        }
    };
    let report = bench::run(&teeth, &near, &stress, &bar);
    if json {
        return print_json(&report);
    }
    let table = |title: String, methods: &[bench::MethodReport]| {
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
    };
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
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn run_simulate(
    case: &str,
    method: Method,
    response: Response,
    max_steps: u64,
    tree: TreeMethod,
    no_cache: bool,
    settings_file: Option<&std::path::Path>,
    json: bool,
) -> Result<()> {
    let mut settings = match settings_file {
        Some(path) => MovementSettings::load(path)?,
        None => MovementSettings::default(),
    };
    settings.response = response;
    let cache = if no_cache {
        None
    } else {
        TreeCache::user_default()
    };
    let progress = std::io::stderr().is_terminal();
    if progress {
        eprint!("building trees…");
    }
    let trees = TreeSettings {
        method: tree,
        branching: 8,
        depth: 4,
    };
    let run = run_case(
        case,
        method,
        settings,
        trees,
        cache.as_ref(),
        max_steps,
        |step| {
            if progress && (step % 50 == 0 || step == max_steps) {
                eprint!("\rsimulating: step {step}/{max_steps}          ");
            }
        },
    )?;
    if progress {
        eprintln!();
    }
    let r = &run.report;
    if json {
        return print_json(r);
    }
    println!(
        "case {}, {} / {}: {} steps, {}",
        r.case,
        r.algorithm,
        r.response,
        r.steps,
        if r.at_rest {
            "at rest"
        } else {
            "not at rest (step limit)"
        }
    );
    println!(
        "moved (> 0.1 mm): {}",
        r.moved
            .iter()
            .map(|f| f.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    println!("{:>7} {:>14} {:>12}", "pair", "centre dist mm", "gap mm");
    for d in &r.distances {
        println!(
            "{:>7} {:>14.3} {:>12.4}",
            format!("{}-{}", d.a, d.b),
            d.centre_distance_mm,
            d.surface_gap_mm
        );
    }
    println!(
        "total centre distance {:.3} mm, max penetration {:.4} mm",
        r.total_centre_distance_mm, r.max_penetration_mm
    );
    println!(
        "{:.1} µs per step ({:.1} µs collision)",
        r.step_us, r.collision_us_per_step
    );
    for (pair, mm) in &r.ipr_mm {
        println!("IPR {pair}: {mm:.3} mm");
    }
    if r.impacts > 0 {
        println!(
            "{} impacts, {:.3e} µJ of kinetic energy lost",
            r.impacts, r.energy_lost_uj
        );
    }
    Ok(())
}

fn run_report_command(
    case: &str,
    out: &std::path::Path,
    tree: TreeMethod,
    fit_depths: Vec<u32>,
    max_steps: u64,
    no_cache: bool,
) -> Result<()> {
    use orthosim::analysis::{ReportOptions, report::ALL_CASES, run_report};
    let cases = if case == "all" {
        ALL_CASES.iter().map(|s| s.to_string()).collect()
    } else {
        vec![case.to_owned()]
    };
    let opts = ReportOptions {
        cases,
        trees: TreeSettings {
            method: tree,
            branching: 8,
            depth: 4,
        },
        fit_depths,
        cache: if no_cache {
            None
        } else {
            TreeCache::user_default()
        },
        settings: MovementSettings::default(),
        max_steps,
    };
    let progress = std::io::stderr().is_terminal();
    let bar = |what: &str, done: usize, total: usize| {
        if progress {
            progress_bar(&format!("{what:<32}"), done, total);
        }
    };
    let summary = run_report(&opts, out, &bar)?;
    println!(
        "wrote {} (cases: {})",
        out.join("index.html").display(),
        summary.cases.keys().cloned().collect::<Vec<_>>().join(", ")
    );
    Ok(())
}

/// One line of progress on stderr: `\r[####    ] done/total what`, ended when done.
fn progress_bar(what: &str, done: usize, total: usize) {
    let filled = (done * 30 / total.max(1)).min(30);
    eprint!(
        "\r[{}{}] {done}/{total} {what}",
        "#".repeat(filled),
        " ".repeat(30 - filled)
    );
    if done == total {
        eprintln!();
    }
}

/// Prints one pretty JSON object on stdout.
fn print_json(value: &impl serde::Serialize) -> Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(value).context("writing JSON")?
    );
    Ok(())
}

fn list_cases() {
    for name in Case::builtin_names() {
        let loaded = Case::resolve(name).expect("built-in cases are valid");
        println!("{name:<8} {}", loaded.case.description);
    }
}

/// Refuses to write `output` over the case file named by `case` (when it is a file).
fn never_overwrite(output: &std::path::Path, case: &str) -> Result<()> {
    orthosim::sphere_tree::report::refuse_overwriting(output, &[std::path::Path::new(case)])
        .map_err(anyhow::Error::msg)
}

fn run_export_case(case: &str, out: &std::path::Path) -> Result<()> {
    let d = Dentition::build(Case::resolve(case)?)?;
    let report = orthosim::teeth::import::export_case(&d, out).map_err(anyhow::Error::msg)?;
    println!(
        "wrote {} ({} teeth, {} triangles)",
        report.case_file.display(),
        report.meshes.len(),
        report.triangles
    );
    Ok(())
}

fn run_inspect(case: &str, json: bool, resolution: Option<u32>) -> Result<()> {
    let mut loaded = Case::resolve(case)?;
    if resolution.is_some() {
        loaded.case.resolution = resolution;
    }
    let progress = std::io::stderr().is_terminal();
    if progress {
        eprintln!(
            "orthosim: building teeth at {} vertices and arranging the arches…",
            loaded.case.tooth_resolution().vertices
        );
    }
    let dentition = Dentition::build(loaded)?;
    if progress {
        eprintln!("orthosim: measuring gaps and penetrations…");
    }
    let report = inspect(&dentition);
    if json {
        return print_json(&report);
    }
    println!(
        "case {} ({}), {} vertices per tooth",
        report.case, report.origin, report.resolution
    );
    println!(
        "{:>4} {:<16} {:<6} {:>5} {:>5} {:>7} {:>9}  crown centre (mm)",
        "fdi", "kind", "arch", "verts", "tris", "closed", "vol mm3"
    );
    for t in &report.teeth {
        let c = t.crown_centre;
        println!(
            "{:>4} {:<16} {:<6} {:>5} {:>5} {:>7} {:>9.1}  ({:>6.2}, {:>6.2}, {:>6.2}){}",
            t.fdi,
            t.kind,
            t.arch,
            t.vertices,
            t.triangles,
            t.closed,
            t.volume_mm3,
            c[0],
            c[1],
            c[2],
            if t.extracted { "  extracted" } else { "" }
        );
    }
    if !report.imported.is_empty() {
        println!("teeth read from mesh files (repairs):");
        for m in &report.imported {
            println!("  {}: {}", m.fdi, m.summary);
        }
    }
    println!("neighbour gaps (mm):");
    for g in &report.neighbour_gaps_mm {
        println!("  {}-{}: {:.3}", g.a, g.b, g.gap_mm);
    }
    println!(
        "max penetration in an arch: {:.4} mm",
        report.max_penetration_mm
    );
    println!(
        "max penetration between arches: {:.4} mm (least gap {:.4} mm)",
        report.occlusal_max_penetration_mm, report.occlusal_min_gap_mm
    );
    let o = report.occlusion;
    println!(
        "overjet {:.2} mm, overbite {:.2} mm, molar relation {:+.2} mm (0 = class I)",
        o.overjet_mm, o.overbite_mm, o.molar_relation_mm
    );
    Ok(())
}

fn run_trees(
    case: &str,
    settings: TreeSettings,
    json: bool,
    out: Option<&std::path::Path>,
    cache: Option<&TreeCache>,
    resolution: Option<u32>,
) -> Result<()> {
    settings.validate()?;
    let mut loaded = Case::resolve(case)?;
    if resolution.is_some() {
        loaded.case.resolution = resolution;
    }
    let dentition = Dentition::build(loaded)?;
    let progress = std::io::stderr().is_terminal();
    let bar = |done: usize, total: usize| {
        if progress {
            progress_bar("building trees", done, total);
        }
    };
    let (report, trees) = trees_report(&dentition, settings, cache, &bar)?;
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create folder", dir.display()))?;
        for (fdi, tree) in &trees {
            let path = dir.join(format!("{fdi}.sph"));
            never_overwrite(&path, case)?;
            write_atomic(&path, &tree.to_sph())
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
    }
    if json {
        return print_json(&report);
    }
    println!(
        "{:?} trees, branching {}, depth {} ({} teeth)",
        report.method,
        report.branching,
        report.depth,
        report.teeth.len()
    );
    println!(
        "{:>4} {:>7} {:>8} {:>9} {:>12} {:>8} {:>9}",
        "fdi", "leaves", "sov_sum", "sov_union", "overhang mm", "covered", "build ms"
    );
    for t in &report.teeth {
        println!(
            "{:>4} {:>7} {:>8.3} {:>9.3} {:>12.3} {:>8} {:>9.2}",
            t.fdi, t.leaves, t.sov_sum, t.sov_union, t.max_overhang_mm, t.covered, t.build_ms
        );
    }
    let s = &report.summary;
    println!(
        "sov_sum mean {:.3} (min {:.3}, max {:.3}), sov_union mean {:.3}, overhang mean {:.3} mm, leaves mean {:.1}, all covered: {}, build {:.1} ms",
        s.sov_sum_mean,
        s.sov_sum_min,
        s.sov_sum_max,
        s.sov_union_mean,
        s.max_overhang_mm_mean,
        s.leaves_mean,
        s.all_covered,
        s.build_ms_total
    );
    Ok(())
}

#[cfg(feature = "viewer")]
fn view(case: &str, camera: orthosim::occlusion_view::CameraPreset) -> Result<()> {
    use orthosim::occlusion_view::OcclusionViewPlugin;
    // Fail early, with the file position, before a window opens.
    Case::resolve(case)?;
    window_app(case, format!("orthosim: {case}"), TreeMethod::Medial)
        .add_plugins(OcclusionViewPlugin {
            initial_view: camera,
            ..Default::default()
        })
        .add_plugins(orthosim::ui::OrthoSimUiPlugin)
        .run();
    Ok(())
}

/// The simulation and view plugins of the window commands, trees medial from the user's cache.
#[cfg(feature = "viewer")]
fn window_app(case: &str, title: String, tree: TreeMethod) -> bevy::prelude::App {
    use bevy::prelude::*;
    use orthosim::{
        OrthoSimPlugins,
        sphere_tree::{SphereTreeCache, SphereTreeSettings},
        teeth::TeethModelPlugin,
    };
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window { title, ..default() }),
        ..default()
    }))
    .add_plugins(OrthoSimPlugins.set(TeethModelPlugin {
        initial_case: Some(case.to_owned()),
    }))
    .insert_resource(SphereTreeCache(TreeCache::user_default()))
    .insert_resource(SphereTreeSettings(TreeSettings {
        method: tree,
        branching: 8,
        depth: 4,
    }));
    app
}

#[cfg(feature = "viewer")]
#[allow(clippy::too_many_arguments)]
fn screenshot(
    case: &str,
    camera: orthosim::occlusion_view::CameraPreset,
    frames: u32,
    tree: TreeMethod,
    overlays: &[orthosim::occlusion_view::Overlay],
    (algorithm, roots): (Method, orthosim::occlusion_view::Roots),
    hide: &[String],
    out: &std::path::Path,
) -> Result<()> {
    use orthosim::{
        collision::CollisionSettings,
        occlusion_view::{OcclusionViewPlugin, ScreenshotOutcome, ScreenshotPlugin},
    };
    Case::resolve(case)?;
    if out.extension().and_then(|e| e.to_str()) != Some("png") {
        anyhow::bail!("{}: the screenshot must be a .png file", out.display());
    }
    never_overwrite(out, case)?;
    let shared = std::sync::Arc::new(std::sync::Mutex::new(ScreenshotOutcome::default()));
    let mut app = window_app(case, format!("orthosim: {case}"), tree);
    app.insert_resource(CollisionSettings { method: algorithm });
    app.add_plugins(OcclusionViewPlugin {
        initial_view: camera,
        overlays: orthosim::occlusion_view::Overlays {
            hide_upper: hide.iter().any(|h| h == "upper"),
            hide_lower: hide.iter().any(|h| h == "lower"),
            roots,
            ..overlays.iter().fold(
                Default::default(),
                |o: orthosim::occlusion_view::Overlays, x| o.with(*x),
            )
        },
    })
    .add_plugins(ScreenshotPlugin {
        path: out.to_owned(),
        frames,
        outcome: shared.clone(),
    });
    app.run();
    let outcome = shared.lock().unwrap_or_else(|p| p.into_inner()).clone();
    match outcome.error {
        Some(e) => anyhow::bail!("{e}"),
        None if outcome.written => {
            println!("wrote {}", out.display());
            Ok(())
        }
        None => anyhow::bail!("the window closed before the screenshot was taken"),
    }
}

#[cfg(not(feature = "viewer"))]
fn view(_case: &str) -> Result<()> {
    anyhow::bail!(
        "this build has no viewer (built without the `viewer` feature); use a headless subcommand, see --help"
    )
}
