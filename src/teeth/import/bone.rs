//! Bone meshes (the maxilla and mandible of a CBCT segmentation): read, welded and checked to be
//! closed, their triangles wound outwards.

use std::path::Path;

use super::{ImportError, RepairLimits, Repairs, Units, check_raw, read_in_mm};
use crate::geometry::TriMesh;

/// Reads the bone mesh at `path` in millimetres (the file's frame): welded as the teeth's meshes
/// are (files that repeat each corner per triangle, as STL does, show their surface whole once
/// welded), every edge shared by two triangles, wound with its normals outwards.
///
/// # Errors
/// What is wrong and where, without the path: unreadable, empty, non-finite, bad indices, or open
/// (with how many edges bound its holes and where the first is).
pub fn read_bone(path: &Path, units: Units) -> Result<TriMesh, ImportError> {
    let raw = read_in_mm(path, units)?;
    check_raw(&raw)?;
    let (vertices, triangles) = super::repair::weld(
        &raw,
        RepairLimits::default().weld_mm,
        &mut Repairs::default(),
    );
    let mut mesh = TriMesh::new(vertices, triangles);
    let open = mesh.open_edges();
    if let Some(&(a, _)) = open.first() {
        return Err(ImportError::OpenBone {
            edges: open.len(),
            at: mesh.vertices[a as usize].to_array(),
        });
    }
    if mesh.signed_volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    Ok(mesh)
}
