//! Labelled whole-arch scans in scanner frames: they split into teeth, land in place by
//! themselves, and bad labels or placements are refused with one line.

use glam::Vec3;
use orthosim::{
    geometry::{Pose, TriMesh},
    prelude::*,
    teeth::{
        Dentition,
        import::{
            LabelledMesh, export_labelled_scans,
            orient::{Arranged, OrientError, orient},
            split,
        },
        labelled_scan::{
            LabelFaults, LabelledArch, ScanFormat, ScannerFrame, labelled_arch, labelled_arch_with,
            write_scan,
        },
    },
};

fn normal() -> Dentition {
    Dentition::build(Case::resolve("normal").unwrap()).unwrap()
}

pub(crate) fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("orthosim-labelled-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The teeth of labelled arches written in `frame`, read back in millimetres.
fn teeth_in(frame: &ScannerFrame, arches: &[&LabelledArch]) -> Vec<(Fdi, TriMesh)> {
    let mut out = Vec::new();
    for arch in arches {
        let placed = frame.apply(&arch.mesh);
        let scan = LabelledMesh::from_vertex_labels(placed, &arch.labels).unwrap();
        let mm = frame.units.mm();
        out.extend(
            split(&scan)
                .into_iter()
                .map(|(f, m)| (f, m.map_vertices(|v| v * mm))),
        );
    }
    out
}

fn place(d: &Dentition, teeth: &[(Fdi, TriMesh)]) -> Result<Pose, OrientError> {
    let pairs: Vec<(Fdi, &TriMesh)> = teeth.iter().map(|(f, m)| (*f, m)).collect();
    // The normal case's teeth are the arrangement's, matched at the reference resolution.
    let shapes =
        orthosim::teeth::ShapeSet::shared(orthosim::teeth::import::orient::REFERENCE_RESOLUTION);
    let geometries: Vec<_> = Fdi::all()
        .map(|f| (f, shapes.get(f.arch(), f.kind())))
        .collect();
    orient(&pairs, |fdi| {
        let t = d.tooth(fdi).unwrap();
        Arranged {
            mesh: &geometries.iter().find(|g| g.0 == fdi).unwrap().1.mesh,
            pose: t.pose,
        }
    })
    .map(|o| o.pose)
}

/// Worst distance (mm) between where `found` and the truth put the crowns' cusp tips, and the
/// angle (degrees) between the rotations.
fn error(d: &Dentition, found: &Pose, frame: &ScannerFrame) -> (f32, f32) {
    let truth = frame.pose.inverse();
    let mut worst = 0.0f32;
    for t in d.visible() {
        for tip in &t.geometry.cusp_tips {
            let p = t.pose.transform_point(*tip);
            let scanned = frame.pose.transform_point(p);
            worst = worst.max(
                found
                    .transform_point(scanned)
                    .distance(truth.transform_point(scanned)),
            );
        }
    }
    (
        worst,
        found.rotation.angle_between(truth.rotation).to_degrees(),
    )
}

#[test]
fn labelled_arches_land_within_half_a_millimetre_and_two_degrees_in_a_hundred_frames() {
    let d = normal();
    // Four sets of scan-like arches (different defects and gum lines), each met with every
    // choice of arches.
    let sets: Vec<[LabelledArch; 2]> = (1..=4)
        .map(|seed| {
            [
                labelled_arch(&d, Arch::Upper, 700, seed),
                labelled_arch(&d, Arch::Lower, 700, seed),
            ]
        })
        .collect();
    let (mut worst_mm, mut worst_deg) = (0.0f32, 0.0f32);
    for i in 0..100u64 {
        let frame = ScannerFrame::random(i);
        let [upper, lower] = &sets[(i as usize / 3) % 4];
        // Both arches of a bite, or one arch alone.
        let arches: Vec<&LabelledArch> = match i % 3 {
            0 => vec![upper, lower],
            1 => vec![upper],
            _ => vec![lower],
        };
        let teeth = teeth_in(&frame, &arches);
        let found = place(&d, &teeth).unwrap_or_else(|e| panic!("frame {i}: {e}"));
        let (mm, deg) = error(&d, &found, &frame);
        assert!(mm <= 0.5 && deg <= 2.0, "frame {i}: {mm:.3} mm, {deg:.3}°");
        worst_mm = worst_mm.max(mm);
        worst_deg = worst_deg.max(deg);
    }
    println!("100 frames: worst {worst_mm:.3} mm, {worst_deg:.3}°");
}

#[test]
fn a_mirrored_scan_is_reported_not_placed() {
    let d = normal();
    let lower = labelled_arch(&d, Arch::Lower, 700, 4);
    let frame = ScannerFrame::random(7);
    let mut teeth = teeth_in(&frame, &[&lower]);
    // Mirror every tooth through a plane of the scanner's frame (winding kept outward).
    for (_, m) in &mut teeth {
        *m = m.map_vertices(|v| Vec3::new(-v.x, v.y, v.z));
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
    }
    let e = place(&d, &teeth).unwrap_err();
    assert!(matches!(e, OrientError::Mirrored { .. }), "{e}");
    assert!(e.to_string().contains("mirrored"), "{e}");
    // Too few teeth to find a frame.
    let few = teeth_in(&frame, &[&lower]);
    let e = place(&d, &few[..2]).unwrap_err();
    assert!(e.to_string().contains("at least 3"), "{e}");
}

#[test]
fn labelled_scans_in_every_format_import_without_a_hand_written_transform() {
    let d = normal();
    for (seed, format) in [
        (11, ScanFormat::PlyProperty),
        (12, ScanFormat::PlyColours),
        (13, ScanFormat::ObjJson),
    ] {
        let dir = temp_dir(&format!("{seed}"));
        let (report, frame) = export_labelled_scans(&d, &dir, 1200, seed, format).unwrap();
        let text = std::fs::read_to_string(&report.case_file).unwrap();
        assert!(text.contains("scans"), "{text}");
        assert!(
            !text.contains("translation"),
            "no transform written: {text}"
        );
        let imported = Dentition::build(Case::load(&report.case_file).unwrap())
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        assert_eq!(imported.teeth.len(), 32, "{format:?}");
        assert_eq!(imported.imported.len(), 32, "{format:?}");
        let o = &imported.orientation;
        assert_eq!(o.len(), 1, "{o:?}");
        assert!(o[0].auto && o[0].files.len() == 2, "{o:?}");
        // Every crown where the case had it: its highest point within 0.5 mm.
        for t in imported.visible() {
            let before = d.tooth(t.fdi).unwrap();
            let top = |p: &orthosim::teeth::PlacedTooth| {
                let up = if p.fdi.arch() == Arch::Lower {
                    Vec3::Y
                } else {
                    Vec3::NEG_Y
                };
                p.geometry
                    .mesh
                    .vertices
                    .iter()
                    .map(|v| p.pose.transform_point(*v).dot(up))
                    .fold(f32::NEG_INFINITY, f32::max)
            };
            let shift = (top(t) - top(before)).abs();
            assert!(
                shift < 0.5,
                "{format:?} {}: occlusal end moved {shift} mm",
                t.fdi
            );
        }
        // Every crown got its template root, and no two teeth of an arch start inside each
        // other by more than 0.05 mm (crowns touching as scanned, roots apart).
        for (fdi, r) in &imported.imported {
            let root = r.root.as_ref().unwrap_or_else(|| panic!("{fdi}: no root"));
            assert_eq!(root.kind, "template", "{format:?} {fdi}: {root:?}");
        }
        let inspected = orthosim::analysis::inspect::inspect(&imported);
        for g in &inspected.neighbour_gaps_mm {
            assert!(g.gap_mm > -0.05, "{format:?}: {}-{} {}", g.a, g.b, g.gap_mm);
        }
        assert!(inspected.max_penetration_mm < 0.05, "{format:?}");
        // The placement found is the scanner frame's inverse.
        let truth = frame.pose.inverse();
        let [rx, ry, rz] = o[0].rotation_deg;
        let found = orthosim::geometry::Pose::new(
            glam::Quat::from_rotation_z(rz.to_radians())
                * glam::Quat::from_rotation_y(ry.to_radians())
                * glam::Quat::from_rotation_x(rx.to_radians()),
            Vec3::from_array(o[0].translation),
        );
        let (mm, deg) = error(&d, &found, &frame);
        assert!(
            mm <= 0.5 && deg <= 2.0,
            "{format:?}: {mm} mm, {deg}° ({truth:?})"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

fn write_case(dir: &std::path::Path, text: &str) -> Result<Dentition, String> {
    let path = dir.join("case.ron");
    std::fs::write(&path, text).unwrap();
    Case::load(&path)
        .and_then(Dentition::build)
        .map_err(|e| e.to_string())
}

#[test]
fn bad_labels_are_refused_on_one_line_naming_the_file() {
    let d = normal();
    let dir = temp_dir("bad");
    let lower = labelled_arch(&d, Arch::Lower, 400, 5);
    let frame = ScannerFrame::random(3);
    let placed = frame.apply(&lower.mesh);
    let (obj, json) =
        orthosim::teeth::labelled_scan::write_scan(&lower, &placed, ScanFormat::ObjJson);
    std::fs::write(dir.join("lower.obj"), &obj).unwrap();
    let units = format!("{:?}", frame.units);
    // A label file with one label too few.
    let mut labels: serde_json::Value = serde_json::from_slice(&json.unwrap()).unwrap();
    let full = labels["labels"].as_array().unwrap().clone();
    labels["labels"] = serde_json::Value::Array(full[1..].to_vec());
    std::fs::write(dir.join("short.json"), labels.to_string()).unwrap();
    let e = write_case(
        &dir,
        &format!(r#"Case(name: "s", scans: [(file: "lower.obj", labels: Json("short.json"), units: {units})])"#),
    )
    .unwrap_err();
    let vertices = placed.vertices.len();
    assert!(e.contains(&format!("{} labels", vertices - 1)), "{e}");
    assert!(e.contains(&format!("{vertices} vertices")), "{e}");
    assert!(e.contains("lower.obj") && !e.contains('\n'), "{e}");
    // An unknown tooth number.
    let mut bad = full.clone();
    let at = bad.iter().position(|v| v.as_u64() == Some(36)).unwrap();
    bad[at] = serde_json::json!(19);
    labels["labels"] = serde_json::Value::Array(bad);
    std::fs::write(dir.join("bad.json"), labels.to_string()).unwrap();
    let e = write_case(
        &dir,
        &format!(r#"Case(name: "s", scans: [(file: "lower.obj", labels: Json("bad.json"), units: {units})])"#),
    )
    .unwrap_err();
    assert!(
        e.contains("label 19") && e.contains(&format!("vertex {at}")),
        "{e}"
    );
    // A tooth given twice: in the scan and in `meshes`.
    labels["labels"] = serde_json::Value::Array(full.clone());
    std::fs::write(dir.join("good.json"), labels.to_string()).unwrap();
    let e = write_case(
        &dir,
        &format!(r#"Case(name: "s", scans: [(file: "lower.obj", labels: Json("good.json"), units: {units})], meshes: {{36: (file: "lower.obj")}})"#),
    )
    .unwrap_err();
    assert!(e.contains("tooth 36") && e.contains("meshes"), "{e}");
    // The good labels import: the lower teeth only, placed by themselves.
    let ok = write_case(
        &dir,
        &format!(r#"Case(name: "s", scans: [(file: "lower.obj", labels: Json("good.json"), units: {units})])"#),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(ok.teeth.len(), 16);
    assert!(ok.teeth.iter().all(|t| t.fdi.arch() == Arch::Lower));
    assert!(ok.orientation[0].auto);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn transforms_read_as_auto_identity_or_rigid() {
    use orthosim::teeth::import::Placement;
    let read = |t: &str| {
        Case::parse(
            &format!(r#"Case(name: "t", meshes: {{11: (file: "11.stl"{t})}})"#),
            "t.ron",
        )
        .map(|c| c.case.meshes.0.values().next().unwrap().transform)
        .map_err(|e| e.to_string())
    };
    assert_eq!(read(""), Ok(Placement::Auto));
    assert_eq!(read(", transform: Auto"), Ok(Placement::Auto));
    assert_eq!(read(", transform: Identity"), Ok(Placement::Identity));
    let Ok(Placement::Rigid(r)) = read(", transform: (translation: (0.0, 2.0, 0.0))") else {
        panic!("rigid");
    };
    assert_eq!(r.translation.1.0, 2.0);
    let e = read(", transform: Sideways").unwrap_err();
    assert!(e.contains("Sideways") && e.starts_with("t.ron:1:"), "{e}");
    let e = read(", transform: (translation: (0.0, NaN, 0.0))").unwrap_err();
    assert!(e.contains("finite"), "{e}");
    let e = read(", transform: (translaton: (0.0, 1.0, 0.0))").unwrap_err();
    assert!(e.contains("translaton"), "{e}");
}

#[test]
fn the_arch_is_fitted_to_the_teeth_as_they_stand() {
    let d = normal();
    // Built-in cases keep the arrangement's forms (their teeth stand on them).
    let arranged = d.arch_forms;
    // Every lower tooth 1.5 mm buccal: the fitted lower arch follows them.
    let offsets: Vec<String> = d
        .teeth
        .iter()
        .filter(|t| t.fdi.arch() == Arch::Lower)
        .map(|t| format!("{}: (translation: (0.0, 1.5, 0.0))", t.fdi))
        .collect();
    let text = format!(r#"Case(name: "wide", offsets: {{{}}})"#, offsets.join(", "));
    let wide = Dentition::build(Case::parse(&text, "wide.ron").unwrap()).unwrap();
    let distance = |form: &orthosim::teeth::arch::BetaArch| {
        let curve = orthosim::teeth::arch::ArchCurve::new(form);
        wide.teeth
            .iter()
            .filter(|t| t.fdi.arch() == Arch::Lower)
            .map(|t| curve.distance(glam::Vec2::new(t.pose.translation.x, t.pose.translation.z)))
            .fold(0.0f32, f32::max)
    };
    let before = distance(&arranged[1]);
    let after = distance(&wide.arch_forms[1]);
    assert!(before > 1.3, "{before}");
    assert!(
        after < 0.5,
        "fitted: {after} mm (arrangement's {before} mm)"
    );
    assert_eq!(
        wide.arch_forms[0], arranged[0],
        "the upper teeth did not move"
    );
}

#[test]
fn closed_teeth_files_of_one_frame_keep_their_relative_pose() {
    use orthosim::teeth::import::{export_case, read_mesh, write_stl};
    // 32 closed teeth with roots, as a CBCT segmentation writes them, moved into a scanner frame.
    let d = normal();
    let dir = temp_dir("cbct");
    let report = export_case(&d, &dir).unwrap();
    let frame = ScannerFrame::random(42);
    for path in &report.meshes {
        let mesh = read_mesh(path).unwrap();
        let mut bytes = Vec::new();
        write_stl(&frame.apply(&mesh), &mut bytes).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    let text = std::fs::read_to_string(&report.case_file).unwrap();
    let units = format!("units: {:?}", frame.units);
    let text = text
        .replace("units: Millimetres", &units)
        .replace("transform: Identity", "transform: Auto");
    std::fs::write(&report.case_file, &text).unwrap();
    let placed = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    assert_eq!(placed.orientation.len(), 1);
    assert!(placed.orientation[0].auto);
    assert_eq!(placed.orientation[0].files.len(), 32);
    for t in placed.visible() {
        let before = d.tooth(t.fdi).unwrap();
        let moved = t.crown_centre().distance(before.crown_centre());
        assert!(moved < 0.5, "{}: {moved} mm", t.fdi);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_mislabelled_teeth_do_not_tilt_the_placement() {
    let d = normal();
    let lower = labelled_arch(&d, Arch::Lower, 700, 6);
    let frame = ScannerFrame::random(77);
    let mut teeth = teeth_in(&frame, &[&lower]);
    // The segmentation swapped the canines' labels.
    let (c3, c4) = (Fdi::new(33).unwrap(), Fdi::new(43).unwrap());
    for (f, _) in &mut teeth {
        *f = if *f == c3 {
            c4
        } else if *f == c4 {
            c3
        } else {
            *f
        };
    }
    let found = place(&d, &teeth).unwrap();
    let (mm, deg) = error(&d, &found, &frame);
    assert!(mm <= 0.5 && deg <= 2.0, "{mm} mm, {deg}°");
}

#[test]
fn labelled_arches_that_fail_as_real_segmentations_import_whole() {
    let d = normal();
    let mut actions = std::collections::BTreeSet::new();
    for seed in [21u64, 22] {
        let dir = temp_dir(&format!("faults-{seed}"));
        let frame = ScannerFrame::random(seed);
        let mut scans = String::new();
        for (arch, name) in [(Arch::Upper, "upper"), (Arch::Lower, "lower")] {
            let scan = labelled_arch_with(&d, arch, 700, seed, &LabelFaults::REAL);
            let placed = frame.apply(&scan.mesh);
            let (bytes, _) = write_scan(&scan, &placed, ScanFormat::PlyProperty);
            std::fs::write(dir.join(format!("{name}.ply")), bytes).unwrap();
            scans += &format!(
                r#"(file: "{name}.ply", labels: Property("label"), units: {:?}),"#,
                frame.units
            );
        }
        let imported = write_case(&dir, &format!(r#"Case(name: "faults", scans: [{scans}])"#))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(imported.teeth.len(), 32, "seed {seed}: every tooth imports");
        assert_eq!(imported.imported.len(), 32, "seed {seed}");
        assert_eq!(imported.scans.len(), 2);
        for s in &imported.scans {
            assert!(s.left_out.is_empty(), "seed {seed}: {:?}", s.left_out);
            actions.extend(s.fixes.iter().map(|f| f.action));
            // Fragments on a neighbour go to that neighbour.
            assert!(
                s.fixes.iter().any(|f| f.to != 0 && f.to != f.label),
                "seed {seed}: {:?}",
                s.fixes
            );
        }
        // The crossed central incisors: rebuilt where the repair could not make them a solid,
        // and close to the scan.
        let rebuilt: Vec<_> = imported
            .imported
            .iter()
            .filter_map(|(f, r)| r.rebuilt.as_ref().map(|b| (*f, b)))
            .collect();
        assert!(
            rebuilt.iter().any(|(f, _)| f.arch() == Arch::Upper)
                && rebuilt.iter().any(|(f, _)| f.arch() == Arch::Lower),
            "seed {seed}: {rebuilt:?}"
        );
        for (f, r) in &rebuilt {
            // The crossed central incisors, and now and then a lower incisor with a steep neck.
            assert!(
                matches!(
                    f.kind(),
                    orthosim::teeth::ToothKind::CentralIncisor
                        | orthosim::teeth::ToothKind::LateralIncisor
                ),
                "{f}: {r:?}"
            );
            assert!(r.mean_mm <= 0.05, "seed {seed} {f}: {r:?}");
        }
        for t in imported.visible() {
            t.geometry
                .mesh
                .validate_solid()
                .unwrap_or_else(|e| panic!("seed {seed} {}: {e}", t.fdi));
            // Placed right: each crown where the case has it (the turned ones aside).
            if rebuilt.iter().any(|(f, _)| *f == t.fdi) {
                continue;
            }
            let before = d.tooth(t.fdi).unwrap();
            let up = if t.fdi.arch() == Arch::Lower {
                Vec3::Y
            } else {
                Vec3::NEG_Y
            };
            let centre = |p: &orthosim::teeth::PlacedTooth| p.crown_centre();
            let shift = (centre(t) - centre(before)).reject_from(up).length();
            assert!(shift < 1.0, "seed {seed} {}: moved {shift} mm", t.fdi);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    for action in ["moved", "dropped", "trimmed"] {
        assert!(actions.contains(action), "{action}: {actions:?}");
    }
}
