//! Class I where the opposing arch allows: the canine relation's measure, extraction spaces
//! closed by the anchorage asked for, and the automatic anchorage's choice.

use std::collections::BTreeMap;

use glam::Vec3;
use orthosim::{
    geometry::Pose,
    planning::{
        Anchorage, ArchAnchorage, PlanLimits, Target, anchorage::Relations, automatic, plan,
    },
    teeth::{Arch, Case, Dentition, Fdi, case::ToothList},
};

fn case(name: &str) -> Dentition {
    Dentition::build(Case::resolve(name).unwrap()).unwrap()
}

fn fdi(n: i64) -> Fdi {
    Fdi::new(n).unwrap()
}

fn with(anchorage: Anchorage) -> PlanLimits {
    PlanLimits {
        anchorage: ArchAnchorage {
            upper: anchorage,
            lower: anchorage,
        },
        ..PlanLimits::default()
    }
}

/// How far a tooth's origin goes forwards (mm, +z) from where it stands to the target.
fn forwards(d: &Dentition, t: &Target, n: i64) -> f32 {
    t.poses[&fdi(n)].translation.z - d.tooth(fdi(n)).unwrap().pose.translation.z
}

#[test]
fn the_canine_relation_follows_the_upper_canine_along_the_arch() {
    let d = case("normal");
    let none = BTreeMap::new();
    let before = Relations::measure(&d, &none);
    // 13 moved 1 mm mesially along the lower arch at 43–44 (towards 43 from 44).
    let (l, m) = (d.tooth(fdi(43)).unwrap(), d.tooth(fdi(44)).unwrap());
    let mesial = ((l.pose.translation - m.pose.translation) * Vec3::new(1.0, 0.0, 1.0)).normalize();
    let u = d.tooth(fdi(13)).unwrap();
    let moved = Pose::new(u.pose.rotation, u.pose.translation + mesial);
    let after = Relations::measure(&d, &BTreeMap::from([(fdi(13), moved)]));
    let (b, a) = (before.canine_mm[0].unwrap(), after.canine_mm[0].unwrap());
    assert!((a - b - 1.0).abs() < 0.02, "{b} → {a}");
    // The left side is untouched, and near class I in the normal arrangement.
    assert_eq!(before.canine_mm[1], after.canine_mm[1]);
    assert!(before.canine_mm[1].unwrap().abs() < 1.0, "{before:?}");
    assert!(before.molar_mm.iter().all(|m| m.unwrap().abs() < 1.0));
}

#[test]
fn extraction_spaces_close_by_the_anchorage_asked_for() {
    // Case 1: first premolars extracted in both arches, about 7 mm of space a side.
    let d = case("case1");
    let min = automatic(&d, &with(Anchorage::Minimum));
    let moderate = automatic(&d, &with(Anchorage::Moderate));
    let max = automatic(&d, &with(Anchorage::Maximum));
    for (t, name, share) in [
        (&min, "minimum", 0.0),
        (&moderate, "moderate", 0.5),
        (&max, "maximum", 1.0),
    ] {
        for s in &t.arches {
            assert_eq!(s.anchorage, name);
            assert!(s.retraction_mm <= 7.0 + 1e-4, "{s:?}");
            // Reached unless the retraction limit stopped it.
            assert!(
                (s.retraction_share - share).abs() < 0.05
                    || (s.retraction_mm > 6.99 && s.retraction_share < share),
                "{s:?}"
            );
        }
    }
    // Minimum: the incisors stay, the molars come forwards by most of the space.
    for n in [11, 21, 31, 41] {
        assert!(forwards(&d, &min, n).abs() < 0.2, "{n}");
        assert!(
            forwards(&d, &max, n) < -4.0,
            "{n}: {}",
            forwards(&d, &max, n)
        );
    }
    for n in [16, 26, 36, 46] {
        let (a, b, c) = (
            forwards(&d, &min, n),
            forwards(&d, &moderate, n),
            forwards(&d, &max, n),
        );
        assert!(
            a > 5.0 && a > b + 2.0 && b > c + 1.0 && c < 2.0,
            "{n}: {a} {b} {c}"
        );
    }
    // Each is a target the stager reaches without collisions.
    let p = plan(&d, &max, &with(Anchorage::Maximum), 0.0);
    assert!(
        p.blocked.is_empty() && p.max_penetration_mm == 0.0,
        "{:?}",
        p.blocked
    );
}

/// The normal case with the upper first premolars extracted and the lower arch 4 mm back: a
/// class II with a 6 mm overjet, treated by upper extractions (camouflage).
fn class_ii_upper_extractions() -> Dentition {
    let mut c = Case::resolve("normal").unwrap();
    c.case.extracted = ToothList(vec![fdi(14), fdi(24)]);
    let mut d = Dentition::build(c).unwrap();
    for t in d.teeth.iter_mut().filter(|t| t.fdi.arch() == Arch::Lower) {
        t.pose.translation.z -= 4.0;
    }
    d.arch_forms[1].front_z -= 4.0;
    d
}

#[test]
fn the_automatic_anchorage_brings_canines_and_molars_nearest_class_i() {
    let d = class_ii_upper_extractions();
    let scanned = Relations::measure(&d, &BTreeMap::new());
    let jet = scanned.overjet_mm.unwrap();
    assert!(jet > 5.0, "{scanned:?}");
    let auto = automatic(&d, &PlanLimits::default());
    let min = automatic(&d, &with(Anchorage::Minimum));
    let max = automatic(&d, &with(Anchorage::Maximum));
    let error = |t: &Target| t.relations.class_error();
    // Minimum anchorage closes the spaces with the upper posterior teeth: canines stay in
    // class II and the molars go further into it. Maximum retracts the incisors through the
    // lower ones' overjet. The choice retracts part-way: the canines near class I, the overjet
    // kept between 1 and 4 mm, the molars left in class II (as upper extractions leave them).
    let upper = |t: &Target| t.arches.iter().find(|s| s.arch == "upper").unwrap().clone();
    let share = upper(&auto).retraction_share;
    assert!(share > 0.2 && share < 0.9, "{:?}", upper(&auto));
    assert!(
        error(&auto) < error(&min) - 5.0,
        "{:?} {:?}",
        auto.relations,
        min.relations
    );
    assert!(
        auto.relations
            .canine_mm
            .iter()
            .all(|c| c.unwrap().abs() < 1.5),
        "{:?}",
        auto.relations
    );
    let jet = auto.relations.overjet_mm.unwrap();
    assert!((1.0..=4.0).contains(&jet), "{jet}");
    assert!(
        max.relations.overjet_mm.unwrap() < 1.0,
        "{:?}",
        max.relations
    );
    assert!(min.relations.canine_mm.iter().all(|c| c.unwrap() > 3.0));
    // The target is planned without collisions.
    let p = plan(&d, &auto, &PlanLimits::default(), 0.0);
    assert!(
        p.blocked.is_empty() && p.max_penetration_mm == 0.0,
        "{:?}",
        p.blocked
    );
    // In case 1 (class I, all first premolars out) any retraction of one arch more than the
    // other would cut its 0.3 mm overjet: the choice is never worse than either end.
    let d = case("case1");
    let auto = automatic(&d, &PlanLimits::default());
    for t in [
        automatic(&d, &with(Anchorage::Minimum)),
        automatic(&d, &with(Anchorage::Maximum)),
    ] {
        assert!(
            error(&auto) <= error(&t) + 1e-4,
            "{} > {}",
            error(&auto),
            error(&t)
        );
    }
    // An arch without spaces has one set-up, whatever the anchorage.
    let n = case("normal");
    let a = automatic(&n, &PlanLimits::default());
    let b = automatic(&n, &with(Anchorage::Maximum));
    assert_eq!(a.poses, b.poses);
    assert!(a.arches.iter().all(|s| s.retraction_share == 0.0));
}

#[test]
fn the_anchorage_is_read_from_the_limits_file() {
    let l =
        PlanLimits::parse("(anchorage: (upper: Maximum), retraction_mm: 5.0)", "l.ron").unwrap();
    assert_eq!(l.anchorage.upper, Anchorage::Maximum);
    assert_eq!(l.anchorage.lower, Anchorage::Auto);
    assert_eq!(l.retraction_mm.0, 5.0);
    let e = PlanLimits::parse("(\n  anchorage: (upper: Most),\n)", "l.ron")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("l.ron:2:"), "{e}");
}
