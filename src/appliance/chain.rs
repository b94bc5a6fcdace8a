//! Elastomeric chain ("power chain") stretched along the brackets from one tooth to another: a
//! tension that follows the chain's stretch and decays over days as the elastomer relaxes.
//!
//! **Force.** Linear in the strain ε = (L − L₀)/L₀ of the chain's length L along the brackets'
//! slots (L₀ its relaxed length): [`N_PER_STRAIN`] × ε, 3 N at 50 % (Buchmann et al., Angle
//! Orthod 2012;82:529–35: 2.3–4.1 N at 50 % across brands); slack (L ≤ L₀) pulls nothing.
//!
//! **Decay.** The force at a given stretch falls to the fraction
//! `0.35 + 0.40·e^(−t/0.5 d) + 0.25·e^(−t/10 d)` of its first value after t days: about 37 % lost in
//! the first day and 62 % by day 21 (Buchmann: 37–75 % lost by day 21; Mousavi et al., Dent Res J
//! 2020: 3.97 N to 1.29 N in four weeks, 68 %).
//!
//! **Loads.** The chain runs through each bracket it passes; each takes the tension along the
//! chain's run on both sides (the ends on one), so the chain's forces always sum to zero.

use glam::DVec3;

/// Tension per unit strain (N): 3 N at 50 %.
pub const N_PER_STRAIN: f64 = 6.0;

/// The fraction of its first force a chain keeps after `days` at a fixed stretch.
pub fn remaining_fraction(days: f64) -> f64 {
    let t = days.max(0.0);
    0.35 + 0.40 * (-t / 0.5).exp() + 0.25 * (-t / 10.0).exp()
}

/// The tension (N) of a chain of relaxed length `relaxed` stretched to `length` (mm), `days`
/// after it was placed.
pub fn tension_n(length: f64, relaxed: f64, days: f64) -> f64 {
    if relaxed <= 0.0 || length <= relaxed {
        return 0.0;
    }
    N_PER_STRAIN * (length - relaxed) / relaxed * remaining_fraction(days)
}

/// The length of a chain through `points` (mm).
pub fn length(points: &[DVec3]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The force on each of `points` from a chain through them under `tension` (N).
pub fn forces(points: &[DVec3], tension: f64) -> Vec<DVec3> {
    let mut out = vec![DVec3::ZERO; points.len()];
    for (i, w) in points.windows(2).enumerate() {
        let d = w[1] - w[0];
        let len = d.length();
        if len < 1e-9 {
            continue;
        }
        let pull = d / len * tension;
        out[i] += pull;
        out[i + 1] -= pull;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chain_relaxes_as_published_and_pulls_only_when_stretched() {
        assert!((remaining_fraction(0.0) - 1.0).abs() < 1e-12);
        let day1 = remaining_fraction(1.0);
        let day21 = remaining_fraction(21.0);
        assert!((0.55..0.75).contains(&day1), "{day1}");
        assert!((0.25..0.65).contains(&day21), "{day21}");
        assert!(remaining_fraction(60.0) < day21);
        // 3 N at 50 % when placed; nothing slack.
        assert!((tension_n(15.0, 10.0, 0.0) - 3.0).abs() < 1e-12);
        assert_eq!(tension_n(9.0, 10.0, 0.0), 0.0);
    }

    #[test]
    fn a_chain_draws_its_ends_together_and_its_forces_balance() {
        let points = [
            DVec3::new(-7.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(7.0, 0.0, 0.0),
        ];
        let f = forces(&points, 2.0);
        let sum: DVec3 = f.iter().copied().sum();
        assert!(sum.length() < 1e-12);
        assert!(f[0].x > 0.0 && f[2].x < 0.0);
        // The middle bracket is pulled in towards the chord.
        assert!(f[1].z < 0.0 && f[1].x.abs() < 1e-12);
        assert!((f[0].length() - 2.0).abs() < 1e-12);
    }
}
