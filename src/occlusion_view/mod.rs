//! `OcclusionViewPlugin` (feature `viewer`): renders the teeth and drives an orbit camera.
//!
//! It only adds viewing: the simulation plugins run the same with or without it. The camera's
//! mouse and key handling runs in [`CameraInputSystems`], so that a UI can keep the camera still
//! while the pointer is over it (the panel does: see `OrthoSimUiPlugin`).

mod camera;
pub mod contact_map;
pub mod overlays;
pub mod screenshot;
mod tooth_render;

use bevy::prelude::*;
use thiserror::Error;

pub use camera::{CameraPreset, OrbitCamera};
pub use overlays::{Overlay, Overlays, Roots, Selection};
pub use screenshot::{ScreenshotOutcome, ScreenshotPlugin};

/// The orbit camera's input handling (mouse drag and wheel), in `Update`: run conditions on
/// this set gate it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CameraInputSystems;

/// A view option that is not one of the names.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum ViewError {
    /// Not a root style.
    #[error("unknown root style '{0}': use solid, translucent or hidden")]
    UnknownRoots(String),
    /// Not an overlay.
    #[error("unknown overlay '{0}': use spheres:LEVEL (0–6), contacts, occlusion-map or circles")]
    UnknownOverlay(String),
}

/// Renders the arches with lit, tooth-coloured materials and an orbit/pan/zoom camera.
///
/// Mouse: left or right drag orbits, middle drag (or shift + left drag) pans, the wheel zooms.
/// Keys: 1 frontal, 2 right, 3 left, 4 maxillary occlusal, 5 mandibular occlusal.
pub struct OcclusionViewPlugin {
    /// The camera view at start-up.
    pub initial_view: CameraPreset,
    /// Overlays shown at start-up.
    pub overlays: Overlays,
    /// Spawn the orbit camera (true by default); an app with its own camera sets false and gets
    /// the lit teeth and overlays only.
    pub orbit_camera: bool,
}

impl Default for OcclusionViewPlugin {
    fn default() -> Self {
        Self {
            initial_view: CameraPreset::default(),
            overlays: Overlays::default(),
            orbit_camera: true,
        }
    }
}

impl Plugin for OcclusionViewPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<tooth_render::ToothRenderAssets>()
            .insert_resource(camera::InitialView(self.initial_view))
            .insert_resource(self.overlays)
            .init_resource::<contact_map::MapState>()
            .init_resource::<Selection>()
            .insert_resource(ClearColor(Color::srgb(0.13, 0.14, 0.17)))
            .insert_resource(GlobalAmbientLight {
                color: Color::WHITE,
                brightness: 300.0,
                affects_lightmapped_meshes: true,
            })
            .add_systems(Startup, camera::spawn_lights)
            .add_systems(
                Update,
                (
                    tooth_render::attach_tooth_meshes,
                    tooth_render::hide_extracted,
                    tooth_render::root_style,
                    overlays::arch_visibility,
                    camera::camera_presets,
                    camera::orbit_camera.in_set(CameraInputSystems),
                    overlays::draw_overlays,
                    overlays::draw_circles,
                    overlays::draw_selection,
                    overlays::draw_appliances,
                    contact_map::update_contact_map,
                )
                    .chain(),
            );
        if self.orbit_camera {
            app.add_systems(Startup, camera::spawn_orbit_camera);
        }
    }
}
