//! Collision detection between moving teeth: the heart of orthosim.
//!
//! Engine-free core: [`motion`] (a step's start and end pose and the bounds rotation needs),
//! [`shape`] (a tooth's compact sphere tree and bounding circle), [`broad_phase`] (arch neighbours and
//! opposing teeth whose swept root spheres can meet), [`narrow_phase`] (circles, spheres,
//! continuous and exact, with their guarantees), [`closing`] (whether a contact's teeth close in,
//! per method, with its tolerances) and [`bench`](mod@bench) (the `orthosim bench` measurements). ECS layer
//! (feature `ecs`): `CollisionPlugin`.

pub mod bench;
pub mod broad_phase;
pub mod closing;
pub mod motion;
pub mod narrow_phase;
#[cfg(feature = "ecs")]
mod plugin;
pub(crate) mod sampling;
pub mod shape;

pub use motion::Motion;
pub use narrow_phase::{Body, EndOverlap, KnownInside, Method, PairContact, query, query_knowing};
#[cfg(feature = "ecs")]
pub use plugin::{
    CollisionPlugin, CollisionSettings, CollisionSystems, Contact, ContactStarted, Contacts,
    ToothCollider, ToothContact, ToothMotion, something_moves,
};
pub use shape::{Circle, CollisionShape, CompactTree, collision_shapes};
