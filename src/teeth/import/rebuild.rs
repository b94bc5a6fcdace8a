//! The fallback for a tooth whose repair cannot make a valid solid: the surface is rebuilt from
//! the solid it encloses, so one bad crown never refuses its arch.
//!
//! The crown is cleaned as the repair cleans it (every piece but the largest dropped as debris),
//! its holes are filled and its margin gets the generated root of [`super::root`] as for any
//! scanned crown (along the arch's apical direction when the margin's own normal does not face the
//! root's side, as happens where a label runs into the gum). That closed surface may cross itself
//! anywhere; its winding number does not care. The solid is every point the surface winds around
//! at least once (`Columns`, exact along each lattice line), sampled on a grid of
//! [`REBUILD_CELL_MM`] with the distance to the surface near it, and its boundary extracted by
//! marching tetrahedra ([`marching_tetrahedra`]: closed, manifold, outward and free of
//! self-intersection by construction). Pockets inside the solid are dropped (the largest shell
//! is kept), the surface is simplified back to about the scan's resolution, and the exact
//! self-intersection check confirms the result (the unsimplified surface is kept if the
//! simplified one fails it).
//!
//! Guarantee: the rebuilt surface lies within about a tenth of a cell of the closed input's
//! outer boundary before simplification (the linear interpolation of a sampled distance); folds
//! and crossings of the scan are filled in. The report gives the scanned vertices' distances to
//! the result ([`Rebuilt`]).

use glam::Vec3;
use serde::Serialize;

use super::{
    MARGIN_COS, Prepared,
    close::MARGIN_SPAN,
    error::ImportError,
    fill::fill_hole,
    occlusal_direction,
    repair::{self, RepairLimits, Repairs, RootReport},
    root,
    template::{self, Template},
};
use crate::geometry::{
    Columns, MeshRef, TriMesh, TriangleBvh, closest_point_on_mesh, closest_point_triangle,
    decimate::{DecimateOptions, decimate},
    isosurface::{SampleGrid, marching_tetrahedra},
};
use crate::teeth::{anatomy::anatomy, fdi::Fdi};

/// Grid spacing (mm) of the rebuild.
pub const REBUILD_CELL_MM: f32 = 0.25;
/// Near the surface a sample carries its distance to it, at least this share of a cell (so no
/// crossing lands on a sample).
const MIN_VALUE_CELLS: f32 = 0.02;
/// The rebuilt surface is simplified to the closed input's vertices, and at least this many.
pub const MIN_REBUILT_VERTICES: usize = 2500;

/// How a tooth was rebuilt, and how far the result is from what was scanned.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rebuilt {
    /// Why the repair could not make a solid.
    pub reason: String,
    /// Grid spacing (mm).
    pub cell_mm: f32,
    /// Distance (mm) from the rebuilt surface's vertices over the scanned crown to the scanned
    /// surface: mean.
    pub mean_mm: f32,
    /// ... 95th percentile.
    pub p95_mm: f32,
    /// ... largest.
    pub max_mm: f32,
    /// Triangles of the rebuilt tooth (root included).
    pub triangles: usize,
}

/// Rebuilds the tooth `fdi` from its mesh `world` (orthosim's frame, mm) after the repair failed
/// with `reason` (see the module doc).
///
/// # Errors
/// Only what makes the mesh no tooth at all: empty, non-finite, no area, a span outside a tooth's
/// ([`super::MIN_SPAN_MM`]–[`super::MAX_SPAN_MM`]), or nothing enclosed.
pub fn rebuild(
    world: &TriMesh,
    fdi: Fdi,
    limits: &RepairLimits,
    reason: &ImportError,
) -> Result<Prepared, ImportError> {
    rebuild_guided(world, fdi, limits, reason, super::RootGuide::default())
}

/// [`rebuild`] with the template root placed as `guide` says (see [`super::prepare_guided`]).
///
/// # Errors
/// As [`rebuild`].
pub fn rebuild_guided(
    world: &TriMesh,
    fdi: Fdi,
    limits: &RepairLimits,
    reason: &ImportError,
    guide: super::RootGuide,
) -> Result<Prepared, ImportError> {
    let mut repairs = Repairs::default();
    let lenient = RepairLimits {
        debris_fraction: 1.0,
        ..*limits
    };
    let crown = super::clean_tooth(world, &lenient, &mut repairs)?;
    let (closed, cervical, apical) = close_leniently(&crown, fdi, limits, &mut repairs, guide)?;
    let surface = solid_boundary(&closed, REBUILD_CELL_MM)?;
    let target = closed.vertices.len().max(MIN_REBUILT_VERTICES);
    let simplified = decimate(
        &surface,
        DecimateOptions {
            target_vertices: target,
            ..Default::default()
        },
    );
    let mesh = if simplified.validate_solid().is_ok() {
        simplified
    } else {
        surface
            .validate_solid()
            .map_err(|e| super::close::explain(&surface, e))?;
        surface
    };
    let (mean_mm, p95_mm, max_mm) = distances(&crown, &closed, &mesh);
    repairs.rebuilt = Some(Rebuilt {
        reason: reason.to_string(),
        cell_mm: REBUILD_CELL_MM,
        mean_mm,
        p95_mm,
        max_mm,
        triangles: mesh.triangles.len(),
    });
    Ok(Prepared {
        mesh,
        cervical,
        apical,
        crown_rotation: None,
        repairs,
    })
}

/// The crown's holes filled and its margin given a root, without any check that the result does
/// not meet itself; its cervical centre and root's apical direction when it has a margin. The
/// root is the template's when the template fits the crown, else a cone.
fn close_leniently(
    crown: &TriMesh,
    fdi: Fdi,
    limits: &RepairLimits,
    repairs: &mut Repairs,
    guide: super::RootGuide,
) -> Result<(TriMesh, Option<Vec3>, Option<Vec3>), ImportError> {
    let loops = repair::boundary_loops(crown)?;
    let lengths: Vec<f32> = loops
        .iter()
        .map(|l| repair::loop_length(crown, l))
        .collect();
    let extent = repair::used_span(crown);
    let margin = (0..loops.len())
        .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
        .filter(|&i| lengths[i] > limits.max_hole_mm && lengths[i] >= MARGIN_SPAN * extent);
    let mut mesh = crown.clone();
    for (i, l) in loops.iter().enumerate() {
        if Some(i) != margin {
            fill_hole(&mut mesh, l);
            repairs.holes_closed_mm.push(lengths[i]);
        }
    }
    let (mut cervical, mut axis) = (None, None);
    if let Some(m) = margin {
        let (centre, own) = root::margin_axis(&mesh, &loops[m])?;
        let toward = -occlusal_direction(fdi.arch());
        let apical = if own.dot(toward) < MARGIN_COS {
            toward
        } else {
            own
        };
        let root_length = anatomy(fdi.arch(), fdi.kind()).root_length;
        let template = Template::of(fdi.arch(), fdi.kind());
        let fit = template::fit(&mesh, fdi, guide.guess, centre, apical);
        let mut templated = mesh.clone();
        let made = match fit {
            None => Err(template::NoTemplate::TooFew),
            Some(f) => f.usable(centre, guide.guess).and_then(|()| {
                let f = guide.applied_to(f);
                let gap = root::GAPS_MM[0];
                super::sweep::close_with_template(
                    &mut templated,
                    &loops[m],
                    gap,
                    &template,
                    &f,
                    true,
                )
                .map(|r| (f, r))
                .map_err(|e| template::NoTemplate::NotClosed(Box::new(e)))
            }),
        };
        if let Ok((f, r)) = &made {
            let (f, r) = (*f, *r);
            mesh = templated;
            repairs.root = Some(RootReport {
                kind: "template",
                roots: r.roots,
                length_mm: r.length_mm,
                axis_deg: r.axis_deg,
                fit_rms_mm: Some(f.rms_mm),
                tilt_deg: guide.tilt.length().to_degrees(),
                shortened_mm: guide.shorten * template.anatomy.root_length,
                fallback: None,
            });
            cervical = Some(r.cervical);
            axis = Some(f.apical());
        } else {
            root::close_with_root_along(
                &mut mesh,
                &loops[m],
                root_length,
                root::GAPS_MM[0],
                centre,
                apical,
            );
            repairs.root = Some(RootReport {
                kind: "cone",
                roots: 1,
                length_mm: root_length,
                axis_deg: apical.angle_between(own).to_degrees(),
                fit_rms_mm: fit.map(|f| f.rms_mm),
                tilt_deg: 0.0,
                shortened_mm: 0.0,
                fallback: made.err().map(|e| e.to_string()),
            });
            cervical = Some(centre);
            axis = Some(apical);
        }
        repairs.root_generated_margin_mm = Some(lengths[m]);
    }
    if mesh.signed_volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
        repairs.turned_outward = true;
    }
    Ok((mesh, cervical, axis))
}

/// The boundary of the solid that the closed surface `closed` winds around (see the module doc),
/// its largest shell only.
///
/// # Errors
/// [`ImportError::Flat`] when it encloses nothing.
pub(super) fn solid_boundary(closed: &TriMesh, cell: f32) -> Result<TriMesh, ImportError> {
    let bounds = closed.aabb();
    let pad = 3.0 * cell;
    let origin = bounds.min - Vec3::splat(pad);
    let e = bounds.extent() + Vec3::splat(2.0 * pad);
    let dims = [0, 1, 2].map(|a| (e[a] / cell).ceil() as usize + 1);
    let grid = SampleGrid { origin, cell, dims };
    let [nx, ny, nz] = dims;
    // Lines along y through the samples: lattice u is z, v is x.
    let columns = Columns::with_lattice(
        closed,
        1,
        [origin.z - 0.5 * cell, origin.x - 0.5 * cell],
        cell,
        [nz, nx],
    );
    let far = 3.0 * cell;
    let mut values = vec![far; grid.len()];
    for k in 0..nz {
        for i in 0..nx {
            for span in columns.spans(k, i) {
                let first = ((span[0] - origin.y) / cell).ceil().max(0.0) as i64;
                let last = (((span[1] - origin.y) / cell).floor() as i64).min(ny as i64 - 1);
                for j in first..=last {
                    values[grid.index(i, j as usize, k)] = -far;
                }
            }
        }
    }
    // Samples within a tetrahedron's longest edge (√3 cells) of the surface carry their exact
    // distance to it: every edge the surface crosses has both ends in that band.
    let band = 3f32.sqrt() * cell;
    let mut distance = vec![f32::INFINITY; grid.len()];
    let cell_of = |x: f32, a: usize| ((x - origin[a]) / cell).floor() as i64;
    for t in 0..closed.triangles.len() {
        let [a, b, c] = closed.triangle(t);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let lo = a.min(b).min(c) - Vec3::splat(band);
        let hi = a.max(b).max(c) + Vec3::splat(band);
        let range = |x: usize| {
            let first = (cell_of(lo[x], x) + 1).max(0);
            let last = cell_of(hi[x], x).min(dims[x] as i64 - 1);
            first as usize..(last + 1).max(first) as usize
        };
        for k in range(2) {
            for j in range(1) {
                for i in range(0) {
                    let p = grid.point(i, j, k);
                    if normal != Vec3::ZERO && (p - a).dot(normal).abs() > band {
                        continue;
                    }
                    let d = closest_point_triangle(p, a, b, c).distance(p);
                    let n = grid.index(i, j, k);
                    if d < distance[n] {
                        distance[n] = d;
                    }
                }
            }
        }
    }
    for (v, d) in values.iter_mut().zip(&distance) {
        if *d <= band {
            *v = v.signum() * d.max(MIN_VALUE_CELLS * cell);
        }
    }
    let mesh = marching_tetrahedra(&grid, &values);
    let mesh = largest_shell(&mesh);
    if mesh.triangles.is_empty() || mesh.signed_volume() <= 0.0 {
        return Err(ImportError::Flat {
            volume: mesh.signed_volume(),
        });
    }
    Ok(mesh)
}

/// The piece of `mesh` with the largest area (the outer shell; pockets inside it are dropped).
fn largest_shell(mesh: &TriMesh) -> TriMesh {
    let (piece, count) = mesh.edge_pieces();
    if count <= 1 {
        return mesh.clone();
    }
    let mut areas = vec![0.0f64; count];
    for (t, &p) in piece.iter().enumerate() {
        let [a, b, c] = mesh.triangle(t).map(|v| v.as_dvec3());
        areas[p as usize] += (b - a).cross(c - a).length();
    }
    let best = (0..count)
        .max_by(|&a, &b| areas[a].total_cmp(&areas[b]))
        .unwrap_or(0) as u32;
    mesh.keeping_piece(&piece, best).without_unused_vertices()
}

/// Mean, 95th percentile and largest distance (mm) from the vertices of `rebuilt` that stand
/// over the scanned surface `scan` (nearer to it than to the holes' fills and the root that
/// `closed` adds) to that surface.
fn distances(scan: &TriMesh, closed: &TriMesh, rebuilt: &TriMesh) -> (f32, f32, f32) {
    let (scan_bvh, closed_bvh) = (TriangleBvh::build(scan), TriangleBvh::build(closed));
    let to_scan = MeshRef {
        mesh: scan,
        bvh: &scan_bvh,
    };
    let to_closed = MeshRef {
        mesh: closed,
        bvh: &closed_bvh,
    };
    let mut d: Vec<f32> = rebuilt
        .vertices
        .iter()
        .filter_map(|&p| {
            let (_, on_scan) = closest_point_on_mesh(to_scan, p)?;
            let (_, on_closed) = closest_point_on_mesh(to_closed, p)?;
            (on_scan <= on_closed + 1e-4).then_some(on_scan)
        })
        .collect();
    if d.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    d.sort_by(f32::total_cmp);
    let mean = d.iter().map(|&x| f64::from(x)).sum::<f64>() / d.len() as f64;
    let p95 = d[((d.len() - 1) as f32 * 0.95).round() as usize];
    (mean as f32, p95, d[d.len() - 1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{
        fdi::{Arch, ToothKind},
        scan_like::{ScanDefects, scan_like_crown},
    };

    /// A scan-like lower incisor crown (1,000 triangles, typical defects of `seed`), its upper
    /// half turned a quarter about the vertical through its middle: the two halves cross along
    /// the whole crown.
    fn twisted_incisor(fdi: u8, seed: u64) -> TriMesh {
        let f = Fdi::new(i64::from(fdi)).unwrap();
        let crown = scan_like_crown(
            f.arch(),
            f.kind(),
            &crate::geometry::Pose::IDENTITY,
            1000,
            &ScanDefects::typical(seed),
            seed,
        );
        let c = crown.mesh.aabb().centre();
        let turn = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        crown
            .mesh
            .map_vertices(|v| if v.y > c.y { c + turn * (v - c) } else { v })
    }

    #[test]
    fn a_crown_crossing_itself_is_rebuilt_into_a_solid_near_the_scan() {
        let limits = RepairLimits::default();
        for (fdi, seed) in [(41u8, 0u64), (42, 1), (36, 1)] {
            let f = Fdi::new(i64::from(fdi)).unwrap();
            let mesh = twisted_incisor(fdi, seed);
            let refused = match super::super::prepare(&mesh, f, &limits) {
                Ok(_) => panic!("{fdi}: the repair was expected to fail"),
                Err(e) => e,
            };
            assert!(refused.is_repairable());
            let rebuilt = match rebuild(&mesh, f, &limits, &refused) {
                Ok(r) => r,
                Err(e) => panic!("{fdi}: {e}"),
            };
            rebuilt.mesh.validate_solid().expect("a valid solid");
            let r = rebuilt.repairs.rebuilt.as_ref().unwrap();
            assert!(r.reason.contains("intersects itself"), "{}", r.reason);
            assert!(r.mean_mm <= 0.05 && r.p95_mm <= 0.1, "{fdi}: {r:?}");
            assert!(rebuilt.repairs.summary().contains("rebuilt"));
            // The root is generated, about the table's length beyond the crown along its axis.
            assert!(rebuilt.cervical.is_some());
            let an = anatomy(f.arch(), f.kind());
            let a = rebuilt.apical.expect("a root axis");
            let reach = |m: &TriMesh| m.vertices.iter().map(|v| v.dot(a)).fold(f32::MIN, f32::max);
            let depth = reach(&rebuilt.mesh) - reach(&mesh);
            assert!(
                depth > 0.6 * an.root_length,
                "{fdi}: root {depth} mm, {:?}",
                rebuilt.repairs.root
            );
            // Scan resolution, not the grid's.
            assert!(
                rebuilt.mesh.triangles.len() < 8 * MIN_REBUILT_VERTICES,
                "{r:?}"
            );
        }
    }

    #[test]
    fn a_margin_not_facing_the_root_gets_its_root_along_the_arch() {
        // A lower incisor crown whose upper part is pressed through itself buccolingually: its
        // opening no longer faces the root's side.
        let f = Fdi::new(41).unwrap();
        let crown = scan_like_crown(
            Arch::Lower,
            ToothKind::CentralIncisor,
            &crate::geometry::Pose::IDENTITY,
            1000,
            &ScanDefects::typical(2),
            2,
        );
        let top = crown.mesh.aabb().max.y;
        let mesh = crown.mesh.map_vertices(|v| {
            let s = 1.0 - 1.6 * (v.y - (top - 3.0)).clamp(0.0, 1.0);
            Vec3::new(v.x, v.y, v.z * s)
        });
        let limits = RepairLimits::default();
        let refused = match super::super::prepare(&mesh, f, &limits) {
            Ok(_) => panic!("the repair was expected to fail"),
            Err(e) => e,
        };
        assert!(refused.to_string().contains("root's side"), "{refused}");
        let rebuilt = rebuild(&mesh, f, &limits, &refused).expect("rebuilt");
        rebuilt.mesh.validate_solid().unwrap();
        // The root grows down (the lower arch's apical side).
        assert!(rebuilt.mesh.aabb().min.y < mesh.aabb().min.y - 5.0);
    }

    #[test]
    fn what_is_no_tooth_is_not_rebuilt() {
        let f = Fdi::new(41).unwrap();
        let limits = RepairLimits::default();
        let tiny = twisted_incisor(41, 0).map_vertices(|v| v * 0.01);
        let reason = ImportError::FlatMargin;
        let e = rebuild(&tiny, f, &limits, &reason).unwrap_err();
        assert!(e.to_string().contains("units"), "{e}");
        assert!(rebuild(&TriMesh::default(), f, &limits, &reason).is_err());
        assert!(
            !ImportError::Span {
                span_mm: 0.1,
                min_mm: 2.0,
                max_mm: 80.0
            }
            .is_repairable()
        );
    }

    #[test]
    fn a_closed_surface_winding_twice_is_one_solid() {
        // Two overlapping cubes in one surface: their union comes back, closed and valid.
        let mut mesh = cube(Vec3::ZERO, 2.0);
        let other = cube(Vec3::new(1.0, 0.5, 0.3), 2.0);
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(&other.vertices);
        mesh.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
        assert!(mesh.find_self_intersection().is_some());
        let solid = solid_boundary(&mesh, 0.1).unwrap();
        solid.validate_solid().unwrap();
        // Union volume: 8 + 8 − overlap (1 × 1.5 × 1.7).
        let exact = 16.0 - 1.0 * 1.5 * 1.7;
        let v = solid.signed_volume();
        assert!((v - exact).abs() < 0.15, "{v} vs {exact}");
    }

    fn cube(at: Vec3, size: f32) -> TriMesh {
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                at + size * Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)
            })
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        TriMesh::new(v, t)
    }
}
