//! A plan as a page: the movement table per tooth, the IPR chart and pictures of the arches at
//! the first and last stage, each tooth coloured by how much it still has to move.

use std::fmt::Write;

use glam::Vec3;
use plotters::prelude::*;

use super::AnalysisError;
use crate::planning::Plan;
use crate::teeth::{Arch, Dentition};

/// Picture size (pixels).
const SIZE: (u32, u32) = (1200, 560);

/// The colour (sRGB, 0–1) of how much a tooth still has to move ([`Plan::still_to_move`]):
/// green for nothing, through yellow, to red.
pub fn still_to_move_colour(t: f32) -> [f32; 3] {
    let (g, y, r) = ([0.35, 0.67, 0.35], [0.92, 0.78, 0.24], [0.82, 0.2, 0.16]);
    let (a, b, f) = if t < 0.5 {
        (g, y, t * 2.0)
    } else {
        (y, r, (t - 0.5) * 2.0)
    };
    [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * f.clamp(0.0, 1.0))
}

fn colour(t: f32) -> RGBColor {
    let [r, g, b] = still_to_move_colour(t).map(|c| (c * 255.0) as u8);
    RGBColor(r, g, b)
}

/// A triangle seen from the occlusal side: its corners (x, z), its height towards the viewer and
/// its colour.
type Flat = ([(f32, f32); 3], f32, RGBColor);

fn draw_arch<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    d: &Dentition,
    plan: &Plan,
    arch: Arch,
    k: u32,
) -> Result<(), AnalysisError> {
    let plot = |e: &dyn std::fmt::Display| AnalysisError::Plot(e.to_string());
    // Seen from the occlusal side: from below for the upper arch (mirrored), above for the lower.
    let facing = if arch == Arch::Upper { -1.0 } else { 1.0 };
    let mut tris: Vec<Flat> = Vec::new();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (i, m) in plan.moves.iter().enumerate() {
        if m.fdi.arch() != arch {
            continue;
        }
        let Some(t) = d.tooth(m.fdi) else { continue };
        let pose = m.pose_at(k);
        let c = colour(plan.still_to_move(i, k));
        for j in 0..t.geometry.mesh.triangles.len() {
            let v = t.geometry.mesh.triangle(j).map(|p| pose.transform_point(p));
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            if n.y * facing <= 0.0 {
                continue;
            }
            let shade = (n.normalize_or_zero().y.abs() * 0.6 + 0.4).clamp(0.0, 1.0);
            let height = (v[0].y + v[1].y + v[2].y) / 3.0 * facing;
            for p in v {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            let c = RGBColor(
                (c.0 as f32 * shade) as u8,
                (c.1 as f32 * shade) as u8,
                (c.2 as f32 * shade) as u8,
            );
            tris.push((v.map(|p| (p.x * facing, p.z)), height, c));
        }
    }
    if tris.is_empty() {
        return Ok(());
    }
    // The nearest surface drawn last.
    tris.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x0, x1) = if facing < 0.0 {
        (-hi.x, -lo.x)
    } else {
        (lo.x, hi.x)
    };
    let title = format!(
        "{} arch, stage {k} of {}",
        if arch == Arch::Upper {
            "upper"
        } else {
            "lower"
        },
        plan.stages
    );
    let mut chart = ChartBuilder::on(area)
        .caption(title, (super::plot::font(), 20))
        .margin(10)
        .build_cartesian_2d(x0 - 2.0..x1 + 2.0, lo.z - 2.0..hi.z + 2.0)
        .map_err(|e| plot(&e))?;
    chart
        .draw_series(
            tris.iter()
                .map(|(t, _, c)| Polygon::new(t.to_vec(), c.filled())),
        )
        .map_err(|e| plot(&e))?;
    // IPR done by this stage: a black ring between the two teeth.
    for ipr in plan
        .ipr
        .iter()
        .filter(|x| x.a.arch() == arch && x.stage <= k)
    {
        let at = |f| {
            let m = plan.moves.iter().find(|m| m.fdi == f)?;
            Some(m.pose_at(k).transform_point(m.pivot))
        };
        if let (Some(a), Some(b)) = (at(ipr.a), at(ipr.b)) {
            let p = (a + b) * 0.5;
            chart
                .draw_series(std::iter::once(Circle::new(
                    (p.x * facing, p.z),
                    5,
                    BLACK.stroke_width(2),
                )))
                .map_err(|e| plot(&e))?;
        }
    }
    Ok(())
}

/// Both arches at stage `k` as a PNG file's bytes.
///
/// # Errors
/// [`AnalysisError::Plot`] when the picture cannot be drawn or encoded.
pub fn stage_png(d: &Dentition, plan: &Plan, k: u32) -> Result<Vec<u8>, AnalysisError> {
    let plot = |e: &dyn std::fmt::Display| AnalysisError::Plot(e.to_string());
    let mut rgb = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot(&e))?;
        let (left, right) = root.split_horizontally(SIZE.0 / 2);
        draw_arch(&left, d, plan, Arch::Upper, k)?;
        draw_arch(&right, d, plan, Arch::Lower, k)?;
        root.present().map_err(|e| plot(&e))?;
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, SIZE.0, SIZE.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(|e| plot(&e))?;
        w.write_image_data(&rgb).map_err(|e| plot(&e))?;
    }
    Ok(out)
}

/// The plan's page, with `first` and `last` the file names of the two stage pictures.
pub fn plan_html(plan: &Plan, first: &str, last: &str) -> String {
    let mut h = String::new();
    let e = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;");
    let _ = write!(
        h,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>orthosim plan: {case}</title>\
         <style>body{{font-family:sans-serif;margin:2em;max-width:1250px}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 7px;text-align:right}}\
         th{{background:#eee}}img{{max-width:100%}}</style></head><body>\
         <h1>Plan for {case}</h1><p>{stages} stages ({seq}), target {target}; planned in {ms:.0} ms \
         (target set up in {tms:.0} ms). Deepest penetration beyond what is allowed: {pen:.3} mm. \
         Deepest overlap in the scan: {scan:.3} mm. Deepest overlap between the arches (not \
         checked between stages): {opp0:.3} mm as scanned, {opp1:.3} mm at the target.</p>",
        case = e(&plan.case),
        stages = plan.stages,
        seq = plan.limits.sequence.name(),
        target = plan.target,
        ms = plan.plan_ms,
        tms = plan.target_ms,
        pen = plan.max_penetration_mm,
        scan = plan.scan_overlap_mm,
        opp0 = plan.opposing_overlap_mm[0],
        opp1 = plan.opposing_overlap_mm[1],
    );
    if !plan.blocked.is_empty() {
        h.push_str("<h2>Blocked</h2><ul>");
        for b in &plan.blocked {
            let _ = write!(
                h,
                "<li>{}–{} at stage {}: {:.3} mm; {}</li>",
                b.a,
                b.b,
                b.stage,
                b.depth_mm,
                e(&b.why)
            );
        }
        h.push_str("</ul>");
    }
    for s in &plan.setup {
        let _ = write!(h, "<p>{}.</p>", e(&s.summary()));
    }
    let _ = write!(h, "<p>{}.</p>", e(&plan.relations_summary()));
    h.push_str(
        "<h2>Movement per tooth</h2><table><tr><th>tooth</th><th>total mm</th><th>total °</th>\
         <th>mesio-distal mm</th><th>bucco-lingual mm</th><th>vertical mm</th><th>rotation °</th>\
         <th>tip °</th><th>torque °</th><th>starts after stage</th><th>stages</th></tr>",
    );
    for t in &plan.teeth {
        let c = t.components;
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{:.2}</td><td>{:.1}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td>\
             <td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td>{}</td><td>{}</td></tr>",
            t.fdi,
            t.total_mm,
            t.total_deg,
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            c[5],
            t.start,
            t.moving_stages
        );
    }
    h.push_str("</table><h2>IPR</h2>");
    if plan.ipr.is_empty() {
        h.push_str("<p>None.</p>");
    } else {
        let rows = plan.ipr.len();
        let _ = write!(
            h,
            "<svg width=\"620\" height=\"{}\" xmlns=\"http://www.w3.org/2000/svg\" font-size=\"13\">",
            rows * 24 + 10
        );
        for (r, x) in plan.ipr.iter().enumerate() {
            let y = r * 24 + 5;
            let w = (x.mm / 0.6 * 400.0).min(400.0);
            let _ = write!(
                h,
                "<text x=\"0\" y=\"{}\">{}|{} stage {}</text><rect x=\"150\" y=\"{y}\" width=\"{w:.0}\" \
                 height=\"18\" fill=\"#c0504d\"/><text x=\"{:.0}\" y=\"{}\">{:.2} mm</text>",
                y + 14,
                x.a,
                x.b,
                x.stage,
                155.0 + w,
                y + 14,
                x.mm
            );
        }
        h.push_str("</svg>");
    }
    let _ = write!(
        h,
        "<h2>First and last stage</h2><p>Teeth coloured by what they still have to move (green: \
         nothing; red: 2 mm or 10° or more); rings mark contacts reduced by then.</p>\
         <img src=\"{first}\" alt=\"stage 0\"><img src=\"{last}\" alt=\"last stage\"></body></html>"
    );
    h
}
