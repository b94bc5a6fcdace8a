use super::*;
use crate::geometry::trimesh::tests::cuboid;
use glam::Quat;

pub(crate) fn refs(m: &TriMesh) -> (TriMesh, TriangleBvh) {
    (m.clone(), TriangleBvh::build(m))
}

/// The query view of a mesh and its hierarchy.
fn view(m: &(TriMesh, TriangleBvh)) -> MeshRef<'_> {
    MeshRef {
        mesh: &m.0,
        bvh: &m.1,
    }
}

#[test]
fn separated_boxes_have_their_gap() {
    let unit = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
    let r = view(&unit);
    let s = mesh_separation(
        r,
        &Pose::IDENTITY,
        r,
        &Pose::from_translation(Vec3::new(1.25, 0.3, -0.2)),
    );
    assert!((s.distance - 0.25).abs() < 1e-6, "{s:?}");
    assert_eq!(s.penetration, 0.0);
    assert!((s.signed_gap() - 0.25).abs() < 1e-6);
}

#[test]
fn overlapping_boxes_report_penetration() {
    let unit = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
    let r = view(&unit);
    let s = mesh_separation(
        r,
        &Pose::IDENTITY,
        r,
        &Pose::from_translation(Vec3::new(0.8, 0.0, 0.0)),
    );
    assert_eq!(s.distance, 0.0);
    assert!((s.penetration - 0.2).abs() < 1e-5, "{s:?}");
    assert!(s.signed_gap() < 0.0);
}

#[test]
fn a_box_inside_another_is_overlapping() {
    let big = refs(&cuboid(Vec3::splat(-5.0), Vec3::splat(5.0)));
    let small = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
    let s = mesh_separation(
        view(&big),
        &Pose::IDENTITY,
        view(&small),
        &Pose::new(Quat::from_rotation_y(0.3), Vec3::ZERO),
    );
    assert!(s.overlapping());
    assert!(s.penetration > 3.5, "{s:?}");
}

#[test]
fn a_bounded_separation_agrees_within_its_limit_and_is_none_beyond() {
    let unit = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
    let r = view(&unit);
    let rotated = |x: f32| Pose::new(Quat::from_rotation_z(0.2), Vec3::new(x, 0.4, 0.1));
    for x in [0.7, 1.0, 1.3, 1.6, 2.4] {
        let full = mesh_separation(r, &Pose::IDENTITY, r, &rotated(x));
        for limit in [0.05, 0.3, 1.0, f32::INFINITY] {
            let within = mesh_separation_within(r, &Pose::IDENTITY, r, &rotated(x), limit);
            if full.signed_gap() <= limit {
                let w = within.unwrap_or_else(|| panic!("x {x} limit {limit}: {full:?}"));
                assert!(
                    (w.signed_gap() - full.signed_gap()).abs() < 1e-6,
                    "{w:?} {full:?}"
                );
            } else {
                assert!(within.is_none(), "x {x} limit {limit}: {within:?}");
            }
        }
    }
    // A solid inside another has no surface within any limit but is still reported.
    let big = refs(&cuboid(Vec3::splat(-5.0), Vec3::splat(5.0)));
    let s = mesh_separation_within(view(&big), &Pose::IDENTITY, r, &Pose::IDENTITY, 0.01)
        .expect("containment is within every limit");
    assert!(s.overlapping() && s.penetration > 3.5, "{s:?}");
}

#[test]
fn inside_test_on_a_rotated_box() {
    let unit = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
    let r = view(&unit);
    assert!(point_inside_mesh(r, Vec3::splat(0.5)));
    assert!(point_inside_mesh(r, Vec3::new(0.5, 0.5, 0.999)));
    assert!(!point_inside_mesh(r, Vec3::new(0.5, 0.5, 1.001)));
    assert!(!point_inside_mesh(r, Vec3::new(-3.0, 0.5, 0.5)));
}
