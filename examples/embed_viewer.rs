//! orthosim's rendering inside another Bevy app that brings its own camera and its own UI: the app
//! adds `OrthoSimPlugins` and `OcclusionViewPlugin` (without its orbit camera, and without
//! orthosim's panel), turns its own camera slowly around the arches, and shows the simulation's
//! progress in a window of its own.
//!
//! ```sh
//! cargo run --release --example embed_viewer            # case 2 in a window
//! cargo run --release --example embed_viewer -- out.png # or a screenshot after 120 frames
//! ```

use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPlugin, EguiPrimaryContextPass, egui};
use orthosim::{
    occlusion_view::{OcclusionViewPlugin, ScreenshotOutcome, ScreenshotPlugin},
    prelude::*,
};

fn main() -> AppExit {
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: "my clinic app".into(),
            ..default()
        }),
        ..default()
    }))
    .add_plugins(OrthoSimPlugins::default().set(TeethModelPlugin {
        initial_case: Some("case2".into()),
    }))
    // The teeth, lights and overlays; this app's own camera instead of the orbit camera.
    .add_plugins(OcclusionViewPlugin {
        orbit_camera: false,
        overlays: Overlays {
            contacts: true,
            ..default()
        },
        ..default()
    })
    .add_plugins(EguiPlugin::default())
    .add_systems(Startup, spawn_turntable_camera)
    .add_systems(Update, turn_camera)
    .add_systems(EguiPrimaryContextPass, status_window);
    if let Some(path) = std::env::args().nth(1) {
        app.add_plugins(ScreenshotPlugin {
            path: path.into(),
            frames: 120,
            outcome: Arc::new(Mutex::new(ScreenshotOutcome::default())),
        });
    }
    app.run()
}

/// The app's own camera: on a circle around the arches, looking at their centre.
#[derive(Component)]
struct Turntable {
    angle: f32,
}

fn spawn_turntable_camera(mut commands: Commands) {
    commands.spawn((
        Camera3d::default(),
        Turntable { angle: 0.3 },
        Transform::default(),
    ));
}

fn turn_camera(time: Res<Time>, mut cameras: Query<(&mut Turntable, &mut Transform)>) {
    for (mut turntable, mut transform) in &mut cameras {
        turntable.angle += 0.2 * time.delta_secs();
        let eye = Vec3::new(
            80.0 * turntable.angle.sin(),
            25.0,
            80.0 * turntable.angle.cos(),
        );
        *transform = Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y);
    }
}

/// The app's own status window: steps, teeth moving, the last step's contacts.
fn status_window(
    mut contexts: EguiContexts,
    status: Res<MovementStatus>,
    contacts: Res<Contacts>,
    progress: Res<SphereTreeProgress>,
) -> Result {
    egui::Window::new("treatment preview").show(contexts.ctx_mut()?, |ui| {
        if progress.busy() {
            ui.label(format!(
                "preparing the teeth: {} of {} shapes",
                progress.built,
                progress.built + progress.pending
            ));
        }
        ui.label(format!(
            "step {}, {} teeth moving{}",
            status.steps,
            status.moved,
            if status.at_rest { ", at rest" } else { "" }
        ));
        ui.label(format!("{} contacts in the last step", contacts.list.len()));
    });
    Ok(())
}
