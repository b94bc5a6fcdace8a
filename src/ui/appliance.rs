//! The **Appliance** part of the teeth window: choose a wire and bond an arch (the selected teeth,
//! or all of it), take a wire off, and place a chain, a coil spring or an intermaxillary elastic
//! between two selected teeth.

use bevy::prelude::*;
use bevy_egui::egui;

use crate::{
    appliance::{ArchForm, Prescription, Slot, WireMaterial, WireSize},
    movement::{EditAppliance, SimulationState, sim::WireChoice},
    teeth::{
        Arch, Fdi,
        case::appliance::{BracketMaterial, CoilKind, Ligation},
    },
};

/// The wire sizes the panel offers (inches), as clinics stock them.
const SIZES: [WireSize; 9] = [
    WireSize::Round(0.012),
    WireSize::Round(0.014),
    WireSize::Round(0.016),
    WireSize::Round(0.018),
    WireSize::Round(0.020),
    WireSize::Rect(0.016, 0.016),
    WireSize::Rect(0.016, 0.022),
    WireSize::Rect(0.019, 0.025),
    WireSize::Rect(0.021, 0.025),
];

/// The wire, chain and coil being composed.
#[derive(Resource)]
pub(super) struct ApplianceEditor {
    choice: WireChoice,
    stretch: f64,
    coil_force_n: f64,
    activation_mm: f64,
}

impl Default for ApplianceEditor {
    fn default() -> Self {
        Self {
            choice: WireChoice::default(),
            stretch: 0.5,
            coil_force_n: 1.5,
            activation_mm: 3.0,
        }
    }
}

/// A combo box of `options` named by `name`.
fn combo<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    id: &str,
    value: &mut T,
    options: &[T],
    name: impl Fn(T) -> String,
    hint: &str,
) {
    egui::ComboBox::from_id_salt(id)
        .selected_text(name(*value))
        .show_ui(ui, |ui| {
            for &o in options {
                ui.selectable_value(value, o, name(o));
            }
        })
        .response
        .on_hover_text(hint);
}

/// The section (see the module doc).
pub(super) fn section(
    ui: &mut egui::Ui,
    editor: &mut ApplianceEditor,
    selected: &[Fdi],
    sim: &SimulationState,
    out: &mut MessageWriter<EditAppliance>,
) {
    ui.separator();
    ui.label("Appliance (ligament model)");
    let c = &mut editor.choice;
    ui.horizontal_wrapped(|ui| {
        combo(
            ui,
            "material",
            &mut c.material,
            &WireMaterial::ALL,
            |m| m.name().into(),
            "the wire's alloy",
        );
        combo(
            ui,
            "size",
            &mut c.size,
            &SIZES,
            |s| s.label(),
            "the wire's cross-section (inches)",
        );
        combo(
            ui,
            "slot",
            &mut c.slot,
            &[Slot::S018, Slot::S022],
            |s| s.label().into(),
            "the brackets' slot",
        );
        combo(
            ui,
            "form",
            &mut c.form,
            &ArchForm::ALL,
            |f| f.name().into(),
            "the preformed arch form, sized to the arch",
        );
        combo(
            ui,
            "rx",
            &mut c.prescription,
            &Prescription::ALL,
            |p| p.name().into(),
            "the brackets' prescription (tip, torque, in-out)",
        );
        combo(
            ui,
            "ligation",
            &mut c.ligation,
            &Ligation::ALL,
            |l| l.name().into(),
            "how the wire is tied into the slots: what presses it on the slot's floor, and so part of the friction a tooth slides with",
        );
        combo(
            ui,
            "brackets",
            &mut c.bracket_material,
            &BracketMaterial::ALL,
            |b| b.name().into(),
            "the brackets' material: ceramic slots rub half again as hard as steel",
        );
    });
    let running = sim.sim.is_some();
    ui.horizontal_wrapped(|ui| {
        for arch in [Arch::Upper, Arch::Lower] {
            let name = if arch == Arch::Upper {
                "upper"
            } else {
                "lower"
            };
            let teeth: Vec<Fdi> = selected
                .iter()
                .copied()
                .filter(|f| f.arch() == arch)
                .collect();
            let hint = if teeth.is_empty() {
                format!("bond every {name} tooth but the third molars and engage this wire")
            } else {
                format!("bond the selected {name} teeth and engage this wire")
            };
            if ui
                .add_enabled(running, egui::Button::new(format!("bond {name}")))
                .on_hover_text(hint)
                .clicked()
            {
                out.write(EditAppliance::Bond {
                    arch,
                    choice: editor.choice,
                    teeth,
                });
            }
            let bonded = sim
                .sim
                .as_ref()
                .is_some_and(|s| s.wires.iter().any(|w| w.arch == arch));
            if ui
                .add_enabled(bonded, egui::Button::new(format!("debond {name}")))
                .on_hover_text(format!(
                    "take the {name} wire, its brackets, chains and coils off"
                ))
                .clicked()
            {
                out.write(EditAppliance::Debond { arch });
            }
        }
    });
    let pair = match selected {
        [a, b] => Some((*a, *b)),
        _ => None,
    };
    ui.horizontal_wrapped(|ui| {
        ui.add(egui::Slider::new(&mut editor.stretch, 0.1..=1.0).text("chain stretch"))
            .on_hover_text("the chain's strain when placed (0.5: stretched by half its length)");
        if ui
            .add_enabled(pair.is_some(), egui::Button::new("chain"))
            .on_hover_text("an elastomeric chain over the brackets between the two selected teeth")
            .clicked()
            && let Some((from, to)) = pair
        {
            out.write(EditAppliance::Chain {
                from,
                to,
                stretch: editor.stretch,
            });
        }
        let across = pair.filter(|(a, b)| a.arch() != b.arch());
        if ui
            .add_enabled(across.is_some(), egui::Button::new("elastic"))
            .on_hover_text("an intermaxillary elastic (Class II or III) between the two selected teeth, one in each arch, rated at the coil force below")
            .clicked()
            && let Some((from, to)) = across
        {
            out.write(EditAppliance::Elastic {
                from,
                to,
                force_n: editor.coil_force_n,
            });
        }
    });
    ui.horizontal_wrapped(|ui| {
        ui.add(egui::Slider::new(&mut editor.coil_force_n, 0.5..=3.0).text("coil N"))
            .on_hover_text("the coil's plateau force");
        ui.add(egui::Slider::new(&mut editor.activation_mm, 0.5..=8.0).text("activation mm"))
            .on_hover_text(
                "how far the coil is stretched (closed) or compressed (open) when placed",
            );
        for (label, kind, hint) in [
            (
                "closed coil",
                CoilKind::Closed,
                "pulls the two selected teeth together",
            ),
            (
                "open coil",
                CoilKind::Open,
                "pushes the two selected teeth apart",
            ),
        ] {
            if ui
                .add_enabled(pair.is_some(), egui::Button::new(label))
                .on_hover_text(hint)
                .clicked()
                && let Some((from, to)) = pair
            {
                out.write(EditAppliance::Coil {
                    from,
                    to,
                    kind,
                    force_n: editor.coil_force_n,
                    activation_mm: editor.activation_mm,
                });
            }
        }
    });
}
