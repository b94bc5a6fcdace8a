//! `export-case`: a case written as one STL file per tooth (in orthosim's frame, mm, where the case
//! places the teeth) and a RON case file that names them, so that a case can start from a template
//! and the import path can be checked round trip.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{Labels, Placement, ScanFile, ToothMeshFile, Units, write_stl};
use crate::{
    io::{OutputError, OutputSet},
    teeth::{
        Dentition,
        case::{Case, ToothMap},
        fdi::Arch,
        labelled_scan::{
            LabelFaults, ScanFormat, ScannerFrame, labelled_arch_with, tooth_colour, write_scan,
        },
        scan_like::{ScanDefects, scan_like_crown},
    },
};

/// What `export-case` wrote.
#[derive(Clone, Debug, Serialize)]
pub struct ExportReport {
    /// The case file written.
    pub case_file: PathBuf,
    /// The mesh files written (one per present tooth, extracted ones included).
    pub meshes: Vec<PathBuf>,
    /// Triangles written in all.
    pub triangles: usize,
}

/// What `export-case` writes for each tooth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExportMeshes {
    /// The tooth's closed mesh, as the case has it.
    Teeth,
    /// A scan-like crown of the tooth's type where the tooth stands ([`scan_like_crown`]): open
    /// at a scalloped gum line, about `triangles` triangles, with the defects real scans have
    /// (drawn from `seed` and the tooth's number), for trying the import of scanned crowns.
    ScanLike {
        /// Triangles per crown (about).
        triangles: usize,
        /// Seed of the defects.
        seed: u64,
    },
}

/// Writes the teeth of `d` to `dir` (created if needed) as `NN.stl` and the case as `NAME.ron`,
/// all or nothing: every output is checked (name and path lengths, never the case file `d` was
/// read from or one of its mesh files) before any is written, each is written to a temporary file
/// and all are moved into place at the end; on failure nothing is left behind.
///
/// # Errors
/// The first output that cannot or must not be written ([`OutputError`]).
pub fn export_case(d: &Dentition, dir: &Path) -> Result<ExportReport, OutputError> {
    export_case_as(d, dir, ExportMeshes::Teeth)
}

/// [`export_case`] writing `meshes` for each tooth.
///
/// # Errors
/// The first output that cannot or must not be written ([`OutputError`]).
pub fn export_case_as(
    d: &Dentition,
    dir: &Path,
    meshes_as: ExportMeshes,
) -> Result<ExportReport, OutputError> {
    let (mut case, case_file, inputs) = export_start(d, dir);
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let meshes: Vec<PathBuf> = d
        .teeth
        .iter()
        .map(|t| dir.join(format!("{}.stl", t.fdi.number())))
        .collect();
    let mut outputs = meshes.clone();
    outputs.push(case_file.clone());
    let mut set = OutputSet::new(dir, outputs, &inputs)?;
    let mut files = ToothMap::default();
    let mut triangles = 0;
    for (t, path) in d.teeth.iter().zip(&meshes) {
        let world = match meshes_as {
            ExportMeshes::Teeth => t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v)),
            ExportMeshes::ScanLike { triangles, seed } => {
                let seed = seed
                    .wrapping_mul(100)
                    .wrapping_add(u64::from(t.fdi.number()));
                scan_like_crown(
                    t.fdi.arch(),
                    t.fdi.kind(),
                    &t.pose,
                    triangles,
                    &ScanDefects::typical(seed),
                    seed,
                )
                .mesh
            }
        };
        let mut bytes = Vec::new();
        write_stl(&world, &mut bytes).map_err(|source| OutputError::Write {
            path: path.clone(),
            source,
        })?;
        set.write(path, bytes)?;
        triangles += world.triangles.len();
        files.0.insert(
            t.fdi,
            ToothMeshFile {
                file: format!("{}.stl", t.fdi.number()),
                units: Units::Millimetres,
                transform: Placement::Identity,
            },
        );
    }
    // The meshes stand where the case placed the teeth: offsets and the bite opening are in them.
    case.meshes = files;
    case.offsets = ToothMap::default();
    case.bite_opening_mm = Default::default();
    let text = case_text(&case, &case_file)?;
    let what = match meshes_as {
        ExportMeshes::Teeth => "one STL per tooth".to_string(),
        ExportMeshes::ScanLike { triangles, seed } => format!(
            "one scan-like crown per tooth (about {triangles} triangles, defects of seed {seed})"
        ),
    };
    let header = format!(
        "// Exported by `orthosim export-case` from {}: {what} (mm, orthosim's frame,\n\
         // where the case placed it), so offsets and the bite opening are part of the meshes.\n",
        d.case.origin
    );
    set.write(&case_file, format!("{header}{text}\n"))?;
    set.commit()?;
    Ok(ExportReport {
        case_file,
        meshes,
        triangles,
    })
}

/// Writes the visible teeth of `d` as two labelled whole-arch scans (`upper` and `lower`, each
/// the scan-like crowns of its teeth and a gum band, [`crate::teeth::labelled_scan`]) in one
/// random scanner frame drawn from `seed` (rotation, translation, units), and the case as
/// `NAME.ron` naming them in `scans` with their units and no transform, so orthosim places them
/// itself. All or nothing, as [`export_case`].
///
/// # Errors
/// The first output that cannot or must not be written ([`OutputError`]).
pub fn export_labelled_scans(
    d: &Dentition,
    dir: &Path,
    triangles: usize,
    seed: u64,
    format: ScanFormat,
) -> Result<(ExportReport, ScannerFrame), OutputError> {
    export_labelled_scans_with(d, dir, triangles, seed, format, &LabelFaults::NONE)
}

/// [`export_labelled_scans`] with labels that fail as real segmentations' do ([`LabelFaults`]).
///
/// # Errors
/// The first output that cannot or must not be written ([`OutputError`]).
pub fn export_labelled_scans_with(
    d: &Dentition,
    dir: &Path,
    triangles: usize,
    seed: u64,
    format: ScanFormat,
    faults: &LabelFaults,
) -> Result<(ExportReport, ScannerFrame), OutputError> {
    let (mut case, case_file, inputs) = export_start(d, dir);
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let extension = match format {
        ScanFormat::ObjJson => "obj",
        _ => "ply",
    };
    let arches: Vec<Arch> = [Arch::Upper, Arch::Lower]
        .into_iter()
        .filter(|a| d.visible().any(|t| t.fdi.arch() == *a))
        .collect();
    let name = |a: Arch| match a {
        Arch::Upper => "upper",
        Arch::Lower => "lower",
    };
    let mut meshes = Vec::new();
    let mut outputs = Vec::new();
    for a in &arches {
        let mesh = dir.join(format!("{}.{extension}", name(*a)));
        meshes.push(mesh.clone());
        outputs.push(mesh);
        if format == ScanFormat::ObjJson {
            outputs.push(dir.join(format!("{}.json", name(*a))));
        }
    }
    outputs.push(case_file.clone());
    let mut set = OutputSet::new(dir, outputs, &inputs)?;
    let frame = ScannerFrame::random(seed);
    let mut written = 0;
    let mut scans = Vec::new();
    for a in &arches {
        let arch = labelled_arch_with(d, *a, triangles, seed, faults);
        let placed = frame.apply(&arch.mesh);
        written += placed.triangles.len();
        let (bytes, json) = write_scan(&arch, &placed, format);
        let file = format!("{}.{extension}", name(*a));
        set.write(&dir.join(&file), bytes)?;
        let labels = match (format, json) {
            (ScanFormat::ObjJson, Some(json)) => {
                let label_file = format!("{}.json", name(*a));
                set.write(&dir.join(&label_file), json)?;
                Labels::Json(label_file)
            }
            (ScanFormat::PlyColours, _) => Labels::Colours(
                d.visible()
                    .filter(|t| t.fdi.arch() == *a)
                    .map(|t| (tooth_colour(t.fdi), t.fdi))
                    .collect(),
            ),
            _ => Labels::Property("label".into()),
        };
        scans.push(ScanFile {
            file,
            labels,
            units: frame.units,
            transform: Placement::Auto,
        });
    }
    // The scans hold the visible teeth where the case placed them.
    case.meshes = ToothMap::default();
    case.scans = scans;
    case.teeth = None;
    case.extracted = Default::default();
    case.offsets = ToothMap::default();
    case.bite_opening_mm = Default::default();
    let text = case_text(&case, &case_file)?;
    let header = format!(
        "// Exported by `orthosim export-case --labelled` from {}: each arch one labelled scan of\n\
         // scan-like crowns (about {triangles} triangles each, defects of seed {seed}) and a gum,\n\
         // in a random scanner frame: no transform is written, orthosim places the scans itself.\n",
        d.case.origin
    );
    set.write(&case_file, format!("{header}{text}\n"))?;
    set.commit()?;
    Ok((
        ExportReport {
            case_file,
            meshes,
            triangles: written,
        },
        frame,
    ))
}

/// The case to write, its file in `dir`, and the files it was read from (never replaced: the
/// case file, its mesh files and its scans with their label files).
fn export_start(d: &Dentition, dir: &Path) -> (Case, PathBuf, Vec<PathBuf>) {
    let case: Case = d.case.case.clone();
    let case_file = dir.join(format!("{}.ron", file_stem(&case.name)));
    let origin = &d.case.origin;
    let mut inputs = vec![PathBuf::from(origin)];
    inputs.extend(
        case.meshes
            .0
            .values()
            .map(|m| Case::mesh_path(origin, &m.file)),
    );
    for scan in &case.scans {
        inputs.push(Case::mesh_path(origin, &scan.file));
        if let Labels::Json(file) = &scan.labels {
            inputs.push(Case::mesh_path(origin, file));
        }
    }
    (case, case_file, inputs)
}

/// The case as RON, for `path`.
fn case_text(case: &Case, path: &Path) -> Result<String, OutputError> {
    ron::ser::to_string_pretty(case, ron::ser::PrettyConfig::default().struct_names(true)).map_err(
        |e| OutputError::Write {
            path: path.to_owned(),
            source: std::io::Error::other(e),
        },
    )
}

fn file_stem(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "case".into() } else { s }
}
