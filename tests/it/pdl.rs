//! The periodontal-ligament model: the published anchors of `orthosim validate`, tipping against
//! translation by wire and moment-to-force ratio, contact forces along the arch, clinical time,
//! and its settings refused with their position.

use glam::Vec3;
use orthosim::{
    analysis::validate,
    collision::{Method, collision_shapes},
    movement::{MovementModel, MovementSettings, Simulation, tooth_travel},
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Case, Dentition, Fdi, ToothResolution, WireModel},
};

fn fdi(n: u8) -> Fdi {
    Fdi::new(n as i64).unwrap()
}

#[test]
fn every_validation_row_is_inside_its_reference() {
    let table = validate(&MovementSettings::default(), ToothResolution::default()).unwrap();
    assert_eq!(table.model, "pdl");
    let rows = |name: &str| -> Vec<_> { table.rows.iter().filter(|r| r.name == name).collect() };
    let teeth = |name: &str| -> Vec<u8> { rows(name).iter().map(|r| r.tooth).collect() };
    assert_eq!(teeth("cres_from_crest"), [11, 13, 31]);
    assert_eq!(teeth("cres_to_furcation_mm"), [16]);
    assert_eq!(teeth("bracket_to_cres_mm"), [11]);
    assert_eq!(teeth("mf_translation"), [11, 13]);
    assert_eq!(teeth("sigma2_over_root_length2"), [11]);
    assert_eq!(teeth("crown_displacement_mm_5n"), [12]);
    assert_eq!(teeth("canine_retraction_mm_per_month_1n"), [13]);
    assert_eq!(teeth("power_arm_bodily_mm"), [11]);
    assert_eq!(teeth("torque_play_deg"), [0, 0]);
    assert_eq!(teeth("twist_for_20nmm_deg"), [0]);
    let crot = rows("crot_from_cres_mm");
    let mfs: Vec<f32> = crot.iter().map(|r| r.mf.unwrap()).collect();
    assert_eq!(mfs, [0.0, 2.0, 4.0, 6.0, 8.0, 12.0]);
    for r in &table.rows {
        assert!(r.value.is_finite(), "{r:?}");
        assert!(
            r.passes(),
            "{} ({}): {} outside {:?}",
            r.name,
            r.tooth,
            r.value,
            r.reference
        );
    }
    // The centre of rotation runs apically as M/F grows towards the bracket's distance, and jumps
    // to the occlusal side past it (root movement).
    let y: Vec<f64> = crot.iter().map(|r| r.value).collect();
    assert!(
        y[0] > 0.0 && y.windows(2).take(4).all(|w| w[1] > w[0]),
        "{y:?}"
    );
    assert!(y[5] < 0.0, "{y:?}");
    let d = rows("bracket_to_cres_mm")[0].value;
    let translation = rows("mf_translation")[0].value;
    assert!((translation - d).abs() < 1.0, "{translation} vs d {d}");
    // A power arm's force is the bracket's force and the couple of the arm: the arm for bodily
    // retraction is the M/F that translates (the wire free within its torque play).
    let arm = rows("power_arm_bodily_mm")[0].value;
    assert!((arm - translation).abs() < 1e-6, "{arm} vs {translation}");
    // The fuller wire in the smaller slot plays more (the slot's measured height, the bevels).
    let play: Vec<f64> = rows("torque_play_deg").iter().map(|r| r.value).collect();
    assert!(play[0] < play[1], "{play:?}");
    assert!(rows("twist_for_20nmm_deg")[0].value > play[1] + 5.0);
}

/// Case 1's arrangement with its loads and constraints removed and 1 N distal on the upper right
/// canine (the first premolar's space behind it), for `days`.
fn retract_canine(wire: WireModel, mf: Option<f32>, days: f64) -> Retraction {
    let mut loaded = Case::resolve("case1").unwrap();
    loaded.case.loads.clear();
    loaded.case.constraints.clear();
    let mut d = Dentition::build(loaded).unwrap();
    let mut distal = Vec3::ZERO;
    for t in &mut d.teeth {
        if t.fdi == fdi(13) {
            distal = -t.anatomical_axes()[0];
            t.force = distal;
            t.wire = wire;
            t.mf = mf;
        }
    }
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut sim =
        Simulation::new(&d, shapes, Method::Continuous, MovementSettings::default()).unwrap();
    let i = sim.index_of(fdi(13)).unwrap();
    let (g, start) = (sim.teeth[i].shape.geometry.clone(), sim.teeth[i].pose);
    let tip =
        start.transform_point(g.frame.cervical_centre + g.frame.long_axis * g.frame.crown_length);
    let apex = start.transform_point(g.frame.apex);
    sim.step();
    // What the ligament asks of the first day, before collisions cut it.
    let cres = start.transform_point(sim.teeth[i].pdl.as_ref().unwrap().centre_of_resistance);
    let t = sim.pdl.twists[i];
    let (u, w) = (
        Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32),
        Vec3::new(t[3] as f32, t[4] as f32, t[5] as f32),
    );
    let first = |p: Vec3| (u + w.cross(p - cres)).dot(distal);
    let first_day = (first(tip), first(apex));
    while sim.elapsed_days < days - 1e-9 {
        sim.step();
    }
    assert!((sim.elapsed_days - days).abs() < 1e-6);
    let travel = tooth_travel(&sim);
    let canine = travel.iter().find(|t| t.fdi == fdi(13)).unwrap();
    Retraction {
        first_day,
        crown: Vec3::from(canine.crown_displacement_mm).dot(distal),
        apex: Vec3::from(canine.apex_displacement_mm).dot(distal),
    }
}

/// Distal movement of the canine's crown tip and apex: in the first day as the ligament asks
/// (before collisions), and in all.
struct Retraction {
    first_day: (f32, f32),
    crown: f32,
    apex: f32,
}

#[test]
fn a_round_wire_tips_a_rectangular_wire_translates_and_mf_moves_the_root() {
    // Round wire: no couple, the crown goes distally and the apex mesially (the apex then meets
    // the lateral incisor's root, which stops the tipping).
    let r = retract_canine(WireModel::Round, None, 20.0);
    assert!(
        r.first_day.0 > 0.0 && r.first_day.1 < 0.0,
        "{:?}",
        r.first_day
    );
    // Rectangular wire fully engaged: crown and apex together, all the way.
    let r = retract_canine(WireModel::Rectangular, None, 20.0);
    assert!((r.first_day.0 - r.first_day.1).abs() < 1e-3 * r.first_day.0);
    assert!(
        r.crown > 0.1 && (r.crown - r.apex).abs() < 0.02 * r.crown,
        "{} {}",
        r.crown,
        r.apex
    );
    // M/F 0 on a rectangular wire tips like a round one; past the bracket's distance to the
    // centre of resistance the apex leads (root movement).
    let r = retract_canine(WireModel::Rectangular, Some(0.0), 1.0);
    assert!(
        r.first_day.0 > 0.0 && r.first_day.1 < 0.0,
        "{:?}",
        r.first_day
    );
    let r = retract_canine(WireModel::Rectangular, Some(16.0), 1.0);
    assert!(r.first_day.1 > r.first_day.0, "{:?}", r.first_day);
}

#[test]
fn contact_forces_push_the_neighbour_and_are_never_pulls() {
    let d = Dentition::build(Case::resolve("case1").unwrap()).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut sim = Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap();
    let mut pushed = false;
    for _ in 0..200 {
        sim.step();
        assert!(sim.pdl.forces.iter().all(|f| *f >= 0.0 && f.is_finite()));
        let (i16, i15) = (
            sim.index_of(fdi(16)).unwrap(),
            sim.index_of(fdi(15)).unwrap(),
        );
        if let Some(k) = sim
            .pdl
            .touching
            .iter()
            .position(|f| (f.a, f.b) == (i15, i16))
        {
            pushed |= sim.pdl.forces.get(k).is_some_and(|f| *f > 0.1);
        }
    }
    assert!(
        pushed,
        "the molar pushes the premolar through their contact"
    );
    // A day a step: elapsed days follow the steps.
    assert!((sim.elapsed_days - sim.steps as f64).abs() < 1e-9);
    let i15 = sim.index_of(fdi(15)).unwrap();
    assert!(sim.teeth[i15].displacement_mm() > 0.5);
}

#[test]
fn pdl_settings_out_of_range_are_refused_with_their_position() {
    let dir = std::env::temp_dir().join(format!("orthosim-it-pdl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (text, field) in [
        ("(\n  pdl: (poisson_ratio: 0.5),\n)\n", "poisson_ratio"),
        (
            "(\n  pdl: (youngs_modulus_mpa: -0.05),\n)\n",
            "youngs_modulus_mpa",
        ),
        ("(\n  pdl: (thickness_mm: 0.0),\n)\n", "thickness_mm"),
        ("(\n  pdl: (crest_mm: (incisor: 12.0)),\n)\n", "incisor"),
        ("(\n  pdl: (threshold_kpa: NaN),\n)\n", "threshold_kpa"),
    ] {
        let path = dir.join("settings.ron");
        std::fs::write(&path, text).unwrap();
        let e = MovementSettings::load(&path).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}:2:", path.display())), "{e}");
        assert!(e.contains(field), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    let path = dir.join("settings.ron");
    std::fs::write(&path, "(model: Paper, pdl: (wire_engagement: 0.5))").unwrap();
    let s = MovementSettings::load(&path).unwrap();
    assert_eq!(
        (s.model, s.pdl.wire_engagement),
        (MovementModel::Paper, 0.5)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
