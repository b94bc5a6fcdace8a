//! Tooth movement: loads, wire models, the quasi-static motion of each step, the next-tooth search
//! along the arch and the collision responses (block, impulse, IPR).
//!
//! Engine-free core: `settings` (the model choice, mobility and response parameters), `model`
//! (the paper's load and wire → motion, constraints), [`pdl`] (the periodontal-ligament model),
//! `arch_path` (sliding along the arch, next present tooth), [`mod@bench`] (the PDL model's costs),
//! [`sim`] (the whole step over a case, with the responses and their guarantees), `report` (the
//! `simulate` command's measures) and [`MovementError`]. ECS layer (feature `ecs`):
//! `MovementPlugin`.

mod arch_path;
pub mod bench;
mod error;
mod model;
pub mod pdl;
#[cfg(feature = "ecs")]
mod plugin;
mod report;
mod settings;
pub mod sim;

pub use error::MovementError;
pub use model::ToothConstraint;
#[cfg(feature = "ecs")]
pub use plugin::{
    EditAppliance, MovementPlugin, MovementStatus, MovementSystems, SetExtracted, SetGroupLoad,
    SetLoad, SetMomentToForce, SetWire, SimulationState, ToothImpact,
};
pub use report::{
    ApplianceReport, BoneMeshReport, BoneOutside, BracketReport, CaseRun, ChainReport, CoilReport,
    Irregularity, MOVED_MM, PairDistance, RunLimit, SimulationReport, ToothTravel, WireReport,
    max_penetration, neighbour_pairs, pair_distances, run_case, run_case_for, tooth_travel,
};
pub use settings::{MovementModel, MovementSettings, Response};
pub use sim::{
    ArchWire, Bonded, CorticalContact, Found, Impact, SimGroup, SimTooth, Simulation, StepOutcome,
    WireChoice,
};
