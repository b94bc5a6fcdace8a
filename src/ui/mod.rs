//! The control panel (feature `viewer`, bevy_egui): case, simulation controls, collision settings
//! and live readouts.
//!
//! - **Case**: load a built-in case, reset the current one.
//! - **Simulation**: play / pause, single step, speed (the virtual clock's rate, which drives the
//!   fixed simulation step).
//! - **Collision**: narrow-phase method and response apply at once; a new tree builder or depth
//!   rebuilds the trees in the background and restarts the case.
//! - **Readouts**: steps, teeth moving, frame rate, collision time per step (broad phase to
//!   response), the contacts of the last step, IPR totals, and the surface gap of every adjacent pair
//!   as a plot with the 1 mm line (measured a few times a second, only while the panel shows it).
//!
//! - **View**: show or hide each arch.
//! - **Overlays**: a sphere-tree level of every tooth, the contacts of the step, the occlusal
//!   contact map.
//!
//! Camera input is ignored while the pointer is over the panel (see [`pointer_free`]).

use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPlugin, EguiPrimaryContextPass, egui, input::EguiWantsInput};
use egui_plot::{HLine, Legend, Line, Plot, PlotPoints, Points};

use crate::{
    collision::{CollisionSettings, Contacts, Method},
    movement::{
        MovementSettings, MovementStatus, Response, SimulationState, report::pair_distances,
    },
    sphere_tree::{SphereTreeSettings, TreeMethod},
    teeth::{ActiveCase, Case, LoadCase, Tooth},
};

/// The panel and the simulation controls.
pub struct OrthoSimUiPlugin;

impl Plugin for OrthoSimUiPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<EguiPlugin>() {
            app.add_plugins(EguiPlugin::default());
        }
        app.init_resource::<PanelState>()
            .add_systems(EguiPrimaryContextPass, panel)
            .add_systems(Update, single_step);
    }
}

/// True when egui does not want the pointer (or there is no egui): camera input may be used.
pub fn pointer_free(wants: Option<Res<EguiWantsInput>>) -> bool {
    wants.is_none_or(|w| !w.wants_any_pointer_input())
}

/// Panel state that is not a simulation setting.
#[derive(Resource)]
struct PanelState {
    /// Case chosen in the list.
    case: String,
    /// Simulation speed (× real time).
    speed: f32,
    /// A single step was asked for while paused.
    step: bool,
    /// Tree settings being edited (applied with a button); the current ones at first.
    tree: Option<(TreeMethod, u32)>,
    /// Surface gaps of adjacent pairs, with when they were measured.
    gaps: Vec<(String, f32)>,
    gaps_at_step: Option<u64>,
    gaps_timer: f32,
    /// Smoothed frame time (s).
    frame: f32,
}

impl Default for PanelState {
    fn default() -> Self {
        Self {
            case: "normal".into(),
            speed: 1.0,
            step: false,
            tree: None,
            gaps: Vec::new(),
            gaps_at_step: None,
            gaps_timer: 0.0,
            frame: 1.0 / 60.0,
        }
    }
}

/// Runs one fixed simulation step while paused.
fn single_step(world: &mut World) {
    let asked = world.resource::<PanelState>().step;
    if !asked {
        return;
    }
    world.resource_mut::<PanelState>().step = false;
    world.run_schedule(FixedUpdate);
}

#[allow(clippy::too_many_arguments)]
fn panel(
    mut contexts: EguiContexts,
    mut state: ResMut<PanelState>,
    mut time: ResMut<Time<Virtual>>,
    real: Res<Time<Real>>,
    mut collision: ResMut<CollisionSettings>,
    mut movement: ResMut<MovementSettings>,
    mut trees: ResMut<SphereTreeSettings>,
    status: Res<MovementStatus>,
    sim: Res<SimulationState>,
    contacts: Res<Contacts>,
    case: Option<Res<ActiveCase>>,
    teeth: Query<&Tooth>,
    mut load: MessageWriter<LoadCase>,
    mut overlays: ResMut<crate::occlusion_view::Overlays>,
) -> Result {
    let dt = real.delta_secs();
    if dt > 0.0 {
        state.frame = 0.9 * state.frame + 0.1 * dt;
    }
    let ctx = contexts.ctx_mut()?;
    let current = case.as_ref().map(|c| c.case.case.name.clone());
    egui::Window::new("orthosim")
        .default_pos([10.0, 10.0])
        .default_width(330.0)
        .show(ctx, |ui| {
            ui.heading("Case");
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt("case")
                    .selected_text(state.case.clone())
                    .show_ui(ui, |ui| {
                        for name in Case::builtin_names() {
                            ui.selectable_value(&mut state.case, name.to_owned(), name);
                        }
                    });
                if ui.button("Load").clicked() {
                    load.write(LoadCase(state.case.clone()));
                }
                if let Some(name) = &current
                    && ui.button("Reset").clicked()
                {
                    load.write(LoadCase(name.clone()));
                }
            });
            ui.label(format!(
                "showing: {}",
                current.as_deref().unwrap_or("(loading)")
            ));

            ui.separator();
            ui.heading("Simulation");
            ui.horizontal(|ui| {
                let paused = time.is_paused();
                if ui
                    .button(if paused { "▶ Play" } else { "⏸ Pause" })
                    .clicked()
                {
                    if paused {
                        time.unpause();
                    } else {
                        time.pause();
                    }
                }
                if ui.add_enabled(paused, egui::Button::new("Step")).clicked() {
                    state.step = true;
                }
            });
            let mut speed = state.speed;
            if ui
                .add(
                    egui::Slider::new(&mut speed, 0.1..=8.0)
                        .text("speed ×")
                        .logarithmic(true),
                )
                .changed()
            {
                state.speed = speed;
                time.set_relative_speed(speed);
            }

            ui.separator();
            ui.heading("Collision");
            let mut method = collision.method;
            egui::ComboBox::from_label("algorithm")
                .selected_text(method.name())
                .show_ui(ui, |ui| {
                    for m in Method::ALL {
                        ui.selectable_value(&mut method, m, m.name());
                    }
                });
            if method != collision.method {
                collision.method = method;
            }
            let mut response = movement.response;
            egui::ComboBox::from_label("response")
                .selected_text(response.name())
                .show_ui(ui, |ui| {
                    for r in [Response::Block, Response::Impulse, Response::Ipr] {
                        ui.selectable_value(&mut response, r, r.name());
                    }
                });
            if response != movement.response {
                movement.response = response;
            }
            let mut chosen = state.tree.unwrap_or((trees.method, trees.depth));
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt("tree")
                    .selected_text(format!("{:?}", chosen.0))
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut chosen.0, TreeMethod::Octree, "Octree");
                        ui.selectable_value(&mut chosen.0, TreeMethod::Medial, "Medial");
                    });
                ui.add(egui::Slider::new(&mut chosen.1, 2..=6).text("tree depth"));
            });
            state.tree = Some(chosen);
            if chosen != (trees.method, trees.depth) && ui.button("Rebuild trees").clicked() {
                trees.method = chosen.0;
                trees.depth = chosen.1;
                if let Some(name) = &current {
                    load.write(LoadCase(name.clone()));
                }
            }

            ui.separator();
            ui.heading("View");
            ui.horizontal(|ui| {
                let mut upper = !overlays.hide_upper;
                if ui.checkbox(&mut upper, "upper arch").changed() {
                    overlays.hide_upper = !upper;
                }
                let mut lower = !overlays.hide_lower;
                if ui.checkbox(&mut lower, "lower arch").changed() {
                    overlays.hide_lower = !lower;
                }
            });
            ui.horizontal(|ui| {
                let mut level = overlays.sphere_level;
                egui::ComboBox::from_label("sphere level")
                    .selected_text(level.map_or("off".to_owned(), |l| l.to_string()))
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut level, None, "off");
                        for l in 0..trees.depth {
                            ui.selectable_value(&mut level, Some(l), l.to_string());
                        }
                    });
                if level != overlays.sphere_level {
                    overlays.sphere_level = level;
                }
            });
            ui.horizontal(|ui| {
                let mut show_contacts = overlays.contacts;
                if ui.checkbox(&mut show_contacts, "contacts").changed() {
                    overlays.contacts = show_contacts;
                }
                let mut map = overlays.occlusion_map;
                if ui
                    .checkbox(&mut map, "occlusion map (red 0 → blue 0.5 mm)")
                    .changed()
                {
                    overlays.occlusion_map = map;
                }
            });

            ui.separator();
            ui.heading("Readouts");
            ui.label(format!(
                "{:.0} fps · step {} · {} teeth moving{}",
                1.0 / state.frame.max(1e-6),
                status.steps,
                status.moved,
                if status.at_rest { " · at rest" } else { "" }
            ));
            ui.label(format!(
                "collision + response: {:.0} µs per step",
                status.collision_us
            ));
            let name = |e: Entity| teeth.get(e).map_or("?".to_owned(), |t| t.id.to_string());
            egui::CollapsingHeader::new(format!("contacts ({})", contacts.list.len()))
                .default_open(false)
                .show(ui, |ui| {
                    for c in contacts.list.iter().take(40) {
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
            if let Some(s) = &sim.sim
                && !s.ipr.is_empty()
            {
                let total: f32 = s.ipr.values().sum();
                ui.label(format!(
                    "IPR: {} contacts, {total:.2} mm in all",
                    s.ipr.len()
                ));
            }
            egui::CollapsingHeader::new("surface gaps of adjacent teeth")
                .default_open(true)
                .show(ui, |ui| {
                    state.gaps_timer -= dt;
                    if let Some(s) = &sim.sim
                        && state.gaps_timer <= 0.0
                        && state.gaps_at_step != Some(s.steps)
                    {
                        state.gaps = pair_distances(s)
                            .into_iter()
                            .map(|d| (format!("{}-{}", d.a, d.b), d.surface_gap_mm))
                            .collect();
                        state.gaps_at_step = Some(s.steps);
                        state.gaps_timer = 0.25;
                    }
                    let points: Vec<[f64; 2]> = state
                        .gaps
                        .iter()
                        .enumerate()
                        .map(|(i, (_, g))| [i as f64, *g as f64])
                        .collect();
                    let labels: Vec<String> = state.gaps.iter().map(|g| g.0.clone()).collect();
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
                });
        });
    Ok(())
}
