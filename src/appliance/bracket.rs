//! Brackets and tubes: where each sits on its crown, how its slot is turned by the prescription,
//! and how much room the slot leaves a wire of a given size.
//!
//! **Slot frame** (in the tooth's local frame): X along the slot, the way the archwire runs (from
//! the patient's right to left), Z out of the slot (buccal), Y = Z × X across the slot's height
//! (upwards in both arches, so one wire frame convention serves both).
//! A bracket is bonded at the crown's bracket point (on the buccal surface at the bracket height)
//! with its slot [`BASE_MM`] plus the prescription's in-out out from the surface, and its slot
//! turned so that a passive straight wire leaves the crown at the prescription's tip, torque and
//! (molar tubes) offset.
//!
//! **Play.** A wire of height h in a slot of height S moves S − h across it and, when
//! rectangular, turns about its axis until a bevelled corner meets the slot's walls
//! ([`torque_play_rad`], one way from centred: the geometric engagement angle of a wire with
//! [`super::section::WireSize::bevel_mm`] corners). Angled in the slot's plane, a wire binds at
//! Kusy's critical contact angle (S − h)/W for a bracket W wide ([`binding_angle_rad`]). Slots
//! are taken at the heights they are made to, not their names: Meling et al. (AJODO
//! 1998;113:387–93) measured "0.018"" slots at 0.0185–0.0189" (brand means), so 0.018" slots are
//! 0.0188" here; 0.022" slots are taken at their nominal height (orthosim has no measurement of
//! them). The torque play follows: 15.4° for 0.016×0.022" in a 0.018" slot (Meling et al. 1997
//! measured 16.6–20.4°) and 14.9° for 0.019×0.025" in a 0.022" slot (about 14° in passive
//! self-ligating brackets, Archambault et al. 2010); `orthosim validate` checks both.

pub use crate::teeth::case::appliance::Slot;
use glam::{DQuat, DVec3};

use super::prescription::Prescription;
use super::rod::Holder;
use super::section::{MM_PER_INCH, WireSize};
use crate::teeth::{Arch, ToothKind};

/// Distance (mm) from the crown's surface to the bottom of the thinnest bracket's slot.
pub const BASE_MM: f64 = 0.8;
/// Stiffness of a slot's walls against the wire (N/mm): steel brackets are far stiffer than any
/// wire's bending over an interbracket span.
pub const WALL_N_PER_MM: f64 = 2.0e3;

impl Slot {
    /// Height (mm) as made: what the wire's height fits into (see the module's doc).
    pub fn height_mm(self) -> f64 {
        match self {
            Self::S018 => 0.0188 * MM_PER_INCH,
            Self::S022 => 0.022 * MM_PER_INCH,
        }
    }

    /// Depth (mm).
    pub fn depth_mm(self) -> f64 {
        match self {
            Self::S018 => 0.025 * MM_PER_INCH,
            Self::S022 => 0.028 * MM_PER_INCH,
        }
    }

    /// As clinicians write it.
    pub fn label(self) -> &'static str {
        match self {
            Self::S018 => "0.018\"",
            Self::S022 => "0.022\"",
        }
    }
}

/// Mesiodistal width of the bracket or tube on a tooth of `kind` (mm): twin brackets of 3.0–3.5 mm
/// on incisors, canines and premolars, 4.0 mm tubes on molars.
pub fn width_mm(arch: Arch, kind: ToothKind) -> f64 {
    match (arch, kind) {
        (Arch::Upper, ToothKind::CentralIncisor) => 3.5,
        (_, ToothKind::FirstMolar | ToothKind::SecondMolar | ToothKind::ThirdMolar) => 4.0,
        _ => 3.0,
    }
}

/// The torque play of `size` in `slot` (radians, one way from centred): how far a rectangular
/// wire turns about its axis before its bevelled corners bear on the slot's walls. `None` for a
/// round wire (it never engages) and for a wire that does not fit.
pub fn torque_play_rad(size: WireSize, slot: Slot) -> Option<f64> {
    let WireSize::Rect(..) = size else {
        return None;
    };
    let (h, w, r, s) = (
        size.height_mm(),
        size.width_mm(),
        size.bevel_mm(),
        slot.height_mm(),
    );
    if h > s {
        return None;
    }
    // Turned by θ, the wire spans (w − 2r) sin θ + (h − 2r) cos θ + 2r across the slot.
    let (a, b) = (w - 2.0 * r, h - 2.0 * r);
    let reach = (a * a + b * b).sqrt();
    let t = (s - 2.0 * r) / reach;
    if t >= 1.0 {
        // A wire that can turn right round in the slot holds no torque.
        return Some(std::f64::consts::FRAC_PI_2);
    }
    Some((t.asin() - b.atan2(a)).max(0.0))
}

/// Kusy's critical contact angle (radians): a wire of `size` angled in the slot's plane by more
/// than this bears on the slot's opposite corners (binding) in a bracket `width` mm wide.
pub fn binding_angle_rad(size: WireSize, slot: Slot, width: f64) -> f64 {
    ((slot.height_mm() - size.height_mm()).max(0.0) / width.max(1e-6)).atan()
}

/// A bracket bonded on a tooth: its slot's centre and frame in the tooth's local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bracket {
    /// Slot size.
    pub slot: Slot,
    /// Mesiodistal width (mm).
    pub width_mm: f64,
    /// The slot's centre (tooth frame, mm).
    pub centre: DVec3,
    /// The slot's frame (tooth frame).
    pub frame: DQuat,
}

/// The tooth's own directions a bracket is placed by (tooth frame, unit): its buccal direction
/// and the way the archwire runs past it (mesial on the patient's right, distal on the left).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToothAxes {
    /// Buccal.
    pub buccal: DVec3,
    /// The wire's running direction.
    pub along: DVec3,
    /// True when `along` is mesial (the patient's right side).
    pub along_is_mesial: bool,
}

impl Bracket {
    /// The bracket of a tooth of `kind` in `arch` with bracket point `point` (on its buccal
    /// surface, tooth frame) and axes `axes`, under `prescription`.
    pub fn place(
        arch: Arch,
        kind: ToothKind,
        point: DVec3,
        axes: &ToothAxes,
        prescription: Prescription,
        slot: Slot,
    ) -> Self {
        let p = prescription.angles(arch, kind);
        let buccal = axes.buccal.normalize();
        let along = (axes.along - buccal * axes.along.dot(buccal)).normalize();
        let up = buccal.cross(along);
        let base = DQuat::from_mat3(&glam::DMat3::from_cols(along, up, buccal)).normalize();
        // Mesial crown tip: the slot is turned the other way, so that a level wire tips the crown
        // mesially. Seen from the buccal (about +Z), turning X towards +Y raises its far end; the
        // far end is mesial on the right side.
        let mesial = if axes.along_is_mesial { 1.0 } else { -1.0 };
        let tip = DQuat::from_rotation_z(-mesial * p.tip_deg.to_radians() as f64);
        // Buccal crown torque: a level wire turns the crown's occlusal part buccally, so the slot
        // is turned back about its axis (X runs mesially on the right, distally on the left).
        let torque = DQuat::from_rotation_x(mesial * p.torque_deg.to_radians() as f64);
        // A distal offset turns the crown distal-in about its long axis.
        let offset = DQuat::from_rotation_y(mesial * p.offset_deg.to_radians() as f64);
        Self {
            slot,
            width_mm: width_mm(arch, kind),
            centre: point + buccal * (BASE_MM + p.in_out_mm as f64),
            frame: (base * offset * tip * torque).normalize(),
        }
    }

    /// The holder this bracket is to wire node `node` of a wire of `size`, the tooth standing at
    /// `pose` (world rotation and translation): free along the slot, the slot's play across it,
    /// into it and about each axis, its walls beyond.
    pub fn holder(
        &self,
        node: usize,
        rotation: DQuat,
        translation: DVec3,
        size: WireSize,
    ) -> Holder {
        let across = 0.5 * (self.slot.height_mm() - size.height_mm()).max(0.0);
        let into = 0.5 * (self.slot.depth_mm() - size.width_mm()).max(0.0);
        let bind = binding_angle_rad(size, self.slot, self.width_mm);
        let depth_bind = (2.0 * into / self.width_mm).atan();
        let torque = torque_play_rad(size, self.slot).unwrap_or(f64::INFINITY);
        let arm = 0.5 * self.width_mm;
        let turn = WALL_N_PER_MM * arm * arm;
        Holder {
            node,
            at: translation + rotation * self.centre,
            frame: (rotation * self.frame).normalize(),
            play: [f64::INFINITY, across, into, torque, depth_bind, bind],
            stiffness: [
                0.0,
                WALL_N_PER_MM,
                WALL_N_PER_MM,
                WALL_N_PER_MM * size.width_mm().powi(2),
                turn,
                turn,
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torque_play_follows_the_slot_geometry() {
        let play = |s, slot| torque_play_rad(s, slot).map(f64::to_degrees);
        assert_eq!(play(WireSize::Round(0.016), Slot::S022), None);
        // Fuller wires play less; a full-size wire hardly at all; bevels add play over sharp
        // corners' 7.2° (0.019×0.025" in 0.022").
        let a = play(WireSize::Rect(0.019, 0.025), Slot::S022).unwrap();
        let b = play(WireSize::Rect(0.021, 0.025), Slot::S022).unwrap();
        let c = play(WireSize::Rect(0.017, 0.025), Slot::S022).unwrap();
        assert!(c > a && a > b, "{c} {a} {b}");
        assert!((7.2..=16.0).contains(&a), "{a}");
        // An undersized wire in a larger slot turns freely further.
        let loose = play(WireSize::Rect(0.016, 0.022), Slot::S022).unwrap();
        let fitted = play(WireSize::Rect(0.016, 0.022), Slot::S018).unwrap();
        assert!(loose > 2.0 * fitted, "{loose} {fitted}");
        // A wire taller than the slot does not go in.
        assert_eq!(play(WireSize::Rect(0.019, 0.025), Slot::S018), None);
    }

    #[test]
    fn binding_angle_is_kusys() {
        let a = binding_angle_rad(WireSize::Round(0.016), Slot::S022, 3.0);
        let want = (0.006 * MM_PER_INCH / 3.0f64).atan();
        assert!((a - want).abs() < 1e-12 && a.to_degrees() > 2.0 && a.to_degrees() < 3.5);
    }

    #[test]
    fn a_passive_prescription_wire_levels_the_crown_and_brackets_stand_out_by_their_in_out() {
        let axes = ToothAxes {
            buccal: DVec3::Z,
            along: DVec3::X,
            along_is_mesial: true,
        };
        let b = Bracket::place(
            Arch::Upper,
            ToothKind::CentralIncisor,
            DVec3::new(0.0, 5.0, 3.0),
            &axes,
            Prescription::Mbt,
            Slot::S022,
        );
        let p = Prescription::Mbt.angles(Arch::Upper, ToothKind::CentralIncisor);
        assert!((b.centre.z - 3.0 - BASE_MM - p.in_out_mm as f64).abs() < 1e-9);
        // The slot's axis is turned by the tip about the buccal direction, its height direction
        // by the torque about the slot's axis.
        let x = b.frame * DVec3::X;
        let tip = x.y.atan2(x.x).to_degrees().abs();
        assert!((tip - p.tip_deg as f64).abs() < 1e-6, "{tip}");
        let z = b.frame * DVec3::Z;
        let torque = z.y.atan2(z.z).to_degrees().abs();
        assert!((torque - p.torque_deg as f64).abs() < 0.5, "{torque}");
        // Mirror teeth mirror their slots.
        let left = Bracket::place(
            Arch::Upper,
            ToothKind::CentralIncisor,
            DVec3::new(0.0, 5.0, 3.0),
            &ToothAxes {
                along_is_mesial: false,
                along: DVec3::X,
                ..axes
            },
            Prescription::Mbt,
            Slot::S022,
        );
        let lx = left.frame * DVec3::X;
        assert!((lx.y + x.y).abs() < 1e-9, "{lx} {x}");
    }
}
