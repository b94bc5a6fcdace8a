//! # orthosim
//!
//! An interactive 3D simulator for orthodontic training and treatment planning: load a patient's
//! two dental arches, extract teeth, apply loads through an archwire, and watch teeth move and
//! touch, with exact contacts and distances. The guide (`docs/` in the repository) explains each
//! part and its figures.
//!
//! ## Example: headless, in your own app
//!
//! The paper's case 1 run until its teeth rest, and a system of your own that reads each step's
//! result (also `examples/headless.rs`):
//!
//! ```
//! # #[cfg(feature = "ecs")] {
//! use bevy::prelude::*;
//! use orthosim::prelude::*;
//!
//! fn report_at_rest(
//!     status: Res<MovementStatus>,
//!     case: Option<Res<ActiveCase>>,
//!     teeth: Query<(&Tooth, &ToothShape, &Transform)>,
//!     mut exit: MessageWriter<AppExit>,
//! ) {
//!     let Some(case) = case else { return };
//!     if !status.at_rest && status.steps < 20_000 {
//!         return;
//!     }
//!     for (tooth, shape, transform) in &teeth {
//!         let Some(placed) = case.tooth(tooth.id) else { continue };
//!         let c = shape.frame.crown_centre;
//!         let travel = transform.transform_point(c).distance(placed.pose.transform_point(c));
//!         if travel > 0.1 {
//!             println!("tooth {} moved {travel:.2} mm", tooth.id);
//!         }
//!     }
//!     exit.write(AppExit::Success);
//! }
//!
//! let exit = App::new()
//!     // One simulation step per app update: a batch run needs no clock.
//!     .add_plugins((MinimalPlugins, TransformPlugin, OrthoSimPlugins::new(Update)))
//!     .add_systems(Startup, |mut load: MessageWriter<LoadCase>| {
//!         load.write(LoadCase("case1".into()));
//!     })
//!     .add_systems(Update, report_at_rest.after(SimulationSystems::Commit))
//!     .run();
//! assert_eq!(exit, AppExit::Success);
//! # }
//! ```
//!
//! ## Layers
//!
//! Each module uses only the ones above it in this list (a test keeps it so):
//!
//! | module | what it is | feature |
//! |---|---|---|
//! | [`geometry`] | triangle meshes, spheres, exact triangle queries, BVH, mesh distance | – |
//! | [`io`] | atomic writes, outputs that never replace inputs, all-or-nothing output sets | – |
//! | [`parallel`] | the one place that spreads work over cores | – |
//! | [`teeth`] | FDI numbers, anatomy, procedural teeth, arch forms, cases, mesh import | – |
//! | [`sphere_tree`] | sphere trees: octree and medial builders, fit, `.sph`, cache | – |
//! | [`collision`] | broad phase, narrow phases (circles, spheres, continuous, exact), contact tests | – |
//! | [`simulation`] | the schedule and the chained [`SimulationSystems`](simulation::SimulationSystems) | `ecs` |
//! | [`movement`] | loads, wires, the engine-free [`Simulation`](movement::Simulation), responses | – |
//! | [`planning`] | target set-ups, staging within limits with no tooth through another, IPR, stage meshes | – |
//! | [`analysis`] | distances, occlusion, IPR, Bolton, reports and plots | – |
//! | `occlusion_view` | rendering, overlays, contact maps, the orbit camera | `viewer` |
//! | `ui` | the egui panel | `viewer` |
//!
//! Without features (`--no-default-features`) the library is the engine-free core, plain Rust on
//! glam: no Bevy and no clap in its dependency tree. Feature `ecs` adds the Bevy plugins, each a
//! thin layer over the core; `viewer` adds rendering and the panel; `cli` the `orthosim` command.
//!
//! ## Plugins
//!
//! | plugin | what it adds |
//! |---|---|
//! | `SimulationSchedulePlugin` | the simulation schedule and its chained stages |
//! | `TeethModelPlugin` | patient cases, tooth entities with shared shapes |
//! | `SphereTreePlugin` | sphere trees per tooth shape, built in the background |
//! | `CollisionPlugin` | broad and narrow phases, contacts of moving teeth |
//! | `MovementPlugin` | loads, wire models, motion per step, block / impulse / IPR responses |
//! | `OcclusionViewPlugin` (feature `viewer`) | rendering, overlays, orbit camera |
//! | `OrthoSimUiPlugin` (feature `viewer`) | the egui control panel and readouts |
//!
//! `OrthoSimPlugins::new(schedule)` adds the simulation plugins, all in one schedule (default
//! `FixedUpdate`); the viewer is added separately, so the simulation runs the same with or without
//! a window. Swap one out with `.build().disable::<…>()` or `.set(…)`: the stages stay ordered.

pub mod analysis;
pub mod appliance;
pub mod collision;
pub mod geometry;
pub mod io;
pub mod movement;
#[cfg(feature = "viewer")]
pub mod occlusion_view;
pub mod parallel;
pub mod planning;
#[cfg(feature = "ecs")]
pub mod simulation;
pub mod sphere_tree;
pub mod teeth;
#[cfg(feature = "viewer")]
pub mod ui;

#[cfg(feature = "ecs")]
use bevy::{
    app::{FixedUpdate, PluginGroup, PluginGroupBuilder},
    ecs::{intern::Interned, schedule::ScheduleLabel},
};

/// Every simulation plugin of orthosim, all running in one schedule (headless-safe).
///
/// | plugin | role |
/// |---|---|
/// | [`simulation::SimulationSchedulePlugin`] | the schedule and the chained [`simulation::SimulationSystems`] |
/// | [`teeth::TeethModelPlugin`] | loads cases, spawns teeth |
/// | [`sphere_tree::SphereTreePlugin`] | builds each tooth shape's sphere tree in the background |
/// | [`collision::CollisionPlugin`] | finds the contacts of moving teeth each simulation step |
/// | [`movement::MovementPlugin`] | moves loaded teeth, responds to contacts, passes loads on |
///
/// Swap one out with `OrthoSimPlugins::default().build().disable::<…>()`, or configure one with
/// `.set(…)`; the others stay ordered.
#[cfg(feature = "ecs")]
#[derive(Clone, Copy, Debug)]
pub struct OrthoSimPlugins {
    schedule: Interned<dyn ScheduleLabel>,
}

#[cfg(feature = "ecs")]
impl OrthoSimPlugins {
    /// The simulation plugins, stepping in `schedule`.
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
        }
    }
}

#[cfg(feature = "ecs")]
impl Default for OrthoSimPlugins {
    /// The simulation plugins, stepping in `FixedUpdate`.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

#[cfg(feature = "ecs")]
impl PluginGroup for OrthoSimPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(simulation::SimulationSchedulePlugin::new(self.schedule))
            .add(teeth::TeethModelPlugin::default())
            .add(sphere_tree::SphereTreePlugin)
            .add(collision::CollisionPlugin::new(self.schedule))
            .add(movement::MovementPlugin::new(self.schedule))
    }
}

/// Internals that the integration tests and benchmarks reach into; not part of the API.
#[doc(hidden)]
pub mod internals {
    pub use crate::{
        collision::{
            narrow_phase::{
                continuous::{first_contact, may_meet},
                lanes::{GROW, f32_slack},
            },
            sampling::{Rng, random_motion},
        },
        geometry::interval::Interval,
    };
}

/// What a user of orthosim touches most: every plugin, system set, message and component, the
/// settings and status resources, and the core types they carry.
pub mod prelude {
    #[cfg(feature = "ecs")]
    pub use crate::{
        OrthoSimPlugins,
        collision::{
            CollisionPlugin, CollisionSettings, CollisionSystems, Contact, ContactStarted,
            Contacts, ToothCollider, ToothContact, ToothMotion,
        },
        movement::{
            MovementPlugin, MovementStatus, MovementSystems, SetExtracted, SetGroupLoad, SetLoad,
            SetWire, SimulationState, ToothImpact,
        },
        simulation::{SimulationSchedule, SimulationSchedulePlugin, SimulationSystems},
        sphere_tree::{
            SphereTreeCache, SphereTreePlugin, SphereTreeProgress, SphereTreeSettings,
            SphereTreeSystems, ToothSphereTree,
        },
        teeth::{
            ActiveCase, CaseLoadFailed, CaseLoaded, Extracted, LoadCase, LoadGroup,
            TeethModelPlugin, TeethModelSystems, Tooth, ToothShape, Wire,
        },
    };
    pub use crate::{
        collision::Method,
        geometry::{Pose, TriMesh},
        movement::{MOVED_MM, MovementSettings, Response, Simulation},
        sphere_tree::{TreeCache, TreeMethod, TreeSettings},
        teeth::{Arch, Case, Dentition, Fdi, Load, ToothKind},
    };
    #[cfg(feature = "viewer")]
    pub use crate::{
        occlusion_view::{CameraInputSystems, OcclusionViewPlugin, Overlays, ScreenshotPlugin},
        ui::OrthoSimUiPlugin,
    };
}
