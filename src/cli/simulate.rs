//! `orthosim simulate`: a case run headless until its teeth rest, and where they went.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use orthosim::{
    collision::Method,
    movement::{
        MovementModel, MovementSettings, Response, RunLimit, SimulationReport, run_case_for,
    },
};

use super::{
    choice,
    terminal::{print_json, progress_wanted},
    tree_args::TreeArgs,
};

/// `simulate`'s arguments.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "case1")]
    pub case: String,
    /// Narrow-phase method.
    #[arg(long, value_parser = choice::method(), default_value_t = Method::Continuous)]
    pub algorithm: Method,
    /// Collision response.
    #[arg(long, value_parser = choice::response(), default_value_t = Response::Block)]
    pub response: Response,
    /// Movement model (overrides the settings file's): the periodontal ligament in clinical
    /// time, or the source paper's.
    #[arg(long, value_parser = choice::model())]
    pub model: Option<MovementModel>,
    /// Most steps to run.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    pub max_steps: u64,
    /// Most clinical days to run (PDL model; a step is `step_hours` of the settings, a day by
    /// default), as an alternative to `--max-steps`.
    #[arg(long, value_parser = days)]
    pub days: Option<f64>,
    #[command(flatten)]
    pub trees: TreeArgs,
    /// Movement settings (a RON `MovementSettings`; missing fields keep their defaults);
    /// `--response` overrides the file's response.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// A number of clinical days: finite, above zero, at most a century.
fn days(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v > 0.0 && v <= 36_500.0 {
        Ok(v)
    } else {
        Err(format!("days must be in (0, 36500], got {s}"))
    }
}

/// Runs the case and prints the report.
pub fn run(args: SimulateArgs) -> Result<()> {
    let mut settings = match &args.settings {
        Some(path) => MovementSettings::load(path)?,
        None => MovementSettings::default(),
    };
    settings.response = args.response;
    if let Some(model) = args.model {
        settings.model = model;
    }
    let progress = progress_wanted();
    if progress {
        eprint!("building trees…");
    }
    if args.days.is_some() && settings.model != MovementModel::Pdl {
        anyhow::bail!("--days needs the PDL movement model (clinical time); use --max-steps");
    }
    let max_steps = match args.days {
        // Enough steps for the days asked, whatever a step's length.
        Some(d) => {
            ((d * 24.0 / settings.pdl.step_hours as f64).ceil() as u64 + 1).max(args.max_steps)
        }
        None => args.max_steps,
    };
    let limit = RunLimit {
        max_steps,
        max_days: args.days,
    };
    let run = run_case_for(
        &args.case,
        args.algorithm,
        settings,
        args.trees.settings(),
        args.trees.cache().as_ref(),
        limit,
        |step| {
            if progress && (step % 50 == 0 || step == max_steps) {
                eprint!("\rsimulating: step {step}/{max_steps}          ");
            }
        },
    )?;
    if progress {
        eprintln!();
    }
    if args.json {
        return print_json(&run.report);
    }
    print_table(&run.report);
    Ok(())
}

fn print_table(r: &SimulationReport) {
    println!(
        "case {}, {} / {} / {}: {} steps ({:.1} days), {}",
        r.case,
        r.model,
        r.algorithm,
        r.response,
        r.steps,
        r.days,
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
    if let Some(a) = &r.appliance {
        for (arch, wires) in &a.wires {
            let seq: Vec<String> = wires
                .iter()
                .map(|w| {
                    format!(
                        "day {:.0}: {} {} {}",
                        w.day,
                        w.size,
                        w.material,
                        w.form.name()
                    )
                })
                .collect();
            println!("{arch} wire: {}", seq.join(", then "));
        }
        println!(
            "{:>5} {:>24} {:>26} {:>10}",
            "tooth", "force N", "moment N·mm", "friction N"
        );
        for b in &a.brackets {
            let v = |x: [f64; 3]| format!("{:7.3} {:7.3} {:7.3}", x[0], x[1], x[2]);
            println!(
                "{:>5} {:>24} {:>26} {:>10.3}{}",
                b.fdi.to_string(),
                v(b.force_n),
                v(b.moment_nmm),
                b.friction_n,
                if b.engaged { "" } else { "  (passive)" }
            );
        }
        for c in &a.chains {
            match c.placed_day {
                Some(day) => println!(
                    "chain {}–{} placed on day {day:.0}: {:.2} N",
                    c.from, c.to, c.tension_n
                ),
                None => println!("chain {}–{}: not placed yet", c.from, c.to),
            }
        }
        for e in &a.elastics {
            match e.placed_day {
                Some(day) => println!(
                    "elastic {}–{} worn from day {day:.0}: {:.2} N",
                    e.from, e.to, e.force_n
                ),
                None => println!("elastic {}–{}: not worn yet", e.from, e.to),
            }
        }
        for c in &a.coils {
            match c.placed_day {
                Some(day) => println!(
                    "{:?} coil {}–{} placed on day {day:.0}: {:.2} N",
                    c.kind, c.from, c.to, c.force_n
                ),
                None => println!("{:?} coil {}–{}: not placed yet", c.kind, c.from, c.to),
            }
        }
        for (arch, series) in [
            ("upper", &a.irregularity_mm.upper),
            ("lower", &a.irregularity_mm.lower),
        ] {
            if let (Some(first), Some(last)) = (series.first(), series.last()) {
                println!(
                    "{arch} irregularity index (Little): {:.2} mm on day {:.0}, {:.2} mm on day {:.0}",
                    first[1], first[0], last[1], last[0]
                );
            }
        }
        println!(
            "wire solve {:.0} µs per step (median; most {:.0}), {:.2}× the collision step{}",
            a.solve_us_per_step[0],
            a.solve_us_per_step[1],
            a.solve_over_collision,
            if a.converged {
                ""
            } else {
                "; some solves did not converge"
            }
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
    if let Some(b) = &r.bone_meshes {
        let outside: Vec<String> = b
            .outside
            .iter()
            .map(|o| format!("{} {}/{}", o.fdi, o.points, o.of))
            .collect();
        println!(
            "bone meshes hold {} teeth; root points outside the bone as placed (not held): {}",
            b.teeth.len(),
            if outside.is_empty() {
                "none".to_owned()
            } else {
                outside.join(", ")
            }
        );
    }
    for c in &r.cortical_contacts {
        println!(
            "root of {} at the {} plate from day {:.0} to day {:.0} (deepest {:.3} mm past it)",
            c.fdi,
            match c.plate {
                orthosim::appliance::Plate::Buccal => "buccal",
                orthosim::appliance::Plate::Lingual => "lingual",
            },
            c.day,
            c.until_day,
            c.depth_mm
        );
    }
    if r.impacts > 0 {
        println!(
            "{} impacts, {:.3e} µJ of kinetic energy lost",
            r.impacts, r.energy_lost_uj
        );
    }
}
