//! The alveolar bone: plain forces, fixed in the world, push roots against the cortical plates,
//! which hold them where the ligament alone would let the tooth leave the jaw.

use orthosim::{
    appliance::bone::PlateContact,
    collision::{Method, collision_shapes},
    movement::{MovementSettings, Simulation},
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Case, Dentition, Fdi},
};

fn pushed(tooth: u8, force: &str, plates: bool) -> Simulation {
    let text = format!(
        "Case(name: \"push\", teeth: All, loads: [(teeth: [{tooth}], force: {force})], \
         wire: (upper: Round, lower: Round))"
    );
    let d = Dentition::build(Case::parse(&text, "push.ron").unwrap()).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut settings = MovementSettings::default();
    settings.pdl.bone_plates = plates;
    Simulation::new(&d, shapes, Method::Exact, settings).unwrap()
}

/// The deepest any root sample of tooth `i` lies past a plate now (mm; negative: inside).
fn deepest(sim: &Simulation, i: usize) -> f32 {
    let t = &sim.teeth[i];
    let roots = &t.pdl.as_ref().unwrap().root_samples;
    sim.bone
        .as_ref()
        .unwrap()
        .contacts(t.fdi, &t.pose, roots, 10.0)
        .iter()
        .map(|c: &PlateContact| c.depth)
        .fold(f32::NEG_INFINITY, f32::max)
}

#[test]
fn a_plain_force_carries_a_tooth_to_the_cortical_plate_and_no_farther() {
    for (tooth, force) in [
        (11, "Anatomical(buccal: 1.5)"),
        (41, "Anatomical(buccal: -1.0)"),
    ] {
        let mut sim = pushed(tooth, force, true);
        let i = sim.index_of(Fdi::new(tooth as i64).unwrap()).unwrap();
        let load = sim.teeth[i].load.force;
        let mut worst = f32::NEG_INFINITY;
        for _ in 0..180 {
            sim.step();
            worst = worst.max(deepest(&sim, i));
        }
        // The force stays what it was in the world as the tooth turns.
        assert_eq!(sim.teeth[i].load.force, load);
        // The root reached a plate, was held there, and the tooth stayed in the jaw.
        assert!(
            sim.cortical
                .iter()
                .any(|c| c.fdi.to_string() == tooth.to_string()),
            "{tooth}: {:?}",
            sim.cortical
        );
        assert!(worst < 0.05, "{tooth}: a root passed a plate by {worst} mm");
        let moved = sim.teeth[i].displacement_mm();
        // Tipped until both plates hold the root (crown lingual or labial, apex the other way),
        // it stays: a further month moves it under 0.05 mm.
        assert!(moved < 6.0, "{tooth} moved {moved} mm in 180 days");
        let before = sim.teeth[i].pose;
        for _ in 0..30 {
            sim.step();
        }
        let drift = sim.teeth[i].pose.translation.distance(before.translation);
        assert!(drift < 0.05, "{tooth} drifted {drift} mm in the last month");
        // Without the plates the same force carries it far out of the arch.
        let mut free = pushed(tooth, force, false);
        for _ in 0..180 {
            free.step();
        }
        let far = free.teeth[i].displacement_mm();
        assert!(
            far > 2.0 * moved && far > 8.0,
            "{tooth}: {far} mm free, {moved} held"
        );
        assert!(free.cortical.is_empty() && free.bone.is_none());
    }
}

#[test]
fn teeth_at_rest_start_inside_the_envelope_and_never_reach_it() {
    let mut sim = pushed(11, "World(0.0, 0.0, 0.0)", true);
    for _ in 0..5 {
        sim.step();
    }
    for i in 0..sim.teeth.len() {
        // At least the plates' distances inside along the arch's normal, which is at least 0.4
        // mm along a plate's slope where the roots taper.
        assert!(
            deepest(&sim, i) < -0.4,
            "{} {}",
            sim.teeth[i].fdi,
            deepest(&sim, i)
        );
    }
    assert!(sim.cortical.is_empty());
}

#[test]
fn simulate_reports_a_root_at_a_plate_in_its_table_and_json() {
    let dir = std::env::temp_dir().join(format!("orthosim-bone-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("push.ron");
    std::fs::write(
        &case,
        "Case(name: \"push\", teeth: All, loads: [(teeth: [11], force: Anatomical(buccal: 1.5))], \
         wire: (upper: Round, lower: Rectangular))",
    )
    .unwrap();
    let run = |json: bool| {
        let mut args = vec!["simulate", "--case", case.to_str().unwrap(), "--days", "40"];
        if json {
            args.push("--json");
        }
        String::from_utf8(crate::cli::succeed(&args).stdout).unwrap()
    };
    let table = run(false);
    assert!(
        table.contains("root of 11 at the buccal plate from day"),
        "{table}"
    );
    let v: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    let first = &v["cortical_contacts"][0];
    assert_eq!(first["fdi"], 11);
    assert_eq!(first["plate"], "buccal");
    assert!(first["depth_mm"].as_f64().unwrap() < 0.05, "{first}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// World positions of tooth `i`'s root samples.
fn roots_of(sim: &Simulation, i: usize) -> Vec<glam::Vec3> {
    let t = &sim.teeth[i];
    let p = t.pdl.as_ref().unwrap();
    p.root_samples
        .iter()
        .map(|r| t.pose.transform_point(*r))
        .collect()
}

#[test]
fn a_bone_mesh_named_by_the_case_holds_the_roots_it_covers_and_an_open_one_is_refused() {
    // Where the lower roots stand, from the same case with the envelope, in 41's frame as
    // placed (z labial, y along its long axis).
    let mut envelope = pushed(41, "Anatomical(buccal: -1.0)", true);
    let i = envelope.index_of(Fdi::new(41).unwrap()).unwrap();
    let frame = envelope.teeth[i].pose;
    let local = |p: glam::Vec3| frame.inverse().transform_point(p);
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    for (k, t) in envelope.teeth.iter().enumerate() {
        if t.fdi.arch() == orthosim::teeth::Arch::Lower && t.pdl.is_some() {
            for p in roots_of(&envelope, k) {
                (lo, hi) = (lo.min(local(p)), hi.max(local(p)));
            }
        }
    }
    // A mandible whose labial wall runs along 41's root 0.3 mm before it, everything else far
    // off (the crest well above the roots: it holds nothing anyway).
    let labial = |sim: &Simulation| {
        roots_of(sim, i)
            .iter()
            .map(|p| local(*p).z)
            .fold(f32::MIN, f32::max)
    };
    let front = labial(&envelope) + 0.3;
    let mandible = orthosim::geometry::TriMesh::cuboid(
        lo - glam::Vec3::splat(5.0),
        glam::Vec3::new(hi.x + 5.0, hi.y + 5.0, front),
    )
    .map_vertices(|v| frame.transform_point(v));
    let dir = std::env::temp_dir().join(format!("orthosim-bone-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, m: &orthosim::geometry::TriMesh| {
        let mut f = std::fs::File::create(dir.join(name)).unwrap();
        orthosim::teeth::import::write_stl(m, &mut f).unwrap();
    };
    write("mandible.stl", &mandible);
    let case = |file: &str| {
        format!(
            "Case(name: \"bone\", teeth: All, loads: [(teeth: [41], force: Anatomical(buccal: \
             -1.0))], wire: (upper: Round, lower: Round), bone: (lower: Some((file: \"{file}\", \
             transform: Identity))))"
        )
    };
    let path = dir.join("case.ron").display().to_string();
    let d = Dentition::build(Case::parse(&case("mandible.stl"), &path).unwrap()).unwrap();
    assert!(d.bone[1].is_some() && d.bone[0].is_none());
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut sim = Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap();
    let meshes = sim
        .bone_meshes
        .as_ref()
        .expect("the mandible holds the lower teeth");
    assert!(meshes.holds(Fdi::new(41).unwrap()) && !meshes.holds(Fdi::new(11).unwrap()));
    let mut worst = f32::NEG_INFINITY;
    for _ in 0..180 {
        sim.step();
        envelope.step();
        worst = worst.max(labial(&sim) - front);
    }
    // The root reached the mesh's labial wall, was held there and recorded.
    assert!(
        worst > -0.05 && worst < 0.05,
        "41's root {worst} mm past the wall"
    );
    assert!(
        sim.cortical
            .iter()
            .any(|c| c.fdi.to_string() == "41"
                && c.plate == orthosim::appliance::bone::Plate::Buccal),
        "{:?}",
        sim.cortical
    );
    // The envelope's plate, a millimetre beyond the roots and their neighbours', let it farther.
    let free = labial(&envelope);
    assert!(free - front > 0.2, "{free} against the wall at {front}");
    // `simulate`'s report names the teeth the mesh holds.
    std::fs::write(dir.join("case.ron"), case("mandible.stl")).unwrap();
    let run = orthosim::movement::run_case_for(
        &path,
        Method::Exact,
        MovementSettings::default(),
        TreeSettings::with_method(TreeMethod::Octree),
        None,
        orthosim::movement::RunLimit {
            max_steps: u64::MAX,
            max_days: Some(2.0),
        },
        |_| {},
    )
    .unwrap();
    let report = run.report.bone_meshes.expect("the case names a mandible");
    assert!(report.teeth.iter().any(|f| f.to_string() == "41"));
    assert!(
        report
            .teeth
            .iter()
            .all(|f| f.arch() == orthosim::teeth::Arch::Lower)
    );
    // A mesh with a hole is refused, naming the file and where.
    let mut open = mandible.clone();
    open.triangles.pop();
    write("open.stl", &open);
    let e = Dentition::build(Case::parse(&case("open.stl"), &path).unwrap()).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("open.stl") && message.contains("open: 3 edges"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
