//! Teeth: FDI numbers, the anatomy table, procedural tooth meshes, arch forms, patient cases, mesh
//! import, scan-like test data, and (feature `ecs`) the `TeethModelPlugin` that spawns tooth
//! entities.
//!
//! Engine-free parts (`fdi`, `anatomy`, `shape`, `frame`, `tooth_shape`, `arch`, `case`,
//! `dentition`, `load`, `import`, `scan_like`) need no `World`; `components` and `plugin` are the ECS layer.

pub mod anatomy;
pub mod arch;
pub mod case;
#[cfg(feature = "ecs")]
mod components;
mod dentition;
mod fdi;
mod frame;
pub mod import;
pub mod labelled_scan;
mod load;
mod memo;
mod patient;
#[cfg(feature = "ecs")]
mod plugin;
pub mod scan_like;
pub mod shape;
mod tooth_shape;

pub use case::{Case, CaseError, LoadedCase, WireModel};
#[cfg(feature = "ecs")]
pub use components::{Extracted, LoadGroup, Tooth, ToothShape, Wire};
pub use dentition::{Dentition, GroupLoad, PlacedTooth};
pub use fdi::{Arch, Fdi, InvalidFdi, Side, ToothKind};
pub use frame::{CentreParameters, ToothFrame};
pub use load::{Load, LoadError};
pub use patient::{LeftOut, MIN_TOOTH_TRIANGLES, OrientationReport, ScanReport};
#[cfg(feature = "ecs")]
pub use plugin::{
    ActiveCase, CaseLoadFailed, CaseLoaded, LoadCase, TeethModelPlugin, TeethModelSystems,
};
pub use shape::ToothResolution;
pub use tooth_shape::{ShapeSet, ToothGeometry};
