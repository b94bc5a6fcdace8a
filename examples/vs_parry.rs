//! orthosim's exact stage beside parry3d's mesh–mesh queries on the same seeded stress
//! motions of real teeth (the stress set of `orthosim bench` and the oracle tests, medial trees of depth 4 from the user's tree
//! cache, built on first use). Prints one JSON object.
//!
//! `cargo run --release --example vs_parry [PAIRS]`
//!
//! A disagreement is a motion where orthosim reports contact at time t with gap g and parry's
//! distance at t differs from g by more than 0.01 mm, or where orthosim reports no contact and
//! parry finds the meshes intersecting at the end pose.

use std::time::Instant;

use orthosim::{
    collision::{Body, Method, bench, query},
    geometry::Pose,
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Case, Dentition},
};
use parry3d::{
    math::{Pose as PPose, Rot3, Vector},
    query::{self as pq, NonlinearRigidMotion},
    shape::TriMesh as PMesh,
};

fn v(p: glam::Vec3) -> Vector {
    let [x, y, z] = p.to_array();
    Vector::new(x, y, z)
}

fn ppose(p: &Pose) -> PPose {
    let [x, y, z, w] = p.rotation.to_array();
    PPose::from_parts(v(p.translation), Rot3::from_xyzw(x, y, z, w))
}

fn nonlinear(m: &orthosim::collision::Motion) -> NonlinearRigidMotion {
    let (axis, angle) = (m.end.rotation * m.start.rotation.inverse()).to_axis_angle();
    NonlinearRigidMotion::new(
        ppose(&m.start),
        Vector::new(0.0, 0.0, 0.0),
        v(m.end.translation - m.start.translation),
        v(axis * angle),
    )
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1000);
    let d = Dentition::build(Case::resolve("normal").expect("built-in case")).expect("valid case");
    let settings = TreeSettings {
        method: TreeMethod::Medial,
        branching: 8,
        depth: 4,
    };
    let cache = orthosim::sphere_tree::TreeCache::user_default();
    let teeth = bench::bench_teeth(&d, settings, cache.as_ref()).expect("valid tree settings");
    let pairs = bench::stress_pairs(&teeth, n, 0x5eed);
    let meshes: Vec<PMesh> = teeth
        .iter()
        .map(|t| {
            let m = &t.shape.geometry.mesh;
            PMesh::new(
                m.vertices.iter().map(|&p| v(p)).collect(),
                m.triangles.clone(),
            )
            .expect("valid mesh")
        })
        .collect();
    let body = |i: usize, m| Body {
        shape: &teeth[i].shape,
        circle: teeth[i].circle,
        motion: m,
    };
    let time = |f: &mut dyn FnMut(usize)| {
        let start = Instant::now();
        for k in 0..pairs.len() {
            f(k);
        }
        start.elapsed().as_secs_f64() * 1e6 / pairs.len() as f64
    };
    let mut ours = Vec::with_capacity(pairs.len());
    let orthosim_exact_us = time(&mut |k| {
        let (i, j, ma, mb) = pairs[k];
        ours.push(query(Method::Exact, &body(i, ma), &body(j, mb)));
    });
    let mut hits = Vec::with_capacity(pairs.len());
    let parry_intersection_us = time(&mut |k| {
        let (i, j, ma, mb) = pairs[k];
        hits.push(
            pq::intersection_test(&ppose(&ma.end), &meshes[i], &ppose(&mb.end), &meshes[j])
                .map(|r| r.intersecting)
                .unwrap_or(false),
        );
    });
    let parry_distance_us = time(&mut |k| {
        let (i, j, ma, mb) = pairs[k];
        std::hint::black_box(pq::distance(
            &ppose(&ma.end),
            &meshes[i],
            &ppose(&mb.end),
            &meshes[j],
        ))
        .ok();
    });
    let mut toi_supported = true;
    let parry_toi_us = time(&mut |k| {
        let (i, j, ma, mb) = pairs[k];
        let r = pq::cast_shapes_nonlinear(
            &nonlinear(&ma),
            &meshes[i],
            &nonlinear(&mb),
            &meshes[j],
            0.0,
            1.0,
            true,
        );
        toi_supported &= r.is_ok();
        std::hint::black_box(r).ok();
    });
    let mut disagreements = 0;
    for (k, r) in ours.iter().enumerate() {
        let (i, j, ma, mb) = pairs[k];
        match r {
            Some(c) => {
                let t = c.time_of_contact;
                let dist =
                    pq::distance(&ppose(&ma.at(t)), &meshes[i], &ppose(&mb.at(t)), &meshes[j])
                        .map(|d| d.distance)
                        .unwrap_or(f32::NAN);
                if (dist - (-c.depth_mm).max(0.0)).abs() > 0.01 {
                    disagreements += 1;
                }
            }
            None if hits[k] => disagreements += 1,
            None => {}
        }
    }
    println!(
        "{}",
        serde_json::json!({
            "pairs": pairs.len(),
            "orthosim_exact_us": orthosim_exact_us,
            "parry_intersection_us": parry_intersection_us,
            "parry_distance_us": parry_distance_us,
            "parry_toi_us": parry_toi_us,
            "parry_toi_supported": toi_supported,
            "disagreements": disagreements,
        })
    );
}
