//! orthosim inside another Bevy app, without a window: `MinimalPlugins` + `OrthoSimPlugins`, the
//! paper's case 1 (first premolars extracted, the first molars drawn mesially) run until its teeth
//! rest, and a system of the app's own, ordered after `SimulationSystems::Commit`, that reads
//! each step's result and prints which teeth moved.
//!
//! ```sh
//! cargo run --release --example headless
//! ```

use bevy::prelude::*;
use orthosim::prelude::*;

fn main() -> AppExit {
    App::new()
        .add_plugins((
            MinimalPlugins,
            TransformPlugin,
            // One simulation step per app update: a batch run needs no clock.
            OrthoSimPlugins::new(Update),
        ))
        // Medial sphere trees, as the `simulate` command uses.
        .insert_resource(SphereTreeSettings(TreeSettings::with_method(
            TreeMethod::Medial,
        )))
        .add_systems(Startup, |mut load: MessageWriter<LoadCase>| {
            load.write(LoadCase("case1".into()));
        })
        .add_systems(Update, report_at_rest.after(SimulationSystems::Commit))
        .run()
}

/// Once the teeth rest (or the case fails to load), prints how far each tooth's crown centre
/// moved from where the case placed it and ends the app.
fn report_at_rest(
    status: Res<MovementStatus>,
    case: Option<Res<ActiveCase>>,
    teeth: Query<(&Tooth, &ToothShape, &Transform)>,
    mut failed: MessageReader<CaseLoadFailed>,
    mut exit: MessageWriter<AppExit>,
) {
    if let Some(e) = failed.read().next() {
        eprintln!("{}", e.0);
        exit.write(AppExit::error());
        return;
    }
    let Some(case) = case else {
        return;
    };
    if !status.at_rest && status.steps < 20_000 {
        return;
    }
    println!(
        "case {}: {} after {} steps",
        case.case.case.name,
        if status.at_rest {
            "at rest"
        } else {
            "still moving"
        },
        status.steps
    );
    let mut moved: Vec<(Fdi, f32)> = teeth
        .iter()
        .filter_map(|(tooth, shape, transform)| {
            let placed = case.tooth(tooth.id)?;
            let c = shape.frame.crown_centre;
            let travel = transform
                .transform_point(c)
                .distance(placed.pose.transform_point(c));
            (travel > MOVED_MM).then_some((tooth.id, travel))
        })
        .collect();
    moved.sort_by_key(|m| m.0);
    for (fdi, mm) in moved {
        println!("tooth {fdi} moved {mm:.2} mm");
    }
    exit.write(AppExit::Success);
}
