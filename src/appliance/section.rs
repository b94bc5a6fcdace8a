//! Archwire cross-sections: round 0.012–0.020" and rectangular 0.016×0.016" to 0.021×0.025", as
//! clinicians name them (inches), with the section properties the rod model needs in millimetres.
//!
//! Rectangular wires are drawn with bevelled (rounded) corners: Rucker & Kusy (AJODO
//! 2002;122:528–41) measured the bevels costing 7–8 % of the area and 15–19 % of the bending
//! stiffness. orthosim rounds each corner with the radius that takes [`BEVEL_AREA_LOSS`] of the
//! area, and computes the area, second moments and the slot play of that rounded rectangle
//! exactly; the torsion constant is the sharp rectangle's (Saint-Venant series) less the same
//! share as the polar moment loses.

pub use crate::teeth::case::appliance::{SizeError, WireSize};

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;
/// Share of a rectangular wire's area its bevelled corners take (Rucker & Kusy 2002: 7–8 %; the
/// low end, which with the slots' measured heights puts both torque plays `validate` checks in
/// their published ranges).
pub const BEVEL_AREA_LOSS: f64 = 0.07;

impl WireSize {
    /// As clinicians write it: `0.016"` or `0.019×0.025"`.
    pub fn label(self) -> String {
        match self {
            Self::Round(d) => format!("{}\"", inches(d)),
            Self::Rect(h, w) => format!("{}×{}\"", inches(h), inches(w)),
        }
    }

    /// True for a rectangular (or square) wire, which can deliver torque.
    pub fn is_rectangular(self) -> bool {
        matches!(self, Self::Rect(..))
    }

    /// Height across the slot (mm): the diameter of a round wire.
    pub fn height_mm(self) -> f64 {
        match self {
            Self::Round(d) => d * MM_PER_INCH,
            Self::Rect(h, _) => h * MM_PER_INCH,
        }
    }

    /// Width into the slot (mm): the diameter of a round wire.
    pub fn width_mm(self) -> f64 {
        match self {
            Self::Round(d) => d * MM_PER_INCH,
            Self::Rect(_, w) => w * MM_PER_INCH,
        }
    }

    /// Corner radius of a rectangular wire's bevels (mm; 0 for round wire): the radius whose
    /// four rounded corners take [`BEVEL_AREA_LOSS`] of the sharp rectangle's area.
    pub fn bevel_mm(self) -> f64 {
        match self {
            Self::Round(_) => 0.0,
            Self::Rect(..) => {
                let (h, w) = (self.height_mm(), self.width_mm());
                let r = (BEVEL_AREA_LOSS * h * w / (4.0 - std::f64::consts::PI)).sqrt();
                r.min(0.5 * h.min(w))
            }
        }
    }

    /// The section's properties.
    pub fn properties(self) -> SectionProperties {
        match self {
            Self::Round(_) => {
                let r = 0.5 * self.height_mm();
                let i = std::f64::consts::PI * r.powi(4) / 4.0;
                SectionProperties {
                    area: std::f64::consts::PI * r * r,
                    i_height: i,
                    i_width: i,
                    torsion: 2.0 * i,
                }
            }
            Self::Rect(..) => {
                let (h, w, r) = (self.height_mm(), self.width_mm(), self.bevel_mm());
                let sharp = SectionProperties {
                    area: h * w,
                    i_height: w * h.powi(3) / 12.0,
                    i_width: h * w.powi(3) / 12.0,
                    torsion: rectangle_torsion(h, w),
                };
                // Each corner: the square r×r at the corner less the quarter disc, both about the
                // section's centre axes (parallel axis theorem).
                let square = r * r;
                let quarter = std::f64::consts::PI * r * r / 4.0;
                let lost = square - quarter;
                // The lost sliver's centroid, from the corner's centre of curvature outwards.
                let arm = if lost > 0.0 {
                    (square * 0.5 * r - quarter * 4.0 * r / (3.0 * std::f64::consts::PI)) / lost
                } else {
                    0.0
                };
                let (cy, cx) = (0.5 * h - r + arm, 0.5 * w - r + arm);
                // Second moment of the sliver about its own centroid is tiny next to the parallel
                // axis term (r ≪ h); the square's own term bounds it.
                let own = square * r * r / 12.0;
                let i_height = sharp.i_height - 4.0 * (lost * cy * cy + own);
                let i_width = sharp.i_width - 4.0 * (lost * cx * cx + own);
                let polar = sharp.i_height + sharp.i_width;
                SectionProperties {
                    area: sharp.area - 4.0 * lost,
                    i_height,
                    i_width,
                    torsion: sharp.torsion * (i_height + i_width) / polar,
                }
            }
        }
    }
}

/// Saint-Venant's torsion constant of a sharp `a`×`b` rectangle (mm⁴), by its series (five terms:
/// better than 0.01 %).
fn rectangle_torsion(a: f64, b: f64) -> f64 {
    let (long, short) = if a >= b { (a, b) } else { (b, a) };
    let mut sum = 0.0;
    for k in 0..5 {
        let n = (2 * k + 1) as f64;
        sum += (n * std::f64::consts::PI * long / (2.0 * short)).tanh() / n.powi(5);
    }
    long * short.powi(3) / 3.0 * (1.0 - 192.0 / std::f64::consts::PI.powi(5) * short / long * sum)
}

/// A size in inches as written on a wire's packet: `.016` style digits without trailing zeros
/// past the thousandths.
fn inches(d: f64) -> String {
    let s = format!("{d:.4}");
    let s = s.trim_end_matches('0');
    s.strip_prefix('0').unwrap_or(s).to_string()
}

/// A section's properties (mm², mm⁴).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionProperties {
    /// Area.
    pub area: f64,
    /// Second moment for bending across the height (occluso-gingival bending, the wire's
    /// first-order-out-of-plane stiffness: what a slot's height deflects).
    pub i_height: f64,
    /// Second moment for bending across the width (bucco-lingual bending: in the arch's plane).
    pub i_width: f64,
    /// Torsion constant.
    pub torsion: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_wire_properties_are_the_circles() {
        let p = WireSize::Round(0.016).properties();
        let d = 0.016 * MM_PER_INCH;
        let i = std::f64::consts::PI * d.powi(4) / 64.0;
        assert!((p.i_height - i).abs() < 1e-12 * i.max(1.0));
        assert!((p.torsion - 2.0 * i).abs() < 1e-12);
        assert!((p.area - std::f64::consts::PI * d * d / 4.0).abs() < 1e-12);
        assert_eq!(WireSize::Round(0.016).label(), ".016\"");
    }

    #[test]
    fn bevels_cost_what_rucker_and_kusy_measured() {
        for (h, w) in [
            (0.016, 0.022),
            (0.019, 0.025),
            (0.021, 0.025),
            (0.016, 0.016),
        ] {
            let s = WireSize::Rect(h, w);
            let p = s.properties();
            let (hm, wm) = (h * MM_PER_INCH, w * MM_PER_INCH);
            let area_loss = 1.0 - p.area / (hm * wm);
            assert!((area_loss - BEVEL_AREA_LOSS).abs() < 1e-9, "{area_loss}");
            let stiffness_loss = 1.0 - p.i_height / (wm * hm.powi(3) / 12.0);
            assert!(
                (0.12..=0.22).contains(&stiffness_loss),
                "{}: {stiffness_loss}",
                s.label()
            );
        }
    }

    #[test]
    fn the_torsion_series_meets_the_square_and_the_thin_strip() {
        // Square: 0.1406 a⁴ (Roark).
        assert!((rectangle_torsion(1.0, 1.0) - 0.1406).abs() < 2e-4);
        // A thin strip: a b³ / 3 (1 − 0.63 b/a).
        let j = rectangle_torsion(10.0, 0.1);
        let strip = 10.0 * 0.001 / 3.0 * (1.0 - 0.63 * 0.01);
        assert!((j - strip).abs() / strip < 1e-3, "{j} {strip}");
    }

    #[test]
    fn sizes_out_of_range_are_refused() {
        assert!(WireSize::Rect(0.019, 0.025).check().is_ok());
        assert_eq!(
            WireSize::Round(f64::NAN)
                .check()
                .map_err(|e| e.to_string())
                .err()
                .map(|s| s.contains("positive")),
            Some(true)
        );
        assert!(WireSize::Round(0.5).check().is_err());
        assert!(WireSize::Rect(0.019, -0.025).check().is_err());
    }
}
