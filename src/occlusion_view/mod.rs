//! `OcclusionViewPlugin` (feature `viewer`): renders the teeth and drives an orbit camera.
//!
//! It only adds viewing: the simulation plugins run the same with or without it.

mod camera;
pub mod contact_map;
pub mod overlays;
pub mod screenshot;
mod tooth_render;

use bevy::prelude::*;

pub use camera::{CameraPreset, OrbitCamera};
pub use overlays::{Overlay, Overlays, Roots, Selection};
pub use screenshot::{ScreenshotOutcome, ScreenshotPlugin};

/// Renders the arches with lit, tooth-coloured materials and an orbit/pan/zoom camera.
///
/// Mouse: left or right drag orbits, middle drag (or shift + left drag) pans, the wheel zooms.
/// Keys: 1 frontal, 2 right, 3 left, 4 maxillary occlusal, 5 mandibular occlusal.
#[derive(Default)]
pub struct OcclusionViewPlugin {
    /// The camera view at start-up.
    pub initial_view: CameraPreset,
    /// Overlays shown at start-up.
    pub overlays: Overlays,
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
            .add_systems(Startup, camera::spawn_camera_and_lights)
            .add_systems(
                Update,
                (
                    tooth_render::attach_tooth_meshes,
                    tooth_render::hide_extracted,
                    tooth_render::root_style,
                    overlays::arch_visibility,
                    camera::camera_presets,
                    camera::orbit_camera.run_if(crate::ui::pointer_free),
                    overlays::draw_overlays,
                    overlays::draw_circles,
                    overlays::draw_selection,
                    contact_map::update_contact_map,
                )
                    .chain(),
            );
    }
}
