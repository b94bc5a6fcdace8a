//! The panel's **Collision** section: method, response, tree builder and depth, build progress.

use bevy::prelude::*;
use bevy_egui::egui;

use super::PanelState;
use crate::{
    collision::{CollisionSettings, Method},
    movement::{MovementModel, MovementSettings, Response},
    occlusion_view::Overlays,
    sphere_tree::{SphereTreeProgress, SphereTreeSettings, TreeMethod},
    teeth::LoadCase,
};

/// The settings this section edits (as `ResMut`, so only a real edit marks one changed: a
/// changed [`SphereTreeSettings`] rebuilds every tree).
pub(super) struct Settings<'a, 'w> {
    pub state: &'a mut PanelState,
    pub collision: &'a mut ResMut<'w, CollisionSettings>,
    pub movement: &'a mut ResMut<'w, MovementSettings>,
    pub trees: &'a mut ResMut<'w, SphereTreeSettings>,
    pub overlays: &'a mut ResMut<'w, Overlays>,
}

/// Method and response apply at once; a new builder or depth rebuilds the trees (restarting the
/// case) when asked.
pub(super) fn section(
    ui: &mut egui::Ui,
    s: Settings<'_, '_>,
    progress: &SphereTreeProgress,
    current: Option<&str>,
    load: &mut MessageWriter<LoadCase>,
) {
    ui.heading("Collision");
    let mut method = s.collision.method;
    egui::ComboBox::from_label("algorithm")
        .selected_text(method.name())
        .show_ui(ui, |ui| {
            for m in Method::ALL {
                ui.selectable_value(&mut method, m, m.name());
            }
        })
        .response
        .on_hover_text(
            "circles: the paper's bounding circles; spheres: sphere trees at the end pose; continuous: swept sphere trees over the step; exact: the triangle meshes, gaps within 0.01 mm",
        );
    if method != s.collision.method {
        s.collision.method = method;
        if method == Method::Circles {
            s.overlays.circles = true;
        }
    }
    let mut response = s.movement.response;
    egui::ComboBox::from_label("response")
        .selected_text(response.name())
        .show_ui(ui, |ui| {
            for r in Response::ALL {
                ui.selectable_value(&mut response, r, r.name());
            }
        })
        .response
        .on_hover_text(
            "what a contact does: block stops the teeth at contact; impulse bounces them; ipr lets them pass, counting the enamel removed",
        );
    if response != s.movement.response {
        s.movement.response = response;
    }
    let mut model = s.movement.model;
    egui::ComboBox::from_label("movement model")
        .selected_text(model.name())
        .show_ui(ui, |ui| {
            for m in MovementModel::ALL {
                ui.selectable_value(&mut model, m, m.name());
            }
        })
        .response
        .on_hover_text(
            "pdl: the periodontal ligament moves the teeth in clinical time; paper: the source paper's wire models",
        );
    if model != s.movement.model {
        s.movement.model = model;
    }
    let mut chosen = s.state.tree.unwrap_or((s.trees.method, s.trees.depth));
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("tree")
            .selected_text(format!("{:?}", chosen.0))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut chosen.0, TreeMethod::Octree, "Octree");
                ui.selectable_value(&mut chosen.0, TreeMethod::Medial, "Medial");
            })
            .response
            .on_hover_text("the sphere-tree builder: medial fits tighter, octree builds faster");
        ui.add(egui::Slider::new(&mut chosen.1, 2..=6).text("tree depth"))
            .on_hover_text("levels of the sphere trees, the root included");
    });
    s.state.tree = Some(chosen);
    if chosen != (s.trees.method, s.trees.depth)
        && ui
            .button("Rebuild trees")
            .on_hover_text("build the trees chosen above and restart the case")
            .clicked()
    {
        s.trees.method = chosen.0;
        s.trees.depth = chosen.1;
        if let Some(name) = current {
            load.write(LoadCase(name.to_owned()));
        }
    }
    if progress.busy() {
        ui.add(
            egui::ProgressBar::new(progress.fraction())
                .text(format!(
                    "building sphere trees: {} of {} tooth shapes",
                    progress.built,
                    progress.built + progress.pending + progress.failed
                ))
                .animate(true),
        );
    }
    if progress.failed > 0 {
        ui.colored_label(
            egui::Color32::LIGHT_RED,
            format!(
                "{} tree(s) could not be built (see the log)",
                progress.failed
            ),
        );
    }
}
