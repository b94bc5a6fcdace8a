//! FDI two-digit tooth numbers and tooth kinds.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use thiserror::Error;

/// A permanent tooth's FDI (ISO 3950) number: quadrant 1–4 then position 1–8 from the midline.
/// Quadrant 1 is the upper right, 2 upper left, 3 lower left, 4 lower right (the patient's sides).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Fdi(u8);

/// A number that is not a permanent tooth's FDI number.
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
#[error("{0} is not an FDI tooth number (11–18, 21–28, 31–38, 41–48)")]
pub struct InvalidFdi(pub i64);

/// Upper (maxillary) or lower (mandibular) arch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Arch {
    /// Maxillary arch.
    Upper,
    /// Mandibular arch.
    Lower,
}

impl Arch {
    /// The other arch.
    pub fn opposing(self) -> Self {
        match self {
            Arch::Upper => Arch::Lower,
            Arch::Lower => Arch::Upper,
        }
    }
}

/// The patient's right or left side.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Patient's right (world −x).
    Right,
    /// Patient's left (world +x).
    Left,
}

/// The eight kinds of permanent tooth in each quadrant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToothKind {
    /// Position 1.
    CentralIncisor,
    /// Position 2.
    LateralIncisor,
    /// Position 3.
    Canine,
    /// Position 4.
    FirstPremolar,
    /// Position 5.
    SecondPremolar,
    /// Position 6.
    FirstMolar,
    /// Position 7.
    SecondMolar,
    /// Position 8.
    ThirdMolar,
}

impl ToothKind {
    /// All kinds, from the midline backwards.
    pub const ALL: [ToothKind; 8] = [
        ToothKind::CentralIncisor,
        ToothKind::LateralIncisor,
        ToothKind::Canine,
        ToothKind::FirstPremolar,
        ToothKind::SecondPremolar,
        ToothKind::FirstMolar,
        ToothKind::SecondMolar,
        ToothKind::ThirdMolar,
    ];

    /// The kind at position 1–8 in a quadrant.
    pub fn from_position(position: u8) -> Option<Self> {
        Self::ALL.get((position as usize).checked_sub(1)?).copied()
    }

    /// Position 1–8 in the quadrant.
    pub fn position(self) -> u8 {
        self as u8 + 1
    }

    /// True for premolars and molars (teeth with an occlusal table).
    pub fn is_posterior(self) -> bool {
        self >= ToothKind::FirstPremolar
    }

    /// True for molars.
    pub fn is_molar(self) -> bool {
        self >= ToothKind::FirstMolar
    }

    /// The snake_case name used in files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            ToothKind::CentralIncisor => "central_incisor",
            ToothKind::LateralIncisor => "lateral_incisor",
            ToothKind::Canine => "canine",
            ToothKind::FirstPremolar => "first_premolar",
            ToothKind::SecondPremolar => "second_premolar",
            ToothKind::FirstMolar => "first_molar",
            ToothKind::SecondMolar => "second_molar",
            ToothKind::ThirdMolar => "third_molar",
        }
    }
}

impl Fdi {
    /// Validates an FDI number.
    pub fn new(n: i64) -> Result<Self, InvalidFdi> {
        let (q, p) = (n / 10, n % 10);
        if (1..=4).contains(&q) && (1..=8).contains(&p) {
            Ok(Self(n as u8))
        } else {
            Err(InvalidFdi(n))
        }
    }

    /// From quadrant 1–4 and position 1–8.
    pub fn from_parts(quadrant: u8, position: u8) -> Result<Self, InvalidFdi> {
        Self::new(quadrant as i64 * 10 + position as i64)
    }

    /// All 32 permanent teeth, quadrant by quadrant.
    pub fn all() -> impl Iterator<Item = Fdi> {
        (1..=4u8).flat_map(|q| (1..=8u8).map(move |p| Fdi(q * 10 + p)))
    }

    /// The two-digit number.
    pub fn number(self) -> u8 {
        self.0
    }

    /// Quadrant 1–4.
    pub fn quadrant(self) -> u8 {
        self.0 / 10
    }

    /// Position 1–8 from the midline.
    pub fn position(self) -> u8 {
        self.0 % 10
    }

    /// The arch it belongs to.
    pub fn arch(self) -> Arch {
        if self.quadrant() <= 2 {
            Arch::Upper
        } else {
            Arch::Lower
        }
    }

    /// The patient's side.
    pub fn side(self) -> Side {
        match self.quadrant() {
            1 | 4 => Side::Right,
            _ => Side::Left,
        }
    }

    /// The kind of tooth.
    pub fn kind(self) -> ToothKind {
        ToothKind::ALL[self.position() as usize - 1]
    }

    /// The same tooth on the other side of the same arch (11 ↔ 21, 36 ↔ 46).
    pub fn mirror(self) -> Fdi {
        let q = match self.quadrant() {
            1 => 2,
            2 => 1,
            3 => 4,
            _ => 3,
        };
        Fdi(q * 10 + self.position())
    }

    /// The tooth at the same position and side in the other arch (16 ↔ 46, 21 ↔ 31).
    pub fn antagonist(self) -> Fdi {
        let q = match self.quadrant() {
            1 => 4,
            2 => 3,
            3 => 2,
            _ => 1,
        };
        Fdi(q * 10 + self.position())
    }

    /// The neighbour one position further from the midline, if any.
    pub fn distal_neighbour(self) -> Option<Fdi> {
        (self.position() < 8).then_some(Fdi(self.0 + 1))
    }

    /// The neighbour towards the midline; for a central incisor, the other central incisor.
    pub fn mesial_neighbour(self) -> Fdi {
        if self.position() == 1 {
            self.mirror()
        } else {
            Fdi(self.0 - 1)
        }
    }

    /// The sign that makes the tooth's local +x axis point mesially, for teeth placed on an arch
    /// (local x = occlusal × buccal, so it points mesially on some quadrants and distally on others).
    pub fn local_x_mesial_sign(self) -> f32 {
        match (self.arch(), self.side()) {
            (Arch::Lower, Side::Left) | (Arch::Upper, Side::Right) => -1.0,
            _ => 1.0,
        }
    }

    /// Signed index along the arch from the patient's right end (−8) through the midline to the
    /// left end (+8), skipping zero; adjacent teeth differ by 1 (or 2 across the midline).
    pub fn arch_index(self) -> i8 {
        let p = self.position() as i8;
        match self.side() {
            Side::Right => -p,
            Side::Left => p,
        }
    }
}

impl fmt::Display for Fdi {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl TryFrom<i64> for Fdi {
    type Error = InvalidFdi;
    fn try_from(n: i64) -> Result<Self, InvalidFdi> {
        Self::new(n)
    }
}

impl Serialize for Fdi {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u8(self.0)
    }
}

impl<'de> Deserialize<'de> for Fdi {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let n = i64::deserialize(d)?;
        Fdi::new(n).map_err(|e| serde::de::Error::custom(format!("unknown tooth: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valid_and_invalid_numbers() {
        assert_eq!(Fdi::all().count(), 32);
        for bad in [0, 9, 10, 19, 20, 29, 30, 39, 40, 49, 50, 51, -11, 110] {
            assert!(Fdi::new(bad).is_err(), "{bad} accepted");
        }
        let t = Fdi::new(36).unwrap();
        assert_eq!((t.quadrant(), t.position()), (3, 6));
        assert_eq!(t.arch(), Arch::Lower);
        assert_eq!(t.side(), Side::Left);
        assert_eq!(t.kind(), ToothKind::FirstMolar);
        assert_eq!(t.mirror().number(), 46);
        assert_eq!(t.antagonist().number(), 26);
        assert_eq!(Fdi::new(11).unwrap().side(), Side::Right);
        assert_eq!(Fdi::new(11).unwrap().mesial_neighbour().number(), 21);
        assert_eq!(Fdi::new(18).unwrap().distal_neighbour(), None);
        assert_eq!(Fdi::new(41).unwrap().arch_index(), -1);
    }
}
