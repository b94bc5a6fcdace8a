//! The **Bite** window: settle the lower arch onto the upper under a bite force, then play a
//! protrusive or lateral excursion step by step (0.5 mm a step, a few steps a second) with the
//! guidance and interferences of each step; the per-tooth contact areas of the bite; back to
//! where the case placed the teeth. The occlusal contact map overlay follows the teeth as they
//! move.

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use crate::{
    analysis::{Bite, Excursion, ExcursionKind, bite, excursion, measures::Posed},
    geometry::Pose,
    movement::SimulationState,
    teeth::{Arch, Tooth},
};

/// What the window holds between frames.
#[derive(Resource, Default)]
pub(super) struct BiteView {
    /// The lower teeth's poses when the bite was settled (index into the simulation, pose).
    base: Vec<(usize, Pose)>,
    /// The settled bite.
    bite: Option<Bite>,
    /// The excursion being shown and its lower-arch poses per step (relative to `base`).
    excursion: Option<(Excursion, Vec<Pose>)>,
    /// Step shown (0: the bite).
    step: usize,
    /// Playing the excursion.
    playing: bool,
    /// Time until the next step (s).
    timer: f32,
}

/// Places the lower teeth at `delta` × their base poses, in the simulation and the transforms.
fn place(
    view: &BiteView,
    delta: &Pose,
    state: &mut SimulationState,
    transforms: &mut Query<&mut Transform, With<Tooth>>,
) {
    let Some(sim) = state.sim.as_mut() else {
        return;
    };
    let poses: Vec<(usize, Pose)> = view.base.iter().map(|(i, p)| (*i, delta.mul(p))).collect();
    sim.place_teeth(&poses);
    for (i, p) in &poses {
        if let Some(e) = state.entities.get(*i)
            && let Ok(mut tf) = transforms.get_mut(*e)
        {
            tf.translation = p.translation;
            tf.rotation = p.rotation;
        }
    }
}

/// The window.
pub(super) fn bite_window(
    mut contexts: EguiContexts,
    mut view: ResMut<BiteView>,
    mut state: ResMut<SimulationState>,
    mut transforms: Query<&mut Transform, With<Tooth>>,
    time: Res<Time<Real>>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    let mut settle = false;
    let mut start: Option<ExcursionKind> = None;
    let mut back = false;
    egui::Window::new("Bite")
        .default_pos([10.0, ctx.viewport_rect().height() - 330.0])
        .default_width(330.0)
        .default_open(false)
        .show(ctx, |ui| {
            ui.horizontal_wrapped(|ui| {
                settle = ui
                    .add_enabled(state.sim.is_some(), egui::Button::new("settle"))
                    .on_hover_text("close the lower arch onto the upper under a bite force")
                    .clicked();
                let settled = view.bite.is_some();
                for (label, kind) in [
                    ("protrusion", ExcursionKind::Protrusive),
                    ("right", ExcursionKind::Right),
                    ("left", ExcursionKind::Left),
                ] {
                    if ui
                        .add_enabled(settled, egui::Button::new(label))
                        .on_hover_text("slide the jaw from the bite in 0.5 mm steps")
                        .clicked()
                    {
                        start = Some(kind);
                    }
                }
                back = ui
                    .add_enabled(settled, egui::Button::new("back to the case"))
                    .on_hover_text("the teeth where the case placed them")
                    .clicked();
            });
            if let Some(b) = &view.bite {
                ui.label(format!(
                    "{}; contacting upper teeth right {}, left {}; incisor gap {:.2} mm",
                    if b.stable {
                        "stable".to_owned()
                    } else {
                        format!("not stable: {}", b.why.as_deref().unwrap_or(""))
                    },
                    b.contact_teeth.right,
                    b.contact_teeth.left,
                    b.incisor_gap_mm
                ));
                egui::CollapsingHeader::new("contact area per pair")
                    .default_open(false)
                    .show(ui, |ui| {
                        for c in &b.contacts {
                            ui.label(format!(
                                "{}–{}: {:.3} mm², gap {:.3} mm",
                                c.upper, c.lower, c.area_mm2, c.min_gap_mm
                            ));
                        }
                    });
            }
            let step = view.step;
            if let Some((e, _)) = &view.excursion
                && let Some(s) = step.checked_sub(1).and_then(|k| e.steps.get(k))
            {
                let pairs = |l: &[[crate::teeth::Fdi; 2]]| {
                    l.iter()
                        .map(|[u, w]| format!("{u}–{w}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                };
                ui.label(format!(
                    "{} {:.1} mm: {} guidance; contacts {}{}",
                    e.kind.name(),
                    s.mm,
                    s.guidance,
                    pairs(&s.contacts),
                    if s.interferences.is_empty() {
                        String::new()
                    } else {
                        format!("; interferences {}", pairs(&s.interferences))
                    }
                ));
            }
        });
    if settle && let Some(sim) = state.sim.as_ref() {
        let base: Vec<(usize, Pose)> = sim
            .teeth
            .iter()
            .enumerate()
            .filter(|(_, t)| t.fdi.arch() == Arch::Lower)
            .map(|(i, t)| (i, t.pose))
            .collect();
        let b = bite("viewer", &Posed::of_simulation(sim), true, 0.0);
        let lower = b.lower_pose;
        *view = BiteView {
            base,
            bite: Some(b),
            ..default()
        };
        place(&view, &lower, &mut state, &mut transforms);
    }
    if let (Some(kind), Some(b), Some(sim)) = (start, view.bite.as_ref(), state.sim.as_ref()) {
        // The excursion from the settled bite, over the teeth where the bite was settled from.
        let mut teeth = Posed::of_simulation(sim);
        for (i, p) in &view.base {
            if let Some(t) = teeth.get_mut(*i) {
                t.pose = *p;
            }
        }
        let e = excursion(&teeth, &b.lower_pose, kind, 6.0);
        let poses = e.steps.iter().map(|s| s.lower_pose).collect();
        view.excursion = Some((e, poses));
        view.step = 0;
        view.playing = true;
        view.timer = 0.0;
    }
    if back {
        place(&view, &Pose::IDENTITY, &mut state, &mut transforms);
        *view = BiteView::default();
    }
    if view.playing {
        view.timer -= time.delta_secs();
        if view.timer <= 0.0 {
            view.timer = 0.3;
            let next = view.step + 1;
            let pose = view
                .excursion
                .as_ref()
                .and_then(|(_, p)| p.get(next - 1).copied());
            match pose {
                Some(p) => {
                    view.step = next;
                    place(&view, &p, &mut state, &mut transforms);
                }
                None => view.playing = false,
            }
        }
    }
    Ok(())
}
