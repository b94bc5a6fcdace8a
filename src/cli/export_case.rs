//! `orthosim export-case`: a case written as one STL per tooth and a RON case file naming them.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use orthosim::teeth::{
    Case, Dentition,
    import::{ExportMeshes, export_case_as},
};

/// `export-case`'s arguments.
#[derive(Args, Debug)]
pub struct ExportCaseArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Folder to write into (created if needed).
    #[arg(long)]
    pub out: PathBuf,
    /// Write each tooth as a scan-like crown of about this many triangles (open at a scalloped
    /// gum line, with holes, spikes, non-manifold spots, folds and debris as real scans have), to
    /// try the import of scanned crowns; the case then gets generated roots.
    #[arg(long, value_name = "TRIANGLES", value_parser = clap::value_parser!(u32).range(100..=200_000))]
    pub scan_like: Option<u32>,
    /// Seed of the scan-like defects.
    #[arg(long, default_value_t = 1, requires = "scan_like")]
    pub seed: u64,
}

/// Exports the case (every output is checked before any is written).
pub fn run(args: ExportCaseArgs) -> Result<()> {
    let d = Dentition::build(Case::resolve(&args.case)?)?;
    let meshes = match args.scan_like {
        Some(triangles) => ExportMeshes::ScanLike {
            triangles: triangles as usize,
            seed: args.seed,
        },
        None => ExportMeshes::Teeth,
    };
    let report = export_case_as(&d, &args.out, meshes)?;
    println!(
        "wrote {} ({} teeth, {} triangles)",
        report.case_file.display(),
        report.meshes.len(),
        report.triangles
    );
    Ok(())
}
