//! `OrthoSimUiPlugin` (feature `viewer`): the egui control panel, one function per heading, and
//! the teeth-and-loads window.
//!
//! - **Case** (`case`): load a built-in case or a case file (the error shown if it fails), reset
//!   the current one.
//! - **Simulation** (`simulation`): play / pause, single step (one run of the simulation
//!   schedule), speed (the virtual clock's rate, which drives the fixed simulation step).
//! - **Collision** (`collision`): narrow-phase method and response apply at once; a new tree
//!   builder or depth rebuilds the trees in the background and restarts the case. Tree builds in
//!   the background show a progress bar.
//! - **View** (`view`): show or hide each arch; roots translucent, solid or hidden; overlays: a
//!   sphere-tree level of every tooth, the contacts of the step, the occlusal contact map, the
//!   bounding circles while the circles algorithm is active.
//! - **Readouts** (`readouts`): steps, teeth moving, frame rate, collision time per step (broad
//!   phase to response), the contacts of the last step, IPR totals, and the surface gap of every
//!   adjacent pair as a plot with the 1 mm line (measured a few times a second, only while the
//!   panel shows it).
//! - **Teeth and loads** (`teeth`, its own window): select teeth by clicking them (shift-click
//!   for a group) or from an FDI chart, and set a force or torque on them with presets along each
//!   tooth's mesial, buccal and occlusal axes. The selected teeth can also get a round or
//!   rectangular wire, or be extracted and restored while the case runs (a refused restore shows
//!   its reason).
//! - **Bite** (`bite`, its own window): settle the lower arch onto the upper, play protrusion or
//!   a lateral excursion with its guidance and interferences, the contact area per pair.
//! - **Plan** (`plan`, its own window): plan the case within editable per-stage limits, a
//!   sequence and anchorage, in the background; step through or play the stages with the teeth
//!   coloured by what they still have to move and rings where contacts were reduced; edit the
//!   target with handles on the selected tooth, its gaps measured live (`plan_edit`).
//!
//! The camera ignores the mouse while the pointer is over the panel or a target handle is being
//! dragged: the plugin makes the view's [`CameraInputSystems`] run only then.

mod appliance;
mod bite;
mod case;
mod collision;
mod help;
mod plan;
mod plan_edit;
mod readouts;
mod simulation;
mod teeth;
mod view;

pub use help::HelpOpen;
pub use plan::PlanRequest;

use bevy::{
    ecs::{schedule::ScheduleLabel, system::SystemParam},
    prelude::*,
};
use bevy_egui::{EguiContexts, EguiPlugin, EguiPrimaryContextPass, egui, input::EguiWantsInput};

use crate::{
    collision::{CollisionSettings, Contacts},
    movement::{MovementModel, MovementSettings, MovementStatus, SimulationState},
    occlusion_view::{CameraInputSystems, Overlays},
    simulation::SimulationSchedule,
    sphere_tree::{SphereTreeProgress, SphereTreeSettings, TreeMethod},
    teeth::{ActiveCase, CaseLoadFailed, CaseLoaded, LoadCase, Tooth},
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
            .init_resource::<HelpOpen>()
            .init_resource::<teeth::LoadEditor>()
            .init_resource::<appliance::ApplianceEditor>()
            .init_resource::<bite::BiteView>()
            .init_resource::<plan::PlanView>()
            .configure_sets(
                Update,
                CameraInputSystems.run_if(pointer_free.and_then(plan_edit::no_grab)),
            )
            .add_observer(teeth::click_tooth)
            .add_systems(
                EguiPrimaryContextPass,
                (
                    panel,
                    teeth::loads_window,
                    bite::bite_window,
                    plan::plan_window,
                    help::help_window,
                ),
            )
            .add_systems(Update, (single_step, clinical_pace))
            .init_gizmo_group::<plan_edit::HandleGizmos>()
            .add_systems(Startup, plan_edit::setup_handle_gizmos)
            .add_systems(Update, plan_edit::target_handles.before(CameraInputSystems));
    }
}

/// Clinical days the clock runs per second at speed 1 under the PDL model: about a week, a pace a
/// person can follow (the fixed step's default 64 Hz would be two months a second).
pub const DAYS_PER_SECOND: f64 = 7.0;

/// Sets the fixed step's rate so that, under the PDL model, speed 1 runs [`DAYS_PER_SECOND`]
/// clinical days a second whatever a step's length; the paper's model keeps Bevy's default rate.
fn clinical_pace(settings: Res<MovementSettings>, mut fixed: ResMut<Time<Fixed>>) {
    let step = match settings.model {
        MovementModel::Pdl => {
            std::time::Duration::from_secs_f64(settings.pdl.step_days() / DAYS_PER_SECOND)
        }
        MovementModel::Paper => Time::<Fixed>::default().timestep(),
    };
    if fixed.timestep() != step && step > std::time::Duration::ZERO {
        fixed.set_timestep(step);
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

/// Runs one step of the simulation schedule while paused.
fn single_step(world: &mut World) {
    let asked = world.resource::<PanelState>().step;
    if !asked {
        return;
    }
    world.resource_mut::<PanelState>().step = false;
    let schedule = world
        .get_resource::<SimulationSchedule>()
        .map_or_else(|| FixedUpdate.intern(), |s| s.0);
    world.run_schedule(schedule);
}

/// The settings and readouts the panel shows and edits.
#[derive(SystemParam)]
struct Panel<'w, 's> {
    state: ResMut<'w, PanelState>,
    help: ResMut<'w, HelpOpen>,
    time: ResMut<'w, Time<Virtual>>,
    real: Res<'w, Time<Real>>,
    collision: ResMut<'w, CollisionSettings>,
    movement: ResMut<'w, MovementSettings>,
    trees: ResMut<'w, SphereTreeSettings>,
    progress: Res<'w, SphereTreeProgress>,
    overlays: ResMut<'w, Overlays>,
    status: Res<'w, MovementStatus>,
    sim: Res<'w, SimulationState>,
    contacts: Res<'w, Contacts>,
    case: Option<Res<'w, ActiveCase>>,
    teeth: Query<'w, 's, &'static Tooth>,
    load: MessageWriter<'w, LoadCase>,
    failed: MessageReader<'w, 's, CaseLoadFailed>,
    loaded: MessageReader<'w, 's, CaseLoaded>,
}

/// The main panel: one section per heading.
fn panel(mut contexts: EguiContexts, mut p: Panel) -> Result {
    if let Some(e) = p.failed.read().last() {
        p.state.load_error = Some(e.0.to_string());
    }
    if p.loaded.read().last().is_some() {
        p.state.load_error = None;
    }
    let dt = p.real.delta_secs();
    if dt > 0.0 {
        p.state.frame = 0.9 * p.state.frame + 0.1 * dt;
    }
    let ctx = contexts.ctx_mut()?;
    let current = p.case.as_ref().map(|c| c.case.case.name.clone());
    egui::Window::new("orthosim")
        .default_pos([10.0, 10.0])
        .default_width(330.0)
        .show(ctx, |ui| {
            if ui
                .small_button("?")
                .on_hover_text("help: the mouse and keyboard controls (F1)")
                .clicked()
            {
                p.help.0 = !p.help.0;
            }
            case::section(ui, &mut p.state, current.as_deref(), &mut p.load);
            ui.separator();
            simulation::section(ui, &mut p.state, &mut p.time);
            ui.separator();
            collision::section(
                ui,
                collision::Settings {
                    state: &mut p.state,
                    collision: &mut p.collision,
                    movement: &mut p.movement,
                    trees: &mut p.trees,
                    overlays: &mut p.overlays,
                },
                &p.progress,
                current.as_deref(),
                &mut p.load,
            );
            ui.separator();
            view::section(ui, &mut p.overlays, p.trees.depth, p.collision.method);
            ui.separator();
            readouts::section(
                ui,
                &mut p.state,
                readouts::Sources {
                    status: &p.status,
                    sim: &p.sim,
                    contacts: &p.contacts,
                    teeth: &p.teeth,
                },
                dt,
            );
        });
    Ok(())
}
