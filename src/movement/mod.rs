//! Tooth movement: loads, wire models, the quasi-static motion of each step, the next-tooth search
//! along the arch and the collision responses (block, impulse, IPR).
//!
//! Engine-free core: [`settings`] (mobility model and response parameters), [`model`] (load and
//! wire → motion, constraints), [`arch_path`] (sliding along the arch, next present tooth),
//! [`sim`] (the whole step over a case, with the responses and their guarantees) and [`report`]
//! (the `simulate` command's measures). ECS layer: [`plugin::MovementPlugin`].

pub mod arch_path;
pub mod model;
pub mod plugin;
pub mod report;
pub mod settings;
pub mod sim;

pub use model::ToothConstraint;
pub use plugin::{
    MovementPlugin, MovementStatus, SetExtracted, SetGroupLoad, SetLoad, SetWire, SimulationState,
    ToothImpact,
};
pub use report::{PairDistance, SimulationReport, run_case};
pub use settings::{MovementSettings, Response};
pub use sim::{Found, Impact, SimGroup, SimTooth, Simulation, StepOutcome};
