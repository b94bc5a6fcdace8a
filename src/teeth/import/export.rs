//! `export-case`: a case written as one STL file per tooth (in orthosim's frame, mm, where the case
//! places the teeth) and a RON case file that names them, so that a case can start from a template
//! and the import path can be checked round trip.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{MeshTransform, ToothMeshFile, Units, write_stl};
use crate::{
    io::{OutputError, OutputSet},
    teeth::{
        Dentition,
        case::{Case, ToothMap},
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

/// Writes the teeth of `d` to `dir` (created if needed) as `NN.stl` and the case as `NAME.ron`,
/// all or nothing: every output is checked (name and path lengths, never the case file `d` was
/// read from or one of its mesh files) before any is written, each is written to a temporary file
/// and all are moved into place at the end; on failure nothing is left behind.
///
/// # Errors
/// The first output that cannot or must not be written ([`OutputError`]).
pub fn export_case(d: &Dentition, dir: &Path) -> Result<ExportReport, OutputError> {
    let source = Path::new(&d.case.origin);
    let mut case: Case = d.case.case.clone();
    let case_file = dir.join(format!("{}.ron", file_stem(&case.name)));
    // Never replace what is read: the case file and its mesh files.
    let mut inputs = vec![source.to_owned()];
    inputs.extend(
        case.meshes
            .0
            .values()
            .map(|m| Case::mesh_path(&d.case.origin, &m.file)),
    );
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
        let world = t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v));
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
                transform: MeshTransform::default(),
            },
        );
    }
    // The meshes stand where the case placed the teeth: offsets and the bite opening are in them.
    case.meshes = files;
    case.offsets = ToothMap::default();
    case.bite_opening_mm = Default::default();
    let text =
        ron::ser::to_string_pretty(&case, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| OutputError::Write {
                path: case_file.clone(),
                source: std::io::Error::other(e),
            })?;
    let header = format!(
        "// Exported by `orthosim export-case` from {}: one STL per tooth (mm, orthosim's frame,\n\
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
