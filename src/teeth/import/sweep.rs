//! A template root hung from a scanned crown's margin: the collar of [`super::root`] towards the
//! fitted template's axis, then rings that turn from the margin's outline into the template's
//! cross-sections, down to its apex.
//!
//! Construction and guarantee. The rings lie in parallel planes across the axis, at increasing
//! depths beyond the collar's plane (where no crown vertex is). When the collar's outline is
//! star-shaped about its centre (strictly increasing angles), or a band [`TRANSITION_MM`] deep
//! leads from it to a star-shaped copy of it (the same radii, angles made to increase; taken only
//! when the band's cross-sections, the vertex-wise blends of the two outlines, are simple at nine
//! depths, and checked exactly with the whole tooth; the caller also tries without it), every
//! later ring is star-shaped about its own centre too, with [`super::root`]'s vertex count reduced to [`SECTION_SAMPLES`]
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
//! outermost surface, at least [`TEMPLATE_MIN_RADIUS_MM`]), blended with the outline over the
//! first [`TEMPLATE_BLEND`] of the depth.
//!
//! Several roots. For a template with two or three roots and a star-shaped outline, the rings
//! stop at the template's furcation (the trunk), and the last one is split into one outline per
//! root: the plane is cut into wedges about the ring's centre (at most half a turn each, their
//! boundaries halfway between the roots' apices, on ring vertices), and each root's outline is the
//! ring's vertices in its wedge plus the centre. Each root is then swept like the trunk, its rings
//! star-shaped about a centre moving towards the template root's axis, to its own apex, every
//! vertex at least [`BRANCH_CLEARANCE_MM`] inside its wedge. A wedge is convex, and each ring is
//! strictly inside it below the furcation's plane, so two roots meet only along the edges they
//! share in that plane (from the centre to the wedge's boundary vertices): the furcation. A
//! split that does not fit (a wedge too narrow, an outline not star-shaped about its centroid)
//! is not made, and the trunk closes with a cone (several roots then show as lobes joined by a
//! thin web).
//!
//! The exact self-intersection check of the whole tooth still runs after closing.

use glam::{DVec2, DVec3, Vec3};

use super::{
    error::ImportError,
    root::{
        Collar, MIN_SEPARATION_MM, area_centroid, join, margin_axis, offending, star, star_with,
    },
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
/// Depth (mm) of the band from the collar's outline to its star-shaped copy.
pub const TRANSITION_MM: f64 = 0.5;
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
    /// Roots below the furcation (1 for a single root, or a trunk closed with a cone).
    pub roots: usize,
}

/// Closes the margin `l` of `mesh` with the root of `template` fitted to the crown (`fit`), its
/// collar's plane `gap` mm beyond the crown's deepest vertex along the template's axis (see the
/// module doc). With `star_body`, a collar outline that is not star-shaped is followed by a band
/// to a star-shaped copy of it, so the body takes the template's sections and roots; that band
/// is not simple by construction (the exact check decides), so the caller tries without it too.
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn close_with_template(
    mesh: &mut TriMesh,
    l: &[u32],
    gap: f32,
    template: &Template,
    fit: &Fit,
    star_body: bool,
) -> Result<TemplateRoot, ImportError> {
    let (_, margin_apical) = margin_axis(mesh, l)?;
    let apical = fit.apical();
    let cervical = fit.origin;
    let length = fit.root_length(template);
    // The collar's outline: the margin seen from the focus, made simple (its strips then hang
    // straight from the margin). The body's rings start from it, or, when `star_body` asks and
    // the outline is not star-shaped about its centre, from a star-shaped copy of it (angles
    // alone made to increase, radii kept) a thin band below it.
    let Collar {
        focus: f,
        h0,
        apex_depth,
        ring: collar,
    } = Collar::new(mesh, l, cervical, apical, length, gap);
    let (c, a, u, w) = (f.c, f.a, f.u, f.w);
    let centre0 = area_centroid(&collar);
    let ring0: Vec<DVec2> = if !star_body || turning(&collar, centre0).is_some() {
        collar.clone()
    } else {
        // The band from the collar's outline to its copy has, at each depth, the outlines'
        // vertex-wise blend as its cross-section: the copy is taken only when those blends are
        // simple.
        let band_simple = |copy: &[DVec2]| {
            (1..10).all(|k| {
                let l = k as f64 / 10.0;
                let blend: Vec<DVec2> = collar
                    .iter()
                    .zip(copy)
                    .map(|(p, q)| *p * (1.0 - l) + *q * l)
                    .collect();
                offending(&blend, MIN_SEPARATION_MM).is_empty()
            })
        };
        [
            star_with(&collar, 0.25, 0),
            star(&collar, MIN_SEPARATION_MM),
        ]
        .into_iter()
        .find(|copy| {
            offending(copy, MIN_SEPARATION_MM).is_empty()
                && turning(copy, centre0).is_some()
                && band_simple(copy)
        })
        .unwrap_or_else(|| collar.clone())
    };
    let pivot = if turning(&ring0, centre0).is_some() {
        centre0
    } else {
        area_centroid(&ring0)
    };
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
    // Where several roots part: the template's furcation, below the collar. The trunk's rings
    // stop there and each root continues on its own (star-shaped outlines only).
    let (trunk, axes) = template.solid.root_axes();
    let depth_of = |p: Vec3| (p.as_dvec3() - c).dot(a);
    let furcation = (turn.is_some() && axes.len() >= 2)
        .then(|| depth_of(fit.to_world(Vec3::new(0.0, -trunk, 0.0))).max(h0 + 1.0))
        .filter(|&d| d < apex_depth - 2.0);
    let mut depths: Vec<f64> = (0..TEMPLATE_RINGS)
        .map(|k| h0 + (apex_depth - h0) * k as f64 / TEMPLATE_RING_STEPS as f64)
        .filter(|&d| furcation.is_none_or(|f| d < f - 0.3))
        .collect();
    depths.extend(furcation);
    let mut prev: Vec<u32> = l.to_vec();
    let mut prev_angles: Option<Vec<f64>> = None;
    let mut centre = pivot;
    for (k, &depth) in depths.iter().enumerate() {
        let t = (depth - h0) / (apex_depth - h0);
        let blend = smooth(t / TEMPLATE_BLEND);
        let shrink = (1.0 - t).powf(0.7);
        let base = mesh.vertices.len() as u32;
        if k == 0 {
            // The collar's own ring: the outline itself, then its star-shaped copy if any.
            for &q in &collar {
                mesh.vertices.push(place(q, depth));
            }
            let ring: Vec<u32> = (0..collar.len() as u32).map(|i| base + i).collect();
            join(mesh, &prev, &ring);
            prev = ring;
            if ring0 != collar {
                let base = mesh.vertices.len() as u32;
                for &q in &ring0 {
                    mesh.vertices.push(place(q, depth + TRANSITION_MM));
                }
                let ring: Vec<u32> = (0..ring0.len() as u32).map(|i| base + i).collect();
                join(mesh, &prev, &ring);
                prev = ring;
            }
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
    let split = furcation.is_some_and(|d| {
        let frame = Plane {
            c,
            a,
            u,
            w,
            depth: d,
        };
        let ring_points: Vec<DVec2> = prev
            .iter()
            .map(|&v| in_plane(mesh.vertices[v as usize]))
            .collect();
        branch(
            mesh,
            &frame,
            &prev,
            &ring_points,
            centre,
            &angles,
            sign,
            template,
            fit,
        )
    });
    if !split {
        let apex = mesh.vertices.len() as u32;
        mesh.vertices.push(place(centre, apex_depth));
        for i in 0..prev.len() {
            let (p, q) = (prev[i], prev[(i + 1) % prev.len()]);
            mesh.triangles.push([q, p, apex]);
        }
    }
    Ok(TemplateRoot {
        roots: if split { axes.len() } else { 1 },
        length_mm: apex_depth as f32,
        axis_deg: apical.angle_between(margin_apical).to_degrees(),
        cervical,
    })
}

/// A plane across the root's axis: the axis's origin `c` and direction `a`, the plane's in-plane
/// axes `u` and `w`, and its depth along `a`.
struct Plane {
    c: DVec3,
    a: DVec3,
    u: DVec3,
    w: DVec3,
    depth: f64,
}

impl Plane {
    /// A point of the plane at in-plane coordinates `q`, `extra` deeper.
    fn at(&self, q: DVec2, extra: f64) -> Vec3 {
        (self.c + self.a * (self.depth + extra) + self.u * q.x + self.w * q.y).as_vec3()
    }

    /// In-plane coordinates of a point.
    fn coords(&self, p: Vec3) -> DVec2 {
        let d = p.as_dvec3() - self.c;
        DVec2::new(d.dot(self.u), d.dot(self.w))
    }

    /// Depth (along the axis, from the plane) of a point.
    fn below(&self, p: Vec3) -> f64 {
        (p.as_dvec3() - self.c).dot(self.a) - self.depth
    }

    /// A world direction of the plane.
    fn dir(&self, d: DVec2) -> Vec3 {
        (self.u * d.x + self.w * d.y).as_vec3()
    }
}

/// Rings of each root below the furcation.
pub const BRANCH_RINGS: usize = 10;
/// Clearance (mm) each root keeps from the planes that part it from its neighbours.
pub const BRANCH_CLEARANCE_MM: f64 = 0.05;

/// The wedge of one root: between the rays from `corner` along `from` and along `to` (unit), the
/// way `sign` turns; at most half a turn.
struct Wedge {
    corner: DVec2,
    /// Inward normals of the two boundary lines.
    normals: [DVec2; 2],
}

impl Wedge {
    fn new(corner: DVec2, from: DVec2, to: DVec2, sign: f64) -> Self {
        Self {
            corner,
            normals: [from.perp() * sign, -to.perp() * sign],
        }
    }

    /// How far from `q` along the unit `d` the wedge reaches (infinite when it does not end).
    fn reach(&self, q: DVec2, d: DVec2) -> f64 {
        self.normals
            .iter()
            .map(|n| {
                let rate = d.dot(*n);
                if rate < 0.0 {
                    (q - self.corner).dot(*n) / -rate
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn contains(&self, q: DVec2) -> bool {
        self.normals.iter().all(|n| (q - self.corner).dot(*n) > 0.0)
    }
}

/// Splits the trunk's last ring `ring` (in-plane `points`, star-shaped about `centre` at the
/// evenly spaced `angles` the way `sign` turns) into one outline per root of the template, each in
/// a wedge about the ring's centre towards its root's apex, and sweeps each root from its outline
/// to its apex inside its wedge. Each outline is the ring's vertices in the wedge and the centre;
/// neighbouring roots share the centre and the wedge's boundary edges. False (nothing added) when
/// the ring does not split cleanly: the caller closes it with a cone.
#[allow(clippy::too_many_arguments)]
fn branch(
    mesh: &mut TriMesh,
    plane: &Plane,
    ring: &[u32],
    points: &[DVec2],
    centre: DVec2,
    angles: &[f64],
    sign: f64,
    template: &Template,
    fit: &Fit,
) -> bool {
    let n = ring.len();
    let tau = std::f64::consts::TAU;
    let (_, axes) = template.solid.root_axes();
    // Each root: its axis in the world, the angle of its apex about the centre.
    let mut roots: Vec<(Vec3, Vec3, f64)> = axes
        .iter()
        .map(|(s, e)| {
            let (s, e) = (fit.to_world(*s), fit.to_world(*e));
            let d = plane.coords(e) - centre;
            (s, e, d.y.atan2(d.x))
        })
        .collect();
    let step = |phi: f64| ((phi - angles[0]) * sign).rem_euclid(tau);
    roots.sort_by(|x, y| step(x.2).total_cmp(&step(y.2)));
    let m = roots.len();
    // Boundaries between consecutive roots, on ring vertices.
    let mut bounds: Vec<usize> = (0..m)
        .map(|j| {
            let (a, b) = (step(roots[j].2), step(roots[(j + 1) % m].2));
            let gap = (b - a).rem_euclid(tau);
            let mid = a + gap / 2.0;
            ((mid / tau * n as f64).round() as usize) % n
        })
        .collect();
    if m == 2 {
        bounds[1] = (bounds[0] + n / 2) % n;
    }
    // Root j lies between bounds[j − 1] and bounds[j].
    let spans: Vec<(usize, usize)> = (0..m)
        .map(|j| (bounds[(j + m - 1) % m], bounds[j]))
        .collect();
    if spans
        .iter()
        .any(|&(a, b)| !(3..=n / 2).contains(&((b + n - a) % n)))
    {
        return false;
    }
    let ray = |k: usize| DVec2::from_angle(angles[k]);
    let wedges: Vec<Wedge> = spans
        .iter()
        .map(|&(a, b)| Wedge::new(centre, ray(a), ray(b), sign))
        .collect();
    // Each root's outline, its centre, and its directions.
    let mut outlines = Vec::with_capacity(m);
    for (j, &(a, b)) in spans.iter().enumerate() {
        let count = (b + n - a) % n + 1;
        let mut idx: Vec<usize> = (0..count).map(|k| (a + k) % n).collect();
        let mut pts: Vec<DVec2> = idx.iter().map(|&k| points[k]).collect();
        pts.push(centre);
        let q = area_centroid(&pts);
        if !wedges[j].contains(q) || turning(&pts, q).is_none() {
            return false;
        }
        idx.push(usize::MAX);
        outlines.push((idx, pts, q));
    }
    // Every root's rings are planned before any is added, so a root that does not fit its wedge
    // leaves the mesh as it was.
    let mut planned: Vec<(Vec<usize>, Vec<Vec<Vec3>>, Vec3)> = Vec::with_capacity(m);
    for (j, (idx, pts, q0)) in outlines.into_iter().enumerate() {
        let (start, apex, _) = roots[j];
        let wedge = &wedges[j];
        let end = plane.below(apex).max(2.0);
        let (ds, de) = (plane.below(start), plane.below(apex));
        let axis_at = |d: f64| {
            let t = ((d - ds) / (de - ds).max(1e-6)).clamp(0.0, 1.0) as f32;
            plane.coords(start + (apex - start) * t)
        };
        let dirs: Vec<DVec2> = pts.iter().map(|p| (*p - q0).normalize()).collect();
        let own: Vec<f64> = pts.iter().map(|p| p.distance(q0)).collect();
        let world_dirs: Vec<Vec3> = dirs.iter().map(|d| plane.dir(*d)).collect();
        let mut q = q0;
        let mut rings = Vec::with_capacity(BRANCH_RINGS);
        for k in 1..=BRANCH_RINGS {
            let t = k as f64 / (BRANCH_RINGS + 1) as f64;
            let d = end * t;
            let blend = smooth(t / 0.4);
            let next = q0 * (1.0 - blend) + axis_at(d) * blend;
            if wedge.contains(next) {
                q = next;
            }
            let reaches: Vec<f64> = dirs
                .iter()
                .map(|e| wedge.reach(q, *e) - BRANCH_CLEARANCE_MM)
                .collect();
            if reaches.iter().any(|&r| r <= 0.02) {
                return false;
            }
            let looks: Vec<f32> = reaches.iter().map(|&r| r.min(20.0) as f32).collect();
            let template_r = super::template::section_from(
                template,
                fit,
                plane.at(q, d),
                &world_dirs,
                &looks,
                0.2,
            );
            let shrink = (1.0 - t).powf(0.7);
            rings.push(
                (0..dirs.len())
                    .map(|i| {
                        let r = own[i] * shrink * (1.0 - blend) + f64::from(template_r[i]) * blend;
                        plane.at(q + dirs[i] * r.clamp(0.02, reaches[i]), d)
                    })
                    .collect(),
            );
        }
        planned.push((idx, rings, plane.at(q, end)));
    }
    let corner = mesh.vertices.len() as u32;
    mesh.vertices.push(plane.at(centre, 0.0));
    for (idx, rings, tip) in planned {
        let mut prev: Vec<u32> = idx
            .iter()
            .map(|&k| if k == usize::MAX { corner } else { ring[k] })
            .collect();
        for r in rings {
            let base = mesh.vertices.len() as u32;
            mesh.vertices.extend(r.iter().copied());
            let next: Vec<u32> = (0..r.len() as u32).map(|i| base + i).collect();
            join(mesh, &prev, &next);
            prev = next;
        }
        let apex = mesh.vertices.len() as u32;
        mesh.vertices.push(tip);
        for i in 0..prev.len() {
            let (p, r) = (prev[i], prev[(i + 1) % prev.len()]);
            mesh.triangles.push([r, p, apex]);
        }
    }
    true
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
