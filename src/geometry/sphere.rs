//! `Sphere` and the smallest sphere enclosing a point set (Welzl 1991).

use glam::{DVec3, Vec3};

/// A sphere: centre and radius (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub centre: Vec3,
    /// Radius (≥ 0).
    pub radius: f32,
}

impl Sphere {
    /// A sphere from its centre and radius.
    pub const fn new(centre: Vec3, radius: f32) -> Self {
        Self { centre, radius }
    }

    /// True when `p` lies inside or on the sphere (exact comparison of squared distances).
    #[inline]
    pub fn contains(&self, p: Vec3) -> bool {
        self.centre.distance_squared(p) <= self.radius * self.radius
    }

    /// True when the spheres overlap or touch.
    #[inline]
    pub fn overlaps(&self, o: &Sphere) -> bool {
        let r = self.radius + o.radius;
        self.centre.distance_squared(o.centre) <= r * r
    }

    /// Volume (mm³).
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * (self.radius as f64).powi(3)
    }

    /// The smallest sphere containing every point, then grown to the largest f32 distance from
    /// the centre so that every point passes [`Sphere::contains`]. Exact up to rounding; empty
    /// input gives a zero sphere at the origin.
    ///
    /// Small sets go to Welzl's algorithm directly. Larger ones keep a core set, starting with the
    /// extreme points along the axes: the smallest sphere around the core set is computed, the
    /// point farthest outside it in each octant around its centre joins the set, until no point is
    /// outside. A sphere around a
    /// subset that holds every point is the smallest for all of them, so the answer is the same,
    /// from a few passes over the points instead of Welzl's shuffled recursion over all of them.
    pub fn enclosing(points: &[Vec3]) -> Sphere {
        const DIRECT: usize = 128;
        if points.is_empty() {
            return Sphere::new(Vec3::ZERO, 0.0);
        }
        let s = if points.len() <= DIRECT {
            welzl(points.iter().map(|v| v.as_dvec3()).collect())
        } else {
            let mut core: Vec<DVec3> = Vec::new();
            // The extreme points along each axis, in one pass.
            let (mut lo, mut hi) = ([points[0]; 3], [points[0]; 3]);
            for q in points {
                for axis in 0..3 {
                    if q[axis] < lo[axis][axis] {
                        lo[axis] = *q;
                    }
                    if q[axis] > hi[axis][axis] {
                        hi[axis] = *q;
                    }
                }
            }
            for q in lo.into_iter().chain(hi) {
                if !core.contains(&q.as_dvec3()) {
                    core.push(q.as_dvec3());
                }
            }
            loop {
                let s = welzl(core.clone());
                // Outside by more than rounding (a point of the core set never is): the farthest
                // such point in each octant around the centre joins the core set.
                let limit = (s.1 * (1.0 + 1e-9) + 1e-9).powi(2);
                let mut far = [(limit, Vec3::ZERO); 8];
                for q in points {
                    let d = q.as_dvec3() - s.0;
                    let d2 = d.length_squared();
                    if d2 > limit {
                        let octant = (d.x > 0.0) as usize
                            | ((d.y > 0.0) as usize) << 1
                            | ((d.z > 0.0) as usize) << 2;
                        if d2 > far[octant].0 {
                            far[octant] = (d2, *q);
                        }
                    }
                }
                let before = core.len();
                for (d2, q) in far {
                    let q = q.as_dvec3();
                    if d2 > limit && !core.contains(&q) {
                        core.push(q);
                    }
                }
                if core.len() == before {
                    break s;
                }
            }
        };
        let centre = s.0.as_vec3();
        let radius = points
            .iter()
            .map(|q| q.distance(centre))
            .fold(0.0f32, f32::max);
        // One ulp more so that the squared comparison in `contains` holds for every point.
        Sphere::new(centre, radius.next_up())
    }
}

/// Welzl's algorithm in its iterative form, in f64, over a deterministic shuffle: the smallest
/// sphere (centre, radius) around non-empty `p`.
fn welzl(mut p: Vec<DVec3>) -> (DVec3, f64) {
    // Deterministic shuffle: the expected linear time needs a random order.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for i in (1..p.len()).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        p.swap(i, (state % (i as u64 + 1)) as usize);
    }
    let inside = |s: &(DVec3, f64), q: DVec3| q.distance(s.0) <= s.1 * (1.0 + 1e-12) + 1e-12;
    let mut s = (p[0], 0.0);
    for i in 1..p.len() {
        if inside(&s, p[i]) {
            continue;
        }
        s = (p[i], 0.0);
        for j in 0..i {
            if inside(&s, p[j]) {
                continue;
            }
            s = sphere2(p[i], p[j]);
            for k in 0..j {
                if inside(&s, p[k]) {
                    continue;
                }
                s = sphere3(p[i], p[j], p[k]);
                for l in 0..k {
                    if !inside(&s, p[l]) {
                        s = sphere4(p[i], p[j], p[k], p[l]);
                    }
                }
            }
        }
    }
    s
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice), deterministic.
pub fn fibonacci_directions(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let t = golden * i as f32;
            Vec3::new(r * t.cos(), y, r * t.sin())
        })
        .collect()
}

fn sphere2(a: DVec3, b: DVec3) -> (DVec3, f64) {
    let c = (a + b) * 0.5;
    (c, a.distance(c))
}

/// The smallest sphere with a, b, c on its surface (centre in their plane).
fn sphere3(a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64) {
    let (ab, ac) = (b - a, c - a);
    let n = ab.cross(ac);
    let d = 2.0 * n.length_squared();
    if d <= 1e-24 * ab.length_squared().max(ac.length_squared()).powi(2) {
        // Collinear: the sphere on the farthest pair.
        return [sphere2(a, b), sphere2(a, c), sphere2(b, c)]
            .into_iter()
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap_or((a, 0.0));
    }
    let offset = (n.cross(ab) * ac.length_squared() + ac.cross(n) * ab.length_squared()) / d;
    (a + offset, offset.length())
}

/// The sphere through a, b, c, d (their circumsphere); coplanar sets fall back to the smallest
/// sphere of the triangle that contains the fourth point.
fn sphere4(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (DVec3, f64) {
    let (u, v, w) = (b - a, c - a, d - a);
    let det = 2.0 * u.dot(v.cross(w));
    let scale = u.length() * v.length() * w.length();
    if det.abs() <= 1e-12 * scale.max(1e-300) {
        let candidates = [
            sphere3(a, b, c),
            sphere3(a, b, d),
            sphere3(a, c, d),
            sphere3(b, c, d),
        ];
        let all = [a, b, c, d];
        return candidates
            .into_iter()
            .filter(|s| {
                all.iter()
                    .all(|q| q.distance(s.0) <= s.1 * (1.0 + 1e-9) + 1e-12)
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap_or_else(|| {
                let c = (a + b + c + d) / 4.0;
                (c, all.iter().map(|q| q.distance(c)).fold(0.0, f64::max))
            });
    }
    let offset = (v.cross(w) * u.length_squared()
        + w.cross(u) * v.length_squared()
        + u.cross(v) * w.length_squared())
        / det;
    (a + offset, offset.length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enclosing_spheres_of_simple_sets() {
        let s = Sphere::enclosing(&[
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.2, 0.0),
        ]);
        assert!(
            (s.radius - 1.0).abs() < 1e-5 && s.centre.length() < 1e-5,
            "{s:?}"
        );
        // Regular tetrahedron: circumradius sqrt(3/8) * edge.
        let t = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        let s = Sphere::enclosing(&t);
        assert!(
            (s.radius - 3f32.sqrt()).abs() < 1e-5 && s.centre.length() < 1e-5,
            "{s:?}"
        );
    }

    #[test]
    fn enclosing_sphere_contains_every_point_and_is_small() {
        let mut rnd = crate::geometry::test_numbers(7);
        for n in [1usize, 2, 5, 50, 2000] {
            let pts: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(rnd(), rnd() * 3.0, rnd()) * 4.0)
                .collect();
            let s = Sphere::enclosing(&pts);
            assert!(pts.iter().all(|p| s.contains(*p)), "n = {n}");
            // Never larger than the box's circumscribed sphere.
            let b = crate::geometry::Aabb::from_points(pts.iter().copied());
            assert!(
                s.radius <= 0.5 * b.extent().length() + 1e-4,
                "n = {n}: {s:?}"
            );
        }
    }

    /// Large sets go through the core set; the sphere is the one Welzl's algorithm finds over
    /// all the points, for blobs, shells (where every point is nearly extreme) and flat patches.
    #[test]
    fn core_set_spheres_match_welzl_over_every_point() {
        let mut rnd = crate::geometry::test_numbers(3);
        for (n, shape) in [(500usize, 0), (3000, 1), (3000, 2), (20_000, 1)] {
            let pts: Vec<Vec3> = (0..n)
                .map(|_| {
                    let p = Vec3::new(rnd(), rnd(), rnd());
                    match shape {
                        0 => p * Vec3::new(4.0, 1.0, 2.0),
                        1 => p.normalize_or_zero() * 3.0 + Vec3::X,
                        _ => Vec3::new(p.x * 5.0, p.y * 2.0, 0.3 * p.z * p.z),
                    }
                })
                .collect();
            let s = Sphere::enclosing(&pts);
            let w = welzl(pts.iter().map(|v| v.as_dvec3()).collect());
            assert!(pts.iter().all(|p| s.contains(*p)), "n {n} shape {shape}");
            assert!(
                (s.radius as f64 - w.1).abs() < 1e-5 * w.1
                    && s.centre.as_dvec3().distance(w.0) < 1e-4 * w.1,
                "n {n} shape {shape}: {s:?} vs {w:?}"
            );
        }
    }

    #[test]
    fn coplanar_and_duplicate_points() {
        let pts = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::X + Vec3::Y,
            Vec3::X,
            Vec3::ZERO,
        ];
        let s = Sphere::enclosing(&pts);
        assert!((s.radius - 0.5f32.sqrt()).abs() < 1e-5, "{s:?}");
        assert!(pts.iter().all(|p| s.contains(*p)));
    }
}
