//! The **Help** window: the viewer's mouse and keyboard controls and what each window does. F1 or
//! "?" opens and closes it (while no text field has the keyboard), as does the panel's "?" button.

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

/// Whether the help window is open.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HelpOpen(pub bool);

/// The controls, as (what you do, what it does).
pub const CONTROLS: [(&str, &str); 12] = [
    ("left or right drag", "orbit the camera about the teeth"),
    ("middle drag, or shift + left drag", "pan"),
    ("scroll", "zoom"),
    (
        "1 2 3 4 5",
        "frontal, right, left, upper occlusal and lower occlusal views",
    ),
    (
        "click a tooth",
        "select it (the Teeth and loads window acts on the selection)",
    ),
    (
        "shift + click a tooth",
        "add it to the selection or take it out",
    ),
    (
        "the FDI chart",
        "select teeth by number; extracted teeth are struck through",
    ),
    (
        "Plan, edit target: drag an arrow",
        "move the selected tooth along that axis",
    ),
    (
        "Plan, edit target: drag a ring",
        "turn the selected tooth about that axis",
    ),
    ("hover a control", "what it does"),
    ("F1 or ?", "this help"),
    ("Esc", "close this help"),
];

/// The windows, as (name, what it is for).
const WINDOWS: [(&str, &str); 4] = [
    (
        "orthosim",
        "load a case, run the clock, choose the collision method, response and movement model, the overlays and roots; readouts",
    ),
    (
        "Teeth and loads",
        "select teeth; loads along their own axes; wires, brackets, chains, coils and elastics; extract and restore",
    ),
    (
        "Bite",
        "settle the bite about the condyles; protrusion and lateral excursions with guidance and interferences",
    ),
    (
        "Plan",
        "a staged treatment plan: limits, anchorage, stages, IPR; edit the target with handles",
    ),
];

/// Opens and closes the window on F1 or "?", and shows it.
pub(super) fn help_window(
    mut contexts: EguiContexts,
    keys: Option<Res<ButtonInput<KeyCode>>>,
    mut open: ResMut<HelpOpen>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    let typing = ctx.egui_wants_keyboard_input();
    let question = ctx.input(|i| {
        i.events
            .iter()
            .any(|e| matches!(e, egui::Event::Text(t) if t == "?"))
    });
    let pressed = |k| keys.as_ref().is_some_and(|keys| keys.just_pressed(k));
    if !typing && (pressed(KeyCode::F1) || question) {
        open.0 = !open.0;
    }
    if open.0 && pressed(KeyCode::Escape) {
        open.0 = false;
    }
    let mut shown = open.0;
    egui::Window::new("Help")
        .open(&mut shown)
        .collapsible(false)
        .default_width(460.0)
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| {
            egui::Grid::new("help controls")
                .num_columns(2)
                .striped(true)
                .show(ui, |ui| {
                    for (what, does) in CONTROLS {
                        ui.strong(what);
                        ui.label(does);
                        ui.end_row();
                    }
                });
            ui.separator();
            for (name, what) in WINDOWS {
                ui.horizontal_wrapped(|ui| {
                    ui.strong(name);
                    ui.label(what);
                });
            }
            ui.separator();
            ui.label("The guide: docs/ in the repository (docs/getting-started.md first).");
        });
    open.0 &= shown;
    Ok(())
}
