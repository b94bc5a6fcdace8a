//! `orthosim report`: every case under every collision method, written as summary.json,
//! distances.csv, one plot per case and index.html.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use orthosim::{
    analysis::{ALL_CASES, ReportOptions, run_report},
    movement::MovementSettings,
};

use super::{
    terminal::{progress_bar, progress_wanted},
    tree_args::TreeArgs,
};

/// `report`'s arguments.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// `all` (case1, case2, case3), a built-in case name or a path to a .ron case file.
    #[arg(long, default_value = "all")]
    pub case: String,
    /// Folder to write into (created if needed).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub trees: TreeArgs,
    /// Depths of the sphere-tree fit table (octree and medial), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "3,4,5,6", value_parser = clap::value_parser!(u32).range(1..=7))]
    pub fit_depths: Vec<u32>,
    /// Most steps per run.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    pub max_steps: u64,
    /// Resolution of the exact stage's run time against error (`bench --sweep` on the normal
    /// case): `high` (10,100 vertices per tooth), a number of vertices per tooth, or `none`.
    #[arg(long, default_value = "high")]
    pub sweep: SweepAt,
    /// Near-contact pair steps of that sweep.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub sweep_pairs: u64,
}

/// `report --sweep`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SweepAt(Option<u32>);

impl std::str::FromStr for SweepAt {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "none" => Ok(Self(None)),
            "high" => Ok(Self(Some(10_100))),
            _ => match s.parse::<u32>() {
                Ok(n) if (20..=200_000).contains(&n) => Ok(Self(Some(n))),
                _ => Err(format!(
                    "'{s}': use high, none or a number of vertices per tooth (20–200000)"
                )),
            },
        }
    }
}

/// Runs the report and says where it is.
pub fn run(args: ReportArgs) -> Result<()> {
    let cases = if args.case == "all" {
        ALL_CASES.iter().map(|s| s.to_string()).collect()
    } else {
        vec![args.case.clone()]
    };
    let opts = ReportOptions {
        cases,
        trees: args.trees.settings(),
        fit_depths: args.fit_depths,
        cache: args.trees.cache(),
        settings: MovementSettings::default(),
        max_steps: args.max_steps,
        sweep_vertices: args.sweep.0,
        sweep_pairs: args.sweep_pairs as usize,
    };
    let progress = progress_wanted();
    let bar = |what: &str, done: usize, total: usize| {
        if progress {
            progress_bar(&format!("{what:<32}"), done, total);
        }
    };
    let summary = run_report(&opts, &args.out, &bar)?;
    println!(
        "wrote {} (cases: {})",
        args.out.join("index.html").display(),
        summary.cases.keys().cloned().collect::<Vec<_>>().join(", ")
    );
    Ok(())
}
