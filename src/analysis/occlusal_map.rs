//! A picture of an arch's occlusal contact map: the arch seen from the opposing arch, each
//! triangle of its teeth coloured by its exact distance to the opposing arch (red at contact
//! through yellow and green to blue at 0.5 mm, grey beyond), as SVG.

use glam::Vec3;
use plotters::prelude::*;

use super::{AnalysisError, measures::Posed};
use crate::{
    geometry::{MeshRef, closest_point_on_mesh_within},
    teeth::Arch,
};

/// Distances beyond this (mm) are drawn grey.
pub const MAP_RANGE_MM: f32 = 0.5;

/// Colour of a distance (mm): red at 0, yellow, green, blue at [`MAP_RANGE_MM`], grey beyond.
pub fn map_colour(d: f32) -> RGBColor {
    if d.is_nan() || d > MAP_RANGE_MM {
        return RGBColor(200, 200, 200);
    }
    let t = (d.max(0.0) / MAP_RANGE_MM).clamp(0.0, 1.0);
    let stops = [
        (0.0, [220.0, 30.0, 30.0]),
        (0.33, [240.0, 220.0, 40.0]),
        (0.66, [50.0, 180.0, 70.0]),
        (1.0, [40.0, 90.0, 220.0]),
    ];
    let k = stops.iter().rposition(|(s, _)| *s <= t).unwrap_or(0).min(2);
    let (s0, c0) = stops[k];
    let (s1, c1) = stops[k + 1];
    let f = ((t - s0) / (s1 - s0)).clamp(0.0, 1.0);
    let c = |i: usize| (c0[i] + (c1[i] - c0[i]) * f) as u8;
    RGBColor(c(0), c(1), c(2))
}

/// A triangle projected on the occlusal plane (x, z) with its distance to the opposing arch.
type FlatTriangle = ([(f32, f32); 3], f32);

/// The triangles of `arch` seen from the opposing arch, each with its distance to it, and the
/// bounds of the arch (x, z).
fn triangles(teeth: &[Posed], arch: Arch) -> (Vec<FlatTriangle>, [f32; 4]) {
    let mine: Vec<&Posed> = teeth.iter().filter(|t| t.fdi.arch() == arch).collect();
    let others: Vec<&Posed> = teeth.iter().filter(|t| t.fdi.arch() != arch).collect();
    let mut polys: Vec<FlatTriangle> = Vec::new();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    // Seen from the opposing arch: from below for the upper arch (mirrored), from above for the
    // lower.
    let facing = if arch == Arch::Upper { -1.0 } else { 1.0 };
    for t in &mine {
        for k in 0..t.geometry.mesh.triangles.len() {
            let tri = t
                .geometry
                .mesh
                .triangle(k)
                .map(|p| t.pose.transform_point(p));
            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            if n.y * facing <= 0.0 {
                continue;
            }
            let c = (tri[0] + tri[1] + tri[2]) / 3.0;
            let mut d = f32::INFINITY;
            for o in &others {
                let local = o.pose.inverse().transform_point(c);
                let m = MeshRef {
                    mesh: &o.geometry.mesh,
                    bvh: &o.geometry.bvh,
                };
                if let Some((_, dist)) = closest_point_on_mesh_within(m, local, MAP_RANGE_MM) {
                    d = d.min(dist);
                }
            }
            let flat = tri.map(|p| Vec3::new(p.x * facing, 0.0, p.z));
            for p in flat {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            polys.push((flat.map(|p| (p.x, p.z)), d));
        }
    }
    // Far triangles first, contacts on top.
    polys.sort_by(|a, b| b.1.total_cmp(&a.1));
    (polys, [lo.x, hi.x, lo.z, hi.z])
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    teeth: &[Posed],
    arch: Arch,
    title: &str,
) -> Result<(), AnalysisError> {
    let plot = |e: &dyn std::fmt::Display| AnalysisError::Plot(e.to_string());
    let (polys, [x0, x1, z0, z1]) = triangles(teeth, arch);
    root.fill(&WHITE).map_err(|e| plot(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (super::plot::font(), 20))
        .margin(12)
        .build_cartesian_2d(x0 - 2.0..x1 + 2.0, z0 - 2.0..z1 + 2.0)
        .map_err(|e| plot(&e))?;
    chart
        .draw_series(
            polys
                .iter()
                .map(|(tri, d)| Polygon::new(tri.to_vec(), map_colour(*d).filled())),
        )
        .map_err(|e| plot(&e))?;
    root.present().map_err(|e| plot(&e))
}

/// The occlusal contact map of `arch` among `teeth` (placed where they stand), as an SVG
/// picture seen from the opposing arch.
///
/// # Errors
/// [`AnalysisError::Plot`] when the picture cannot be drawn.
pub fn occlusal_map_svg(teeth: &[Posed], arch: Arch, title: &str) -> Result<String, AnalysisError> {
    let mut out = String::new();
    draw(
        SVGBackend::with_string(&mut out, (700, 620)).into_drawing_area(),
        teeth,
        arch,
        title,
    )?;
    Ok(out)
}

/// The same picture as a PNG file at `path` (drawn beside it, then renamed).
///
/// # Errors
/// [`AnalysisError::Plot`] or [`AnalysisError::Output`].
pub fn occlusal_map_png(
    path: &std::path::Path,
    teeth: &[Posed],
    arch: Arch,
    title: &str,
) -> Result<(), AnalysisError> {
    super::plot::write_png(path, (700, 620), |root| draw(root, teeth, arch, title))
}
