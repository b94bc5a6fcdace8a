//! The house rules of the source tree, checked on every test run: every `crate::` path points down
//! the layer order of DESIGN.md, no file under src/ is longer than 700 lines, main.rs only
//! dispatches, and the library returns typed errors.

use std::{
    collections::BTreeSet,
    path::{Path, PathBuf},
};

/// Layers, lowest first: a module may use only the ones before it (and itself).
const ORDER: [&str; 14] = [
    "geometry",
    "io",
    "parallel",
    "teeth",
    "sphere_tree",
    "collision",
    "appliance",
    "simulation",
    "movement",
    "planning",
    "analysis",
    "occlusion_view",
    "ui",
    "cli",
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under src/, in a fixed order.
fn source_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The layer a source file belongs to (None for lib.rs, which may use every layer).
fn layer_of(rel: &Path) -> Option<String> {
    let first = rel.components().next()?.as_os_str().to_str()?.to_owned();
    match first.as_str() {
        "lib.rs" => None,
        "main.rs" | "cli" => Some("cli".into()),
        f => Some(f.trim_end_matches(".rs").to_owned()),
    }
}

/// The text without `#[cfg(test)]` items (test modules may reach anywhere); a file that is itself
/// a test module (`tests.rs`) is left out whole.
fn without_tests(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            let (mut depth, mut started) = (0i64, false);
            for next in lines.by_ref() {
                depth += next.matches('{').count() as i64 - next.matches('}').count() as i64;
                started |= next.contains('{');
                if (started && depth <= 0) || (!started && next.trim_end().ends_with(';')) {
                    break;
                }
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The top-level modules a text names through `crate::`: in paths (`crate::teeth::Fdi`) and in
/// grouped imports (`use crate::{teeth::Fdi, geometry::Pose}`).
fn named_layers(text: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        let rest = &text[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // The items of the group at its top level of braces.
            let (mut depth, mut item) = (0, String::new());
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.insert(ident(item.trim()));
                        item.clear();
                    }
                    _ if depth == 0 => item.push(c),
                    _ => {}
                }
            }
            out.insert(ident(item.trim()));
        } else {
            out.insert(ident(rest));
        }
    }
    out.retain(|m| !m.is_empty() && m.starts_with(|c: char| c.is_ascii_lowercase()));
    out
}

#[test]
fn every_import_points_down_the_layers() {
    let files = source_files();
    let mut upward = Vec::new();
    let mut unknown = BTreeSet::new();
    for path in &files {
        let rel = path.strip_prefix(src()).unwrap();
        let Some(me) = layer_of(rel) else {
            continue;
        };
        if path.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let Some(rank) = ORDER.iter().position(|l| *l == me) else {
            unknown.insert(me);
            continue;
        };
        let text = without_tests(&std::fs::read_to_string(path).unwrap());
        for target in named_layers(&text) {
            if ["self", "super", "prelude", "internals"].contains(&target.as_str()) || target == me
            {
                continue;
            }
            match ORDER.iter().position(|l| *l == target) {
                Some(t) if t > rank => {
                    upward.push(format!("{}: {me} uses {target}", rel.display()))
                }
                Some(_) => {}
                None => {
                    unknown.insert(target);
                }
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "modules outside the layer order: {unknown:?}"
    );
    assert!(
        upward.is_empty(),
        "imports that point up:\n{}",
        upward.join("\n")
    );
}

#[test]
fn the_layer_check_sees_an_upward_import() {
    // The check itself: a grouped import and a path, at the top level and nested.
    let text = "use crate::{geometry::Pose, teeth::{Fdi, case::Case}};\nfn f() { crate::ui::x(); }\n\
                #[cfg(test)]\nmod tests {\n    use crate::cli::y;\n}\n";
    let named = named_layers(&without_tests(text));
    assert_eq!(
        named.into_iter().collect::<Vec<_>>(),
        ["geometry", "teeth", "ui"]
    );
}

#[test]
fn no_source_file_is_longer_than_700_lines_and_main_only_dispatches() {
    let files = source_files();
    let long: Vec<String> = files
        .iter()
        .filter_map(|p| {
            let n = std::fs::read_to_string(p).unwrap().lines().count();
            (n > 700).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "files over 700 lines: {long:?}");
    let main = std::fs::read_to_string(src().join("main.rs")).unwrap();
    assert!(
        main.lines().count() < 80,
        "main.rs is {} lines",
        main.lines().count()
    );
}

#[test]
fn the_library_returns_typed_errors() {
    let files = source_files();
    let stringly: Vec<String> = files
        .iter()
        .filter(|p| layer_of(p.strip_prefix(src()).unwrap()).is_some_and(|l| l != "cli"))
        .flat_map(|p| {
            let text = without_tests(&std::fs::read_to_string(p).unwrap());
            let hits: Vec<String> = text
                .lines()
                .filter(|l| {
                    let l = l.replace(' ', "");
                    l.contains(",String>") && l.contains("Result<") || l.contains("anyhow")
                })
                .map(|l| format!("{}: {}", p.display(), l.trim()))
                .collect();
            hits
        })
        .collect();
    assert!(
        stringly.is_empty(),
        "string errors or anyhow in the library:\n{}",
        stringly.join("\n")
    );
}
