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
