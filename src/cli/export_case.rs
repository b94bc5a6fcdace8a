//! `orthosim export-case`: a case written as one STL per tooth and a RON case file naming them.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use orthosim::teeth::{
    Case, Dentition,
    import::{ExportMeshes, export_case_as, export_labelled_scans_with},
    labelled_scan::{LabelFaults, ScanFormat},
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
    /// With `--scan-like`: write each arch as one labelled whole-arch scan (the crowns and a gum
    /// band) in a random scanner frame and units, as segmentation software exports them: `ply`
    /// (a per-vertex `label` property), `colours` (per-vertex colours) or `obj` (OBJ with a JSON
    /// label file). The case names them in `scans` without a transform.
    #[arg(long, value_enum, requires = "scan_like")]
    pub labelled: Option<LabelledFormat>,
    /// With `--labelled`: labels that fail as real segmentations' do: labels run into the gum,
    /// fragments of a tooth's label on its neighbour, islands on the gum, lower incisors with deep scallops, and central incisors
    /// whose surface crosses itself (see `inspect` for what the import makes of them).
    #[arg(long, requires = "labelled")]
    pub faults: bool,
    /// Seed of the scan-like defects (and of the scanner frame with `--labelled`).
    #[arg(long, default_value_t = 1, requires = "scan_like")]
    pub seed: u64,
}

/// How `--labelled` writes the labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LabelledFormat {
    /// PLY with an integer `label` per vertex.
    Ply,
    /// PLY with a colour per vertex.
    Colours,
    /// OBJ with a JSON label file (`{"jaw", "labels"}`).
    Obj,
}

/// Exports the case (every output is checked before any is written).
pub fn run(args: ExportCaseArgs) -> Result<()> {
    let d = Dentition::build(Case::resolve(&args.case)?)?;
    if let (Some(format), Some(triangles)) = (args.labelled, args.scan_like) {
        let format = match format {
            LabelledFormat::Ply => ScanFormat::PlyProperty,
            LabelledFormat::Colours => ScanFormat::PlyColours,
            LabelledFormat::Obj => ScanFormat::ObjJson,
        };
        let faults = if args.faults {
            LabelFaults::REAL
        } else {
            LabelFaults::NONE
        };
        let (report, frame) = export_labelled_scans_with(
            &d,
            &args.out,
            triangles as usize,
            args.seed,
            format,
            &faults,
        )?;
        let (r, t) = orthosim::teeth::import::orient::as_euler_deg(&frame.pose.inverse());
        println!(
            "wrote {} ({} scans, {} triangles, {:?}); the scans' true placement: rotation_deg ({:.2}, {:.2}, {:.2}), translation ({:.2}, {:.2}, {:.2}) mm",
            report.case_file.display(),
            report.meshes.len(),
            report.triangles,
            frame.units,
            r[0],
            r[1],
            r[2],
            t[0],
            t[1],
            t[2]
        );
        return Ok(());
    }
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
