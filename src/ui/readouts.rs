//! The panel's **Readouts** section: progress of the simulation, the last step's contacts, IPR
//! totals, and the surface gaps of adjacent teeth as a plot.

use bevy::prelude::*;
use bevy_egui::egui;
use egui_plot::{HLine, Legend, Line, Plot, PlotPoints, Points};

use super::PanelState;
use crate::{
    collision::Contacts,
    movement::{MovementStatus, SimulationState, pair_distances},
    teeth::Tooth,
};

/// What the readouts show.
pub(super) struct Sources<'a, 'w, 's> {
    pub status: &'a MovementStatus,
    pub sim: &'a SimulationState,
    pub contacts: &'a Contacts,
    pub teeth: &'a Query<'w, 's, &'static Tooth>,
}

/// Frame rate, steps, teeth moving, collision time, contacts, IPR, and the gap plot (the gaps are
/// measured at most four times a second, once per step).
pub(super) fn section(ui: &mut egui::Ui, state: &mut PanelState, s: Sources<'_, '_, '_>, dt: f32) {
    ui.heading("Readouts");
    ui.label(format!(
        "{:.0} fps · step {} · {} · {} teeth moving{}",
        1.0 / state.frame.max(1e-6),
        s.status.steps,
        elapsed(s.status.days),
        s.status.moved,
        if s.status.at_rest { " · at rest" } else { "" }
    ));
    ui.label(format!(
        "collision + response: {:.0} µs per step",
        s.status.collision_us
    ));
    let name = |e: Entity| s.teeth.get(e).map_or("?".to_owned(), |t| t.id.to_string());
    egui::CollapsingHeader::new(format!("contacts ({})", s.contacts.list.len()))
        .default_open(false)
        .show(ui, |ui| {
            for c in s.contacts.list.iter().take(40) {
                let what = if c.depth_mm >= 0.0 {
                    format!("depth {:.3} mm", c.depth_mm)
                } else {
                    format!("gap {:.3} mm", -c.depth_mm)
                };
                ui.label(format!(
                    "{}–{}: {what}, t = {:.3}",
                    name(c.a),
                    name(c.b),
                    c.time_of_contact
                ));
            }
        });
    if let Some(sim) = &s.sim.sim
        && !sim.ipr.is_empty()
    {
        let total: f32 = sim.ipr.values().sum();
        ui.label(format!(
            "IPR: {} contacts, {total:.2} mm in all",
            sim.ipr.len()
        ));
    }
    egui::CollapsingHeader::new("surface gaps of adjacent teeth")
        .default_open(true)
        .show(ui, |ui| {
            state.gaps_timer -= dt;
            if let Some(sim) = &s.sim.sim
                && state.gaps_timer <= 0.0
                && state.gaps_at_step != Some(sim.steps)
            {
                state.gaps = pair_distances(sim)
                    .into_iter()
                    .map(|d| (format!("{}-{}", d.a, d.b), d.surface_gap_mm))
                    .collect();
                state.gaps_at_step = Some(sim.steps);
                state.gaps_timer = 0.25;
            }
            gap_plot(ui, &state.gaps);
        });
}

/// Elapsed treatment time as a clinician reads it: days, then weeks past two weeks, then months
/// past two months.
fn elapsed(days: f64) -> String {
    if days >= 61.0 {
        format!("{:.1} months ({days:.0} days)", days / 30.44)
    } else if days >= 14.0 {
        format!("{:.1} weeks ({days:.0} days)", days / 7.0)
    } else if days >= 1.0 {
        format!("{days:.0} days")
    } else {
        format!("{:.1} s", days * 86_400.0)
    }
}

/// The gaps (mm) of the labelled pairs, with the 1 mm line.
fn gap_plot(ui: &mut egui::Ui, gaps: &[(String, f32)]) {
    let points: Vec<[f64; 2]> = gaps
        .iter()
        .enumerate()
        .map(|(i, (_, g))| [i as f64, *g as f64])
        .collect();
    let labels: Vec<String> = gaps.iter().map(|g| g.0.clone()).collect();
    Plot::new("gaps")
        .height(160.0)
        .legend(Legend::default())
        .x_axis_formatter(move |mark, _| {
            let i = mark.value.round();
            if (mark.value - i).abs() < 1e-6 && i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .show(ui, |plot| {
            plot.hline(HLine::new("1 mm", 1.0));
            plot.line(Line::new("gap mm", PlotPoints::from(points.clone())));
            plot.points(Points::new("pairs", PlotPoints::from(points)).radius(2.5));
        });
}
