//! A generated root for a scanned crown, built so that it meets neither the crown nor itself.
//!
//! Intraoral scans see crowns only: the segmented mesh is open along the gum line. Roots matter
//! for collisions (and for where a tooth tips), so the opening (the cervical margin) is closed by a
//! stand-in root of the anatomy table's length, documented as such in the import report.
//!
//! Construction. Let `a` be the margin's apical direction (its Newell normal, turned away from the
//! crown, then leaning [`LEAN_RAD`] aside) and `h0` a plane across `a` just beyond every vertex of
//! the crown ([`GAPS_MM`] beyond the deepest one):
//!
//! - **Collar.** Each margin vertex is joined to where the ray from it to the *focus* (a point on
//!   the axis one root length beyond the crown's deepest vertex) meets that plane; the strips
//!   between neighbouring rays are planar quads through the focus. When the margin seen from the
//!   focus (its central projection `Q`) is a simple polygon (no two edges closer than
//!   [`MIN_SEPARATION_MM`]), the strips meet only along shared edges, because their cross-section
//!   at every depth is a part of a scaled copy of `Q`. A jagged margin on a steep wall folds over
//!   itself in projection; the import first trims the crown's triangles at the folds ([`tangles`]
//!   says where; `close` does the trimming). Folds that remain are smoothed out of `Q` locally
//!   (only the vertices at a fold move, towards their neighbours), or, failing that, `Q` becomes a
//!   star-shaped polygon with one vertex per margin vertex (strictly increasing angles about the
//!   margin's centre, radii averaged over [`SMOOTH`] neighbours), simple by construction, and
//!   smoothed further ([`STAR_SMOOTHING`]) until it is simple with room to spare. Where `Q`
//!   was moved the strips lean a little, and the exact check after closing verifies them.
//! - **Body.** Rings below the plane are copies of `Q` scaled about one point by `(1 − t)^0.7`
//!   at depths growing linearly towards the apex, closed by a cone to the apex. Two consecutive
//!   rings are related by a homothety, so each band between them is a frustum of a cone: its quads
//!   are planar and its cross-section at every depth is a scaled copy of `Q`, which is simple; the
//!   cone's cross-sections are scaled copies too. So the body meets itself only along shared
//!   edges, whatever the margin's shape, and it lies beyond the plane `h0`, where no crown vertex
//!   is.
//!
//! The exact self-intersection check of the whole tooth still runs after closing
//! ([`crate::geometry::TriMesh::validate_solid`]); the import tries the next gap of [`GAPS_MM`]
//! when a strip meets the crown, then cuts out the crown's triangles that it meets (see
//! `close`).

use glam::{DVec2, DVec3, Vec3};

use super::{error::ImportError, repair::loop_centroid};
use crate::geometry::TriMesh;

/// Rings of the body: at `t = k / RING_STEPS` for `k < RINGS`, the last at `(1 − t)^0.7 ≈ 0.53`
/// of the margin's size; a cone closes the body from it to the apex. (Rings are not shrunk further:
/// a jagged margin scaled much smaller would bring its edges closer than single precision can
/// keep apart, while the cone's triangles all share the apex.)
pub const RINGS: usize = 7;
/// Steps from the collar to the apex that the rings are placed on.
pub const RING_STEPS: usize = 10;
/// Distances (mm) tried between the crown's deepest vertex and the collar's plane.
pub const GAPS_MM: [f32; 3] = [0.3, 1.0, 2.5];
/// Least distance (mm) between non-adjacent edges of the projected margin for the collar to be
/// vertical strips.
pub const MIN_SEPARATION_MM: f64 = 2e-3;
/// The root leans this much (radians, about 3°) off the margin's normal. Its collar is then never
/// parallel to the tooth's long axis (the principal axis of the closed tooth, which for a
/// symmetric crown is the margin's normal to the last digit): the medial sphere-tree builder's
/// lattice lines run along that axis and lose the inside of surfaces exactly parallel to them.
pub const LEAN_RAD: f64 = 0.05;
/// Rounds of local smoothing that may make a tangled projected margin simple.
pub const UNTANGLE_ROUNDS: usize = 40;
/// Half-width (vertices) of the window over which a star-shaped collar's radii are averaged.
pub const SMOOTH: usize = 3;

/// Unit normal of a closed polygon (Newell's method), or None when it has no area.
fn polygon_normal(points: &[Vec3]) -> Option<DVec3> {
    let mut n = DVec3::ZERO;
    for i in 0..points.len() {
        let a = points[i].as_dvec3();
        let b = points[(i + 1) % points.len()].as_dvec3();
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    (n.length() > 1e-12).then(|| n.normalize())
}

/// Area-weighted centroid of a surface.
fn surface_centroid(mesh: &TriMesh) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let mut total = 0.0;
    for i in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle(i).map(|v| v.as_dvec3());
        let w = 0.5 * (b - a).cross(c - a).length();
        sum += (a + b + c) / 3.0 * w;
        total += w;
    }
    if total > 0.0 {
        sum / total
    } else {
        DVec3::ZERO
    }
}

/// The margin's centre and apical direction: where the root starts and which way it grows.
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn margin_axis(mesh: &TriMesh, l: &[u32]) -> Result<(Vec3, Vec3), ImportError> {
    let points: Vec<Vec3> = l.iter().map(|&i| mesh.vertices[i as usize]).collect();
    let centre = loop_centroid(mesh, l).as_dvec3();
    let crown = surface_centroid(mesh);
    let mut apical = polygon_normal(&points).ok_or(ImportError::FlatMargin)?;
    if apical.dot(centre - crown) < 0.0 {
        apical = -apical;
    }
    Ok((centre.as_vec3(), apical.as_vec3()))
}

/// Closes the margin `l` (in its edges' direction) of `mesh` with a root reaching `root_length`
/// mm beyond the margin's centre, its collar `gap` mm beyond the crown's deepest vertex. Returns
/// the margin's centroid (the cervical centre) and the unit apical direction.
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn close_with_root(
    mesh: &mut TriMesh,
    l: &[u32],
    root_length: f32,
    gap: f32,
) -> Result<(Vec3, Vec3), ImportError> {
    let (centre, apical) = margin_axis(mesh, l)?;
    close_with_root_along(mesh, l, root_length, gap, centre, apical);
    Ok((centre, apical))
}

/// [`close_with_root`] along a given unit `apical` direction from the margin's `centre` (for a
/// margin whose own normal is not to be trusted, such as one the labels bled into).
pub fn close_with_root_along(
    mesh: &mut TriMesh,
    l: &[u32],
    root_length: f32,
    gap: f32,
    centre: Vec3,
    apical: Vec3,
) {
    let Collar {
        focus: f,
        h0,
        apex_depth,
        ring: ring0,
    } = Collar::new(mesh, l, centre, apical, root_length, gap);
    let (c, a, u, w) = (f.c, f.a, f.u, f.w);
    let pivot = area_centroid(&ring0);
    let place = |q: DVec2, depth: f64| (c + a * depth + u * q.x + w * q.y).as_vec3();
    let mut prev: Vec<u32> = l.to_vec();
    for k in 0..RINGS {
        let t = k as f64 / RING_STEPS as f64;
        let scale = (1.0 - t).powf(0.7);
        let depth = h0 + (apex_depth - h0) * t;
        let base = mesh.vertices.len() as u32;
        for &q in &ring0 {
            mesh.vertices
                .push(place(pivot + (q - pivot) * scale, depth));
        }
        let ring: Vec<u32> = (0..ring0.len() as u32).map(|i| base + i).collect();
        join(mesh, &prev, &ring);
        prev = ring;
    }
    let apex = mesh.vertices.len() as u32;
    mesh.vertices.push(place(pivot, apex_depth));
    for i in 0..prev.len() {
        let (p, q) = (prev[i], prev[(i + 1) % prev.len()]);
        mesh.triangles.push([q, p, apex]);
    }
}

/// The collar of a root along `apical` from `centre`: its strips run from each margin vertex
/// towards the focus, to the plane `gap` mm beyond the crown's deepest vertex, where they end on
/// the margin's outline seen from the focus (made simple).
pub(super) struct Collar {
    pub(super) focus: Focus,
    /// Depth of the collar's plane.
    pub(super) h0: f64,
    /// Depth of the apex: the root length, and at least 30 % of it beyond the collar.
    pub(super) apex_depth: f64,
    /// The outline in the collar's plane (in-plane coordinates), one vertex per margin vertex.
    pub(super) ring: Vec<DVec2>,
}

impl Collar {
    pub(super) fn new(
        mesh: &TriMesh,
        l: &[u32],
        centre: Vec3,
        apical: Vec3,
        root_length: f32,
        gap: f32,
    ) -> Self {
        let focus = Focus::new(mesh, centre, apical, root_length);
        let h0 = focus.deepest + f64::from(gap);
        let apex_depth = f64::from(root_length).max(h0 + 0.3 * f64::from(root_length));
        let projected = focus.project(mesh, l);
        let outline = untangle(&projected, MIN_SEPARATION_MM)
            .unwrap_or_else(|| star(&projected, MIN_SEPARATION_MM));
        let to_h0 = (focus.depth - h0) / (focus.depth - focus.deepest);
        let ring = outline.iter().map(|&q| q * to_h0).collect();
        Self {
            focus,
            h0,
            apex_depth,
            ring,
        }
    }
}

/// Where the collar's strips converge: a point on the root's axis one root length beyond the
/// crown's deepest vertex, and the frame the margin is projected in.
pub(super) struct Focus {
    pub(super) c: DVec3,
    pub(super) a: DVec3,
    pub(super) u: DVec3,
    pub(super) w: DVec3,
    /// Depth (along `a`, from `c`) of the crown's deepest vertex.
    pub(super) deepest: f64,
    /// Depth of the focus.
    pub(super) depth: f64,
}

impl Focus {
    pub(super) fn new(mesh: &TriMesh, centre: Vec3, apical: Vec3, root_length: f32) -> Self {
        let (c, a) = (centre.as_dvec3(), leaning(apical));
        let u = a.any_orthonormal_vector();
        let w = a.cross(u);
        let deepest = mesh
            .vertices
            .iter()
            .map(|v| (v.as_dvec3() - c).dot(a))
            .fold(f64::NEG_INFINITY, f64::max);
        let depth = deepest + f64::from(root_length).max(GAPS_MM[GAPS_MM.len() - 1] as f64 + 1.0);
        Self {
            c,
            a,
            u,
            w,
            deepest,
            depth,
        }
    }

    /// The margin's vertices projected from the focus onto the plane through the crown's deepest
    /// vertex, in the coordinates of `u` and `w`.
    pub(super) fn project(&self, mesh: &TriMesh, l: &[u32]) -> Vec<DVec2> {
        l.iter()
            .map(|&i| {
                let d = mesh.vertices[i as usize].as_dvec3() - self.c;
                let scale = (self.depth - self.deepest) / (self.depth - d.dot(self.a));
                DVec2::new(d.dot(self.u), d.dot(self.w)) * scale
            })
            .collect()
    }
}

/// Positions in `l` of the margin vertices where the margin, seen from the root's focus, folds,
/// crosses or nearly touches itself (empty when the collar's strips can all point at the focus).
///
/// # Errors
/// [`ImportError::FlatMargin`] when the margin encloses no area.
pub fn tangles(mesh: &TriMesh, l: &[u32], root_length: f32) -> Result<Vec<usize>, ImportError> {
    let (centre, apical) = margin_axis(mesh, l)?;
    let f = Focus::new(mesh, centre, apical, root_length);
    Ok(offending(&f.project(mesh, l), MIN_SEPARATION_MM))
}

/// [`tangles`] for a root along a given unit `apical` direction from `centre` (a template's).
pub fn tangles_along(
    mesh: &TriMesh,
    l: &[u32],
    centre: Vec3,
    apical: Vec3,
    root_length: f32,
) -> Vec<usize> {
    let f = Focus::new(mesh, centre, apical, root_length);
    offending(&f.project(mesh, l), MIN_SEPARATION_MM)
}

/// The direction the root is built along: the apical direction turned by [`LEAN_RAD`].
fn leaning(apical: Vec3) -> DVec3 {
    let a = apical.as_dvec3();
    (a + a.any_orthonormal_vector() * LEAN_RAD.tan()).normalize()
}

/// Quads between two rings of equal size: `upper` runs in its triangles' edge direction, so the
/// new triangles run each of its edges the other way.
pub(super) fn join(mesh: &mut TriMesh, upper: &[u32], lower: &[u32]) {
    let n = upper.len();
    for i in 0..n {
        let j = (i + 1) % n;
        mesh.triangles.push([upper[j], upper[i], lower[i]]);
        mesh.triangles.push([upper[j], lower[i], lower[j]]);
    }
}

/// Centroid of a polygon's area (its vertices' mean when it has none).
pub(super) fn area_centroid(p: &[DVec2]) -> DVec2 {
    let mut sum = DVec2::ZERO;
    let mut area = 0.0;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let cross = a.perp_dot(b);
        area += cross;
        sum += (a + b) * cross;
    }
    if area.abs() > 1e-12 {
        sum / (3.0 * area)
    } else {
        p.iter().copied().sum::<DVec2>() / p.len().max(1) as f64
    }
}

/// Distance between segments `ab` and `cd` in the plane (zero when they cross).
fn segment_distance(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (o1, o2, o3, o4) = (
        orient(a, b, c),
        orient(a, b, d),
        orient(c, d, a),
        orient(c, d, b),
    );
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return 0.0;
    }
    let to_segment = |p: DVec2, s: DVec2, e: DVec2| {
        let se = e - s;
        let t = if se.length_squared() > 0.0 {
            ((p - s).dot(se) / se.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        p.distance(s + se * t)
    };
    to_segment(a, c, d)
        .min(to_segment(b, c, d))
        .min(to_segment(c, a, b))
        .min(to_segment(d, a, b))
}

/// True when the closed polygon `p` is simple with room to spare: every edge at least `eps` long,
/// non-adjacent edges at least `eps` apart, and no edge folding back onto the next.
#[cfg(test)]
fn is_simple(p: &[DVec2], eps: f64) -> bool {
    p.len() >= 3 && offending(p, eps).is_empty()
}

/// The vertices of `p` at which it is not simple with room to spare (see [`is_simple`]): both
/// ends of a short edge, the middle vertex of a fold, the ends of edges that come too close.
pub(super) fn offending(p: &[DVec2], eps: f64) -> Vec<usize> {
    let n = p.len();
    let mut bad = vec![false; n];
    let edge = |i: usize| (p[i], p[(i + 1) % n]);
    for i in 0..n {
        let (a, b) = edge(i);
        if a.distance(b) < eps {
            bad[i] = true;
            bad[(i + 1) % n] = true;
        }
        // Adjacent edges fold back when the next one's far end comes back near this edge.
        let c = p[(i + 2) % n];
        if segment_distance(a, a, b, c).min(segment_distance(c, c, a, b)) < eps {
            bad[(i + 1) % n] = true;
        }
    }
    // Boxes first: most pairs are far apart.
    let boxes: Vec<(DVec2, DVec2)> = (0..n)
        .map(|i| {
            let (a, b) = edge(i);
            (a.min(b) - eps, a.max(b) + eps)
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by(|&i, &j| boxes[i].0.x.total_cmp(&boxes[j].0.x));
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if boxes[j].0.x > boxes[i].1.x {
                break;
            }
            if (i + 1) % n == j || (j + 1) % n == i {
                continue;
            }
            let (lo1, hi1) = boxes[i];
            let (lo2, hi2) = boxes[j];
            if lo1.y > hi2.y || lo2.y > hi1.y {
                continue;
            }
            let (a, b) = edge(i);
            let (c, d) = edge(j);
            if segment_distance(a, b, c, d) < eps {
                for v in [i, (i + 1) % n, j, (j + 1) % n] {
                    bad[v] = true;
                }
            }
        }
    }
    (0..n).filter(|&i| bad[i]).collect()
}

/// Makes `p` simple by moving only the vertices where it is not: each towards the midpoint of
/// its neighbours (a local smoothing), for up to [`UNTANGLE_ROUNDS`] rounds. None when that does
/// not suffice.
pub(super) fn untangle(p: &[DVec2], eps: f64) -> Option<Vec<DVec2>> {
    let n = p.len();
    let mut q = p.to_vec();
    for _ in 0..UNTANGLE_ROUNDS {
        let bad = offending(&q, eps);
        if bad.is_empty() {
            return Some(q);
        }
        let before = q.clone();
        for &i in &bad {
            // The vertex and its two neighbours move, so a fold opens from both sides.
            for k in [n - 1, 0, 1] {
                let v = (i + k) % n;
                let mid = (before[(v + n - 1) % n] + before[(v + 1) % n]) * 0.5;
                q[v] = before[v] * 0.3 + mid * 0.7;
            }
        }
    }
    offending(&q, eps).is_empty().then_some(q)
}

/// A star-shaped polygon with one vertex per vertex of `p`, simple with room to spare at `eps`
/// (no vertex [`offending`]) unless even a circle is not: the first of [`STAR_SMOOTHING`]'s
/// smoothings ([`star_with`]) that is.
///
/// Strictly increasing angles alone make a simple polygon, but not one with room: where a jagged
/// outline's backward steps were flattened, neighbouring vertices lie almost on one ray, and
/// their radii, out and back in, fold the outline onto itself by less than a vertex's single
/// precision can hold apart once the root's rings are stored. So the steps keep a share of the
/// mean step, and when that is not enough, the angles are evened out and the radii averaged
/// over wider windows, the last time over the whole outline (a circle).
pub(super) fn star(p: &[DVec2], eps: f64) -> Vec<DVec2> {
    let mut outline = Vec::new();
    for &(share, half) in &STAR_SMOOTHING {
        outline = star_with(p, share, half);
        if offending(&outline, eps).is_empty() {
            break;
        }
    }
    outline
}

/// Smoothings of `star`, tried in turn: the least share of the mean angle step that each step
/// keeps, and the half-width (vertices) of the window each radius is averaged over (capped at
/// half the outline).
pub const STAR_SMOOTHING: [(f64, usize); 4] = [
    (0.25, SMOOTH),
    (0.5, 4 * SMOOTH),
    (1.0, 12 * SMOOTH),
    (1.0, usize::MAX),
];

/// A star-shaped polygon with one vertex per vertex of `p`: angles about `p`'s centre made
/// strictly increasing (the backward steps of a jagged outline flattened out, each step at least
/// `share` of the mean one), radii averaged over `half` neighbours each side. Simple by
/// construction.
pub(super) fn star_with(p: &[DVec2], share: f64, half: usize) -> Vec<DVec2> {
    let n = p.len();
    let half = half.min(n.saturating_sub(1) / 2);
    let centre = area_centroid(p);
    let theta: Vec<f64> = p.iter().map(|q| (*q - centre).to_angle()).collect();
    let wrap = |x: f64| {
        let t = std::f64::consts::TAU;
        (x + std::f64::consts::PI).rem_euclid(t) - std::f64::consts::PI
    };
    let steps: Vec<f64> = (0..n)
        .map(|i| wrap(theta[(i + 1) % n] - theta[i]))
        .collect();
    let total: f64 = steps.iter().sum();
    let radius = |i: usize| {
        let mut s = 0.0;
        for k in 0..=2 * half {
            s += (p[(i + n + k - half) % n] - centre).length();
        }
        (s / (2 * half + 1) as f64).max(0.05)
    };
    // Each step at least the share of the mean one and above zero.
    let floored = |forward: Vec<f64>| -> Vec<f64> {
        let least = (share * forward.iter().sum::<f64>() / n as f64).max(1e-9);
        forward.into_iter().map(|s| s.max(least)).collect()
    };
    let (sign, forward): (f64, Vec<f64>) = if total.abs() > std::f64::consts::PI {
        // The centre is inside: keep each forward step, flatten the backward ones.
        let sign = total.signum();
        (
            sign,
            floored(steps.iter().map(|s| (s * sign).max(0.0)).collect()),
        )
    } else {
        // The centre is outside the outline: spread the angles by arc length instead.
        let sign = if (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() >= 0.0 {
            1.0
        } else {
            -1.0
        };
        (
            sign,
            floored((0..n).map(|i| p[i].distance(p[(i + 1) % n])).collect()),
        )
    };
    let scale = std::f64::consts::TAU / forward.iter().sum::<f64>();
    let mut angle = theta[0];
    (0..n)
        .map(|i| {
            let q = centre + DVec2::from_angle(angle) * radius(i);
            angle += sign * forward[i] * scale;
            q
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_polygons_are_told_from_crossing_and_folding_ones() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(is_simple(&square, 1e-3));
        let bowtie = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(!is_simple(&bowtie, 1e-3));
        // A back-step along the same line: the edge folds onto the one before.
        let fold = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.5, 0.0),
            DVec2::new(0.5, 1.0),
        ];
        assert!(!is_simple(&fold, 1e-3));
        // A repeated point.
        let repeated = [square[0], square[1], square[1], square[2], square[3]];
        assert!(!is_simple(&repeated, 1e-3));
    }

    #[test]
    fn the_star_polygon_of_a_jagged_outline_is_simple() {
        // A circle whose points step back in angle every third vertex.
        let n = 90;
        let jagged: Vec<DVec2> = (0..n)
            .map(|i| {
                let back = if i % 3 == 2 { -2.5 } else { 0.0 };
                let t = (i as f64 + back) / n as f64 * std::f64::consts::TAU;
                DVec2::from_angle(t) * (4.0 + 0.3 * (i % 2) as f64)
            })
            .collect();
        assert!(!is_simple(&jagged, 1e-3));
        let s = star(&jagged, 1e-3);
        assert_eq!(s.len(), n);
        assert!(is_simple(&s, 1e-3));
        // The outline keeps its size.
        let r = s.iter().map(|q| q.length()).fold(0.0, f64::max);
        assert!((3.5..4.6).contains(&r), "{r}");
    }
}
