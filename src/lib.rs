//! # orthosim
//!
//! An interactive 3D simulator for orthodontic training and treatment planning: load a patient's
//! two dental arches, extract teeth, apply loads through an archwire, and watch teeth move and
//! touch, with exact contacts and distances.
//!
//! The engine-free core (`geometry`, the non-ECS parts of `teeth`, `analysis`) is plain Rust on
//! glam types. Each plugin is a thin ECS layer over it.
//!
//! | plugin | module | what it adds |
//! |---|---|---|
//! | [`teeth::TeethModelPlugin`] | [`teeth`] | patient cases, tooth entities with shared shapes |
//! | `OcclusionViewPlugin` (feature `viewer`) | `occlusion_view` | rendering, orbit camera |
//!
//! [`sphere_tree`] holds the sphere-tree data structure, its coverage check, `.sph` I/O, the octree
//! builder and fit metrics (engine-free; its plugin comes with the sphere-tree work).
//!
//! [`OrthoSimPlugins`] adds every simulation plugin; the viewer is added separately so the
//! simulation runs the same with or without a window.

pub mod analysis;
pub mod geometry;
#[cfg(feature = "viewer")]
pub mod occlusion_view;
pub mod sphere_tree;
pub mod teeth;

use bevy::{app::PluginGroupBuilder, prelude::*};

/// Every simulation plugin of orthosim (headless-safe).
///
/// | plugin | role |
/// |---|---|
/// | [`teeth::TeethModelPlugin`] | loads cases, spawns teeth |
///
/// Swap one out with `OrthoSimPlugins.build().disable::<…>()`.
pub struct OrthoSimPlugins;

impl PluginGroup for OrthoSimPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>().add(teeth::TeethModelPlugin::default())
    }
}

/// The most used types.
pub mod prelude {
    pub use crate::{
        OrthoSimPlugins,
        geometry::{Pose, TriMesh},
        teeth::{
            ActiveCase, Arch, Case, CaseLoaded, Extracted, Fdi, Load, LoadCase, TeethModelPlugin,
            Tooth, ToothKind, ToothShape,
        },
    };
}
