//! The `orthosim` binary's headless subcommands, as a user runs them.

use std::process::Command;

pub(crate) fn orthosim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orthosim"))
        .args(args)
        .output()
        .expect("the orthosim binary runs")
}

/// Runs `orthosim` with `args`, which must succeed (else the test fails with its stderr).
pub(crate) fn succeed(args: &[&str]) -> std::process::Output {
    let out = orthosim(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `orthosim` with `args`, which must succeed, and parses its one JSON object.
fn json_of(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&succeed(args).stdout).expect("one JSON object")
}

/// An empty folder private to this test process.
fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("orthosim-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn cases_lists_the_builtin_cases() {
    let out = orthosim(&["cases"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let names: Vec<&str> = text
        .lines()
        .map(|l| l.split_whitespace().next().unwrap_or(""))
        .collect();
    assert_eq!(
        names,
        [
            "normal",
            "case1",
            "case2",
            "case3",
            "crowded",
            "case1-chain"
        ],
        "{text}"
    );
}

#[test]
fn simulate_days_reports_the_wire_and_its_brackets() {
    let out = succeed(&[
        "simulate",
        "--case",
        "crowded",
        "--algorithm",
        "exact",
        "--days",
        "3",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["days"], 3.0);
    assert_eq!(v["at_rest"], false);
    let a = &v["appliance"];
    assert_eq!(a["wire"]["material"], "NiTi");
    assert_eq!(a["wire"]["size"], ".014\"");
    assert_eq!(a["wire"]["form"], "ovoid");
    assert_eq!(a["wires"]["lower"].as_array().unwrap().len(), 1);
    let brackets = a["brackets"].as_array().unwrap();
    assert_eq!(brackets.len(), 14);
    assert_eq!(brackets[0]["fdi"], 47);
    assert!(brackets.iter().any(|b| b["engaged"] == true));
    for b in brackets {
        assert_eq!(b["force_n"].as_array().unwrap().len(), 3);
        assert_eq!(b["moment_nmm"].as_array().unwrap().len(), 3);
    }
    assert!(a["solve_us_per_step"][0].as_f64().unwrap() > 0.0);
    // Little's index of each arch, day by day: the lower arch's crowding starts at 5–6 mm and
    // falls; the upper arch stands aligned.
    let lower = a["irregularity_mm"]["lower"].as_array().unwrap();
    assert_eq!(lower.len(), 4, "{lower:?}");
    let mm = |p: &serde_json::Value| p[1].as_f64().unwrap();
    assert_eq!(lower[0][0], 0.0);
    assert_eq!(lower[3][0], 3.0);
    assert!((5.0..6.0).contains(&mm(&lower[0])), "{lower:?}");
    assert!(mm(&lower[3]) < mm(&lower[0]), "{lower:?}");
    // The canine-to-canine chain waits for day 120.
    assert_eq!(a["chains"][0]["from"], 43);
    assert_eq!(a["chains"][0]["to"], 33);
    assert!(a["chains"][0]["placed_day"].is_null());
    assert_eq!(a["chains"][0]["tension_n"], 0.0);
    let upper = a["irregularity_mm"]["upper"].as_array().unwrap();
    assert!(upper.iter().all(|p| mm(p) < 0.01), "{upper:?}");
    // No root reaches the bone's plates in three days of light NiTi.
    assert_eq!(a["cortical_contacts"], serde_json::json!([]));
    assert_eq!(v["cortical_contacts"], serde_json::json!([]));
    // Days are refused where they mean nothing, and when not a number of days.
    for bad in [
        vec![
            "simulate", "--case", "normal", "--model", "paper", "--days", "3",
        ],
        vec!["simulate", "--case", "normal", "--days=-1"],
        vec!["simulate", "--case", "normal", "--days", "NaN"],
    ] {
        let out = orthosim(&bad);
        assert!(!out.status.success(), "{bad:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains("days"), "{bad:?}: {err}");
    }
}

#[test]
fn inspect_normal_meets_the_arrangement_figures() {
    let out = succeed(&["inspect", "--case", "normal", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["case"], "normal");
    // Aligned rows: Little's index 0 with its five contacts, and the arch-length discrepancy
    // of teeth in contact (a millimetre or so).
    for (k, arch) in ["upper", "lower"].iter().enumerate() {
        let a = &v["alignment"][k];
        assert_eq!(a["arch"], *arch);
        assert!(a["irregularity_mm"].as_f64().unwrap() < 0.01, "{a}");
        assert_eq!(a["contacts"].as_array().unwrap().len(), 5);
        assert!(
            a["arch_length_discrepancy_mm"].as_f64().unwrap().abs() < 3.0,
            "{a}"
        );
    }
    let teeth = v["teeth"].as_array().unwrap();
    assert_eq!(teeth.len(), 32);
    for t in teeth {
        for key in [
            "fdi",
            "kind",
            "arch",
            "vertices",
            "triangles",
            "closed",
            "volume_mm3",
            "crown_centre",
            "extracted",
        ] {
            assert!(t.get(key).is_some(), "missing {key} in {t}");
        }
        assert_eq!(t["closed"], true, "{t}");
        assert!(t["volume_mm3"].as_f64().unwrap() > 0.0);
        let n = t["vertices"].as_u64().unwrap();
        assert!((100..=250).contains(&n), "{n} vertices: {t}");
        assert_eq!(t["crown_centre"].as_array().unwrap().len(), 3);
    }
    let gaps = v["neighbour_gaps_mm"].as_array().unwrap();
    assert_eq!(gaps.len(), 30, "15 contacts per arch");
    for g in gaps {
        let gap = g["gap_mm"].as_f64().unwrap();
        assert!((0.0..=0.1).contains(&gap), "{g}");
    }
    assert!(v["max_penetration_mm"].as_f64().unwrap() <= 0.01);
    assert!(v["occlusal_max_penetration_mm"].as_f64().unwrap() <= 0.05);
}

#[test]
fn inspect_skips_extracted_teeth_in_the_gaps() {
    let out = orthosim(&["inspect", "--case", "case1", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let gaps = v["neighbour_gaps_mm"].as_array().unwrap();
    assert_eq!(gaps.len(), 26, "14 visible teeth per arch");
    let across = gaps
        .iter()
        .find(|g| g["a"] == 15 && g["b"] == 13)
        .expect("15-13 pair across the space");
    assert!(across["gap_mm"].as_f64().unwrap() > 5.0, "{across}");
    assert!(gaps.iter().all(|g| g["a"] != 14 && g["b"] != 14));
}

#[test]
fn bad_case_files_fail_with_one_line_and_a_position() {
    let dir = std::env::temp_dir().join(format!("orthosim-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "syntax.ron",
            "Case(\n  name: \"x\"\n  extracted: [14],\n)\n",
            ":3:",
        ),
        (
            "unknown.ron",
            "Case(\n  name: \"x\",\n  extracted: [14, 59],\n)\n",
            ":3:",
        ),
        (
            "nan.ron",
            "Case(\n  name: \"x\",\n  loads: [(teeth: [16], force: World(inf, 0.0, 0.0))],\n)\n",
            ":3:",
        ),
        (
            "extracted.ron",
            "Case(\n  name: \"x\",\n  extracted: [16],\n  loads: [(teeth: [16], force: World(1.0, 0.0, 0.0))],\n)\n",
            ":4:",
        ),
        ("empty.ron", "", ":1:1:"),
    ];
    for (name, text, position) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let out = orthosim(&["inspect", "--case", path.to_str().unwrap()]);
        assert!(!out.status.success(), "{name} accepted");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&format!("{name}{position}")), "{name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let out = orthosim(&["inspect", "--case", "no-such-case"]);
    assert!(!out.status.success());
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn help_lists_the_subcommands() {
    let out = orthosim(&["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for sub in ["view", "cases", "inspect", "trees", "validate"] {
        assert!(text.contains(sub), "{text}");
    }
}

#[test]
fn trees_reports_covering_octrees_and_writes_sph_files() {
    let dir = std::env::temp_dir().join(format!("orthosim-trees-{}", std::process::id()));
    let out = succeed(&[
        "trees",
        "--case",
        "normal",
        "--method",
        "octree",
        "--depth",
        "3",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(
        (
            v["method"].as_str(),
            v["branching"].as_u64(),
            v["depth"].as_u64()
        ),
        (Some("octree"), Some(8), Some(3))
    );
    let teeth = v["teeth"].as_array().unwrap();
    assert_eq!(teeth.len(), 32);
    for t in teeth {
        for key in [
            "fdi",
            "leaves",
            "sov_sum",
            "sov_union",
            "max_overhang_mm",
            "covered",
            "build_ms",
        ] {
            assert!(t.get(key).is_some(), "missing {key} in {t}");
        }
        assert!(
            t["sov_sum"].as_f64().unwrap() >= t["sov_union"].as_f64().unwrap() - 1e-9,
            "{t}"
        );
        let leaves = t["leaves"].as_u64().unwrap();
        assert!((1..=64).contains(&leaves), "{t}");
    }
    let s = &v["summary"];
    for key in [
        "sov_sum_mean",
        "sov_sum_min",
        "sov_sum_max",
        "sov_union_mean",
        "max_overhang_mm_mean",
        "leaves_mean",
        "all_covered",
        "build_ms_total",
    ] {
        assert!(s.get(key).is_some(), "missing {key} in {s}");
    }
    assert_eq!(s["all_covered"], true);
    let written = std::fs::read_to_string(dir.join("36.sph")).unwrap();
    let tree = orthosim::sphere_tree::SphereTree::from_sph(&written).unwrap();
    assert_eq!((tree.levels, tree.branching), (3, 8));
    assert_eq!(
        tree.leaves().count() as u64,
        teeth.iter().find(|t| t["fdi"] == 36).unwrap()["leaves"]
            .as_u64()
            .unwrap()
    );
    let refused = orthosim(&["trees", "--method", "octree", "--branching", "4"]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("branching 8"));
    std::fs::remove_dir_all(dir).ok();
}

/// `trees --resolution` rebuilds the teeth at another vertex count (other meshes, other fits);
/// a count out of range is refused.
#[test]
fn trees_take_a_resolution() {
    let sov = |extra: &[&str]| -> Vec<f64> {
        let mut args = vec!["trees", "--depth", "2", "--json"];
        args.extend_from_slice(extra);
        json_of(&args)["teeth"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["sov_sum"].as_f64().unwrap())
            .collect()
    };
    let default = sov(&[]);
    assert_eq!(default, sov(&["--resolution", "125"]), "125 is the default");
    let finer = sov(&["--resolution", "400"]);
    assert_eq!(finer.len(), default.len());
    assert_ne!(finer, default);
    let out = orthosim(&["trees", "--resolution", "5"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--resolution"), "{err}");
}

#[test]
fn medial_trees_fit_tightly_and_come_back_from_the_cache() {
    let cache = std::env::temp_dir().join(format!("orthosim-tree-cache-{}", std::process::id()));
    std::fs::remove_dir_all(&cache).ok();
    let run = || {
        let out = succeed(&[
            "trees",
            "--method",
            "medial",
            "--depth",
            "3",
            "--json",
            "--cache",
            cache.to_str().unwrap(),
        ]);
        serde_json::from_slice::<serde_json::Value>(&out.stdout).expect("one JSON object")
    };
    let first = run();
    let s = &first["summary"];
    assert_eq!(s["all_covered"], true);
    // The octree at this depth has a mean near 3 (the guide's table, docs/sphere-trees.md); the medial builder must stay far
    // below it (0.30 in that table; a polish that lost track of piece corners gave 0.34),
    // and within the budget of 8² leaves.
    let mean = s["sov_sum_mean"].as_f64().unwrap();
    assert!(mean > 0.0 && mean < 0.32, "{s}");
    let teeth = first["teeth"].as_array().unwrap();
    assert!(teeth.iter().all(|t| t["leaves"].as_u64().unwrap() <= 64));
    assert!(teeth.iter().all(|t| t["from_cache"] == false));
    // 16 distinct shapes, one file each.
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 16);
    let second = run();
    let again = second["teeth"].as_array().unwrap();
    assert!(again.iter().all(|t| t["from_cache"] == true));
    for (a, b) in teeth.iter().zip(again) {
        assert_eq!(
            a["sov_sum"], b["sov_sum"],
            "the cached tree is the built one"
        );
        assert_eq!(a["leaves"], b["leaves"]);
    }
    std::fs::remove_dir_all(&cache).ok();
}

#[test]
fn bench_reports_every_method_with_no_false_negatives() {
    let out = succeed(&[
        "bench",
        "--pairs",
        "60",
        "--tree",
        "octree",
        "--no-cache",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["pairs"], 60);
    assert!(v["full_mouth_step_us"].as_f64().unwrap() > 0.0);
    let methods = v["methods"].as_array().unwrap();
    let names: Vec<&str> = methods
        .iter()
        .map(|m| m["method"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["circles", "spheres", "continuous", "exact"]);
    for m in methods {
        for key in [
            "us_per_pair",
            "false_negatives",
            "false_positives",
            "mean_error_mm",
            "max_error_mm",
        ] {
            assert!(m.get(key).is_some(), "missing {key} in {m}");
        }
        if m["method"] != "circles" {
            assert_eq!(m["false_negatives"], 0, "{m}");
        }
    }
    let exact = &methods[3];
    assert_eq!(exact["false_positives"], 0);
    assert!(
        exact["max_error_mm"].as_f64().unwrap() <= 0.01 + 1e-6,
        "{exact}"
    );
    // The stress set: same measures, still no misses.
    assert_eq!(v["stress"]["pairs"], 60);
    let stress = v["stress"]["methods"].as_array().unwrap();
    assert_eq!(stress.len(), 4);
    for m in &stress[1..] {
        assert_eq!(m["false_negatives"], 0, "{m}");
    }
}

#[test]
fn bench_sweep_prints_run_time_against_error() {
    let out = succeed(&[
        "bench",
        "--sweep",
        "--pairs",
        "40",
        "--tree",
        "octree",
        "--no-cache",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["pairs"], 40);
    let pareto = v["pareto"].as_array().unwrap();
    let tolerances: Vec<f64> = pareto
        .iter()
        .map(|p| p["tolerance_mm"].as_f64().unwrap())
        .collect();
    let expected = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05];
    assert_eq!(tolerances.len(), expected.len());
    for (t, e) in tolerances.iter().zip(expected) {
        assert!((t - e).abs() < 1e-6, "{t} for {e}");
    }
    let mut contacts = 0;
    for p in pareto {
        assert!(p["us_per_pair"].as_f64().unwrap() > 0.0, "{p}");
        assert_eq!(p["false_negatives"], 0, "{p}");
        let tol = p["tolerance_mm"].as_f64().unwrap();
        assert!(
            p["max_error_mm"].as_f64().unwrap() <= tol * 1.01 + 1e-6,
            "{p}"
        );
        // A looser tolerance stops sooner, never later: it finds every contact a tighter one
        // finds.
        let c = p["contacts"].as_u64().unwrap();
        assert!(c >= contacts, "{p}");
        contacts = c;
    }
    assert!(contacts > 0);
}

#[test]
fn simulate_reports_the_contract_keys() {
    let out = succeed(&[
        "simulate",
        "--case",
        "case3",
        "--algorithm",
        "circles",
        "--tree",
        "octree",
        "--no-cache",
        "--max-steps",
        "40",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    for key in [
        "case",
        "algorithm",
        "response",
        "steps",
        "at_rest",
        "moved",
        "displacement_mm",
        "max_penetration_mm",
        "distances",
        "total_centre_distance_mm",
        "collision_us_per_step",
        "step_us",
        "model",
        "days",
        "teeth",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["model"], "pdl");
    let teeth = v["teeth"].as_array().unwrap();
    assert_eq!(teeth.len(), 32);
    for t in teeth {
        assert!(t["fdi"].as_u64().is_some(), "{t}");
        for key in ["crown_displacement_mm", "apex_displacement_mm"] {
            assert_eq!(t[key].as_array().map(|a| a.len()), Some(3), "{t}");
        }
        assert!(t["rotation_deg"].as_f64().is_some(), "{t}");
    }
    // A day a step by default.
    let steps = v["steps"].as_f64().unwrap();
    assert!((v["days"].as_f64().unwrap() - steps).abs() < 1e-6);
    assert_eq!(v["case"], "case3");
    assert_eq!(v["algorithm"], "circles");
    assert_eq!(v["response"], "block");
    assert!(v["steps"].as_u64().unwrap() <= 40);
    let distances = v["distances"].as_array().unwrap();
    assert_eq!(distances.len(), 30, "15 adjacent pairs per arch");
    for d in distances {
        for key in ["a", "b", "centre_distance_mm", "surface_gap_mm"] {
            assert!(d.get(key).is_some(), "{d}");
        }
    }
    assert_eq!(v["displacement_mm"].as_object().unwrap().len(), 32);
    let total: f64 = distances
        .iter()
        .map(|d| d["centre_distance_mm"].as_f64().unwrap())
        .sum();
    assert!((total - v["total_centre_distance_mm"].as_f64().unwrap()).abs() < 1e-3);
}

#[test]
fn simulate_takes_either_model_and_validate_prints_its_rows() {
    let out = succeed(&[
        "simulate",
        "--case",
        "case3",
        "--model",
        "paper",
        "--tree",
        "octree",
        "--no-cache",
        "--max-steps",
        "20",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "paper");
    let seconds = v["days"].as_f64().unwrap() * 86_400.0;
    assert!(
        (seconds - v["steps"].as_f64().unwrap() / 64.0).abs() < 1e-6,
        "{v}"
    );
    let out = orthosim(&["simulate", "--model", "springs"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("pdl") && err.contains("paper"), "{err}");

    let out = succeed(&["validate", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["model"], "pdl");
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 25);
    for name in [
        "torque_play_deg",
        "twist_for_20nmm_deg",
        "power_arm_bodily_mm",
    ] {
        assert!(
            rows.iter().any(|r| r["name"] == name && r["unit"] != ""),
            "{name}"
        );
    }
    assert!(
        rows.iter()
            .any(|r| r["name"] == "niti_unloading_force_n" && r["tooth"] == 0)
    );
    assert!(
        rows.iter()
            .any(|r| r["name"] == "crowded_alignment_days" && r["unit"] == "days")
    );
    for r in rows {
        for key in ["name", "tooth", "value", "unit", "reference", "source"] {
            assert!(r.get(key).is_some(), "{key} missing: {r}");
        }
    }
    assert!(rows.iter().any(|r| r["mf"].as_f64() == Some(12.0)));
    let table = succeed(&["validate"]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains("canine_retraction_mm_per_month_1n"), "{text}");
    assert!(!text.contains("OUTSIDE"), "{text}");
}

#[test]
fn occlusion_reports_the_settled_bite_with_the_contract_keys() {
    let v = json_of(&["occlusion", "--settle", "--opening", "2", "--json"]);
    for key in [
        "case",
        "stable",
        "max_penetration_mm",
        "incisor_gap_mm",
        "contact_teeth",
        "contacts",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["case"], "normal");
    assert_eq!(v["stable"], true, "{v}");
    assert!(v["contact_teeth"]["left"].as_u64().unwrap() >= 1);
    assert!(v["contact_teeth"]["right"].as_u64().unwrap() >= 1);
    for c in v["contacts"].as_array().unwrap() {
        for key in ["upper", "lower", "area_mm2", "min_gap_mm"] {
            assert!(c.get(key).is_some(), "{c}");
        }
    }
    let out = orthosim(&["occlusion", "--opening", "9"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("0 to 5 mm"));
}

#[test]
fn simulate_refuses_unknown_cases_and_bad_options_in_one_line() {
    let out = orthosim(&["simulate", "--case", "nosuch"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("nosuch"), "{err}");
    let out = orthosim(&["simulate", "--response", "bounce"]);
    assert!(!out.status.success());
}

#[test]
fn report_writes_every_file_its_page_refers_to() {
    let dir = std::env::temp_dir().join(format!("orthosim-report-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    succeed(&[
        "report",
        "--case",
        "case3",
        "--out",
        dir.to_str().unwrap(),
        "--tree",
        "octree",
        "--fit-depths",
        "3",
        "--no-cache",
        "--sweep",
        "400",
        "--sweep-pairs",
        "24",
    ]);
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let mut refs = Vec::new();
    for attr in ["href=\"", "src=\""] {
        for part in html.split(attr).skip(1) {
            refs.push(part.split('"').next().unwrap().to_owned());
        }
    }
    for f in [
        "summary.json",
        "distances.csv",
        "case3.svg",
        "case3.png",
        "occlusion_upper.png",
        "occlusion_lower.png",
        "occlusion_upper.svg",
        "occlusion_lower.svg",
        "pareto.png",
        "pareto.svg",
    ] {
        assert!(refs.iter().any(|r| r == f), "index.html refers to {f}");
    }
    for r in &refs {
        let len = std::fs::metadata(dir.join(r)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{r} missing or empty");
    }
    for png in [
        "case3.png",
        "occlusion_upper.png",
        "occlusion_lower.png",
        "pareto.png",
    ] {
        let png = std::fs::read(dir.join(png)).unwrap();
        assert_eq!(&png[..4], b"\x89PNG");
    }
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for m in ["circles", "spheres", "continuous", "exact"] {
        let a = &v["cases"]["case3"][m];
        for key in ["total_centre_distance_mm", "max_penetration_mm", "moved"] {
            assert!(a.get(key).is_some(), "{m}: {key}");
        }
    }
    assert!(
        v["cases"]["case3"]["exact"]["max_penetration_mm"]
            .as_f64()
            .unwrap()
            <= 0.01
    );
    assert_eq!(v["bite"]["stable"], true, "{}", v["bite"]);
    let sweep = &v["sweep"];
    assert_eq!(sweep["vertices"], 400, "{sweep}");
    let pareto = sweep["pareto"].as_array().unwrap();
    assert_eq!(pareto.len(), 6, "{sweep}");
    for p in pareto {
        let tol = p["tolerance_mm"].as_f64().unwrap();
        assert!(p["us_per_pair"].as_f64().unwrap() > 0.0, "{p}");
        assert!(
            p["max_error_mm"].as_f64().unwrap() <= tol * 1.01 + 1e-6,
            "{p}"
        );
        assert_eq!(p["false_negatives"], 0, "{p}");
    }
    assert_eq!(
        v["biomechanics"]["rows"].as_array().map(|r| r.len()),
        Some(25)
    );
    assert!(html.contains("The bite") && html.contains("biomechanics"));
    let fit = v["tree_fit"].as_array().unwrap();
    assert_eq!(fit.len(), 2, "octree and medial at depth 3");
    for row in fit {
        for key in [
            "method",
            "depth",
            "sov_sum_mean",
            "sov_sum_min",
            "sov_sum_max",
        ] {
            assert!(row.get(key).is_some(), "{row}");
        }
    }
    for key in [
        "anterior_ratio_pct",
        "overall_ratio_pct",
        "arch_length_discrepancy_upper_mm",
    ] {
        assert!(v["bolton"][key].is_number(), "{key}");
    }
    // One row per adjacent pair (15 per arch) per algorithm.
    let csv = std::fs::read_to_string(dir.join("distances.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "case,algorithm,tooth_a,tooth_b,centre_distance_mm,surface_gap_mm"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 4 * 30);
    for m in ["circles", "spheres", "continuous", "exact"] {
        assert_eq!(
            rows.iter()
                .filter(|r| r.starts_with(&format!("case3,{m},")))
                .count(),
            30
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn export_case_writes_a_case_that_imports_and_simulates_like_the_original() {
    let dir = fresh_dir("export");
    succeed(&[
        "export-case",
        "--case",
        "case1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let case = dir.join("case1.ron");
    assert!(case.exists());
    assert_eq!(
        std::fs::read_dir(&dir)
            .unwrap()
            .filter(|e| e
                .as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "stl"))
            .count(),
        32
    );
    let inspect = |case: &str| json_of(&["inspect", "--case", case, "--json"]);
    let (a, b) = (inspect("case1"), inspect(case.to_str().unwrap()));
    assert_eq!(b["imported"].as_array().unwrap().len(), 32);
    for m in b["imported"].as_array().unwrap() {
        assert_eq!(m["summary"], "nothing", "{m}");
    }
    let gaps = |v: &serde_json::Value| -> Vec<f64> {
        v["neighbour_gaps_mm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|g| g["gap_mm"].as_f64().unwrap())
            .collect()
    };
    let (ga, gb) = (gaps(&a), gaps(&b));
    assert_eq!(ga.len(), gb.len());
    for (x, y) in ga.iter().zip(&gb) {
        assert!((x - y).abs() < 1e-3, "{x} vs {y}");
    }
    // The imported case simulates like the original: the same teeth move, about as far.
    let simulate = |case: &str| {
        json_of(&[
            "simulate",
            "--case",
            case,
            "--tree",
            "octree",
            "--no-cache",
            "--max-steps",
            "300",
            "--json",
        ])
    };
    let (sa, sb) = (simulate("case1"), simulate(case.to_str().unwrap()));
    assert_eq!(sa["moved"], sb["moved"]);
    assert!(!sa["moved"].as_array().unwrap().is_empty());
    for (fdi, da) in sa["displacement_mm"].as_object().unwrap() {
        let (da, db) = (
            da.as_f64().unwrap(),
            sb["displacement_mm"][fdi].as_f64().unwrap(),
        );
        assert!((da - db).abs() <= 0.05 + 0.1 * da, "{fdi}: {da} vs {db} mm");
    }
    assert!(sb["max_penetration_mm"].as_f64().unwrap() < 0.05, "{sb}");
    // Exporting over the folder the case was read from is refused, and nothing is lost.
    let before = std::fs::read(&case).unwrap();
    let again = orthosim(&[
        "export-case",
        "--case",
        case.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("refusing"));
    assert_eq!(std::fs::read(&case).unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_labelled_scan_export_is_placed_inspected_and_simulated_without_a_transform() {
    let dir = fresh_dir("labelled");
    succeed(&[
        "export-case",
        "--case",
        "case1",
        "--out",
        dir.to_str().unwrap(),
        "--scan-like",
        "1000",
        "--labelled",
        "ply",
        "--seed",
        "5",
    ]);
    let case = dir.join("case1.ron");
    let text = std::fs::read_to_string(&case).unwrap();
    assert!(
        text.contains("scans") && !text.contains("transform: ("),
        "{text}"
    );
    let report = json_of(&["inspect", "--case", case.to_str().unwrap(), "--json"]);
    let o = report["orientation"].as_array().unwrap();
    assert_eq!(o.len(), 1, "{o:?}");
    assert_eq!(o[0]["auto"], true);
    assert_eq!(o[0]["files"].as_array().unwrap().len(), 2);
    assert_eq!(o[0]["rotation_deg"].as_array().unwrap().len(), 3);
    // case1's first premolars are extracted: the scans hold the other 28 teeth.
    assert_eq!(report["teeth"].as_array().unwrap().len(), 28);
    assert_eq!(report["imported"].as_array().unwrap().len(), 28);
    let sim = json_of(&[
        "simulate",
        "--case",
        case.to_str().unwrap(),
        "--tree",
        "octree",
        "--no-cache",
        "--max-steps",
        "300",
        "--json",
    ]);
    assert!(!sim["moved"].as_array().unwrap().is_empty(), "{sim}");
    assert!(sim["max_penetration_mm"].as_f64().unwrap() < 0.05, "{sim}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scans_that_fail_as_real_segmentations_import_whole_and_inspect_says_how() {
    let dir = fresh_dir("faults");
    succeed(&[
        "export-case",
        "--case",
        "normal",
        "--out",
        dir.to_str().unwrap(),
        "--scan-like",
        "700",
        "--labelled",
        "ply",
        "--faults",
        "--seed",
        "22",
    ]);
    let case = dir.join("normal.ron");
    let report = json_of(&["inspect", "--case", case.to_str().unwrap(), "--json"]);
    assert_eq!(
        report["teeth"].as_array().unwrap().len(),
        32,
        "no tooth left out"
    );
    let scans = report["scans"].as_array().unwrap();
    assert_eq!(scans.len(), 2);
    for s in scans {
        assert!(s["left_out"].as_array().unwrap().is_empty(), "{s}");
        for f in s["fixes"].as_array().unwrap() {
            for key in ["label", "action", "to", "triangles", "at"] {
                assert!(f.get(key).is_some(), "missing {key} in {f}");
            }
        }
    }
    let rebuilt: Vec<_> = report["imported"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m["repairs"].get("rebuilt"))
        .collect();
    assert!(!rebuilt.is_empty(), "{report}");
    for r in &rebuilt {
        for key in [
            "reason",
            "cell_mm",
            "mean_mm",
            "p95_mm",
            "max_mm",
            "triangles",
        ] {
            assert!(r.get(key).is_some(), "missing {key} in {r}");
        }
        assert!(r["mean_mm"].as_f64().unwrap() <= 0.05, "{r}");
    }
    // The table says the same in words.
    let table = succeed(&["inspect", "--case", case.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains("labels of upper.ply"), "{text}");
    assert!(text.contains("rebuilt on a"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_never_replace_the_case_file_being_read() {
    let dir = fresh_dir("inputs");
    let text = "Case(name: \"odd\", teeth: Only([11, 21]))\n";
    for (name, args) in [
        (
            "index.html",
            vec!["report", "--max-steps", "1", "--fit-depths", "2"],
        ),
        ("shot.png", vec!["screenshot"]),
    ] {
        let case = dir.join(name);
        std::fs::write(&case, text).unwrap();
        let mut all: Vec<&str> = args.clone();
        all.extend(["--case", case.to_str().unwrap(), "--out"]);
        let out_arg = if name.ends_with(".png") {
            case.to_str().unwrap().to_owned()
        } else {
            dir.to_str().unwrap().to_owned()
        };
        all.push(&out_arg);
        let out = orthosim(&all);
        assert!(!out.status.success(), "{name}: the input was overwritten");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("refusing to overwrite"), "{name}: {err}");
        assert_eq!(
            std::fs::read_to_string(&case).unwrap(),
            text,
            "{name} changed"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A case's name becomes a file name on export: names of 1–120 characters without control
/// characters are accepted, others refused at the name's position in the file.
#[test]
fn case_names_are_short_and_printable() {
    let dir = fresh_dir("names");
    for (name, ok) in [
        ("a".to_owned(), true),
        ("é".repeat(120), true),
        (String::new(), false),
        ("n".repeat(121), false),
        ("n".repeat(300_000), false),
        ("tab\there".to_owned(), false),
    ] {
        let case = dir.join("named.ron");
        let text =
            format!("// a case\nCase(\n    name: \"{name}\",\n    teeth: Only([11, 21]),\n)\n");
        std::fs::write(&case, text).unwrap();
        let out = orthosim(&["inspect", "--case", case.to_str().unwrap(), "--json"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.success(), ok, "{} chars: {err}", name.len());
        if !ok {
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(err.contains("named.ron:3:5:"), "{err}");
            assert!(err.contains("case name"), "{err}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `export-case` checks every output before it writes any: a refused export leaves the folder as
/// it was, and a folder it would have created is not created.
#[test]
fn a_refused_export_writes_nothing() {
    let dir = fresh_dir("all-or-nothing");
    // The case file sits where the export would write its 21.stl: refused before anything is written.
    let case = dir.join("21.stl");
    std::fs::write(&case, "Case(name: \"x\", teeth: Only([11, 21]))\n").unwrap();
    // A case file named with an extension other than .ron still loads: it is named in full.
    let out = orthosim(&[
        "export-case",
        "--case",
        case.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("21.stl: refusing to overwrite"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(left, ["21.stl"], "nothing written beside the case");
    // An output folder that does not exist is not created by a refused export.
    let fresh = dir.join("new");
    let long = "d".repeat(300);
    let out = orthosim(&[
        "export-case",
        "--case",
        case.to_str().unwrap(),
        "--out",
        fresh.join(&long).to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(!fresh.exists(), "a refused export created its folder");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scan_like_export_imports_and_runs_through_inspect_trees_and_simulate() {
    let dir = fresh_dir("scan-like");
    succeed(&[
        "export-case",
        "--case",
        "case1",
        "--scan-like",
        "1500",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let case = dir.join("case1.ron");
    let case = case.to_str().unwrap();
    let report = json_of(&["inspect", "--case", case, "--json"]);
    let imported = report["imported"].as_array().unwrap();
    assert_eq!(imported.len(), 32);
    for m in imported {
        assert!(m["repairs"]["root_generated_margin_mm"].is_number(), "{m}");
    }
    for t in report["teeth"].as_array().unwrap() {
        assert_eq!(t["closed"], true, "{t}");
        // Each crown's root is its tooth type's template, along the template's axis.
        let root = &t["root"];
        assert_eq!(root["kind"], "template", "{t}");
        let length = root["length_mm"].as_f64().unwrap();
        assert!((10.0..18.0).contains(&length), "{t}");
        assert!(root["axis_deg"].as_f64().unwrap() < 45.0, "{t}");
    }
    // The occlusion is measured on the scanned teeth.
    assert!(report["occlusion"]["molar_relation_mm"].is_number());
    let trees = json_of(&["trees", "--case", case, "--method", "octree", "--json"]);
    assert_eq!(
        trees["summary"]["all_covered"], true,
        "{}",
        trees["summary"]
    );
    let sim = json_of(&[
        "simulate",
        "--case",
        case,
        "--tree",
        "octree",
        "--no-cache",
        "--max-steps",
        "300",
        "--json",
    ]);
    // The same teeth move as in the built-in case, and no deeper into their neighbours than the
    // scanned teeth already were (generated roots of neighbours can start overlapping).
    let built_in = json_of(&[
        "simulate",
        "--case",
        "case1",
        "--tree",
        "octree",
        "--no-cache",
        "--max-steps",
        "300",
        "--json",
    ]);
    assert_eq!(sim["moved"], built_in["moved"], "{sim}");
    let start = report["max_penetration_mm"].as_f64().unwrap();
    let end = sim["max_penetration_mm"].as_f64().unwrap();
    assert!(
        end <= start + 0.05,
        "{start} mm at the start, {end} mm after"
    );
}
