//! Overjet, overbite and molar relation measured on the teeth a case has, where they stand.

use orthosim::{
    analysis::measure_occlusion,
    prelude::*,
    teeth::{Dentition, import::export_case},
};

fn build(ron: &str) -> Dentition {
    Dentition::build(Case::parse(ron, "test.ron").unwrap()).unwrap()
}

#[test]
fn the_normal_case_measures_as_its_arrangement() {
    let d = Dentition::build(Case::resolve("normal").unwrap()).unwrap();
    let m = measure_occlusion(&d);
    let a = d.arrangement;
    assert!(
        (m.overjet_mm.unwrap() - a.overjet_mm).abs() < 1e-4,
        "{m:?} {a:?}"
    );
    assert!((m.overbite_mm.unwrap() - a.overbite_mm).abs() < 1e-4);
    assert!((m.molar_relation_mm.unwrap() - a.molar_relation_mm).abs() < 1e-4);
    assert!(m.unmeasured.is_empty());
}

#[test]
fn offsets_and_extractions_change_what_is_measured() {
    let base = build(r#"(name: "base")"#);
    let b = measure_occlusion(&base);
    // Both upper central incisors 1 mm labially: the overjet grows by about 1 mm; the molars stay.
    let flared = build(
        r#"(name: "flared", offsets: {
            11: (translation: (0.0, 1.0, 0.0)),
            21: (translation: (0.0, 1.0, 0.0)),
        })"#,
    );
    let f = measure_occlusion(&flared);
    let grew = f.overjet_mm.unwrap() - b.overjet_mm.unwrap();
    assert!((0.7..1.1).contains(&grew), "overjet grew {grew} mm");
    assert!((f.molar_relation_mm.unwrap() - b.molar_relation_mm.unwrap()).abs() < 1e-5);
    // The arrangement's numbers do not see the offsets; the measure does.
    assert!((flared.arrangement.overjet_mm - base.arrangement.overjet_mm).abs() < 1e-6);
    // One side only: the other side's pair measures alone.
    let one = build(r#"(name: "one", extracted: [11, 16])"#);
    let o = measure_occlusion(&one);
    assert!(o.overjet_mm.is_some() && o.molar_relation_mm.is_some());
    // Both upper centrals and both lower first molars gone: null, and why.
    let gone = build(r#"(name: "gone", extracted: [11, 21, 36, 46])"#);
    let g = measure_occlusion(&gone);
    assert_eq!(
        (g.overjet_mm, g.overbite_mm, g.molar_relation_mm),
        (None, None, None)
    );
    assert!(g.unmeasured["overjet_mm"].contains("11, 21"), "{g:?}");
    assert!(g.unmeasured["molar_relation_mm"].contains("36"), "{g:?}");
    let json = serde_json::to_value(&g).unwrap();
    assert!(json["overjet_mm"].is_null());
}

#[test]
fn imported_teeth_measure_as_the_teeth_they_were() {
    let dir = std::env::temp_dir().join(format!("orthosim-occlusion-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let d = Dentition::build(Case::resolve("normal").unwrap()).unwrap();
    let report = export_case(&d, &dir).unwrap();
    let back = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    let (a, b) = (measure_occlusion(&d), measure_occlusion(&back));
    for (x, y) in [
        (a.overjet_mm, b.overjet_mm),
        (a.overbite_mm, b.overbite_mm),
        (a.molar_relation_mm, b.molar_relation_mm),
    ] {
        // An imported incisor's incisal point is its highest vertex, not the solid's edge point.
        assert!((x.unwrap() - y.unwrap()).abs() < 0.15, "{a:?} {b:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
