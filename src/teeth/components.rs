//! ECS components of a tooth entity (feature `ecs`); its [`Load`] is a core type that is a
//! component too.

use std::sync::Arc;

use bevy::prelude::*;

use super::{
    case::WireModel,
    fdi::{Fdi, ToothKind},
    load::Load,
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

/// The archwire model that decides how the tooth responds to its load.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Deref)]
pub struct Wire(pub WireModel);

/// The tooth moves as part of a group (a segment on a wire); the index of its group load.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Deref)]
pub struct LoadGroup(pub usize);

/// Marker: the tooth has been extracted (hidden, skipped by the simulation).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub struct Extracted;
