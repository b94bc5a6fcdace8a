//! `orthosim screenshot`: the real window on a case, simulated for some frames once its trees are
//! built, saved as a PNG.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
#[cfg(feature = "viewer")]
use orthosim::occlusion_view::{CameraPreset, Overlay, Roots};
use orthosim::{collision::Method, sphere_tree::TreeMethod};

use super::choice;

/// `screenshot`'s arguments.
#[derive(Args, Debug)]
pub struct ScreenshotArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Camera view.
    #[cfg(feature = "viewer")]
    #[arg(long, value_parser = choice::camera(), default_value_t = CameraPreset::Frontal)]
    pub view: CameraPreset,
    /// Frames to run once the simulation is ready (trees built).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frames: u32,
    /// Sphere-tree builder (depth 4, branching 8; medial from the user's tree cache).
    #[arg(long, value_parser = choice::tree_method(), default_value_t = TreeMethod::Medial)]
    pub tree: TreeMethod,
    /// Overlays: `spheres:LEVEL` (a sphere-tree level, 0 = root), `contacts` (overlapping leaf
    /// spheres and contact points of the step), `occlusion-map` (surfaces coloured by their
    /// distance to the opposing arch) or `circles` (bounding circles, with `--algorithm
    /// circles`); repeat for several.
    #[cfg(feature = "viewer")]
    #[arg(long)]
    pub overlay: Vec<Overlay>,
    /// Narrow-phase method of the simulation.
    #[arg(long, value_parser = choice::method(), default_value_t = Method::Continuous)]
    pub algorithm: Method,
    /// How roots are drawn: translucent, solid or hidden.
    #[cfg(feature = "viewer")]
    #[arg(long, default_value = "translucent")]
    pub roots: Roots,
    /// Hide an arch (`upper` or `lower`), e.g. to see the other one's occlusal surface.
    #[arg(long, value_parser = ["upper", "lower"])]
    pub hide: Vec<String>,
    /// Show the panel and the teeth window as the viewer does
    #[arg(long)]
    pub panel: bool,
    /// Select a tooth (FDI number) in the teeth window, as a click would; repeat for several
    #[arg(long, value_parser = clap::value_parser!(u8).range(11..=48))]
    pub select: Vec<u8>,
    /// Plan the case in the Plan window once it is ready and show this stage (the last when
    /// beyond it), the teeth coloured by what they still have to move (implies `--panel`).
    #[arg(long)]
    pub plan: Option<u32>,
    /// With `--plan`: show the target being edited, the first `--select`ed tooth with its
    /// handles and its gaps to the teeth near it.
    #[arg(long, requires = "plan")]
    pub edit_target: bool,
    /// Open the help window (implies `--panel`).
    #[arg(long)]
    pub show_help: bool,
    /// The PNG file to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// Takes the screenshot: checks the case and the output first, then runs the window until the
/// picture is written.
#[cfg(feature = "viewer")]
pub fn run(args: ScreenshotArgs) -> Result<()> {
    use std::sync::{Arc, Mutex};

    use orthosim::{
        collision::CollisionSettings,
        occlusion_view::{OcclusionViewPlugin, Overlays, ScreenshotOutcome, ScreenshotPlugin},
        teeth::Case,
    };
    Case::resolve(&args.case)?;
    if args.out.extension().and_then(|e| e.to_str()) != Some("png") {
        anyhow::bail!("{}: the screenshot must be a .png file", args.out.display());
    }
    orthosim::io::check_output(&args.out, &[std::path::Path::new(&args.case)])?;
    let shared = Arc::new(Mutex::new(ScreenshotOutcome::default()));
    let overlays = Overlays {
        hide_upper: args.hide.iter().any(|h| h == "upper"),
        hide_lower: args.hide.iter().any(|h| h == "lower"),
        roots: args.roots,
        ..args
            .overlay
            .iter()
            .fold(Overlays::default(), |o, x| o.with(*x))
    };
    let mut app = super::view::window_app(&args.case, args.tree);
    app.insert_resource(CollisionSettings {
        method: args.algorithm,
    })
    .add_plugins(OcclusionViewPlugin {
        initial_view: args.view,
        overlays,
        ..Default::default()
    })
    .insert_resource(PreSelect(args.select.clone()))
    .add_systems(bevy::prelude::Update, pre_select)
    .add_plugins(ScreenshotPlugin {
        path: args.out.clone(),
        frames: args.frames,
        outcome: shared.clone(),
    });
    if args.panel || args.plan.is_some() || args.show_help {
        app.add_plugins(orthosim::ui::OrthoSimUiPlugin);
    }
    if args.show_help {
        app.insert_resource(orthosim::ui::HelpOpen(true));
    }
    if let Some(stage) = args.plan {
        app.insert_resource(orthosim::ui::PlanRequest {
            stage,
            edit: args.edit_target,
        });
    }
    app.run();
    let outcome = shared.lock().unwrap_or_else(|p| p.into_inner()).clone();
    match outcome.error {
        Some(e) => anyhow::bail!("{e}"),
        None if outcome.written => {
            println!("wrote {}", args.out.display());
            Ok(())
        }
        None => anyhow::bail!("the window closed before the screenshot was taken"),
    }
}

/// Without the viewer: says so.
/// Teeth to select once they are spawned.
#[cfg(feature = "viewer")]
#[derive(bevy::prelude::Resource)]
struct PreSelect(Vec<u8>);

#[cfg(feature = "viewer")]
fn pre_select(
    mut wanted: bevy::prelude::ResMut<PreSelect>,
    teeth: bevy::prelude::Query<(bevy::prelude::Entity, &orthosim::teeth::Tooth)>,
    mut selection: bevy::prelude::ResMut<orthosim::occlusion_view::Selection>,
) {
    if wanted.0.is_empty() {
        return;
    }
    let found: Vec<_> = wanted
        .0
        .iter()
        .filter_map(|n| {
            teeth
                .iter()
                .find(|(_, t)| t.id.number() == *n)
                .map(|(e, _)| e)
        })
        .collect();
    if found.len() == wanted.0.len() {
        for e in found {
            selection.pick(e, true);
        }
        wanted.0.clear();
    }
}

#[cfg(not(feature = "viewer"))]
pub fn run(args: ScreenshotArgs) -> Result<()> {
    let _ = (
        args.frames,
        args.tree,
        args.algorithm,
        args.hide,
        args.out,
        args.panel,
        args.plan,
        args.edit_target,
        args.show_help,
        args.select,
    );
    orthosim::teeth::Case::resolve(&args.case)?;
    super::view::no_viewer()
}
