//! Labelled whole-arch scans: one mesh per arch, each vertex or face labelled with its tooth (FDI)
//! or with 0 for the gum, as segmentation software writes them. Three ways to give the labels:
//!
//! - `Property("label")`: an integer property of the PLY file's `vertex` or `face` element;
//! - `Json("upper.json")`: a JSON file `{"jaw": "upper", "labels": [FDI or 0 per vertex], …}` beside
//!   an OBJ or PLY mesh (the convention of the public 3D tooth segmentation benchmarks);
//! - `Colours({(139, 0, 0): 41, …})`: per-vertex or per-face RGB colours (PLY `red`, `green`,
//!   `blue`; OBJ `v x y z r g b`), each listed colour a tooth, every other colour gum.
//!
//! Labels per vertex become labels per triangle by majority (a triangle whose three corners all
//! differ is gum, so the tooth's margin runs inside its labelled vertices). [`split`] then cuts the
//! arch into one raw crown mesh per tooth, which the import repairs as any scanned crown.

use std::{collections::BTreeMap, io::BufRead, path::Path};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{
    error::ImportError,
    read::{MeshFormat, malformed, ply_scalar, read_mesh},
};
use crate::{
    geometry::TriMesh,
    teeth::fdi::{Arch, Fdi},
};

/// How a scan's teeth are labelled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Labels {
    /// An integer property of the PLY `vertex` or `face` element: FDI, or 0 for gum.
    Property(String),
    /// A JSON file (path relative to the case file) with `"labels"`: FDI or 0 per vertex.
    Json(String),
    /// RGB colour of each tooth, per vertex or per face; other colours are gum.
    Colours(BTreeMap<(u8, u8, u8), Fdi>),
}

/// A labelled whole-arch scan read from its files: the mesh and a label per triangle.
#[derive(Clone, Debug, Default)]
pub struct LabelledMesh {
    /// The mesh as in the file.
    pub mesh: TriMesh,
    /// FDI number per triangle, `None` for gum.
    pub labels: Vec<Option<Fdi>>,
}

impl LabelledMesh {
    /// A scan from per-vertex labels (FDI number, 0 for gum), as read from a file.
    ///
    /// # Errors
    /// A label count that does not match the vertices, or a label that is not 0 nor FDI.
    pub fn from_vertex_labels(mesh: TriMesh, labels: &[u32]) -> Result<Self, ImportError> {
        if labels.len() != mesh.vertices.len() {
            return Err(ImportError::Labels(format!(
                "{} labels for {} vertices: one label per vertex",
                labels.len(),
                mesh.vertices.len()
            )));
        }
        let per_vertex = labels
            .iter()
            .enumerate()
            .map(|(i, &v)| label(i64::from(v)).map_err(|_| bad_label(i64::from(v), "vertex", i)))
            .collect::<Result<Vec<_>, _>>()?;
        let labels = vertex_to_triangle(&mesh, &per_vertex);
        Ok(Self { mesh, labels })
    }
}

/// The arch named by a label file's `"jaw"`, if any.
#[derive(Debug, Deserialize)]
struct LabelFile {
    #[serde(default)]
    jaw: Option<String>,
    labels: Vec<serde_json::Value>,
}

/// Reads a labelled scan; `labels_file` is the resolved path of a `Json` label file.
///
/// # Errors
/// What is wrong, on one line: the mesh's own errors, a missing label property or colour, a
/// label count that does not match the mesh (both counts), a label that is not 0 nor an FDI tooth
/// (with its vertex or face), a JSON `jaw` that contradicts the labels.
pub fn read_labelled(
    path: &Path,
    labels: &Labels,
    labels_file: Option<&Path>,
) -> Result<LabelledMesh, ImportError> {
    let format = MeshFormat::of(path)?;
    let raw = match (format, labels) {
        (MeshFormat::Ply, _) => read_ply_attributes(path, labels)?,
        (MeshFormat::Obj, Labels::Property(_)) => {
            return Err(ImportError::Labels(
                "`Property` labels need a PLY file; an OBJ scan takes `Json` or `Colours` labels"
                    .into(),
            ));
        }
        (MeshFormat::Obj, _) => read_obj_attributes(path)?,
        (MeshFormat::Stl, Labels::Json(_)) => RawScan {
            mesh: read_mesh(path)?,
            ..RawScan::default()
        },
        (MeshFormat::Stl, _) => {
            return Err(ImportError::Labels(
                "an STL file holds no labels nor colours; a labelled STL scan takes `Json` labels"
                    .into(),
            ));
        }
    };
    let vertices = raw.mesh.vertices.len();
    let faces = raw.faces;
    let per_vertex = |values: &[i64], what: &str| -> Result<Vec<Option<Fdi>>, ImportError> {
        values
            .iter()
            .enumerate()
            .map(|(i, &v)| label(v).map_err(|_| bad_label(v, what, i)))
            .collect()
    };
    let labels = match labels {
        Labels::Property(name) => match (&raw.vertex_property, &raw.face_property) {
            (Some(v), _) => per_vertex(v, "vertex").map(|l| vertex_to_triangle(&raw.mesh, &l))?,
            (None, Some(f)) => {
                let l = per_vertex(f, "face")?;
                raw.face_of_triangle.iter().map(|&f| l[f]).collect()
            }
            (None, None) => {
                return Err(ImportError::Labels(format!(
                    "the PLY file has no integer property `{name}` on its vertices or faces"
                )));
            }
        },
        Labels::Json(_) => {
            let file = labels_file.ok_or_else(|| ImportError::Labels("no label file".into()))?;
            let values = read_label_json(file)?;
            if values.len() != vertices {
                return Err(ImportError::Labels(format!(
                    "the label file gives {} labels but the mesh has {vertices} vertices ({faces} faces): one label per vertex",
                    values.len()
                )));
            }
            per_vertex(&values, "vertex").map(|l| vertex_to_triangle(&raw.mesh, &l))?
        }
        Labels::Colours(map) => {
            let of = |c: &[u8; 3]| map.get(&(c[0], c[1], c[2])).copied();
            match (&raw.vertex_colours, &raw.face_colours) {
                (Some(v), _) => {
                    let l: Vec<_> = v.iter().map(of).collect();
                    vertex_to_triangle(&raw.mesh, &l)
                }
                (None, Some(f)) => raw.face_of_triangle.iter().map(|&i| of(&f[i])).collect(),
                (None, None) => {
                    return Err(ImportError::Labels(
                        "the mesh has no colours (`red`, `green`, `blue` on its vertices or faces, or `v x y z r g b`)".into(),
                    ));
                }
            }
        }
    };
    Ok(LabelledMesh {
        mesh: raw.mesh,
        labels,
    })
}

/// 0 is gum, anything else must be an FDI number.
fn label(v: i64) -> Result<Option<Fdi>, ()> {
    if v == 0 {
        Ok(None)
    } else {
        Fdi::new(v).map(Some).map_err(|_| ())
    }
}

fn bad_label(v: i64, what: &str, i: usize) -> ImportError {
    ImportError::Labels(format!(
        "label {v} of {what} {i} is neither 0 (gum) nor an FDI tooth number (11–18, 21–28, 31–38, 41–48)"
    ))
}

/// Per-vertex labels to per-triangle labels: the label two or three corners share; gum when all
/// three differ.
fn vertex_to_triangle(mesh: &TriMesh, labels: &[Option<Fdi>]) -> Vec<Option<Fdi>> {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| labels.get(i as usize).copied().flatten());
            if a == b || a == c {
                a
            } else if b == c {
                b
            } else {
                None
            }
        })
        .collect()
}

/// Reads a JSON label file: per-vertex labels, checked against its `jaw` when it has one.
fn read_label_json(path: &Path) -> Result<Vec<i64>, ImportError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        ImportError::Labels(format!(
            "cannot read the label file {}: {e}",
            path.display()
        ))
    })?;
    let file: LabelFile = serde_json::from_str(&text).map_err(|e| {
        ImportError::Labels(format!(
            "{}:{}:{}: not a label file ({{\"jaw\": …, \"labels\": [FDI or 0 per vertex]}}): {e}",
            path.display(),
            e.line(),
            e.column()
        ))
    })?;
    let mut out = Vec::with_capacity(file.labels.len());
    for (i, v) in file.labels.iter().enumerate() {
        let n = v.as_i64().ok_or_else(|| {
            ImportError::Labels(format!(
                "{}: label {i} is {v}, not an integer",
                path.display()
            ))
        })?;
        out.push(n);
    }
    if let Some(jaw) = &file.jaw {
        let arch = match jaw.to_ascii_lowercase().as_str() {
            "upper" | "maxilla" | "maxillary" => Arch::Upper,
            "lower" | "mandible" | "mandibular" => Arch::Lower,
            other => {
                return Err(ImportError::Labels(format!(
                    "{}: jaw \"{other}\" is neither \"upper\" nor \"lower\"",
                    path.display()
                )));
            }
        };
        if let Some((i, f)) = out
            .iter()
            .enumerate()
            .find_map(|(i, &v)| Some((i, Fdi::new(v).ok()?)).filter(|(_, f)| f.arch() != arch))
        {
            return Err(ImportError::Labels(format!(
                "{}: the jaw is \"{jaw}\" but vertex {i} is labelled {f}, a tooth of the other arch",
                path.display()
            )));
        }
    }
    Ok(out)
}

/// A mesh with the attributes labels can come from.
#[derive(Default)]
struct RawScan {
    mesh: TriMesh,
    /// Faces in the file (polygons before triangulation).
    faces: usize,
    /// The face each triangle comes from.
    face_of_triangle: Vec<usize>,
    vertex_property: Option<Vec<i64>>,
    face_property: Option<Vec<i64>>,
    vertex_colours: Option<Vec<[u8; 3]>>,
    face_colours: Option<Vec<[u8; 3]>>,
}

fn read_ply_attributes(path: &Path, labels: &Labels) -> Result<RawScan, ImportError> {
    use ply_rs_bw::{
        parser::Parser,
        ply::{DefaultElement, Property},
    };
    let file = std::fs::File::open(path).map_err(|e| ImportError::Unreadable(e.to_string()))?;
    if file.metadata().is_ok_and(|m| m.len() == 0) {
        return Err(ImportError::EmptyFile);
    }
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::BufReader::new(file))
        .map_err(|e| malformed(MeshFormat::Ply, e))?;
    let (mesh, face_of_triangle) = super::read::ply_mesh(&ply)?;
    // Integers, and floats that hold whole numbers (some tools write labels as floats).
    let integer = |p: &Property| -> Option<i64> {
        let v = ply_scalar(p)?;
        (v.fract() == 0.0 && v.abs() < 1e9).then_some(v as i64)
    };
    // Colour channels: integers (0–255) or floats (0–1, or 0–255).
    let channel = |p: &Property| -> Option<u8> {
        let v = ply_scalar(p)?;
        Some(match p {
            Property::Float(_) | Property::Double(_) => colour_channel(v as f32),
            _ => v.clamp(0.0, 255.0) as u8,
        })
    };
    let elements = |name: &str| ply.payload.get(name).map(Vec::as_slice).unwrap_or(&[]);
    let property = |element: &str, name: &str| -> Result<Option<Vec<i64>>, ImportError> {
        let items = elements(element);
        if !items.first().is_some_and(|e| e.contains_key(name)) {
            return Ok(None);
        }
        items
            .iter()
            .enumerate()
            .map(|(i, e)| {
                e.get(name).and_then(integer).ok_or_else(|| {
                    ImportError::Labels(format!(
                        "PLY {element} {i} has no integer `{name}` property"
                    ))
                })
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    };
    let colours = |element: &str| -> Result<Option<Vec<[u8; 3]>>, ImportError> {
        let items = elements(element);
        let names = [["red", "green", "blue"], ["r", "g", "b"]];
        let Some(names) = names.iter().find(|n| {
            items
                .first()
                .is_some_and(|e| n.iter().all(|k| e.contains_key(*k)))
        }) else {
            return Ok(None);
        };
        items
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let mut rgb = [0u8; 3];
                for (k, name) in names.iter().enumerate() {
                    rgb[k] = e.get(*name).and_then(channel).ok_or_else(|| {
                        ImportError::Labels(format!("PLY {element} {i} has no colour `{name}`"))
                    })?;
                }
                Ok(rgb)
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    };
    let mut raw = RawScan {
        faces: elements("face").len(),
        face_of_triangle,
        ..RawScan::default()
    };
    match labels {
        Labels::Property(name) => {
            raw.vertex_property = property("vertex", name)?;
            if raw.vertex_property.is_none() {
                raw.face_property = property("face", name)?;
            }
        }
        Labels::Colours(_) => {
            raw.vertex_colours = colours("vertex")?;
            if raw.vertex_colours.is_none() {
                raw.face_colours = colours("face")?;
            }
        }
        Labels::Json(_) => {}
    }
    raw.mesh = mesh;
    Ok(raw)
}

/// A colour channel given as a float: 0–1 scaled to 0–255, larger values taken as 0–255.
fn colour_channel(v: f32) -> u8 {
    if !v.is_finite() {
        return 0;
    }
    let v = if v <= 1.0 { v * 255.0 } else { v };
    v.round().clamp(0.0, 255.0) as u8
}

/// Reads an OBJ file's vertices in file order (labels are per vertex in that order), their
/// colours when every vertex has them (`v x y z r g b`), and its faces (polygons as fans; indices
/// may be negative, relative to the end).
fn read_obj_attributes(path: &Path) -> Result<RawScan, ImportError> {
    let file = std::fs::File::open(path).map_err(|e| ImportError::Unreadable(e.to_string()))?;
    let reader = std::io::BufReader::new(file);
    let mut raw = RawScan::default();
    let mut colours: Vec<[u8; 3]> = Vec::new();
    let mut all_coloured = true;
    let bad = |line: usize, what: &str| ImportError::Malformed {
        format: MeshFormat::Obj,
        detail: format!("{what} (line {line})"),
    };
    for (n, line) in reader.lines().enumerate() {
        let line = line.map_err(|e| ImportError::Unreadable(e.to_string()))?;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let numbers = words
                    .map(str::parse::<f32>)
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(|_| bad(n + 1, "a vertex with a coordinate that is not a number"))?;
                if numbers.len() < 3 {
                    return Err(bad(n + 1, "a vertex with fewer than three coordinates"));
                }
                raw.mesh
                    .vertices
                    .push(Vec3::new(numbers[0], numbers[1], numbers[2]));
                if numbers.len() >= 6 {
                    colours.push([3, 4, 5].map(|k| colour_channel(numbers[k])));
                } else {
                    all_coloured = false;
                }
            }
            Some("f") => {
                let count = raw.mesh.vertices.len() as i64;
                let corners = words
                    .map(|w| {
                        let i = w.split('/').next().unwrap_or("").parse::<i64>().ok()?;
                        let i = if i < 0 { count + i } else { i - 1 };
                        u32::try_from(i).ok()
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| bad(n + 1, "a face with a vertex index that is not valid"))?;
                if corners.len() < 3 {
                    return Err(bad(n + 1, "a face with fewer than three vertices"));
                }
                for k in 1..corners.len() - 1 {
                    raw.mesh
                        .triangles
                        .push([corners[0], corners[k], corners[k + 1]]);
                    raw.face_of_triangle.push(raw.faces);
                }
                raw.faces += 1;
            }
            _ => {}
        }
    }
    if raw.mesh.vertices.is_empty() && raw.mesh.triangles.is_empty() {
        return Err(ImportError::EmptyFile);
    }
    if all_coloured && !colours.is_empty() {
        raw.vertex_colours = Some(colours);
    }
    Ok(raw)
}

/// The teeth of a labelled scan, each as a raw mesh (its labelled triangles, vertices renumbered),
/// in FDI order.
pub fn split(scan: &LabelledMesh) -> BTreeMap<Fdi, TriMesh> {
    let mut out: BTreeMap<Fdi, (TriMesh, BTreeMap<u32, u32>)> = BTreeMap::new();
    for (t, label) in scan.mesh.triangles.iter().zip(&scan.labels) {
        let Some(fdi) = label else { continue };
        let (mesh, index) = out.entry(*fdi).or_default();
        let tri = t.map(|v| {
            *index.entry(v).or_insert_with(|| {
                mesh.vertices.push(
                    scan.mesh
                        .vertices
                        .get(v as usize)
                        .copied()
                        .unwrap_or(Vec3::NAN),
                );
                (mesh.vertices.len() - 1) as u32
            })
        });
        mesh.triangles.push(tri);
    }
    out.into_iter().map(|(f, (m, _))| (f, m)).collect()
}

/// Checks a scan's indices and coordinates before it is split (a bad index would otherwise vanish
/// into one tooth's mesh).
///
/// # Errors
/// [`ImportError::Empty`], [`ImportError::BadIndex`], [`ImportError::NonFinite`], or labels that
/// name no tooth.
pub fn check_scan(scan: &LabelledMesh) -> Result<(), ImportError> {
    check_raw(&scan.mesh)?;
    if scan.labels.iter().all(Option::is_none) {
        return Err(ImportError::Labels(
            "no triangle is labelled with a tooth: every label is 0 (gum) or unlisted".into(),
        ));
    }
    Ok(())
}

/// Checks a raw mesh's counts, coordinates and indices (before it is placed: a NaN would
/// otherwise spoil the placement of every tooth in its frame).
///
/// # Errors
/// [`ImportError::Empty`], [`ImportError::BadIndex`], [`ImportError::NonFinite`].
pub fn check_raw(m: &TriMesh) -> Result<(), ImportError> {
    if m.vertices.is_empty() || m.triangles.is_empty() {
        return Err(ImportError::Empty {
            vertices: m.vertices.len(),
            triangles: m.triangles.len(),
        });
    }
    if let Some(i) = m.vertices.iter().position(|v| !v.is_finite()) {
        return Err(ImportError::NonFinite(i));
    }
    for (i, t) in m.triangles.iter().enumerate() {
        if let Some(&v) = t.iter().find(|&&v| v as usize >= m.vertices.len()) {
            return Err(ImportError::BadIndex {
                triangle: i,
                vertex: v,
                vertices: m.vertices.len(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("orthosim-labels-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    const HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";

    #[test]
    fn per_face_properties_and_colours_label_their_triangles() {
        let ply = format!(
            "{HEAD}element face 2\nproperty list uchar int vertex_indices\nproperty int label\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 11 200 0 0\n3 0 2 3 0 9 9 9\n"
        );
        let path = write("faces.ply", &ply);
        let by_property = read_labelled(&path, &Labels::Property("label".into()), None).unwrap();
        let eleven = Fdi::new(11).ok();
        assert_eq!(by_property.labels, vec![eleven, None]);
        let colours = Labels::Colours([((200, 0, 0), Fdi::new(11).unwrap())].into());
        let by_colour = read_labelled(&path, &colours, None).unwrap();
        assert_eq!(by_colour.labels, vec![eleven, None]);
        let teeth = split(&by_property);
        assert_eq!(teeth.len(), 1);
        assert_eq!(teeth[&Fdi::new(11).unwrap()].triangles.len(), 1);
        let e = read_labelled(&path, &Labels::Property("tooth".into()), None).unwrap_err();
        assert!(e.to_string().contains("`tooth`"), "{e}");
    }

    #[test]
    fn per_vertex_labels_vote_and_bad_numbers_are_named() {
        let ply = format!(
            "{HEAD}property int label\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0 21\n1 0 0 21\n1 1 0 0\n0 1 0 22\n3 0 1 2\n3 0 2 3\n"
        );
        let path = write("vertices.ply", &ply);
        let scan = read_labelled(&path, &Labels::Property("label".into()), None).unwrap();
        // Two corners of 21: 21; all three different: gum.
        assert_eq!(scan.labels, vec![Fdi::new(21).ok(), None]);
        let bad = ply.replace("0 1 0 22", "0 1 0 19");
        let path = write("bad.ply", &bad);
        let e = read_labelled(&path, &Labels::Property("label".into()), None).unwrap_err();
        assert!(e.to_string().contains("label 19 of vertex 3"), "{e}");
        // OBJ with vertex colours (0–1 floats), faces with texture indices and negative indices.
        let obj = write(
            "colours.obj",
            "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 1 1 0 1 0 0\nv 0 1 0 0 1 0\nf 1/1 2/2 3/3\nf -4 -2 -1\n",
        );
        let colours = Labels::Colours([((255, 0, 0), Fdi::new(31).unwrap())].into());
        let scan = read_labelled(&obj, &colours, None).unwrap();
        assert_eq!(scan.labels, vec![Fdi::new(31).ok(), Fdi::new(31).ok()]);
        let e = read_labelled(&obj, &Labels::Property("label".into()), None).unwrap_err();
        assert!(e.to_string().contains("PLY"), "{e}");
    }
}
