//! Screenshots of the real window after a number of simulated frames (`orthosim screenshot`).
//!
//! Frames are counted once the case is simulating (its trees built); then the primary window is
//! captured into a temporary file beside the target, renamed into place when complete, and the app
//! exits. A case that fails to load ends the app with an error.

use std::{
    path::PathBuf,
    sync::{Arc, Mutex},
};

use bevy::{
    prelude::*,
    render::view::screenshot::{Screenshot, save_to_disk},
};

use crate::{movement::SimulationState, teeth::CaseLoadFailed};

/// Captures the window after `frames` frames of simulation and exits.
pub struct ScreenshotPlugin {
    /// Where to write the PNG.
    pub path: PathBuf,
    /// Frames to run once the simulation is ready.
    pub frames: u32,
    /// Where the outcome is reported (the app's world is gone once it has run).
    pub outcome: Arc<Mutex<ScreenshotOutcome>>,
}

/// Shared outcome of the screenshot job.
#[derive(Resource, Clone, Deref)]
struct Shared(Arc<Mutex<ScreenshotOutcome>>);

/// The outcome, readable after the app exits.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ScreenshotOutcome {
    /// The error that stopped it, if any.
    pub error: Option<String>,
    /// The file was written.
    pub written: bool,
}

#[derive(Resource)]
struct Job {
    path: PathBuf,
    tmp: PathBuf,
    frames: u32,
    counted: u32,
    requested: bool,
    waited: u32,
}

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        let name = self
            .path
            .file_name()
            .map_or_else(|| "screenshot".into(), |n| n.to_string_lossy().into_owned());
        let tmp = self
            .path
            .with_file_name(format!(".{name}.tmp-{}.png", std::process::id()));
        app.insert_resource(Job {
            path: self.path.clone(),
            tmp,
            frames: self.frames,
            counted: 0,
            requested: false,
            waited: 0,
        })
        .insert_resource(Shared(self.outcome.clone()))
        .add_systems(Update, (fail_on_bad_case, capture).chain());
    }
}

fn fail_on_bad_case(
    mut failed: MessageReader<CaseLoadFailed>,
    shared: Res<Shared>,
    mut exit: MessageWriter<AppExit>,
) {
    if let Some(e) = failed.read().next() {
        let mut outcome = shared.lock().unwrap_or_else(|p| p.into_inner());
        outcome.error = Some(e.0.to_string());
        exit.write(AppExit::error());
    }
}

fn capture(
    mut commands: Commands,
    mut job: ResMut<Job>,
    sim: Res<SimulationState>,
    shared: Res<Shared>,
    mut exit: MessageWriter<AppExit>,
) {
    let mut outcome = shared.lock().unwrap_or_else(|p| p.into_inner());
    if job.requested {
        job.waited += 1;
        if job.waited > 600 && !job.tmp.exists() {
            outcome.error = Some("the window could not be captured".into());
            exit.write(AppExit::error());
            return;
        }
        if job.tmp.exists() {
            match std::fs::rename(&job.tmp, &job.path) {
                Ok(()) => outcome.written = true,
                Err(e) => {
                    let _ = std::fs::remove_file(&job.tmp);
                    outcome.error = Some(format!("{}: {e}", job.path.display()));
                }
            }
            exit.write(if outcome.written {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
        return;
    }
    if sim.sim.is_none() {
        return;
    }
    job.counted += 1;
    if job.counted >= job.frames {
        job.requested = true;
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(job.tmp.clone()));
    }
}
