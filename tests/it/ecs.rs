//! The ECS layer, headless: loading cases spawns the right tooth entities.

use std::{sync::Arc, time::Duration};

use bevy::{prelude::*, time::TimeUpdateStrategy};
use orthosim::{
    prelude::*,
    teeth::{CaseLoadFailed, Wire, WireModel},
};

/// A headless app with the simulation plugins and a manual clock.
pub(crate) fn create_app() -> App {
    app_with(OrthoSimPlugins::default().build())
}

/// A headless app with the given plugins and a manual clock.
fn app_with(plugins: bevy::app::PluginGroupBuilder) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, plugins))
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(
            16,
        )));
    app.finish();
    app.cleanup();
    app
}

/// Sends a load request and updates until the case is in the world (or fails). Cursors start
/// after the messages already written, so an earlier load's messages are not mistaken for this one's.
fn load(app: &mut App, case: &str) -> Result<(), String> {
    let mut loaded = app
        .world()
        .resource::<Messages<CaseLoaded>>()
        .get_cursor_current();
    let mut failed = app
        .world()
        .resource::<Messages<CaseLoadFailed>>()
        .get_cursor_current();
    app.world_mut().write_message(LoadCase(case.to_owned()));
    for _ in 0..2000 {
        app.update();
        let world = app.world();
        if let Some(done) = loaded.read(world.resource::<Messages<CaseLoaded>>()).last() {
            assert_eq!(done.teeth, 32, "every case loaded here has all 32 teeth");
            return Ok(());
        }
        if let Some(e) = failed
            .read(world.resource::<Messages<CaseLoadFailed>>())
            .next()
        {
            return Err(e.0.to_string());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Err("case did not load in time".into())
}

fn tooth_entities(app: &mut App) -> Vec<(Tooth, ToothShape, Load, Transform, bool, Wire)> {
    let mut q = app.world_mut().query::<(
        &Tooth,
        &ToothShape,
        &Load,
        &Transform,
        Has<Extracted>,
        &Wire,
    )>();
    let mut v: Vec<_> = q
        .iter(app.world())
        .map(|(t, s, l, tr, e, w)| (*t, s.clone(), *l, *tr, e, *w))
        .collect();
    v.sort_by_key(|x| x.0.id);
    v
}

#[test]
fn every_builtin_case_spawns_its_teeth() {
    let mut app = create_app();
    for (case, extracted) in [
        ("normal", vec![]),
        ("case1", vec![14, 24, 34, 44]),
        ("case2", vec![15, 25, 35, 45]),
        ("case3", vec![]),
    ] {
        load(&mut app, case).unwrap();
        let teeth = tooth_entities(&mut app);
        assert_eq!(teeth.len(), 32, "{case}: one entity per present tooth");
        let marked: Vec<u8> = teeth
            .iter()
            .filter(|t| t.4)
            .map(|t| t.0.id.number())
            .collect();
        assert_eq!(marked, extracted, "{case}: Extracted markers");
        for (tooth, shape, _, transform, _, wire) in &teeth {
            assert_eq!(tooth.kind, tooth.id.kind());
            assert_eq!(shape.kind, tooth.kind);
            assert!(transform.translation.is_finite() && transform.rotation.is_normalized());
            assert_eq!(wire.0, WireModel::Rectangular);
        }
        let active = app.world().resource::<ActiveCase>();
        assert_eq!(active.case.case.name, case);
    }
}

#[test]
fn mirrored_teeth_share_one_shape() {
    let mut app = create_app();
    load(&mut app, "normal").unwrap();
    let teeth = tooth_entities(&mut app);
    let shape = |n: u8| {
        teeth
            .iter()
            .find(|t| t.0.id.number() == n)
            .unwrap()
            .1
            .0
            .clone()
    };
    assert!(Arc::ptr_eq(&shape(11), &shape(21)));
    assert!(Arc::ptr_eq(&shape(36), &shape(46)));
    assert!(
        !Arc::ptr_eq(&shape(16), &shape(46)),
        "upper and lower molars differ"
    );
    let distinct: std::collections::HashSet<usize> =
        teeth.iter().map(|t| Arc::as_ptr(&t.1.0) as usize).collect();
    assert_eq!(distinct.len(), 16);
}

#[test]
fn case_loads_become_load_components() {
    let mut app = create_app();
    load(&mut app, "case1").unwrap();
    let teeth = tooth_entities(&mut app);
    for (tooth, shape, load, transform, _, _) in &teeth {
        let n = tooth.id.number();
        if [16, 26, 36, 46].contains(&n) {
            assert!((load.force.length() - 1.5).abs() < 1e-4, "{n}: {load:?}");
            // Mesial on a first molar points forwards (+z) and towards the midline.
            let centre = transform.transform_point(shape.frame.crown_centre);
            assert!(load.force.z > 1.0, "{n}: {load:?}");
            assert!(
                load.force.x * centre.x <= 0.0,
                "{n} pushed away from the midline: {load:?}"
            );
        } else {
            assert_eq!(load.force, Vec3::ZERO, "{n}");
        }
    }
    load(&mut app, "case3").unwrap();
    for (tooth, _, load, _, _, _) in tooth_entities(&mut app) {
        match tooth.id.number() {
            11 | 41 => assert_eq!(load.force, Vec3::X),
            21 | 31 => assert_eq!(load.force, -Vec3::X),
            _ => assert_eq!(load.force, Vec3::ZERO),
        }
    }
}

#[test]
fn a_bad_case_leaves_the_scene_as_it_was() {
    let mut app = create_app();
    load(&mut app, "case2").unwrap();
    let dir = std::env::temp_dir().join(format!("orthosim-ecs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, "Case(\n  name: \"bad\",\n  extracted: [14, 99],\n)\n").unwrap();
    let err = load(&mut app, bad.to_str().unwrap()).unwrap_err();
    assert!(err.contains("bad.ron:3:"), "{err}");
    assert_eq!(tooth_entities(&mut app).len(), 32);
    assert_eq!(app.world().resource::<ActiveCase>().case.case.name, "case2");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn every_tooth_gets_a_covering_sphere_tree() {
    use orthosim::sphere_tree::{ToothSphereTree, check_coverage, coverage::DEFAULT_SPLIT_DEPTH};
    let mut app = create_app();
    load(&mut app, "normal").unwrap();
    let mut ready = 0;
    for _ in 0..3000 {
        app.update();
        let mut q = app
            .world_mut()
            .query_filtered::<(), (With<Tooth>, With<ToothSphereTree>)>();
        ready = q.iter(app.world()).count();
        if ready == 32 {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(ready, 32, "every tooth has its tree");
    let mut q = app
        .world_mut()
        .query::<(&Tooth, &ToothShape, &ToothSphereTree)>();
    let mut distinct = std::collections::HashSet::new();
    for (tooth, shape, tree) in q.iter(app.world()) {
        distinct.insert(Arc::as_ptr(&tree.0) as usize);
        let c = check_coverage(&tree.0, &shape.mesh, DEFAULT_SPLIT_DEPTH);
        assert!(c.covered, "{}: {c:?}", tooth.id);
        assert_eq!(tree.levels, 4);
    }
    assert_eq!(distinct.len(), 16, "mirrored teeth share one tree");
}

#[derive(Resource, Default)]
struct Started(Vec<(Entity, Entity)>);

#[test]
fn a_moving_tooth_reports_contacts_and_nothing_runs_when_nothing_moves() {
    use orthosim::{
        collision::{ContactStarted, Contacts, Motion, ToothCollider, ToothContact, ToothMotion},
        geometry::Pose,
    };
    // Motions are set by hand here: the collision plugin alone, without the movement plugin
    // (which would write every tooth's motion each step).
    let mut app = app_with(
        OrthoSimPlugins::default()
            .build()
            .disable::<orthosim::movement::MovementPlugin>(),
    );
    app.init_resource::<Started>().add_observer(
        |ev: On<ContactStarted>, mut started: ResMut<Started>| {
            started.0.push((ev.entity, ev.other));
        },
    );
    load(&mut app, "normal").unwrap();
    let mut ready = 0;
    for _ in 0..3000 {
        app.update();
        let mut q = app
            .world_mut()
            .query_filtered::<(), (With<Tooth>, With<ToothCollider>)>();
        ready = q.iter(app.world()).count();
        if ready == 32 {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(
        ready, 32,
        "every tooth gets a collider once its tree is built"
    );
    // Nothing moves: no pair is tested.
    for _ in 0..5 {
        app.update();
    }
    assert_eq!(app.world().resource::<Contacts>().pairs_tested, 0);
    assert!(app.world().resource::<Contacts>().list.is_empty());
    // Tooth 11 moves 0.5 mm towards 21 (0.05 mm away): they must touch during the step.
    let mut q = app.world_mut().query::<(Entity, &Tooth, &Transform)>();
    let find = |n: u8, world: &World, q: &mut QueryState<(Entity, &Tooth, &Transform)>| {
        q.iter(world)
            .find(|(_, t, _)| t.id.number() == n)
            .map(|(e, _, t)| (e, *t))
            .unwrap()
    };
    let (e11, t11) = find(11, app.world(), &mut q);
    let (e21, t21) = find(21, app.world(), &mut q);
    let start = Pose::new(t11.rotation, t11.translation);
    let towards = (t21.translation - t11.translation).normalize();
    let motion = Motion {
        start,
        end: Pose::new(start.rotation, start.translation + towards * 0.5),
    };
    app.world_mut().entity_mut(e11).insert(ToothMotion(motion));
    let mut cursor = app
        .world()
        .resource::<Messages<ToothContact>>()
        .get_cursor_current();
    for _ in 0..3 {
        app.update();
    }
    let contacts = app.world().resource::<Contacts>();
    assert!(contacts.pairs_tested >= 2, "11 has at least two neighbours");
    let hit = contacts
        .list
        .iter()
        .find(|c| (c.a == e11 && c.b == e21) || (c.a == e21 && c.b == e11))
        .expect("11 and 21 touch");
    assert!(hit.time_of_contact < 0.5, "{hit:?}");
    let messages = cursor
        .read(app.world().resource::<Messages<ToothContact>>())
        .count();
    assert!(
        messages >= 3,
        "one message per contact per step: {messages}"
    );
    // The pair started touching once, though the contact persists over the steps.
    let started = &app.world().resource::<Started>().0;
    assert_eq!(
        started
            .iter()
            .filter(|p| **p == (e11, e21) || **p == (e21, e11))
            .count(),
        1,
        "{started:?}"
    );
}
