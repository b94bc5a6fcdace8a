//! Intermaxillary elastics: latex bands hooked from a bracket of one arch to a bracket or tube of
//! the other (Class II: upper canine to lower first molar; Class III: lower canine to upper
//! first molar), worn full time and changed daily.
//!
//! An elastic is sold by the force it gives stretched to [`RATED_STRETCH`] times its lumen (its
//! relaxed inside diameter), the stretch it is chosen to be worn at; its force is linear in its
//! extension beyond the lumen (latex over the working range). Changed every day, as patients
//! are told, it keeps its rating from day to day; the loss within a day (about a quarter in the
//! first hours, Kanchana & Godfrey, AJODO 2000) is not modelled.

use glam::DVec3;

/// The stretch, in lumens, at which an elastic's rated force is given and at which it is worn.
pub const RATED_STRETCH: f64 = 3.0;

/// The force (N) of an elastic rated `rating_n` and worn at `placed_mm` (taken as its rated
/// stretch) when its hooks are `length_mm` apart: zero once it is back to its lumen.
pub fn force_n(rating_n: f64, placed_mm: f64, length_mm: f64) -> f64 {
    let lumen = placed_mm / RATED_STRETCH;
    if placed_mm <= lumen || !length_mm.is_finite() {
        return 0.0;
    }
    (rating_n * (length_mm - lumen) / (placed_mm - lumen)).max(0.0)
}

/// The forces on the hooks at `a` and `b` of an elastic pulling with `force_n`: each towards the
/// other.
pub fn end_forces(a: DVec3, b: DVec3, force_n: f64) -> [DVec3; 2] {
    let d = (b - a).normalize_or_zero() * force_n;
    [d, -d]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_elastic_gives_its_rating_where_worn_and_slackens_to_its_lumen() {
        assert!((force_n(1.5, 24.0, 24.0) - 1.5).abs() < 1e-12);
        // Half its extension: half its force; shorter than its lumen: none.
        assert!((force_n(1.5, 24.0, 16.0) - 0.75).abs() < 1e-12);
        assert_eq!(force_n(1.5, 24.0, 7.0), 0.0);
        assert!(force_n(1.5, 24.0, 30.0) > 1.5);
        let [fa, fb] = end_forces(DVec3::ZERO, DVec3::new(0.0, 0.0, 10.0), 2.0);
        assert_eq!(fa, DVec3::new(0.0, 0.0, 2.0));
        assert_eq!(fa + fb, DVec3::ZERO);
    }
}
