//! The control panel (feature `viewer`, bevy_egui): case, simulation controls, collision settings
//! and live readouts.
//!
//! - **Case**: load a built-in case or a case file (the error shown if it fails), reset the
//!   current one.
//! - **Simulation**: play / pause, single step, speed (the virtual clock's rate, which drives the
//!   fixed simulation step).
//! - **Collision**: narrow-phase method and response apply at once; a new tree builder or depth
//!   rebuilds the trees in the background and restarts the case.
//! - **Readouts**: steps, teeth moving, frame rate, collision time per step (broad phase to
//!   response), the contacts of the last step, IPR totals, and the surface gap of every adjacent pair
//!   as a plot with the 1 mm line (measured a few times a second, only while the panel shows it).
//!
//! - **Teeth and loads**: select teeth by clicking them (shift-click for a group) or from an FDI
//!   chart, and set a force or torque on them with presets along each tooth's mesial, buccal and
//!   occlusal axes (mesial/distal, buccal/lingual, extrusion/intrusion, tipping, rotation, torque).
//!   The selected teeth can also get a round or rectangular wire, or be extracted and restored
//!   while the case runs (a restore is refused, with the reason shown, when a tooth has moved into
//!   the place).
//! - **View**: show or hide each arch; roots translucent, solid or hidden.
//! - **Overlays**: a sphere-tree level of every tooth, the contacts of the step, the occlusal
//!   contact map, the bounding circles while the circles algorithm is active.
//! - Tree builds in the background show a progress bar.
//!
//! Camera input is ignored while the pointer is over the panel (see [`pointer_free`]).

use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPlugin, EguiPrimaryContextPass, egui, input::EguiWantsInput};
use egui_plot::{HLine, Legend, Line, Plot, PlotPoints, Points};

use crate::{
    collision::{CollisionSettings, Contacts, Method},
    movement::{
        MovementSettings, MovementStatus, Response, SetExtracted, SetLoad, SetWire,
        SimulationState, report::pair_distances,
    },
    occlusion_view::{Roots, Selection},
    sphere_tree::{SphereTreeProgress, SphereTreeSettings, TreeMethod},
    teeth::{ActiveCase, Case, CaseLoadFailed, CaseLoaded, LoadCase, Tooth},
    teeth::{Extracted, Load, Wire, WireModel},
};

/// The panel and the simulation controls.
pub struct OrthoSimUiPlugin;

impl Plugin for OrthoSimUiPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<EguiPlugin>() {
            app.add_plugins(EguiPlugin::default());
        }
        if !app.is_plugin_added::<bevy::picking::mesh_picking::MeshPickingPlugin>() {
            app.add_plugins(bevy::picking::mesh_picking::MeshPickingPlugin);
        }
        app.init_resource::<PanelState>()
            .init_resource::<LoadEditor>()
            .add_observer(click_tooth)
            .add_systems(EguiPrimaryContextPass, (panel, loads_panel))
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
    /// Case file path typed in the panel.
    file: String,
    /// The last case that failed to load, and why.
    load_error: Option<String>,
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
            file: String::new(),
            load_error: None,
        }
    }
}

/// Selects a tooth by clicking it (shift-click adds or removes it).
fn click_tooth(
    click: On<Pointer<Click>>,
    teeth: Query<(), With<Tooth>>,
    keys: Option<Res<ButtonInput<KeyCode>>>,
    mut selection: ResMut<Selection>,
) {
    if click.event.button != PointerButton::Primary || !teeth.contains(click.entity) {
        return;
    }
    let add = keys.is_some_and(|k| k.pressed(KeyCode::ShiftLeft) || k.pressed(KeyCode::ShiftRight));
    selection.pick(click.entity, add);
}

/// An axis of a tooth (0 mesial, 1 buccal, 2 occlusal) and a sign.
type AxisSign = (usize, f32);

/// The load being composed for the selection.
#[derive(Resource)]
struct LoadEditor {
    force_n: f32,
    torque_nmm: f32,
}

impl Default for LoadEditor {
    fn default() -> Self {
        Self {
            force_n: 1.5,
            torque_nmm: 15.0,
        }
    }
}

/// The teeth as the loads panel reads them.
type PanelTeeth<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Tooth,
        &'static Transform,
        &'static Load,
        Has<Extracted>,
        Option<&'static Wire>,
    ),
>;

/// What the loads panel asks of the simulation.
#[derive(bevy::ecs::system::SystemParam)]
struct ToothEdits<'w> {
    load: MessageWriter<'w, SetLoad>,
    wire: MessageWriter<'w, SetWire>,
    extracted: MessageWriter<'w, SetExtracted>,
}

/// Selection (FDI chart) and loads on the selected teeth, with presets along each tooth's own
/// mesial, buccal and occlusal axes.
fn loads_panel(
    mut contexts: EguiContexts,
    mut editor: ResMut<LoadEditor>,
    mut selection: ResMut<Selection>,
    teeth: PanelTeeth,
    sim: Res<SimulationState>,
    mut edits: ToothEdits,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    egui::Window::new("Teeth and loads")
        .default_pos([ctx.viewport_rect().width() - 350.0, 10.0])
        .default_width(330.0)
        .show(ctx, |ui| {
            ui.label("Click a tooth (shift-click for a group) or use the chart:");
            let find = |n: u8| teeth.iter().find(|t| t.1.id.number() == n);
            for row in [
                [
                    18u8, 17, 16, 15, 14, 13, 12, 11, 21, 22, 23, 24, 25, 26, 27, 28,
                ],
                [
                    48, 47, 46, 45, 44, 43, 42, 41, 31, 32, 33, 34, 35, 36, 37, 38,
                ],
            ] {
                ui.horizontal_wrapped(|ui| {
                    ui.spacing_mut().item_spacing.x = 2.0;
                    for n in row {
                        let Some((e, _, _, _, extracted, _)) = find(n) else {
                            ui.add_enabled(false, egui::Button::new(n.to_string()).small());
                            continue;
                        };
                        let on = selection.0.contains(&e);
                        let mut label = egui::RichText::new(n.to_string());
                        if extracted {
                            label = label.strikethrough().weak();
                        }
                        let b = ui
                            .add(egui::Button::new(label).small().selected(on))
                            .on_hover_text(if extracted { "extracted" } else { "" });
                        if b.clicked() {
                            selection.pick(e, true);
                        }
                    }
                });
            }
            let names: Vec<String> = selection
                .0
                .iter()
                .filter_map(|e| teeth.get(*e).ok().map(|t| t.1.id.to_string()))
                .collect();
            ui.label(format!(
                "selected: {}",
                if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(" ")
                }
            ));
            ui.add(egui::Slider::new(&mut editor.force_n, 0.0..=5.0).text("force N"));
            ui.add(egui::Slider::new(&mut editor.torque_nmm, 0.0..=50.0).text("torque N·mm"));
            // (label, force axis and sign, torque axis and sign): 0 mesial, 1 buccal, 2 occlusal.
            let presets: [(&str, Option<AxisSign>, Option<AxisSign>); 9] = [
                ("mesial", Some((0, 1.0)), None),
                ("distal", Some((0, -1.0)), None),
                ("buccal", Some((1, 1.0)), None),
                ("lingual", Some((1, -1.0)), None),
                ("extrusion", Some((2, 1.0)), None),
                ("intrusion", Some((2, -1.0)), None),
                ("tip (crown mesial)", None, Some((1, 1.0))),
                ("rotate", None, Some((2, 1.0))),
                ("torque", None, Some((0, 1.0))),
            ];
            let mut chosen = None;
            ui.horizontal_wrapped(|ui| {
                for (label, f, t) in presets {
                    if ui
                        .add_enabled(!selection.0.is_empty(), egui::Button::new(label))
                        .clicked()
                    {
                        chosen = Some((f, t));
                    }
                }
                if ui
                    .add_enabled(!selection.0.is_empty(), egui::Button::new("clear"))
                    .clicked()
                {
                    chosen = Some((None, None));
                }
            });
            if let Some((f, t)) = chosen {
                for e in &selection.0 {
                    let Ok((_, tooth, tf, current, _, _)) = teeth.get(*e) else {
                        continue;
                    };
                    let axes = [
                        tf.rotation * (Vec3::X * tooth.id.local_x_mesial_sign()),
                        tf.rotation * Vec3::Z,
                        tf.rotation * Vec3::Y,
                    ];
                    let mut load = if f.is_none() && t.is_none() {
                        Load::default()
                    } else {
                        *current
                    };
                    if let Some((k, sign)) = f {
                        load.force = axes[k] * sign * editor.force_n;
                    }
                    if let Some((k, sign)) = t {
                        load.torque = axes[k] * sign * editor.torque_nmm;
                    }
                    edits.load.write(SetLoad { tooth: *e, load });
                }
            }
            ui.horizontal_wrapped(|ui| {
                let any = !selection.0.is_empty();
                for (label, wire) in [
                    ("round wire", WireModel::Round),
                    ("rectangular wire", WireModel::Rectangular),
                ] {
                    if ui.add_enabled(any, egui::Button::new(label)).clicked() {
                        for e in &selection.0 {
                            edits.wire.write(SetWire { tooth: *e, wire });
                        }
                    }
                }
                for (label, extracted) in [("extract", true), ("restore", false)] {
                    if ui.add_enabled(any, egui::Button::new(label)).clicked() {
                        for e in &selection.0 {
                            edits.extracted.write(SetExtracted {
                                tooth: *e,
                                extracted,
                            });
                        }
                    }
                }
            });
            if let Some(notice) = &sim.notice {
                ui.colored_label(egui::Color32::LIGHT_RED, notice);
            }
            for e in &selection.0 {
                if let Ok((_, tooth, _, l, extracted, wire)) = teeth.get(*e) {
                    if extracted {
                        ui.label(format!("{}: extracted", tooth.id));
                        continue;
                    }
                    let wire = match wire.map(|w| w.0) {
                        Some(WireModel::Round) => "round",
                        _ => "rectangular",
                    };
                    ui.label(format!(
                        "{}: force {:.2} N, torque {:.1} N·mm, {wire} wire",
                        tooth.id,
                        l.force.length(),
                        l.torque.length()
                    ));
                }
            }
        });
    Ok(())
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
    progress: Res<SphereTreeProgress>,
    (mut failed, mut loaded): (MessageReader<CaseLoadFailed>, MessageReader<CaseLoaded>),
) -> Result {
    if let Some(e) = failed.read().last() {
        state.load_error = Some(e.0.to_string());
    }
    if loaded.read().last().is_some() {
        state.load_error = None;
    }
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
            ui.horizontal(|ui| {
                ui.add(
                    egui::TextEdit::singleline(&mut state.file)
                        .hint_text("case file (.ron)")
                        .desired_width(200.0),
                );
                let path = state.file.trim().to_owned();
                if ui
                    .add_enabled(!path.is_empty(), egui::Button::new("Load file"))
                    .clicked()
                {
                    load.write(LoadCase(path));
                }
            });
            ui.label(format!(
                "showing: {}",
                current.as_deref().unwrap_or("(loading)")
            ));
            if let Some(e) = &state.load_error {
                ui.colored_label(egui::Color32::LIGHT_RED, e);
            }

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
                if method == Method::Circles {
                    overlays.circles = true;
                }
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
                    .checkbox(&mut map, "occlusion map (red 0 to blue 0.5 mm)")
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
                    });
                if roots != overlays.roots {
                    overlays.roots = roots;
                }
                let mut circles = overlays.circles;
                if ui
                    .add_enabled(
                        collision.method == Method::Circles,
                        egui::Checkbox::new(&mut circles, "bounding circles"),
                    )
                    .on_disabled_hover_text("drawn while the circles algorithm is active")
                    .changed()
                {
                    overlays.circles = circles;
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
