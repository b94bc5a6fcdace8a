//! A tooth's load: the force and torque on it, and the limits a load must keep.

use glam::Vec3;
use thiserror::Error;

use super::case::{MAX_FORCE_N, MAX_TORQUE_NMM};

/// Force (N) and torque (N·mm) on a tooth, world frame (with feature `ecs`, also a component of
/// the tooth's entity).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "ecs",
    derive(bevy::prelude::Component, bevy::prelude::Reflect)
)]
pub struct Load {
    /// Force (N).
    pub force: Vec3,
    /// Torque (N·mm).
    pub torque: Vec3,
}

/// A load that cannot be simulated.
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum LoadError {
    /// A component is NaN or infinite.
    #[error("a load with NaN or infinite components was refused")]
    NotFinite,
    /// The force is larger than a case accepts.
    #[error("a force of {0:.1} N was refused: at most {MAX_FORCE_N} N")]
    Force(f32),
    /// The torque is larger than a case accepts.
    #[error("a torque of {0:.1} N·mm was refused: at most {MAX_TORQUE_NMM} N·mm")]
    Torque(f32),
}

impl Load {
    /// Refuses loads that cannot be simulated: NaN or infinite components, or magnitudes beyond
    /// what a case file accepts ([`MAX_FORCE_N`], [`MAX_TORQUE_NMM`]).
    ///
    /// # Errors
    /// The first [`LoadError`] that applies.
    pub fn check(&self) -> Result<(), LoadError> {
        if !(self.force.is_finite() && self.torque.is_finite()) {
            return Err(LoadError::NotFinite);
        }
        let (f, t) = (self.force.length(), self.torque.length());
        if f > MAX_FORCE_N {
            return Err(LoadError::Force(f));
        }
        if t > MAX_TORQUE_NMM {
            return Err(LoadError::Torque(t));
        }
        Ok(())
    }
}
