use super::drift::Relative;
use super::*;
use crate::{collision::sampling::Rng, geometry::Pose};
use glam::Quat;

/// A motion from a random pose, turned by `degrees` about a random axis and shifted by up to
/// `mm` per axis.
fn motion(rng: &mut Rng, degrees: f32, mm: f32) -> Motion {
    let rotation = Quat::from_axis_angle(rng.unit(), 3.0 * rng.uniform());
    let start = Pose::new(rotation, rng.vec(5.0));
    let turn = Quat::from_axis_angle(rng.unit(), degrees.to_radians());
    Motion {
        start,
        end: Pose::new(
            (turn * rotation).normalize(),
            start.translation + rng.vec(mm),
        ),
    }
}

/// The directional step never lets two triangles come closer along the direction than half
/// the tolerance: checked against the poses the motions really produce, at 65 times within
/// each step, for rotations up to 15° and steps up to 5 mm of both teeth.
#[test]
fn directional_steps_keep_half_the_tolerance() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut long, mut cases) = (0, 0);
    for case in 0..4000 {
        let (degrees, mm) = if case % 2 == 0 {
            (2.0, 0.5)
        } else {
            (15.0, 5.0)
        };
        let degrees = degrees * rng.uniform();
        let (ma, mb) = (motion(&mut rng, degrees, mm), motion(&mut rng, degrees, mm));
        let t0 = 0.9 * rng.uniform() as f64;
        let Frame { to_a, rel, .. } = relative(&ma, &mb, t0);
        let x = [rng.vec(8.0), rng.vec(8.0), rng.vec(8.0)];
        let y_local = [rng.vec(8.0), rng.vec(8.0), rng.vec(8.0)];
        let rho_b = y_local.iter().map(|v| v.length()).fold(0.0f32, f32::max) as f64;
        let (tx, ty) = (
            PlacedTri::new(x),
            PlacedTri::new(y_local.map(|v| rel.apply(v))),
        );
        let n = (ty.centre - tx.centre).normalize();
        let Some(drift) =
            Relative::new(&ma, &mb, rho_b).drift(t0, to_a, n, &rel, 0.5 * GAP_TOLERANCE_MM as f64)
        else {
            continue;
        };
        // The same bound from the triangles' boxes in a frame along n (as the hierarchical
        // search takes it for node pairs): as safe.
        let r = super::tree::frame_of(n);
        let boxed = |v: [Vec3; 3]| crate::geometry::Aabb::from_points(v.map(|p| r * p));
        let (bx, by) = (boxed(tx.v), boxed(ty.v));
        let framed = drift
            .framed(r)
            .step_nodes((bx.min.z, bx.max.z), (by.min.z, by.max.z), &by);
        let step = drift.step(&tx, &ty).min(1.0 - t0);
        if step <= 0.0 {
            continue;
        }
        cases += 1;
        long += (step > 0.1) as usize;
        let nd = n.as_dvec3();
        let along = |t: f64| {
            let (pa, pb) = (ma.at(t as f32), mb.at(t as f32));
            let (da, db) = (DPose::from_pose(&pa), DPose::from_pose(&pb));
            let p = x.map(|v| nd.dot(v.as_dvec3()));
            let q = y_local.map(|v| {
                let w = db.apply(v);
                nd.dot(da.rotation.inverse() * (w - da.translation))
            });
            let lo = |v: [f64; 3]| v[0].min(v[1]).min(v[2]);
            let hi = |v: [f64; 3]| v[0].max(v[1]).max(v[2]);
            (lo(q) - hi(p)).max(lo(p) - hi(q))
        };
        for step in [step, framed.min(1.0 - t0)] {
            for k in 0..=64 {
                let t = t0 + step * k as f64 / 64.0;
                let gap = along(t);
                assert!(
                    gap >= 0.5 * GAP_TOLERANCE_MM as f64 - 1e-5,
                    "case {case}: gap {gap} at {t} (step {step} from {t0})"
                );
            }
        }
    }
    // Most triangles placed at random are apart along the direction between them, and many
    // steps reach far.
    assert!(cases > 2000, "{cases}");
    assert!(long > 500, "{long}");
}

/// The hierarchical search lists, of each meeting leaf, only the triangles whose bounding spheres
/// reach a partner leaf's sphere swept over the motion; every triangle that touches or crosses the
/// other tooth at some time of the step must still be listed. Checked at scan resolution on seeded
/// steps of neighbouring teeth (the oracle tests' distribution: up to 5 mm and 15°, many ending
/// deep; in half of them both teeth move), at 9 times across each step from the earliest leaf time, against the whole meshes'
/// crossing triangles; and the listing must leave out most of the leaves' triangles on short steps
/// (as near contact), and some on long ones.
#[test]
fn listed_candidates_hold_every_triangle_that_meets_the_other_tooth() {
    use crate::collision::sampling::random_motion;
    use crate::geometry::crossing_triangles;

    let [a, b] = first_molar_and_premolar();
    let mut rng = Rng(0x11_57ed);
    let (mut crossing, mut listed, mut in_leaves, mut contacts) = (0, [0; 2], [0; 2], 0);
    for case in 0..60 {
        let ma = random_motion(&mut rng, &a.1, b.1.translation);
        // In every other step the second tooth moves too.
        let mb = if case % 2 == 0 {
            Motion::still(b.1)
        } else {
            random_motion(&mut rng, &b.1, a.1.translation)
        };
        let (body_a, body_b) = (body(&a, ma), body(&b, mb));
        let Some(swept) = continuous::query(&body_a, &body_b, true) else {
            continue;
        };
        let [ca, cb] = super::tree::candidates(&body_a, &body_b, &swept);
        // The search over them (which checks its leaf masks against the lists in tests).
        contacts += query(&body_a, &body_b).is_some() as usize;
        // Steps searched whole (no point travels more than 1 mm), as near contact.
        let travel = ma.speed_bound(a.0.max_rho as f64) + mb.speed_bound(b.0.max_rho as f64);
        let short = (travel <= WHOLE_STEP_TRAVEL_MM) as usize;
        listed[short] += ca.len() + cb.len();
        let mut all = [Vec::new(), Vec::new()];
        for &(i, j, _) in &swept.leaf_times {
            all[0].extend_from_slice(a.0.tree.triangles(i as usize));
            all[1].extend_from_slice(b.0.tree.triangles(j as usize));
        }
        for side in &mut all {
            side.sort_unstable();
            side.dedup();
        }
        in_leaves[short] += all[0].len() + all[1].len();
        let t0 = swept.earliest();
        for k in 0..=8 {
            let t = (t0 + (1.0 - t0) * k as f64 / 8.0) as f32;
            let (pa, pb) = (ma.at(t), mb.at(t));
            let (xa, xb) = crossing_triangles(
                a.0.geometry.mesh_ref(),
                &pa,
                b.0.geometry.mesh_ref(),
                &pb,
                0.0,
            );
            crossing += xa.len() + xb.len();
            for (x, listed) in [(&xa, &ca), (&xb, &cb)] {
                for tri in x {
                    assert!(
                        listed.contains(tri),
                        "case {case}: triangle {tri} meets the other tooth at t = {t} but is not listed"
                    );
                }
            }
        }
    }
    eprintln!(
        "crossing {crossing}, listed {listed:?} of {in_leaves:?} (long, short steps), {contacts} contacts"
    );
    assert!(contacts > 10, "{contacts}");
    assert!(crossing > 1000, "{crossing}");
    assert!(listed[0] < in_leaves[0], "{listed:?} of {in_leaves:?}");
    assert!(2 * listed[1] < in_leaves[1], "{listed:?} of {in_leaves:?}");
}

/// The hierarchical search prunes a little below the best so far: the gap it finds is a real
/// pair's, within [`tree::NEAREST_SLACK`] of the least over every candidate pair, and the lower
/// bound it returns for the step is never above that least. Checked at scan resolution on seeded
/// near-contact steps of neighbouring teeth (many starting within a few tenths of a millimetre,
/// some touching or overlapping), against every candidate pair measured one by one.
#[test]
fn hierarchical_search_bounds_the_least_distance() {
    use crate::collision::sampling::random_motion;

    let [a, b] = first_molar_and_premolar();
    let mut rng = Rng(0x005e_ed11);
    let (mut searched, mut apart, mut above) = (0, 0, 0);
    for case in 0..80 {
        let ma = random_motion(&mut rng, &a.1, b.1.translation);
        let (body_a, body_b) = (body(&a, ma), body(&b, Motion::still(b.1)));
        let Some(swept) = continuous::query(&body_a, &body_b, true) else {
            continue;
        };
        let Some((gap, low, least)) = tree::least_at_start(&body_a, &body_b, &swept) else {
            continue;
        };
        searched += 1;
        apart += (least > 0.0) as usize;
        above += (gap > least) as usize;
        assert!(
            low <= least,
            "case {case}: bound {low} above the least {least}"
        );
        assert!(
            gap >= least,
            "case {case}: gap {gap} below the least {least}"
        );
        assert!(
            gap * (1.0 - tree::NEAREST_SLACK) <= least * (1.0 + 1e-5),
            "case {case}: gap {gap} not within the slack of the least {least}"
        );
        if least == 0.0 {
            assert_eq!(gap, 0.0, "case {case}: teeth that meet found {gap} apart");
        }
    }
    eprintln!("{searched} searches, {apart} apart, {above} found above the least");
    assert!(
        searched > 30 && apart > 10,
        "{searched} searches, {apart} apart"
    );
}

/// A contact at the start of a short step carries the meshes' overlap at the step's end, walked
/// from the candidates that meet there: the same depth as the whole-mesh search finds, so
/// `deepens` answers the same with it as without it (when it searches the whole meshes' meeting
/// triangles). Checked at the paper's resolution (flat search) and at scan resolution on seeded steps of two neighbouring teeth that start
/// overlapping by up to 0.4 mm and move up to 0.3 mm and 1° (in half of them both teeth move):
/// some end apart, some deeper, some shallower. A query of the next step, starting where this
/// one ended, gives the same contact when it is told that overlap, and uses it.
#[test]
fn end_overlap_is_the_whole_meshes_overlap() {
    for vertices in [125, 10_100] {
        end_overlap_at(vertices);
    }
}

/// [`end_overlap_is_the_whole_meshes_overlap`] at `vertices` per tooth (125: the flat search).
fn end_overlap_at(vertices: u32) {
    use crate::collision::{Method, closing::deepens};
    use crate::geometry::mesh_penetration;

    let [a, b] = molar_and_premolar_at(vertices);
    let towards = (b.1.translation - a.1.translation).normalize();
    let mut rng = Rng(0x0e0d_0f57);
    let (mut carried, mut apart, mut deeper, mut known, mut floored) = (0, 0, 0, 0, 0);
    let mut again = 0;
    for case in 0..40 {
        let start = Pose::new(
            a.1.rotation,
            a.1.translation + towards * 0.4 * rng.uniform(),
        );
        let turn = Quat::from_axis_angle(rng.unit(), rng.uniform().to_radians());
        let end = Pose::new(
            (turn * start.rotation).normalize(),
            start.translation + rng.vec(0.3),
        );
        let ma = Motion { start, end };
        let mb = if case % 2 == 0 {
            Motion::still(b.1)
        } else {
            let shift = Pose::new(b.1.rotation, b.1.translation + rng.vec(0.1));
            Motion {
                start: b.1,
                end: shift,
            }
        };
        let (body_a, body_b) = (body(&a, ma), body(&b, mb));
        let Some(c) = query_knowing(&body_a, &body_b, None) else {
            continue;
        };
        let Some(e) = c.end_overlap.clone() else {
            assert!(
                c.time_of_contact > 0.0,
                "case {case}: a contact at the start without its end"
            );
            continue;
        };
        carried += 1;
        assert_eq!(c.time_of_contact, 0.0, "case {case}");
        // The deepest sample's place in its tooth's frame is the deepest point reported.
        if let Some((side, local)) = e.deepest {
            let at = e.poses[side].transform_point(local);
            assert!(at.distance(e.points[side]) < 1e-4, "case {case}");
            floored += 1;
        }
        assert_eq!(e.poses, [ma.end, mb.end], "case {case}");
        let whole = mesh_penetration(
            a.0.geometry.mesh_ref(),
            &ma.end,
            b.0.geometry.mesh_ref(),
            &mb.end,
        );
        assert_eq!(e.depth_mm, whole.0, "case {case}");
        apart += (whole.0 <= 0.0) as usize;
        let searched = PairContact {
            end_overlap: None,
            ..c.clone()
        };
        let deepening = deepens(Method::Exact, &body_a, &body_b, &c);
        assert_eq!(
            deepening,
            deepens(Method::Exact, &body_a, &body_b, &searched),
            "case {case}"
        );
        deeper += deepening as usize;

        // The next step starts where this one ended: knowing the overlap there changes nothing
        // but the work; an overlap known at other poses is ignored, and one at these poses is
        // what the contact reports.
        let next = |m: &Motion, shift: Vec3| Motion {
            start: m.end,
            end: Pose::new(m.end.rotation, m.end.translation + shift),
        };
        let (na, nb) = (next(&ma, rng.vec(0.05)), next(&mb, Vec3::ZERO));
        let (body_a, body_b) = (body(&a, na), body(&b, nb));
        let plain = query_knowing(&body_a, &body_b, None);
        assert_eq!(
            query(&body_a, &body_b),
            plain.clone().map(|c| PairContact {
                end_overlap: None,
                ..c
            }),
            "case {case}"
        );
        let knowing = query_knowing(&body_a, &body_b, Some(&e));
        assert_eq!(knowing, plain, "case {case}");
        // Found from the samples the last overlap kept inside, not walked.
        let inside = knowing.and_then(|c| c.end_overlap?.inside.samples);
        again += inside.is_some_and(|s| s.rest_mm() > 0.0) as usize;
        let elsewhere = EndOverlap {
            poses: [ma.start, mb.start],
            ..e.clone()
        };
        assert_eq!(
            query_knowing(&body_a, &body_b, Some(&elsewhere)),
            plain,
            "case {case}"
        );
        if plain.as_ref().is_some_and(|c| c.depth_mm > 0.0) {
            let doctored = EndOverlap {
                depth_mm: e.depth_mm + 1.0,
                ..e.clone()
            };
            let c = query_knowing(&body_a, &body_b, Some(&doctored)).unwrap();
            assert_eq!(c.depth_mm, doctored.depth_mm, "case {case}");
            known += 1;
            // The same overlap said to be of other meshes is ignored.
            let [ga, gb] = doctored.inside.geometry.clone();
            let of_others = EndOverlap {
                inside: crate::collision::KnownInside {
                    geometry: [gb, ga],
                    samples: None,
                },
                ..doctored
            };
            let c = query_knowing(&body_a, &body_b, Some(&of_others));
            assert_eq!(c, plain, "case {case}");
        }
    }
    eprintln!(
        "{vertices} vertices: {carried} carried, {apart} end apart, {deeper} deepen, {known} known, {floored} with a deepest sample, {again} found again"
    );
    assert!(again > 5, "{again} found from the samples kept");
    assert!(carried > 25 && apart > 2 && deeper > 5 && carried - deeper > 5 && known > 10);
    assert!(floored > 10);
}

/// Teeth 16 and 15 of the normal case at scan resolution (10,100 vertices), with medial sphere
/// trees (branching 8, depth 4), and their poses.
fn first_molar_and_premolar() -> [(crate::collision::CollisionShape, Pose); 2] {
    molar_and_premolar_at(10_100)
}

/// Teeth 16 and 15 of the normal case at `vertices` per tooth, as [`first_molar_and_premolar`].
fn molar_and_premolar_at(vertices: u32) -> [(crate::collision::CollisionShape, Pose); 2] {
    use crate::collision::CollisionShape;
    use crate::sphere_tree::{TreeMethod, TreeSettings};
    use crate::teeth::{Case, Dentition, Fdi};
    use std::sync::Arc;

    let mut case = Case::resolve("normal").unwrap();
    case.case.resolution = Some(vertices);
    let d = Dentition::build(case).unwrap();
    let settings = TreeSettings {
        method: TreeMethod::Medial,
        branching: 8,
        depth: 4,
    };
    [16, 15].map(|n| {
        let t = (d.teeth.iter())
            .find(|t| t.fdi == Fdi::new(n).unwrap())
            .unwrap();
        let tree = settings.build(&t.geometry.mesh, &t.geometry.bvh).unwrap();
        (CollisionShape::new(Arc::clone(&t.geometry), &tree), t.pose)
    })
}

/// A tooth of [`first_molar_and_premolar`] moving by `motion` (its circle at its pose).
fn body(tooth: &(crate::collision::CollisionShape, Pose), motion: Motion) -> Body<'_> {
    Body {
        shape: &tooth.0,
        circle: crate::collision::Circle::of(&tooth.0.geometry, &tooth.1),
        motion,
    }
}
