//! Archwire alloys: stainless steel, β-titanium (TMA), superelastic and copper NiTi.
//!
//! Steel and TMA are linear elastic up to their yield (which orthodontic activations stay below;
//! orthosim does not model permanent set). Superelastic NiTi follows a flag-shaped stress–strain
//! law: austenite's modulus up to the loading plateau, a near-flat plateau while it transforms to
//! martensite, and on the way back a lower (unloading) plateau, so a deflected NiTi wire pushes
//! teeth with a force nearly constant over millimetres of movement. Each fibre of the section
//! follows the law from its own peak strain; the bending moment is the law integrated over the
//! section (round: a circle; rectangular: its height), given as a share of the elastic moment
//! ([`WireMaterial::bending_scale`]). An element remembers the largest curvature it was bent to
//! ([`Transformation`]) until it is back on the elastic line.
//!
//! Sources for the moduli: Kusy's wire property studies (steel 193–200 GPa nominal, measured wires
//! about 20 % lower; orthosim takes 180 GPa), Burstone & Goldberg AJO 1980;77:121 (TMA 69–72 GPa;
//! 69 GPa taken). NiTi's flag (austenite 40 GPa, loading plateau from 1.25 % strain, unloading
//! plateau at 0.6 of the loading plateau's stress, plateau end 6 %) is typical of orthodontic
//! superelastic wires, its heights set so that a 0.016" wire in the three-bracket test (ISO 15841)
//! unloads at about 1.0–1.5 N at 2 mm, as measured across brands (Materials Research 2015);
//! copper NiTi's plateaus are lower.

pub use crate::teeth::case::appliance::WireMaterial;

use super::section::WireSize;

/// Where a NiTi element stands on its flag-shaped law, kept between solves.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Transformation {
    /// The largest bending curvature (1/mm) this element has been loaded to since it was last
    /// fully austenitic.
    pub peak_curvature: f64,
}

impl WireMaterial {
    /// Every alloy, for pickers.
    pub const ALL: [Self; 4] = [
        Self::StainlessSteel,
        Self::Tma,
        Self::NiTi,
        Self::CopperNiTi,
    ];

    /// Its name as reports and the viewer show it.
    pub fn name(self) -> &'static str {
        match self {
            Self::StainlessSteel => "stainless steel",
            Self::Tma => "TMA",
            Self::NiTi => "NiTi",
            Self::CopperNiTi => "copper NiTi",
        }
    }

    /// Young's modulus (N/mm², i.e. MPa): the elastic (austenite) modulus for NiTi.
    pub fn young(self) -> f64 {
        match self {
            Self::StainlessSteel => 180_000.0,
            Self::Tma => 69_000.0,
            Self::NiTi => 40_000.0,
            Self::CopperNiTi => 35_000.0,
        }
    }

    /// Poisson's ratio.
    pub fn poisson(self) -> f64 {
        match self {
            Self::StainlessSteel => 0.3,
            Self::Tma => 0.34,
            Self::NiTi | Self::CopperNiTi => 0.33,
        }
    }

    /// Shear modulus (N/mm²).
    pub fn shear(self) -> f64 {
        self.young() / (2.0 * (1.0 + self.poisson()))
    }

    /// True for the superelastic alloys.
    pub fn superelastic(self) -> bool {
        matches!(self, Self::NiTi | Self::CopperNiTi)
    }

    /// The flag as strains (stress over austenite's modulus): where the loading plateau starts,
    /// the unloading plateau's height as a share of the loading one's, and where transformation
    /// ends.
    fn flag(self) -> (f64, f64, f64) {
        match self {
            Self::CopperNiTi => (0.0105, 0.55, 0.06),
            _ => (0.0125, 0.60, 0.06),
        }
    }

    /// A fibre's stress over austenite's modulus (a strain) at `strain` (≥ 0) after a peak strain
    /// of `peak`: elastic, then the loading plateau (rising by [`PLATEAU_SLOPE`] of the elastic
    /// slope; past the transformation's end, by half of it); below the peak, the elastic line down
    /// from the peak's stress to the unloading plateau, along it, and elastic again where it meets
    /// the elastic line.
    fn fibre(self, strain: f64, peak: f64) -> f64 {
        let (load, ratio, end) = self.flag();
        let loading = |e: f64| {
            if e <= load {
                e
            } else if e <= end {
                load + PLATEAU_SLOPE * (e - load)
            } else {
                load + PLATEAU_SLOPE * (end - load) + 0.5 * (e - end)
            }
        };
        let peak = peak.max(strain);
        if peak <= load || strain >= peak {
            return loading(strain);
        }
        let unload = ratio * load;
        if strain <= unload {
            return strain;
        }
        let back = loading(peak) - (peak - strain);
        let plateau = unload + PLATEAU_SLOPE * (strain - unload);
        back.max(plateau).min(loading(strain))
    }

    /// The bending moment as a share of the linear-elastic moment `E I κ` at curvature magnitude
    /// `curvature` (1/mm) for a section of wire `size`, after the element's `state`: 1 for steel
    /// and TMA; for NiTi, the flag integrated over the section (48 strips across its height).
    pub fn bending_scale(self, curvature: f64, size: WireSize, state: &Transformation) -> f64 {
        if !self.superelastic() || curvature <= 0.0 {
            return 1.0;
        }
        let half = 0.5 * size.height_mm();
        let (load, _, _) = self.flag();
        if curvature.max(state.peak_curvature) * half <= load {
            return 1.0;
        }
        let strips = 48;
        let (mut moment, mut elastic) = (0.0, 0.0);
        for k in 0..strips {
            let y = half * (k as f64 + 0.5) / strips as f64;
            let width = match size {
                WireSize::Round(_) => (half * half - y * y).max(0.0).sqrt(),
                WireSize::Rect(..) => 1.0,
            };
            let e = curvature * y;
            moment += self.fibre(e, state.peak_curvature * y) * y * width;
            elastic += e * y * width;
        }
        (moment / elastic).clamp(0.0, 1.0)
    }

    /// The element's state after it was bent to `curvature` with wire `size`.
    pub fn advance(self, state: &mut Transformation, curvature: f64, size: WireSize) {
        if !self.superelastic() {
            return;
        }
        let (load, ratio, _) = self.flag();
        if curvature * 0.5 * size.height_mm() <= ratio * load {
            // Back on the elastic line in every fibre: austenite again.
            state.peak_curvature = curvature;
        } else {
            state.peak_curvature = state.peak_curvature.max(curvature);
        }
    }
}

/// Slope of NiTi's plateaus as a share of austenite's modulus (plateaus are not quite flat; the
/// slope also keeps the wire's equilibrium unique).
pub const PLATEAU_SLOPE: f64 = 0.02;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steel_and_tma_are_linear_and_niti_makes_a_flag() {
        let fresh = Transformation::default();
        let size = WireSize::Round(0.016);
        let h = 0.5 * size.height_mm();
        assert_eq!(
            WireMaterial::StainlessSteel.bending_scale(0.1, size, &fresh),
            1.0
        );
        let m = WireMaterial::NiTi;
        // Elastic below the plateau.
        assert!((m.bending_scale(0.008 / h, size, &fresh) - 1.0).abs() < 1e-12);
        // On the loading plateau the moment rises slowly (the elastic core shrinks).
        let moment = |e: f64, s: &Transformation| m.bending_scale(e / h, size, s) * e;
        let (a, b) = (moment(0.02, &fresh), moment(0.04, &fresh));
        assert!(b > a && b < 1.4 * a, "{a} {b}");
        // Unloading from 4 % strain: lower than loading at the same strain.
        let mut state = Transformation::default();
        m.advance(&mut state, 0.04 / h, size);
        let (u2, u3) = (moment(0.02, &state), moment(0.03, &state));
        assert!(u2 < 0.7 * a, "unloading {u2} against loading {a}");
        assert!(u3 > u2, "{u2} {u3}");
        // Back on the elastic line below the unloading plateau.
        assert!((m.bending_scale(0.004 / h, size, &state) - 1.0).abs() < 1e-9);
        // The moment never rises on the way back down.
        let mut last = f64::INFINITY;
        for k in (1..=40).rev() {
            let e = 0.001 * k as f64;
            let v = moment(e, &state);
            assert!(v <= last + 1e-12, "at {e}: {v} after {last}");
            last = v;
        }
    }

    #[test]
    fn moduli_are_the_sources() {
        assert!(
            (WireMaterial::Tma.young() / WireMaterial::StainlessSteel.young() - 0.383).abs() < 0.01
        );
        assert!(WireMaterial::ALL.iter().all(|m| m.shear() < m.young()));
    }
}
