//! The panel's **Simulation** section: play, pause, single step, speed.

use bevy::prelude::*;
use bevy_egui::egui;

use super::PanelState;

/// Play / pause the virtual clock, ask for a single step while paused, set the speed.
pub(super) fn section(ui: &mut egui::Ui, state: &mut PanelState, time: &mut Time<Virtual>) {
    ui.heading("Simulation");
    ui.horizontal(|ui| {
        let paused = time.is_paused();
        if ui
            .button(if paused { "▶ Play" } else { "⏸ Pause" })
            .on_hover_text("run or hold the simulation clock")
            .clicked()
        {
            if paused {
                time.unpause();
            } else {
                time.pause();
            }
        }
        if ui
            .add_enabled(paused, egui::Button::new("Step"))
            .on_hover_text("one simulation step while paused")
            .clicked()
        {
            state.step = true;
        }
    });
    let mut speed = state.speed;
    if ui
        .add(
            egui::Slider::new(&mut speed, 0.1..=30.0)
                .text("speed ×")
                .logarithmic(true),
        )
        .on_hover_text(format!(
            "Clock speed. Under the ligament model, 1× runs about {:.0} clinical days a second; 30× about seven months a second.",
            super::DAYS_PER_SECOND
        ))
        .changed()
    {
        state.speed = speed;
        time.set_relative_speed(speed);
    }
}
