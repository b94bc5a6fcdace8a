//! Friction between an archwire and a bracket's slot: the coefficient of each wire and bracket
//! material, the force each ligation presses the wire into the slot with, and the normal force
//! at the slot that friction is drawn from.
//!
//! **Model.** Coulomb friction at the slot: the wire resists sliding along the slot with a
//! force of at most μ·N, and holds (no sliding) below it. N is the sum of the slot's normal
//! forces:
//! - across the slot's height, the wire's force across it or, when the wire is angled in the
//!   slot past its play, the couple of the two diagonal corners it binds on: max(|F|, 2|M|/w)
//!   for a bracket w wide (second-order binding, Kusy's critical contact angle);
//! - into the slot's depth, the same with the first-order angle;
//! - for a rectangular wire twisted against the slot's walls, the couple of its edges on them:
//!   2|M|/(wire's width into the slot);
//! - the ligation's seating force, pressing the wire onto the slot's floor.
//!
//! Guarantee: the bound is exact Coulomb for the wire's reaction as given; the wire's own
//! motion along the slot is not part of it (the simulation holds the wire still along the slot
//! within a step, see `movement::sim::friction`).

use super::{Reaction, Slot, WireMaterial, WireSize};
use crate::teeth::case::appliance::{BracketMaterial, Ligation};
use glam::{DQuat, DVec3};

/// Kinetic coefficient of friction between a wire of `wire` alloy and a slot of `bracket`.
///
/// Steel brackets: stainless steel on steel 0.21 (Arici et al., Korean J Orthod 2015,
/// 0.019×0.025" in 0.022"); NiTi a little higher; β-titanium about twice steel (Kusy's
/// uncoated couples about 0.42; the OMSS rig lost 72 % of the force on TMA against 34 % on
/// steel, PMC8233268). Polycrystalline ceramic slots about half again as much (Arici et al.
/// 2015: ceramic slots 0.3–0.85 against 0.21 for steel).
pub fn coefficient(wire: WireMaterial, bracket: BracketMaterial) -> f64 {
    let steel = match wire {
        WireMaterial::StainlessSteel => 0.21,
        WireMaterial::NiTi | WireMaterial::CopperNiTi => 0.26,
        WireMaterial::Tma => 0.42,
    };
    match bracket {
        BracketMaterial::Steel => steel,
        BracketMaterial::Ceramic => 1.5 * steel,
    }
}

/// Force (N) with which `ligation` presses a wire of `size` into `slot`'s floor.
///
/// Elastomeric modules about 1 N and a steel tie backed off about half that (archwire seating
/// forces of the order Khambay et al., Eur J Orthod 2005 measured; loosely tied steel ligatures
/// gave the least friction, Hain et al., AJODO 2003); a passive self-ligating gate none
/// (virtually zero friction, Griffiths et al., AJODO 2005); an active clip none until the wire
/// fills the slot's depth past the clip's rest (a wire 0.018" or more into a 0.022" slot, 0.016"
/// into a 0.018"), then 0.5 N.
pub fn seating_force_n(ligation: Ligation, size: WireSize, slot: Slot) -> f64 {
    match ligation {
        Ligation::Elastomeric => 1.0,
        Ligation::SteelTie => 0.5,
        Ligation::PassiveSelfLigating => 0.0,
        Ligation::ActiveSelfLigating => {
            let clip_rest = match slot {
                Slot::S018 => 0.016,
                Slot::S022 => 0.018,
            };
            let depth = match size {
                WireSize::Round(d) => d,
                WireSize::Rect(_, w) => w,
            };
            if depth >= clip_rest - 1e-9 { 0.5 } else { 0.0 }
        }
    }
}

/// The slot's normal force (N) under the wire's `reaction` (world force, moment about the slot;
/// see the module doc) for a slot of frame `frame` (world; X along, Y across, Z into) in a
/// bracket `width_mm` wide, a wire of `size`, plus `seating_n` from the ligation.
pub fn normal_force_n(
    reaction: &Reaction,
    frame: DQuat,
    width_mm: f64,
    size: WireSize,
    seating_n: f64,
) -> f64 {
    let inv = frame.inverse();
    let f: DVec3 = inv * reaction.force;
    let m: DVec3 = inv * reaction.moment;
    let w = width_mm.max(1e-6);
    let across = f.y.abs().max(2.0 * m.z.abs() / w);
    let into = f.z.abs().max(2.0 * m.y.abs() / w);
    let torque = match size {
        WireSize::Round(_) => 0.0,
        WireSize::Rect(..) => 2.0 * m.x.abs() / size.width_mm().max(1e-6),
    };
    across + into + torque + seating_n.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alloys_and_brackets_rank_as_measured() {
        let s = |w| coefficient(w, BracketMaterial::Steel);
        assert!(s(WireMaterial::StainlessSteel) < s(WireMaterial::NiTi));
        assert!(s(WireMaterial::NiTi) < s(WireMaterial::Tma));
        for w in [
            WireMaterial::StainlessSteel,
            WireMaterial::NiTi,
            WireMaterial::CopperNiTi,
            WireMaterial::Tma,
        ] {
            assert!(coefficient(w, BracketMaterial::Ceramic) > s(w));
            assert!((0.15..=0.7).contains(&coefficient(w, BracketMaterial::Ceramic)));
        }
    }

    #[test]
    fn only_an_active_clip_on_a_full_wire_and_ties_press_the_wire() {
        let round = WireSize::Round(0.014);
        let full = WireSize::Rect(0.019, 0.025);
        assert_eq!(
            seating_force_n(Ligation::PassiveSelfLigating, full, Slot::S022),
            0.0
        );
        assert_eq!(
            seating_force_n(Ligation::ActiveSelfLigating, round, Slot::S022),
            0.0
        );
        assert!(seating_force_n(Ligation::ActiveSelfLigating, full, Slot::S022) > 0.0);
        assert!(
            seating_force_n(Ligation::Elastomeric, round, Slot::S022)
                > seating_force_n(Ligation::SteelTie, round, Slot::S022)
        );
    }

    #[test]
    fn a_couple_binds_the_wire_harder_than_its_force_alone() {
        let frame = DQuat::from_rotation_y(0.3);
        let size = WireSize::Round(0.016);
        // A free wire in the slot: only the ligature.
        let none = normal_force_n(&Reaction::default(), frame, 3.0, size, 1.0);
        assert!((none - 1.0).abs() < 1e-12);
        // A force across the slot bears once.
        let push = Reaction {
            force: frame * DVec3::Y * 2.0,
            moment: DVec3::ZERO,
        };
        assert!((normal_force_n(&push, frame, 3.0, size, 0.0) - 2.0).abs() < 1e-9);
        // The same force with a tipping couple of 6 N·mm on a 3 mm bracket: its corners bear
        // 2 × 6 / 3 = 4 N.
        let bound = Reaction {
            moment: frame * DVec3::Z * 6.0,
            ..push
        };
        assert!((normal_force_n(&bound, frame, 3.0, size, 0.0) - 4.0).abs() < 1e-9);
        // A round wire twisted holds no torque; a rectangular one bears on its edges.
        let twist = Reaction {
            force: DVec3::ZERO,
            moment: frame * DVec3::X * 2.0,
        };
        assert_eq!(normal_force_n(&twist, frame, 3.0, size, 0.0), 0.0);
        let rect = WireSize::Rect(0.019, 0.025);
        let n = normal_force_n(&twist, frame, 3.0, rect, 0.0);
        assert!((n - 4.0 / rect.width_mm()).abs() < 1e-9, "{n}");
    }
}
