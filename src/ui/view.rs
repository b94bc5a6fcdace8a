//! The panel's **View** section: arches shown, roots, overlays.

use bevy::prelude::*;
use bevy_egui::egui;

use crate::{
    collision::Method,
    occlusion_view::{Overlays, Roots},
};

/// Which arch is shown, how roots are drawn, and the overlays (a sphere-tree level up to
/// `depth`, contacts, the occlusion map, bounding circles while `method` is circles). Overlays
/// are marked changed only when edited.
pub(super) fn section(
    ui: &mut egui::Ui,
    overlays: &mut ResMut<Overlays>,
    depth: u32,
    method: Method,
) {
    ui.heading("View");
    ui.horizontal(|ui| {
        let mut upper = !overlays.hide_upper;
        if ui
            .checkbox(&mut upper, "upper arch")
            .on_hover_text("show or hide the upper teeth")
            .changed()
        {
            overlays.hide_upper = !upper;
        }
        let mut lower = !overlays.hide_lower;
        if ui
            .checkbox(&mut lower, "lower arch")
            .on_hover_text("show or hide the lower teeth")
            .changed()
        {
            overlays.hide_lower = !lower;
        }
    });
    ui.horizontal(|ui| {
        let mut level = overlays.sphere_level;
        egui::ComboBox::from_label("sphere level")
            .selected_text(level.map_or("off".to_owned(), |l| l.to_string()))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut level, None, "off");
                for l in 0..depth {
                    ui.selectable_value(&mut level, Some(l), l.to_string());
                }
            })
            .response
            .on_hover_text("draw one level of every tooth's sphere tree (0: the root sphere)");
        if level != overlays.sphere_level {
            overlays.sphere_level = level;
        }
    });
    ui.horizontal(|ui| {
        let mut show_contacts = overlays.contacts;
        if ui
            .checkbox(&mut show_contacts, "contacts")
            .on_hover_text(
                "the step's contacts: overlapping leaf spheres orange, contact points red",
            )
            .changed()
        {
            overlays.contacts = show_contacts;
        }
        let mut map = overlays.occlusion_map;
        if ui
            .checkbox(&mut map, "occlusion map (red 0 to blue 0.5 mm)")
            .on_hover_text("each tooth surface coloured by its exact distance to the opposing arch")
            .changed()
        {
            overlays.occlusion_map = map;
        }
    });
    ui.horizontal(|ui| {
        let mut roots = overlays.roots;
        egui::ComboBox::from_label("roots")
            .selected_text(roots.name())
            .show_ui(ui, |ui| {
                for r in Roots::ALL {
                    ui.selectable_value(&mut roots, r, r.name());
                }
            })
            .response
            .on_hover_text("how the roots are drawn: translucent, solid or hidden");
        if roots != overlays.roots {
            overlays.roots = roots;
        }
        let mut circles = overlays.circles;
        if ui
            .add_enabled(
                method == Method::Circles,
                egui::Checkbox::new(&mut circles, "bounding circles"),
            )
            .on_hover_text("the paper's bounding circles at crown height, red where two meet")
            .on_disabled_hover_text("drawn while the circles algorithm is active")
            .changed()
        {
            overlays.circles = circles;
        }
    });
}
