//! The `orthosim` command: the viewer by default, headless subcommands for everything else. Each
//! subcommand and its arguments live in their own file under `cli/`; this file only dispatches.

mod cli;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    View(cli::view::ViewArgs),
    /// Open the real window, simulate a case for some frames and save a screenshot (PNG).
    Screenshot(cli::screenshot::ScreenshotArgs),
    /// List the built-in cases, one line each.
    Cases,
    /// Run a case headless until the teeth come to rest and report where they went.
    Simulate(cli::simulate::SimulateArgs),
    /// Run cases under every collision method and write a report: summary.json, distances.csv,
    /// one plot per case (PNG and SVG) and index.html.
    Report(cli::report::ReportArgs),
    /// Print per-tooth mesh data and exact gaps and penetrations of a case.
    Inspect(cli::inspect::InspectArgs),
    /// Write a case as one STL file per tooth plus a RON case file that names them (a template
    /// for patient cases, and the import path's round trip).
    ExportCase(cli::export_case::ExportCaseArgs),
    /// Build each tooth's sphere tree and report its fit (the paper's relative outside volume).
    Trees(cli::trees::TreesArgs),
    /// Where the arches meet: contacts, areas, the incisor gap; `--settle` closes the lower arch
    /// onto the upper under a bite force until it is stable.
    Occlusion(cli::occlusion::OcclusionArgs),
    /// A staged treatment plan from the teeth as they stand to a target: stages within per-stage
    /// limits, no tooth passing through another, IPR where they must pass; plan.json, stage STLs
    /// and an HTML page.
    Plan(cli::plan::PlanArgs),
    /// Compare the periodontal-ligament model with published biomechanics (centres of
    /// resistance and rotation, moment-to-force ratios, displacement, rate of movement).
    Validate(cli::validate::ValidateArgs),
    /// Measure collision detection: µs per pair query and errors of each method on seeded
    /// near-contact motions of real teeth, and the cost of one full-mouth step.
    Bench(cli::bench::BenchArgs),
}

fn main() -> ExitCode {
    let command = Cli::parse().command;
    let result = match command.unwrap_or_else(|| Command::View(Default::default())) {
        Command::View(args) => cli::view::run(args),
        Command::Screenshot(args) => cli::screenshot::run(args),
        Command::Cases => cli::cases::run(),
        Command::Simulate(args) => cli::simulate::run(args),
        Command::Report(args) => cli::report::run(args),
        Command::Inspect(args) => cli::inspect::run(args),
        Command::ExportCase(args) => cli::export_case::run(args),
        Command::Trees(args) => cli::trees::run(args),
        Command::Bench(args) => cli::bench::run(args),
        Command::Validate(args) => cli::validate::run(args),
        Command::Occlusion(args) => cli::occlusion::run(args),
        Command::Plan(args) => cli::plan::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("orthosim: {e:#}");
            ExitCode::FAILURE
        }
    }
}
