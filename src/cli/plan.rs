//! `orthosim plan`: a staged plan from a case's teeth as they stand to a target, within per-stage
//! limits, with no two teeth passing through each other, written as `plan.json`, one STL per
//! arch per stage and an HTML page.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use orthosim::{
    analysis::plan_report::{plan_html, stage_png},
    io::OutputSet,
    planning::{
        PlanLimits, automatic,
        export::{stage_file, stage_stl},
        from_offsets, plan,
        target::read_target,
    },
    teeth::{Arch, Case, Dentition},
};

use super::terminal::print_json;

/// `plan`'s arguments.
#[derive(Args, Debug)]
pub struct PlanArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "crowded")]
    pub case: String,
    /// A target file (`{11: (translation: (…), rotation_deg: (…))}`, each tooth's movement from
    /// where it stands along its mesial, buccal and occlusal axes); default: the case's `target`,
    /// or else the automatic set-up.
    #[arg(long)]
    pub target: Option<PathBuf>,
    /// A limits file (RON; any of the per-stage limits, IPR limits, sequence and waits).
    #[arg(long)]
    pub limits: Option<PathBuf>,
    /// Folder to write plan.json, the stage meshes and plan.html into.
    #[arg(long)]
    pub out: PathBuf,
    /// Print the plan as one JSON object instead of a summary.
    #[arg(long)]
    pub json: bool,
}

/// Plans, writes the files and prints the summary or JSON.
pub fn run(args: PlanArgs) -> Result<()> {
    let loaded = Case::resolve(&args.case)?;
    let case_path = (!loaded.origin.starts_with("builtin:")).then(|| PathBuf::from(&loaded.origin));
    let d = Dentition::build(loaded)?;
    let limits = match &args.limits {
        Some(p) => PlanLimits::load(p)?,
        None => PlanLimits::default(),
    };
    let started = Instant::now();
    let target = match &args.target {
        Some(p) => from_offsets(&d, &read_target(p, &d)?),
        None if !d.case.case.target.is_empty() => from_offsets(&d, &d.case.case.target),
        None => automatic(&d, &limits),
    };
    let target_ms = started.elapsed().as_secs_f64() * 1e3;
    let p = plan(&d, &target, &limits, target_ms);
    write_outputs(&args, case_path.as_deref(), &d, &p)?;
    if args.json {
        return print_json(&p);
    }
    println!(
        "case {}: {} stages ({}), target {} (set up in {:.0} ms), planned in {:.0} ms with {} exact distance queries",
        p.case,
        p.stages,
        p.limits.sequence.name(),
        p.target,
        p.target_ms,
        p.plan_ms,
        p.measures
    );
    for s in &p.setup {
        println!("  {}", s.summary());
    }
    for x in &p.ipr {
        println!("  IPR {}|{}: {:.2} mm at stage {}", x.a, x.b, x.mm, x.stage);
    }
    for b in &p.blocked {
        println!(
            "  blocked {}–{} at stage {}: {:.3} mm too deep ({})",
            b.a, b.b, b.stage, b.depth_mm, b.why
        );
    }
    println!(
        "deepest penetration beyond what is allowed: {:.3} mm (overlap in the scan: {:.3} mm); between the arches (not checked between stages): {:.3} mm as scanned, {:.3} mm at the target; files in {}",
        p.max_penetration_mm,
        p.scan_overlap_mm,
        p.opposing_overlap_mm[0],
        p.opposing_overlap_mm[1],
        args.out.display()
    );
    println!("{}", p.relations_summary());
    Ok(())
}

fn write_outputs(
    args: &PlanArgs,
    case_path: Option<&Path>,
    d: &Dentition,
    p: &orthosim::planning::Plan,
) -> Result<()> {
    let dir = &args.out;
    let mut paths = vec![dir.join("plan.json"), dir.join("plan.html")];
    let (first, last) = ("stage_first.png", "stage_last.png");
    paths.push(dir.join(first));
    paths.push(dir.join(last));
    let arches: Vec<Arch> = [Arch::Upper, Arch::Lower]
        .into_iter()
        .filter(|a| d.visible().any(|t| t.fdi.arch() == *a))
        .collect();
    for k in 0..=p.stages {
        for a in &arches {
            paths.push(stage_file(dir, *a, k, p.stages));
        }
    }
    let mut inputs: Vec<&Path> = Vec::new();
    inputs.extend(case_path);
    inputs.extend(args.target.as_deref());
    inputs.extend(args.limits.as_deref());
    let mut set = OutputSet::new(dir, paths, &inputs)?;
    let json = serde_json::to_string_pretty(p).context("writing plan.json")?;
    set.write(&dir.join("plan.json"), json)?;
    set.write(&dir.join("plan.html"), plan_html(p, first, last))?;
    set.write(&dir.join(first), stage_png(d, p, 0)?)?;
    set.write(&dir.join(last), stage_png(d, p, p.stages)?)?;
    for k in 0..=p.stages {
        for a in &arches {
            set.write(&stage_file(dir, *a, k, p.stages), stage_stl(d, p, *a, k))?;
        }
    }
    set.commit()?;
    Ok(())
}
