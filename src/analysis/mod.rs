//! Analysis: measures computed from placed teeth (no ECS needed).

pub mod inspect;

pub use inspect::{InspectReport, inspect};
