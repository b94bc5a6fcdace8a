//! The **Plan** window: plan the case from its teeth where the case places them (not where the
//! simulation has moved them since) to the automatic target
//! within editable per-stage limits and a sequence, then step through the stages with a slider
//! or play them, the teeth coloured by how much they still have to move (green: done, through
//! yellow, to red: 2 mm or 10° or more) and a ring between two teeth once their contact has been
//! reduced (IPR); the plan's stages, IPR, blocked pairs and deepest penetration; back to the case.
//! Planning pauses the simulation, so the teeth stay where the stage puts them.

use std::collections::HashMap;

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use crate::{
    analysis::plan_report::still_to_move_colour,
    geometry::Pose,
    movement::SimulationState,
    planning::{Anchorage, Plan, PlanLimits, Sequence, automatic, plan},
    teeth::{ActiveCase, Tooth},
};

/// Colours of the remaining movement, from nothing left to 2 mm or 10° or more.
const PALETTE: usize = 8;

/// Asks the Plan window to open, plan the case once its simulation is ready and show `stage`
/// (the last when beyond it): what `orthosim screenshot --plan` inserts.
#[derive(Resource, Clone, Copy, Debug)]
pub struct PlanRequest {
    /// The stage to show.
    pub stage: u32,
}

/// What the window holds between frames.
#[derive(Resource, Default)]
pub(super) struct PlanView {
    /// The limits being edited.
    limits: Option<PlanLimits>,
    /// The plan shown.
    plan: Option<Plan>,
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
    let mut placed: Vec<(usize, Pose)> = Vec::new();
    for (entity, tooth, mut tf, mut material) in teeth.iter_mut() {
        let Some(i) = p.moves.iter().position(|m| m.fdi == tooth.id) else {
            continue;
        };
        let pose = p.moves[i].pose_at(stage);
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
    let limits = view.limits.get_or_insert_with(PlanLimits::default).clone();
    let mut edited = limits.clone();
    egui::Window::new("Plan")
        .default_pos([
            ctx.viewport_rect().width() - 360.0,
            ctx.viewport_rect().height() - 290.0,
        ])
        .default_width(340.0)
        .default_open(asked.is_some())
        .show(ctx, |ui| {
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
            egui::ComboBox::from_label("sequence")
                .selected_text(edited.sequence.name())
                .show_ui(ui, |ui| {
                    for s in [
                        Sequence::AllAtOnce,
                        Sequence::AnteriorsFirst,
                        Sequence::VPattern,
                    ] {
                        ui.selectable_value(&mut edited.sequence, s, s.name());
                    }
                })
                .response
                .on_hover_text("which teeth start moving first");
            ui.horizontal(|ui| {
                for (label, value) in [
                    ("upper", &mut edited.anchorage.upper),
                    ("lower", &mut edited.anchorage.lower),
                ] {
                    egui::ComboBox::from_label(format!("{label} anchorage"))
                        .selected_text(value.name())
                        .show_ui(ui, |ui| {
                            for a in [
                                Anchorage::Auto,
                                Anchorage::Minimum,
                                Anchorage::Moderate,
                                Anchorage::Maximum,
                            ] {
                                ui.selectable_value(value, a, a.name());
                            }
                        })
                        .response
                        .on_hover_text(
                            "which teeth close the arch's spaces: minimum, the posterior teeth come forward; maximum, the anterior teeth retract; auto, the share that brings canines and molars nearest class I keeping the overjet",
                        );
                }
            });
            ui.horizontal(|ui| {
                compute |= ui
                    .add_enabled(case.is_some(), egui::Button::new("plan"))
                    .on_hover_text("set up the target and stage the case within these limits")
                    .clicked();
                back = ui
                    .add_enabled(view.plan.is_some(), egui::Button::new("back to the case"))
                    .on_hover_text("the teeth where the case has them, their own colours")
                    .clicked();
            });
            let Some(p) = view.plan.as_ref() else {
                return;
            };
            ui.label(format!(
                "{} stages, planned in {:.0} ms (target {:.0} ms); deepest penetration {:.3} mm",
                p.stages, p.plan_ms, p.target_ms, p.max_penetration_mm
            ));
            ui.label(p.relations_summary());
            let mut stage = view.stage;
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
    if compute && let Some(case) = case {
        let limits = view.limits.clone().unwrap_or_default();
        // The simulation holds still while the stages are shown (Play in the panel goes on).
        clock.pause();
        // Teeth and colours back before a new plan replaces the old one.
        show(&mut view, None, &mut state, &mut teeth, &mut materials);
        let started = std::time::Instant::now();
        let target = automatic(&case.0, &limits);
        let ms = started.elapsed().as_secs_f64() * 1e3;
        view.plan = Some(plan(&case.0, &target, &limits, ms));
        view.stage = 0;
        view.playing = false;
        go_to = Some(0);
        if let Some(r) = asked.filter(|_| !view.requested) {
            view.requested = true;
            go_to = Some(r.stage.min(view.plan.as_ref().map_or(0, |p| p.stages)));
        }
    }
    if back {
        show(&mut view, None, &mut state, &mut teeth, &mut materials);
        view.plan = None;
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
