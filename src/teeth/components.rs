//! ECS components of a tooth entity.

use std::sync::Arc;

use bevy::prelude::*;

use super::{
    case::WireModel,
    fdi::{Fdi, ToothKind},
    tooth_shape::ToothGeometry,
};

/// A tooth: its FDI number and kind. One entity per present tooth.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(opaque)]
#[require(Transform, Load)]
pub struct Tooth {
    /// FDI number.
    pub id: Fdi,
    /// Kind of tooth.
    pub kind: ToothKind,
}

/// The tooth's shared geometry (mesh, hierarchy, frame); teeth of one type share one.
#[derive(Component, Clone, Debug, Deref)]
pub struct ToothShape(pub Arc<ToothGeometry>);

/// Force (N) and torque (N·mm) on a tooth, world frame.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Reflect)]
pub struct Load {
    /// Force (N).
    pub force: Vec3,
    /// Torque (N·mm).
    pub torque: Vec3,
}

impl Load {
    /// Refuses loads that cannot be simulated: NaN or infinite components, or magnitudes beyond
    /// what a case file accepts ([`MAX_FORCE_N`](super::case::MAX_FORCE_N),
    /// [`MAX_TORQUE_NMM`](super::case::MAX_TORQUE_NMM)).
    pub fn check(&self) -> Result<(), String> {
        if !(self.force.is_finite() && self.torque.is_finite()) {
            return Err("a load with NaN or infinite components was refused".into());
        }
        let (f, t) = (self.force.length(), self.torque.length());
        if f > super::case::MAX_FORCE_N {
            return Err(format!(
                "a force of {f:.1} N was refused: at most {} N",
                super::case::MAX_FORCE_N
            ));
        }
        if t > super::case::MAX_TORQUE_NMM {
            return Err(format!(
                "a torque of {t:.1} N·mm was refused: at most {} N·mm",
                super::case::MAX_TORQUE_NMM
            ));
        }
        Ok(())
    }
}

/// The archwire model that decides how the tooth responds to its load.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Deref)]
pub struct Wire(pub WireModel);

/// The tooth moves as part of a group (a segment on a wire); the index of its group load.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Deref)]
pub struct LoadGroup(pub usize);

/// Marker: the tooth has been extracted (hidden, skipped by the simulation).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub struct Extracted;
