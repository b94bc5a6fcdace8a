//! Collision detection against parry3d: seeded random motions of real tooth pairs near contact.

use std::sync::Arc;

use glam::{Quat, Vec3};
use orthosim::{
    collision::{Body, Circle, CollisionShape, Method, Motion, query},
    geometry::Pose,
    internals::Rng,
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Case, Dentition, Fdi},
};
use parry3d::{query as pq, shape::TriMesh as PMesh};

use crate::parry_support::{pmesh, ppose};

struct TestTooth {
    shape: CollisionShape,
    circle: Circle,
    rest: Pose,
    parry: PMesh,
}

fn teeth(method: TreeMethod, depth: u32, pairs: &[(u8, u8)]) -> Vec<(TestTooth, TestTooth)> {
    teeth_branching(method, 8, depth, pairs)
}

fn teeth_branching(
    method: TreeMethod,
    branching: u32,
    depth: u32,
    pairs: &[(u8, u8)],
) -> Vec<(TestTooth, TestTooth)> {
    teeth_at(method, branching, depth, pairs, None)
}

/// Teeth of the normal case at `vertices` per tooth (the case's resolution when `None`).
fn teeth_at(
    method: TreeMethod,
    branching: u32,
    depth: u32,
    pairs: &[(u8, u8)],
    vertices: Option<u32>,
) -> Vec<(TestTooth, TestTooth)> {
    let mut case = Case::resolve("normal").unwrap();
    if vertices.is_some() {
        case.case.resolution = vertices;
    }
    let d = Dentition::build(case).unwrap();
    let settings = TreeSettings {
        method,
        branching,
        depth,
    };
    let make = |n: u8| {
        let t = d
            .teeth
            .iter()
            .find(|t| t.fdi == Fdi::new(n as i64).unwrap())
            .unwrap();
        let tree = settings.build(&t.geometry.mesh, &t.geometry.bvh).unwrap();
        TestTooth {
            shape: CollisionShape::new(Arc::clone(&t.geometry), &tree),
            circle: Circle::of(&t.geometry, &t.pose),
            rest: t.pose,
            parry: pmesh(&t.geometry.mesh),
        }
    };
    pairs.iter().map(|&(a, b)| (make(a), make(b))).collect()
}

/// A random step of `t` near its rest pose, heading roughly towards `target` (the bench's
/// generator: 0.01–5 mm, up to ±15°).
fn random_motion(rng: &mut Rng, t: &TestTooth, target: Vec3) -> Motion {
    orthosim::internals::random_motion(rng, &t.rest, target)
}

fn intersects(a: &TestTooth, pa: &Pose, b: &TestTooth, pb: &Pose) -> bool {
    pq::intersection_test(&ppose(pa), &a.parry, &ppose(pb), &b.parry)
        .unwrap()
        .intersecting
}

#[derive(Default, Debug)]
struct Tally {
    configs: usize,
    touching: usize,
    false_negatives: [usize; 4],
    late: usize,
    gap_errors: usize,
    max_gap_diff: f32,
    /// Largest relative motion of the reported contact points between the exact stage's time and
    /// the oracle's bisected first-contact time (mm), when measured.
    max_time_motion: f32,
}

fn run(pairs: &[(TestTooth, TestTooth)], configs: usize, seed: u64, bisect: bool) -> Tally {
    const SAMPLES: usize = 8;
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    for k in 0..configs {
        let (a, b) = &pairs[k % pairs.len()];
        let ma = random_motion(&mut rng, a, b.rest.translation);
        let mb = if rng.uniform() < 0.5 {
            Motion::still(b.rest)
        } else {
            random_motion(&mut rng, b, a.rest.translation)
        };
        let (ba, bb) = (
            Body {
                shape: &a.shape,
                circle: a.circle,
                motion: ma,
            },
            Body {
                shape: &b.shape,
                circle: b.circle,
                motion: mb,
            },
        );
        // Oracle: the first sampled time at which the meshes intersect.
        let first = (0..=SAMPLES)
            .map(|s| s as f32 / SAMPLES as f32)
            .find(|&t| intersects(a, &ma.at(t), b, &mb.at(t)));
        let at_end = intersects(a, &ma.end, b, &mb.end);
        tally.configs += 1;
        let results: Vec<_> = Method::ALL.iter().map(|&m| query(m, &ba, &bb)).collect();
        if first.is_some() {
            tally.touching += 1;
        }
        if at_end && results[1].is_none() {
            tally.false_negatives[1] += 1;
        }
        for (i, r) in results.iter().enumerate().skip(2) {
            if let Some(t) = first {
                match r {
                    None => tally.false_negatives[i] += 1,
                    Some(c) if c.time_of_contact > t + 1e-6 => tally.late += 1,
                    _ => {}
                }
            }
        }
        // The exact stage's gap against parry's distance at the reported time.
        if let Some(c) = &results[3]
            && c.time_of_contact > 0.0
        {
            let (pa, pb) = (ma.at(c.time_of_contact), mb.at(c.time_of_contact));
            let d = pq::distance(&ppose(&pa), &a.parry, &ppose(&pb), &b.parry)
                .unwrap()
                .distance;
            let diff = (d - (-c.depth_mm)).abs();
            tally.max_gap_diff = tally.max_gap_diff.max(diff);
            if diff > 2e-3 || d > 0.01 + 2e-3 || intersects(a, &pa, b, &pb) {
                tally.gap_errors += 1;
            }
            // The oracle's first contact, bisected to 2⁻²⁰ of the step between the last clear
            // sample and the first intersecting one; how far the contact points move relative to
            // each other between the two times.
            if bisect && let Some(t1) = first {
                let (mut lo, mut hi) = ((t1 - 1.0 / SAMPLES as f32).max(c.time_of_contact), t1);
                if !intersects(a, &ma.at(lo), b, &mb.at(lo)) {
                    for _ in 0..20 {
                        let mid = 0.5 * (lo + hi);
                        if intersects(a, &ma.at(mid), b, &mb.at(mid)) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    let (la, lb) = (
                        pa.inverse().transform_point(c.points[0]),
                        pb.inverse().transform_point(c.points[1]),
                    );
                    let moved =
                        |t: f32| ma.at(t).transform_point(la) - mb.at(t).transform_point(lb);
                    let motion = (moved(hi) - moved(c.time_of_contact)).length();
                    tally.max_time_motion = tally.max_time_motion.max(motion);
                }
            }
        }
    }
    tally
}

const PAIRS: [(u8, u8); 8] = [
    (11, 21),
    (11, 12),
    (13, 14),
    (16, 17),
    (26, 36),
    (16, 46),
    (31, 41),
    (34, 35),
];

#[test]
fn no_false_negatives_against_parry_on_ten_thousand_motions() {
    let pairs = teeth(TreeMethod::Octree, 4, &PAIRS);
    let t = run(&pairs, 10_000, 0x0c0f_fee5_eed5, false);
    eprintln!("{t:?}");
    assert!(t.touching > 1000, "the set must exercise contact: {t:?}");
    assert_eq!(t.false_negatives, [0; 4], "{t:?}");
    assert_eq!(t.late, 0, "{t:?}");
    assert_eq!(t.gap_errors, 0, "{t:?}");
}

#[test]
fn medial_trees_keep_the_guarantees() {
    let pairs = teeth(TreeMethod::Medial, 3, &PAIRS[..3]);
    let t = run(&pairs, 600, 0x51de_5eed, true);
    eprintln!("{t:?}");
    // The exact stage stops with at most 0.01 mm of gap; in sliding contacts the points still move
    // farther than that before they touch (0.14 mm at most on this set, measured). A regression
    // guard, not the goal.
    assert!(t.max_time_motion > 0.0 && t.max_time_motion < 0.25, "{t:?}");
    assert!(t.touching > 50, "{t:?}");
    assert_eq!(t.false_negatives, [0; 4], "{t:?}");
    assert_eq!(t.late, 0, "{t:?}");
    assert_eq!(t.gap_errors, 0, "{t:?}");
}

/// The descents test children eight at a time: branchings with part-filled groups (3) and with
/// more than one group per node (12) keep every guarantee too.
#[test]
fn other_branchings_keep_the_guarantees() {
    for (branching, depth) in [(3, 4), (12, 3)] {
        let pairs = teeth_branching(TreeMethod::Medial, branching, depth, &PAIRS[..2]);
        let t = run(&pairs, 300, 0xb4a9_c4e5 + branching as u64, true);
        eprintln!("branching {branching}: {t:?}");
        assert!(t.touching > 20, "{t:?}");
        assert_eq!(t.false_negatives, [0; 4], "{t:?}");
        assert_eq!(t.late, 0, "{t:?}");
        assert_eq!(t.gap_errors, 0, "{t:?}");
    }
}

/// Checks the continuous and exact methods against parry sampled at 256 times: no miss, never late.
fn check_against_samples(a: &TestTooth, ma: Motion, b: &TestTooth, mb: Motion) -> Option<f32> {
    let ba = Body {
        shape: &a.shape,
        circle: a.circle,
        motion: ma,
    };
    let bb = Body {
        shape: &b.shape,
        circle: b.circle,
        motion: mb,
    };
    let first = (0..=256)
        .map(|s| s as f32 / 256.0)
        .find(|&t| intersects(a, &ma.at(t), b, &mb.at(t)));
    for m in [Method::Continuous, Method::Exact] {
        let r = query(m, &ba, &bb);
        if let Some(t) = first {
            let c = r.unwrap_or_else(|| panic!("{m:?} missed a contact at t = {t}"));
            assert!(c.time_of_contact <= t + 1e-6, "{m:?} late: {c:?} vs {t}");
        }
    }
    query(Method::Exact, &ba, &bb).map(|c| c.time_of_contact)
}

#[test]
fn adversarial_motions() {
    let pairs = teeth(TreeMethod::Octree, 4, &[(11, 21), (16, 46)]);
    let (a, b) = &pairs[0];
    let towards = (b.rest.translation - a.rest.translation).normalize();
    let shift = |p: Pose, d: Vec3| Pose::new(p.rotation, p.translation + d);
    fn body(t: &TestTooth, m: Motion) -> Body<'_> {
        Body {
            shape: &t.shape,
            circle: t.circle,
            motion: m,
        }
    }
    // Zero relative motion: both move together 2 mm; 0.05 mm apart throughout, never touch.
    let d = Vec3::new(0.3, -2.0, 1.0);
    let (ma, mb) = (
        Motion {
            start: a.rest,
            end: shift(a.rest, d),
        },
        Motion {
            start: b.rest,
            end: shift(b.rest, d),
        },
    );
    // (The leaf spheres stick out more than 0.05 mm, so the sphere methods report their overlap.)
    assert!(query(Method::Exact, &body(a, ma), &body(b, mb)).is_none());
    // Identical poses: a tooth against itself overlaps from the start.
    for m in Method::ALL {
        let c = query(
            m,
            &body(a, Motion::still(a.rest)),
            &body(a, Motion::still(a.rest)),
        )
        .unwrap_or_else(|| panic!("{m:?}"));
        if m != Method::Circles && m != Method::Spheres {
            assert_eq!(c.time_of_contact, 0.0, "{m:?}");
        }
    }
    // Pure rotation by 15° about the vertical and about the mesiodistal direction.
    for axis in [Vec3::Y, towards.cross(Vec3::Y).normalize()] {
        let m = Motion {
            start: a.rest,
            end: Pose::new(
                Quat::from_axis_angle(axis, 15f32.to_radians()) * a.rest.rotation,
                a.rest.translation,
            ),
        };
        check_against_samples(a, m, b, Motion::still(b.rest));
    }
    // Grazing: sliding past the neighbour, parallel to the contact.
    let tangent = towards.cross(Vec3::Y).normalize();
    check_against_samples(
        a,
        Motion {
            start: a.rest,
            end: shift(a.rest, tangent * 3.0),
        },
        b,
        Motion::still(b.rest),
    );
    // Tiny and huge steps towards the neighbour; the huge one (100 mm) would tunnel through it.
    let tiny = check_against_samples(
        a,
        Motion {
            start: a.rest,
            end: shift(a.rest, towards * 1e-6),
        },
        b,
        Motion::still(b.rest),
    );
    assert!(tiny.is_none(), "a micrometre does not close 0.05 mm");
    let huge = Motion {
        start: a.rest,
        end: shift(a.rest, towards * 100.0),
    };
    let t = check_against_samples(a, huge, b, Motion::still(b.rest)).expect("tunnelling caught");
    assert!(t < 0.01, "{t}");
    // Far from the origin: the same head-on motion 10⁴ mm away gives the same time.
    let far = Vec3::new(1e4, 0.0, 1e4);
    let step = |p: Pose| Motion {
        start: p,
        end: shift(p, towards * 0.5),
    };
    let near_t = query(
        Method::Exact,
        &body(a, step(a.rest)),
        &body(b, Motion::still(b.rest)),
    )
    .expect("contact")
    .time_of_contact;
    let far_t = query(
        Method::Exact,
        &body(a, step(shift(a.rest, far))),
        &body(b, Motion::still(shift(b.rest, far))),
    )
    .expect("contact far away")
    .time_of_contact;
    assert!((near_t - far_t).abs() < 0.01, "{near_t} vs {far_t}");
    // Occluding teeth: the upper first molar closing 2.5 mm onto the lower one (their cusps stand
    // about 1.3 mm apart at rest; class I puts the contacts on the neighbours).
    let (u, l) = &pairs[1];
    let gap = pq::distance(&ppose(&u.rest), &u.parry, &ppose(&l.rest), &l.parry)
        .unwrap()
        .distance;
    assert!(gap > 0.0 && gap < 2.0, "{gap}");
    check_against_samples(
        u,
        Motion {
            start: u.rest,
            end: shift(u.rest, Vec3::new(0.0, -2.5, 0.0)),
        },
        l,
        Motion::still(l.rest),
    )
    .expect("the molars meet");
}

/// At scan resolution (10,100 vertices, 21,168 triangles per tooth) the exact stage searches its
/// many candidates through the triangle hierarchies: the same guarantees against parry on a
/// smaller seeded set.
#[test]
fn scan_resolution_keeps_the_guarantees() {
    let pairs = teeth_at(TreeMethod::Medial, 8, 4, &PAIRS[..3], Some(10_100));
    let t = run(&pairs, 90, 0x5ca1_ab1e, false);
    eprintln!("{t:?}");
    assert!(t.touching > 10, "{t:?}");
    assert_eq!(t.false_negatives, [0; 4], "{t:?}");
    assert_eq!(t.late, 0, "{t:?}");
    assert_eq!(t.gap_errors, 0, "{t:?}");
}

/// Whether an exact contact deepens over the step is judged from where the meshes meet at its end
/// (the walk over the part of each surface inside the other): the same answer as the whole-mesh
/// separation gives, for teeth that end apart, touching, or overlapping by up to 0.6 mm, with start
/// depths on either side of the end's.
#[test]
fn exact_deepening_is_judged_from_where_the_meshes_meet() {
    use orthosim::collision::{PairContact, closing::deepens};
    use orthosim::geometry::mesh_separation;
    let pairs = teeth(
        TreeMethod::Octree,
        4,
        &[(11, 21), (11, 12), (13, 14), (16, 15)],
    );
    let mut rng = Rng(0xdee9);
    let (mut deeper, mut not) = (0, 0);
    for k in 0..160 {
        let (a, b) = &pairs[k % pairs.len()];
        let towards = (b.rest.translation - a.rest.translation).normalize();
        let start = rng.perturb(&a.rest, 1.0, 0.1);
        // From 0.3 mm apart to 0.6 mm further in, along the line between the teeth.
        let end = Pose::new(
            start.rotation,
            start.translation + towards * (rng.uniform() * 0.9 - 0.3) * 1.5,
        );
        let (ma, mb) = (Motion { start, end }, Motion::still(b.rest));
        let end_gap = mesh_separation(
            a.shape.geometry.mesh_ref(),
            &end,
            b.shape.geometry.mesh_ref(),
            &b.rest,
        )
        .signed_gap();
        let depth_mm = rng.uniform() * 0.4 - 0.1;
        let contact = PairContact {
            time_of_contact: 0.0,
            points: [start.translation; 2],
            normal: towards,
            depth_mm,
            leaf_pairs: Vec::new(),
            end_overlap: None,
        };
        let expected = end_gap < 0.0 && end_gap < -depth_mm - 1e-6;
        fn body(t: &TestTooth, m: Motion) -> Body<'_> {
            Body {
                shape: &t.shape,
                circle: t.circle,
                motion: m,
            }
        }
        let got = deepens(Method::Exact, &body(a, ma), &body(b, mb), &contact);
        assert_eq!(
            got, expected,
            "motion {k}: end gap {end_gap}, start depth {depth_mm}"
        );
        if got {
            deeper += 1;
        } else {
            not += 1;
        }
    }
    assert!(deeper > 20 && not > 20, "{deeper} deepen, {not} do not");
}
