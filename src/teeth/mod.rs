//! Teeth: FDI numbers, the anatomy table, procedural tooth meshes, arch forms, patient cases and
//! the [`TeethModelPlugin`] that spawns tooth entities.
//!
//! Engine-free parts (`fdi`, `anatomy`, `shape`, `frame`, `tooth_shape`, `arch`, `case`,
//! `dentition`) need no `World`; `components` and `plugin` are the ECS layer.

pub mod anatomy;
pub mod arch;
pub mod case;
pub mod components;
pub mod dentition;
pub mod fdi;
pub mod frame;
pub mod import;
mod memo;
pub mod plugin;
pub mod shape;
pub mod tooth_shape;

pub use case::{Case, CaseError, LoadedCase, WireModel};
pub use components::{Extracted, Load, LoadGroup, Tooth, ToothShape, Wire};
pub use dentition::{Dentition, PlacedTooth};
pub use fdi::{Arch, Fdi, Side, ToothKind};
pub use plugin::{
    ActiveCase, CaseLoadFailed, CaseLoaded, LoadCase, TeethModelPlugin, TeethModelSystems,
};
pub use shape::ToothResolution;
pub use tooth_shape::{ShapeSet, ToothGeometry};
