//! Malformed input, generated: case files and mesh files mutated at random must give a clear
//! one-line error (naming the file, and for case files the line and column) or a valid result,
//! never a panic. A fixed budget of cases per run (proptest).

use std::panic::{AssertUnwindSafe, catch_unwind};

use orthosim::{
    prelude::*,
    teeth::{
        Dentition,
        arch::ArchCurve,
        import::{
            Labels, RepairLimits, check_scan, import_mesh,
            orient::{Arranged, orient},
            read_labelled, read_mesh, split,
        },
        labelled_scan::{ScanFormat, labelled_arch, tooth_colour, write_scan},
    },
};
use proptest::prelude::*;

/// A mutation of a text or byte string: (position fraction, kind, payload).
type Mutation = (f64, u8, Vec<u8>);

const TOKENS: [&str; 16] = [
    "NaN", "inf", "-inf", "1e999", "-1", "99", "0", "(", ")", "[", "]", ",", ":", "\"", "Some(",
    "//",
];

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    prop::collection::vec(
        (
            0.0f64..1.0,
            0u8..4,
            prop::collection::vec(any::<u8>(), 0..6),
        ),
        1..6,
    )
}

fn mutate(source: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut s = source.to_vec();
    for (at, kind, payload) in muts {
        let i = ((s.len() as f64) * at) as usize;
        let i = i.min(s.len());
        match kind {
            // Delete a few bytes.
            0 => {
                let end = (i + 1 + payload.len()).min(s.len());
                s.drain(i..end);
            }
            // Insert random bytes.
            1 => {
                s.splice(i..i, payload.iter().copied());
            }
            // Insert a token that parsers and validators must refuse or accept cleanly.
            2 => {
                let t = TOKENS[payload.first().copied().unwrap_or(0) as usize % TOKENS.len()];
                s.splice(i..i, t.bytes());
            }
            // Overwrite a byte.
            _ => {
                if i < s.len() {
                    s[i] = payload.first().copied().unwrap_or(b'#');
                }
            }
        }
    }
    s
}

fn one_line(e: &impl std::fmt::Display) {
    let e = e.to_string();
    assert!(!e.is_empty() && !e.contains('\n'), "not one line: {e:?}");
}

fn case_sources() -> Vec<String> {
    let mut v: Vec<String> = Case::builtin_names()
        .map(|n| Case::resolve(n).unwrap().source)
        .collect();
    v.push(
        r#"Case(name: "m", teeth: Only([11, 21]), meshes: {11: (file: "11.stl", units: Metres,
            transform: (translation: (0.0, 1.0, 0.0), rotation_deg: (0.0, 0.0, 90.0)))})"#
            .into(),
    );
    v.push(
        r#"Case(name: "s", scans: [(file: "lower.ply", labels: Colours({(139, 0, 0): 41, (255, 48, 48): 42}),
            units: Inches), (file: "upper.obj", labels: Json("upper.json"), transform: Identity)],
            meshes: {36: (file: "36.stl", transform: Auto)}, loads: [(teeth: [41], force: World(0.0, 0.0, 1.0))])"#
            .into(),
    );
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn mutated_case_files_never_panic(which in 0usize..6, muts in mutations()) {
        let sources = case_sources();
        let source = mutate(sources[which % sources.len()].as_bytes(), &muts);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let text = String::from_utf8_lossy(&source).into_owned();
            match Case::parse(&text, "fuzz.ron") {
                Err(e) => {
                    let e = e.to_string();
                    one_line(&e);
                    assert!(e.starts_with("fuzz.ron:"), "{e}");
                }
                Ok(loaded) => {
                    // Keep the run short: large resolutions are valid but slow to build.
                    if loaded.case.resolution.is_none_or(|r| r <= 2000)
                        && let Err(e) = Dentition::build(loaded)
                    {
                        one_line(&e.to_string());
                    }
                }
            }
        }));
        prop_assert!(outcome.is_ok(), "panicked on: {}", String::from_utf8_lossy(&source));
    }
}

/// The normal case, built once.
fn normal() -> &'static Dentition {
    static D: std::sync::OnceLock<Dentition> = std::sync::OnceLock::new();
    D.get_or_init(|| Dentition::build(Case::resolve("normal").unwrap()).unwrap())
}

/// A tooth's mesh in four file formats (made once).
fn mesh_files() -> &'static [(&'static str, Vec<u8>)] {
    static FILES: std::sync::OnceLock<Vec<(&'static str, Vec<u8>)>> = std::sync::OnceLock::new();
    FILES.get_or_init(make_mesh_files)
}

fn make_mesh_files() -> Vec<(&'static str, Vec<u8>)> {
    let t = normal().tooth(Fdi::new(11).unwrap()).unwrap();
    let m = t.geometry.mesh.map_vertices(|v| t.pose.transform_point(v));
    crate::mesh_files::every_format(&m)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn mutated_mesh_files_never_panic(which in 0usize..4, muts in mutations(), junk in prop::collection::vec(any::<u8>(), 0..200), raw in any::<bool>()) {
        let (ext, bytes) = &mesh_files()[which];
        let bytes = if raw { junk } else { mutate(bytes, &muts) };
        let dir = std::env::temp_dir().join(format!("orthosim-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("tooth.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            match read_mesh(&path) {
                Err(e) => one_line(&e),
                Ok(mesh) => {
                    let curve = ArchCurve::new(&normal().arch_forms[0]);
                    if let Err(e) = import_mesh(&mesh, Fdi::new(11).unwrap(), &curve, &RepairLimits::default()) {
                        one_line(&e);
                    }
                }
            }
        }));
        prop_assert!(outcome.is_ok(), "panicked on a mutated .{ext} file");
    }
}

/// A labelled scan file: mesh extension, mesh bytes, labels, JSON label bytes.
type ScanFiles = (&'static str, Vec<u8>, Labels, Vec<u8>);

/// A lower arch as labelled scans in three forms (made once).
fn labelled_files() -> &'static [ScanFiles] {
    static FILES: std::sync::OnceLock<Vec<ScanFiles>> = std::sync::OnceLock::new();
    FILES.get_or_init(|| {
        let d = normal();
        let arch = labelled_arch(d, Arch::Lower, 300, 9);
        let colours = d
            .teeth
            .iter()
            .filter(|t| t.fdi.arch() == Arch::Lower)
            .map(|t| (tooth_colour(t.fdi), t.fdi))
            .collect();
        [
            (
                ScanFormat::PlyProperty,
                "ply",
                Labels::Property("label".into()),
            ),
            (ScanFormat::PlyColours, "ply", Labels::Colours(colours)),
            (
                ScanFormat::ObjJson,
                "obj",
                Labels::Json("labels.json".into()),
            ),
        ]
        .into_iter()
        .map(|(format, ext, labels)| {
            let (mesh, json) = write_scan(&arch, &arch.mesh, format);
            (ext, mesh, labels, json.unwrap_or_default())
        })
        .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    #[test]
    fn mutated_labelled_scans_never_panic(which in 0usize..3, muts in mutations(), json in any::<bool>()) {
        let (ext, mesh, labels, label_bytes) = &labelled_files()[which];
        let (mesh, label_bytes) = if json && *ext == "obj" {
            (mesh.clone(), mutate(label_bytes, &muts))
        } else {
            (mutate(mesh, &muts), label_bytes.clone())
        };
        let dir = std::env::temp_dir().join(format!("orthosim-fuzz-scan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("lower.{ext}"));
        let label_path = dir.join("labels.json");
        std::fs::write(&path, &mesh).unwrap();
        std::fs::write(&label_path, &label_bytes).unwrap();
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            match read_labelled(&path, labels, Some(&label_path)).and_then(|s| check_scan(&s).map(|()| s)) {
                Err(e) => one_line(&e),
                Ok(scan) => {
                    let teeth = split(&scan);
                    let pairs: Vec<(Fdi, &orthosim::geometry::TriMesh)> =
                        teeth.iter().map(|(f, m)| (*f, m)).collect();
                    let d = normal();
                    if let Err(e) = orient(&pairs, |fdi| {
                        let t = d.tooth(fdi).unwrap();
                        Arranged { mesh: &t.geometry.mesh, pose: t.pose }
                    }) {
                        one_line(&e);
                    }
                }
            }
        }));
        prop_assert!(outcome.is_ok(), "panicked on a mutated labelled .{ext} scan");
    }
}
