use super::*;
use crate::geometry::trimesh::tests::cuboid;

/// Volume of the cap of a sphere of radius r beyond distance d from its centre.
fn cap(r: f64, d: f64) -> f64 {
    let h = r - d;
    std::f64::consts::PI * h * h * (3.0 * r - h) / 3.0
}

#[test]
fn lines_through_shared_edges_count_once() {
    // Lines at (0.25 + k/2, 0.25 + l/2) cross the diagonals of the box's square faces exactly.
    let mesh = cuboid(Vec3::ZERO, Vec3::new(2.0, 2.0, 8.0));
    let c = Columns::with_lattice(&mesh, 2, [0.0, 0.0], 0.5, [4, 4]);
    assert_eq!(c.spans.len(), 16, "{:?}", c.spans);
    assert!((c.volume() - 32.0).abs() < 1e-4, "{}", c.volume());
    assert_eq!(Columns::build(&mesh, 8).axis, 2);
}

#[test]
fn sphere_outside_volumes_match_caps() {
    // Half-space z ≤ 0 as a large box; spheres cut at various depths.
    let mesh = cuboid(Vec3::new(-10.0, -10.0, -30.0), Vec3::new(10.0, 10.0, 0.0));
    let c = Columns::build(&mesh, 400);
    for (z, r) in [
        (0.4f32, 1.0f32),
        (-0.5, 1.0),
        (-1.8, 2.0),
        (0.0, 0.7),
        (3.0, 1.0),
    ] {
        let s = Sphere::new(Vec3::new(0.3, -0.2, z), r);
        let exact = if z >= r {
            s.volume()
        } else if z >= 0.0 {
            s.volume() - cap(r as f64, z as f64)
        } else {
            cap(r as f64, -z as f64).max(0.0) * (r > -z) as u8 as f64
        };
        let est = c.outside_volume(&s);
        assert!(
            (est - exact).abs() < 0.01 * s.volume() + 1e-4,
            "z {z} r {r}: {est} vs {exact}"
        );
    }
}

#[test]
fn several_radii_at_once_agree_with_one_at_a_time() {
    let mesh = cuboid(Vec3::ZERO, Vec3::new(4.0, 5.0, 6.0));
    let c = Columns::build(&mesh, 64);
    let centre = Vec3::new(1.0, 2.5, 3.0);
    let radii = [0.5, 1.2, 2.0, 3.5];
    let mut out = [0.0; 4];
    c.outside_volumes(centre, &radii, &mut out);
    for (k, &r) in radii.iter().enumerate() {
        let one = c.outside_volume(&Sphere::new(centre, r));
        assert!(
            (one - out[k]).abs() < 1e-6 * one.max(1e-3),
            "{one} vs {}",
            out[k]
        );
    }
    // Radius 0.5 at depth 1 is inside; larger spheres stick out more and more.
    assert!(out[0] < 1e-6, "{}", out[0]);
    assert!(out[1] > 0.0 && out[2] > out[1] && out[3] > out[2]);
}

/// Three 2 × 2 × 1 slabs stacked along z with gaps of 1.
fn three_slabs() -> TriMesh {
    let slab = |z0: f32| cuboid(Vec3::new(0.0, 0.0, z0), Vec3::new(2.0, 2.0, z0 + 1.0));
    let (a, b, d) = (slab(0.0), slab(2.0), slab(4.0));
    let mut vertices = a.vertices.clone();
    let mut triangles = a.triangles.clone();
    for (k, m) in [b, d].iter().enumerate() {
        let base = 8 * (k as u32 + 1);
        vertices.extend(&m.vertices);
        triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    TriMesh::new(vertices, triangles)
}

/// Eight spheres measured at once on gathered lines agree with one at a time, on lines with
/// three intervals, with none (off the lattice) and with partial ones; a sphere that pokes
/// out of the reach is reported as not held.
#[test]
fn gathered_lines_measure_eight_spheres_as_one_at_a_time() {
    let c = Columns::build(&three_slabs(), 40);
    let mut rng = crate::geometry::test_numbers(11);
    let mut local = LocalLines::default();
    for round in 0..40 {
        let anchor = Vec3::new(rng() * 4.0 + 1.0, rng() * 4.0 + 1.0, rng() * 7.0 + 2.5);
        let reach = 0.4 + (rng() + 0.5) * 1.6;
        c.gather(anchor, reach, &mut local);
        let spheres: [Sphere; 8] = std::array::from_fn(|k| {
            let r = (0.3 + 0.7 * (rng() + 0.5)) * reach * 0.5;
            let room = reach - r;
            let offset = Vec3::new(rng(), rng(), rng() * 4.0) * room;
            let offset = offset.clamp_length_max(room * 0.999);
            let mut s = Sphere::new(anchor + offset, r);
            if k == 7 && round % 2 == 0 {
                s.radius = 0.0;
            }
            s
        });
        let many = local.outside_volumes(&c, &spheres);
        for (s, got) in spheres.iter().zip(many) {
            if s.radius == 0.0 {
                assert_eq!(got, 0.0);
                continue;
            }
            assert!(local.holds(&c, s));
            let one = c.outside_volume(s);
            assert!(
                (one - got).abs() < 1e-4 * s.volume(),
                "round {round}: {got} vs {one} for {s:?}"
            );
        }
        let out = Sphere::new(anchor + Vec3::new(reach * 0.7, 0.0, 0.0), reach * 0.5);
        assert!(!local.holds(&c, &out));
    }
    assert!(
        c.more.iter().filter(|&&m| m).count() > 100,
        "the slabs give lines with three intervals"
    );
}

/// Three slabs stacked along the lines' axis: every line through them has three intervals,
/// and spheres that reach past the lattice meet lines with none.
#[test]
fn lines_with_many_intervals_and_spheres_off_the_lattice() {
    let c = Columns::build(&three_slabs(), 40);
    assert_eq!(c.axis, 2);
    assert!(c.more.iter().filter(|&&m| m).count() > 100);
    assert!((c.volume() - 12.0).abs() < 1e-3, "{}", c.volume());
    // A sphere around everything: its volume less the slabs'.
    let big = Sphere::new(Vec3::new(1.0, 1.0, 2.5), 6.0);
    let expect = big.volume() - 12.0;
    let got = c.outside_volume(&big);
    assert!(
        (got - expect).abs() < 0.002 * big.volume(),
        "{got} vs {expect}"
    );
    // Spheres centred in each gap and slab, one radius at a time and eight at once.
    for z in [0.5f32, 1.5, 2.5, 3.5, 4.5, 5.5] {
        let centre = Vec3::new(1.3, 0.7, z);
        let radii = [0.3, 0.6, 0.9, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0];
        let mut out = [0.0; 9];
        c.outside_volumes(centre, &radii, &mut out);
        for (k, &r) in radii.iter().enumerate() {
            let one = c.outside_volume(&Sphere::new(centre, r));
            assert!(
                (one - out[k]).abs() < 1e-5 * one.max(1e-2),
                "z {z} r {r}: {one} vs {}",
                out[k]
            );
            // The slow, obvious sum over lines.
            let mut slow = 0.0f64;
            for i in -200..240 {
                for j in -200..240 {
                    let x = c.line_centre(i, j);
                    let d2 = ((x[0] - centre.x as f64).powi(2) + (x[1] - centre.y as f64).powi(2))
                        as f32;
                    if d2 < r * r {
                        let h = (r * r - d2).sqrt();
                        slow += (2.0 * h - c.inside_length(i, j, z - h, z + h)) as f64;
                    }
                }
            }
            slow *= (c.cell as f64).powi(2);
            assert!(
                (one - slow).abs() < 1e-5 * slow.max(1e-2),
                "z {z} r {r}: {one} vs {slow}"
            );
        }
    }
}

#[test]
fn union_counts_overlaps_once() {
    let mesh = cuboid(Vec3::new(-10.0, -10.0, -30.0), Vec3::new(10.0, 10.0, 0.0));
    let c = Columns::build(&mesh, 400);
    let s = Sphere::new(Vec3::new(0.0, 0.0, 0.4), 1.0);
    let one = c.outside_volume(&s);
    // The same sphere twice is the sphere once; two disjoint copies are twice.
    assert!((c.union_outside_volume(&[s, s]) - one).abs() < 1e-6 * one);
    let far = Sphere::new(Vec3::new(5.0, 0.0, 0.4), 1.0);
    let two = c.union_outside_volume(&[s, far]);
    assert!((two - 2.0 * one).abs() < 0.01 * one, "{two} vs {one}");
    // Half-overlapping: between one and two.
    let half = c.union_outside_volume(&[s, Sphere::new(Vec3::new(1.0, 0.0, 0.4), 1.0)]);
    assert!(half > 1.2 * one && half < 1.9 * one, "{half}");
}
