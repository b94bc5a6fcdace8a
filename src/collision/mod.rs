//! Collision detection between moving teeth: the heart of orthosim.
//!
//! Engine-free core: [`motion`] (a step's start and end pose and the bounds rotation needs),
//! [`shape`] (a tooth's compact sphere tree and bounding circle), [`broad_phase`] (arch neighbours and
//! opposing teeth whose swept root spheres can meet) and [`narrow_phase`] (circles, spheres,
//! continuous and exact, with their guarantees). ECS layer: [`plugin::CollisionPlugin`].

pub mod bench;
pub mod broad_phase;
pub mod motion;
pub mod narrow_phase;
pub mod plugin;
pub mod shape;

pub use motion::Motion;
pub use narrow_phase::{Body, Method, PairContact, query};
pub use plugin::{
    CollisionPlugin, CollisionSettings, Contact, ContactStarted, Contacts, SimulationSystems,
    ToothCollider, ToothContact, ToothMotion,
};
pub use shape::{Circle, CollisionShape, CompactTree, collision_shapes};
