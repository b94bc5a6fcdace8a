//! Treatment plans: stages within the limits, no tooth through another between stages (parry3d
//! as the oracle), the target reached, IPR where teeth must pass, sequencing, bad files, the
//! command, and a plan on scan-like labelled arches at scan resolution.

use glam::Vec3;
use orthosim::{
    collision::Motion,
    geometry::{Pose, mesh_separation},
    planning::{
        Plan, PlanLimits, Sequence, Target, automatic, clearance::BAND_MM, from_offsets, plan,
    },
    teeth::{
        Case, Dentition, Fdi,
        case::{CaseOffset, Finite, ToothMap},
        labelled_scan::ScanFormat,
    },
};
use parry3d::query as pq;

use crate::parry_support::{pmesh, ppose};

fn case(name: &str) -> Dentition {
    Dentition::build(Case::resolve(name).unwrap()).unwrap()
}

fn fdi(n: i64) -> Fdi {
    Fdi::new(n).unwrap()
}

fn planned(d: &Dentition, limits: &PlanLimits) -> (Target, Plan) {
    let target = automatic(d, limits);
    let p = plan(d, &target, limits, 0.0);
    (target, p)
}

/// Crown-centre distance (mm) and angle (degrees) between two poses of a tooth.
fn apart(d: &Dentition, f: Fdi, a: &Pose, b: &Pose) -> (f32, f32) {
    let c = d.tooth(f).unwrap().geometry.frame.crown_centre;
    (
        a.transform_point(c).distance(b.transform_point(c)),
        a.rotation.angle_between(b.rotation).to_degrees(),
    )
}

#[test]
fn the_crowded_plan_stays_within_the_limits_and_reaches_its_target() {
    let d = case("crowded");
    let limits = PlanLimits::default();
    let (target, p) = planned(&d, &limits);
    assert!(p.blocked.is_empty(), "{:?}", p.blocked);
    assert_eq!(p.max_penetration_mm, 0.0);
    // 42 turns about 18° back into line at 2° a stage.
    assert!(p.stages >= 9, "{} stages", p.stages);
    let per_stage = limits.per_stage();
    let step_mm = Vec3::new(per_stage[0], per_stage[1], per_stage[2]).length();
    let step_deg = Vec3::new(per_stage[3], per_stage[4], per_stage[5]).length();
    for m in &p.moves {
        for k in 1..=p.stages {
            for (c, l) in m.stage_components(k).iter().zip(per_stage) {
                assert!(c.abs() <= l + 1e-4, "{} stage {k}: {c} over {l}", m.fdi);
            }
            // The same from the poses alone.
            let (mm, deg) = apart(&d, m.fdi, &m.pose_at(k - 1), &m.pose_at(k));
            assert!(
                mm <= step_mm + 1e-3 && deg <= step_deg + 1e-2,
                "{} {k}: {mm} {deg}",
                m.fdi
            );
        }
        let (mm, deg) = apart(&d, m.fdi, &m.pose_at(p.stages), &target.poses[&m.fdi]);
        assert!(mm <= 0.01 && deg <= 0.1, "{}: {mm} mm {deg}° off", m.fdi);
    }
    // The lower arch's alignment leaves the molars about where they met.
    for [before, after] in [0, 1].map(|s| p.molar_relation_mm.map(|r| r[s])) {
        let (before, after) = (before.unwrap(), after.unwrap());
        assert!(
            (after - before).abs() < 0.5,
            "molar relation {before} → {after}"
        );
    }
    // The target puts the crowded lower front back where the normal arrangement has it.
    for n in [31, 32, 33, 41, 42, 43] {
        let (mm, deg) = apart(&d, fdi(n), &target.poses[&fdi(n)], &d.setup[&fdi(n)]);
        assert!(
            mm < 0.4 && deg < 2.0,
            "{n}: {mm} mm {deg}° from the arrangement"
        );
    }
    // Each tooth's table row sums its stages.
    let t42 = p.teeth.iter().find(|t| t.fdi == fdi(42)).unwrap();
    assert_eq!(t42.stages.len() as u32, p.stages + 1);
    assert!(t42.total_deg > 15.0, "{}", t42.total_deg);
}

#[test]
fn no_two_teeth_pass_through_each_other_between_stages() {
    // parry3d's intersection test at 24 instants of every transition of every pair of an arch
    // that comes within 1 mm. Where it finds the surfaces crossing, the depth may not exceed the
    // check's guarantee between measures (the band): moving one tooth that far away from the
    // other along the line between their crown centres parts them.
    let d = case("crowded");
    let (_, p) = planned(&d, &PlanLimits::default());
    let meshes: Vec<_> = p
        .moves
        .iter()
        .map(|m| pmesh(&d.tooth(m.fdi).unwrap().geometry.mesh))
        .collect();
    let mut crossings = 0;
    let mut tested = 0;
    for k in 0..p.stages {
        for i in 0..p.moves.len() {
            for j in i + 1..p.moves.len() {
                let (a, b) = (&p.moves[i], &p.moves[j]);
                if a.fdi.arch() != b.fdi.arch() {
                    continue;
                }
                let ma = Motion {
                    start: a.pose_at(k),
                    end: a.pose_at(k + 1),
                };
                let mb = Motion {
                    start: b.pose_at(k),
                    end: b.pose_at(k + 1),
                };
                if ma.is_still() && mb.is_still() {
                    continue;
                }
                let (ga, gb) = (
                    &d.tooth(a.fdi).unwrap().geometry,
                    &d.tooth(b.fdi).unwrap().geometry,
                );
                if mesh_separation(ga.mesh_ref(), &ma.start, gb.mesh_ref(), &mb.start).distance
                    > 1.0
                {
                    continue;
                }
                for s in 0..=24 {
                    let t = s as f32 / 24.0;
                    let (pa, pb) = (ma.at(t), mb.at(t));
                    tested += 1;
                    let hit =
                        pq::intersection_test(&ppose(&pa), &meshes[i], &ppose(&pb), &meshes[j])
                            .unwrap()
                            .intersecting;
                    if hit {
                        crossings += 1;
                        let away = (pb.transform_point(gb.frame.crown_centre)
                            - pa.transform_point(ga.frame.crown_centre))
                        .normalize();
                        let moved = Pose::new(pb.rotation, pb.translation + away * BAND_MM);
                        let still = pq::intersection_test(
                            &ppose(&pa),
                            &meshes[i],
                            &ppose(&moved),
                            &meshes[j],
                        )
                        .unwrap()
                        .intersecting;
                        assert!(
                            !still,
                            "{}–{} stage {k} at {t}: more than {BAND_MM} mm inside",
                            a.fdi, b.fdi
                        );
                    }
                }
            }
        }
    }
    assert!(tested > 500, "{tested} instants tested");
    assert!(crossings <= tested / 50, "{crossings} of {tested} crossing");
}

#[test]
fn the_same_case_plans_the_same_way() {
    let d = case("crowded");
    let limits = PlanLimits::default();
    let strip = |p: &Plan| {
        let mut v = serde_json::to_value(p).unwrap();
        for k in ["plan_ms", "target_ms"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    assert_eq!(
        strip(&planned(&d, &limits).1),
        strip(&planned(&d, &limits).1)
    );
}

fn mesial(n: i64, mm: f32) -> ToothMap<CaseOffset> {
    let mut m = ToothMap::default();
    m.0.insert(
        fdi(n),
        CaseOffset {
            translation: (Finite(mm), Finite(0.0), Finite(0.0)),
            rotation_deg: (Finite(0.0), Finite(0.0), Finite(0.0)),
        },
    );
    m
}

#[test]
fn teeth_that_cannot_pass_get_ipr_within_the_contact_limit_or_are_reported() {
    let d = case("normal");
    let limits = PlanLimits::default();
    // 32 moved 0.3 mm mesially into 31: a reduction of the contact, in 0.05 mm steps.
    let target = from_offsets(&d, &mesial(32, 0.3));
    let p = plan(&d, &target, &limits, 0.0);
    assert!(p.blocked.is_empty(), "{:?}", p.blocked);
    assert_eq!(p.max_penetration_mm, 0.0);
    // The normal bite as arranged, and with 32 moved along its arch, closes without overlap.
    assert_eq!(p.opposing_overlap_mm, [0.0, 0.0]);
    let ipr = p
        .ipr
        .iter()
        .find(|x| (x.a, x.b) == (fdi(31), fdi(32)))
        .unwrap_or_else(|| panic!("{:?}", p.ipr));
    let steps = ipr.mm / 0.05;
    assert!((steps - steps.round()).abs() < 1e-3, "{}", ipr.mm);
    assert!(ipr.mm >= 0.2 && ipr.mm <= 0.4 + 1e-4, "{}", ipr.mm);
    assert!(ipr.stage < p.stages, "{ipr:?}");
    // 1 mm would take more enamel than a lower incisor contact has: blocked, and said why.
    let target = from_offsets(&d, &mesial(32, 1.0));
    let p = plan(&d, &target, &limits, 0.0);
    let b = p.blocked.iter().find(|b| (b.a, b.b) == (fdi(31), fdi(32)));
    let b = b.unwrap_or_else(|| panic!("{:?}", p.blocked));
    assert!(b.why.contains("limit"), "{}", b.why);
    assert!(p.max_penetration_mm > 0.2, "{}", p.max_penetration_mm);
}

#[test]
fn sequences_start_the_groups_in_their_order() {
    let d = case("case1");
    let group_of = |p: &Plan, pos: &[u8]| {
        p.moves
            .iter()
            .filter(|m| m.steps > 0 && pos.contains(&m.fdi.position()))
            .map(|m| m.start_stage)
            .collect::<Vec<_>>()
    };
    let mut limits = PlanLimits {
        sequence: Sequence::AnteriorsFirst,
        ..PlanLimits::default()
    };
    let (_, p) = planned(&d, &limits);
    let anterior_end = p
        .moves
        .iter()
        .filter(|m| m.fdi.position() <= 3)
        .map(|m| m.steps)
        .max()
        .unwrap();
    assert!(
        group_of(&p, &[4, 5, 6, 7, 8])
            .iter()
            .all(|s| *s >= anterior_end)
    );
    limits.sequence = Sequence::VPattern;
    let (_, p) = planned(&d, &limits);
    let molars = group_of(&p, &[6, 7, 8]);
    let incisors = group_of(&p, &[1, 2]);
    assert!(
        molars.iter().min() < incisors.iter().min(),
        "{molars:?} {incisors:?}"
    );
    assert!(p.blocked.is_empty() && p.max_penetration_mm == 0.0);
}

#[test]
fn bad_limits_files_are_refused_with_their_position() {
    for (text, says) in [
        (
            "(\n  mesiodistal_mm: 0.0,\n)",
            "l.ron:2:3: mesiodistal_mm must be above 0",
        ),
        ("(\n  tip_deg: -1.0,\n)", "l.ron:2:"),
        ("(bogus: 1.0)", "l.ron:1:"),
        ("(wait: {19: 2})", "l.ron:1:"),
        (
            "(contact_gap_mm: 0.2)",
            "contact_gap_mm must be 0 to 0.05 mm",
        ),
    ] {
        let e = PlanLimits::parse(text, "l.ron").unwrap_err().to_string();
        assert!(e.contains(says), "{text}: {e}");
    }
    let ok = PlanLimits::parse("(sequence: VPattern, wait: {13: 4})", "l.ron").unwrap();
    assert_eq!(ok.sequence, Sequence::VPattern);
}

#[test]
fn the_plan_command_writes_its_files_and_json() {
    let dir = std::env::temp_dir().join(format!("orthosim-plan-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = crate::cli::succeed(&[
        "plan",
        "--case",
        "crowded",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "case",
        "stages",
        "limits",
        "ipr",
        "teeth",
        "max_penetration_mm",
        "plan_ms",
    ] {
        assert!(v.get(key).is_some(), "no {key}");
    }
    // The relations, as scanned and at the target, right and left; the set-up's anchorage.
    for key in ["molar_relation_mm", "canine_relation_mm"] {
        let r = &v[key];
        assert!(r[1][0].is_f64() && r[1][1].is_f64(), "{key}: {r}");
    }
    assert!(v["overjet_mm"][1].is_f64());
    let upper = &v["setup"][0];
    assert_eq!(upper["anchorage"], "auto");
    assert!(upper["retraction_share"].is_f64() && upper["retraction_mm"].is_f64());
    let stages = v["stages"].as_u64().unwrap();
    let file: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("plan.json")).unwrap()).unwrap();
    assert_eq!(file["teeth"], v["teeth"]);
    let t = &v["teeth"][0];
    assert!(t["fdi"].is_u64() && t["total_mm"].is_f64() && t["total_deg"].is_f64());
    assert_eq!(t["stages"].as_array().unwrap().len() as u64, stages + 1);
    assert_eq!(t["stages"][0].as_array().unwrap().len(), 6);
    // One STL per arch per stage, each the arch's teeth.
    let d = case("crowded");
    let lower: usize = d
        .visible()
        .filter(|t| t.fdi.arch() == orthosim::teeth::Arch::Lower)
        .map(|t| t.geometry.mesh.triangles.len())
        .sum();
    for k in [0, stages] {
        let bytes = std::fs::read(dir.join(format!("lower_{k:02}.stl"))).unwrap();
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        assert_eq!(n, lower);
        assert_eq!(bytes.len(), 84 + 50 * n);
        assert!(dir.join(format!("upper_{k:02}.stl")).exists());
    }
    let html = std::fs::read_to_string(dir.join("plan.html")).unwrap();
    assert!(html.contains("stage_first.png") && html.contains("<table>"));
    assert!(html.contains("canines") && html.contains("overjet"));
    assert!(
        std::fs::read(dir.join("stage_last.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    // A target file moving an extracted tooth is refused on one line naming the file and place.
    let target = dir.join("t.ron");
    let plan_to = |text: &str, out: &str| {
        std::fs::write(&target, text).unwrap();
        let out = dir.join(out);
        crate::cli::orthosim(&[
            "plan",
            "--case",
            "case1",
            "--target",
            target.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = plan_to("{\n  18: (translation: (0.1, 0.0, 0.0)),\n}", "again");
    assert!(out.status.success(), "18 is present in case 1");
    let out = plan_to("{\n  14: (translation: (0.1, 0.0, 0.0)),\n}", "refused");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("t.ron:2:3: tooth 14 is extracted"),
        "{err}"
    );
    assert!(!dir.join("refused").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scanned_crowded_arch_at_scan_resolution_plans_clean() {
    // The crowded lower arch scanned as one labelled arch, 20,000 triangles per crown.
    let text = Case::resolve("crowded").unwrap().source.replace(
        "teeth: All,",
        "teeth: Only([31, 32, 33, 34, 35, 36, 37, 41, 42, 43, 44, 45, 46, 47]),",
    );
    let d = Dentition::build(Case::parse(&text, "crowded-lower").unwrap()).unwrap();
    let dir = std::env::temp_dir().join(format!("orthosim-plan-scan-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (report, _) = orthosim::teeth::import::export_labelled_scans(
        &d,
        &dir,
        20_000,
        5,
        ScanFormat::PlyProperty,
    )
    .unwrap();
    let scanned = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    assert_eq!(scanned.imported.len(), 14);
    let (_, p) = planned(&scanned, &PlanLimits::default());
    assert!(p.blocked.is_empty(), "{:?}", p.blocked);
    assert_eq!(p.max_penetration_mm, 0.0);
    // The turned lateral incisor is turned back (its crown's fitted axes, not the arch's).
    let t42 = p.teeth.iter().find(|t| t.fdi == fdi(42)).unwrap();
    assert!(t42.total_deg > 12.0, "{}", t42.total_deg);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scanned_crowns_take_their_axes_from_the_fitted_template() {
    // The normal arches as scan-like crowns, one file per tooth: every crown with a template
    // root stands as the arrangement turned it (premolars and molars fit their template about as
    // well turned half round; the buccal side is the one facing out of the arch).
    let d = case("normal");
    let dir = std::env::temp_dir().join(format!("orthosim-plan-axes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let as_scans = orthosim::teeth::import::ExportMeshes::ScanLike {
        triangles: 3000,
        seed: 2,
    };
    let report = orthosim::teeth::import::export_case_as(&d, &dir, as_scans).unwrap();
    let scanned = Dentition::build(Case::load(&report.case_file).unwrap()).unwrap();
    let mut templates = 0;
    for t in scanned.visible() {
        let root = scanned.imported[&t.fdi].root.as_ref().unwrap();
        if root.kind != "template" {
            continue;
        }
        templates += 1;
        let anatomical = t.pose.rotation * t.geometry.axes;
        let truth = d.tooth(t.fdi).unwrap().pose.rotation;
        let off = anatomical.angle_between(truth).to_degrees();
        assert!(off < 10.0, "{}: axes {off}° from the arrangement's", t.fdi);
    }
    assert!(templates >= 28, "{templates} template roots");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_target_pose_turns_back_into_the_offset_that_made_it() {
    // What the viewer saves when a target is edited: each tooth's offset from where it stands.
    let d = case("crowded");
    for (k, t) in d.visible().enumerate() {
        let v = |i: usize| Finite(((k * 7 + i * 3) % 11) as f32 * 0.3 - 1.5);
        let o = CaseOffset {
            translation: (v(0), v(1), v(2)),
            rotation_deg: (
                Finite(v(3).0 * 8.0),
                Finite(v(4).0 * 8.0),
                Finite(v(5).0 * 8.0),
            ),
        };
        let back = t.offset_between(&t.offset_pose(&o));
        let pairs = [
            (o.translation.0, back.translation.0),
            (o.translation.1, back.translation.1),
            (o.translation.2, back.translation.2),
            (o.rotation_deg.0, back.rotation_deg.0),
            (o.rotation_deg.1, back.rotation_deg.1),
            (o.rotation_deg.2, back.rotation_deg.2),
        ];
        for (a, b) in pairs {
            assert!((a.0 - b.0).abs() < 2e-3, "{}: {o:?} → {back:?}", t.fdi);
        }
    }
}

#[test]
fn a_chosen_arch_form_sets_the_canines_width() {
    // Preformed forms sized to the fitted arch: the square form carries its canines widest,
    // the tapered narrowest; each target is staged without collisions.
    let d = case("crowded");
    let width = |form: orthosim::planning::TargetForm| {
        let limits = PlanLimits {
            arch_form: form,
            ..PlanLimits::default()
        };
        let (t, p) = planned(&d, &limits);
        assert!(
            p.blocked.is_empty() && p.max_penetration_mm == 0.0,
            "{form:?}: {:?}",
            p.blocked
        );
        let x = |n: i64| t.poses[&fdi(n)].translation.x;
        x(33) - x(43)
    };
    use orthosim::planning::TargetForm::{Ovoid, Square, Tapered};
    let (tapered, ovoid, square) = (width(Tapered), width(Ovoid), width(Square));
    assert!(
        tapered + 0.5 < ovoid && ovoid + 0.5 < square,
        "{tapered} {ovoid} {square}"
    );
}
