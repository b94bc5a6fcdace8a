//! Bracket prescriptions: the tip, torque, in-out and molar offset that a straight-wire
//! (pre-adjusted edgewise) appliance builds into each bracket and tube, so that a full-size wire,
//! once passive, holds every crown in its finished position.
//!
//! ## What the numbers mean
//!
//! - **Tip** (angulation, second order): the angle of the slot to the occlusal plane seen from the
//!   labial, in degrees. Positive means the crown is tipped mesially (the occlusal end of the
//!   crown's long axis lies mesial to its gingival end), as in Andrews' crown angulation.
//! - **Torque** (inclination, third order): the slot's built-in buccolingual twist, in degrees.
//!   Positive means labial/buccal crown torque (palatal/lingual root torque); negative means the
//!   crown is inclined lingually, as on every posterior tooth.
//! - **In-out** (first order, bracket prominence): how far the slot stands out from the crown's
//!   surface, in millimetres, measured beyond the thinnest bracket of the same arch (the canine).
//!   It lets a flat wire allow for the different labial prominence of each crown.
//! - **Offset** (first order rotation) of a molar tube, in degrees: positive is a distal offset,
//!   which turns the crown distal-in about its long axis (the mesiobuccal corner out), against the
//!   usual mesio-lingual rotation of molars. Brackets other than molar tubes carry 0 here, so the
//!   small Roth rotations on premolars (2° distal upper, 4° distal lower) and on the lower canine
//!   (2° mesial) are not modelled.
//!
//! Third molars are not part of either prescription; they reuse the second molars' tubes.
//!
//! ## Sources
//!
//! - **MBT**: McLaughlin RP, Bennett JC, Trevisi HJ, "A clinical review of the MBT orthodontic
//!   treatment program", *Orthodontic Perspectives* IV(2), 3M Unitek, 1997. The same values are
//!   restated as current in McLaughlin & Bennett's MB 5.0 pages (2019 onwards),
//!   <https://mclaughlin-bennett.com/about-mb-5-0/> (upper incisors, upper canines, lower canines,
//!   premolars and upper molars, lower molars) and in Bennett JC, McLaughlin RP, *Fundamentals of
//!   Orthodontic Treatment Mechanics*, LeGrande, 2014 (ISBN 978-0-9564555-2-9). Molar tube values
//!   agree with a manufacturer's listing (Saudent MBT .022 tubes: torque −14°/−20° first,
//!   −14°/−10° second molars, offset 10°/0°, <https://saudent1.odoo.com>).
//! - **Roth**: Roth RH, "Five year clinical evaluation of the Andrews straight-wire appliance",
//!   *J Clin Orthod* 10, 1976; Roth RH, "The straight-wire appliance 17 years later", *J Clin
//!   Orthod* 21(9):632–642, 1987; values as reproduced in Roth-philosophy teaching material (Roth
//!   versus Andrews lower-arch table) and in Moesi B, Dyer F, Benson PE, "Roth versus MBT",
//!   *Eur J Orthod*, doi:10.1093/ejo/cjr126, and Mittal M et al., *Angle Orthod*
//!   85(2):292–297, 2015, doi:10.2319/122313-941.
//! - **In-out**: no complete published in-out table could be confirmed (manufacturers differ).
//!   The values below are a representative approximation (within about 0.3 mm) anchored on two
//!   published facts: canines carry the thinnest brackets in each arch, and Andrews' research
//!   found the upper lateral incisor inset 0.55 mm from the central, an inset MBT deliberately
//!   reduces (McLaughlin & Bennett, "In-out reconsidered",
//!   <https://mclaughlin-bennett.com/about-mb-5-0/a-new-focus-on-in-out/>; Andrews LF, *Straight
//!   Wire: the Concept and Appliance*, L.A. Wells, 1989). Replace them with a chosen
//!   manufacturer's table when exact prominence matters.
//!
//! ## Where sources disagree
//!
//! Roth's lower second molar torque is −30° here (Roth's table); Andrews' standard set has −35°.
//! Some Roth catalogues give the lower molars 0° tip and 0° offset instead of −1° and 4° distal;
//! the values here follow Roth's own rationale table. MBT offers alternative canine torques
//! (0°, and the bracket inverted: +7° upper, +6° lower) and an inverted upper lateral (−10°); the
//! table holds the routine brackets.

pub use crate::teeth::case::appliance::Prescription;

use crate::teeth::{Arch, ToothKind};

/// What a prescription builds into one tooth's bracket or tube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BracketAngles {
    /// Mesial crown tip (degrees).
    pub tip_deg: f32,
    /// Buccal crown torque (degrees).
    pub torque_deg: f32,
    /// Slot's distance out from the crown's surface beyond the thinnest bracket (mm).
    pub in_out_mm: f32,
    /// Distal offset (rotation) built into a molar tube (degrees; 0 elsewhere).
    pub offset_deg: f32,
}

/// One table row: tip, torque, in-out, offset.
const fn row(tip_deg: f32, torque_deg: f32, in_out_mm: f32, offset_deg: f32) -> BracketAngles {
    BracketAngles {
        tip_deg,
        torque_deg,
        in_out_mm,
        offset_deg,
    }
}

impl Prescription {
    /// Every prescription, for pickers.
    pub const ALL: [Self; 2] = [Self::Mbt, Self::Roth];

    /// Its name as the viewer and reports show it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mbt => "MBT",
            Self::Roth => "Roth",
        }
    }

    /// The angles built into the bracket of a tooth of `kind` in `arch`.
    ///
    /// Third molars get the second molars' tube.
    pub fn angles(self, arch: Arch, kind: ToothKind) -> BracketAngles {
        use Arch::{Lower, Upper};
        use Prescription::{Mbt, Roth};
        use ToothKind::{
            Canine, CentralIncisor, FirstMolar, FirstPremolar, LateralIncisor, SecondMolar,
            SecondPremolar, ThirdMolar,
        };
        match (self, arch, kind) {
            // MBT, upper: tip, torque, in-out, offset.
            (Mbt, Upper, CentralIncisor) => row(4.0, 17.0, 0.4, 0.0),
            (Mbt, Upper, LateralIncisor) => row(8.0, 10.0, 0.7, 0.0),
            (Mbt, Upper, Canine) => row(8.0, -7.0, 0.0, 0.0),
            (Mbt, Upper, FirstPremolar) => row(0.0, -7.0, 0.2, 0.0),
            (Mbt, Upper, SecondPremolar) => row(0.0, -7.0, 0.2, 0.0),
            (Mbt, Upper, FirstMolar) => row(0.0, -14.0, 0.3, 10.0),
            (Mbt, Upper, SecondMolar | ThirdMolar) => row(0.0, -14.0, 0.3, 10.0),
            // MBT, lower.
            (Mbt, Lower, CentralIncisor) => row(0.0, -6.0, 0.6, 0.0),
            (Mbt, Lower, LateralIncisor) => row(0.0, -6.0, 0.6, 0.0),
            (Mbt, Lower, Canine) => row(3.0, -6.0, 0.0, 0.0),
            (Mbt, Lower, FirstPremolar) => row(2.0, -12.0, 0.2, 0.0),
            (Mbt, Lower, SecondPremolar) => row(2.0, -17.0, 0.3, 0.0),
            (Mbt, Lower, FirstMolar) => row(0.0, -20.0, 0.4, 0.0),
            (Mbt, Lower, SecondMolar | ThirdMolar) => row(0.0, -10.0, 0.4, 0.0),
            // Roth, upper.
            (Roth, Upper, CentralIncisor) => row(5.0, 12.0, 0.4, 0.0),
            (Roth, Upper, LateralIncisor) => row(9.0, 8.0, 0.95, 0.0),
            (Roth, Upper, Canine) => row(13.0, -2.0, 0.0, 0.0),
            (Roth, Upper, FirstPremolar) => row(0.0, -7.0, 0.2, 0.0),
            (Roth, Upper, SecondPremolar) => row(0.0, -7.0, 0.2, 0.0),
            (Roth, Upper, FirstMolar) => row(0.0, -14.0, 0.3, 14.0),
            (Roth, Upper, SecondMolar | ThirdMolar) => row(0.0, -14.0, 0.3, 14.0),
            // Roth, lower.
            (Roth, Lower, CentralIncisor) => row(2.0, -1.0, 0.6, 0.0),
            (Roth, Lower, LateralIncisor) => row(2.0, -1.0, 0.6, 0.0),
            (Roth, Lower, Canine) => row(7.0, -11.0, 0.0, 0.0),
            (Roth, Lower, FirstPremolar) => row(-1.0, -17.0, 0.2, 0.0),
            (Roth, Lower, SecondPremolar) => row(-1.0, -22.0, 0.3, 0.0),
            (Roth, Lower, FirstMolar) => row(-1.0, -30.0, 0.4, 4.0),
            (Roth, Lower, SecondMolar | ThirdMolar) => row(-1.0, -30.0, 0.4, 4.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-6
    }

    #[test]
    fn key_published_values() {
        let u1 = Prescription::Mbt.angles(Arch::Upper, ToothKind::CentralIncisor);
        assert!(
            close(u1.torque_deg, 17.0) && close(u1.tip_deg, 4.0),
            "{u1:?}"
        );
        let r1 = Prescription::Roth.angles(Arch::Upper, ToothKind::CentralIncisor);
        assert!(
            close(r1.torque_deg, 12.0) && close(r1.tip_deg, 5.0),
            "{r1:?}"
        );
        // The documented MBT changes: less upper canine tip, more lower incisor lingual torque.
        let tip = |p: Prescription| p.angles(Arch::Upper, ToothKind::Canine).tip_deg;
        assert!(close(tip(Prescription::Mbt), 8.0) && close(tip(Prescription::Roth), 13.0));
        let l1 = |p: Prescription| p.angles(Arch::Lower, ToothKind::CentralIncisor).torque_deg;
        assert!(close(l1(Prescription::Mbt), -6.0) && close(l1(Prescription::Roth), -1.0));
        let u6 = |p: Prescription| p.angles(Arch::Upper, ToothKind::FirstMolar).offset_deg;
        assert!(close(u6(Prescription::Mbt), 10.0) && close(u6(Prescription::Roth), 14.0));
    }

    #[test]
    fn roth_lower_first_molar_is_the_most_lingually_torqued() {
        let first = Prescription::Roth
            .angles(Arch::Lower, ToothKind::FirstMolar)
            .torque_deg;
        for kind in ToothKind::ALL {
            let torque = Prescription::Roth.angles(Arch::Lower, kind).torque_deg;
            assert!(
                torque >= first,
                "{kind:?} torque {torque} below first molar {first}"
            );
        }
    }

    #[test]
    fn every_value_is_plausible() {
        for p in Prescription::ALL {
            for arch in [Arch::Upper, Arch::Lower] {
                for kind in ToothKind::ALL {
                    let a = p.angles(arch, kind);
                    let what = format!("{} {arch:?} {kind:?}: {a:?}", p.name());
                    for deg in [a.tip_deg, a.torque_deg, a.offset_deg] {
                        assert!(deg.is_finite() && deg.abs() <= 35.0, "{what}");
                    }
                    assert!(a.in_out_mm.is_finite(), "{what}");
                    assert!((0.0..2.0).contains(&a.in_out_mm), "{what}");
                    assert!(a.offset_deg >= 0.0, "{what}");
                    if !kind.is_molar() {
                        assert!(close(a.offset_deg, 0.0), "{what}");
                    }
                    if kind.is_posterior() {
                        assert!(a.torque_deg < 0.0, "{what}");
                    }
                }
                // Canines carry the thinnest bracket of each arch.
                let canine = p.angles(arch, ToothKind::Canine).in_out_mm;
                assert!(
                    ToothKind::ALL
                        .iter()
                        .all(|&k| p.angles(arch, k).in_out_mm >= canine)
                );
                // Third molars reuse the second molars' tube.
                let second = p.angles(arch, ToothKind::SecondMolar);
                assert_eq!(p.angles(arch, ToothKind::ThirdMolar), second);
            }
        }
    }

    #[test]
    fn names_and_serde() {
        assert_eq!(Prescription::default(), Prescription::Mbt);
        assert_eq!(Prescription::ALL.map(Prescription::name), ["MBT", "Roth"]);
        for p in Prescription::ALL {
            let json = serde_json::to_string(&p).expect("a unit variant serialises");
            let back: Prescription = serde_json::from_str(&json).expect("and reads back");
            assert_eq!(back, p);
        }
        assert_eq!(
            serde_json::to_string(&Prescription::Roth).ok().as_deref(),
            Some("\"roth\"")
        );
    }
}
