//! Reading tooth meshes: STL (binary or ASCII, `stl_io`), OBJ (`tobj`, polygons triangulated) and
//! PLY (ASCII or binary, `ply-rs-bw`, polygons triangulated as fans). The result is an unchecked
//! [`TriMesh`]; [`super::repair`] checks and repairs it.

use std::{
    fs::File,
    io::{BufReader, Seek},
    path::Path,
};

use glam::Vec3;

use super::error::{ImportError, PlyProblem};
use crate::geometry::TriMesh;

/// Mesh file formats orthosim reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
}

impl std::fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MeshFormat::Stl => "STL",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
        })
    }
}

impl MeshFormat {
    /// The format of a file, from its extension.
    ///
    /// # Errors
    /// [`ImportError::UnknownFormat`] for any other extension.
    pub fn of(path: &Path) -> Result<Self, ImportError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Ok(Self::Stl),
            Some("obj") => Ok(Self::Obj),
            Some("ply") => Ok(Self::Ply),
            _ => Err(ImportError::UnknownFormat),
        }
    }
}

/// Reads a mesh file.
///
/// # Errors
/// What is wrong, on one line, without the path: an unknown format, an unreadable or empty file,
/// or one that is not valid in its format (with the line, for OBJ).
pub fn read_mesh(path: &Path) -> Result<TriMesh, ImportError> {
    let format = MeshFormat::of(path)?;
    let file = File::open(path).map_err(|e| ImportError::Unreadable(e.to_string()))?;
    let mut reader = BufReader::new(file);
    match format {
        MeshFormat::Stl => read_stl(&mut reader),
        MeshFormat::Obj => read_obj(&mut reader).map_err(|e| match (e, obj_bad_line(path)) {
            (ImportError::Malformed { format, detail }, Some(line)) => ImportError::Malformed {
                format,
                detail: format!("{detail} (line {line})"),
            },
            (e, _) => e,
        }),
        MeshFormat::Ply => read_ply(&mut reader),
    }
}

/// The parser's message as the detail of a malformed file (on one line).
pub(super) fn malformed(format: MeshFormat, e: impl std::fmt::Display) -> ImportError {
    ImportError::Malformed {
        format,
        detail: one_line(&e.to_string()),
    }
}

/// Parsers' messages can span lines; errors are one line.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn read_stl<R: std::io::Read + Seek>(reader: &mut R) -> Result<TriMesh, ImportError> {
    let unreadable = |e: std::io::Error| ImportError::Unreadable(e.to_string());
    let len = reader.seek(std::io::SeekFrom::End(0)).map_err(unreadable)?;
    reader.rewind().map_err(unreadable)?;
    if len == 0 {
        return Err(ImportError::EmptyFile);
    }
    let mesh = stl_io::read_stl(reader).map_err(|e| {
        // A binary file that ends early: say what its header promised.
        let mut head = [0u8; 84];
        let promised = (len >= 84
            && reader.rewind().is_ok()
            && std::io::Read::read_exact(reader, &mut head).is_ok())
        .then(|| u32::from_le_bytes([head[80], head[81], head[82], head[83]]) as u64);
        match promised {
            Some(n) if 84 + 50 * n != len && !head.starts_with(b"solid") => {
                ImportError::StlLength {
                    triangles: n,
                    expected: 84 + 50 * n,
                    bytes: len,
                }
            }
            _ => malformed(MeshFormat::Stl, e),
        }
    })?;
    Ok(TriMesh::new(
        mesh.vertices
            .iter()
            .map(|v| Vec3::from_array(v.0))
            .collect(),
        mesh.faces
            .iter()
            .map(|f| f.vertices.map(|i| i as u32))
            .collect(),
    ))
}

fn read_obj<R: std::io::BufRead>(reader: &mut R) -> Result<TriMesh, ImportError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    // Materials are not needed: never open .mtl files.
    let (models, _) =
        tobj::load_obj_buf(reader, &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| malformed(MeshFormat::Obj, e))?;
    let mut mesh = TriMesh::default();
    for model in models {
        let base = mesh.vertices.len() as u32;
        let m = &model.mesh;
        mesh.vertices.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        for t in m.indices.chunks_exact(3) {
            mesh.triangles.push([t[0] + base, t[1] + base, t[2] + base]);
        }
    }
    Ok(mesh)
}

/// The first line of an OBJ file whose vertex or face record does not parse, for error messages.
fn obj_bad_line(path: &Path) -> Option<usize> {
    let text = std::fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&text);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let ok = match words.next() {
            Some("v") => {
                let numbers: Vec<_> = words.map(str::parse::<f32>).collect();
                numbers.len() >= 3 && numbers.iter().all(Result::is_ok)
            }
            Some("f") => {
                let corners: Vec<_> = words
                    .map(|w| w.split('/').next().unwrap_or("").parse::<i64>())
                    .collect();
                corners.len() >= 3 && corners.iter().all(|c| c.as_ref().is_ok_and(|&c| c != 0))
            }
            _ => true,
        };
        if !ok {
            return Some(i + 1);
        }
    }
    None
}

fn read_ply<R: std::io::Read>(reader: &mut R) -> Result<TriMesh, ImportError> {
    use ply_rs_bw::{parser::Parser, ply::DefaultElement};
    let ply = Parser::<DefaultElement>::new()
        .read_ply(reader)
        .map_err(|e| malformed(MeshFormat::Ply, e))?;
    ply_mesh(&ply).map(|(mesh, _)| mesh)
}

/// A PLY scalar property as a number (`None` for a list).
pub(super) fn ply_scalar(p: &ply_rs_bw::ply::Property) -> Option<f64> {
    use ply_rs_bw::ply::Property;
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

/// The mesh of a parsed PLY file, and the face each triangle comes from (polygons become fans).
pub(super) fn ply_mesh(
    ply: &ply_rs_bw::ply::Ply<ply_rs_bw::ply::DefaultElement>,
) -> Result<(TriMesh, Vec<usize>), ImportError> {
    use ply_rs_bw::ply::Property;
    let list = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
            _ => return None,
        })
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or(ImportError::PlyContent(PlyProblem::NoElement("vertex")))?;
    let mut mesh = TriMesh::default();
    for (i, v) in vertices.iter().enumerate() {
        let mut xyz = [0.0f32; 3];
        for (k, name) in ["x", "y", "z"].into_iter().enumerate() {
            let value = v
                .get(name)
                .and_then(ply_scalar)
                .ok_or(ImportError::PlyContent(PlyProblem::NoCoordinate {
                    vertex: i,
                    name,
                }))?;
            xyz[k] = value as f32;
        }
        mesh.vertices.push(Vec3::from_array(xyz));
    }
    let faces = ply
        .payload
        .get("face")
        .ok_or(ImportError::PlyContent(PlyProblem::NoElement("face")))?;
    let mut face_of_triangle = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        let indices = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(list)
            .ok_or(ImportError::PlyContent(PlyProblem::NoIndices(i)))?;
        if indices.len() < 3 {
            return Err(ImportError::PlyContent(PlyProblem::TooFewVertices {
                face: i,
                count: indices.len(),
            }));
        }
        let index = |x: i64| {
            u32::try_from(x)
                .map_err(|_| ImportError::PlyContent(PlyProblem::BadIndex { face: i, index: x }))
        };
        for k in 1..indices.len() - 1 {
            mesh.triangles.push([
                index(indices[0])?,
                index(indices[k])?,
                index(indices[k + 1])?,
            ]);
            face_of_triangle.push(i);
        }
    }
    Ok((mesh, face_of_triangle))
}

/// Writes a mesh as binary STL (facet normals from the triangles).
pub fn write_stl(mesh: &TriMesh, out: &mut impl std::io::Write) -> std::io::Result<()> {
    let triangles: Vec<stl_io::Triangle> = (0..mesh.triangles.len())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            let n = (b - a).cross(c - a).normalize_or_zero();
            stl_io::Triangle {
                normal: stl_io::Normal::new(n.to_array()),
                vertices: [a, b, c].map(|v| stl_io::Vertex::new(v.to_array())),
            }
        })
        .collect();
    stl_io::write_stl(out, triangles.iter())
}
