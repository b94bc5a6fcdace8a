//! Friction of the slots on the wire, on the forces that slide teeth along it.
//!
//! Each step, after the wire's equilibrium and the auxiliaries' pull, the part of each bracket's
//! chain and coil force that runs along its slot is reduced by the slot's friction: by μ·N at
//! most, and never past zero, so that friction takes force from a sliding tooth and never
//! drives one (Coulomb's law with the tooth sliding the way it is pulled, or held when the pull
//! is under μ·N). μ is the wire's and brackets' (or the case's); N is the slot's normal force
//! under the wire's reaction of this step, binding couples included, plus the ligation's seating
//! force on brackets (a molar's tube has no ligature) ([`crate::appliance::friction`]). The force so lost is each bracket's `friction_n`.
//!
//! What friction takes from a tooth it gives to the wire, which is held in every slot and at its
//! stop: the sum is shared equally by the arch's brackets, so that the arch's forces still
//! balance and an elastic's pull still reaches the whole arch (as a force on each tooth, not
//! resolved by where the wire bears).
//!
//! Departure, and its bound: friction is applied to the forces that slide teeth along the wire
//! (chains, coils, elastics), where sliding mechanics lose their force. The wire itself runs
//! freely through the other slots (it carries no force along them but at its stop and cinches),
//! and a tooth pushed along the wire by its neighbours' contacts slides without friction. A fully coupled
//! stick–slip of the wire in every slot (friction in the wire's own equilibrium) was tried and
//! left aside: its lagged normal force fed back through the binding couples and made canine
//! retraction chaotic.

use glam::DVec3;

use super::{Simulation, archwire::world};
use crate::{appliance::friction, teeth::ToothKind};

impl Simulation {
    /// Takes the slots' friction off wire `k`'s chain and coil forces along the slots (see the
    /// module doc) and records it per bracket.
    pub(super) fn slot_friction(&mut self, k: usize) {
        let n = self.wires[k].brackets.len();
        self.wires[k].friction_n = vec![0.0; n];
        let mu = self.wires[k].choice.mu();
        if mu <= 0.0 {
            return;
        }
        let frames: Vec<_> = self.wires[k]
            .brackets
            .iter()
            .map(|b| (world(&self.teeth[b.tooth]).0 * b.bracket.frame).normalize())
            .collect();
        let w = &mut self.wires[k];
        let seating = friction::seating_force_n(w.choice.ligation, w.choice.size, w.choice.slot);
        let mut held = DVec3::ZERO;
        for j in 0..n.min(w.chain_forces.len()) {
            let along = frames[j] * DVec3::X;
            let pull = w.chain_forces[j].dot(along);
            if pull == 0.0 {
                continue;
            }
            let reaction = w.reactions.get(j).copied().unwrap_or_default();
            // Molars carry tubes, which hold the wire with no ligature.
            let tube = matches!(
                w.brackets[j].fdi.kind(),
                ToothKind::FirstMolar | ToothKind::SecondMolar | ToothKind::ThirdMolar
            );
            let normal = friction::normal_force_n(
                &reaction,
                frames[j],
                w.brackets[j].bracket.width_mm,
                w.choice.size,
                if tube { 0.0 } else { seating },
            );
            let lost = (mu * normal).min(pull.abs()) * -pull.signum();
            w.chain_forces[j] += along * lost;
            w.friction_n[j] = lost;
            held -= along * lost;
        }
        // The wire passes what friction took on to the whole arch, shared by its brackets.
        let share = held / n.max(1) as f64;
        for f in &mut w.chain_forces {
            *f += share;
        }
    }
}
