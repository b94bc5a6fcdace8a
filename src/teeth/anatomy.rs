//! Average dimensions of the permanent teeth.
//!
//! Source: Ash and Nelson, *Wheeler's Dental Anatomy, Physiology and Occlusion* (8th ed., 2003),
//! table "Measurements of the teeth: specifications for drawing and carving teeth of average size"
//! (millimetres). For molars with buccal and lingual roots of different lengths, the table's longer
//! (lingual/palatal) root length is used. Root counts follow the usual textbook forms: upper first
//! premolar 2, upper molars 3, lower molars 2, all others 1.

use super::fdi::{Arch, ToothKind};

/// Average dimensions of one tooth type (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToothAnatomy {
    /// Cervico-incisal / cervico-occlusal crown length.
    pub crown_length: f32,
    /// Root length from the cementoenamel junction to the apex.
    pub root_length: f32,
    /// Mesiodistal crown width at the contact areas.
    pub mesiodistal: f32,
    /// Mesiodistal width at the cervix.
    pub mesiodistal_cervix: f32,
    /// Buccolingual (labiolingual) crown width at the height of contour.
    pub buccolingual: f32,
    /// Buccolingual width at the cervix.
    pub buccolingual_cervix: f32,
    /// Number of roots (1–4).
    pub roots: u8,
}

const fn a(
    crown_length: f32,
    root_length: f32,
    mesiodistal: f32,
    mesiodistal_cervix: f32,
    buccolingual: f32,
    buccolingual_cervix: f32,
    roots: u8,
) -> ToothAnatomy {
    ToothAnatomy {
        crown_length,
        root_length,
        mesiodistal,
        mesiodistal_cervix,
        buccolingual,
        buccolingual_cervix,
        roots,
    }
}

/// Maxillary teeth, central incisor to third molar (Wheeler's table).
const UPPER: [ToothAnatomy; 8] = [
    a(10.5, 13.0, 8.5, 7.0, 7.0, 6.0, 1),
    a(9.0, 13.0, 6.5, 5.0, 6.0, 5.0, 1),
    a(10.0, 17.0, 7.5, 5.5, 8.0, 7.0, 1),
    a(8.5, 14.0, 7.0, 5.0, 9.0, 8.0, 2),
    a(8.5, 14.0, 7.0, 5.0, 9.0, 8.0, 1),
    a(7.5, 13.0, 10.0, 8.0, 11.0, 10.0, 3),
    a(7.0, 12.0, 9.0, 7.0, 11.0, 10.0, 3),
    a(6.5, 11.0, 8.5, 6.5, 10.0, 9.5, 3),
];

/// Mandibular teeth, central incisor to third molar (Wheeler's table).
const LOWER: [ToothAnatomy; 8] = [
    a(9.0, 12.5, 5.0, 3.5, 6.0, 5.3, 1),
    a(9.5, 14.0, 5.5, 4.0, 6.5, 5.8, 1),
    a(11.0, 16.0, 7.0, 5.5, 7.5, 7.0, 1),
    a(8.5, 14.0, 7.0, 5.0, 7.5, 6.5, 1),
    a(8.0, 14.5, 7.0, 5.0, 8.0, 7.0, 1),
    a(7.5, 14.0, 11.0, 9.0, 10.5, 9.0, 2),
    a(7.0, 13.0, 10.5, 8.0, 10.0, 9.0, 2),
    a(7.0, 11.0, 10.0, 7.5, 9.5, 9.0, 2),
];

/// The average anatomy of a tooth kind in an arch.
pub fn anatomy(arch: Arch, kind: ToothKind) -> ToothAnatomy {
    let table = match arch {
        Arch::Upper => &UPPER,
        Arch::Lower => &LOWER,
    };
    table[kind as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_counts_follow_the_textbook_forms() {
        for kind in ToothKind::ALL {
            let up = anatomy(Arch::Upper, kind).roots;
            let low = anatomy(Arch::Lower, kind).roots;
            let (eu, el) = match kind {
                ToothKind::FirstPremolar => (2, 1),
                k if k.is_molar() => (3, 2),
                _ => (1, 1),
            };
            assert_eq!((up, low), (eu, el), "{kind:?}");
        }
    }

    #[test]
    fn bolton_ratios_of_the_table_are_near_the_norms() {
        let sum = |arch, n: usize| -> f32 {
            ToothKind::ALL[..n]
                .iter()
                .map(|&k| 2.0 * anatomy(arch, k).mesiodistal)
                .sum()
        };
        let anterior = sum(Arch::Lower, 3) / sum(Arch::Upper, 3) * 100.0;
        let overall = sum(Arch::Lower, 6) / sum(Arch::Upper, 6) * 100.0;
        assert!((anterior - 77.2).abs() < 1.5, "anterior ratio {anterior}");
        assert!((overall - 91.3).abs() < 1.5, "overall ratio {overall}");
    }
}
