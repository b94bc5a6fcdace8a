//! `SphereTreePlugin`: builds each distinct tooth shape's sphere tree in the background and attaches
//! it to every tooth with that shape.
//!
//! A tooth without a [`ToothSphereTree`] is not ready: collision systems must skip it rather than
//! report a result. Changing [`SphereTreeSettings`] drops every tree and rebuilds. With a
//! [`SphereTreeCache`] directory set (the viewer sets the user's cache directory), trees are read
//! from and written to disk (see [`super::cache`]).

use std::{collections::HashMap, sync::Arc};

use bevy::{
    prelude::*,
    tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future},
};

use super::{
    build::{TreeBuildError, TreeSettings},
    cache::TreeCache,
    tree::SphereTree,
};
use crate::teeth::{ToothGeometry, ToothShape};

/// The settings trees are built with.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct SphereTreeSettings(pub TreeSettings);

/// Where built trees are cached on disk; None (the default) builds every tree afresh.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq, Deref, DerefMut)]
pub struct SphereTreeCache(pub Option<TreeCache>);

/// How far the background builds have come, counted in distinct tooth shapes (teeth of one type
/// share a tree), for progress readouts.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SphereTreeProgress {
    /// Shapes whose tree is built.
    pub built: usize,
    /// Shapes whose tree is being built.
    pub pending: usize,
    /// Shapes whose tree could not be built.
    pub failed: usize,
}

impl SphereTreeProgress {
    /// True while some tree is being built.
    pub fn busy(&self) -> bool {
        self.pending > 0
    }

    /// Fraction of the started builds that have finished (1 when nothing was started).
    pub fn fraction(&self) -> f32 {
        let all = self.built + self.pending + self.failed;
        if all == 0 {
            1.0
        } else {
            (self.built + self.failed) as f32 / all as f32
        }
    }
}

/// A tooth's sphere tree (shared by teeth of the same shape).
#[derive(Component, Clone, Debug, Deref)]
pub struct ToothSphereTree(pub Arc<SphereTree>);

/// A tree being built on the async compute pool.
type BuildTask = Task<Result<SphereTree, TreeBuildError>>;

/// Trees built or being built, keyed by shape (the `Arc` is held so the key stays unique).
#[derive(Resource, Default)]
struct TreeStore {
    built: HashMap<usize, (Arc<ToothGeometry>, Arc<SphereTree>)>,
    pending: HashMap<usize, (Arc<ToothGeometry>, BuildTask)>,
    failed: HashMap<usize, Arc<ToothGeometry>>,
}

/// System sets of the sphere-tree plugin, in `Update`.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
pub enum SphereTreeSystems {
    /// Drop trees when the settings change.
    Invalidate,
    /// Start builds and attach finished trees.
    Build,
}

/// Builds sphere trees for tooth shapes in the background.
#[derive(Default)]
pub struct SphereTreePlugin;

impl Plugin for SphereTreePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SphereTreeSettings>()
            .init_resource::<SphereTreeCache>()
            .init_resource::<TreeStore>()
            .init_resource::<SphereTreeProgress>()
            .configure_sets(
                Update,
                (SphereTreeSystems::Invalidate, SphereTreeSystems::Build).chain(),
            )
            .add_systems(
                Update,
                (
                    invalidate_on_settings_change
                        .run_if(resource_changed::<SphereTreeSettings>)
                        .in_set(SphereTreeSystems::Invalidate),
                    (finish_builds, start_builds_and_attach, count_progress)
                        .chain()
                        .in_set(SphereTreeSystems::Build),
                ),
            );
    }
}

fn key(shape: &ToothShape) -> usize {
    Arc::as_ptr(&shape.0) as usize
}

fn invalidate_on_settings_change(
    mut commands: Commands,
    mut store: ResMut<TreeStore>,
    teeth: Query<Entity, With<ToothSphereTree>>,
) {
    *store = TreeStore::default();
    for e in &teeth {
        commands.entity(e).try_remove::<ToothSphereTree>();
    }
}

fn finish_builds(mut store: ResMut<TreeStore>) {
    let mut finished = Vec::new();
    for (k, (_, task)) in store.pending.iter_mut() {
        if let Some(result) = block_on(future::poll_once(task)) {
            finished.push((*k, result));
        }
    }
    for (k, result) in finished {
        let Some((geometry, _)) = store.pending.remove(&k) else {
            continue;
        };
        match result {
            Ok(tree) => {
                store.built.insert(k, (geometry, Arc::new(tree)));
            }
            Err(e) => {
                error!(
                    "sphere tree of a {:?} could not be built: {e}",
                    geometry.kind
                );
                store.failed.insert(k, geometry);
            }
        }
    }
}

fn count_progress(store: Res<TreeStore>, mut progress: ResMut<SphereTreeProgress>) {
    let now = SphereTreeProgress {
        built: store.built.len(),
        pending: store.pending.len(),
        failed: store.failed.len(),
    };
    if *progress != now {
        *progress = now;
    }
}

fn start_builds_and_attach(
    mut commands: Commands,
    mut store: ResMut<TreeStore>,
    settings: Res<SphereTreeSettings>,
    cache: Res<SphereTreeCache>,
    teeth: Query<(Entity, &ToothShape), Without<ToothSphereTree>>,
) {
    for (entity, shape) in &teeth {
        let k = key(shape);
        if let Some((_, tree)) = store.built.get(&k) {
            // The tooth may be despawned by a case reload later this frame.
            commands
                .entity(entity)
                .try_insert(ToothSphereTree(tree.clone()));
        } else if !store.pending.contains_key(&k) && !store.failed.contains_key(&k) {
            let geometry = shape.0.clone();
            let settings = settings.0;
            let job = geometry.clone();
            let cache = cache.0.clone();
            let task = AsyncComputeTaskPool::get().spawn(async move {
                match cache {
                    Some(cache) => cache
                        .load_or_build(&settings, &job.mesh, &job.bvh)
                        .map(|(tree, _)| tree),
                    None => settings.build(&job.mesh, &job.bvh),
                }
            });
            store.pending.insert(k, (geometry, task));
        }
    }
}
