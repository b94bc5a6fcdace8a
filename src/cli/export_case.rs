//! `orthosim export-case`: a case written as one STL per tooth and a RON case file naming them.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use orthosim::teeth::{Case, Dentition, import::export_case};

/// `export-case`'s arguments.
#[derive(Args, Debug)]
pub struct ExportCaseArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Folder to write into (created if needed).
    #[arg(long)]
    pub out: PathBuf,
}

/// Exports the case (every output is checked before any is written).
pub fn run(args: ExportCaseArgs) -> Result<()> {
    let d = Dentition::build(Case::resolve(&args.case)?)?;
    let report = export_case(&d, &args.out)?;
    println!(
        "wrote {} ({} teeth, {} triangles)",
        report.case_file.display(),
        report.meshes.len(),
        report.triangles
    );
    Ok(())
}
