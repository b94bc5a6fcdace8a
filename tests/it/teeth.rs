//! Procedural teeth: valid solids at every resolution, with the anatomy they were made from.

use glam::Vec3;
use orthosim::teeth::{Arch, ShapeSet, ToothKind, ToothResolution, anatomy::anatomy};

/// Number of clusters among points, joining points closer than `link`.
fn clusters(points: &[Vec3], link: f32) -> usize {
    let mut label: Vec<usize> = (0..points.len()).collect();
    fn find(l: &mut [usize], i: usize) -> usize {
        let mut r = i;
        while l[r] != r {
            r = l[r];
        }
        l[i] = r;
        r
    }
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            if points[i].distance(points[j]) < link {
                let (a, b) = (find(&mut label, i), find(&mut label, j));
                label[a] = b;
            }
        }
    }
    (0..points.len())
        .filter(|&i| find(&mut label, i) == i)
        .count()
}

#[test]
fn paper_resolution_teeth_have_their_anatomy() {
    let shapes = ShapeSet::shared(ToothResolution::PAPER);
    for arch in [Arch::Upper, Arch::Lower] {
        for kind in ToothKind::ALL {
            let g = shapes.get(arch, kind);
            let an = anatomy(arch, kind);
            let name = format!("{arch:?} {kind:?}");
            let report = g
                .mesh
                .validate_solid()
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                (100..=160).contains(&report.vertices),
                "{name}: {} vertices",
                report.vertices
            );
            let f = &g.frame;
            assert!(
                f.long_axis.dot(Vec3::Y) > 0.97,
                "{name}: long axis {}",
                f.long_axis
            );
            assert!(
                (f.crown_length - an.crown_length).abs() < 1.0,
                "{name}: crown {}",
                f.crown_length
            );
            assert!(
                (f.root_length - an.root_length).abs() < 1.0,
                "{name}: root {}",
                f.root_length
            );
            // Centres of resistance and tipping lie on the root, a third of the way from the apex.
            let along = (f.centre_of_resistance - f.apex).dot(f.long_axis);
            assert!((along - f.root_length / 3.0).abs() < 1e-3, "{name}");
            assert!(
                f.centre_of_tipping.y < 0.0 && f.crown_centre.y > 0.0,
                "{name}"
            );
            // Crown widths close to the table's.
            let crown: Vec<Vec3> = g
                .mesh
                .vertices
                .iter()
                .copied()
                .filter(|v| v.y > 0.0)
                .collect();
            let width = |axis: fn(&Vec3) -> f32| {
                crown.iter().map(axis).fold(f32::NEG_INFINITY, f32::max)
                    - crown.iter().map(axis).fold(f32::INFINITY, f32::min)
            };
            assert!(
                (width(|v| v.x) - an.mesiodistal).abs() < 0.6,
                "{name}: MD {}",
                width(|v| v.x)
            );
            assert!(
                (width(|v| v.z) - an.buccolingual).abs() < 0.8,
                "{name}: BL {}",
                width(|v| v.z)
            );
            // As many root apices as the anatomy has roots.
            let deep: Vec<Vec3> = g
                .mesh
                .vertices
                .iter()
                .copied()
                .filter(|v| v.y < -0.8 * an.root_length)
                .collect();
            assert_eq!(
                clusters(&deep, 2.5),
                an.roots as usize,
                "{name}: root apices"
            );
        }
    }
}

#[test]
fn crowns_carry_cusps_edges_and_tips() {
    let shapes = ShapeSet::shared(ToothResolution::DENSE);
    for arch in [Arch::Upper, Arch::Lower] {
        for kind in ToothKind::ALL {
            let g = shapes.get(arch, kind);
            let an = anatomy(arch, kind);
            let top = g
                .mesh
                .vertices
                .iter()
                .map(|v| v.y)
                .fold(f32::NEG_INFINITY, f32::max);
            let near_top: Vec<Vec3> = g
                .mesh
                .vertices
                .iter()
                .copied()
                .filter(|v| v.y > top - 0.5)
                .collect();
            let spread_x = near_top.iter().map(|v| v.x.abs()).fold(0.0, f32::max);
            let centre_height = g
                .mesh
                .vertices
                .iter()
                .filter(|v| v.x.abs() < 0.4 && v.z.abs() < 0.4 && v.y > 0.0)
                .map(|v| v.y)
                .fold(f32::NEG_INFINITY, f32::max);
            let name = format!("{arch:?} {kind:?}");
            match kind {
                // An incisal edge: the top runs across most of the crown's width.
                ToothKind::CentralIncisor | ToothKind::LateralIncisor => {
                    assert!(spread_x > 0.25 * an.mesiodistal, "{name}: edge {spread_x}")
                }
                // A cusp tip: the top is a point in the middle.
                ToothKind::Canine => {
                    assert!(spread_x < 0.15 * an.mesiodistal, "{name}: tip {spread_x}")
                }
                // Cusps around a central fossa: the middle is lower than the cusp tips.
                _ => assert!(
                    top - centre_height > 0.8,
                    "{name}: fossa depth {}",
                    top - centre_height
                ),
            }
        }
    }
}

#[test]
fn dense_teeth_reach_scan_resolution_and_stay_valid() {
    let shapes = ShapeSet::shared(ToothResolution::DENSE);
    for arch in [Arch::Upper, Arch::Lower] {
        for kind in ToothKind::ALL {
            let g = shapes.get(arch, kind);
            let r = g
                .mesh
                .validate_solid()
                .unwrap_or_else(|e| panic!("{arch:?} {kind:?}: {e}"));
            assert!(
                r.triangles >= 20_000,
                "{arch:?} {kind:?}: {} triangles",
                r.triangles
            );
            // The dense and default meshes describe the same solid.
            let coarse = ShapeSet::shared(ToothResolution::PAPER).get(arch, kind);
            let ratio = coarse.frame.volume_mm3 / g.frame.volume_mm3;
            assert!(
                (0.85..1.05).contains(&ratio),
                "{arch:?} {kind:?}: volume ratio {ratio}"
            );
        }
    }
}
