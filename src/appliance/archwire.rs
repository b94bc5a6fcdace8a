//! Archwires as bought: a preformed arch form (ovoid, tapered, square) sized to the patient's arch,
//! and the wire laid through a row of brackets.
//!
//! **Forms.** Each form is the curve z(x) = D + b x² + c x⁴ in the occlusal plane (x across the
//! arch, z forwards) through the incisor point (0, D), the canines (±W₃/2, D − d₃) and the first
//! molars (±W₆/2, 0), with the canine width and depth as shares of the molar width and the arch
//! depth that distinguish the forms (tapered: narrow canines; square: wide, flat front; ovoid
//! between), in the proportions of the usual preformed wire templates. Beyond the molars the wire
//! runs on straight along its end tangent for [`TAIL_MM`] (through the tubes).
//!
//! **Sizing.** [`ArchSize::fit`] takes the molar width and the arch depth from the brackets
//! themselves (their slot centres in the occlusal plane); [`fit_form`] then sizes and places the
//! form by least squares on the slots' distances to it (within 15 % of that extent): the wire is
//! chosen for the patient, and the brackets' departures from it are the malalignment it corrects.
//!
//! **Laying.** [`lay`] makes the wire's passive nodes about [`SPACING_MM`] apart along the form,
//! with a node exactly at each bracket's nearest point on the form, and says which node each
//! bracket holds. Given offsets, it coordinates the wire to a patient's arch: the wire passes that
//! far outside the form at each bracket, the offsets blended between brackets (C¹), as a clinician
//! bends a preformed wire to the arch of a setup. Guarantee: the passive wire passes through each
//! bracket's point on the form plus its offset to within the form's sampling (2,000 steps across
//! the arch: within 0.02 mm).

pub use crate::teeth::case::appliance::ArchForm;
use glam::DVec3;

use super::rod::RodNode;

/// Length of straight wire past each end of the form (mm).
pub const TAIL_MM: f64 = 3.0;
/// Spacing of the wire's nodes (mm).
pub const SPACING_MM: f64 = 2.0;

/// The size of an arch form: first molar to first molar width and the depth from there to the
/// incisors (mm, in the occlusal plane, at the slots).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArchSize {
    /// Width between the first molars.
    pub molar_width_mm: f64,
    /// Depth from the molars' line to the incisors.
    pub depth_mm: f64,
}

impl ArchSize {
    /// The size of the arch through the slot centres `points` (world; x across, z forwards):
    /// the width between the two outermost and the depth from the two rearmost to the front.
    /// `None` for fewer than three points or a degenerate arch.
    pub fn fit(points: &[DVec3]) -> Option<Self> {
        if points.len() < 3 {
            return None;
        }
        let left = points.iter().copied().max_by(|a, b| a.x.total_cmp(&b.x))?;
        let right = points.iter().copied().min_by(|a, b| a.x.total_cmp(&b.x))?;
        let front = points.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
        let size = Self {
            molar_width_mm: left.x - right.x,
            depth_mm: front - 0.5 * (left.z + right.z),
        };
        (size.molar_width_mm > 1.0 && size.depth_mm > 1.0).then_some(size)
    }
}

/// `form` sized and placed to pass nearest the slot centres `points` (world) in the occlusal
/// plane: the molar width, depth and forward shift (z0) that least-squares the points' distances
/// to the form (Gauss–Newton from [`ArchSize::fit`]'s extremes). The form keeps its proportions;
/// only its size and place are the patient's. `None` as for [`ArchSize::fit`].
pub fn fit_form(form: ArchForm, points: &[DVec3]) -> Option<(ArchSize, f64)> {
    let start = ArchSize::fit(points)?;
    let (left, right) = (
        points.iter().max_by(|a, b| a.x.total_cmp(&b.x))?,
        points.iter().min_by(|a, b| a.x.total_cmp(&b.x))?,
    );
    let residuals = |q: [f64; 3]| -> Vec<f64> {
        let size = ArchSize {
            molar_width_mm: q[0],
            depth_mm: q[1],
        };
        points
            .iter()
            .map(|&p| {
                let (at, t) = nearest_on_form(form, &size, p.y, q[2], p);
                (p - at).dot(t.cross(DVec3::Y))
            })
            .collect()
    };
    let q0 = [
        start.molar_width_mm,
        start.depth_mm,
        0.5 * (left.z + right.z),
    ];
    // Within a wire size or two of the brackets' own extent, and a few millimetres of their
    // place: a preformed form is chosen, not drawn to any shape.
    let bounded = |q: [f64; 3]| {
        [
            q[0].clamp(0.85 * q0[0], 1.15 * q0[0]),
            q[1].clamp(0.85 * q0[1], 1.15 * q0[1]),
            q[2].clamp(q0[2] - 5.0, q0[2] + 5.0),
        ]
    };
    let mut q = q0;
    let cost = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    let mut r = residuals(q);
    for _ in 0..30 {
        // Forward-difference Jacobian, then the 3×3 normal equations.
        let h = 1e-4;
        let cols: Vec<Vec<f64>> = (0..3)
            .map(|j| {
                let mut e = q;
                e[j] += h;
                residuals(e)
                    .iter()
                    .zip(&r)
                    .map(|(a, b)| (a - b) / h)
                    .collect()
            })
            .collect();
        let mut a = glam::DMat3::ZERO;
        let mut g = DVec3::ZERO;
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = cols[i].iter().zip(&cols[j]).map(|(x, y)| x * y).sum();
                *a.col_mut(j).as_mut().get_mut(i).expect("3×3") = v;
            }
            g[i] = cols[i].iter().zip(&r).map(|(x, y)| x * y).sum();
        }
        if a.determinant().abs() < 1e-12 {
            break;
        }
        // Gauss–Newton's step, halved until it lowers the cost.
        let mut step = a.inverse() * -g;
        let mut taken = None;
        for _ in 0..12 {
            let next = bounded([q[0] + step.x, q[1] + step.y, q[2] + step.z]);
            let r_next = residuals(next);
            if cost(&r_next) < cost(&r) {
                taken = Some((next, r_next));
                break;
            }
            step *= 0.5;
        }
        let Some((next, r_next)) = taken else {
            break;
        };
        (q, r) = (next, r_next);
        if step.length() < 1e-6 {
            break;
        }
    }
    Some((
        ArchSize {
            molar_width_mm: q[0],
            depth_mm: q[1],
        },
        q[2],
    ))
}

impl ArchForm {
    /// Every form, for pickers.
    pub const ALL: [Self; 3] = [Self::Ovoid, Self::Tapered, Self::Square];

    /// Its name as case files write it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ovoid => "ovoid",
            Self::Tapered => "tapered",
            Self::Square => "square",
        }
    }

    /// Canine width over molar width, and the canines' depth behind the incisors over the arch
    /// depth.
    fn canines(self) -> (f64, f64) {
        match self {
            Self::Tapered => (0.66, 0.36),
            Self::Ovoid => (0.72, 0.30),
            Self::Square => (0.78, 0.24),
        }
    }

    /// The form's coefficients (D, b, c) for `size`.
    fn coefficients(self, size: &ArchSize) -> (f64, f64, f64) {
        let (ratio, behind) = self.canines();
        let d = size.depth_mm;
        let (x3, z3) = (0.5 * ratio * size.molar_width_mm, d * (1.0 - behind));
        let x6 = 0.5 * size.molar_width_mm;
        // z3 = d + b x3² + c x3⁴ and 0 = d + b x6² + c x6⁴.
        let (a1, b1, r1) = (x3 * x3, x3.powi(4), z3 - d);
        let (a2, b2, r2) = (x6 * x6, x6.powi(4), -d);
        let det = a1 * b2 - a2 * b1;
        let b = (r1 * b2 - r2 * b1) / det;
        let c = (a1 * r2 - a2 * r1) / det;
        (d, b, c)
    }

    /// The form's point at `x` (mm across the arch) for `size`, in the occlusal plane (y = 0),
    /// relative to the molars' line.
    pub fn point(self, size: &ArchSize, x: f64) -> DVec3 {
        let (d, b, c) = self.coefficients(size);
        DVec3::new(x, 0.0, d + b * x * x + c * x.powi(4))
    }
}

/// The place of `form` of `size` at height `y`, shifted forwards by `z0`, nearest to `p` in the
/// occlusal plane (its straight tails included), and the form's unit tangent there, running from
/// the patient's right to left (+x).
pub fn nearest_on_form(
    form: ArchForm,
    size: &ArchSize,
    y: f64,
    z0: f64,
    p: DVec3,
) -> (DVec3, DVec3) {
    let half = 0.5 * size.molar_width_mm;
    let at = |x: f64| form.point(size, x) + DVec3::new(0.0, y, z0);
    let tangent = |x: f64| (at(x + 1e-5) - at(x - 1e-5)).normalize();
    let flat = DVec3::new(p.x, y, p.z);
    let d2 = |x: f64| at(x).distance_squared(flat);
    // Coarse samples, then golden-section search around the best (the distance is unimodal
    // within a sample's neighbourhood on these smooth forms).
    let samples = 400;
    let xs = |i: usize| -half + size.molar_width_mm * i as f64 / samples as f64;
    let best = (0..=samples)
        .min_by(|&a, &b| d2(xs(a)).total_cmp(&d2(xs(b))))
        .unwrap_or(0);
    let (mut lo, mut hi) = (xs(best.saturating_sub(1)), xs((best + 1).min(samples)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if d2(a) < d2(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    let x = 0.5 * (lo + hi);
    // Past a molar end, the straight tail.
    for end in [-half, half] {
        let t = tangent(end);
        let beyond = (flat - at(end)).dot(t) * end.signum();
        if (x - end).abs() < 1e-6 * size.molar_width_mm.max(1.0) && beyond > 0.0 {
            return (at(end) + t * (flat - at(end)).dot(t), t);
        }
    }
    (at(x), tangent(x))
}

/// A wire laid through brackets: its passive nodes and, per bracket, the node it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Laid {
    /// The wire's passive shape.
    pub nodes: Vec<RodNode>,
    /// Per bracket, the index of its node.
    pub held: Vec<usize>,
}

/// Lays `form` of `size` at height `y`, shifted forwards by `z0` (the molars' line), through
/// brackets at `points` (world slot centres, in any order): see the module doc. `offsets` (one
/// per point, or empty for none) individualise the wire: it passes that far outside the form
/// (mm, in the occlusal plane) at each bracket's place, the offset blended between brackets by a
/// Catmull–Rom spline of arc length and held beyond the end brackets, as a clinician coordinates
/// a preformed wire to the patient's arch.
pub fn lay(
    form: ArchForm,
    size: &ArchSize,
    y: f64,
    z0: f64,
    points: &[DVec3],
    offsets: &[f64],
) -> Laid {
    let half = 0.5 * size.molar_width_mm;
    let at = |x: f64| form.point(size, x) + DVec3::new(0.0, y, z0);
    // The form sampled finely by x, then measured along its length.
    let samples = 2000;
    let xs: Vec<f64> = (0..=samples)
        .map(|i| -half + size.molar_width_mm * i as f64 / samples as f64)
        .collect();
    let mut arc = vec![0.0];
    for w in xs.windows(2) {
        let l = arc[arc.len() - 1] + at(w[0]).distance(at(w[1]));
        arc.push(l);
    }
    let total = arc[arc.len() - 1];
    let tangent = |x: f64| (at(x + 1e-4) - at(x - 1e-4)).normalize();
    // A point of the form (or its straight tails) by arc length from the right molar.
    let point_at = |s: f64| -> (DVec3, DVec3) {
        if s <= 0.0 {
            let t = tangent(-half);
            return (at(-half) + t * s, t);
        }
        if s >= total {
            let t = tangent(half);
            return (at(half) + t * (s - total), t);
        }
        let k = arc.partition_point(|a| *a < s).clamp(1, samples);
        let f = (s - arc[k - 1]) / (arc[k] - arc[k - 1]).max(1e-12);
        let x = xs[k - 1] + f * (xs[k] - xs[k - 1]);
        (at(x), tangent(x))
    };
    // Each bracket's nearest place on the form (or its straight tails), by arc length.
    let nearest = |p: DVec3| -> f64 {
        let flat = DVec3::new(p.x, y, p.z);
        let (mut best, mut i_best) = (f64::INFINITY, 0);
        for (i, x) in xs.iter().enumerate() {
            let d = at(*x).distance_squared(flat);
            if d < best {
                (best, i_best) = (d, i);
            }
        }
        // Between the nearest sample and its neighbours: the foot of the perpendicular on the
        // nearer of the two chords (the samples alone would snap a bracket up to half a sample
        // along the arch).
        let mut s_best = arc[i_best];
        for j in [i_best.saturating_sub(1), i_best] {
            if j + 1 > samples {
                continue;
            }
            let (a, b) = (at(xs[j]), at(xs[j + 1]));
            let ab = b - a;
            let f = ((flat - a).dot(ab) / ab.length_squared().max(1e-18)).clamp(0.0, 1.0);
            let d = (a + ab * f).distance_squared(flat);
            if d < best {
                (best, s_best) = (d, arc[j] + f * (arc[j + 1] - arc[j]));
            }
        }
        if s_best <= 0.0 {
            let t = tangent(-half);
            return s_best + (flat - at(-half)).dot(t).min(0.0);
        }
        if s_best >= total {
            let t = tangent(half);
            return s_best + (flat - at(half)).dot(t).max(0.0);
        }
        s_best
    };
    let at_brackets: Vec<f64> = points.iter().map(|p| nearest(*p)).collect();
    let mut stations: Vec<f64> = at_brackets.clone();
    let (start, end) = (-TAIL_MM, total + TAIL_MM);
    let n = ((end - start) / SPACING_MM).ceil() as usize;
    for i in 0..=n {
        let s = start + (end - start) * i as f64 / n as f64;
        // Regular nodes too near a bracket's node give way to it.
        if at_brackets.iter().all(|b| (b - s).abs() > 0.3 * SPACING_MM) {
            stations.push(s);
        }
    }
    stations.sort_by(f64::total_cmp);
    stations.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    // The individual offset along the arc: Catmull–Rom through the brackets' offsets.
    let mut knots: Vec<(f64, f64)> = at_brackets
        .iter()
        .zip(offsets.iter().chain(std::iter::repeat(&0.0)))
        .map(|(s, d)| (*s, *d))
        .collect();
    knots.sort_by(|a, b| a.0.total_cmp(&b.0));
    knots.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-9);
    let offset_at = |s: f64| -> f64 {
        if offsets.is_empty() || knots.is_empty() {
            return 0.0;
        }
        let n = knots.len();
        if s <= knots[0].0 {
            return knots[0].1;
        }
        if s >= knots[n - 1].0 {
            return knots[n - 1].1;
        }
        let k = knots.partition_point(|q| q.0 <= s).clamp(1, n - 1);
        let (s0, d0) = knots[k - 1];
        let (s1, d1) = knots[k];
        let slope = |i: usize| -> f64 {
            let (a, b) = (knots[i.saturating_sub(1)], knots[(i + 1).min(n - 1)]);
            if b.0 > a.0 {
                (b.1 - a.1) / (b.0 - a.0)
            } else {
                0.0
            }
        };
        let h = s1 - s0;
        let t = (s - s0) / h;
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * d0
            + (t3 - 2.0 * t2 + t) * h * slope(k - 1)
            + (-2.0 * t3 + 3.0 * t2) * d1
            + (t3 - t2) * h * slope(k)
    };
    let places: Vec<DVec3> = stations
        .iter()
        .map(|&s| {
            let (p, t) = point_at(s);
            p + t.cross(DVec3::Y).normalize() * offset_at(s)
        })
        .collect();
    let last = places.len().saturating_sub(1);
    let nodes = (0..places.len())
        .map(|i| {
            let t = places[(i + 1).min(last)] - places[i.saturating_sub(1)];
            RodNode::along(places[i], t, DVec3::Y)
        })
        .collect();
    let held = at_brackets
        .iter()
        .map(|b| {
            stations
                .iter()
                .position(|s| (s - b).abs() < 1e-9)
                .unwrap_or(0)
        })
        .collect();
    Laid { nodes, held }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::appliance::{Holder, Rod, Settings, WireMaterial, WireSize};
    use glam::DQuat;

    /// Twelve brackets on an ovoid arch 46 mm wide and 26 mm deep, patient's right first, slots
    /// along the form (as a finished case stands).
    fn aligned() -> (ArchSize, Vec<DVec3>, Vec<DQuat>) {
        let size = ArchSize {
            molar_width_mm: 46.0,
            depth_mm: 26.0,
        };
        let laid = lay(ArchForm::Ovoid, &size, 0.0, 0.0, &[], &[]);
        let total = laid.nodes.len() - 1;
        let mut points = Vec::new();
        let mut frames = Vec::new();
        for k in 0..12 {
            let i = (TAIL_MM / SPACING_MM) as usize
                + ((total as f64 - 2.0 * TAIL_MM / SPACING_MM) * k as f64 / 11.0).round() as usize;
            points.push(laid.nodes[i].x);
            frames.push(laid.nodes[i].q);
        }
        (size, points, frames)
    }

    #[test]
    fn forms_pass_their_points_and_fit_their_brackets() {
        let size = ArchSize {
            molar_width_mm: 46.0,
            depth_mm: 26.0,
        };
        for form in ArchForm::ALL {
            assert!((form.point(&size, 0.0).z - 26.0).abs() < 1e-9);
            assert!(form.point(&size, 23.0).z.abs() < 1e-9);
            assert!(form.point(&size, -23.0).z.abs() < 1e-9);
        }
        // Tapered is narrower at the canines than square.
        let x3 = 0.5 * 0.7 * 46.0;
        assert!(ArchForm::Tapered.point(&size, x3).z < ArchForm::Square.point(&size, x3).z);
        let (_, points, _) = aligned();
        let fitted = ArchSize::fit(&points).unwrap();
        assert!(
            (fitted.molar_width_mm - 46.0 - 2.0 * 0.0).abs() < 6.0,
            "{fitted:?}"
        );
        assert!(ArchSize::fit(&points[..2]).is_none());
    }

    #[test]
    fn the_nearest_place_fit_and_coordinated_wire_are_exact() {
        let size = ArchSize {
            molar_width_mm: 46.0,
            depth_mm: 26.0,
        };
        let form = ArchForm::Ovoid;
        // A point 0.7 mm outside the form (and off its plane) finds the form's point and the
        // distance along its normal; past a molar the straight tail.
        for x in [-20.0, -6.0, 0.0, 11.0] {
            let on = form.point(&size, x) + DVec3::new(0.0, 1.0, 2.0);
            let (q, t) = nearest_on_form(form, &size, 1.0, 2.0, on);
            assert!(q.distance(on) < 1e-6, "{x}: {q} vs {on}");
            let out = t.cross(DVec3::Y).normalize();
            let p = on + out * 0.7 + DVec3::Y * 3.0;
            let (q, _) = nearest_on_form(form, &size, 1.0, 2.0, p);
            assert!((DVec3::new(p.x, 1.0, p.z) - q).length() - 0.7 < 1e-6, "{x}");
        }
        let end = form.point(&size, 23.0) + DVec3::new(0.0, 0.0, 2.0);
        let (_, t) = nearest_on_form(form, &size, 0.0, 2.0, end);
        let (q, _) = nearest_on_form(form, &size, 0.0, 2.0, end + t * 4.0);
        assert!(q.distance(end + t * 4.0) < 1e-6);
        // Slots on a form of known size and place, the fit started from their extremes finds it.
        let (_, points, _) = aligned();
        let moved: Vec<DVec3> = points.iter().map(|p| *p + DVec3::Z * 1.5).collect();
        let (fitted, z0) = fit_form(form, &moved).unwrap();
        assert!((fitted.molar_width_mm - 46.0).abs() < 0.05, "{fitted:?}");
        assert!((fitted.depth_mm - 26.0).abs() < 0.05, "{fitted:?}");
        assert!((z0 - 1.5).abs() < 0.05, "{z0}");
        // Coordinated through offsets, the passive wire passes through each offset slot.
        let offsets: Vec<f64> = (0..points.len()).map(|k| 0.3 * (k as f64).sin()).collect();
        let laid = lay(form, &size, 0.0, 0.0, &points, &offsets);
        for ((p, d), node) in points.iter().zip(&offsets).zip(&laid.held) {
            let (_, t) = nearest_on_form(form, &size, 0.0, 0.0, *p);
            let want = *p + t.cross(DVec3::Y).normalize() * *d;
            assert!(
                laid.nodes[*node].x.distance(want) < 0.02,
                "{d}: {} vs {want} (slot {p})",
                laid.nodes[*node].x
            );
        }
    }

    #[test]
    fn a_wire_through_aligned_brackets_is_passive_and_one_displaced_bracket_is_pulled_back() {
        let (size, points, frames) = aligned();
        let laid = lay(ArchForm::Ovoid, &size, 0.0, 0.0, &points, &[]);
        assert_eq!(laid.held.len(), 12);
        for (p, &k) in points.iter().zip(&laid.held) {
            // To the fine sampling of the form.
            assert!(laid.nodes[k].x.distance(*p) < 0.05);
        }
        let holders = |shift: DVec3| -> Vec<Holder> {
            (0..12)
                .map(|b| {
                    let mut h = Holder::clamp(laid.held[b], &laid.nodes[laid.held[b]]);
                    h.frame = frames[b];
                    h.play = [f64::INFINITY, 0.07, 0.1, f64::INFINITY, 0.02, 0.03];
                    h.stiffness = [0.0, 2e3, 2e3, 0.0, 4e3, 4e3];
                    if b == 4 {
                        h.at += shift;
                    }
                    h
                })
                .collect()
        };
        let mut rod = Rod::new(
            laid.nodes.clone(),
            WireSize::Round(0.014),
            WireMaterial::NiTi,
        );
        let passive = holders(DVec3::ZERO);
        let e = rod.solve(&passive, &[], &Settings::default());
        assert!(e.converged && e.iterations == 0, "{e:?}");
        // The fifth bracket 2 mm lingual of the form (its slot's buccal is its frame's Z).
        let lingual = -(frames[4] * DVec3::Z);
        let displaced = holders(lingual * 2.0);
        let e = rod.solve(&displaced, &[], &Settings::default());
        assert!(e.converged, "{e:?}");
        let r = rod.reactions(&displaced);
        // The wire pulls the displaced bracket back out, 0.3–3 N for a light NiTi wire, and its
        // neighbours in; forces balance.
        let pull = -r[4].force.dot(lingual);
        assert!((0.3..3.0).contains(&pull), "{pull} N: {:?}", r[4]);
        assert!(r[3].force.dot(lingual) > 0.0 && r[5].force.dot(lingual) > 0.0);
        let total: DVec3 = r.iter().map(|r| r.force).sum();
        assert!(total.length() < 1e-4 * pull, "{total}");
        // Brackets far from the displaced one feel almost nothing.
        assert!(r[11].force.length() < 0.1 * pull, "{:?}", r[11]);
    }
}
