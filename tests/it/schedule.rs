//! The simulation schedule: one chain of stages that every plugin's sets sit in, whichever plugin
//! is disabled or replaced, and in whichever schedule the simulation runs.

use bevy::{
    app::PluginGroupBuilder,
    ecs::schedule::{InternedSystemSet, ScheduleLabel, SingleThreadedExecutor},
    prelude::*,
};
use orthosim::prelude::*;

/// The names of the probes that ran, in order.
#[derive(Resource, Default)]
struct Ran(Vec<&'static str>);

fn probe(name: &'static str) -> impl FnMut(ResMut<Ran>) {
    move |mut ran: ResMut<Ran>| ran.0.push(name)
}

/// Where probes go, in the order they must run.
fn stages() -> Vec<(&'static str, InternedSystemSet)> {
    vec![
        ("loads", SimulationSystems::Loads.intern()),
        ("motion", SimulationSystems::Motion.intern()),
        ("broad phase", SimulationSystems::BroadPhase.intern()),
        ("narrow phase", SimulationSystems::NarrowPhase.intern()),
        ("resolve", SimulationSystems::Resolve.intern()),
        ("commit", SimulationSystems::Commit.intern()),
    ]
}

fn collision_sets() -> Vec<(&'static str, InternedSystemSet)> {
    vec![
        ("collision prepare", CollisionSystems::Prepare.intern()),
        ("collision broad", CollisionSystems::BroadPhase.intern()),
        ("collision narrow", CollisionSystems::NarrowPhase.intern()),
    ]
}

fn movement_sets() -> Vec<(&'static str, InternedSystemSet)> {
    vec![
        ("movement start", MovementSystems::Start.intern()),
        ("movement loads", MovementSystems::Loads.intern()),
        ("movement propose", MovementSystems::Propose.intern()),
        ("movement clock", MovementSystems::Clock.intern()),
        ("movement resolve", MovementSystems::Resolve.intern()),
        ("movement commit", MovementSystems::Commit.intern()),
    ]
}

/// The order the plugin sets' probes must run in.
fn expected(movement: bool) -> Vec<&'static str> {
    if movement {
        vec![
            "collision prepare",
            "movement start",
            "movement loads",
            "movement propose",
            "movement clock",
            "collision broad",
            "collision narrow",
            "movement resolve",
            "movement commit",
            "user",
        ]
    } else {
        vec![
            "collision prepare",
            "collision broad",
            "collision narrow",
            "user",
        ]
    }
}

/// The stages' probes in order.
fn expected_stages() -> Vec<&'static str> {
    let mut order: Vec<&str> = stages().iter().map(|s| s.0).collect();
    order.push("user");
    order
}

/// Runs one step of `schedule` with a probe in each of `sets` and one after the `Commit` stage,
/// each added after the ones that must follow it (so only the sets' ordering can put them right),
/// on the single-threaded executor; returns the probes in the order they ran.
fn run_probes(
    plugins: PluginGroupBuilder,
    schedule: impl ScheduleLabel + Clone,
    sets: &[(&'static str, InternedSystemSet)],
) -> Vec<&'static str> {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, plugins))
        .init_resource::<Ran>();
    app.edit_schedule(schedule.clone(), |s| {
        s.set_executor(SingleThreadedExecutor::new());
    });
    app.add_systems(
        schedule.clone(),
        probe("user").after(SimulationSystems::Commit),
    );
    for (name, set) in sets.iter().rev() {
        app.add_systems(schedule.clone(), probe(name).in_set(*set));
    }
    app.finish();
    app.cleanup();
    app.world_mut().run_schedule(schedule);
    std::mem::take(&mut app.world_mut().resource_mut::<Ran>().0)
}

fn all_sets(movement: bool) -> Vec<(&'static str, InternedSystemSet)> {
    let mut sets = collision_sets();
    if movement {
        sets.extend(movement_sets());
    }
    // In their expected order (`run_probes` adds them in reverse).
    let order = expected(movement);
    sets.sort_by_key(|(n, _)| order.iter().position(|o| o == n));
    sets
}

#[test]
fn without_the_chain_the_probes_run_out_of_order() {
    // The control: the same probes in sets nobody orders run in another order than the one the
    // tests below expect, so those tests see the plugins' ordering, not the executor's habits.
    #[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
    struct Loose(&'static str);
    let names = expected(true);
    let sets: Vec<(&'static str, InternedSystemSet)> =
        names.iter().map(|n| (*n, Loose(n).intern())).collect();
    let mut app = App::new();
    app.add_plugins(MinimalPlugins).init_resource::<Ran>();
    app.edit_schedule(FixedUpdate, |s| {
        s.set_executor(SingleThreadedExecutor::new());
    });
    for (name, set) in sets.iter().rev() {
        app.add_systems(FixedUpdate, probe(name).in_set(*set));
    }
    app.finish();
    app.cleanup();
    app.world_mut().run_schedule(FixedUpdate);
    assert_ne!(app.world().resource::<Ran>().0, names);
}

#[test]
fn every_plugin_set_runs_inside_its_stage_in_order() {
    let ran = run_probes(
        OrthoSimPlugins::default().build(),
        FixedUpdate,
        &all_sets(true),
    );
    assert_eq!(ran, expected(true));
    let ran = run_probes(OrthoSimPlugins::default().build(), FixedUpdate, &stages());
    assert_eq!(ran, expected_stages());
}

#[test]
fn disabling_any_plugin_keeps_the_others_ordered() {
    let cases: [(&str, PluginGroupBuilder, bool); 5] = [
        (
            "schedule",
            OrthoSimPlugins::default()
                .build()
                .disable::<SimulationSchedulePlugin>(),
            true,
        ),
        (
            "teeth",
            OrthoSimPlugins::default()
                .build()
                .disable::<TeethModelPlugin>(),
            true,
        ),
        (
            "trees",
            OrthoSimPlugins::default()
                .build()
                .disable::<SphereTreePlugin>(),
            true,
        ),
        (
            "collision",
            OrthoSimPlugins::default()
                .build()
                .disable::<CollisionPlugin>(),
            true,
        ),
        (
            "movement",
            OrthoSimPlugins::default()
                .build()
                .disable::<MovementPlugin>(),
            false,
        ),
    ];
    for (name, plugins, movement) in cases {
        let mut sets = all_sets(movement);
        sets.extend(stages());
        let ran = run_probes(plugins, FixedUpdate, &sets);
        let (plugin_probes, stage_probes): (Vec<&str>, Vec<&str>) = ran
            .iter()
            .filter(|n| **n != "user")
            .partition(|n| n.starts_with("collision") || n.starts_with("movement"));
        let mut want = expected(movement);
        want.pop();
        assert_eq!(plugin_probes, want, "{name} disabled");
        let mut want = expected_stages();
        want.pop();
        assert_eq!(stage_probes, want, "{name} disabled");
        assert_eq!(ran.last(), Some(&"user"), "{name} disabled");
    }
}

/// A user's own narrow phase in place of the collision plugin: its system runs in the narrow
/// phase stage, between the movement plugin's clock and its response.
#[test]
fn a_replaced_collision_plugin_runs_in_its_stage() {
    struct MyNarrowPhase;
    impl Plugin for MyNarrowPhase {
        fn build(&self, app: &mut App) {
            app.add_systems(
                FixedUpdate,
                probe("my narrow phase").in_set(SimulationSystems::NarrowPhase),
            );
        }
    }
    let plugins = OrthoSimPlugins::default()
        .build()
        .disable::<CollisionPlugin>()
        .add(MyNarrowPhase);
    let mut sets = movement_sets();
    sets.sort_by_key(|(n, _)| expected(true).iter().position(|o| o == n));
    let ran = run_probes(plugins, FixedUpdate, &sets);
    assert_eq!(
        ran,
        [
            "movement start",
            "movement loads",
            "movement propose",
            "movement clock",
            "my narrow phase",
            "movement resolve",
            "movement commit",
            "user"
        ]
    );
}

/// `OrthoSimPlugins::new(schedule)` puts every plugin, and the panel's single step, in that
/// schedule.
#[test]
fn the_simulation_runs_in_the_schedule_it_is_given() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, OrthoSimPlugins::new(PostUpdate)));
    assert_eq!(
        app.world().resource::<SimulationSchedule>().0,
        PostUpdate.intern()
    );
    let ran = run_probes(
        OrthoSimPlugins::new(PostUpdate).build(),
        PostUpdate,
        &all_sets(true),
    );
    assert_eq!(ran, expected(true));
}
