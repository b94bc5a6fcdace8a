//! A template root hung from a scanned crown's margin: the collar of [`super::root`] towards the
//! fitted template's axis, then rings that turn from the margin's outline into the template's
//! cross-sections, down to its apex.
//!
//! Construction and guarantee. The rings lie in parallel planes across the axis, at increasing
//! depths beyond the collar's plane (where no crown vertex is). When the collar's outline is
//! star-shaped about its centre (strictly increasing angles), every later ring is star-shaped
//! about its own centre too, with [`super::root`]'s vertex count reduced to [`SECTION_SAMPLES`]
//! evenly spaced directions: ring `k`'s vertex `i` is `c_k + r_ki · d_i`, any radius `r_ki > 0`.
//! Two rings are joined by a band whose triangles each span one angular interval, the intervals
//! of a band following each other round once (a merge of the two rings' angles; between rings of
//! the same directions these are the usual quads). The cross-section of such a band at any depth
//! then has its vertices at increasing angles about the interpolated centre (each on an edge
//! whose ends lie at two angles less than half a turn apart), so it is simple, and no two depths
//! meet: the body meets itself only along shared edges. An outline that is not star-shaped keeps
//! its shape and vertices, each ring a scaled and moved copy of it (cross-sections are scaled
//! copies, simple), never scaled below [`MIN_COPY_SCALE`] (a jagged outline scaled smaller would
//! bring its edges closer than single precision keeps apart). The cone to the apex has the last
//! ring's centre below it. Radii come from the template's cross-section in each direction (its
//! outermost surface, at least [`TEMPLATE_MIN_RADIUS_MM`]; several roots show as lobes joined by
//! a thin web), blended with the outline over the first [`TEMPLATE_BLEND`] of the depth.
//!
//! The exact self-intersection check of the whole tooth still runs after closing.

use glam::{DVec2, Vec3};

use super::{
    error::ImportError,
    root::{Focus, MIN_SEPARATION_MM, area_centroid, join, margin_axis, star, untangle},
    template::{Fit, Template, section},
};
use crate::geometry::TriMesh;

/// Rings of a template root's body: at `t = k / TEMPLATE_RING_STEPS` for `k < TEMPLATE_RINGS`;
/// a cone closes the body from the last one to the apex.
pub const TEMPLATE_RINGS: usize = 15;
/// Steps from the collar to the apex that a template root's rings are placed on.
pub const TEMPLATE_RING_STEPS: usize = 16;
/// Share of the root's depth over which a template root's rings turn from the margin's outline
/// into the template's cross-sections.
pub const TEMPLATE_BLEND: f64 = 0.35;
/// Thinnest a template root's cross-section gets (mm from its centre), between the lobes of
/// several roots and at the apex.
pub const TEMPLATE_MIN_RADIUS_MM: f32 = 0.3;
/// Directions a template's cross-section is sampled in, and vertices of the body's rings below
/// the collar's when its outline is star-shaped.
pub const SECTION_SAMPLES: usize = 48;
/// Smallest scale of a copied outline that is not star-shaped.
pub const MIN_COPY_SCALE: f64 = 0.5;

/// What a template root came to: its length and how far its axis is from the margin's normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemplateRoot {
    /// From the template's cervical centre to the apex along the root's axis (mm).
    pub length_mm: f32,
    /// Angle (degrees) between the root's axis and the margin's apical normal.
    pub axis_deg: f32,
    /// The cervical centre: where the template's long axis meets its cementoenamel junction.
    pub cervical: Vec3,
}

/// Closes the margin `l` of `mesh` with the root of `template` fitted to the crown (`fit`), its
/// collar's plane `gap` mm beyond the crown's deepest vertex along the template's axis (see the
/// module doc).
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn close_with_template(
    mesh: &mut TriMesh,
    l: &[u32],
    gap: f32,
    template: &Template,
    fit: &Fit,
) -> Result<TemplateRoot, ImportError> {
    let (_, margin_apical) = margin_axis(mesh, l)?;
    let apical = fit.apical();
    let cervical = fit.origin;
    let length = fit.root_length(template);
    let f = Focus::new(mesh, cervical, apical, length);
    let (c, a, u, w) = (f.c, f.a, f.u, f.w);
    let h0 = f.deepest + f64::from(gap);
    let apex_depth = f64::from(length).max(h0 + 0.3 * f64::from(length));
    let projected = f.project(mesh, l);
    let outline = untangle(&projected, MIN_SEPARATION_MM)
        .unwrap_or_else(|| star(&projected, MIN_SEPARATION_MM));
    let to_h0 = (f.depth - h0) / (f.depth - f.deepest);
    let ring0: Vec<DVec2> = outline.iter().map(|&q| q * to_h0).collect();
    let pivot = area_centroid(&ring0);
    let place = |q: DVec2, depth: f64| (c + a * depth + u * q.x + w * q.y).as_vec3();
    let in_plane = |p: Vec3| {
        let d = p.as_dvec3() - c;
        DVec2::new(d.dot(u), d.dot(w))
    };
    let turn = turning(&ring0, pivot);
    // The template's sections are sampled at evenly spaced angles about the axis, starting at
    // the outline's first vertex and running its way round.
    let start = (ring0[0] - pivot).to_angle();
    let sign = turn.unwrap_or(1.0);
    let angles: Vec<f64> = (0..SECTION_SAMPLES)
        .map(|k| start + sign * k as f64 / SECTION_SAMPLES as f64 * std::f64::consts::TAU)
        .collect();
    let dirs: Vec<DVec2> = angles.iter().map(|&t| DVec2::from_angle(t)).collect();
    let world_dirs: Vec<Vec3> = dirs.iter().map(|d| (u * d.x + w * d.y).as_vec3()).collect();
    let outline_radius = |d: DVec2| radius_along(&ring0, pivot, d);
    let mean_ring0 =
        ring0.iter().map(|q| q.distance(pivot)).sum::<f64>() / ring0.len().max(1) as f64;
    let mut prev: Vec<u32> = l.to_vec();
    let mut prev_angles: Option<Vec<f64>> = None;
    let mut centre = pivot;
    for k in 0..TEMPLATE_RINGS {
        let t = k as f64 / TEMPLATE_RING_STEPS as f64;
        let depth = h0 + (apex_depth - h0) * t;
        let blend = smooth(t / TEMPLATE_BLEND);
        let shrink = (1.0 - t).powf(0.7);
        let base = mesh.vertices.len() as u32;
        if k == 0 {
            // The collar's own ring: the outline itself.
            for &q in &ring0 {
                mesh.vertices.push(place(q, depth));
            }
            let ring: Vec<u32> = (0..ring0.len() as u32).map(|i| base + i).collect();
            join(mesh, &prev, &ring);
            prev = ring;
            if turn.is_some() {
                prev_angles = Some(unwrapped_angles(&ring0, pivot, start, sign));
            }
            continue;
        }
        let (at, radii) = section(
            template,
            fit,
            a.as_vec3(),
            depth as f32,
            &world_dirs,
            TEMPLATE_MIN_RADIUS_MM,
        );
        centre = pivot * (1.0 - blend) + in_plane(at) * blend;
        match &prev_angles {
            Some(from) => {
                for (d, &r) in dirs.iter().zip(&radii) {
                    let own = outline_radius(*d) * shrink;
                    let r = own * (1.0 - blend) + f64::from(r) * blend;
                    mesh.vertices.push(place(centre + *d * r.max(1e-3), depth));
                }
                let ring: Vec<u32> = (0..SECTION_SAMPLES as u32).map(|i| base + i).collect();
                if k == 1 {
                    zip(mesh, &prev, from, &ring, &angles, sign);
                } else {
                    join(mesh, &prev, &ring);
                }
                prev_angles = Some(angles.clone());
                prev = ring;
            }
            None => {
                let mean_template =
                    radii.iter().map(|&r| f64::from(r)).sum::<f64>() / radii.len().max(1) as f64;
                let scale = (shrink * (1.0 - blend) + mean_template / mean_ring0.max(1e-6) * blend)
                    .max(MIN_COPY_SCALE);
                for &q in &ring0 {
                    mesh.vertices
                        .push(place(centre + (q - pivot) * scale, depth));
                }
                let ring: Vec<u32> = (0..ring0.len() as u32).map(|i| base + i).collect();
                join(mesh, &prev, &ring);
                prev = ring;
            }
        }
    }
    let apex = mesh.vertices.len() as u32;
    mesh.vertices.push(place(centre, apex_depth));
    for i in 0..prev.len() {
        let (p, q) = (prev[i], prev[(i + 1) % prev.len()]);
        mesh.triangles.push([q, p, apex]);
    }
    Ok(TemplateRoot {
        length_mm: apex_depth as f32,
        axis_deg: apical.angle_between(margin_apical).to_degrees(),
        cervical,
    })
}

/// Smoothstep on [0, 1].
fn smooth(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The way `p` turns about `centre` (+1 or −1) when its vertices lie at strictly increasing
/// angles all the way round once; None when it is not star-shaped about it.
fn turning(p: &[DVec2], centre: DVec2) -> Option<f64> {
    let n = p.len();
    if n < 3 {
        return None;
    }
    let mut total = 0.0;
    let mut sign = 0.0;
    for i in 0..n {
        let (a, b) = (p[i] - centre, p[(i + 1) % n] - centre);
        if a.length() < 1e-9 || b.length() < 1e-9 {
            return None;
        }
        let step = a.perp_dot(b).atan2(a.dot(b));
        if step == 0.0 || (sign != 0.0 && step.signum() != sign) || step.abs() >= 3.0 {
            return None;
        }
        sign = step.signum();
        total += step;
    }
    ((total.abs() - std::f64::consts::TAU).abs() < 1e-6).then_some(sign)
}

/// The angles of `p`'s vertices about `centre`, from `start` the way `sign` turns, unwrapped so
/// that they increase (times `sign`) from `start` (the first is `start`).
fn unwrapped_angles(p: &[DVec2], centre: DVec2, start: f64, sign: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(p.len());
    let mut last = start;
    for (i, q) in p.iter().enumerate() {
        let a = (*q - centre).to_angle();
        if i == 0 {
            out.push(start);
            continue;
        }
        let mut step = (a - last).rem_euclid(std::f64::consts::TAU);
        if sign < 0.0 {
            step -= std::f64::consts::TAU;
        }
        last += step;
        out.push(last);
    }
    out
}

/// Distance from `centre` to the star-shaped polygon `p` along the unit direction `d`.
fn radius_along(p: &[DVec2], centre: DVec2, d: DVec2) -> f64 {
    let n = p.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (p[i] - centre, p[(i + 1) % n] - centre);
        // Solve t·d = a + s·(b − a), t > 0, s in [0, 1].
        let e = b - a;
        let den = d.perp_dot(e);
        if den.abs() < 1e-15 {
            continue;
        }
        let t = a.perp_dot(e) / den;
        let s = a.perp_dot(d) / den;
        if t > 0.0 && (-1e-9..=1.0 + 1e-9).contains(&s) {
            best = best.min(t);
        }
    }
    if best.is_finite() {
        best
    } else {
        p.iter().map(|q| q.distance(centre)).sum::<f64>() / n.max(1) as f64
    }
}

/// Joins ring `upper` (angles `ua`, increasing times `sign` from the first, in the direction its
/// triangles run it the other way, as [`join`] expects) to ring `lower` (angles `la`, same start
/// and direction) by triangles that each span one angular interval, merging the two rings'
/// angles once round.
fn zip(mesh: &mut TriMesh, upper: &[u32], ua: &[f64], lower: &[u32], la: &[f64], sign: f64) {
    let (n, m) = (upper.len(), lower.len());
    let tau = std::f64::consts::TAU;
    // Angle (times sign, from the common start) of the k-th vertex of a ring, past the end
    // continuing round.
    let at = |angles: &[f64], k: usize| {
        let len = angles.len();
        (angles[k % len] - angles[0]) * sign + tau * (k / len) as f64
    };
    let (mut i, mut j) = (0usize, 0usize);
    while i < n || j < m {
        let advance_upper = j >= m || (i < n && at(ua, i + 1) <= at(la, j + 1));
        if advance_upper {
            mesh.triangles
                .push([upper[(i + 1) % n], upper[i % n], lower[j % m]]);
            i += 1;
        } else {
            mesh.triangles
                .push([upper[i % n], lower[j % m], lower[(j + 1) % m]]);
            j += 1;
        }
    }
}
