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
//! themselves (their slot centres in the occlusal plane): the wire is chosen for the patient, not
//! bent to every bracket, and the brackets' departures from it are the malalignment it corrects.
//!
//! **Laying.** [`lay`] makes the wire's passive nodes about [`SPACING_MM`] apart along the form,
//! with a node exactly at each bracket's nearest point on the form, and says which node each
//! bracket holds.

pub use crate::teeth::case::appliance::ArchForm;
use glam::DVec3;

use super::rod::RodNode;

/// Length of straight wire past each end of the form (mm).
pub const TAIL_MM: f64 = 3.0;
/// Spacing of the wire's nodes (mm).
pub const SPACING_MM: f64 = 1.0;

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

/// A wire laid through brackets: its passive nodes and, per bracket, the node it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Laid {
    /// The wire's passive shape.
    pub nodes: Vec<RodNode>,
    /// Per bracket, the index of its node.
    pub held: Vec<usize>,
}

/// Lays `form` of `size` at height `y`, shifted forwards by `z0` (the molars' line), through
/// brackets at `points` (world slot centres, in any order): see the module doc.
pub fn lay(form: ArchForm, size: &ArchSize, y: f64, z0: f64, points: &[DVec3]) -> Laid {
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
    // A point of the form (or its straight tails) by arc length from the right molar.
    let point_at = |s: f64| -> (DVec3, DVec3) {
        let tangent = |x: f64| (at(x + 1e-4) - at(x - 1e-4)).normalize();
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
    // Each bracket's nearest place on the form, by arc length.
    let nearest = |p: DVec3| -> f64 {
        let (mut best, mut s_best) = (f64::INFINITY, 0.0);
        for (i, x) in xs.iter().enumerate() {
            let d = at(*x).distance_squared(DVec3::new(p.x, y, p.z));
            if d < best {
                (best, s_best) = (d, arc[i]);
            }
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
    let nodes = stations
        .iter()
        .map(|&s| {
            let (p, t) = point_at(s);
            RodNode::along(p, t, DVec3::Y)
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
        let laid = lay(ArchForm::Ovoid, &size, 0.0, 0.0, &[]);
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
    fn a_wire_through_aligned_brackets_is_passive_and_one_displaced_bracket_is_pulled_back() {
        let (size, points, frames) = aligned();
        let laid = lay(ArchForm::Ovoid, &size, 0.0, 0.0, &points);
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
