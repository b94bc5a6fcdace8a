//! The **Plan** window: plan the case from its teeth where the case places them (not where the
//! simulation has moved them since) to the automatic target
//! within editable per-stage limits and a sequence, then step through the stages with a slider
//! or play them, the teeth coloured by how much they still have to move (green: done, through
//! yellow, to red: 2 mm or 10° or more) and a ring between two teeth once their contact has been
//! reduced (IPR); the plan's stages, IPR, blocked pairs and deepest penetration; back to the case.
//! Planning pauses the simulation, so the teeth stay where the stage puts them. Planning runs in
//! the background (a scan-resolution case takes a second or two); the window says so meanwhile.
//! **edit target** shows the teeth at the target with handles on the selected tooth (see
//! [`super::plan_edit`]); **plan to this target** stages the edited target.

use std::collections::HashMap;

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use bevy::tasks::{AsyncComputeTaskPool, Task, futures::check_ready};

use super::plan_edit::{Grip, TargetEditor, gap_colour, nudge, save_target};
use crate::{
    analysis::plan_report::still_to_move_colour,
    geometry::Pose,
    movement::SimulationState,
    planning::{Anchorage, Plan, PlanLimits, Sequence, Target, TargetForm, automatic, plan},
    teeth::{ActiveCase, Tooth},
};

/// Colours of the remaining movement, from nothing left to 2 mm or 10° or more.
const PALETTE: usize = 8;

/// Asks the Plan window to open, plan the case once its simulation is ready and show `stage`
/// (the last when beyond it), or with `edit` the target with the selected tooth's handles: what
/// `orthosim screenshot --plan` inserts. A requested plan is computed at once, not in the
/// background, so that the picture shows it.
#[derive(Resource, Clone, Copy, Debug)]
pub struct PlanRequest {
    /// The stage to show.
    pub stage: u32,
    /// Show the target being edited instead.
    pub edit: bool,
}

/// What the window holds between frames.
#[derive(Resource, Default)]
pub(super) struct PlanView {
    /// The limits being edited.
    limits: Option<PlanLimits>,
    /// The plan shown.
    plan: Option<Plan>,
    /// Its target, edited in place while editing.
    pub(super) target: Option<Target>,
    /// The target editor.
    pub(super) edit: TargetEditor,
    /// A plan being computed in the background, and when it started.
    task: Option<(Task<(Target, Plan)>, std::time::Instant)>,
    /// Stage shown.
    stage: u32,
    /// Playing the stages.
    playing: bool,
    /// Time until the next stage (s).
    timer: f32,
    /// Each tooth's crown material before the plan coloured it.
    originals: HashMap<Entity, Handle<StandardMaterial>>,
    /// The remaining-movement colours.
    palette: Vec<Handle<StandardMaterial>>,
    /// A [`PlanRequest`] was carried out.
    requested: bool,
}

/// The window's system parameters that place and colour the teeth.
type ToothQuery<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Tooth,
        &'static mut Transform,
        &'static mut MeshMaterial3d<StandardMaterial>,
    ),
>;

/// Places every tooth of the plan at stage `k` (in the simulation and the transforms) and
/// colours it by what it still has to move; `None` puts the teeth and colours back.
fn show(
    view: &mut PlanView,
    k: Option<u32>,
    state: &mut SimulationState,
    teeth: &mut ToothQuery,
    materials: &mut Assets<StandardMaterial>,
) {
    let Some(p) = view.plan.as_ref() else {
        return;
    };
    if view.palette.is_empty() {
        view.palette = (0..PALETTE)
            .map(|i| {
                materials.add(StandardMaterial {
                    base_color: {
                        let [r, g, b] = still_to_move_colour(i as f32 / (PALETTE - 1) as f32);
                        Color::srgb(r, g, b)
                    },
                    perceptual_roughness: 0.45,
                    reflectance: 0.4,
                    ..default()
                })
            })
            .collect();
    }
    let stage = k.unwrap_or(0);
    // Editing shows the target as edited.
    let target = view
        .target
        .as_ref()
        .filter(|_| view.edit.active && k.is_some());
    let mut placed: Vec<(usize, Pose)> = Vec::new();
    for (entity, tooth, mut tf, mut material) in teeth.iter_mut() {
        let Some(i) = p.moves.iter().position(|m| m.fdi == tooth.id) else {
            continue;
        };
        let pose = target
            .and_then(|t| t.poses.get(&tooth.id).copied())
            .unwrap_or_else(|| p.moves[i].pose_at(stage));
        tf.translation = pose.translation;
        tf.rotation = pose.rotation;
        if let Some(sim) = state.sim.as_ref()
            && let Some(s) = sim.teeth.iter().position(|t| t.fdi == tooth.id)
        {
            placed.push((s, pose));
        }
        match k {
            Some(k) => {
                view.originals
                    .entry(entity)
                    .or_insert_with(|| material.0.clone());
                let t = p.still_to_move(i, k);
                let c = ((t * (PALETTE - 1) as f32).round() as usize).min(PALETTE - 1);
                material.0 = view.palette[c].clone();
            }
            None => {
                if let Some(h) = view.originals.remove(&entity) {
                    material.0 = h;
                }
            }
        }
    }
    if let Some(sim) = state.sim.as_mut() {
        sim.place_teeth(&placed);
    }
}

/// The window.
#[allow(clippy::too_many_arguments)]
pub(super) fn plan_window(
    mut contexts: EguiContexts,
    mut view: ResMut<PlanView>,
    mut state: ResMut<SimulationState>,
    case: Option<Res<ActiveCase>>,
    mut teeth: ToothQuery,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut gizmos: Gizmos,
    time: Res<Time<Real>>,
    mut clock: ResMut<Time<Virtual>>,
    request: Option<Res<PlanRequest>>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    let mut compute = false;
    let asked = request.as_deref().copied();
    if asked.is_some() && !view.requested && case.is_some() && state.sim.is_some() {
        compute = true;
    }
    let mut back = false;
    let mut go_to: Option<u32> = None;
    let mut toggle_play = false;
    let mut stop_play = false;
    let mut toggle_edit = false;
    let mut plan_edited = false;
    let mut save = false;
    let mut nudged: Option<(Grip, f32)> = None;
    // A background plan that is done.
    if let Some((task, _)) = view.task.as_mut()
        && let Some((target, p)) = check_ready(task)
    {
        view.task = None;
        go_to = Some(if view.edit.active { p.stages } else { 0 });
        view.target = Some(target);
        view.plan = Some(p);
        view.stage = 0;
        view.playing = false;
        view.edit.changed = false;
        view.edit.measured = None;
    }
    let running = view.task.as_ref().map(|(_, t)| t.elapsed().as_secs_f32());
    let limits = view.limits.get_or_insert_with(PlanLimits::default).clone();
    let mut edited = limits.clone();
    let editing = view.edit.active;
    let selected = case.as_ref().and(view.edit.measured.map(|(f, _)| f));
    egui::Window::new("Plan")
        .default_pos([
            ctx.viewport_rect().width() - 360.0,
            ctx.viewport_rect().height() - 290.0,
        ])
        .default_width(340.0)
        .default_open(asked.is_some())
        .show(ctx, |ui| {
            limits_ui(ui, &mut edited);
            ui.horizontal(|ui| {
                compute |= ui
                    .add_enabled(
                        case.is_some() && running.is_none(),
                        egui::Button::new("plan"),
                    )
                    .on_hover_text("set up the automatic target and stage the case within these limits")
                    .clicked();
                back = ui
                    .add_enabled(view.plan.is_some(), egui::Button::new("back to the case"))
                    .on_hover_text("the teeth where the case has them, their own colours")
                    .clicked();
            });
            if let Some(s) = running {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label(format!("planning… {s:.1} s"));
                });
            }
            let Some(p) = view.plan.as_ref() else {
                return;
            };
            ui.label(format!(
                "{} stages, planned in {:.0} ms (target {:.0} ms); deepest penetration {:.3} mm",
                p.stages, p.plan_ms, p.target_ms, p.max_penetration_mm
            ));
            ui.label(p.relations_summary());
            let mut stage = view.stage;
            ui.add_enabled_ui(!editing, |ui| {
                ui.horizontal(|ui| {
                    let playing = view.playing;
                    if ui
                        .button(if playing { "pause" } else { "play" })
                        .on_hover_text("step through the stages, a few a second")
                        .clicked()
                    {
                        go_to = Some(if !playing && stage >= p.stages {
                            0
                        } else {
                            stage
                        });
                        toggle_play = true;
                    }
                    if ui
                        .add(egui::Slider::new(&mut stage, 0..=p.stages).text("stage"))
                        .on_hover_text("the teeth at this stage")
                        .changed()
                    {
                        go_to = Some(stage);
                        stop_play = true;
                    }
                });
            });
            for x in &p.ipr {
                ui.label(format!(
                    "IPR {}|{}: {:.2} mm at stage {}",
                    x.a, x.b, x.mm, x.stage
                ));
            }
            for b in &p.blocked {
                ui.colored_label(
                    egui::Color32::from_rgb(200, 60, 40),
                    format!("blocked {}–{} at stage {}: {}", b.a, b.b, b.stage, b.why),
                );
            }
            ui.separator();
            let mut on = editing;
            if ui
                .checkbox(&mut on, "edit target")
                .on_hover_text(
                    "the teeth at the target; drag the selected tooth's arrows to move it along its mesial (red), buccal (green) and occlusal (blue) axes, its rings to turn it",
                )
                .changed()
            {
                toggle_edit = true;
            }
            if !editing {
                return;
            }
            match selected {
                Some(f) => {
                    ui.label(format!("tooth {f}: drag its handles, or step it:"));
                    nudged = nudge_ui(ui);
                }
                None => {
                    ui.label("select a tooth to move it");
                }
            }
            for c in &view.edit.contacts {
                let [r, g, b] = gap_colour(c.gap_mm);
                ui.colored_label(
                    egui::Color32::from_rgb(r, g, b),
                    format!(
                        "{}–{}: {:+.3} mm",
                        selected.map_or(String::new(), |f| f.to_string()),
                        c.other,
                        c.gap_mm
                    ),
                )
                .on_hover_text("exact gap (negative: the teeth overlap)");
            }
            ui.horizontal(|ui| {
                plan_edited = ui
                    .add_enabled(
                        view.edit.changed && running.is_none(),
                        egui::Button::new("plan to this target"),
                    )
                    .on_hover_text("stage the case to the target as edited")
                    .clicked();
                save = ui
                    .button("save target")
                    .on_hover_text(
                        "write each tooth's movement from where the case has it, for orthosim plan --target",
                    )
                    .clicked();
                ui.text_edit_singleline(&mut view.edit.path);
            });
            if let Some(m) = &view.edit.saved {
                ui.label(m);
            }
        });
    if toggle_play {
        view.playing = !view.playing;
    }
    if stop_play {
        view.playing = false;
    }
    if edited != limits {
        view.limits = Some(edited);
    }
    if toggle_edit {
        view.edit.active = !view.edit.active;
        view.edit.measured = None;
        view.playing = false;
        go_to = Some(if view.edit.active {
            view.plan.as_ref().map_or(0, |p| p.stages)
        } else {
            view.stage
        });
    }
    if let (Some((handle, amount)), Some(case), Some(f)) = (nudged, case.as_ref(), selected)
        && let Some(target) = view.target.as_mut()
    {
        nudge(target, &case.0, f, handle, amount);
        view.edit.changed = true;
    }
    if save && let Some(case) = case.as_ref() {
        let view = &mut *view;
        if view.edit.path.trim().is_empty() {
            view.edit.path = "target.ron".into();
        }
        let path = std::path::PathBuf::from(view.edit.path.trim());
        if let Some(target) = view.target.as_ref() {
            view.edit.saved = Some(save_target(&case.0, target, &path));
        }
    }
    if (compute || plan_edited)
        && let Some(case) = case
    {
        let limits = view.limits.clone().unwrap_or_default();
        // The simulation holds still while the stages are shown (Play in the panel goes on).
        clock.pause();
        // Teeth and colours back before a new plan replaces the old one.
        if !plan_edited {
            show(&mut view, None, &mut state, &mut teeth, &mut materials);
        }
        let given = plan_edited
            .then(|| view.target.clone())
            .flatten()
            .map(|mut t| {
                t.source = "edited";
                t
            });
        let d = case.0.clone();
        let job = move || {
            let started = std::time::Instant::now();
            let target = given.unwrap_or_else(|| automatic(&d, &limits));
            let ms = started.elapsed().as_secs_f64() * 1e3;
            let p = plan(&d, &target, &limits, ms);
            (target, p)
        };
        match asked.filter(|_| !view.requested) {
            Some(r) => {
                let (target, p) = job();
                view.requested = true;
                view.edit.active = r.edit;
                go_to = Some(r.stage.min(p.stages));
                view.target = Some(target);
                view.plan = Some(p);
                view.stage = 0;
                view.playing = false;
            }
            None => {
                let task = AsyncComputeTaskPool::get().spawn(async move { job() });
                view.task = Some((task, std::time::Instant::now()));
            }
        }
    }
    if back {
        show(&mut view, None, &mut state, &mut teeth, &mut materials);
        view.plan = None;
        view.target = None;
        view.edit.active = false;
        view.playing = false;
        return Ok(());
    }
    if view.playing {
        view.timer -= time.delta_secs();
        if view.timer <= 0.0 {
            view.timer = 0.25;
            let last = view.plan.as_ref().map_or(0, |p| p.stages);
            if view.stage < last {
                go_to = Some(view.stage + 1);
            } else {
                view.playing = false;
            }
        }
    }
    if let Some(k) = go_to {
        view.stage = k;
        show(&mut view, Some(k), &mut state, &mut teeth, &mut materials);
    }
    // Rings between teeth whose contact has been reduced by the stage shown.
    if let Some(p) = view.plan.as_ref() {
        let centre = |f| {
            let m = p.moves.iter().find(|m| m.fdi == f)?;
            Some(m.pose_at(view.stage).transform_point(m.pivot))
        };
        for x in p.ipr.iter().filter(|x| x.stage <= view.stage) {
            if let (Some(a), Some(b)) = (centre(x.a), centre(x.b)) {
                gizmos.sphere(
                    Isometry3d::from_translation((a + b) * 0.5),
                    0.6,
                    Color::BLACK,
                );
            }
        }
    }
    Ok(())
}

/// The limits, sequence and anchorage, editable.
fn limits_ui(ui: &mut egui::Ui, edited: &mut PlanLimits) {
    egui::Grid::new("plan limits")
        .num_columns(2)
        .show(ui, |ui| {
            for (label, value, tip) in [
                (
                    "mesio-distal mm",
                    &mut edited.mesiodistal_mm.0,
                    "crown movement along the arch per stage",
                ),
                (
                    "bucco-lingual mm",
                    &mut edited.buccolingual_mm.0,
                    "crown movement across the arch per stage",
                ),
                (
                    "vertical mm",
                    &mut edited.vertical_mm.0,
                    "intrusion or extrusion per stage",
                ),
                (
                    "rotation °",
                    &mut edited.rotation_deg.0,
                    "rotation about the vertical per stage",
                ),
                ("tip °", &mut edited.tip_deg.0, "tip per stage"),
                ("torque °", &mut edited.torque_deg.0, "torque per stage"),
            ] {
                ui.label(label).on_hover_text(tip);
                ui.add(egui::DragValue::new(value).range(0.01..=5.0).speed(0.01))
                    .on_hover_text(tip);
                ui.end_row();
            }
        });
    choice(
        ui,
        "sequence",
        &mut edited.sequence,
        &[
            Sequence::AllAtOnce,
            Sequence::AnteriorsFirst,
            Sequence::VPattern,
        ],
        Sequence::name,
        "which teeth start moving first",
    );
    choice(
        ui,
        "arch form",
        &mut edited.arch_form,
        &[
            TargetForm::Fitted,
            TargetForm::Ovoid,
            TargetForm::Tapered,
            TargetForm::Square,
        ],
        TargetForm::name,
        "the form the target aligns the teeth on: fitted to them, or a preformed one sized to it",
    );
    ui.horizontal(|ui| {
        for (label, value) in [
            ("upper", &mut edited.anchorage.upper),
            ("lower", &mut edited.anchorage.lower),
        ] {
            choice(
                ui,
                &format!("{label} anchorage"),
                value,
                &[
                    Anchorage::Auto,
                    Anchorage::Minimum,
                    Anchorage::Moderate,
                    Anchorage::Maximum,
                ],
                Anchorage::name,
                "which teeth close the arch's spaces: minimum, the posterior teeth come forward; maximum, the anterior teeth retract; auto, the share that brings canines and molars nearest class I keeping the overjet",
            );
        }
    });
}

/// A combo box choosing `value` among `options`, each shown by `name`, with a tooltip.
fn choice<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[T],
    name: fn(T) -> &'static str,
    tip: &str,
) {
    egui::ComboBox::from_label(label)
        .selected_text(name(*value))
        .show_ui(ui, |ui| {
            for &o in options {
                ui.selectable_value(value, o, name(o));
            }
        })
        .response
        .on_hover_text(tip);
}

/// Step buttons for the edited tooth's six movements; the one pressed.
fn nudge_ui(ui: &mut egui::Ui) -> Option<(Grip, f32)> {
    let mut pressed = None;
    egui::Grid::new("target nudges")
        .num_columns(3)
        .show(ui, |ui| {
            for (label, handle, step) in [
                ("mesial mm", Grip::Move(0), 0.1),
                ("buccal mm", Grip::Move(1), 0.1),
                ("occlusal mm", Grip::Move(2), 0.1),
                ("torque °", Grip::Turn(0), 1.0),
                ("tip °", Grip::Turn(1), 1.0),
                ("rotation °", Grip::Turn(2), 1.0),
            ] {
                ui.label(label);
                if ui.small_button("−").clicked() {
                    pressed = Some((handle, -step));
                }
                if ui.small_button("+").clicked() {
                    pressed = Some((handle, step));
                }
                ui.end_row();
            }
        });
    pressed
}
