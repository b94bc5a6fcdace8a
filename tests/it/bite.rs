//! The bite: the lower arch closed onto the upper under a bite force until stable, never
//! interpenetrating; what `orthosim occlusion` reports.

use orthosim::{
    analysis::{bite, bite::BITE_FORCE_N, measures::Posed},
    teeth::{Arch, Case, Dentition},
};

fn dentition(case: &str) -> Dentition {
    Dentition::build(Case::resolve(case).unwrap()).unwrap()
}

#[test]
fn the_normal_arrangement_is_a_class_one_bite_that_settles_without_penetration() {
    let d = dentition("normal");
    let teeth = Posed::of_dentition(&d);
    // As arranged: every premolar and molar of both arches meets an antagonist, the incisors
    // stand just apart, overjet and overbite about 2 mm.
    let placed = bite("normal", &teeth, false, 0.0);
    assert!(placed.max_penetration_mm <= 0.01, "{placed:?}");
    for f in d
        .teeth
        .iter()
        .map(|t| t.fdi)
        .filter(|f| f.kind().is_posterior())
    {
        assert!(
            placed.contacts.iter().any(|c| c.upper == f || c.lower == f),
            "{f} meets nothing: {placed:?}"
        );
    }
    let o = d.arrangement;
    assert!((1.5..2.5).contains(&o.overjet_mm), "{o:?}");
    assert!((1.5..2.5).contains(&o.overbite_mm), "{o:?}");
    for (opening, b) in [(None, placed.clone())]
        .into_iter()
        .chain([0.0, 3.0].map(|x| (Some(x), bite("normal", &teeth, true, x))))
    {
        assert!(b.max_penetration_mm <= 0.01, "{opening:?}: {b:?}");
        assert!(
            b.contact_teeth.left >= 4 && b.contact_teeth.right >= 4,
            "{opening:?}: {b:?}"
        );
        assert!(
            (0.05..=0.3).contains(&b.incisor_gap_mm),
            "{opening:?}: {b:?}"
        );
        assert!(
            b.contacts
                .iter()
                .all(|c| c.min_gap_mm >= -0.01 && c.min_gap_mm <= 0.05)
        );
        assert!(
            b.contacts.iter().map(|c| c.area_mm2).sum::<f32>() > 0.3,
            "{b:?}"
        );
        let Some(opening) = opening else { continue };
        assert!(b.stable, "{opening} mm: {:?}", b.why);
        assert!(b.why.is_none());
        // It closed from the opening about the condyles: the lower arch rose by about the
        // opening, back to where the arrangement has it.
        assert!(b.lower_travel_mm >= 0.95 * opening, "{b:?}");
        assert!(b.opened_mm == 0.0, "{b:?}");
        // The teeth take most of the bite force; the condyles the rest.
        let condyles = b.condyles.left + b.condyles.right;
        assert!(condyles < 0.5 * BITE_FORCE_N as f32, "{b:?}");
    }
}

#[test]
fn a_mandible_without_posterior_teeth_rests_on_its_condyles_and_incisors() {
    let mut d = dentition("normal");
    // No lower posterior teeth: the mandible closes about its condyles until the incisors meet;
    // the condyles and the front teeth hold the bite, the condyles taking most of it.
    for t in &mut d.teeth {
        if t.fdi.arch() == Arch::Lower && t.fdi.kind().is_posterior() {
            t.extracted = true;
        }
    }
    let teeth = Posed::of_dentition(&d);
    let b = bite("normal", &teeth, true, 2.0);
    assert!(b.stable, "{b:?}");
    assert!(b.max_penetration_mm <= 0.01, "{b:?}");
    assert!(
        b.contacts.iter().all(|c| !c.lower.kind().is_posterior()),
        "{b:?}"
    );
    let condyles = b.condyles.left + b.condyles.right;
    assert!(condyles > 0.5 * BITE_FORCE_N as f32, "{b:?}");
    assert!(
        (b.condyles.left - b.condyles.right).abs() < 0.2 * condyles,
        "{b:?}"
    );
}

#[test]
fn a_bite_that_cannot_close_says_why() {
    let mut d = dentition("normal");
    // Upper molars over lower incisors only: nothing ever meets.
    for t in &mut d.teeth {
        let keep = match t.fdi.arch() {
            Arch::Upper => t.fdi.kind().is_molar(),
            Arch::Lower => !t.fdi.kind().is_posterior(),
        };
        t.extracted = !keep;
    }
    let teeth = Posed::of_dentition(&d);
    let b = bite("normal", &teeth, true, 2.0);
    assert!(!b.stable, "{b:?}");
    assert!(
        b.why.as_deref().is_some_and(|w| w.contains("do not meet")),
        "{b:?}"
    );
    let placed = bite("normal", &teeth, false, 0.0);
    assert_eq!(placed.why.as_deref(), Some("the arches do not touch"));
}

#[test]
fn interpenetrating_arches_are_opened_about_the_hinge_then_settle() {
    let d = dentition("normal");
    let mut teeth = Posed::of_dentition(&d);
    // The lower arch pushed 0.3 mm into the upper, as a segmentation may leave it.
    for t in teeth.iter_mut().filter(|t| t.fdi.arch() == Arch::Lower) {
        t.pose.translation.y += 0.3;
    }
    let placed = bite("normal", &teeth, false, 0.0);
    assert!(placed.max_penetration_mm > 0.2, "{placed:?}");
    let b = bite("normal", &teeth, true, 0.0);
    assert!(b.opened_mm > 0.2, "{b:?}");
    assert!(b.stable, "{b:?}");
    assert!(b.max_penetration_mm <= 0.01, "{b:?}");
    assert!(
        b.contact_teeth.left >= 4 && b.contact_teeth.right >= 4,
        "{b:?}"
    );
}

#[test]
fn excursions_keep_contact_and_flag_guidance_and_interferences() {
    use orthosim::analysis::{ExcursionKind, excursion};
    let d = dentition("normal");
    let teeth = Posed::of_dentition(&d);
    let b = bite("normal", &teeth, true, 0.0);
    assert!(b.stable);
    for kind in [
        ExcursionKind::Protrusive,
        ExcursionKind::Right,
        ExcursionKind::Left,
    ] {
        let e = excursion(&teeth, &b.lower_pose, kind, 6.0);
        assert_eq!(e.steps.len(), 12, "{kind:?}");
        for (k, s) in e.steps.iter().enumerate() {
            assert!((s.mm - 0.5 * (k + 1) as f32).abs() < 1e-6);
            // Sliding keeps contact, and never through the other arch.
            assert!(!s.contacts.is_empty(), "{kind:?} {s:?}");
            assert!(
                s.min_gap_mm >= 0.0 && s.min_gap_mm <= 0.05,
                "{kind:?} {s:?}"
            );
            assert!(["anterior", "canine", "group function", "posterior"].contains(&s.guidance));
            for pair in &s.interferences {
                assert!(s.contacts.contains(pair));
            }
            let side = |f: orthosim::teeth::Fdi| if matches!(f.quadrant(), 2 | 3) { 1 } else { -1 };
            for [u, l] in &s.contacts {
                let flagged = s.interferences.contains(&[*u, *l]);
                match kind {
                    ExcursionKind::Protrusive => {
                        assert_eq!(flagged, u.kind().is_posterior() || l.kind().is_posterior())
                    }
                    ExcursionKind::Right => assert_eq!(flagged, side(*u) == 1 && side(*l) == 1),
                    ExcursionKind::Left => assert_eq!(flagged, side(*u) == -1 && side(*l) == -1),
                }
            }
        }
        // The front teeth guide the jaw open as it slides.
        assert!(e.steps[3].opening_mm > 0.5, "{kind:?} {:?}", e.steps[3]);
        // They disclude the posterior teeth: on the working side from 0.5 to 3 mm of a lateral,
        // everywhere past 1 mm of protrusion up to 3 mm.
        let side = |f: orthosim::teeth::Fdi| if matches!(f.quadrant(), 2 | 3) { 1 } else { -1 };
        for s in e.steps.iter().filter(|s| s.mm <= 3.0 + 1e-3) {
            let posterior = |[u, l]: &[orthosim::teeth::Fdi; 2]| {
                u.kind().is_posterior() || l.kind().is_posterior()
            };
            match kind {
                ExcursionKind::Protrusive if s.mm > 1.0 + 1e-3 => {
                    assert!(!s.contacts.iter().any(posterior), "{s:?}");
                    assert_eq!(s.guidance, "anterior", "{s:?}");
                }
                ExcursionKind::Protrusive => {}
                _ => {
                    let working = if kind == ExcursionKind::Left { 1 } else { -1 };
                    assert!(
                        !s.contacts
                            .iter()
                            .any(|c| posterior(c) && side(c[0]) == working),
                        "{kind:?} {s:?}"
                    );
                    assert!(s.interferences.is_empty(), "{kind:?} {s:?}");
                }
            }
        }
    }
}

#[test]
fn a_settled_bite_placed_in_a_simulation_stays_there() {
    use orthosim::{
        collision::{Method, collision_shapes},
        movement::{MovementSettings, Simulation, max_penetration},
        sphere_tree::{TreeMethod, TreeSettings},
        teeth::Arch,
    };
    let d = dentition("normal");
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None).unwrap();
    let mut sim = Simulation::new(&d, shapes, Method::Exact, MovementSettings::default()).unwrap();
    let b = bite("normal", &Posed::of_simulation(&sim), true, 0.0);
    assert!(b.stable);
    let poses: Vec<_> = sim
        .teeth
        .iter()
        .enumerate()
        .filter(|(_, t)| t.fdi.arch() == Arch::Lower)
        .map(|(i, t)| (i, b.lower_pose.mul(&t.pose)))
        .collect();
    sim.place_teeth(&poses);
    for (i, p) in &poses {
        assert_eq!(sim.teeth[*i].pose, *p);
    }
    assert!(max_penetration(&sim) <= 0.01);
    // Nothing is loaded: the settled teeth rest where they were put.
    for _ in 0..5 {
        assert!(sim.step().moved == 0);
    }
    for (i, p) in &poses {
        assert_eq!(sim.teeth[*i].pose, *p);
    }
}

#[test]
fn the_canine_guided_layout_lets_the_working_canine_guide_laterals() {
    use orthosim::analysis::{ExcursionKind, excursion};
    use orthosim::teeth::{
        ShapeSet, ToothKind, ToothResolution,
        arch::{ArchLayout, Spaces, arrange},
    };
    // The canine-guided layout's working canines guide both laterals, with the posterior teeth
    // of the working side apart.
    let shapes = ShapeSet::shared(ToothResolution::PAPER);
    let guidance = |layout: &ArchLayout| {
        let a = arrange(&shapes, layout, &Spaces::new());
        let geometries: Vec<_> = a
            .poses
            .iter()
            .map(|(f, _)| shapes.get(f.arch(), f.kind()))
            .collect();
        let teeth: Vec<Posed> = a
            .poses
            .iter()
            .zip(&geometries)
            .map(|((fdi, pose), geometry)| Posed {
                fdi: *fdi,
                geometry,
                pose: *pose,
            })
            .collect();
        let b = bite("canine-guided", &teeth, true, 0.0);
        let runs = [
            ExcursionKind::Right,
            ExcursionKind::Left,
            ExcursionKind::Protrusive,
        ]
        .map(|kind| excursion(&teeth, &b.lower_pose, kind, 3.0));
        (b, runs)
    };
    let (_, normal) = guidance(&ArchLayout::default());
    assert!(
        normal[0].steps.iter().all(|s| s.guidance != "canine"),
        "{:?}",
        normal[0]
    );
    let (b, [right, left, protrusive]) = guidance(&ArchLayout::canine_guided());
    assert!(b.stable, "{b:?}");
    assert!(b.max_penetration_mm <= 0.01, "{b:?}");
    assert!((0.05..=0.3).contains(&b.incisor_gap_mm), "{b:?}");
    assert!(
        b.contact_teeth.left >= 4 && b.contact_teeth.right >= 4,
        "{b:?}"
    );
    for (run, working) in [(&right, 1), (&left, 2)] {
        for s in &run.steps {
            // The working canines meet, and nothing posterior meets on the working side.
            assert_eq!(s.guidance, "canine", "{s:?}");
            assert!(
                s.contacts.iter().any(|[u, l]| u.quadrant() == working
                    && u.kind() == ToothKind::Canine
                    && l.kind() == ToothKind::Canine),
                "{s:?}"
            );
            assert!(s.interferences.is_empty(), "{s:?}");
        }
    }
    // Protrusion: the front teeth alone from 1 mm on.
    for s in protrusive.steps.iter().filter(|s| s.mm > 1.0 + 1e-3) {
        assert!(
            s.contacts
                .iter()
                .all(|[u, l]| !u.kind().is_posterior() && !l.kind().is_posterior()),
            "{s:?}"
        );
    }
}
