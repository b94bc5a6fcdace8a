//! Archwires moving teeth: brackets bonded on the built-in arches, the wire's force as the only
//! load, and the teeth brought back to the wire's arch form over clinical time.

use glam::Quat;
use orthosim::{
    collision::{Method, collision_shapes},
    geometry::Pose,
    movement::{MovementSettings, Simulation, WireChoice, max_penetration},
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Arch, Case, Dentition, Fdi},
};

fn fdi(n: u8) -> Fdi {
    Fdi::new(n as i64).unwrap()
}

/// The PDL simulation (exact contacts, octree trees) of the case written in `src`, read as
/// file `name`.
fn case_sim(src: &str, name: &str) -> Simulation {
    let d = Dentition::build(orthosim::teeth::Case::parse(src, name).unwrap()).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap()
}

/// The normal case with no loads, its PDL simulation.
fn normal() -> Simulation {
    let mut loaded = Case::resolve("normal").unwrap();
    loaded.case.loads.clear();
    loaded.case.constraints.clear();
    let d = Dentition::build(loaded).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap()
}

#[test]
fn a_niti_wire_brings_a_displaced_incisor_back_and_then_stops() {
    let mut sim = normal();
    let i = sim.index_of(fdi(41)).unwrap();
    let start = sim.teeth[i].pose;
    let g = sim.teeth[i].shape.geometry.clone();
    let buccal = start.transform_vector(g.frame.buccolingual).normalize();
    // 41 carried 1 mm labially (out of its contacts) and turned 5° about its long axis.
    let axis = start.transform_vector(g.frame.long_axis).normalize();
    let centre = start.transform_point(g.frame.crown_centre);
    let turn = Quat::from_axis_angle(axis, 5f32.to_radians());
    let moved = Pose::new(
        (turn * start.rotation).normalize(),
        centre + buccal * 1.0 + turn * (start.translation - centre),
    );
    sim.place_teeth(&[(i, moved)]);
    // Carried labially, the incisor starts inside the upper incisors' palatal surfaces.
    let overlap0 = max_penetration(&sim);
    sim.bond(Arch::Lower, WireChoice::default(), &[]).unwrap();
    assert_eq!(sim.wires.len(), 1);
    assert_eq!(sim.wires[0].brackets.len(), 14);
    assert!(sim.wires[0].last.converged, "{:?}", sim.wires[0].last);
    let pull = sim.wires[0].reaction_of(i).unwrap();
    // The wire pulls the incisor lingually, with a force of a light wire (0.1–3 N).
    assert!(pull.force.dot(buccal.as_dvec3()) < -0.1, "{pull:?}");
    assert!(pull.force.length() < 3.0, "{pull:?}");
    let energy0 = sim.wires[0].rod.energy();
    let crown = |sim: &Simulation| sim.teeth[i].crown_centre();
    let out0 = (crown(&sim) - start.transform_point(g.frame.crown_centre)).dot(buccal);
    let mut energies = vec![energy0];
    for _ in 0..90 {
        sim.step();
        energies.push(sim.wires[0].rod.energy());
    }
    let out = (crown(&sim) - start.transform_point(g.frame.crown_centre)).dot(buccal);
    // The light NiTi, past its loading plateau, unloads on its lower plateau: it brings the
    // incisor part of the way back and falls under the ligament's threshold (the rest waits for
    // the next, stiffer wire).
    assert!(
        out < 0.85 * out0,
        "after 90 days 41 stands {out} mm labial (from {out0})"
    );
    // The wire's energy falls as the incisor aligns (to what the rest of the arch's departures
    // from the wire's form keep in it), never rising by more than a step's rounding.
    let energy = sim.wires[0].rod.energy();
    assert!(energy < 0.5 * energy0, "{energy} from {energy0}");
    for (day, w) in energies.windows(2).enumerate() {
        assert!(
            w[1] <= w[0] + 1e-3 * energy0,
            "day {day}: {} after {}",
            w[1],
            w[0]
        );
    }
    // No overlap deeper than the one it started with (the ligament's contacts hold whatever
    // touches; the wire brings the incisor out of its start).
    assert!(
        max_penetration(&sim) <= overlap0 + 0.01,
        "{} from {overlap0}",
        max_penetration(&sim)
    );
    // Stopped: a further month moves the incisor under 0.1 mm.
    let before = crown(&sim);
    for _ in 0..30 {
        sim.step();
    }
    let drift = crown(&sim).distance(before);
    assert!(drift < 0.1, "drifted {drift} mm in the last month");
    // And no tooth of the arch has left its place by more than the wire's correction allows.
    for t in sim.teeth.iter().filter(|t| t.fdi.arch() == Arch::Lower) {
        assert!(
            t.displacement_mm() < 1.5,
            "{} moved {} mm",
            t.fdi,
            t.displacement_mm()
        );
    }
}

#[test]
fn the_crowded_case_aligns_under_its_first_wire_without_penetration() {
    let loaded = Case::resolve("crowded").unwrap();
    let d = Dentition::build(loaded).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut sim = Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap();
    // The case bonds the lower arch, second molar to second molar, with its wire sequence.
    assert_eq!(sim.wires.len(), 1);
    let w = &sim.wires[0];
    assert_eq!(
        (w.arch, w.brackets.len(), w.sequence.len()),
        (Arch::Lower, 14, 2)
    );
    let energy0 = w.rod.energy();
    let worst_force = |sim: &Simulation| {
        sim.wires[0]
            .reactions
            .iter()
            .map(|r| r.force.length())
            .fold(0.0, f64::max)
    };
    let force0 = worst_force(&sim);
    assert!(force0 > 0.5, "the crowding activates the wire: {force0} N");
    let index = |sim: &Simulation| f64::from(sim.irregularity_mm(Arch::Lower).unwrap());
    let index0 = index(&sim);
    assert!((5.0..6.0).contains(&index0), "{index0}");
    let mut converged = true;
    while sim.elapsed_days < 59.5 {
        sim.step();
        converged &= sim.wires[0].last.converged;
    }
    // The round NiTi takes out most of the crowding, within its play in the slots.
    let index60 = index(&sim);
    assert!(index60 < 0.5 * index0, "{index0} → {index60}");
    assert!(converged, "every wire solve converged");
    let energy = sim.wires[0].rod.energy();
    assert!(
        energy < 0.2 * energy0,
        "wire energy {energy} from {energy0}"
    );
    assert!(
        worst_force(&sim) < 0.5 * force0,
        "{} from {force0}",
        worst_force(&sim)
    );
    assert!(max_penetration(&sim) < 0.05, "{}", max_penetration(&sim));
    for t in &sim.teeth {
        assert!(
            t.displacement_mm() < 4.0,
            "{} moved {} mm",
            t.fdi,
            t.displacement_mm()
        );
    }
    // On day 60 the next wire goes in.
    sim.step();
    let w = &sim.wires[0];
    assert_eq!(w.history.len(), 2);
    assert_eq!(w.choice.size, orthosim::appliance::WireSize::Round(0.018));
    // The steel wire on day 120 finishes the alignment: Little's index under 1 mm within
    // 60–240 days (clinical trials), with no tooth inside another.
    let mut aligned = None;
    while sim.elapsed_days < 240.0 && aligned.is_none() {
        sim.step();
        if index(&sim) < 1.0 {
            aligned = Some(sim.elapsed_days);
        }
    }
    // (with the chain from canine to canine closing the spaces the turned teeth leave).
    let day = aligned.unwrap_or_else(|| {
        panic!(
            "not aligned: {} mm on day {}",
            index(&sim),
            sim.elapsed_days
        )
    });
    assert!((60.0..=240.0).contains(&day), "{day}");
    let c = &sim.wires[0].chains[0];
    assert!(c.placed.is_some_and(|p| p.0 == 120.0), "{c:?}");
    assert!(c.tension_n > 0.0 && c.tension_n < 3.0, "{c:?}");
    assert!(max_penetration(&sim) < 0.05, "{}", max_penetration(&sim));
}

#[test]
fn a_chain_must_end_on_bonded_teeth() {
    let src = r#"Case(
    name: "chained",
    appliance: (
        lower: Some((
            material: ni_ti,
            size: Round(0.016),
            bonded: [33, 32, 31, 41, 42, 43],
            chains: [(from: 43, to: 34)],
        )),
    ),
)"#;
    let loaded = orthosim::teeth::Case::parse(src, "chained.ron").unwrap();
    let d = Dentition::build(loaded).unwrap();
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let text = match Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()) {
        Ok(_) => panic!("34 carries no bracket"),
        Err(e) => e.to_string(),
    };
    assert!(text.contains("34") && text.contains("bracket"), "{text}");
}

/// 13 and 16 of case 1 (first premolars out) pulled together by a 1.5 N closed coil on
/// 0.019×0.025" steel for 60 days, the slots' friction as `ligation` (a case-file fragment) sets
/// it: the space closed (mm), the simulation, and the canine's and molar's indices.
fn coil_closure(ligation: &str) -> (f32, Simulation, usize, usize) {
    let src = format!(
        r#"Case(
    name: "coiled",
    bite_opening_mm: 3.0,
    extracted: [14, 24, 34, 44],
    appliance: (
        upper: Some((
            material: stainless_steel,
            size: Rect(0.019, 0.025),
            {ligation}
            coils: [(from: 13, to: 16, force_n: 1.5, activation_mm: 3.0)],
        )),
    ),
)"#
    );
    let mut sim = case_sim(&src, "coiled.ron");
    let (c, m) = (
        sim.index_of(fdi(13)).unwrap(),
        sim.index_of(fdi(16)).unwrap(),
    );
    let apart = |sim: &Simulation| {
        sim.teeth[c]
            .crown_centre()
            .distance(sim.teeth[m].crown_centre())
    };
    let start = apart(&sim);
    while sim.elapsed_days < 60.0 {
        sim.step();
        // Friction only ever takes from the coil's pull along each slot: never more than the
        // pull, never the other way, and nothing where no coil pulls.
        let w = &sim.wires[0];
        for (j, b) in w.brackets.iter().enumerate() {
            let along =
                (sim.teeth[b.tooth].pose.rotation.as_dquat() * b.bracket.frame) * glam::DVec3::X;
            let after = w.chain_forces[j].dot(along);
            let before = after - w.friction_n[j];
            // (The slot's frame here is the pose's single-precision one: 0.01 N of slack.)
            assert!(
                w.friction_n[j] * before <= 0.0 && after * before.signum() >= -1e-2,
                "{}: pull {before} N, friction {} N",
                b.fdi,
                w.friction_n[j]
            );
            if before == 0.0 {
                assert_eq!(w.friction_n[j], 0.0, "{}", b.fdi);
            }
        }
    }
    (start - apart(&sim), sim, c, m)
}

#[test]
fn a_closed_coil_closes_an_extraction_space_along_the_wire_against_friction() {
    // Frictionless slots first: the coil's mechanics alone.
    let (closed, sim, c, m) = coil_closure("friction: Some(0.0),");
    let coil = &sim.wires[0].coils[0];
    // The coil pulls its plateau until it has all but closed, then less.
    assert!(coil.placed.is_some() && coil.force_n <= 1.5, "{coil:?}");
    let (_, relaxed) = coil.placed.unwrap();
    let left = sim.wires[0].brackets.len();
    assert!(
        left == 12,
        "brackets on 17–27 but the extracted 14 and 24: {left}"
    );
    assert!(relaxed > 0.0);
    // The canine and the molar come together at the ligament's pace under a 1.5 N coil, the
    // anchorage molar less than the canine (3.2 mm in two months, most of it while the coil
    // still pulls its plateau).
    assert!((1.0..4.0).contains(&closed), "closed {closed} mm");
    assert!(
        sim.teeth[c].displacement_mm() > sim.teeth[m].displacement_mm(),
        "canine {} molar {}",
        sim.teeth[c].displacement_mm(),
        sim.teeth[m].displacement_mm()
    );
    assert!(max_penetration(&sim) < 0.05, "{}", max_penetration(&sim));
    // Elastomeric modules on the steel wire: the canine, tipped against the wire, binds, and
    // most of the pull goes to friction; the space still closes, more slowly.
    let (rubbed, sim, _, _) = coil_closure("ligation: elastomeric,");
    let canine = sim.wires[0]
        .brackets
        .iter()
        .position(|b| b.fdi == fdi(13))
        .unwrap();
    assert!(
        sim.wires[0].friction_n[canine].abs() > 0.3,
        "{:?}",
        sim.wires[0].friction_n
    );
    assert!(
        rubbed > 0.05 && rubbed < 0.5 * closed,
        "with friction {rubbed} mm, without {closed} mm"
    );
    assert!(max_penetration(&sim) < 0.05, "{}", max_penetration(&sim));
}

#[test]
fn the_panel_can_bond_chain_coil_and_debond_an_arch() {
    let mut sim = normal();
    sim.bond(Arch::Lower, WireChoice::default(), &[]).unwrap();
    sim.add_chain(fdi(43), fdi(33), 0.5).unwrap();
    sim.add_coil(
        fdi(44),
        fdi(46),
        orthosim::teeth::case::appliance::CoilKind::Open,
        1.5,
        3.0,
    )
    .unwrap();
    // Refused: ends on two arches, an end without a bracket, a stretch or force out of range.
    for bad in [
        sim.add_chain(fdi(43), fdi(13), 0.5),
        sim.add_chain(fdi(43), fdi(48), 0.5),
        sim.add_chain(fdi(43), fdi(33), f64::NAN),
        sim.add_coil(fdi(44), fdi(46), Default::default(), 9.0, 3.0),
    ] {
        let e = bad.unwrap_err().to_string();
        assert!(e.contains("chain") || e.contains("coil"), "{e}");
    }
    assert_eq!(sim.wires[0].chains.len(), 1);
    assert_eq!(sim.wires[0].coils.len(), 1);
    // Placed today, they pull from the next step.
    sim.step();
    assert!(
        sim.wires[0].chains[0].tension_n > 0.5,
        "{:?}",
        sim.wires[0].chains
    );
    assert!(
        sim.wires[0].coils[0].force_n > 0.5,
        "{:?}",
        sim.wires[0].coils
    );
    sim.debond(Arch::Lower);
    assert!(sim.wires.is_empty());
    assert!(sim.add_chain(fdi(43), fdi(33), 0.5).is_err());
}

#[test]
fn case1_chain_closes_the_extraction_spaces_by_sliding_on_the_wire() {
    use orthosim::movement::{RunLimit, run_case_for};
    let run = run_case_for(
        "case1-chain",
        Method::Exact,
        MovementSettings::default(),
        TreeSettings::with_method(TreeMethod::Octree),
        None,
        RunLimit {
            max_steps: 100_000,
            max_days: Some(365.0),
        },
        |_| {},
    )
    .unwrap();
    let r = &run.report;
    let sim = &run.simulation;
    assert!(r.max_penetration_mm <= 0.01, "{}", r.max_penetration_mm);
    let a = r.appliance.as_ref().unwrap();
    assert!(a.converged);
    assert_eq!(a.chains.len(), 6);
    // Each first molar is drawn mesially along its arch in a year, against the slots' friction
    // (much of each chain's pull at the canines and molars goes to it; the anterior block
    // retracts into the space too: 0.8–2.2 mm of molar travel in this run).
    let rubbed = a
        .brackets
        .iter()
        .filter(|b| [13, 23, 33, 43, 16, 26, 36, 46].contains(&b.fdi.number()))
        .filter(|b| b.friction_n.abs() > 0.2)
        .count();
    assert!(rubbed >= 6, "{:?}", a.brackets);
    for m in [16, 26, 36, 46] {
        let i = sim.index_of(fdi(m)).unwrap();
        let t = &sim.teeth[i];
        let mesial = t
            .initial
            .transform_vector(glam::Vec3::X * t.fdi.local_x_mesial_sign());
        let moved = (t.crown_centre()
            - t.initial
                .transform_point(t.shape.geometry.frame.crown_centre))
        .dot(mesial);
        assert!(moved > 0.2, "{m} moved {moved} mm mesially");
    }
    // The extraction spaces (about 7 mm each) close: every one by more than a millimetre,
    // together by more than half (measured: 3.3, 5.6, 2.8 and 1.4 mm left; the upper left, whose
    // molar binds hardest in its tube, closes least).
    let gaps: Vec<f32> = [(15, 13), (23, 25), (45, 43), (33, 35)]
        .iter()
        .map(|&(a, b)| {
            r.distances
                .iter()
                .find(|d| (d.a, d.b) == (fdi(a), fdi(b)) || (d.a, d.b) == (fdi(b), fdi(a)))
                .unwrap()
                .surface_gap_mm
        })
        .collect();
    assert!(
        gaps.iter().all(|g| *g < 6.0) && gaps.iter().sum::<f32>() < 14.0,
        "spaces left {gaps:?} mm"
    );
}

#[test]
fn a_power_arm_retracts_a_canine_more_bodily() {
    // Canine retraction by a closed coil on a round steel wire (which lets the canine tip), the
    // coil hooked at the slot or on a power arm reaching 10 mm towards the root (near its centre of resistance).
    let tip_and_travel = |arm: f32| {
        let src = format!(
            r#"Case(
    name: "arm",
    bite_opening_mm: 3.0,
    extracted: [14, 24, 34, 44],
    appliance: (
        upper: Some((
            material: stainless_steel,
            size: Round(0.016),
            // Frictionless slots: the arm's couple alone.
            friction: Some(0.0),
            coils: [(from: 13, to: 16, force_n: 1.5, activation_mm: 3.0, from_arm_mm: {arm})],
        )),
    ),
)"#
        );
        let mut sim = case_sim(&src, "arm.ron");
        let c = sim.index_of(fdi(13)).unwrap();
        while sim.elapsed_days < 30.0 {
            sim.step();
        }
        // Tipping: how far the long axis leaned along the arch, in degrees: positive with the
        // crown distal and the root mesial, negative the other way.
        let t = &sim.teeth[c];
        let axis =
            |p: &orthosim::geometry::Pose| p.transform_vector(t.shape.geometry.frame.long_axis);
        let mesial = t
            .initial
            .transform_vector(glam::Vec3::X * t.fdi.local_x_mesial_sign());
        let lean = (axis(&t.pose) - axis(&t.initial)).dot(mesial);
        ((-lean).asin().to_degrees(), t.displacement_mm())
    };
    let (tip0, moved0) = tip_and_travel(0.0);
    let (tip8, moved8) = tip_and_travel(8.0);
    let (tip12, moved12) = tip_and_travel(12.0);
    // At the slot the crown leads; the higher the arm, the more the root leads instead (already
    // at 8 mm: the wire in the slots resists the crown's tipping too, so a smaller couple from
    // the arm turns the balance).
    assert!(
        moved0 > 0.2 && moved8 > 0.2 && moved12 > 0.2,
        "{moved0} {moved8} {moved12}"
    );
    assert!(tip0 > 1.0, "tipped {tip0}° at the slot");
    assert!(
        tip8 < 0.0,
        "tipped {tip8}° on an 8 mm arm, {tip0}° at the slot"
    );
    assert!(
        tip12 < tip8,
        "tipped {tip12}° on a 12 mm arm, {tip8}° on 8 mm"
    );
}

#[test]
fn a_cinched_wire_holds_its_terminal_tube_where_a_free_one_lets_it_slide() {
    // An open coil pushing 17 distally from 16 in frictionless slots: the free wire lets 17 slide
    // back along it; cinched behind 17's tube, the wire holds it within the stop's play.
    let travel = |cinched: bool| {
        let src = format!(
            r#"Case(
    name: "cinch",
    bite_opening_mm: 3.0,
    appliance: (
        upper: Some((
            material: stainless_steel,
            size: Rect(0.019, 0.025),
            friction: Some(0.0),
            cinched: {cinched},
            coils: [(from: 16, to: 17, kind: open, force_n: 1.5, activation_mm: 3.0)],
        )),
    ),
)"#
        );
        let mut sim = case_sim(&src, "cinch.ron");
        let i = sim.index_of(fdi(17)).unwrap();
        while sim.elapsed_days < 60.0 {
            sim.step();
        }
        let t = &sim.teeth[i];
        let distal = t
            .initial
            .transform_vector(glam::Vec3::X * -t.fdi.local_x_mesial_sign());
        (t.crown_centre()
            - t.initial
                .transform_point(t.shape.geometry.frame.crown_centre))
        .dot(distal)
    };
    let (free, cinched) = (travel(false), travel(true));
    assert!(free > 0.5, "free wire: 17 moved {free} mm distally");
    assert!(
        cinched < 0.6 && cinched < 0.5 * free,
        "cinched {cinched} mm, free {free} mm"
    );
}

#[test]
fn class_ii_elastics_retract_the_upper_arch_and_bring_the_lower_forward() {
    // Both arches on 0.019×0.025" steel, with and without Class II elastics (upper canine to
    // lower first molar, 1.5 N) for 60 days: the difference is the elastics'.
    let run = |elastics: &str| {
        let src = format!(
            r#"Case(
    name: "class2",
    bite_opening_mm: 3.0,
    appliance: (
        upper: Some((material: stainless_steel, size: Rect(0.019, 0.025))),
        lower: Some((material: stainless_steel, size: Rect(0.019, 0.025))),
        {elastics}
    ),
)"#
        );
        let mut sim = case_sim(&src, "class2.ron");
        while sim.elapsed_days < 60.0 {
            sim.step();
        }
        assert!(max_penetration(&sim) < 0.05, "{}", max_penetration(&sim));
        sim
    };
    let with =
        run("elastics: [(from: 13, to: 46, force_n: 1.5), (from: 23, to: 36, force_n: 1.5)],");
    let without = run("");
    assert_eq!(with.elastics.len(), 2);
    assert!(
        with.elastics
            .iter()
            .all(|e| e.force_n > 1.0 && e.placed.is_some()),
        "{:?}",
        with.elastics
    );
    // Forward (+z) and vertical (+y) travel of a crown, the elastics' run less the plain one.
    let moved = |f: u8| {
        let at = |s: &Simulation| {
            let t = &s.teeth[s.index_of(fdi(f)).unwrap()];
            t.crown_centre()
                - t.initial
                    .transform_point(t.shape.geometry.frame.crown_centre)
        };
        at(&with) - at(&without)
    };
    let upper: f32 = [11, 21, 13, 23].iter().map(|&f| moved(f).z).sum::<f32>() / 4.0;
    let lower: f32 = [31, 41].iter().map(|&f| moved(f).z).sum::<f32>() / 2.0;
    assert!(upper < -0.1, "upper anterior teeth {upper} mm forward");
    assert!(lower > 0.1, "lower incisors {lower} mm forward");
    // The elastics' known side effect: they extrude the upper anterior segment they hook on
    // (on a full-size steel wire, the segment as one: the canines need not extrude alike).
    let extruded: f32 = [11, 21, 13, 23].iter().map(|&f| moved(f).y).sum::<f32>() / 4.0;
    assert!(
        extruded < -0.05,
        "{extruded}: {:?}",
        [11, 21, 13, 23].map(|f| moved(f).y)
    );
    // Refused: both ends in one arch, an end without a bracket.
    let mut sim = run("");
    assert!(sim.add_elastic(fdi(13), fdi(16), 1.5).is_err());
    assert!(sim.add_elastic(fdi(13), fdi(48), 1.5).is_err());
    assert!(sim.add_elastic(fdi(13), fdi(46), 9.0).is_err());
    assert!(sim.add_elastic(fdi(33), fdi(16), 1.5).is_ok());
}
