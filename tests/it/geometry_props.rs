//! Property tests of the engine-free geometry: invariances and bounds that must hold for any input.

use glam::{Quat, Vec3};
use orthosim::{
    geometry::{
        MassProperties, Pose, closest_points_triangle_triangle, mesh_separation,
        triangles_intersect,
    },
    teeth::{Arch, ShapeSet, ToothKind, ToothResolution},
};
use proptest::prelude::*;

fn vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn triangle(range: f32) -> impl Strategy<Value = [Vec3; 3]> {
    [vec3(range), vec3(range), vec3(range)]
}

fn pose() -> impl Strategy<Value = Pose> {
    (vec3(3.0), vec3(30.0))
        .prop_map(|(axis_angle, t)| Pose::new(Quat::from_scaled_axis(axis_angle), t))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// The exact distance is a lower bound of the distance between any two points of the triangles,
    /// and it is attained by the reported points.
    #[test]
    fn triangle_distance_is_the_minimum(a in triangle(2.0), b in triangle(2.0), offset in vec3(3.0),
                                        wa in (0.0f32..1.0, 0.0f32..1.0), wb in (0.0f32..1.0, 0.0f32..1.0)) {
        let b = b.map(|p| p + offset);
        let r = closest_points_triangle_triangle(&a, &b);
        let point = |t: &[Vec3; 3], (u, v): (f32, f32)| {
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v
        };
        let sampled = point(&a, wa).distance(point(&b, wb));
        prop_assert!(r.distance <= sampled + 1e-4, "{} > sampled {}", r.distance, sampled);
        prop_assert!((r.on_first.distance(r.on_second) - r.distance).abs() < 1e-4);
        if r.distance > 1e-5 {
            prop_assert!(!triangles_intersect(&a, &b), "separated by {} yet intersecting", r.distance);
        }
    }

    /// Touching triangles (one vertex of b placed on a) intersect and have zero distance.
    #[test]
    fn tangent_triangles_touch(a in triangle(2.0), b in triangle(2.0), (u, v) in (0.05f32..0.45, 0.05f32..0.45)) {
        let on_a = a[0] + (a[1] - a[0]) * u + (a[2] - a[0]) * v;
        let n = (a[1] - a[0]).cross(a[2] - a[0]);
        prop_assume!(n.length() > 0.1);
        let n = n.normalize();
        // b hangs above a, touching it at one vertex.
        let b = [on_a, on_a + n + b[1] * 0.3, on_a + n * 1.5 + b[2] * 0.3];
        let r = closest_points_triangle_triangle(&a, &b);
        prop_assert!(r.distance < 1e-4, "{}", r.distance);
    }

    /// Distances between posed teeth do not depend on where the pair stands in the world.
    #[test]
    fn mesh_distance_is_invariant_under_a_common_motion(pa in pose(), pb in pose(), common in pose()) {
        let shapes = ShapeSet::shared(ToothResolution::PAPER);
        let (a, b) = (shapes.get(Arch::Upper, ToothKind::FirstMolar), shapes.get(Arch::Lower, ToothKind::Canine));
        let direct = mesh_separation(a.mesh_ref(), &pa, b.mesh_ref(), &pb);
        let moved = mesh_separation(a.mesh_ref(), &common.mul(&pa), b.mesh_ref(), &common.mul(&pb));
        prop_assert_eq!(direct.overlapping(), moved.overlapping());
        let scale = 1e-4 * (1.0 + pa.translation.length() + pb.translation.length() + common.translation.length());
        prop_assert!((direct.distance - moved.distance).abs() < 10.0 * scale, "{direct:?} vs {moved:?}");
    }

    /// Volume is invariant and the centre of mass moves with the mesh.
    #[test]
    fn mass_properties_follow_the_pose(p in pose()) {
        let shapes = ShapeSet::shared(ToothResolution::PAPER);
        let mesh = &shapes.get(Arch::Lower, ToothKind::FirstMolar).mesh;
        let base = MassProperties::of(mesh);
        let moved = MassProperties::of(&mesh.map_vertices(|v| p.transform_point(v)));
        prop_assert!((base.volume - moved.volume).abs() < 1e-3 * base.volume);
        prop_assert!(p.transform_point(base.centre_of_mass).distance(moved.centre_of_mass) < 1e-2);
        let (m0, _) = base.principal_axes();
        let (m1, _) = moved.principal_axes();
        prop_assert!((m0 - m1).length() < 1e-3 * m0.length(), "{m0} vs {m1}");
    }
}
