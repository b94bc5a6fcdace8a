//! `orthosim trees`: each tooth's sphere tree built and its fit reported; optionally written as
//! Bradshaw `.sph` files.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use orthosim::{
    io::OutputSet,
    sphere_tree::{TreeCache, TreeMethod, TreeSettings, TreesReport, trees_report},
    teeth::{Case, Dentition},
};

use super::{
    choice,
    terminal::{print_json, progress_bar, progress_wanted},
};

/// `trees`' arguments.
#[derive(Args, Debug)]
pub struct TreesArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Tree builder.
    #[arg(long, value_parser = choice::tree_method(), default_value_t = TreeSettings::default().method)]
    pub method: TreeMethod,
    /// Levels including the root.
    #[arg(long, default_value_t = TreeSettings::default().depth)]
    pub depth: u32,
    /// Children per node.
    #[arg(long, default_value_t = TreeSettings::default().branching)]
    pub branching: u32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write one Bradshaw .sph file per tooth into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Read trees from, and store new ones in, this cache folder (build_ms is then the time to
    /// read and check a cached tree).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Vertices per procedural tooth, overriding the case (125 is the paper's; 10100 gives
    /// about 20,000 triangles per tooth).
    #[arg(long, value_parser = clap::value_parser!(u32).range(20..=200_000))]
    pub resolution: Option<u32>,
}

/// Builds the trees, writes them if asked and prints the report.
pub fn run(args: TreesArgs) -> Result<()> {
    let settings = TreeSettings {
        method: args.method,
        branching: args.branching,
        depth: args.depth,
    };
    settings.validate()?;
    let mut loaded = Case::resolve(&args.case)?;
    if args.resolution.is_some() {
        loaded.case.resolution = args.resolution;
    }
    let dentition = Dentition::build(loaded)?;
    let progress = progress_wanted();
    let bar = |done: usize, total: usize| {
        if progress {
            progress_bar("building trees", done, total);
        }
    };
    let cache = args.cache.map(TreeCache::new);
    let (report, trees) = trees_report(&dentition, settings, cache.as_ref(), &bar)?;
    if let Some(dir) = &args.out {
        let paths: Vec<PathBuf> = trees
            .iter()
            .map(|(fdi, _)| dir.join(format!("{fdi}.sph")))
            .collect();
        let mut set = OutputSet::new(dir, paths.clone(), &[Path::new(&args.case)])?;
        for (path, (_, tree)) in paths.iter().zip(&trees) {
            set.write(path, tree.to_sph())?;
        }
        set.commit()?;
    }
    if args.json {
        return print_json(&report);
    }
    print_table(&report);
    Ok(())
}

fn print_table(report: &TreesReport) {
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
}
