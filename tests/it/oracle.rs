//! Exact geometry checked against parry3d as an independent oracle (values exchanged as arrays).

use glam::{Quat, Vec3};
use orthosim::{
    geometry::{
        MassProperties, Pose, closest_points_triangle_triangle, mesh_separation,
        triangles_intersect,
    },
    internals::Rng,
    teeth::{Case, Dentition, PlacedTooth},
};
use parry3d::{
    math::{Pose as PPose, Vector},
    query,
    shape::Triangle,
};

use crate::parry_support::{pmesh, ppose as pose, v};

#[test]
fn triangle_distances_match_parry() {
    let mut rng = Rng(0x5eed_1234_abcd);
    let mut intersecting = 0;
    for i in 0..5000 {
        // Mix of far, near and crossing pairs; some nearly parallel.
        let spread = [0.3, 1.0, 3.0][i % 3];
        let a = [rng.vec(1.0), rng.vec(1.0), rng.vec(1.0)];
        let offset = rng.vec(spread);
        let mut b = [
            rng.vec(1.0) + offset,
            rng.vec(1.0) + offset,
            rng.vec(1.0) + offset,
        ];
        if i % 7 == 0 {
            // Nearly parallel to a, slightly above it.
            let n = (a[1] - a[0]).cross(a[2] - a[0]).normalize();
            b = [
                a[0] + n * 0.05 + offset * 0.1,
                a[1] + n * 0.05,
                a[2] + n * 0.05 - offset * 0.1,
            ];
        }
        let ours = closest_points_triangle_triangle(&a, &b);
        let ta = Triangle::new(v(a[0]), v(a[1]), v(a[2]));
        let tb = Triangle::new(v(b[0]), v(b[1]), v(b[2]));
        let id = PPose::identity();
        let theirs = query::distance(&id, &ta, &id, &tb).unwrap().distance;
        // parry's GJK stops within about 1e-3 relative; ours is exact, so never above parry's.
        assert!(
            (ours.distance - theirs).abs() <= 1e-3 * (1.0 + theirs),
            "pair {i}: ours {} parry {theirs}",
            ours.distance
        );
        assert!(
            ours.distance <= theirs + 1e-5,
            "pair {i}: ours {} above parry {theirs}",
            ours.distance
        );
        // The reported points lie on their triangles and are `distance` apart, so the distance is
        // attained (an upper bound on the true one).
        assert!((ours.on_first.distance(ours.on_second) - ours.distance).abs() < 1e-4);
        assert!(
            on_triangle(ours.on_first, &a) && on_triangle(ours.on_second, &b),
            "pair {i}: {ours:?} for {a:?} {b:?}"
        );
        let hit = query::intersection_test(&id, &ta, &id, &tb)
            .unwrap()
            .intersecting;
        if theirs > 1e-4 {
            assert!(
                !triangles_intersect(&a, &b),
                "pair {i}: separated by {theirs} but reported intersecting"
            );
        }
        if hit && theirs == 0.0 {
            intersecting += 1;
            assert!(ours.distance <= 1e-5, "pair {i}");
        }
    }
    assert!(
        intersecting > 100,
        "the sample must contain crossing pairs ({intersecting})"
    );
}

/// True when `p` lies on triangle `t` (within 1e-4).
fn on_triangle(p: Vec3, t: &[Vec3; 3]) -> bool {
    let closest = orthosim::geometry::closest_point_triangle(p, t[0], t[1], t[2]);
    closest.distance(p) < 1e-4
}

fn normal_dentition() -> Dentition {
    Dentition::build(Case::resolve("normal").unwrap()).unwrap()
}

fn parry_distance(a: &PlacedTooth, b: &PlacedTooth) -> f32 {
    let (ma, mb) = (pmesh(&a.geometry.mesh), pmesh(&b.geometry.mesh));
    query::distance(&pose(&a.pose), &ma, &pose(&b.pose), &mb)
        .unwrap()
        .distance
}

#[test]
fn neighbour_gaps_match_parry_mesh_distance() {
    let d = normal_dentition();
    for (a, b) in d.neighbour_pairs() {
        let (ta, tb) = (d.tooth(a).unwrap(), d.tooth(b).unwrap());
        let ours = mesh_separation(
            ta.geometry.mesh_ref(),
            &ta.pose,
            tb.geometry.mesh_ref(),
            &tb.pose,
        );
        let theirs = parry_distance(ta, tb);
        assert!(
            (ours.distance - theirs).abs() < 1e-3,
            "{a}-{b}: ours {} parry {theirs}",
            ours.distance
        );
        assert!(
            (0.0..=0.1).contains(&theirs),
            "{a}-{b}: contact gap {theirs}"
        );
    }
}

#[test]
fn the_arches_do_not_interpenetrate_by_parry() {
    let d = normal_dentition();
    let upper: Vec<&PlacedTooth> = d
        .teeth
        .iter()
        .filter(|t| t.fdi.arch() == orthosim::teeth::Arch::Upper)
        .collect();
    let lower: Vec<&PlacedTooth> = d
        .teeth
        .iter()
        .filter(|t| t.fdi.arch() == orthosim::teeth::Arch::Lower)
        .collect();
    let mut least = f32::INFINITY;
    for a in &upper {
        for b in &lower {
            if a.pose.translation.distance(b.pose.translation) > 40.0 {
                continue;
            }
            let (ma, mb) = (pmesh(&a.geometry.mesh), pmesh(&b.geometry.mesh));
            let hit = query::intersection_test(&pose(&a.pose), &ma, &pose(&b.pose), &mb)
                .unwrap()
                .intersecting;
            assert!(!hit, "{} and {} intersect", a.fdi, b.fdi);
            least = least.min(parry_distance(a, b));
        }
    }
    assert!(
        least < 0.1,
        "the arches are in occlusion (least gap {least})"
    );
}

#[test]
fn overlap_is_detected_like_parry() {
    let d = normal_dentition();
    let (a, b) = (
        d.tooth(orthosim::teeth::Fdi::new(11).unwrap()).unwrap(),
        d.tooth(orthosim::teeth::Fdi::new(21).unwrap()).unwrap(),
    );
    let toward = (a.crown_centre() - b.crown_centre()).normalize();
    for push in [0.1f32, 0.4, 1.0] {
        let moved = Pose::new(b.pose.rotation, b.pose.translation + toward * push);
        let ours = mesh_separation(
            a.geometry.mesh_ref(),
            &a.pose,
            b.geometry.mesh_ref(),
            &moved,
        );
        let (ma, mb) = (pmesh(&a.geometry.mesh), pmesh(&b.geometry.mesh));
        let hit = query::intersection_test(&pose(&a.pose), &ma, &pose(&moved), &mb)
            .unwrap()
            .intersecting;
        assert!(hit, "parry sees an overlap after {push} mm");
        assert!(
            ours.overlapping() && ours.signed_gap() < 0.0,
            "{push}: {ours:?}"
        );
    }
}

#[test]
fn tooth_mass_properties_match_parry() {
    let d = normal_dentition();
    for fdi in [11, 13, 16, 36] {
        let t = d.tooth(orthosim::teeth::Fdi::new(fdi).unwrap()).unwrap();
        let m = &t.geometry.mesh;
        let ours = MassProperties::of(m);
        let indices: Vec<[u32; 3]> = m.triangles.clone();
        let verts: Vec<Vector> = m.vertices.iter().map(|&p| v(p)).collect();
        let theirs = parry3d::mass_properties::MassProperties::from_trimesh(1.0, &verts, &indices);
        let volume = 1.0 / theirs.inv_mass as f64;
        assert!(
            (ours.volume - volume).abs() < 1e-3 * volume,
            "{fdi}: {} vs {volume}",
            ours.volume
        );
        let com = Vec3::from_array(theirs.local_com.to_array());
        assert!(
            ours.centre_of_mass.distance(com) < 1e-2,
            "{fdi}: {} vs {com}",
            ours.centre_of_mass
        );
        let mut theirs_moments = theirs.principal_inertia().to_array();
        theirs_moments.sort_by(f32::total_cmp);
        let (ours_moments, _) = ours.principal_axes();
        for k in 0..3 {
            let (o, p) = (ours_moments[k], theirs_moments[k]);
            assert!((o - p).abs() < 1e-2 * p, "{fdi}: moment {k}: {o} vs {p}");
        }
    }
}

#[test]
fn rotated_pose_distances_match_parry() {
    let d = normal_dentition();
    let a = d.tooth(orthosim::teeth::Fdi::new(16).unwrap()).unwrap();
    let b = d.tooth(orthosim::teeth::Fdi::new(46).unwrap()).unwrap();
    let mut rng = Rng(42);
    for _ in 0..10 {
        let spin = Quat::from_scaled_axis(rng.vec(0.5));
        let moved = Pose::new(
            spin * b.pose.rotation,
            b.pose.translation + rng.vec(2.0) - Vec3::Y * 2.0,
        );
        let ours = mesh_separation(
            a.geometry.mesh_ref(),
            &a.pose,
            b.geometry.mesh_ref(),
            &moved,
        )
        .distance;
        let (ma, mb) = (pmesh(&a.geometry.mesh), pmesh(&b.geometry.mesh));
        let theirs = query::distance(&pose(&a.pose), &ma, &pose(&moved), &mb)
            .unwrap()
            .distance;
        assert!(
            (ours - theirs).abs() < 1e-3 * (1.0 + theirs),
            "ours {ours} parry {theirs}"
        );
    }
}
