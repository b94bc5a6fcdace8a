//! `export-case`: a case written as one STL file per tooth (in orthosim's frame, mm, where the case
//! places the teeth) and a RON case file that names them, so that a case can start from a template
//! and the import path can be checked round trip.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{MeshTransform, ToothMeshFile, Units, write_stl};
use crate::{
    sphere_tree::report::{refuse_overwriting, write_atomic_bytes},
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

/// Writes the teeth of `d` to `dir` (created if needed) as `NN.stl` and the case as `NAME.ron`.
/// Files are written atomically; the case file `d` was read from and its mesh files are never
/// replaced.
pub fn export_case(d: &Dentition, dir: &Path) -> Result<ExportReport, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
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
    refuse_overwriting(&case_file, &inputs)?;
    for t in &d.teeth {
        refuse_overwriting(&dir.join(format!("{}.stl", t.fdi.number())), &inputs)?;
    }
    let mut meshes = Vec::new();
    let mut files = ToothMap::default();
    let mut triangles = 0;
    for t in &d.teeth {
        let name = format!("{}.stl", t.fdi.number());
        let path = dir.join(&name);
        let world = t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v));
        let mut bytes = Vec::new();
        write_stl(&world, &mut bytes).map_err(|e| format!("{}: {e}", path.display()))?;
        write_atomic_bytes(&path, &bytes)
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        triangles += world.triangles.len();
        files.0.insert(
            t.fdi,
            ToothMeshFile {
                file: name,
                units: Units::Millimetres,
                transform: MeshTransform::default(),
            },
        );
        meshes.push(path);
    }
    // The meshes stand where the case placed the teeth: offsets and the bite opening are in them.
    case.meshes = files;
    case.offsets = ToothMap::default();
    case.bite_opening_mm = Default::default();
    let text =
        ron::ser::to_string_pretty(&case, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| format!("cannot write the case: {e}"))?;
    let header = format!(
        "// Exported by `orthosim export-case` from {}: one STL per tooth (mm, orthosim's frame,\n\
         // where the case placed it), so offsets and the bite opening are part of the meshes.\n",
        d.case.origin
    );
    write_atomic_bytes(&case_file, format!("{header}{text}\n").as_bytes())
        .map_err(|e| format!("{}: cannot write: {e}", case_file.display()))?;
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
