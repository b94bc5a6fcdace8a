//! Template roots: scanned crowns made from the procedural teeth (where the true root is known)
//! get roots along the true long axis, of the true length, with the true centre of resistance.

use glam::{Quat, Vec3};
use orthosim::{
    geometry::{MeshRef, Pose, TriangleBvh, mesh_separation},
    prelude::*,
    teeth::{
        Dentition,
        anatomy::anatomy,
        arch::ArchCurve,
        import::{
            ImportError, Prepared, RepairLimits, RootGuide, apart::keep_roots_apart,
            export_labelled_scans, prepare_guided,
        },
        labelled_scan::ScanFormat,
        scan_like::ScanDefects,
    },
};

use crate::scans::{normal, scan_of};

#[test]
fn scan_like_crowns_get_roots_along_the_true_axis_of_the_true_length() {
    let d = normal();
    let limits = RepairLimits::default();
    for (n, seed) in [
        (11, 1),
        (12, 2),
        (13, 3),
        (14, 4),
        (16, 5),
        (31, 6),
        (33, 7),
        (36, 8),
        (45, 9),
        (47, 10),
    ] {
        let fdi = Fdi::new(n).unwrap();
        let tooth = d.tooth(fdi).unwrap();
        let scan = scan_of(&d, fdi, 1500, &ScanDefects::typical(seed), seed);
        // The fit starts from a pose 8° and 1 mm off the truth, as the arrangement is off a
        // patient's teeth, and without it (from the crown's margin alone).
        let off = Pose::new(
            Quat::from_axis_angle(Vec3::new(1.0, 0.0, 1.0).normalize(), 0.14) * tooth.pose.rotation,
            tooth.pose.translation + Vec3::new(0.6, -0.5, 0.6),
        );
        for guess in [Some(off), None] {
            let guide = RootGuide {
                guess,
                ..RootGuide::default()
            };
            let p = prepare_guided(&scan.mesh, fdi, &limits, guide)
                .unwrap_or_else(|e| panic!("{n}: {e}"));
            let root = p.repairs.root.clone().expect("a root");
            assert_eq!(root.kind, "template", "{n}: {root:?}");
            let truth = tooth.pose.rotation * Vec3::NEG_Y;
            let axis = p.apical.expect("an axis");
            let angle = axis.angle_between(truth).to_degrees();
            assert!(angle < 5.0, "{n} ({guess:?}): axis {angle}° off");
            let length = anatomy(fdi.arch(), fdi.kind()).root_length;
            assert!(
                (root.length_mm / length - 1.0).abs() < 0.15,
                "{n}: root {} mm, true {length} mm",
                root.length_mm
            );
            // The centre of resistance, from the mesh as the PDL model reads it.
            let curve = ArchCurve::new(&d.arch_forms[usize::from(fdi.arch() == Arch::Lower)]);
            let imported = p.frame(fdi, &curve);
            let cr = imported
                .pose
                .transform_point(imported.geometry.frame.centre_of_resistance);
            let true_cr = tooth
                .pose
                .transform_point(tooth.geometry.frame.centre_of_resistance);
            assert!(
                cr.distance(true_cr) < 0.5,
                "{n}: centre of resistance {} mm off",
                cr.distance(true_cr)
            );
        }
    }
}

#[test]
fn roots_that_start_crossing_are_turned_apart() {
    // Lower central and lateral incisors, crowns where the normal case has them, roots turned 12°
    // towards the midline: the central incisors' roots cross. Turning them apart leaves no pair
    // more than 0.05 mm inside another, and each turned tooth reports its turn.
    let d = normal();
    let limits = RepairLimits::default();
    let fdis: Vec<Fdi> = [42, 41, 31, 32].map(|n| Fdi::new(n).unwrap()).to_vec();
    let inputs: Vec<_> = fdis
        .iter()
        .enumerate()
        .map(|(i, &f)| scan_of(&d, f, 1200, &ScanDefects::CLEAN, 20 + i as u64).mesh)
        .collect();
    let mut guides: Vec<RootGuide> = fdis
        .iter()
        .map(|&f| {
            let tooth = d.tooth(f).unwrap();
            // Lateral incisors' apices towards the midline (x = 0), central incisors' away from
            // it: about each tooth's buccal axis.
            let buccal = tooth.pose.rotation * Vec3::Z;
            let toward = if tooth.pose.translation.x > 0.0 {
                -1.0
            } else {
                1.0
            };
            let turn = if f.kind() == ToothKind::CentralIncisor {
                -14f32
            } else {
                14.0
            };
            RootGuide {
                guess: Some(tooth.pose),
                tilt: buccal * toward * turn.to_radians(),
                ..RootGuide::default()
            }
        })
        .collect();
    let mut results: Vec<_> = fdis
        .iter()
        .zip(&inputs)
        .zip(&guides)
        .map(|((&f, m), g)| prepare_guided(m, f, &limits, *g))
        .collect();
    let deepest = |results: &[Result<Prepared, ImportError>]| {
        let mut worst = 0.0f32;
        for i in 0..results.len() {
            for j in i + 1..results.len() {
                let (a, b) = (results[i].as_ref().unwrap(), results[j].as_ref().unwrap());
                let s = mesh_separation(
                    MeshRef {
                        mesh: &a.mesh,
                        bvh: &TriangleBvh::build(&a.mesh),
                    },
                    &Pose::IDENTITY,
                    MeshRef {
                        mesh: &b.mesh,
                        bvh: &TriangleBvh::build(&b.mesh),
                    },
                    &Pose::IDENTITY,
                );
                worst = worst.max(-s.signed_gap());
            }
        }
        worst
    };
    let before = deepest(&results);
    assert!(before > 0.3, "the roots were to cross: {before} mm");
    keep_roots_apart(&fdis, &inputs, &mut results, &mut guides, &limits);
    let after = deepest(&results);
    assert!(
        after <= 0.05,
        "still {after} mm inside ({before} mm before)"
    );
    for (f, r) in fdis.iter().zip(&results) {
        let root = r.as_ref().unwrap().repairs.root.clone().unwrap();
        assert_eq!(root.kind, "template", "{f}");
        assert!(root.tilt_deg < 14.0, "{f}: {root:?}");
    }
}

#[test]
fn molars_and_the_upper_first_premolar_get_their_roots() {
    // Cut across the root axis two thirds of the way to the apex: a lower molar shows two roots,
    // an upper molar three, the upper first premolar two, a lower premolar one.
    let d = normal();
    let limits = RepairLimits::default();
    for (n, roots) in [(36, 2), (47, 2), (16, 3), (27, 3), (14, 2), (44, 1)] {
        let fdi = Fdi::new(n).unwrap();
        let tooth = d.tooth(fdi).unwrap();
        let scan = scan_of(&d, fdi, 1500, &ScanDefects::CLEAN, n as u64);
        let guide = RootGuide {
            guess: Some(tooth.pose),
            ..RootGuide::default()
        };
        let p = prepare_guided(&scan.mesh, fdi, &limits, guide).unwrap();
        p.mesh.validate_solid().unwrap();
        let root = p.repairs.root.clone().unwrap();
        assert_eq!(root.kind, "template", "{n}: {root:?}");
        let (c, a) = (p.cervical.unwrap(), p.apical.unwrap());
        let at = c + a * (root.length_mm * 0.67);
        let loops = orthosim::geometry::section_loops(&p.mesh, at, a);
        assert_eq!(loops, roots, "{n}: {loops} roots at two thirds");
    }
}

#[test]
fn a_crowded_lower_front_imports_with_no_teeth_inside_each_other() {
    // The lower incisors turned 18° and the canines 12° about their long axes, as crowded teeth
    // stand (their crowns still apart), scanned as one labelled arch: every tooth gets a template
    // root, and no two teeth start more than 0.05 mm inside each other.
    let mut d = normal();
    for (n, deg) in [
        (31, -18f32),
        (41, -18.0),
        (32, -18.0),
        (42, -18.0),
        (33, -12.0),
        (43, -12.0),
    ] {
        let t = d.teeth.iter_mut().find(|t| t.fdi.number() == n).unwrap();
        let axis = t.pose.rotation * Vec3::Y;
        let cervix = t.pose.translation;
        t.pose =
            Pose::turn_about(cervix, Quat::from_axis_angle(axis, deg.to_radians())).mul(&t.pose);
    }
    let lower: Vec<_> = d
        .visible()
        .filter(|t| t.fdi.arch() == Arch::Lower)
        .collect();
    for (i, a) in lower.iter().enumerate() {
        for b in &lower[i + 1..] {
            let s = mesh_separation(
                a.geometry.mesh_ref(),
                &a.pose,
                b.geometry.mesh_ref(),
                &b.pose,
            );
            assert!(
                s.signed_gap() > -0.01,
                "{}-{} overlap as turned",
                a.fdi,
                b.fdi
            );
        }
    }
    let dir = crate::labelled::temp_dir("crowded");
    let (report, _) = export_labelled_scans(&d, &dir, 1200, 31, ScanFormat::PlyProperty).unwrap();
    let imported = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    for (fdi, r) in &imported.imported {
        let root = r.root.as_ref().unwrap_or_else(|| panic!("{fdi}: no root"));
        assert_eq!(root.kind, "template", "{fdi}: {root:?}");
    }
    let inspected = orthosim::analysis::inspect::inspect(&imported);
    for g in &inspected.neighbour_gaps_mm {
        assert!(g.gap_mm > -0.05, "{}-{}: {} mm", g.a, g.b, g.gap_mm);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
