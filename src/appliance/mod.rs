//! Appliances: what delivers the forces that move teeth. Brackets and tubes bonded on the crowns
//! hold an archwire; the wire, bent out of its passive arch form by the teeth's malalignment,
//! pushes back on each bracket with a force and a moment that fade as the teeth align.
//!
//! Engine-free (no ECS): the wire's cross-sections ([`section`]), alloys ([`material`]), the
//! elastic rod and its equilibrium in the slots ([`rod`]), the slots' friction ([`friction`]), and the banded solver it uses; the
//! alveolar envelope whose cortical plates hold the roots ([`bone`]).

pub mod archwire;
pub mod banded;
pub mod bench;
pub mod bone;
pub mod bone_mesh;
pub mod bracket;
pub mod chain;
pub mod coil;
pub mod elastic;
pub mod friction;
pub mod material;
pub mod prescription;
pub mod rod;
pub mod section;

pub use archwire::{ArchForm, ArchSize, Laid, fit_form, lay, nearest_on_form};
pub use bone::{AlveolarEnvelope, Plate, PlateContact, RootedTooth};
pub use bracket::{Bracket, Slot, ToothAxes, binding_angle_rad, torque_play_rad};
pub use material::{Transformation, WireMaterial};
pub use prescription::{BracketAngles, Prescription};
pub use rod::{Equilibrium, Holder, NodeLoad, Reaction, Rod, RodNode, Settings};
pub use section::{SectionProperties, SizeError, WireSize};
