//! `MovementPlugin`: the ECS layer over [`Simulation`].
//!
//! Once every visible tooth of the [`ActiveCase`] has its collider (its sphere tree is built), a
//! [`Simulation`] of the case is made and kept in [`SimulationState`]. Each step of the simulation
//! schedule (default `FixedUpdate`) then runs the plugin's [`MovementSystems`], each nested in its
//! stage of [`SimulationSystems`]: `Start` and `Loads` in `Loads` (the simulation made or
//! restarted; wires, extractions and loads set by messages or changed [`Load`] components),
//! `Propose` in `Motion` (each tooth's [`ToothMotion`] for the step), `Clock` at the start of
//! `BroadPhase` (the collision time is measured from there), `Resolve` (the response to the
//! [`Contacts`], see [`super::sim`]) and `Commit` (end poses written to `Transform`,
//! [`MovementStatus`] updated, a [`ToothImpact`] message per impact). A new case, or a change of
//! the collision method, starts a new simulation.

use std::sync::Arc;

use bevy::{
    ecs::{intern::Interned, schedule::ScheduleLabel},
    prelude::*,
};

use super::{
    MovementError,
    settings::MovementSettings,
    sim::{Found, Impact, Simulation, WireChoice},
};
use crate::{
    collision::{
        CollisionSettings, CollisionSystems, Contacts, EndOverlap, PairContact, ToothCollider,
        ToothMotion, motion::Motion,
    },
    simulation::{SimulationSystems, ensure_schedule},
    teeth::{
        ActiveCase, Arch, Dentition, Extracted, Fdi, Load, Tooth, Wire, WireModel,
        case::appliance::CoilKind,
    },
};

/// The movement plugin's systems, in the order they run; each sits in the stage of
/// [`SimulationSystems`] named in brackets.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MovementSystems {
    /// The simulation made when a case is ready, restarted when it changes (`Loads`, after the
    /// colliders are attached).
    Start,
    /// Wires, extractions and loads asked for by messages or changed components (`Loads`).
    Loads,
    /// Each tooth's proposed motion (`Motion`).
    Propose,
    /// The collision time starts (`BroadPhase`, before the collision plugin's broad phase).
    Clock,
    /// The response to the step's contacts (`Resolve`).
    Resolve,
    /// End poses written, status and messages (`Commit`).
    Commit,
}

/// The running simulation of the active case.
#[derive(Resource, Default)]
pub struct SimulationState {
    /// The simulation, once every tooth is ready.
    pub sim: Option<Simulation>,
    /// The entity of each simulated tooth (same order as `sim.teeth`).
    pub entities: Vec<Entity>,
    /// The case it was made for.
    case: Option<Arc<Dentition>>,
    /// This step is skipped (some tooth does not carry its `ToothMotion` yet, so the collision
    /// stage could not see the motions).
    skip: bool,
    /// The last edit of the teeth that was refused, and why (for the panel).
    pub notice: Option<String>,
}

impl SimulationState {
    /// The simulation index of an entity.
    pub fn index_of(&self, e: Entity) -> Option<usize> {
        self.entities.iter().position(|x| *x == e)
    }
}

/// Progress of the simulation, for readouts.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct MovementStatus {
    /// Steps taken.
    pub steps: u64,
    /// Teeth that moved in the last step.
    pub moved: usize,
    /// Nothing moves any more.
    pub at_rest: bool,
    /// Clinical (PDL) or simulated (paper) time elapsed (days).
    pub days: f64,
    /// Time of the last step's broad phase, narrow phase and response (µs).
    pub collision_us: f64,
}

/// When the last step's collision stage started.
#[derive(Resource, Default)]
struct CollisionClock(Option<std::time::Instant>);

/// Set a tooth's load from code (replaces its own load).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SetLoad {
    /// The tooth.
    pub tooth: Entity,
    /// Its new load (world frame).
    pub load: Load,
}

/// Set a group's load from code (the group's index in the case's group loads).
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SetGroupLoad {
    /// Index of the group.
    pub group: usize,
    /// Its new load (world frame).
    pub load: Load,
}

/// Set a tooth's archwire model from code.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SetWire {
    /// The tooth.
    pub tooth: Entity,
    /// Its wire model from now on.
    pub wire: WireModel,
}

/// Set a tooth's moment-to-force ratio at the bracket (mm; None: the wire's engagement decides),
/// PDL model. A ratio out of range is refused with a notice in [`SimulationState::notice`].
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SetMomentToForce {
    /// The tooth.
    pub tooth: Entity,
    /// Its M/F from now on.
    pub mf: Option<f32>,
}

/// Extract a tooth (`extracted: true`) or restore it, while the case runs (see
/// [`Simulation::with_extraction`]). A refused restore is reported in
/// [`SimulationState::notice`].
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SetExtracted {
    /// The tooth.
    pub tooth: Entity,
    /// Extract (true) or restore (false).
    pub extracted: bool,
}

/// Change the appliances while the case runs (PDL model). A refused change is reported in
/// [`SimulationState::notice`].
#[derive(Message, Clone, Debug, PartialEq)]
pub enum EditAppliance {
    /// Bond `teeth` of `arch` (all but third molars when empty) and engage `choice`'s wire,
    /// replacing the arch's wire.
    Bond {
        /// The arch.
        arch: Arch,
        /// The wire and brackets.
        choice: WireChoice,
        /// The teeth to bond.
        teeth: Vec<Fdi>,
    },
    /// Take the arch's wire and brackets off.
    Debond {
        /// The arch.
        arch: Arch,
    },
    /// An elastomeric chain between two bonded teeth, stretched by `stretch`.
    Chain {
        /// One end.
        from: Fdi,
        /// The other end.
        to: Fdi,
        /// Strain when placed.
        stretch: f64,
    },
    /// An intermaxillary elastic between bonded teeth of the two arches, rated `force_n`.
    Elastic {
        /// One end.
        from: Fdi,
        /// The other end (the other arch).
        to: Fdi,
        /// Rated force (N).
        force_n: f64,
    },
    /// A NiTi coil spring between two bonded teeth.
    Coil {
        /// One end.
        from: Fdi,
        /// The other end.
        to: Fdi,
        /// Closed or open.
        kind: CoilKind,
        /// Plateau force (N).
        force_n: f64,
        /// Activation (mm).
        activation_mm: f64,
    },
}

/// An impact of the `impulse` response.
#[derive(Message, Clone, Debug, PartialEq, Deref)]
pub struct ToothImpact(pub Impact);

/// Tooth movement and the response to contacts.
pub struct MovementPlugin {
    schedule: Interned<dyn ScheduleLabel>,
}

impl MovementPlugin {
    /// Tooth movement in `schedule` (the simulation's: see [`crate::OrthoSimPlugins`]).
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
        }
    }
}

impl Default for MovementPlugin {
    /// Tooth movement in `FixedUpdate`.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

impl Plugin for MovementPlugin {
    fn build(&self, app: &mut App) {
        ensure_schedule(app, self.schedule);
        // What movement reads of collision, there even when another plugin replaces it.
        app.init_resource::<CollisionSettings>()
            .init_resource::<Contacts>()
            .init_resource::<MovementSettings>()
            .init_resource::<SimulationState>()
            .init_resource::<MovementStatus>()
            .init_resource::<CollisionClock>()
            .add_message::<SetLoad>()
            .add_message::<SetGroupLoad>()
            .add_message::<SetWire>()
            .add_message::<SetMomentToForce>()
            .add_message::<SetExtracted>()
            .add_message::<EditAppliance>()
            .add_message::<ToothImpact>()
            .configure_sets(
                self.schedule,
                (
                    (MovementSystems::Start, MovementSystems::Loads)
                        .chain()
                        .in_set(SimulationSystems::Loads)
                        .after(CollisionSystems::Prepare),
                    MovementSystems::Propose.in_set(SimulationSystems::Motion),
                    MovementSystems::Clock
                        .in_set(SimulationSystems::BroadPhase)
                        .before(CollisionSystems::BroadPhase),
                    MovementSystems::Resolve.in_set(SimulationSystems::Resolve),
                    MovementSystems::Commit.in_set(SimulationSystems::Commit),
                ),
            )
            .add_systems(
                self.schedule,
                (
                    start_simulation.in_set(MovementSystems::Start),
                    (edit_teeth, apply_loads, edit_appliances)
                        .chain()
                        .in_set(MovementSystems::Loads),
                    propose.in_set(MovementSystems::Propose),
                    start_clock.in_set(MovementSystems::Clock),
                    resolve.in_set(MovementSystems::Resolve),
                    commit.in_set(MovementSystems::Commit),
                ),
            );
    }
}

type TeethQuery<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Tooth,
        Option<&'static ToothCollider>,
        &'static Transform,
    ),
    Without<Extracted>,
>;

/// Makes the simulation when a case is ready (or restarts it when the case, the method or the
/// settings change).
fn start_simulation(
    mut commands: Commands,
    mut state: ResMut<SimulationState>,
    case: Option<Res<ActiveCase>>,
    collision: Res<CollisionSettings>,
    settings: Res<MovementSettings>,
    teeth: TeethQuery,
) {
    let Some(case) = case else {
        return;
    };
    let same_case = state.case.as_ref().is_some_and(|c| Arc::ptr_eq(c, &case.0));
    if let Some(sim) = state.sim.as_mut()
        && same_case
    {
        if sim.method != collision.method {
            sim.method = collision.method;
        }
        if settings.is_changed()
            && sim.settings != *settings
            && let Err(e) = sim.set_settings(*settings)
        {
            error!("{e}; keeping the previous movement settings");
        }
        return;
    }
    if !same_case {
        state.sim = None;
        state.case = Some(case.0.clone());
    }
    let visible: Vec<_> = case.visible().map(|t| t.fdi).collect();
    let mut entities = Vec::new();
    let mut shapes = Vec::new();
    for fdi in &visible {
        let Some((e, _, Some(collider), _)) = teeth.iter().find(|(_, t, _, _)| t.id == *fdi) else {
            return;
        };
        entities.push(e);
        shapes.push((*fdi, collider.shape.clone()));
    }
    match Simulation::new(&case.0, shapes, collision.method, *settings) {
        Ok(sim) => {
            for (e, t) in entities.iter().zip(&sim.teeth) {
                commands
                    .entity(*e)
                    .try_insert(ToothMotion(Motion::still(t.pose)));
            }
            state.sim = Some(sim);
            state.entities = entities;
        }
        Err(e) => error!("cannot simulate case '{}': {e}", case.case.case.name),
    }
}

/// Wire models, extractions and restorations asked for by [`SetWire`] and [`SetExtracted`].
fn edit_teeth(
    mut commands: Commands,
    mut state: ResMut<SimulationState>,
    case: Option<Res<ActiveCase>>,
    mut wires: MessageReader<SetWire>,
    mut ratios: MessageReader<SetMomentToForce>,
    mut extractions: MessageReader<SetExtracted>,
    teeth: Query<(Entity, &Tooth, Option<&ToothCollider>, Has<Extracted>)>,
) {
    let state = &mut *state;
    let (Some(sim), Some(case)) = (state.sim.as_mut(), case) else {
        wires.clear();
        ratios.clear();
        extractions.clear();
        return;
    };
    for m in ratios.read() {
        if let Some(i) = state.entities.iter().position(|e| *e == m.tooth)
            && let Err(e) = sim.set_mf(i, m.mf)
        {
            state.notice = Some(e.to_string());
        }
    }
    for m in wires.read() {
        if let Some(i) = state.entities.iter().position(|e| *e == m.tooth) {
            sim.set_wire(i, m.wire);
        }
        if teeth.contains(m.tooth) {
            commands.entity(m.tooth).try_insert(Wire(m.wire));
        }
    }
    let mut extracted: std::collections::HashMap<Entity, bool> =
        teeth.iter().map(|(e, _, _, x)| (e, x)).collect();
    for m in extractions.read() {
        let Ok((_, tooth, collider, _)) = teeth.get(m.tooth) else {
            continue;
        };
        if extracted.get(&m.tooth) == Some(&m.extracted) {
            continue;
        }
        let shape = collider.map(|c| c.shape.clone());
        let next = match sim.with_extraction(&case.0, tooth.id, m.extracted, shape) {
            Ok(next) => next,
            Err(e) => {
                warn!("{e}");
                state.notice = Some(e.to_string());
                continue;
            }
        };
        *sim = next;
        state.notice = None;
        extracted.insert(m.tooth, m.extracted);
        if m.extracted {
            commands.entity(m.tooth).try_insert(Extracted);
        } else {
            commands.entity(m.tooth).try_remove::<Extracted>();
        }
        state.entities = sim
            .teeth
            .iter()
            .filter_map(|t| {
                teeth
                    .iter()
                    .find(|(_, tooth, _, _)| tooth.id == t.fdi)
                    .map(|(e, ..)| e)
            })
            .collect();
        for (e, t) in state.entities.iter().zip(&sim.teeth) {
            commands
                .entity(*e)
                .try_insert(ToothMotion(Motion::still(t.pose)));
            // The restored tooth goes back to its place in the case.
            if *e == m.tooth {
                commands.entity(*e).try_insert(
                    Transform::from_translation(t.pose.translation).with_rotation(t.pose.rotation),
                );
            }
        }
    }
}

fn apply_loads(
    mut state: ResMut<SimulationState>,
    mut messages: MessageReader<SetLoad>,
    mut group_messages: MessageReader<SetGroupLoad>,
    mut loads: Query<(Entity, &mut Load), Without<Extracted>>,
) {
    let state = &mut *state;
    let Some(sim) = state.sim.as_mut() else {
        messages.clear();
        group_messages.clear();
        return;
    };
    let mut refuse = |e: MovementError| {
        warn!("{e}");
        state.notice = Some(e.to_string());
    };
    for m in group_messages.read() {
        match (sim.groups.get_mut(m.group), m.load.check()) {
            (Some(g), Ok(())) => g.load = m.load,
            (Some(_), Err(e)) => refuse(e.into()),
            (None, _) => refuse(MovementError::NoGroup(m.group)),
        }
    }
    for m in messages.read() {
        if let Err(e) = m.load.check() {
            refuse(e.into());
            continue;
        }
        if let Ok((_, mut l)) = loads.get_mut(m.tooth) {
            *l = m.load;
        }
    }
    for (e, load) in loads.iter_mut() {
        if !load.is_changed() {
            continue;
        }
        if let Some(i) = state.entities.iter().position(|x| *x == e)
            && let Err(e) = sim.set_load(i, *load)
        {
            refuse(e);
        }
    }
}

fn edit_appliances(mut state: ResMut<SimulationState>, mut messages: MessageReader<EditAppliance>) {
    let state = &mut *state;
    let Some(sim) = state.sim.as_mut() else {
        messages.clear();
        return;
    };
    for m in messages.read() {
        let done = match m {
            EditAppliance::Bond {
                arch,
                choice,
                teeth,
            } => sim.bond(*arch, *choice, teeth),
            EditAppliance::Debond { arch } => {
                sim.debond(*arch);
                Ok(())
            }
            EditAppliance::Chain { from, to, stretch } => sim.add_chain(*from, *to, *stretch),
            EditAppliance::Elastic { from, to, force_n } => sim.add_elastic(*from, *to, *force_n),
            EditAppliance::Coil {
                from,
                to,
                kind,
                force_n,
                activation_mm,
            } => sim.add_coil(*from, *to, *kind, *force_n, *activation_mm),
        };
        match done {
            Ok(()) => state.notice = None,
            Err(e) => {
                warn!("{e}");
                state.notice = Some(e.to_string());
            }
        }
    }
}

fn write_motions(state: &SimulationState, motions: &mut Query<&mut ToothMotion>) {
    let Some(sim) = state.sim.as_ref() else {
        return;
    };
    for (e, m) in state.entities.iter().zip(&sim.motions) {
        if let Ok(mut tm) = motions.get_mut(*e)
            && tm.0 != *m
        {
            tm.0 = *m;
        }
    }
}

fn propose(mut state: ResMut<SimulationState>, mut motions: Query<&mut ToothMotion>) {
    let ready = state.entities.iter().all(|e| motions.contains(*e));
    state.skip = !ready;
    if !ready {
        return;
    }
    if let Some(sim) = state.sim.as_mut() {
        sim.propose();
    }
    write_motions(&state, &mut motions);
}

fn resolve(
    mut state: ResMut<SimulationState>,
    contacts: Res<Contacts>,
    mut motions: Query<&mut ToothMotion>,
) {
    if state.skip {
        return;
    }
    let Some(moving) = state
        .sim
        .as_ref()
        .map(|sim| sim.motions.iter().any(|m| !m.is_still()))
    else {
        return;
    };
    let mut found = Vec::new();
    if moving {
        for c in &contacts.list {
            let (Some(i), Some(j)) = (state.index_of(c.a), state.index_of(c.b)) else {
                continue;
            };
            let mut contact = PairContact {
                time_of_contact: c.time_of_contact,
                points: c.points,
                normal: c.normal,
                depth_mm: c.depth_mm,
                leaf_pairs: c.leaf_pairs.clone(),
                end_overlap: c.end_overlap.clone(),
            };
            let (a, b) = if i < j {
                (i, j)
            } else {
                contact.points.swap(0, 1);
                contact.normal = -contact.normal;
                contact.leaf_pairs.iter_mut().for_each(|p| *p = (p.1, p.0));
                contact.end_overlap = contact.end_overlap.map(EndOverlap::swapped);
                (j, i)
            };
            found.push(Found { a, b, contact });
        }
    }
    if let Some(sim) = state.sim.as_mut() {
        sim.resolve(found);
    }
    write_motions(&state, &mut motions);
}

fn start_clock(mut clock: ResMut<CollisionClock>) {
    clock.0 = Some(std::time::Instant::now());
}

fn commit(
    mut state: ResMut<SimulationState>,
    mut status: ResMut<MovementStatus>,
    clock: Res<CollisionClock>,
    mut transforms: Query<&mut Transform, With<Tooth>>,
    mut motions: Query<&mut ToothMotion>,
    mut impacts: MessageWriter<ToothImpact>,
) {
    let state_ref = &mut *state;
    if state_ref.skip {
        return;
    }
    let Some(sim) = state_ref.sim.as_mut() else {
        return;
    };
    let collision_us = clock.0.map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e6);
    sim.commit();
    for (e, t) in state_ref.entities.iter().zip(&sim.teeth) {
        if let Ok(mut tf) = transforms.get_mut(*e)
            && (tf.translation != t.pose.translation || tf.rotation != t.pose.rotation)
        {
            tf.translation = t.pose.translation;
            tf.rotation = t.pose.rotation;
        }
        if let Ok(mut m) = motions.get_mut(*e)
            && !m.is_still()
        {
            m.0 = Motion::still(t.pose);
        }
    }
    for i in &sim.last.impacts {
        impacts.write(ToothImpact(i.clone()));
    }
    let new = MovementStatus {
        steps: sim.steps,
        moved: sim.last.moved,
        at_rest: sim.last.at_rest,
        days: sim.elapsed_days,
        collision_us,
    };
    if *status != new {
        *status = new;
    }
}
