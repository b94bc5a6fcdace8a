//! Mesh import: export a case and read it back, each repair, each refusal, each format.

use std::{io::Write, path::PathBuf};

use glam::Vec3;
use orthosim::{
    geometry::{TriMesh, mesh_separation},
    prelude::*,
    teeth::{
        Dentition,
        arch::ArchCurve,
        import::{RepairLimits, export_case, import_mesh, write_stl},
    },
};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("orthosim-import-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn normal() -> Dentition {
    Dentition::build(Case::resolve("normal").unwrap()).unwrap()
}

/// Tooth `n` of the normal case in the world frame, and its arch curve.
fn world_tooth(d: &Dentition, n: u8) -> (TriMesh, ArchCurve, Fdi) {
    let fdi = Fdi::new(n as i64).unwrap();
    let t = d.tooth(fdi).unwrap();
    let curve = ArchCurve::new(&d.arch_forms[usize::from(fdi.arch() == Arch::Lower)]);
    (
        t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v)),
        curve,
        fdi,
    )
}

fn import(
    mesh: &TriMesh,
    n: u8,
) -> Result<orthosim::teeth::import::ImportedTooth, orthosim::teeth::import::ImportError> {
    let d = normal();
    let (_, curve, fdi) = world_tooth(&d, n);
    import_mesh(mesh, fdi, &curve, &RepairLimits::default())
}

fn world_of(t: &orthosim::teeth::import::ImportedTooth) -> TriMesh {
    t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v))
}

#[test]
fn an_exported_case_reads_back_with_the_same_geometry() {
    let dir = temp_dir("round-trip");
    let d = normal();
    let report = export_case(&d, &dir).unwrap();
    assert_eq!(report.meshes.len(), 32);
    let back = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    assert_eq!(back.imported.len(), 32);
    let mut worst = 0.0f32;
    for (a, b) in d.teeth.iter().zip(&back.teeth) {
        assert_eq!(a.fdi, b.fdi);
        assert!(
            back.imported[&a.fdi].is_clean(),
            "{}: {:?}",
            a.fdi,
            back.imported[&a.fdi]
        );
        let world = |t: &orthosim::teeth::PlacedTooth| -> Vec<Vec3> {
            t.geometry
                .mesh
                .vertices
                .iter()
                .map(|v| t.pose.transform_point(*v))
                .collect()
        };
        let (wa, wb) = (world(a), world(b));
        assert_eq!(wa.len(), wb.len(), "{}", a.fdi);
        assert_eq!(
            a.geometry.mesh.triangles.len(),
            b.geometry.mesh.triangles.len()
        );
        for p in &wa {
            let nearest = wb
                .iter()
                .map(|q| q.distance(*p))
                .fold(f32::INFINITY, f32::min);
            worst = worst.max(nearest);
        }
        let (va, vb) = (a.geometry.frame.volume_mm3, b.geometry.frame.volume_mm3);
        assert!((va - vb).abs() < 1e-3 * va, "{}: {va} vs {vb}", a.fdi);
        // The frame found from the mesh agrees with the procedural one.
        let [m, bu, o] = a.anatomical_axes();
        let [m2, bu2, o2] = b.anatomical_axes();
        assert!(
            o.dot(o2) > 0.95 && bu.dot(bu2) > 0.9 && m.dot(m2) > 0.9,
            "{}",
            a.fdi
        );
    }
    println!("round trip: vertices within {worst:e} mm");
    assert!(worst <= 1e-4, "vertices moved by {worst} mm");
    // Gaps between neighbours are the same.
    for (a, b) in d.neighbour_pairs() {
        let gap = |d: &Dentition| {
            let (x, y) = (d.tooth(a).unwrap(), d.tooth(b).unwrap());
            mesh_separation(
                x.geometry.mesh_ref(),
                &x.pose,
                y.geometry.mesh_ref(),
                &y.pose,
            )
            .distance
        };
        assert!((gap(&d) - gap(&back)).abs() < 1e-3, "{a}-{b}");
    }
    // The exported case is not overwritten by exporting it onto itself.
    let again = export_case(&back, &dir).unwrap_err().to_string();
    assert!(again.contains("refusing"), "{again}");
    // Nor are its mesh files, read by a case kept elsewhere; nothing is written then.
    let text = std::fs::read_to_string(&report.case_file).unwrap();
    let moved = text
        .replace("file: \"", "file: \"../")
        .replace("name: \"normal\"", "name: \"moved\"");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/moved.ron"), moved).unwrap();
    let elsewhere = Dentition::build(Case::load(&dir.join("sub/moved.ron")).unwrap()).unwrap();
    let again = export_case(&elsewhere, &dir).unwrap_err().to_string();
    assert!(
        again.contains("refusing") && again.contains(".stl"),
        "{again}"
    );
    assert!(!dir.join("moved.ron").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn stl_obj_and_ply_files_read_alike() {
    let dir = temp_dir("formats");
    let d = normal();
    let (mesh, _, _) = world_tooth(&d, 21);
    let mut names = Vec::new();
    for (k, (ext, bytes)) in crate::mesh_files::every_format(&mesh)
        .into_iter()
        .enumerate()
    {
        let name = format!("21-{k}.{ext}");
        std::fs::write(dir.join(&name), bytes).unwrap();
        names.push(name);
    }
    for name in &names {
        let read = orthosim::teeth::import::read_mesh(&dir.join(name)).unwrap();
        let t = import(&read, 21).unwrap();
        let w = world_of(&t);
        assert_eq!(w.triangles.len(), mesh.triangles.len(), "{name}");
        assert!(
            (w.signed_volume() - mesh.signed_volume()).abs() < 1e-3 * mesh.signed_volume(),
            "{name}"
        );
    }
    // Units and transforms: a file in metres, shifted, lands in the same place.
    let metres = mesh.map_vertices(|v| (v - Vec3::new(0.0, 5.0, 0.0)) / 1000.0);
    let mut bytes = Vec::new();
    write_stl(&metres, &mut bytes).unwrap();
    std::fs::write(dir.join("21m.stl"), bytes).unwrap();
    let case = r#"Case(name: "one", teeth: Only([21]), meshes: {21: (file: "21m.stl", units: Metres, transform: (translation: (0.0, 5.0, 0.0)))})"#;
    std::fs::write(dir.join("one.ron"), case).unwrap();
    let one = Dentition::build(Case::load(&dir.join("one.ron")).unwrap()).unwrap();
    let t = &one.teeth[0];
    let c = t.pose.transform_point(t.geometry.frame.crown_centre);
    let original = d.tooth(Fdi::new(21).unwrap()).unwrap().crown_centre();
    assert!(c.distance(original) < 1e-2, "{c} vs {original}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn each_repair_is_made_and_reported() {
    let d = normal();
    let (mesh, _, _) = world_tooth(&d, 36);
    let volume = mesh.signed_volume();

    // Unwelded: every triangle with its own three vertices.
    let mut loose = TriMesh::default();
    for i in 0..mesh.triangles.len() {
        let base = loose.vertices.len() as u32;
        loose.vertices.extend(mesh.triangle(i));
        loose.triangles.push([base, base + 1, base + 2]);
    }
    let t = import(&loose, 36).unwrap();
    assert_eq!(
        t.repairs.welded_vertices,
        loose.vertices.len() - mesh.vertices.len()
    );
    assert_eq!(t.geometry.mesh.vertices.len(), mesh.vertices.len());

    // A degenerate and a duplicated triangle.
    let mut m = mesh.clone();
    m.triangles.push([0, 0, 1]);
    m.triangles.push(mesh.triangles[5]);
    let t = import(&m, 36).unwrap();
    assert_eq!(
        (
            t.repairs.degenerate_triangles,
            t.repairs.duplicate_triangles
        ),
        (1, 1)
    );

    // Ten triangles wound the wrong way.
    let mut m = mesh.clone();
    for t in m.triangles.iter_mut().step_by(17).take(10) {
        t.swap(1, 2);
    }
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.flipped_triangles, 10);
    assert!(!t.repairs.turned_outward);

    // All of them: the surface faces inward.
    let m = mesh.map_vertices(|v| v);
    let mut m = m;
    m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    let t = import(&m, 36).unwrap();
    assert!(t.repairs.turned_outward);
    assert!((world_of(&t).signed_volume() - volume).abs() < 1e-3 * volume);

    // A small hole: the triangle with the shortest boundary removed.
    let mut m = mesh.clone();
    let perimeter = |i: usize| {
        let [a, b, c] = mesh.triangle(i);
        a.distance(b) + b.distance(c) + c.distance(a)
    };
    let small = (0..mesh.triangles.len())
        .min_by(|&i, &j| perimeter(i).total_cmp(&perimeter(j)))
        .unwrap();
    m.triangles.remove(small);
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.holes_closed_mm.len(), 1);
    assert!(t.repairs.holes_closed_mm[0] > 0.0);
    assert!((world_of(&t).signed_volume() - volume).abs() < 0.02 * volume);

    // Debris: a small loose tetrahedron beside the tooth.
    let mut m = mesh.clone();
    let base = m.vertices.len() as u32;
    let p = mesh.aabb().max + Vec3::splat(3.0);
    m.vertices
        .extend([p, p + Vec3::X * 0.1, p + Vec3::Y * 0.1, p + Vec3::Z * 0.1]);
    m.triangles.extend([
        [base, base + 2, base + 1],
        [base, base + 1, base + 3],
        [base, base + 3, base + 2],
        [base + 1, base + 2, base + 3],
    ]);
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.debris_pieces, 1);
    assert!(t.repairs.summary().contains("loose pieces dropped"));

    // A fin: a third triangle on an edge. The edge's triangles go, and the hole is closed.
    let mut m = mesh.clone();
    let [a, b, _] = mesh.triangles[0];
    m.vertices.push(mesh.aabb().max + Vec3::ONE);
    m.triangles.push([a, b, m.vertices.len() as u32 - 1]);
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.fin_triangles, 3);
    assert_eq!(t.repairs.holes_closed_mm.len(), 1);
    assert!((world_of(&t).signed_volume() - volume).abs() < 0.02 * volume);

    // A bow-tie: two triangles of one vertex's fan removed, so two holes meet at the vertex.
    let mut m = mesh.clone();
    let v = m.triangles[40][0];
    let fan: Vec<usize> = (0..m.triangles.len())
        .filter(|&i| m.triangles[i].contains(&v))
        .collect();
    let shares_edge = |i: usize, j: usize| {
        m.triangles[i]
            .iter()
            .filter(|x| m.triangles[j].contains(x))
            .count()
            > 1
    };
    let other = *fan[1..].iter().find(|&&j| !shares_edge(fan[0], j)).unwrap();
    let (hi, lo) = (fan[0].max(other), fan[0].min(other));
    m.triangles.remove(hi);
    m.triangles.remove(lo);
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.split_vertices, 1, "{:?}", t.repairs);
    // Split, the vertex's two copies join the two holes into one opening, closed at once.
    assert_eq!(t.repairs.holes_closed_mm.len(), 1);
    assert!((world_of(&t).signed_volume() - volume).abs() < 0.02 * volume);

    // A spike: the highest cusp's vertex pulled 12 mm out along its normal goes back among its neighbours.
    let mut m = mesh.clone();
    let normals = mesh.vertex_normals();
    let top = (0..mesh.vertices.len())
        .max_by(|&a, &b| mesh.vertices[a].y.total_cmp(&mesh.vertices[b].y))
        .unwrap();
    m.vertices[top] += normals[top] * 12.0;
    let t = import(&m, 36).unwrap();
    assert_eq!(t.repairs.spikes_smoothed, 1, "{:?}", t.repairs);
    assert!((world_of(&t).signed_volume() - volume).abs() < 0.02 * volume);
    assert!(t.repairs.summary().contains("spikes smoothed"));
}

#[test]
fn a_scanned_crown_gets_a_generated_root() {
    let d = normal();
    let fdi = Fdi::new(36).unwrap();
    let tooth = d.tooth(fdi).unwrap();
    let f = &tooth.geometry.frame;
    // The crown only: triangles above the cervical plane.
    let local = &tooth.geometry.mesh;
    let mut crown = local.clone();
    crown.triangles.retain(|t| {
        let c = (local.vertices[t[0] as usize]
            + local.vertices[t[1] as usize]
            + local.vertices[t[2] as usize])
            / 3.0;
        (c - f.cervical_centre).dot(f.long_axis) > 0.0
    });
    let world = crown.map_vertices(|v| tooth.pose.transform_point(v));
    let t = import(&world, 36).unwrap();
    let margin = t.repairs.root_generated_margin_mm.expect("a root");
    assert!(margin > 15.0, "{margin} mm margin");
    let w = world_of(&t);
    w.validate_solid().unwrap();
    // The root reaches about one root length beyond the margin, on the apical side.
    let an = tooth.geometry.anatomy;
    let apical = -orthosim::teeth::import::occlusal_direction(fdi.arch());
    let deepest = w
        .vertices
        .iter()
        .map(|v| v.dot(apical))
        .fold(f32::NEG_INFINITY, f32::max);
    let margin_level = tooth.pose.transform_point(f.cervical_centre).dot(apical);
    let reach = deepest - margin_level;
    assert!(
        (reach - an.root_length).abs() < 0.25 * an.root_length,
        "root reaches {reach} mm, table {}",
        an.root_length
    );
    // Its volume is of the order of the procedural tooth's.
    let ratio = w.signed_volume() / local.signed_volume();
    assert!((0.6..1.4).contains(&ratio), "{ratio}");
}

#[test]
fn broken_meshes_are_refused_with_the_reason() {
    let d = normal();
    let (mesh, _, _) = world_tooth(&d, 36);
    let refuse = |m: &TriMesh, what: &str| {
        let e = match import(m, 36) {
            Ok(t) => panic!("expected '{what}', imported: {}", t.repairs.summary()),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(what), "expected '{what}' in: {e}");
    };
    refuse(&TriMesh::default(), "empty");
    // A file in metres read as millimetres.
    refuse(&mesh.map_vertices(|v| v / 1000.0), "units");
    let mut m = mesh.clone();
    m.vertices[3].x = f32::NAN;
    refuse(&m, "non-finite");
    // A crown upside down: its margin faces the occlusal side.
    let crown = d.tooth(Fdi::new(36).unwrap()).unwrap();
    let f = &crown.geometry.frame;
    let mut cut = crown.geometry.mesh.clone();
    let local = crown.geometry.mesh.clone();
    cut.triangles.retain(|t| {
        let c = (local.vertices[t[0] as usize]
            + local.vertices[t[1] as usize]
            + local.vertices[t[2] as usize])
            / 3.0;
        (c - f.cervical_centre).dot(f.long_axis) > 0.0
    });
    let flip = glam::Quat::from_rotation_x(std::f32::consts::PI);
    let upside_down = cut.map_vertices(|v| crown.pose.transform_point(flip * v));
    refuse(&upside_down, "does not face the root's side");
    // Two teeth in one file.
    let mut m = mesh.clone();
    let (other, _, _) = world_tooth(&d, 46);
    let base = m.vertices.len() as u32;
    m.vertices.extend(&other.vertices);
    m.triangles
        .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    refuse(&m, "separate pieces");
    // The crown turned sideways through the root: crossings over far more than the repair cuts.
    let c = mesh.aabb().centre();
    let turn = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let m = mesh.map_vertices(|v| if v.y > c.y { c + turn * (v - c) } else { v });
    refuse(&m, "intersects itself");
}

#[test]
fn bad_mesh_files_fail_naming_the_file_and_tooth() {
    let dir = temp_dir("bad-files");
    std::fs::write(dir.join("empty.stl"), b"").unwrap();
    std::fs::write(
        dir.join("nan.obj"),
        "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n",
    )
    .unwrap();
    let mut f = std::fs::File::create(dir.join("junk.ply")).unwrap();
    f.write_all(
        b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\nbanana\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n").unwrap();
    for (file, what) in [
        ("bad.obj", "line 3"),
        ("empty.stl", "empty"),
        ("nan.obj", "non-finite"),
        ("junk.ply", "PLY"),
        ("missing.stl", "cannot read"),
        ("tooth.xyz", ".stl, .obj or .ply"),
    ] {
        let case = format!(
            r#"Case(name: "bad", teeth: Only([11, 21]), meshes: {{11: (file: "{file}")}})"#
        );
        let path = dir.join("bad.ron");
        std::fs::write(&path, case).unwrap();
        let e = Case::load(&path)
            .and_then(Dentition::build)
            .unwrap_err()
            .to_string();
        assert!(e.contains(what), "{file}: {e}");
        assert!(e.contains(file), "{file}: {e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_tooth_file_the_repair_refuses_is_rebuilt_in_a_case() {
    // The crown turned sideways through the root, as in the refusal test: `import_mesh` refuses
    // it, while a case naming the file imports it rebuilt, near where the file has it.
    let d = normal();
    let (mesh, _, _) = world_tooth(&d, 36);
    let c = mesh.aabb().centre();
    let turn = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let m = mesh.map_vertices(|v| if v.y > c.y { c + turn * (v - c) } else { v });
    assert!(import(&m, 36).is_err());
    let dir = temp_dir("rebuilt");
    let mut file = std::fs::File::create(dir.join("36.stl")).unwrap();
    orthosim::teeth::import::write_stl(&m, &mut file).unwrap();
    drop(file);
    let case = dir.join("case.ron");
    std::fs::write(
        &case,
        r#"Case(name: "rebuilt", meshes: {36: (file: "36.stl", transform: Identity)})"#,
    )
    .unwrap();
    let built = Dentition::build(Case::load(&case).unwrap()).unwrap();
    let repairs = &built.imported[&Fdi::new(36).unwrap()];
    let r = repairs.rebuilt.as_ref().expect("rebuilt");
    assert!(r.reason.contains("intersects itself"), "{r:?}");
    assert!(r.mean_mm <= 0.05, "{r:?}");
    let t = built.tooth(Fdi::new(36).unwrap()).unwrap();
    t.geometry.mesh.validate_solid().unwrap();
    let volume = t.geometry.mesh.signed_volume();
    assert!(volume > 0.5 * m.signed_volume().abs(), "{volume}");
    let _ = std::fs::remove_dir_all(&dir);
}
