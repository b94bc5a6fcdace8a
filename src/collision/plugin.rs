//! `CollisionPlugin`: the ECS layer over the collision core.
//!
//! Each step (in the simulation schedule, default `FixedUpdate`), for the teeth that have a
//! [`ToothCollider`] (their sphere tree is built) and are not extracted: the broad phase pairs them,
//! the narrow phase chosen in [`CollisionSettings`] tests the pairs, and the results go to the
//! [`Contacts`] resource, one [`ToothContact`] message per contact, and a [`ContactStarted`] entity
//! event (on the first tooth of the pair) when a pair starts touching. A tooth's motion over the
//! step is its [`ToothMotion`] (written by the movement stage), else it stands still at its
//! `Transform`. When nothing moves the broad and narrow phases do not run. A pair's query starts
//! from the overlap its contact found at the end of the last step, as a simulation's steps do
//! ([`crate::collision::query_knowing`]): a resting contact's overlap is not walked again.
//!
//! The systems sit in the chained [`CollisionSystems`] sets; the simulation schedule plugin (a
//! layer above) nests each in its stage of the simulation step.

use std::{
    collections::{HashMap, HashSet},
    sync::Arc,
};

use bevy::{
    ecs::{intern::Interned, schedule::ScheduleLabel},
    prelude::*,
};
use serde::{Deserialize, Serialize};

use super::{
    broad_phase::{BroadItem, candidate_pairs},
    motion::Motion,
    narrow_phase::{Body, EndOverlap, Method, query_knowing},
    shape::{Circle, CollisionShape},
};
use crate::{
    geometry::Pose,
    sphere_tree::ToothSphereTree,
    teeth::{Extracted, Tooth, ToothShape},
};

/// The collision plugin's systems, chained in this order; the simulation schedule puts each in
/// the stage of the simulation step named in brackets.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CollisionSystems {
    /// Colliders attached to teeth whose sphere tree is new (`Loads`).
    Prepare,
    /// Candidate pairs (`BroadPhase`).
    BroadPhase,
    /// Contacts of the candidate pairs (`NarrowPhase`).
    NarrowPhase,
}

/// Collision settings (RON-serialisable).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionSettings {
    /// Narrow-phase method.
    pub method: Method,
}

/// A tooth's motion over the current step.
#[derive(Component, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
pub struct ToothMotion(pub Motion);

/// What collision detection needs of a tooth: its compacted tree and bounding circle.
#[derive(Component, Clone, Debug)]
pub struct ToothCollider {
    /// Mesh and compact tree.
    pub shape: CollisionShape,
    /// Bounding circle in the x–z plane.
    pub circle: Circle,
    /// The tree this collider was made from (rebuilt when the tree changes).
    tree: Arc<crate::sphere_tree::SphereTree>,
}

/// The contact of two teeth in this step.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// First tooth.
    pub a: Entity,
    /// Second tooth.
    pub b: Entity,
    /// Time of contact in [0, 1] (1 for the discrete methods).
    pub time_of_contact: f32,
    /// Contact points (world): on `a`, then on `b`.
    pub points: [Vec3; 2],
    /// Unit normal from `a` towards `b`.
    pub normal: Vec3,
    /// Penetration (mm) when positive, minus the gap when negative.
    pub depth_mm: f32,
    /// Overlapping leaf pairs (compact-tree nodes of `a` and `b`).
    pub leaf_pairs: Vec<(u32, u32)>,
    /// The meshes' overlap at the end of the step, when the method found it
    /// ([`crate::collision::PairContact::end_overlap`]).
    pub end_overlap: Option<EndOverlap>,
}

/// The contacts found in the last step that ran collision detection.
#[derive(Resource, Clone, Debug, Default)]
pub struct Contacts {
    /// Every contact, in pair order.
    pub list: Vec<Contact>,
    /// Candidate pairs tested.
    pub pairs_tested: usize,
}

/// One contact, as a message.
#[derive(Message, Clone, Debug, PartialEq, Deref)]
pub struct ToothContact(pub Contact);

/// Fired on tooth `entity` when it starts touching `other`.
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq)]
pub struct ContactStarted {
    /// The first tooth of the pair.
    pub entity: Entity,
    /// The other tooth.
    pub other: Entity,
}

/// Candidate pairs of this step.
#[derive(Resource, Default)]
struct BroadPairs {
    pairs: Vec<(Entity, Entity)>,
}

/// Pairs touching in the previous step (for [`ContactStarted`]).
#[derive(Resource, Default)]
struct Touching(HashSet<(Entity, Entity)>);

/// Collision detection between teeth.
pub struct CollisionPlugin {
    schedule: Interned<dyn ScheduleLabel>,
}

impl CollisionPlugin {
    /// Collision detection in `schedule` (the simulation's: see [`crate::OrthoSimPlugins`]).
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
        }
    }
}

impl Default for CollisionPlugin {
    /// Collision detection in `FixedUpdate`.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

impl Plugin for CollisionPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<CollisionSettings>()
            .init_resource::<Contacts>()
            .init_resource::<BroadPairs>()
            .init_resource::<Touching>()
            .add_message::<ToothContact>()
            .configure_sets(
                self.schedule,
                (
                    CollisionSystems::Prepare,
                    CollisionSystems::BroadPhase,
                    CollisionSystems::NarrowPhase,
                )
                    .chain(),
            )
            .add_systems(
                self.schedule,
                (
                    attach_colliders.in_set(CollisionSystems::Prepare),
                    broad_phase
                        .run_if(something_moves)
                        .in_set(CollisionSystems::BroadPhase),
                    narrow_phase
                        .run_if(something_moves)
                        .in_set(CollisionSystems::NarrowPhase),
                ),
            );
    }
}

fn pose_of(t: &Transform) -> Pose {
    Pose::new(t.rotation, t.translation)
}

/// True when some tooth's motion this step is not standing still.
pub fn something_moves(motions: Query<&ToothMotion, Without<Extracted>>) -> bool {
    motions.iter().any(|m| !m.is_still())
}

fn attach_colliders(
    mut commands: Commands,
    teeth: Query<(
        Entity,
        &ToothShape,
        &ToothSphereTree,
        &Transform,
        Option<&ToothCollider>,
    )>,
) {
    for (entity, shape, tree, transform, collider) in &teeth {
        if collider.is_some_and(|c| Arc::ptr_eq(&c.tree, &tree.0)) {
            continue;
        }
        let pose = pose_of(transform);
        commands.entity(entity).try_insert(ToothCollider {
            shape: CollisionShape::new(shape.0.clone(), &tree.0),
            circle: Circle::of(&shape.0, &pose),
            tree: tree.0.clone(),
        });
    }
}

type ColliderQuery<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Tooth,
        &'static ToothCollider,
        &'static Transform,
        Option<&'static ToothMotion>,
    ),
    Without<Extracted>,
>;

fn motion_of(transform: &Transform, motion: Option<&ToothMotion>) -> Motion {
    motion.map_or_else(|| Motion::still(pose_of(transform)), |m| m.0)
}

fn broad_phase(teeth: ColliderQuery, mut out: ResMut<BroadPairs>) {
    let mut entities = Vec::new();
    let mut items = Vec::new();
    for (entity, tooth, collider, transform, motion) in &teeth {
        let Some(root) = collider.shape.tree.spheres.first() else {
            continue;
        };
        entities.push(entity);
        items.push(BroadItem {
            fdi: tooth.id,
            root: *root,
            local_box: collider.shape.local_box,
            motion: motion_of(transform, motion),
        });
    }
    let mut pairs = Vec::new();
    candidate_pairs(&items, &mut pairs);
    out.pairs = pairs
        .into_iter()
        .map(|(i, j)| (entities[i], entities[j]))
        .collect();
}

fn narrow_phase(
    mut commands: Commands,
    teeth: ColliderQuery,
    settings: Res<CollisionSettings>,
    pairs: Res<BroadPairs>,
    mut contacts: ResMut<Contacts>,
    mut touching: ResMut<Touching>,
    mut messages: MessageWriter<ToothContact>,
) {
    // Each pair's overlap at the end of the last step, for its query this step (which ignores
    // it if a tooth's mesh changed since).
    let last: HashMap<(Entity, Entity), EndOverlap> = (contacts.list.drain(..))
        .filter_map(|c| Some(((c.a, c.b), c.end_overlap?)))
        .collect();
    contacts.pairs_tested = pairs.pairs.len();
    let mut now = HashSet::new();
    for &(ea, eb) in &pairs.pairs {
        let (Ok(a), Ok(b)) = (teeth.get(ea), teeth.get(eb)) else {
            continue;
        };
        let body_a = Body {
            shape: &a.2.shape,
            circle: a.2.circle,
            motion: motion_of(a.3, a.4),
        };
        let body_b = Body {
            shape: &b.2.shape,
            circle: b.2.circle,
            motion: motion_of(b.3, b.4),
        };
        let known = last.get(&(ea, eb));
        let Some(hit) = query_knowing(settings.method, &body_a, &body_b, known) else {
            continue;
        };
        let contact = Contact {
            a: ea,
            b: eb,
            time_of_contact: hit.time_of_contact,
            points: hit.points,
            normal: hit.normal,
            depth_mm: hit.depth_mm,
            leaf_pairs: hit.leaf_pairs,
            end_overlap: hit.end_overlap,
        };
        if !touching.0.contains(&(ea, eb)) {
            commands.trigger(ContactStarted {
                entity: ea,
                other: eb,
            });
        }
        now.insert((ea, eb));
        messages.write(ToothContact(contact.clone()));
        contacts.list.push(contact);
    }
    touching.0 = now;
}
