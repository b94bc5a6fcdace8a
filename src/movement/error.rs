//! What can go wrong in tooth movement: settings out of range, a simulation that cannot be made,
//! an edit that is refused, a case that cannot be run.

use std::path::PathBuf;

use thiserror::Error;

use crate::{
    sphere_tree::TreeBuildError,
    teeth::{CaseError, Fdi, LoadError},
};

/// A movement error; each names what is wrong (and the file and position for a settings file).
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MovementError {
    /// A movement parameter is out of its range or not finite.
    #[error("movement setting {field} must be in {min}–{max}, got {value}")]
    Setting {
        /// The parameter.
        field: &'static str,
        /// Its value.
        value: f32,
        /// Least accepted.
        min: f32,
        /// Most accepted.
        max: f32,
    },
    /// A settings file could not be read.
    #[error("{}: cannot read movement settings: {message}", .path.display())]
    SettingsUnreadable {
        /// The file.
        path: PathBuf,
        /// What the system said.
        message: String,
    },
    /// A settings file is not valid; `line` and `column` are 1-based.
    #[error("{}:{line}:{column}: {message}", .path.display())]
    SettingsInvalid {
        /// The file.
        path: PathBuf,
        /// Line of the problem.
        line: usize,
        /// Column of the problem.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A tooth's root cannot carry a periodontal ligament.
    #[error("tooth {fdi}: {source}")]
    Pdl {
        /// The tooth.
        fdi: Fdi,
        /// Why.
        source: crate::movement::pdl::PdlError,
    },
    /// A visible tooth was given no collision shape.
    #[error("no collision shape for tooth {0}")]
    NoShape(Fdi),
    /// A load was refused.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// A group load names no group of the case.
    #[error("a load for group {0} was refused: no such group")]
    NoGroup(usize),
    /// The tooth is not one of the case's.
    #[error("tooth {0} is not in the case")]
    NotInCase(Fdi),
    /// Extracting a tooth already extracted.
    #[error("tooth {0} is already extracted")]
    AlreadyExtracted(Fdi),
    /// Restoring a tooth already in place.
    #[error("tooth {0} is already in place")]
    AlreadyInPlace(Fdi),
    /// Restoring a tooth whose collision shape is not built yet.
    #[error("tooth {0} has no collision shape yet")]
    NotReady(Fdi),
    /// Restoring a tooth into a place another tooth has moved into.
    #[error(
        "cannot restore tooth {fdi}: tooth {by} has moved into its place (overlap {overlap_mm:.2} mm)"
    )]
    Occupied {
        /// The tooth to restore.
        fdi: Fdi,
        /// The tooth in its place.
        by: Fdi,
        /// How deep they would overlap (mm).
        overlap_mm: f32,
    },
    /// The case could not be read or built.
    #[error(transparent)]
    Case(#[from] CaseError),
    /// The case's sphere trees could not be built.
    #[error(transparent)]
    Trees(#[from] TreeBuildError),
    /// Brackets or a wire cannot be placed as asked.
    #[error("appliance: {0}")]
    Appliance(String),
    /// A simulation of the named case could not be made.
    #[error("{case}: {source}")]
    InCase {
        /// The case (name or path).
        case: String,
        /// Why.
        source: Box<MovementError>,
    },
}
