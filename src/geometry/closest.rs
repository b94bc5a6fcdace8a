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
    if sum.abs() <= f64::MIN_POSITIVE {
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
    const EPS: f64 = 1e-18;
    let [p1, q1, p2, q2] = [p1, q1, p2, q2].map(|v| v.as_dvec3());
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    let (s, t);
    if a <= EPS && e <= EPS {
        return (p1.as_vec3(), p2.as_vec3());
    }
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
    ((p1 + d1 * s).as_vec3(), (p2 + d2 * t).as_vec3())
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
/// rounding; the axes are the two face normals, the nine edge–edge cross products and, for
/// (nearly) coplanar triangles, the in-plane edge normals.
pub fn triangles_intersect(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> bool {
    let separated = |axis: Vec3| -> bool {
        let len2 = axis.length_squared();
        if len2 <= f32::MIN_POSITIVE {
            return false;
        }
        let (mut min1, mut max1) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut min2, mut max2) = (f32::INFINITY, f32::NEG_INFINITY);
        for k in 0..3 {
            let a = axis.dot(t1[k]);
            let b = axis.dot(t2[k]);
            min1 = min1.min(a);
            max1 = max1.max(a);
            min2 = min2.min(b);
            max2 = max2.max(b);
        }
        max1 < min2 || max2 < min1
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

/// Exact closest points between two triangles (Ericson 5.1.9's reduction: for disjoint triangles
/// the minimum is reached between a vertex and the other triangle or between two edges). When the
/// triangles intersect the distance is 0 and both points are a point where an edge of one crosses
/// the other.
pub fn closest_points_triangle_triangle(t1: &[Vec3; 3], t2: &[Vec3; 3]) -> TrianglePair {
    if triangles_intersect(t1, t2) {
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
    if triangles_intersect(t1, t2) {
        best.distance = 0.0;
    }
    best
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
