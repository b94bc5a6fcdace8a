//! Why a tooth mesh could not be imported: each error says what is wrong and where in the mesh
//! (a vertex, triangle or position in mm), on one line, without the file's path (the case's error
//! adds it).

use std::fmt;

use glam::Vec3;
use thiserror::Error;

use super::read::MeshFormat;
use crate::geometry::MeshError;

/// A position in a message: `near (x, y, z) mm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Near(pub Vec3);

impl fmt::Display for Near {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        write!(f, "near ({:.3}, {:.3}, {:.3}) mm", v.x, v.y, v.z)
    }
}

/// A tooth mesh that could not be read, repaired or framed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ImportError {
    /// The file name's extension is not a mesh format orthosim reads.
    #[error("unknown mesh format: the file must end in .stl, .obj or .ply")]
    UnknownFormat,
    /// The file could not be opened or read.
    #[error("cannot read the mesh file: {0}")]
    Unreadable(String),
    /// The file has no bytes.
    #[error("the file is empty")]
    EmptyFile,
    /// A bone mesh with holes (a bone mesh must be a closed surface).
    #[error(
        "the bone mesh is open: {edges} edges bound its holes, the first at ({:.2}, {:.2}, {:.2}) mm; a bone mesh must be a closed surface",
        at[0], at[1], at[2]
    )]
    OpenBone {
        /// Edges used by one triangle only.
        edges: usize,
        /// A vertex of the first of them (mm, the file's frame).
        at: [f32; 3],
    },
    /// The file is not valid in its format (the parser's words, on one line).
    #[error("not a valid {format} file: {detail}")]
    Malformed {
        /// The format.
        format: MeshFormat,
        /// What the parser said, and where.
        detail: String,
    },
    /// A binary STL file shorter or longer than its header says.
    #[error(
        "not a valid STL file: as binary STL its header announces {triangles} triangles ({expected} bytes), but the file has {bytes} bytes"
    )]
    StlLength {
        /// Triangles announced.
        triangles: u64,
        /// Bytes they take.
        expected: u64,
        /// Bytes in the file.
        bytes: u64,
    },
    /// A PLY file lacks an element or property a mesh needs.
    #[error("{0}")]
    PlyContent(PlyProblem),
    /// The mesh has no vertices or no triangles.
    #[error("the mesh is empty ({vertices} vertices, {triangles} triangles)")]
    Empty {
        /// Vertices.
        vertices: usize,
        /// Triangles.
        triangles: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {0} has a non-finite coordinate (NaN or infinity)")]
    NonFinite(usize),
    /// A triangle names a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but there are only {vertices} vertices"
    )]
    BadIndex {
        /// The triangle.
        triangle: usize,
        /// The vertex it names.
        vertex: u32,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// Every triangle is degenerate.
    #[error("the mesh has no triangle of non-zero area")]
    NoArea,
    /// An edge is shared by more than two triangles.
    #[error(
        "the mesh is non-manifold: an edge {at} is shared by {triangles} triangles ({edges} such edges)"
    )]
    SharedEdge {
        /// Where the first such edge is.
        at: Near,
        /// Triangles sharing it.
        triangles: usize,
        /// Such edges in all.
        edges: usize,
    },
    /// Several large pieces: more than one tooth, or a tooth in pieces.
    #[error(
        "the file holds {pieces} separate pieces of {limit} triangles or more: one tooth per file"
    )]
    SeveralPieces {
        /// Large pieces.
        pieces: usize,
        /// The size from which a piece counts as large.
        limit: usize,
    },
    /// The surface cannot be given one winding.
    #[error("the surface cannot be oriented (a Möbius-like twist) at the edge {0}")]
    Twisted(Near),
    /// Two holes share a vertex.
    #[error("the mesh is non-manifold: two holes meet at the vertex {0}")]
    HolesMeet(Near),
    /// A vertex where the surface is not a disc.
    #[error("the mesh is non-manifold at the vertex {0}")]
    NonManifoldVertex(Near),
    /// A hole's boundary does not come back to its start.
    #[error("a hole's boundary does not close at the vertex {0}")]
    OpenBoundary(Near),
    /// The mesh is too small or too large to be a tooth in millimetres.
    #[error(
        "the mesh spans {span_mm:.4} mm, not a tooth's {min_mm}–{max_mm} mm: are its units right (units: Millimetres, Metres or Inches)?"
    )]
    Span {
        /// Its largest extent.
        span_mm: f32,
        /// Least accepted.
        min_mm: f32,
        /// Most accepted.
        max_mm: f32,
    },
    /// One large opening that does not face the root's side, so not a crown's margin.
    #[error(
        "the mesh is open: its longest opening, a {length_mm:.2} mm boundary {at}, is a crown's margin by its size (beyond {max_hole_mm} mm and the crown's width) but does not face the root's side: is the mesh upside down, or its transform wrong?"
    )]
    OpenNotMargin {
        /// Its boundary length.
        length_mm: f32,
        /// Where it is.
        at: Near,
        /// The longest boundary closed automatically.
        max_hole_mm: f32,
    },
    /// The cervical margin is degenerate.
    #[error("the cervical margin encloses no area: cannot generate a root")]
    FlatMargin,
    /// Two triangles cross.
    #[error(
        "the mesh intersects itself beyond what the repair cuts out: triangles {a} and {b} cross {at}"
    )]
    SelfIntersecting {
        /// One triangle.
        a: usize,
        /// The other.
        b: usize,
        /// Where.
        at: Near,
    },
    /// A degenerate triangle is left after the repair.
    #[error("a degenerate triangle remains after repair {0}")]
    Degenerate(Near),
    /// The closed surface encloses no volume.
    #[error("the mesh encloses no volume ({volume:.4} mm³): it is flat")]
    Flat {
        /// Its signed volume.
        volume: f64,
    },
    /// A labelled scan's labels are missing, malformed or do not fit its mesh.
    #[error("{0}")]
    Labels(String),
    /// The repaired mesh fails another check of a closed solid.
    #[error("the repaired mesh is not a closed solid: {0}")]
    NotSolid(MeshError),
}

impl ImportError {
    /// True when the mesh holds a tooth's surface that the repair could not make a solid, so a
    /// rebuild may still give one; false when it is no tooth at all (empty, unreadable,
    /// non-finite, of a size no tooth has) or the error is in the file or labels.
    pub fn is_repairable(&self) -> bool {
        matches!(
            self,
            ImportError::SharedEdge { .. }
                | ImportError::SeveralPieces { .. }
                | ImportError::Twisted(_)
                | ImportError::HolesMeet(_)
                | ImportError::NonManifoldVertex(_)
                | ImportError::OpenBoundary(_)
                | ImportError::OpenNotMargin { .. }
                | ImportError::FlatMargin
                | ImportError::SelfIntersecting { .. }
                | ImportError::Degenerate(_)
                | ImportError::Flat { .. }
                | ImportError::NotSolid(_)
        )
    }
}

/// What a PLY file lacks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlyProblem {
    /// No element of this name.
    NoElement(&'static str),
    /// A vertex without a numeric coordinate.
    NoCoordinate {
        /// The vertex.
        vertex: usize,
        /// The coordinate's name.
        name: &'static str,
    },
    /// A face without its vertex list.
    NoIndices(usize),
    /// A face with fewer than three vertices.
    TooFewVertices {
        /// The face.
        face: usize,
        /// Its vertices.
        count: usize,
    },
    /// A face with a vertex index that is negative or too large.
    BadIndex {
        /// The face.
        face: usize,
        /// The index.
        index: i64,
    },
}

impl fmt::Display for PlyProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlyProblem::NoElement(name) => write!(f, "the PLY file has no `{name}` element"),
            PlyProblem::NoCoordinate { vertex, name } => {
                write!(f, "PLY vertex {vertex} has no numeric `{name}`")
            }
            PlyProblem::NoIndices(face) => {
                write!(f, "PLY face {face} has no `vertex_indices` list")
            }
            PlyProblem::TooFewVertices { face, count } => {
                write!(f, "PLY face {face} has {count} vertices")
            }
            PlyProblem::BadIndex { face, index } => {
                write!(f, "PLY face {face} has the vertex index {index}")
            }
        }
    }
}
