//! Exact closest-point and intersection queries between points, segments and triangles
//! (after Ericson, *Real-Time Collision Detection*, 5.1.5, 5.1.9 and 4.4 / 5.2).
//!
//! Guarantees: the closest-point functions are exact up to floating-point rounding (computed in
//! f64, returned in f32: about 1e-7 of the coordinates' magnitude), sliver triangles included. [`triangles_intersect`] is a separating-axis test
//! that treats touching triangles as intersecting.

use glam::{DVec3, Vec3};

/// The closest point to `p` on the triangle `a b c` (Ericson 5.1.5, Voronoi regions), computed in
/// f64 so that sliver triangles stay accurate.
pub fn closest_point_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let [p, a, b, c] = [p, a, b, c].map(|v| v.as_dvec3());
    closest_point_triangle_f64(p, a, b, c).as_vec3()
}

fn closest_point_triangle_f64(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let sum = va + vb + vc;
    // sum = |ab × ac|²: a needle (sine below 10⁻⁶) or a point has no reliable face region.
    if sum.abs() <= 1e-12 * ab.length_squared() * ac.length_squared()
        || sum.abs() <= f64::MIN_POSITIVE
    {
        // A degenerate triangle: the nearest of its edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(s, e)| closest_point_segment_f64(p, s, e))
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    let v = vb / sum;
    let w = vc / sum;
    a + ab * v + ac * w
}

fn closest_point_segment_f64(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 <= f64::MIN_POSITIVE {
        return a;
    }
    a + d * ((p - a).dot(d) / len2).clamp(0.0, 1.0)
}

/// Closest points between segments `p1 q1` and `p2 q2` (Ericson 5.1.9), degenerate segments
/// included, computed in f64. Returns the two points.
pub fn closest_points_segment_segment(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> (Vec3, Vec3) {
    let [p1, q1, p2, q2] = [p1, q1, p2, q2].map(|v| v.as_dvec3());
    let (a, b) = segment_points_f64(p1, q1, p2, q2);
    (a.as_vec3(), b.as_vec3())
}

/// Closest points between two triangles and their distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrianglePair {
    /// Distance between the triangles (0 when they touch or intersect).
    pub distance: f32,
    /// Closest point on the first triangle.
    pub on_first: Vec3,
    /// Closest point on the second triangle.
    pub on_second: Vec3,
}

/// Separating-axis test for two triangles in 3D; touching counts as intersecting. Exact up to
/// f64 rounding of the f32 corners' differences (about 1e-16 of the triangles' size); the axes are the two face normals, the nine edge–edge cross products and, for
/// (nearly) coplanar triangles, the in-plane edge normals.
pub fn triangles_intersect(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> bool {
    triangles_within(t1, t2, 0.0)
}

/// [`triangles_intersect`] widened by `margin` (mm): false only when one of the same axes
/// separates the triangles by more than the margin, so every pair within the margin of each other
/// (and some pairs farther apart) gives true.
pub fn triangles_within(t1: &[Vec3; 3], t2: &[Vec3; 3], margin: f32) -> bool {
    // In f64 about the first triangle's first corner: there the differences of f32 coordinates
    // are exact and every projection keeps about 1e-16 of its size, so sliver triangles lying a
    // micrometre apart and nearly coplanar (a fine mesh's neighbouring strips) are told apart,
    // which f32 projections of coordinates tens of millimetres large are not.
    let o = t1[0].as_dvec3();
    let (t1, t2) = (t1.map(|v| v.as_dvec3() - o), t2.map(|v| v.as_dvec3() - o));
    let margin = f64::from(margin);
    let separated = |axis: DVec3| -> bool {
        let len2 = axis.length_squared();
        if len2 <= f64::MIN_POSITIVE {
            return false;
        }
        let pad = if margin > 0.0 {
            margin * len2.sqrt()
        } else {
            0.0
        };
        let (mut min1, mut max1) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut min2, mut max2) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..3 {
            let a = axis.dot(t1[k]);
            let b = axis.dot(t2[k]);
            min1 = min1.min(a);
            max1 = max1.max(a);
            min2 = min2.min(b);
            max2 = max2.max(b);
        }
        max1 + pad < min2 || max2 + pad < min1
    };
    let e1 = [t1[1] - t1[0], t1[2] - t1[1], t1[0] - t1[2]];
    let e2 = [t2[1] - t2[0], t2[2] - t2[1], t2[0] - t2[2]];
    let n1 = e1[0].cross(e1[1]);
    let n2 = e2[0].cross(e2[1]);
    if separated(n1) || separated(n2) {
        return false;
    }
    let coplanar =
        n1.cross(n2).length_squared() <= 1e-10 * n1.length_squared() * n2.length_squared();
    if coplanar {
        for e in e1 {
            if separated(n1.cross(e)) {
                return false;
            }
        }
        for e in e2 {
            if separated(n2.cross(e)) {
                return false;
            }
        }
        return true;
    }
    for a in e1 {
        for b in e2 {
            if separated(a.cross(b)) {
                return false;
            }
        }
    }
    true
}

/// Where segment `p q` crosses triangle `t`, if it does (Möller–Trumbore on the segment).
pub fn segment_triangle_crossing(p: Vec3, q: Vec3, t: &[Vec3; 3]) -> Option<Vec3> {
    let d = q - p;
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() <= 1e-12 * e1.length() * e2.length() * d.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = p - t[0];
    let u = inv * s.dot(h);
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = s.cross(e1);
    let v = inv * d.dot(qv);
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let tt = inv * e2.dot(qv);
    (0.0..=1.0).contains(&tt).then(|| p + d * tt)
}

/// Exact closest points between two triangles. When the triangles intersect the distance is 0
/// and both points are a point where an edge of one crosses the other.
///
/// For disjoint triangles the minimum is reached between two edges or between a vertex and the
/// other's face (Ericson 5.1.9). The nine edge pairs come first, in f64: an edge pair whose closest
/// points P, Q leave each triangle's third vertex on its own side of the slab between the planes
/// through P and Q normal to Q − P is the answer at once (the slab separates the triangles; Larsen
/// and Gottschalk's test in PQP). Otherwise a vertex of one triangle is the answer when the whole
/// triangle lies on one side of the other's plane and that nearest vertex projects into the other
/// face (no point of the triangle is nearer the plane); otherwise, if some axis showed the
/// triangles apart, the best edge pair is. Triangles not shown apart touch or intersect and take
/// the exhaustive path (every vertex–face and edge–edge pair, and a crossing point).
pub fn closest_points_triangle_triangle(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> TrianglePair {
    closest_points(t1, t2, false)
}

/// [`closest_points_triangle_triangle`] with the vertex over the other face tried before the
/// edge pairs: the same answer, sooner for triangles known to face each other (one wholly beyond
/// the other's plane, where the vertex is usually the answer), later for others.
pub fn closest_points_facing_triangles(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> TrianglePair {
    closest_points(t1, t2, true)
}

#[inline(always)]
fn closest_points(t1: &[Vec3; 3], t2: &[Vec3; 3], vertex_first: bool) -> TrianglePair {
    let s = t1.map(|v| v.as_dvec3());
    let t = t2.map(|v| v.as_dvec3());
    let pair = |d2: f64, p: DVec3, q: DVec3| TrianglePair {
        distance: d2.sqrt() as f32,
        on_first: p.as_vec3(),
        on_second: q.as_vec3(),
    };
    let mut shown_apart = false;
    let vertex_over_faces = |shown_apart: &mut bool| {
        for (first, other, swapped) in [(&s, &t, false), (&t, &s, true)] {
            if let Some((point, on_face)) = vertex_over_face(first, other, shown_apart) {
                let (p, q) = if swapped {
                    (point, on_face)
                } else {
                    (on_face, point)
                };
                return Some(pair(p.distance_squared(q), p, q));
            }
        }
        None
    };
    if vertex_first && let Some(answer) = vertex_over_faces(&mut shown_apart) {
        return answer;
    }
    let mut best = (f64::INFINITY, s[0], t[0]);
    for i in 0..3 {
        for j in 0..3 {
            let (p, q) = segment_points_f64(s[i], s[(i + 1) % 3], t[j], t[(j + 1) % 3]);
            let v = q - p;
            let dd = v.length_squared();
            if dd <= best.0 {
                best = (dd, p, q);
                let a = (s[(i + 2) % 3] - p).dot(v);
                let b = (t[(j + 2) % 3] - q).dot(v);
                if a <= 0.0 && b >= 0.0 {
                    return pair(dd, p, q);
                }
                // Extent of each triangle along v beyond its closest point: apart along v when
                // the gap |v|² exceeds them.
                if dd - a.max(0.0) + b.min(0.0) > 0.0 {
                    shown_apart = true;
                }
            }
        }
    }
    if !vertex_first && let Some(answer) = vertex_over_faces(&mut shown_apart) {
        return answer;
    }
    if shown_apart {
        return pair(best.0, best.1, best.2);
    }
    exhaustive(t1, t2)
}

/// When `other` lies wholly on one side of `face`'s plane: its vertex nearest the plane, if that
/// vertex projects into the face, with the projection. Sets `shown_apart` when the plane
/// separates them.
#[inline]
fn vertex_over_face(
    face: &[DVec3; 3],
    other: &[DVec3; 3],
    shown_apart: &mut bool,
) -> Option<(DVec3, DVec3)> {
    let e = [face[1] - face[0], face[2] - face[1], face[0] - face[2]];
    let n = e[0].cross(e[1]);
    let nl = n.length_squared();
    // Needles (sine below 10⁻⁶): their normal is not trusted; their edges carry the answer.
    if nl <= 1e-12 * e[0].length_squared() * e[1].length_squared() || nl == 0.0 {
        return None;
    }
    let h = other.map(|v| (face[0] - v).dot(n));
    let k = if h.iter().all(|&x| x > 0.0) {
        (0..3).min_by(|&x, &y| h[x].total_cmp(&h[y]))?
    } else if h.iter().all(|&x| x < 0.0) {
        (0..3).max_by(|&x, &y| h[x].total_cmp(&h[y]))?
    } else {
        return None;
    };
    *shown_apart = true;
    let v = other[k];
    let inside = (0..3).all(|m| (v - face[m]).dot(n.cross(e[m])) > 0.0);
    inside.then(|| (v, v + n * (h[k] / nl)))
}

/// Closest points of segments `p1 q1` and `p2 q2` in f64 (Ericson 5.1.9), degenerate segments
/// included.
#[inline(always)]
fn segment_points_f64(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> (DVec3, DVec3) {
    const EPS: f64 = 1e-18;
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    if a <= EPS && e <= EPS {
        return (p1, p2);
    }
    let (s, t);
    if a <= EPS {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 1e-12 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

/// Every vertex–face and edge–edge pair, for triangles that touch or intersect (and as the
/// reference in tests).
fn exhaustive(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> TrianglePair {
    let intersecting = triangles_intersect(t1, t2);
    if intersecting {
        let crossing = (0..3)
            .find_map(|k| segment_triangle_crossing(t1[k], t1[(k + 1) % 3], t2))
            .or_else(|| (0..3).find_map(|k| segment_triangle_crossing(t2[k], t2[(k + 1) % 3], t1)));
        if let Some(p) = crossing {
            return TrianglePair {
                distance: 0.0,
                on_first: p,
                on_second: p,
            };
        }
        // Touching or coplanar overlap without a clean crossing: fall through to the closest
        // features, whose distance is (up to rounding) zero.
    }
    let mut best = TrianglePair {
        distance: f32::INFINITY,
        on_first: t1[0],
        on_second: t2[0],
    };
    let mut consider = |a: Vec3, b: Vec3| {
        let d = a.distance(b);
        if d < best.distance {
            best = TrianglePair {
                distance: d,
                on_first: a,
                on_second: b,
            };
        }
    };
    for k in 0..3 {
        consider(t1[k], closest_point_triangle(t1[k], t2[0], t2[1], t2[2]));
        consider(closest_point_triangle(t2[k], t1[0], t1[1], t1[2]), t2[k]);
    }
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) =
                closest_points_segment_segment(t1[i], t1[(i + 1) % 3], t2[j], t2[(j + 1) % 3]);
            consider(a, b);
        }
    }
    if intersecting {
        best.distance = 0.0;
    }
    best
}

/// A triangle's plane in f64: unit normal and offset (n · p = offset on the plane). Needles (sine
/// of the angle below 10⁻⁶), whose normal is not trusted, get a zero normal and bound nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FacePlane {
    /// Unit normal (zero for a needle).
    pub normal: DVec3,
    /// n · (first vertex).
    pub offset: f64,
}

impl FacePlane {
    /// The plane of `t`.
    #[inline]
    pub fn of(t: &[Vec3; 3]) -> Self {
        let p = t[0].as_dvec3();
        let (e1, e2) = (t[1].as_dvec3() - p, t[2].as_dvec3() - p);
        let n = e1.cross(e2);
        let len2 = n.length_squared();
        let normal = if len2 > 1e-12 * e1.length_squared() * e2.length_squared() && len2 > 0.0 {
            n / len2.sqrt()
        } else {
            DVec3::ZERO
        };
        Self {
            normal,
            offset: normal.dot(p),
        }
    }

    /// How far all of `o` lies beyond the plane, on either side (0 if it straddles the plane).
    #[inline]
    pub fn beyond(&self, o: &[Vec3; 3]) -> f64 {
        let s = o.map(|p| self.normal.dot(p.as_dvec3()) - self.offset);
        if s[0] > 0.0 && s[1] > 0.0 && s[2] > 0.0 {
            s[0].min(s[1]).min(s[2])
        } else if s[0] < 0.0 && s[1] < 0.0 && s[2] < 0.0 {
            -(s[0].max(s[1]).max(s[2]))
        } else {
            0.0
        }
    }
}

/// A lower bound of the distance between two triangles: how far one lies beyond the other's
/// plane (0 when neither lies wholly on one side, or a triangle is a needle). Computed in f64 and
/// rounded down, so never above the exact distance.
#[inline]
pub fn triangle_plane_gap(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> f32 {
    plane_gap(t1, &FacePlane::of(t1), t2, &FacePlane::of(t2))
}

/// [`triangle_plane_gap`] with the planes given (for callers that measure a triangle against
/// many others). The unit normal's direction is within 10⁻¹⁰ (sine ≥ 10⁻⁶, f64) and each signed
/// distance within a few ulps of the coordinates: the bound is shrunk by 10⁻⁸ of the triangles'
/// spread and 10⁻¹⁴ of their distance from the origin, far more than both.
#[inline]
pub fn plane_gap(t1: &[Vec3; 3], p1: &FacePlane, t2: &[Vec3; 3], p2: &FacePlane) -> f32 {
    let m = p1.beyond(t2).max(p2.beyond(t1));
    if m <= 0.0 {
        return 0.0;
    }
    let (mut near, mut far) = (0.0f32, 0.0f32);
    for v in t1.iter().chain(t2) {
        near = near.max((*v - t1[0]).abs().max_element());
        far = far.max(v.abs().max_element());
    }
    let margin = 1e-8 * near as f64 + 1e-14 * far as f64;
    ((m - margin).max(0.0) as f32) * (1.0 - 1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [Vec3; 3] {
        [Vec3::from(a), Vec3::from(b), Vec3::from(c)]
    }

    #[test]
    fn point_triangle_regions() {
        let [a, b, c] = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let inside = closest_point_triangle(Vec3::new(0.2, 0.2, 3.0), a, b, c);
        assert!(
            (inside - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-6,
            "{inside}"
        );
        assert_eq!(
            closest_point_triangle(Vec3::new(-1.0, -1.0, 0.0), a, b, c),
            a
        );
        assert_eq!(
            closest_point_triangle(Vec3::new(2.0, -0.5, 0.0), a, b, c),
            b
        );
        let on_edge = closest_point_triangle(Vec3::new(0.5, -2.0, 1.0), a, b, c);
        assert!(
            (on_edge - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6,
            "{on_edge}"
        );
        let on_hyp = closest_point_triangle(Vec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((on_hyp - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
    }

    #[test]
    fn parallel_and_degenerate_segments() {
        let (a, b) = closest_points_segment_segment(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        );
        assert!((a.distance(b) - 1.0).abs() < 1e-6);
        let (a, b) =
            closest_points_segment_segment(Vec3::ONE, Vec3::ONE, Vec3::ZERO, Vec3::X * 2.0);
        assert_eq!(a, Vec3::ONE);
        assert_eq!(b, Vec3::X);
    }

    #[test]
    fn crossing_triangles_intersect_and_have_zero_distance() {
        let t1 = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let t2 = tri([0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [3.0, 3.0, 0.0]);
        assert!(triangles_intersect(&t1, &t2));
        let r = closest_points_triangle_triangle(&t1, &t2);
        assert_eq!(r.distance, 0.0);
        assert!(r.on_first.z.abs() < 1e-6);
    }

    #[test]
    fn separated_triangles_report_the_gap() {
        let t1 = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let t2 = tri([0.5, 0.5, 0.3], [1.5, 0.5, 0.3], [0.5, 1.0, 2.0]);
        assert!(!triangles_intersect(&t1, &t2));
        let r = closest_points_triangle_triangle(&t1, &t2);
        assert!((r.distance - 0.3).abs() < 1e-6, "{r:?}");
        // Within a margin above the gap they count as near, within one below it they do not.
        assert!(triangles_within(&t1, &t2, 0.31));
        assert!(!triangles_within(&t1, &t2, 0.29));
        // Corner to corner: near within the distance; the axes separate them by at least the
        // planes' 0.5 (and may by less than the distance: the test is a superset).
        let t3 = tri([3.0, -1.0, 0.5], [3.0, 1.0, 0.5], [4.0, 0.0, 0.5]);
        let d = closest_points_triangle_triangle(&t1, &t3).distance;
        assert!(triangles_within(&t1, &t3, d * 1.01));
        assert!(!triangles_within(&t1, &t3, 0.49), "{d}");
    }

    #[test]
    fn plane_gap_is_a_lower_bound_and_tight_for_facing_triangles() {
        let t1 = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        // Parallel, 0.3 above: the bound is the distance.
        let t2 = tri([0.2, 0.2, 0.3], [1.0, 0.2, 0.3], [0.2, 1.0, 0.3]);
        let g = triangle_plane_gap(&t1, &t2);
        assert!(g <= 0.3 && g > 0.2999, "{g}");
        // Straddling the plane: no bound.
        let t3 = tri([5.0, 0.0, -1.0], [5.0, 0.0, 1.0], [6.0, 0.0, 0.0]);
        assert_eq!(triangle_plane_gap(&t1, &t3), 0.0);
        // Random pairs: never above the exact distance.
        let mut rnd = crate::geometry::test_numbers(99);
        for _ in 0..5000 {
            let mut v = || Vec3::new(rnd(), rnd(), rnd()) * 4.0;
            let (a, b) = ([v(), v(), v()], [v(), v(), v()]);
            let exact = closest_points_triangle_triangle(&a, &b).distance;
            assert!(triangle_plane_gap(&a, &b) <= exact, "{a:?} {b:?}");
        }
    }

    #[test]
    fn the_fast_triangle_distance_agrees_with_the_exhaustive_one() {
        let mut rnd = crate::geometry::test_numbers(12345);
        let mut by_kind = [0usize; 3];
        for n in 0..40_000 {
            let mut v = |s: f32| Vec3::new(rnd(), rnd(), rnd()) * s;
            let a = [v(4.0), v(4.0), v(4.0)];
            let mut b = [v(4.0), v(4.0), v(4.0)];
            match n % 4 {
                // Nearly parallel and close, as teeth meet.
                0 => {
                    let lift = Vec3::Z * v(0.01).z.abs();
                    let flat = Vec3::new(1.0, 1.0, 0.0);
                    let a0 = a.map(|p| p * flat);
                    let shift = v(1.0) * flat;
                    b = a0.map(|p| p + shift + lift + v(0.001));
                    check(&a0, &b, &mut by_kind);
                    continue;
                }
                // A needle.
                1 => b[2] = b[0] + (b[1] - b[0]) * 0.5 + v(1e-7),
                _ => {}
            }
            check(&a, &b, &mut by_kind);
        }
        // Every outcome was exercised.
        assert!(by_kind.iter().all(|&k| k > 100), "{by_kind:?}");

        fn check(a: &[Vec3; 3], b: &[Vec3; 3], by_kind: &mut [usize; 3]) {
            // Reference: 0 where an edge crosses the other triangle, else the nearest of the
            // vertex–face and edge–edge pairs.
            let crossing = (0..3).any(|k| {
                segment_triangle_crossing(a[k], a[(k + 1) % 3], b).is_some()
                    || segment_triangle_crossing(b[k], b[(k + 1) % 3], a).is_some()
            });
            let mut slow = exhaustive(a, b);
            if !crossing {
                let features = (0..3)
                    .flat_map(|k| {
                        [
                            a[k].distance(closest_point_triangle(a[k], b[0], b[1], b[2])),
                            b[k].distance(closest_point_triangle(b[k], a[0], a[1], a[2])),
                        ]
                    })
                    .chain((0..9).map(|m| {
                        let (i, j) = (m / 3, m % 3);
                        let (p, q) = closest_points_segment_segment(
                            a[i],
                            a[(i + 1) % 3],
                            b[j],
                            b[(j + 1) % 3],
                        );
                        p.distance(q)
                    }))
                    .fold(f32::INFINITY, f32::min);
                slow.distance = features;
            }
            let tol = 1e-5 * (1.0 + slow.distance);
            // Both orders of the fast search.
            for fast in [
                closest_points_triangle_triangle(a, b),
                closest_points_facing_triangles(a, b),
            ] {
                assert!(
                    (fast.distance - slow.distance).abs() <= tol,
                    "{a:?} {b:?}: {fast:?} vs {slow:?}"
                );
                // The points are on their triangles and as far apart as reported.
                assert!((fast.on_first.distance(fast.on_second) - fast.distance).abs() <= tol);
                for (p, t) in [(fast.on_first, a), (fast.on_second, b)] {
                    let q = closest_point_triangle(p, t[0], t[1], t[2]);
                    assert!(q.distance(p) <= 1e-5, "{p} off {t:?}");
                }
            }
            by_kind[if slow.distance == 0.0 {
                0
            } else if slow.distance < 0.05 {
                1
            } else {
                2
            }] += 1;
        }
    }

    #[test]
    fn sliver_strips_a_micrometre_apart_do_not_intersect() {
        // Two strips of a generated root at 40,000 triangles: 14 µm wide, 1 mm long, nearly
        // coplanar, the second wholly on one side of the first's plane by 1–3 µm (checked in
        // exact rational arithmetic). f32 projections took them for crossing.
        let t1 = tri(
            [28.156425, -9.366802, -26.460337],
            [28.143988, -9.367285, -26.468922],
            [27.896626, -10.316576, -26.589489],
        );
        let t2 = tri(
            [27.90808, -10.316132, -26.581585],
            [27.639736, -11.266236, -26.716635],
            [27.650167, -11.265831, -26.709436],
        );
        assert!(!triangles_intersect(&t1, &t2));
        assert!(!triangles_intersect(&t2, &t1));
        // Moved onto the first's plane, the second does meet it: the test still sees contact.
        let n = (t1[1] - t1[0]).cross(t1[2] - t1[0]).normalize();
        let off = n.dot(t2[0] - t1[0]);
        let t3 = t2.map(|v| v - n * off);
        assert!(triangles_within(&t1, &t3, 1e-4));
    }

    #[test]
    fn coplanar_overlap_and_separation() {
        let t1 = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let t2 = tri([0.5, 0.5, 0.0], [3.0, 0.5, 0.0], [0.5, 3.0, 0.0]);
        assert!(triangles_intersect(&t1, &t2));
        let t3 = tri([2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]);
        assert!(!triangles_intersect(&t1, &t3));
        let r = closest_points_triangle_triangle(&t1, &t3);
        assert!((r.distance - 2.0f32.sqrt()).abs() < 1e-5, "{r:?}");
    }
}
