//! Auxiliaries on an arch's wire: elastomeric chains along the brackets and NiTi coil springs
//! between two of them, placed on their day, whose forces join the wire's at each bracket.

use glam::DVec3;

use super::{Simulation, archwire::world};
use crate::{
    appliance::{chain, coil},
    movement::MovementError,
    teeth::{Arch, Fdi, case::appliance::CaseArchWire},
};

/// An elastomeric chain over an arch's brackets (see [`crate::appliance::chain`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth.
    pub to: Fdi,
    /// Strain when placed.
    pub stretch: f64,
    /// Clinical day it is placed.
    pub day: f64,
    /// Replaced by a fresh chain at the same stretch every this many days (None: never).
    pub renew_days: Option<f64>,
    /// Power arms on the `from` and `to` teeth: from the slot towards the root (mm).
    pub arms: [f64; 2],
    /// Once placed: the day it was and its relaxed length (mm).
    pub placed: Option<(f64, f64)>,
    /// Its tension in the last step (N).
    pub tension_n: f64,
}

/// A NiTi coil spring between two brackets (see [`crate::appliance::coil`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Coil {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth.
    pub to: Fdi,
    /// Closed or open.
    pub kind: coil::CoilKind,
    /// Plateau force (N).
    pub force: f64,
    /// Activation when placed (mm).
    pub activation: f64,
    /// Power arms on the `from` and `to` teeth: from the slot towards the root (mm).
    pub arms: [f64; 2],
    /// Clinical day it is placed.
    pub day: f64,
    /// Once placed: the day it was and its relaxed length (mm).
    pub placed: Option<(f64, f64)>,
    /// Its force in the last step (N).
    pub force_n: f64,
}

impl Simulation {
    /// The chains and coils a case names on `arch`'s wire, just bonded.
    ///
    /// # Errors
    /// [`MovementError::Appliance`] when one ends on a tooth without a bracket.
    pub(super) fn auxiliaries(
        &self,
        arch: Arch,
        w: &CaseArchWire,
    ) -> Result<(Vec<Chain>, Vec<Coil>), MovementError> {
        let mut chains = Vec::new();
        for c in &w.chains {
            self.bracketed(arch, "a chain", [c.from, c.to])?;
            chains.push(Chain {
                from: c.from,
                to: c.to,
                stretch: f64::from(c.stretch.0),
                day: f64::from(c.day.0),
                renew_days: c.renew_days.map(|d| f64::from(d.0)).filter(|d| *d > 0.0),
                arms: [c.from_arm_mm.0, c.to_arm_mm.0].map(f64::from),
                placed: None,
                tension_n: 0.0,
            });
        }
        let mut coils = Vec::new();
        for c in &w.coils {
            self.bracketed(arch, "a coil", [c.from, c.to])?;
            coils.push(Coil {
                from: c.from,
                to: c.to,
                kind: c.kind,
                force: f64::from(c.force_n.0),
                activation: f64::from(c.activation_mm.0),
                day: f64::from(c.day.0),
                arms: [c.from_arm_mm.0, c.to_arm_mm.0].map(f64::from),
                placed: None,
                force_n: 0.0,
            });
        }
        Ok((chains, coils))
    }

    /// An error naming the first of `ends` that carries no bracket of the wire last bonded on
    /// `arch` (`what` ends on it).
    fn bracketed(&self, arch: Arch, what: &str, ends: [Fdi; 2]) -> Result<(), MovementError> {
        let wire = self.wires.iter().rev().find(|w| w.arch == arch);
        for f in ends {
            if !wire.is_some_and(|w| w.brackets.iter().any(|b| b.fdi == f)) {
                return Err(MovementError::Appliance(format!(
                    "{what} ends on tooth {f}, which carries no bracket of the {arch:?} arch's wire"
                )));
            }
        }
        Ok(())
    }

    /// The index of the wire both `ends` are bonded to.
    fn wire_between(&self, what: &str, ends: [Fdi; 2]) -> Result<usize, MovementError> {
        let arch = ends[0].arch();
        if ends[1].arch() != arch || ends[0] == ends[1] {
            return Err(MovementError::Appliance(format!(
                "{what} needs two teeth of one arch, not {} and {}",
                ends[0], ends[1]
            )));
        }
        self.bracketed(arch, what, ends)?;
        self.wires
            .iter()
            .rposition(|w| w.arch == arch)
            .ok_or_else(|| {
                MovementError::Appliance(format!("{what}: no wire on the {arch:?} arch"))
            })
    }

    /// Places an elastomeric chain from `from` to `to` over the brackets between them, today,
    /// stretched by `stretch` (strain, 0–1.5).
    ///
    /// # Errors
    /// [`MovementError::Appliance`] when an end carries no bracket, the ends are not of one arch,
    /// or the stretch is out of range.
    pub fn add_chain(&mut self, from: Fdi, to: Fdi, stretch: f64) -> Result<(), MovementError> {
        let k = self.wire_between("a chain", [from, to])?;
        if !(stretch.is_finite() && (0.0..=1.5).contains(&stretch)) {
            return Err(MovementError::Appliance(format!(
                "a chain's stretch must be 0–1.5, not {stretch}"
            )));
        }
        let day = self.elapsed_days;
        self.wires[k].chains.push(Chain {
            from,
            to,
            stretch,
            day,
            renew_days: None,
            arms: [0.0; 2],
            placed: None,
            tension_n: 0.0,
        });
        Ok(())
    }

    /// Places a NiTi coil spring between the brackets of `from` and `to`, today, with a plateau
    /// of `force` N, activated by `activation` mm.
    ///
    /// # Errors
    /// As [`Simulation::add_chain`], and for a force outside 0–5 N or an activation outside
    /// 0–10 mm.
    pub fn add_coil(
        &mut self,
        from: Fdi,
        to: Fdi,
        kind: coil::CoilKind,
        force: f64,
        activation: f64,
    ) -> Result<(), MovementError> {
        let k = self.wire_between("a coil", [from, to])?;
        let bad = |v: f64, hi: f64| !(v.is_finite() && (0.0..=hi).contains(&v));
        if bad(force, 5.0) || bad(activation, 10.0) {
            return Err(MovementError::Appliance(format!(
                "a coil needs a force of 0–5 N and an activation of 0–10 mm, not {force} N and {activation} mm"
            )));
        }
        let day = self.elapsed_days;
        self.wires[k].coils.push(Coil {
            from,
            to,
            kind,
            force,
            activation,
            day,
            arms: [0.0; 2],
            placed: None,
            force_n: 0.0,
        });
        Ok(())
    }

    /// Places wire `k`'s chains and coils that are due and sets each bracket's force and moment
    /// (about its slot) from them for this step. A chain or coil ending on a power arm pulls at
    /// the arm's tip, `arm` mm from the slot towards the root along the tooth's long axis, and
    /// its bracket takes the force and the moment of the force about the slot.
    pub(super) fn pull_chains(&mut self, k: usize) {
        let mut slots: Vec<DVec3> = Vec::new();
        let mut apical: Vec<DVec3> = Vec::new();
        for b in &self.wires[k].brackets {
            let t = &self.teeth[b.tooth];
            let (rotation, translation) = world(t);
            slots.push(translation + rotation * b.bracket.centre);
            apical.push(
                -(rotation * t.shape.geometry.frame.long_axis.as_dvec3()).normalize_or_zero(),
            );
        }
        let today = self.elapsed_days;
        let w = &mut self.wires[k];
        let n = slots.len();
        w.chain_forces = vec![DVec3::ZERO; n];
        w.chain_moments = vec![DVec3::ZERO; n];
        let arm_tip = |i: usize, arm: f64| slots[i] + apical[i] * arm;
        let pull = |forces: &mut [DVec3], moments: &mut [DVec3], i: usize, arm: f64, f: DVec3| {
            forces[i] += f;
            moments[i] += (arm_tip(i, arm) - slots[i]).cross(f);
        };
        for c in &mut w.chains {
            let ends = [c.from, c.to].map(|f| w.brackets.iter().position(|b| b.fdi == f));
            let [Some(a), Some(b)] = ends else {
                continue;
            };
            let (lo, hi) = (a.min(b), a.max(b));
            let arm = |i: usize| if i == a { c.arms[0] } else { c.arms[1] };
            let mut points = slots[lo..=hi].to_vec();
            points[0] = arm_tip(lo, arm(lo));
            points[hi - lo] = arm_tip(hi, arm(hi));
            let length = chain::length(&points);
            let due = match (c.placed, c.renew_days) {
                (None, _) => c.day <= today + 1e-9,
                (Some((placed, _)), Some(every)) => today - placed >= every - 1e-9,
                (Some(_), None) => false,
            };
            if due {
                c.placed = Some((today, length / (1.0 + c.stretch)));
            }
            let Some((placed, relaxed)) = c.placed else {
                continue;
            };
            c.tension_n = chain::tension_n(length, relaxed, today - placed);
            for (j, f) in chain::forces(&points, c.tension_n).into_iter().enumerate() {
                let i = lo + j;
                let arm = if i == lo || i == hi { arm(i) } else { 0.0 };
                pull(&mut w.chain_forces, &mut w.chain_moments, i, arm, f);
            }
        }
        for c in &mut w.coils {
            let ends = [c.from, c.to].map(|f| w.brackets.iter().position(|b| b.fdi == f));
            let [Some(a), Some(b)] = ends else {
                continue;
            };
            let (pa, pb) = (arm_tip(a, c.arms[0]), arm_tip(b, c.arms[1]));
            let length = pa.distance(pb);
            if c.placed.is_none() && c.day <= today + 1e-9 {
                let relaxed = match c.kind {
                    coil::CoilKind::Closed => (length - c.activation).max(0.0),
                    coil::CoilKind::Open => length + c.activation,
                };
                c.placed = Some((today, relaxed));
            }
            let Some((_, relaxed)) = c.placed else {
                continue;
            };
            c.force_n = coil::force_n(c.kind, c.force, relaxed, length);
            let [fa, fb] = coil::end_forces(c.kind, pa, pb, c.force_n);
            pull(&mut w.chain_forces, &mut w.chain_moments, a, c.arms[0], fa);
            pull(&mut w.chain_forces, &mut w.chain_moments, b, c.arms[1], fb);
        }
    }
}
