//! Intermaxillary elastics in the simulation: from a bracket of one arch to one of the other,
//! their pull joining the chains' and coils' at each bracket (and so meeting the slots'
//! friction as they do). See [`crate::appliance::elastic`].

use super::{Simulation, archwire::world};
use crate::{
    appliance::elastic,
    movement::MovementError,
    teeth::{Fdi, case::appliance::CaseElastic},
};

/// An intermaxillary elastic.
#[derive(Clone, Debug, PartialEq)]
pub struct Elastic {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth (the other arch).
    pub to: Fdi,
    /// Its rated force where first worn (N).
    pub rating_n: f64,
    /// Clinical day it is first worn.
    pub day: f64,
    /// Clinical day it is last worn (None: to the end).
    pub until_day: Option<f64>,
    /// Once worn: the day it first was and its hooks' distance then (mm), where it gives its
    /// rating.
    pub placed: Option<(f64, f64)>,
    /// Its force in the last step (N; 0 when not worn).
    pub force_n: f64,
}

impl Simulation {
    /// Hooks an elastic from `from` to `to` (teeth of opposite arches, both bonded) from today,
    /// rated `force_n`.
    ///
    /// # Errors
    /// [`MovementError::Appliance`] for ends in one arch, an end without a bracket, or a force
    /// outside 0–5 N.
    pub fn add_elastic(&mut self, from: Fdi, to: Fdi, force_n: f64) -> Result<(), MovementError> {
        let day = self.elapsed_days;
        let e = self.elastic(from, to, force_n, day, None)?;
        self.elastics.push(e);
        Ok(())
    }

    /// The elastics a case names, checked against the brackets just bonded.
    ///
    /// # Errors
    /// As [`Simulation::add_elastic`].
    pub(super) fn case_elastics(&mut self, spec: &[CaseElastic]) -> Result<(), MovementError> {
        let mut out = Vec::new();
        for e in spec {
            out.push(self.elastic(
                e.from,
                e.to,
                f64::from(e.force_n.0),
                f64::from(e.day.0),
                e.until_day.map(|d| f64::from(d.0)),
            )?);
        }
        self.elastics = out;
        Ok(())
    }

    fn elastic(
        &self,
        from: Fdi,
        to: Fdi,
        force_n: f64,
        day: f64,
        until_day: Option<f64>,
    ) -> Result<Elastic, MovementError> {
        if from.arch() == to.arch() {
            return Err(MovementError::Appliance(format!(
                "an elastic goes from one arch to the other, not from {from} to {to}"
            )));
        }
        if !(force_n.is_finite() && (0.0..=5.0).contains(&force_n)) {
            return Err(MovementError::Appliance(format!(
                "an elastic's force must be 0–5 N, not {force_n}"
            )));
        }
        for f in [from, to] {
            if self.slot_of(f).is_none() {
                return Err(MovementError::Appliance(format!(
                    "an elastic ends on tooth {f}, which carries no bracket"
                )));
            }
        }
        Ok(Elastic {
            from,
            to,
            rating_n: force_n,
            day,
            until_day,
            placed: None,
            force_n: 0.0,
        })
    }

    /// The wire and bracket index of tooth `f`'s bracket.
    pub(super) fn slot_of(&self, f: Fdi) -> Option<(usize, usize)> {
        self.wires
            .iter()
            .enumerate()
            .find_map(|(k, w)| w.brackets.iter().position(|b| b.fdi == f).map(|j| (k, j)))
    }

    /// Adds each elastic worn today to its two brackets' auxiliary forces.
    pub(super) fn pull_elastics(&mut self) {
        let today = self.elapsed_days;
        for n in 0..self.elastics.len() {
            let e = &self.elastics[n];
            let worn = e.day <= today + 1e-9 && e.until_day.is_none_or(|u| today <= u + 1e-9);
            let ends = [e.from, e.to].map(|f| self.slot_of(f));
            let [Some(a), Some(b)] = ends else {
                self.elastics[n].force_n = 0.0;
                continue;
            };
            if !worn {
                self.elastics[n].force_n = 0.0;
                continue;
            }
            let point = |(k, j): (usize, usize)| {
                let bonded = &self.wires[k].brackets[j];
                let (rotation, translation) = world(&self.teeth[bonded.tooth]);
                translation + rotation * bonded.bracket.centre
            };
            let (pa, pb) = (point(a), point(b));
            let length = pa.distance(pb);
            let e = &mut self.elastics[n];
            let (_, placed) = *e.placed.get_or_insert((today, length));
            e.force_n = elastic::force_n(e.rating_n, placed, length);
            let [fa, fb] = elastic::end_forces(pa, pb, e.force_n);
            for ((k, j), f) in [(a, fa), (b, fb)] {
                if let Some(slot) = self.wires[k].chain_forces.get_mut(j) {
                    *slot += f;
                }
            }
        }
    }
}
