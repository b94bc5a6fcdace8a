//! The **Teeth and loads** window: the selection (click a tooth, shift-click for a group, or the
//! FDI chart) and what is done to it: loads with presets along each tooth's own axes, wires,
//! extraction and restoration, and the appliances (see [`super::appliance`]); each selected
//! tooth's bracket force and whether its root is at a cortical plate.

use bevy::{ecs::system::SystemParam, prelude::*};
use bevy_egui::{EguiContexts, egui};

use super::appliance::{self, ApplianceEditor};
use crate::{
    movement::{EditAppliance, SetExtracted, SetLoad, SetMomentToForce, SetWire, SimulationState},
    occlusion_view::Selection,
    teeth::{Extracted, Load, Tooth, Wire, WireModel},
};

/// Selects a tooth by clicking it (shift-click adds or removes it).
pub(super) fn click_tooth(
    click: On<Pointer<Click>>,
    teeth: Query<(), With<Tooth>>,
    keys: Option<Res<ButtonInput<KeyCode>>>,
    mut selection: ResMut<Selection>,
    plan: Option<Res<super::plan::PlanView>>,
) {
    if click.event.button != PointerButton::Primary || !teeth.contains(click.entity) {
        return;
    }
    // A press that took a target handle ends in no selection.
    if plan.is_some_and(|p| p.edit.took_press) {
        return;
    }
    let add = keys.is_some_and(|k| k.pressed(KeyCode::ShiftLeft) || k.pressed(KeyCode::ShiftRight));
    selection.pick(click.entity, add);
}

/// An axis of a tooth (0 mesial, 1 buccal, 2 occlusal) and a sign.
type AxisSign = (usize, f32);

/// A load preset: its label, force axis and sign, torque axis and sign.
type Preset = (&'static str, Option<AxisSign>, Option<AxisSign>);

/// The presets along each tooth's own axes.
const PRESETS: [Preset; 9] = [
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

/// The FDI chart's rows, as the clinician faces the patient.
const CHART: [[u8; 16]; 2] = [
    [
        18, 17, 16, 15, 14, 13, 12, 11, 21, 22, 23, 24, 25, 26, 27, 28,
    ],
    [
        48, 47, 46, 45, 44, 43, 42, 41, 31, 32, 33, 34, 35, 36, 37, 38,
    ],
];

/// The load being composed for the selection.
#[derive(Resource)]
pub(super) struct LoadEditor {
    force_n: f32,
    torque_nmm: f32,
    /// Moment-to-force ratio at the bracket (mm) for the selected teeth.
    mf_mm: f32,
}

impl Default for LoadEditor {
    fn default() -> Self {
        Self {
            force_n: 1.5,
            torque_nmm: 15.0,
            mf_mm: 10.0,
        }
    }
}

/// The teeth as the window reads them.
type WindowTeeth<'w, 's> = Query<
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

/// What the window asks of the simulation.
#[derive(SystemParam)]
pub(super) struct ToothEdits<'w> {
    load: MessageWriter<'w, SetLoad>,
    wire: MessageWriter<'w, SetWire>,
    mf: MessageWriter<'w, SetMomentToForce>,
    extracted: MessageWriter<'w, SetExtracted>,
    appliance: MessageWriter<'w, EditAppliance>,
}

/// The window: chart, load presets, wires, extraction, and what the selected teeth carry.
pub(super) fn loads_window(
    mut contexts: EguiContexts,
    mut editor: ResMut<LoadEditor>,
    mut appliances: ResMut<ApplianceEditor>,
    mut selection: ResMut<Selection>,
    teeth: WindowTeeth,
    sim: Res<SimulationState>,
    mut edits: ToothEdits,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    egui::Window::new("Teeth and loads")
        .default_pos([ctx.viewport_rect().width() - 350.0, 10.0])
        .default_width(330.0)
        .show(ctx, |ui| {
            chart(ui, &mut selection, &teeth);
            ui.add(egui::Slider::new(&mut editor.force_n, 0.0..=5.0).text("force N"))
                .on_hover_text("the magnitude the force presets apply");
            ui.add(egui::Slider::new(&mut editor.torque_nmm, 0.0..=50.0).text("torque N·mm"))
                .on_hover_text("the magnitude the torque presets apply");
            loads(ui, &editor, &selection, &teeth, &mut edits.load);
            moment_to_force(ui, &mut editor, &selection, &mut edits.mf);
            wires_and_extraction(ui, &selection, &mut edits);
            let numbers: Vec<crate::teeth::Fdi> = selection
                .0
                .iter()
                .filter_map(|e| teeth.get(*e).ok().map(|t| t.1.id))
                .collect();
            appliance::section(ui, &mut appliances, &numbers, &sim, &mut edits.appliance);
            if let Some(notice) = &sim.notice {
                ui.colored_label(egui::Color32::LIGHT_RED, notice);
            }
            selected(ui, &selection, &teeth, &sim);
        });
    Ok(())
}

/// The FDI chart (extracted teeth struck through) and the names of the selected teeth.
fn chart(ui: &mut egui::Ui, selection: &mut ResMut<Selection>, teeth: &WindowTeeth) {
    ui.label("Click a tooth (shift-click for a group) or use the chart:");
    let find = |n: u8| teeth.iter().find(|t| t.1.id.number() == n);
    for row in CHART {
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
                    .on_hover_text(if extracted {
                        "extracted; click to select it (restore puts it back)"
                    } else {
                        "click to add or remove it from the selection"
                    });
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
}

/// The preset buttons: a force or torque of the editor's magnitude along a tooth's own axis, or
/// no load.
fn loads(
    ui: &mut egui::Ui,
    editor: &LoadEditor,
    selection: &Selection,
    teeth: &WindowTeeth,
    out: &mut MessageWriter<SetLoad>,
) {
    let mut chosen = None;
    ui.horizontal_wrapped(|ui| {
        for (label, f, t) in PRESETS {
            if ui
                .add_enabled(!selection.0.is_empty(), egui::Button::new(label))
                .on_hover_text("this load on the selected teeth, along each tooth's own axes")
                .clicked()
            {
                chosen = Some((f, t));
            }
        }
        if ui
            .add_enabled(!selection.0.is_empty(), egui::Button::new("clear"))
            .on_hover_text("no load on the selected teeth")
            .clicked()
        {
            chosen = Some((None, None));
        }
    });
    let Some((f, t)) = chosen else {
        return;
    };
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
        out.write(SetLoad { tooth: *e, load });
    }
}

/// The bracket's moment-to-force ratio for the selected teeth (PDL model, rectangular wire): 0
/// tips the crown, about the bracket's distance to the centre of resistance (8–12 mm) translates,
/// more moves the root.
fn moment_to_force(
    ui: &mut egui::Ui,
    editor: &mut LoadEditor,
    selection: &Selection,
    out: &mut MessageWriter<SetMomentToForce>,
) {
    let any = !selection.0.is_empty();
    ui.horizontal_wrapped(|ui| {
        ui.add(egui::Slider::new(&mut editor.mf_mm, 0.0..=15.0).text("M/F mm"))
            .on_hover_text("moment-to-force ratio at the bracket: about 10 mm translates a tooth");
        let mut chosen = None;
        if ui
            .add_enabled(any, egui::Button::new("set M/F"))
            .on_hover_text("give the selected teeth's brackets this moment-to-force ratio")
            .clicked()
        {
            chosen = Some(Some(editor.mf_mm));
        }
        if ui
            .add_enabled(any, egui::Button::new("wire decides"))
            .on_hover_text("no set M/F: a rectangular wire supplies its engagement's couple")
            .clicked()
        {
            chosen = Some(None);
        }
        if let Some(mf) = chosen {
            for e in &selection.0 {
                out.write(SetMomentToForce { tooth: *e, mf });
            }
        }
    });
}

/// Round or rectangular wire, extract or restore, for every selected tooth.
fn wires_and_extraction(ui: &mut egui::Ui, selection: &Selection, edits: &mut ToothEdits) {
    ui.horizontal_wrapped(|ui| {
        let any = !selection.0.is_empty();
        for (label, wire) in [
            ("round wire", WireModel::Round),
            ("rectangular wire", WireModel::Rectangular),
        ] {
            if ui
                .add_enabled(any, egui::Button::new(label))
                .on_hover_text("the paper's wire model for the selected teeth")
                .clicked()
            {
                for e in &selection.0 {
                    edits.wire.write(SetWire { tooth: *e, wire });
                }
            }
        }
        for (label, extracted) in [("extract", true), ("restore", false)] {
            if ui
                .add_enabled(any, egui::Button::new(label))
                .on_hover_text(if extracted {
                    "take the selected teeth out while the case runs"
                } else {
                    "put them back, unless a neighbour has moved into their place"
                })
                .clicked()
            {
                for e in &selection.0 {
                    edits.extracted.write(SetExtracted {
                        tooth: *e,
                        extracted,
                    });
                }
            }
        }
    });
}

/// Each selected tooth's load, wire and M/F, or that it is extracted; under the PDL model where
/// its centres of resistance and rotation are (drawn as markers: green and magenta).
fn selected(ui: &mut egui::Ui, selection: &Selection, teeth: &WindowTeeth, sim: &SimulationState) {
    for e in &selection.0 {
        let Ok((_, tooth, _, l, extracted, wire)) = teeth.get(*e) else {
            continue;
        };
        if extracted {
            ui.label(format!("{}: extracted", tooth.id));
            continue;
        }
        let wire = match wire.map(|w| w.0) {
            Some(WireModel::Round) => "round",
            _ => "rectangular",
        };
        let run = sim.sim.as_ref().zip(sim.index_of(*e));
        let mf = run
            .and_then(|(s, i)| s.teeth[i].mf)
            .map_or(String::new(), |m| format!(", M/F {m:.1} mm"));
        ui.label(format!(
            "{}: force {:.2} N, torque {:.1} N·mm, {wire} wire{mf}",
            tooth.id,
            l.force.length(),
            l.torque.length()
        ));
        if let Some((s, i)) = run
            && let Some(cres) = s.centre_of_resistance(i)
        {
            let t = &s.teeth[i];
            let axis = t.pose.transform_vector(t.shape.geometry.frame.long_axis);
            let rotation = match s.centre_of_rotation(i) {
                Some(c) => format!(
                    "centre of rotation {:+.1} mm along the axis (+ apical)",
                    (cres - c).dot(axis)
                ),
                None if s
                    .pdl
                    .twists
                    .get(i)
                    .is_some_and(|t| t.iter().any(|v| *v != 0.0)) =>
                {
                    "translating".to_owned()
                }
                None => "at rest".to_owned(),
            };
            ui.label(format!("    {rotation}"));
            if let Some(r) = s.wires.iter().find_map(|w| w.reaction_of(i)) {
                let (f, m) = (r.force, r.moment);
                ui.label(format!(
                    "    bracket: {:.2} N ({:+.2}, {:+.2}, {:+.2}), {:.1} N·mm",
                    f.length(),
                    f.x,
                    f.y,
                    f.z,
                    m.length()
                ))
                .on_hover_text("the wire's force on the bracket (world x left, y up, z forward) and its moment");
            }
            if let Some(f) = s
                .wires
                .iter()
                .find_map(|w| w.friction_of(i))
                .filter(|f| *f != 0.0)
            {
                ui.label(format!("    slot friction: {:.2} N", f.abs()))
                    .on_hover_text("what the slot's friction takes from the chain or coil sliding this tooth along the wire");
            }
            if let Some(c) = s
                .cortical
                .iter()
                .rev()
                .find(|c| c.fdi == t.fdi && c.until_day >= s.elapsed_days - 1.0)
            {
                ui.label(
                    format!("    root at the {:?} plate since day {:.0}", c.plate, c.day)
                        .to_lowercase(),
                );
            }
        }
    }
}
