//! The panel's **Case** section: built-in cases, case files, reset.

use bevy::prelude::*;
use bevy_egui::egui;

use super::PanelState;
use crate::teeth::{Case, LoadCase};

/// Load a built-in case or a case file (the last load error shown), reset the current case.
pub(super) fn section(
    ui: &mut egui::Ui,
    state: &mut PanelState,
    current: Option<&str>,
    load: &mut MessageWriter<LoadCase>,
) {
    ui.heading("Case");
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("case")
            .selected_text(state.case.clone())
            .show_ui(ui, |ui| {
                for name in Case::builtin_names() {
                    ui.selectable_value(&mut state.case, name.to_owned(), name);
                }
            })
            .response
            .on_hover_text("a built-in case (orthosim cases lists them)");
        if ui
            .button("Load")
            .on_hover_text("load the chosen built-in case")
            .clicked()
        {
            load.write(LoadCase(state.case.clone()));
        }
        if let Some(name) = current
            && ui
                .button("Reset")
                .on_hover_text("load the current case again, its teeth where the case puts them")
                .clicked()
        {
            load.write(LoadCase(name.to_owned()));
        }
    });
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut state.file)
                .hint_text("case file (.ron)")
                .desired_width(200.0),
        )
        .on_hover_text("the path of a case file (RON); see docs/cases.md");
        let path = state.file.trim().to_owned();
        if ui
            .add_enabled(!path.is_empty(), egui::Button::new("Load file"))
            .on_hover_text("load the case file typed beside; an error shows below")
            .clicked()
        {
            load.write(LoadCase(path));
        }
    });
    ui.label(format!("showing: {}", current.unwrap_or("(loading)")));
    if let Some(e) = &state.load_error {
        ui.colored_label(egui::Color32::LIGHT_RED, e);
    }
}
