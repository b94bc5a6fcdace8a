//! `orthosim view` (and `orthosim` with no subcommand): the 3D viewer on a case.

use anyhow::Result;
use clap::Args;
#[cfg(feature = "viewer")]
use orthosim::occlusion_view::CameraPreset;
use orthosim::teeth::Case;

#[cfg(feature = "viewer")]
use super::choice;

/// `view`'s arguments.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Camera view at start-up (keys 1–5 switch views in the window).
    #[cfg(feature = "viewer")]
    #[arg(long, value_parser = choice::camera(), default_value_t = CameraPreset::Frontal)]
    pub camera: CameraPreset,
}

impl Default for ViewArgs {
    /// The viewer on the default case, from the front.
    fn default() -> Self {
        Self {
            case: "normal".into(),
            #[cfg(feature = "viewer")]
            camera: CameraPreset::default(),
        }
    }
}

/// Opens the viewer (the case is checked first, so a bad file fails before a window opens).
#[cfg(feature = "viewer")]
pub fn run(args: ViewArgs) -> Result<()> {
    use orthosim::{
        occlusion_view::OcclusionViewPlugin, sphere_tree::TreeMethod, ui::OrthoSimUiPlugin,
    };
    Case::resolve(&args.case)?;
    window_app(&args.case, TreeMethod::Medial)
        .add_plugins(OcclusionViewPlugin {
            initial_view: args.camera,
            ..Default::default()
        })
        .add_plugins(OrthoSimUiPlugin)
        .run();
    Ok(())
}

/// Without the viewer: says so.
#[cfg(not(feature = "viewer"))]
pub fn run(args: ViewArgs) -> Result<()> {
    Case::resolve(&args.case)?;
    no_viewer()
}

/// The error of a window command in a build without the `viewer` feature.
#[cfg(not(feature = "viewer"))]
pub fn no_viewer() -> Result<()> {
    anyhow::bail!(
        "this build has no viewer (built without the `viewer` feature); use a headless subcommand, see --help"
    )
}

/// The window commands' app: default plugins with a titled window and the simulation plugins on
/// `case`, trees from the user's cache.
#[cfg(feature = "viewer")]
pub fn window_app(case: &str, tree: orthosim::sphere_tree::TreeMethod) -> bevy::prelude::App {
    use bevy::prelude::*;
    use orthosim::{
        OrthoSimPlugins,
        sphere_tree::{SphereTreeCache, SphereTreeSettings, TreeCache, TreeSettings},
        teeth::TeethModelPlugin,
    };
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: format!("orthosim: {case}"),
            ..default()
        }),
        ..default()
    }))
    .add_plugins(OrthoSimPlugins::default().set(TeethModelPlugin {
        initial_case: Some(case.to_owned()),
    }))
    .insert_resource(SphereTreeCache(TreeCache::user_default()))
    .insert_resource(SphereTreeSettings(TreeSettings::with_method(tree)));
    app
}
