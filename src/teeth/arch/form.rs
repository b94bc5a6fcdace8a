//! The beta-function arch form (Braun et al. 1998) and its arc-length table.

use glam::Vec2;
use serde::Serialize;

/// The beta-function arch form.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BetaArch {
    /// Width `W` at the distal of the second molars (mm).
    pub width: f32,
    /// Depth `D` from the second molars' line to the front (mm).
    pub depth: f32,
    /// World z of the curve's front point.
    pub front_z: f32,
}

impl BetaArch {
    /// The point of the curve at lateral position `x` (|x| ≤ W/2), as (x, z).
    pub fn point(&self, x: f32) -> Vec2 {
        let u = (x / self.width).clamp(-0.5, 0.5);
        let z = 2f32.powf(1.6) * self.depth * ((0.5 + u) * (0.5 - u)).max(0.0).powf(0.8);
        Vec2::new(x, self.front_z - self.depth + z)
    }
}

/// An arch curve tabulated by arc length from the midline, for placing teeth.
#[derive(Clone, Debug)]
pub struct ArchCurve {
    /// (arc length, point) along the left half, from the midline.
    table: Vec<(f32, Vec2)>,
}

impl ArchCurve {
    /// Tabulates a beta arch (x = W/2 · sin θ, dense where the curve turns backwards).
    pub fn new(form: &BetaArch) -> Self {
        Self::tabulate(form.width, |x| form.point(x))
    }

    /// Tabulates any symmetric arch `point(x)` → (x, z) for 0 ≤ x ≤ `width`/2, as [`Self::new`]
    /// does a beta arch.
    pub fn tabulate(width: f32, point: impl Fn(f32) -> Vec2) -> Self {
        const N: usize = 1500;
        let mut table = Vec::with_capacity(N + 1);
        let mut s = 0.0;
        let mut prev = point(0.0);
        for i in 0..=N {
            let theta = std::f32::consts::FRAC_PI_2 * i as f32 / N as f32;
            let p = point(0.5 * width * theta.sin());
            s += p.distance(prev);
            prev = p;
            table.push((s, p));
        }
        Self { table }
    }

    /// Arc length from the midline to where the curve turns into its straight continuation.
    pub fn half_length(&self) -> f32 {
        self.table.last().map_or(0.0, |e| e.0)
    }

    /// Point and unit tangent (direction of increasing arc length: from the patient's right to
    /// left) at signed arc length `s` (negative on the patient's right).
    pub fn at(&self, s: f32) -> (Vec2, Vec2) {
        let u = s.abs();
        let (end_s, end_p) = *self.table.last().expect("tabulated curve");
        let (p, dir) = if u >= end_s {
            (end_p + Vec2::new(0.0, -(u - end_s)), Vec2::new(0.0, -1.0))
        } else {
            let i = self
                .table
                .partition_point(|e| e.0 < u)
                .clamp(1, self.table.len() - 1);
            let (s0, p0) = self.table[i - 1];
            let (s1, p1) = self.table[i];
            let f = if s1 > s0 { (u - s0) / (s1 - s0) } else { 0.0 };
            (p0.lerp(p1, f), (p1 - p0).normalize_or(Vec2::X))
        };
        if s >= 0.0 {
            (p, dir)
        } else {
            (Vec2::new(-p.x, p.y), Vec2::new(dir.x, -dir.y))
        }
    }
}

impl ArchCurve {
    /// The signed arc length of the curve point nearest to `p` (x, z): negative on the patient's
    /// right, as [`ArchCurve::at`] takes it.
    pub fn project(&self, p: Vec2) -> f32 {
        let q = Vec2::new(p.x.abs(), p.y);
        let (end_s, end_p) = *self.table.last().expect("tabulated curve");
        // The straight continuation behind the last point.
        let mut best = if q.y <= end_p.y {
            (end_s + (end_p.y - q.y), (q.x - end_p.x).abs())
        } else {
            (end_s, q.distance(end_p))
        };
        for w in self.table.windows(2) {
            let ((s0, p0), (s1, p1)) = (w[0], w[1]);
            let d = p1 - p0;
            let len2 = d.length_squared();
            let f = if len2 > 0.0 {
                ((q - p0).dot(d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let dist = q.distance(p0 + d * f);
            if dist < best.1 {
                best = (s0 + (s1 - s0) * f, dist);
            }
        }
        if p.x < 0.0 { -best.0 } else { best.0 }
    }
}

impl ArchCurve {
    /// Distance (mm) from `p` (x, z) to the curve.
    pub fn distance(&self, p: Vec2) -> f32 {
        self.at(self.project(p)).0.distance(p)
    }
}

/// Fewest points an arch form is fitted to; with fewer, [`BetaArch::fit`] keeps its start.
pub const MIN_FIT_POINTS: usize = 4;

impl BetaArch {
    /// The beta arch closest to `points` (x, z; the teeth's cervical centres) in the least-squares
    /// sense over width, depth and front, starting from `self` (Nelder–Mead on the summed squared
    /// distances to the curve). With fewer than `MIN_FIT_POINTS` points, or when the fit is not
    /// closer by more than 0.01 mm root mean square, `self` is returned. The form stays symmetric about the midline (x = 0).
    pub fn fit(&self, points: &[Vec2]) -> BetaArch {
        if points.len() < MIN_FIT_POINTS || points.iter().any(|p| !p.is_finite()) {
            return *self;
        }
        let form = |v: [f32; 3]| BetaArch {
            width: v[0],
            depth: v[1],
            front_z: v[2],
        };
        let cost = |v: [f32; 3]| -> f32 {
            if !(10.0..=150.0).contains(&v[0]) || !(5.0..=100.0).contains(&v[1]) {
                return f32::INFINITY;
            }
            let curve = ArchCurve::new(&form(v));
            points.iter().map(|p| curve.distance(*p).powi(2)).sum()
        };
        let start = [self.width, self.depth, self.front_z];
        let mut simplex: Vec<([f32; 3], f32)> = (0..4)
            .map(|i| {
                let mut v = start;
                if i > 0 {
                    v[i - 1] += 4.0;
                }
                (v, cost(v))
            })
            .collect();
        let comb = |a: [f32; 3], b: [f32; 3], t: f32| [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
        for _ in 0..200 {
            simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
            if simplex[3].1 - simplex[0].1 <= 1e-5 * (1.0 + simplex[0].1) {
                break;
            }
            let centroid =
                [0, 1, 2].map(|k| simplex[..3].iter().map(|s| s.0[k]).sum::<f32>() / 3.0);
            let worst = simplex[3];
            let reflected = comb(centroid, worst.0, -1.0);
            let fr = cost(reflected);
            if fr < simplex[0].1 {
                let expanded = comb(centroid, worst.0, -2.0);
                let fe = cost(expanded);
                simplex[3] = if fe < fr {
                    (expanded, fe)
                } else {
                    (reflected, fr)
                };
            } else if fr < simplex[2].1 {
                simplex[3] = (reflected, fr);
            } else {
                let contracted = comb(centroid, worst.0, 0.5);
                let fc = cost(contracted);
                if fc < worst.1 {
                    simplex[3] = (contracted, fc);
                } else {
                    let best = simplex[0].0;
                    for s in simplex.iter_mut().skip(1) {
                        s.0 = comb(best, s.0, 0.5);
                        s.1 = cost(s.0);
                    }
                }
            }
        }
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        // Keep the start unless the fit is better by more than 0.01 mm root mean square.
        let rms = |c: f32| (c / points.len() as f32).sqrt();
        if rms(simplex[0].1) < rms(cost(start)) - 0.01 {
            form(simplex[0].0)
        } else {
            *self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_beta_curve_has_its_depth_and_width() {
        let form = BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        };
        assert!((form.point(0.0).y - 18.0).abs() < 1e-2);
        assert!((form.point(25.0).y - (18.0 - 36.0)).abs() < 1e-4);
        let curve = ArchCurve::new(&form);
        let (p, t) = curve.at(0.0);
        assert!((p - Vec2::new(0.0, 18.0)).length() < 1e-2, "{p}");
        assert!((t - Vec2::X).length() < 1e-2, "{t}");
        let (l, tl) = curve.at(30.0);
        let (r, tr) = curve.at(-30.0);
        assert!(
            (l.x + r.x).abs() < 1e-4 && (l.y - r.y).abs() < 1e-4,
            "mirror symmetric"
        );
        assert!(tl.y < 0.0 && tr.y > 0.0);
        // Past the end the curve runs straight back.
        let (far, tf) = curve.at(200.0);
        assert!((far.x - 25.0).abs() < 1e-3 && (tf - Vec2::new(0.0, -1.0)).length() < 1e-6);
    }

    #[test]
    fn projection_inverts_the_arc_length() {
        let curve = ArchCurve::new(&BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        });
        for s in [-60.0f32, -31.5, -12.0, -0.7, 0.0, 3.3, 25.0, 44.0, 58.0] {
            let (p, _) = curve.at(s);
            let back = curve.project(p);
            assert!((back - s).abs() < 0.02, "{s} -> {back}");
        }
    }

    #[test]
    fn the_fit_recovers_a_form_from_its_points() {
        let truth = BetaArch {
            width: 54.0,
            depth: 31.0,
            front_z: 16.0,
        };
        let curve = ArchCurve::new(&truth);
        let points: Vec<Vec2> = [
            -40.0f32, -30.0, -18.0, -9.0, -3.0, 3.0, 11.0, 22.0, 33.0, 41.0,
        ]
        .iter()
        .map(|s| curve.at(*s).0)
        .collect();
        let start = BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        };
        let fitted = start.fit(&points);
        let fc = ArchCurve::new(&fitted);
        let worst = points
            .iter()
            .map(|p| fc.distance(*p))
            .fold(0.0f32, f32::max);
        assert!(worst < 0.05, "{fitted:?}: {worst} mm");
        // Too few points: the start is kept.
        assert_eq!(start.fit(&points[..3]), start);
    }
}
