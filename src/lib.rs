//! # orthosim
//!
//! An interactive 3D simulator for orthodontic training and treatment planning: load a patient's
//! two dental arches, extract teeth, apply loads through an archwire, and watch teeth move and
//! touch, with exact contacts and distances.
//!
//! The engine-free core (`geometry`, the non-ECS parts of `teeth`, `sphere_tree` and `collision`,
//! `analysis`) is plain Rust on
//! glam types. Each plugin is a thin ECS layer over it.
//!
//! | plugin | module | what it adds |
//! |---|---|---|
//! | [`teeth::TeethModelPlugin`] | [`teeth`] | patient cases, tooth entities with shared shapes |
//! | [`sphere_tree::SphereTreePlugin`] | [`sphere_tree`] | sphere trees per tooth shape, built in the background |
//! | [`collision::CollisionPlugin`] | [`collision`] | broad and narrow phases, contacts of moving teeth |
//! | [`movement::MovementPlugin`] | [`movement`] | loads, wire models, motion per step, block / impulse / IPR responses |
//! | `OcclusionViewPlugin` (feature `viewer`) | `occlusion_view` | rendering, orbit camera |
//! | `OrthoSimUiPlugin` (feature `viewer`) | `ui` | the egui control panel and readouts |

//!
//! [`OrthoSimPlugins`] adds every simulation plugin; the viewer is added separately so the
//! simulation runs the same with or without a window.

pub mod analysis;
pub mod collision;
pub mod geometry;
pub mod movement;
#[cfg(feature = "viewer")]
pub mod occlusion_view;
pub mod parallel;
pub mod sphere_tree;
pub mod teeth;
#[cfg(feature = "viewer")]
pub mod ui;

use bevy::{app::PluginGroupBuilder, prelude::*};

/// Every simulation plugin of orthosim (headless-safe).
///
/// | plugin | role |
/// |---|---|
/// | [`teeth::TeethModelPlugin`] | loads cases, spawns teeth |
/// | [`sphere_tree::SphereTreePlugin`] | builds each tooth shape's sphere tree in the background |
/// | [`collision::CollisionPlugin`] | finds the contacts of moving teeth each simulation step |
/// | [`movement::MovementPlugin`] | moves loaded teeth, responds to contacts, passes loads on |
///
/// Swap one out with `OrthoSimPlugins.build().disable::<…>()`.
pub struct OrthoSimPlugins;

impl PluginGroup for OrthoSimPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(teeth::TeethModelPlugin::default())
            .add(sphere_tree::SphereTreePlugin)
            .add(collision::CollisionPlugin::default())
            .add(movement::MovementPlugin::default())
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
