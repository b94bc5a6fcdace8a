//! `SimulationSchedulePlugin` (feature `ecs`): the schedule the simulation runs in and the chained
//! [`SimulationSystems`] sets that every simulation plugin nests its own sets in.
//!
//! This plugin alone declares and chains the stages, so disabling or replacing any other plugin
//! never unorders the rest. It also nests the collision plugin's sets
//! ([`CollisionSystems`]) in their stages, since collision is
//! the layer below; the plugins above (movement) nest their own sets, and add this plugin, in
//! their schedule, when the app does not have it yet.
//!
//! | stage | what runs there |
//! |---|---|
//! | `Loads` | colliders for new trees, the simulation (re)started, edits and loads → net force and torque per tooth |
//! | `Motion` | each moving tooth's proposed motion over the step |
//! | `BroadPhase` | candidate pairs: arch neighbours and opposing teeth, moving pairs only |
//! | `NarrowPhase` | the chosen method on each candidate pair → contacts |
//! | `Resolve` | the response: motions cut at first contact, loads passed on, impacts |
//! | `Commit` | end poses written to `Transform`, status and messages |
//!
//! Systems of a user that read the step's results go `.after(SimulationSystems::Commit)`.

use bevy::{
    ecs::{intern::Interned, schedule::ScheduleLabel},
    prelude::*,
    transform::TransformSystems,
};

use crate::collision::CollisionSystems;

/// The stages of one simulation step, chained in this order in the simulation schedule (before
/// transform propagation).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SimulationSystems {
    /// Colliders and the simulation made ready; loads → net force and torque per tooth.
    Loads,
    /// Proposed motion of this step per moving tooth.
    Motion,
    /// Candidate pairs.
    BroadPhase,
    /// Contacts of the candidate pairs.
    NarrowPhase,
    /// Response to contacts.
    Resolve,
    /// End poses written to `Transform`.
    Commit,
}

/// The schedule the simulation runs in, for code that runs a step by hand (the panel's single
/// step runs it while paused).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq, Deref)]
pub struct SimulationSchedule(pub Interned<dyn ScheduleLabel>);

/// Declares the simulation schedule and chains [`SimulationSystems`] in it.
#[derive(Clone, Copy, Debug)]
pub struct SimulationSchedulePlugin {
    schedule: Interned<dyn ScheduleLabel>,
}

impl SimulationSchedulePlugin {
    /// The simulation in `schedule`.
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
        }
    }

    /// The schedule the stages are chained in.
    pub fn schedule(&self) -> Interned<dyn ScheduleLabel> {
        self.schedule
    }
}

impl Default for SimulationSchedulePlugin {
    /// The simulation in `FixedUpdate`.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

impl Plugin for SimulationSchedulePlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(SimulationSchedule(self.schedule))
            .configure_sets(
                self.schedule,
                (
                    SimulationSystems::Loads,
                    SimulationSystems::Motion,
                    SimulationSystems::BroadPhase,
                    SimulationSystems::NarrowPhase,
                    SimulationSystems::Resolve,
                    SimulationSystems::Commit,
                )
                    .chain()
                    .before(TransformSystems::Propagate),
            )
            .configure_sets(
                self.schedule,
                (
                    CollisionSystems::Prepare.in_set(SimulationSystems::Loads),
                    CollisionSystems::BroadPhase.in_set(SimulationSystems::BroadPhase),
                    CollisionSystems::NarrowPhase.in_set(SimulationSystems::NarrowPhase),
                ),
            );
    }
}

/// Adds [`SimulationSchedulePlugin`] in `schedule` unless the app has it: the plugins above the
/// simulation layer call this first, so the stages are ordered whichever plugins are disabled. A plugin asked to
/// run in another schedule than the app's simulation schedule is reported, since its systems
/// would then run outside the chain.
pub(crate) fn ensure_schedule(app: &mut App, schedule: Interned<dyn ScheduleLabel>) {
    if !app.is_plugin_added::<SimulationSchedulePlugin>() {
        app.add_plugins(SimulationSchedulePlugin { schedule });
        return;
    }
    if let Some(existing) = app.world().get_resource::<SimulationSchedule>()
        && existing.0 != schedule
    {
        warn!(
            "a simulation plugin runs in {schedule:?} but the simulation schedule is {:?}: its \
             systems are not ordered with the others",
            existing.0
        );
    }
}
