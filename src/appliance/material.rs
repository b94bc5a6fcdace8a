//! Archwire alloys: stainless steel, β-titanium (TMA), superelastic and copper NiTi.
//!
//! Steel and TMA are linear elastic up to their yield (which orthodontic activations stay below;
//! orthosim does not model permanent set). Superelastic NiTi follows a flag-shaped law in bending:
//! austenite's modulus up to the loading plateau, a near-flat plateau while it transforms, and on
//! the way back a lower (unloading) plateau, so a deflected NiTi wire pushes teeth with the
//! unloading plateau's force, nearly constant over millimetres of movement. The law is written on
//! the bending curvature's magnitude, as moment over the section's elastic moment
//! ([`WireMaterial::bending_scale`]); see `rod.rs` for how the rod uses it.
//!
//! Sources for the moduli: Kusy's wire property studies (steel 193–200 GPa nominal, measured wires
//! about 20 % lower; orthosim takes 180 GPa), Burstone & Goldberg AJO 1980;77:121 (TMA 69–72 GPa;
//! 69 GPa taken). NiTi's austenite modulus, plateau strains and the ratio of its plateaus are
//! typical of orthodontic superelastic wires (austenite about 40 GPa, loading plateau from 1 %
//! strain at about 390 MPa, unloading plateau about 0.4 of the loading plateau); the plateau
//! heights are set so that a 0.016" wire in the three-bracket test (ISO 15841) unloads at about
//! 1.0–1.5 N at 2 mm, as measured across brands (Materials Research 2015).

use serde::{Deserialize, Serialize};

/// An archwire's alloy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WireMaterial {
    /// Austenitic stainless steel.
    #[default]
    StainlessSteel,
    /// β-titanium (TMA).
    Tma,
    /// Superelastic nickel–titanium.
    NiTi,
    /// Copper NiTi (thermally activated at mouth temperature): lower plateaus than NiTi.
    CopperNiTi,
}

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

    /// The outer-fibre strains of the flag: (loading plateau starts, transformation complete),
    /// and the plateaus' moments as shares of the elastic moment at the loading plateau's start:
    /// (loading plateau, unloading plateau).
    fn flag(self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::CopperNiTi => ([0.0085, 0.06], [1.0, 0.40]),
            _ => ([0.0100, 0.06], [1.0, 0.40]),
        }
    }

    /// The bending moment as a share of the linear-elastic moment `E I κ` at curvature magnitude
    /// `curvature` (1/mm) for a section whose outer fibre lies `half_height` mm from its neutral
    /// axis, given the element's transformation state: 1 for steel and TMA; for NiTi, below 1
    /// once on a plateau (the loading plateau while the curvature exceeds the state's peak, else
    /// the unloading branch). The plateaus rise by 5 % of the elastic slope (a flag's plateaus
    /// are not quite flat), which also keeps the rod's equilibrium unique.
    pub fn bending_scale(self, curvature: f64, half_height: f64, state: &Transformation) -> f64 {
        if !self.superelastic() || curvature <= 0.0 {
            return 1.0;
        }
        let ([load, _end], [m_load, m_unload]) = self.flag();
        // The unloading plateau meets the elastic line where its moment is the elastic one.
        let unload = m_unload * load;
        let strain = curvature * half_height;
        let slope = 0.05;
        let peak = (state.peak_curvature * half_height).max(strain);
        // Loading branch: elastic to `load`, then the plateau.
        let loading = |e: f64| {
            if e <= load {
                e
            } else {
                m_load * load + slope * (e - load)
            }
        };
        let moment = if strain >= peak - 1e-12 || peak <= load {
            loading(strain)
        } else {
            // Unloading from `peak`: elastic drop until the unloading plateau, along it back to
            // where it meets the elastic line at `unload`, then elastic.
            let plateau = unload + slope * (strain - unload);
            let back = loading(peak) - (peak - strain);
            if strain <= unload {
                strain
            } else {
                back.max(plateau)
            }
        };
        (moment / strain).clamp(0.0, 1.0)
    }

    /// The element's state after it was bent to `curvature`.
    pub fn advance(self, state: &mut Transformation, curvature: f64, half_height: f64) {
        if !self.superelastic() {
            return;
        }
        let ([load, _], [_, m_unload]) = self.flag();
        let unload = m_unload * load;
        if curvature * half_height <= unload {
            // Back on the elastic line: austenite again.
            state.peak_curvature = curvature;
        } else {
            state.peak_curvature = state.peak_curvature.max(curvature);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steel_and_tma_are_linear_and_niti_makes_a_flag() {
        let fresh = Transformation::default();
        assert_eq!(
            WireMaterial::StainlessSteel.bending_scale(0.1, 0.2, &fresh),
            1.0
        );
        let m = WireMaterial::NiTi;
        let h = 0.2;
        // Elastic below the plateau.
        assert!((m.bending_scale(0.004 / h, h, &fresh) - 1.0).abs() < 1e-12);
        // On the loading plateau: the moment nearly flat.
        let moment = |e: f64, s: &Transformation| m.bending_scale(e / h, h, s) * e;
        let (a, b) = (moment(0.02, &fresh), moment(0.04, &fresh));
        assert!(b > a && b < 1.2 * a, "{a} {b}");
        // Unloading from 4 % strain: lower than loading at the same strain, and its own plateau.
        let mut state = Transformation::default();
        m.advance(&mut state, 0.04 / h, h);
        let (u2, u3) = (moment(0.02, &state), moment(0.03, &state));
        assert!(u2 < 0.6 * a, "unloading {u2} against loading {a}");
        assert!(u3 > u2 && u3 < 1.2 * u2, "{u2} {u3}");
        // Back below the unloading plateau's end: elastic again.
        assert!((m.bending_scale(0.003 / h, h, &state) - 1.0).abs() < 1e-12);
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
