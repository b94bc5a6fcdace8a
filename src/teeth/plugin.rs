//! `TeethModelPlugin`: loads patient cases and spawns one entity per present tooth.
//!
//! Loading is asynchronous: a [`LoadCase`] message starts building the case's dentition on the
//! async compute pool (tooth meshes and the arch arrangement are cached per process); when it is
//! ready, the previous teeth are despawned, the new ones spawned, [`ActiveCase`] replaced and a
//! [`CaseLoaded`] message written. A case that fails to load leaves the scene as it was and writes a
//! [`CaseLoadFailed`] message with the one-line error.

use std::sync::Arc;

use bevy::{
    prelude::*,
    tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future},
};

use super::{
    case::{Case, CaseError},
    components::{Extracted, LoadGroup, Tooth, ToothShape, Wire},
    dentition::Dentition,
    load::Load,
};

/// Ask for a case to be loaded: a built-in name (`normal`, `case1`…) or a path to a .ron file.
#[derive(Message, Clone, Debug, PartialEq, Eq)]
pub struct LoadCase(pub String);

/// A case finished loading and its teeth are spawned.
#[derive(Message, Clone, Debug, PartialEq, Eq)]
pub struct CaseLoaded {
    /// Case name.
    pub name: String,
    /// Number of tooth entities spawned.
    pub teeth: usize,
}

/// A case could not be loaded.
#[derive(Message, Clone, Debug, PartialEq)]
pub struct CaseLoadFailed(pub CaseError);

/// The case whose teeth are in the world.
#[derive(Resource, Clone, Debug, Deref)]
pub struct ActiveCase(pub Arc<Dentition>);

/// A case being built in the background.
#[derive(Resource)]
struct PendingCase(Task<Result<Dentition, CaseError>>);

/// System sets of the teeth model, in `Update`.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
pub enum TeethModelSystems {
    /// Start loading requested cases.
    Request,
    /// Spawn teeth of a finished case.
    Spawn,
}

/// Loads cases and keeps one entity per present tooth.
#[derive(Default)]
pub struct TeethModelPlugin {
    /// A case to load at start-up (name or path).
    pub initial_case: Option<String>,
}

impl Plugin for TeethModelPlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<LoadCase>()
            .add_message::<CaseLoaded>()
            .add_message::<CaseLoadFailed>()
            .configure_sets(
                Update,
                (TeethModelSystems::Request, TeethModelSystems::Spawn).chain(),
            )
            .add_systems(
                Update,
                (
                    start_loading.in_set(TeethModelSystems::Request),
                    finish_loading
                        .run_if(resource_exists::<PendingCase>)
                        .in_set(TeethModelSystems::Spawn),
                ),
            );
        if let Some(case) = &self.initial_case {
            app.world_mut().write_message(LoadCase(case.clone()));
        }
    }
}

/// Starts building the last requested case (earlier requests in the same frame are superseded).
fn start_loading(mut commands: Commands, mut requests: MessageReader<LoadCase>) {
    let Some(LoadCase(name)) = requests.read().last().cloned() else {
        return;
    };
    let task = AsyncComputeTaskPool::get()
        .spawn(async move { Case::resolve(&name).and_then(Dentition::build) });
    commands.insert_resource(PendingCase(task));
}

/// Replaces the teeth when the pending case is ready.
fn finish_loading(
    mut commands: Commands,
    mut pending: ResMut<PendingCase>,
    old: Query<Entity, With<Tooth>>,
    mut loaded: MessageWriter<CaseLoaded>,
    mut failed: MessageWriter<CaseLoadFailed>,
) {
    let Some(result) = block_on(future::poll_once(&mut pending.0)) else {
        return;
    };
    commands.remove_resource::<PendingCase>();
    let dentition = match result {
        Ok(d) => d,
        Err(e) => {
            error!("{e}");
            failed.write(CaseLoadFailed(e));
            return;
        }
    };
    for e in &old {
        commands.entity(e).despawn();
    }
    for t in &dentition.teeth {
        let mut entity = commands.spawn((
            Name::new(format!("tooth {}", t.fdi)),
            Tooth {
                id: t.fdi,
                kind: t.fdi.kind(),
            },
            ToothShape(t.geometry.clone()),
            Transform {
                translation: t.pose.translation,
                rotation: t.pose.rotation,
                scale: Vec3::ONE,
            },
            Load {
                force: t.force,
                torque: t.torque,
            },
            Wire(t.wire),
        ));
        if t.extracted {
            entity.insert(Extracted);
        }
        if let Some(g) = t.group {
            entity.insert(LoadGroup(g));
        }
    }
    loaded.write(CaseLoaded {
        name: dentition.case.case.name.clone(),
        teeth: dentition.teeth.len(),
    });
    info!(
        "loaded case '{}' ({} teeth)",
        dentition.case.case.name,
        dentition.teeth.len()
    );
    commands.insert_resource(ActiveCase(Arc::new(dentition)));
}
