//! The response's blocking: motions cut at the first contact that closes, contacts tested again
//! with the cut motions until none blocks, and loads passed on to the tooth pushed.

use std::collections::BTreeMap;

use glam::Vec3;

use super::{Found, SOFT_ROUNDS, Simulation, StepOutcome, TIME_SLACK};
use crate::{
    collision::{
        Method, Motion,
        closing::{approaching, closes_in},
    },
    geometry::mesh_separation,
    movement::{arch_path::next_present_tooth, settings::Response},
    teeth::Fdi,
};

impl Simulation {
    /// Whether the contact's teeth approach each other at time `t` of the step.
    fn closing(&self, f: &Found, t: f32) -> bool {
        approaching(self.method, &self.body(f.a), &self.body(f.b), &f.contact, t)
    }

    /// Whether tooth `x` of the contact, moving alone (the other held at its start pose),
    /// approaches the other.
    fn closes_alone(&self, f: &Found, t: f32, x: usize) -> bool {
        let (mut a, mut b) = (self.body(f.a), self.body(f.b));
        if x == f.a {
            b.motion = Motion::still(b.motion.start);
        } else {
            a.motion = Motion::still(a.motion.start);
        }
        approaching(self.method, &a, &b, &f.contact, t)
    }

    /// For a contact touching at the start of the step (discrete methods: at its end), whether
    /// its teeth close in on each other.
    fn closes_in(&self, f: &Found) -> bool {
        closes_in(self.method, &self.body(f.a), &self.body(f.b), &f.contact)
    }

    /// The time at which the contact stops its teeth, or None when it does not block.
    pub(super) fn blocking_time(&self, f: &Found) -> Option<f32> {
        let same_arch = self.teeth[f.a].fdi.arch() == self.teeth[f.b].fdi.arch();
        // The paper's circles ignore height: upper and lower teeth always "collide".
        if self.method == Method::Circles && !same_arch {
            return None;
        }
        if self.settings.response == Response::Ipr && same_arch {
            return (self.ipr_over.contains(&(f.a, f.b)) && self.closing(f, 0.0)).then_some(0.0);
        }
        if self.method.is_discrete() {
            return self.closes_in(f).then_some(0.0);
        }
        let t = f.contact.time_of_contact;
        if t >= 1.0 - TIME_SLACK {
            None
        } else if t <= 1e-6 {
            self.closes_in(f).then_some(0.0)
        } else {
            Some(t)
        }
    }

    /// Centre of mass at the start of the step (world).
    fn com(&self, i: usize) -> Vec3 {
        self.motions[i]
            .start
            .transform_point(self.teeth[i].shape.geometry.frame.centre_of_mass)
    }

    /// Records the force `x` passes to `y` when `x` is blocked by `y`.
    fn pass_load(&self, x: usize, y: usize, passes: &mut BTreeMap<(usize, usize), Vec3>) {
        let (tx, ty) = (&self.teeth[x], &self.teeth[y]);
        let force = self.effective[x];
        if tx.fdi.arch() != ty.fdi.arch() || force == Vec3::ZERO || passes.contains_key(&(x, y)) {
            return;
        }
        let tangent = self.arch_frame(x).tangent;
        let present = |f: Fdi| self.teeth.iter().any(|t| t.fdi == f);
        if next_present_tooth(tx.fdi, force, tangent, present) != Some(ty.fdi) {
            return;
        }
        let d = self.com(y) - self.com(x);
        let dir = Vec3::new(d.x, 0.0, d.z).normalize_or_zero();
        let along = self.settings.passed_fraction * force.dot(dir);
        if along > self.settings.force_threshold_n {
            passes.insert((x, y), dir * along);
        }
    }

    /// The response: cuts, replaces or keeps the proposed motions given the contacts found.
    pub fn resolve(&mut self, mut found: Vec<Found>) {
        found.sort_by_key(|f| (f.a, f.b));
        self.last = StepOutcome::default();
        match self.settings.response {
            Response::Block => {
                let pass = self.settings.model == crate::movement::MovementModel::Paper;
                self.block(found, pass)
            }
            Response::Impulse => {
                let changed = self.impulse(&found);
                let found = self.retest(found, &changed);
                self.block(found, false);
            }
            Response::Ipr => {
                self.mark_ipr_over(&found);
                self.block(found, false);
            }
        }
    }

    /// Pairs involving `changed` teeth tested again with the current motions; other pairs keep
    /// their contacts.
    fn retest(&mut self, found: Vec<Found>, changed: &[bool]) -> Vec<Found> {
        if !changed.iter().any(|&c| c) {
            return found;
        }
        let pairs: Vec<(usize, usize)> = self
            .broad_pairs()
            .into_iter()
            .filter(|&(a, b)| changed[a] || changed[b])
            .collect();
        self.last.queries += pairs.len();
        let mut out: Vec<Found> = found
            .into_iter()
            .filter(|f| !changed[f.a] && !changed[f.b])
            .collect();
        out.extend(self.narrow(&pairs));
        out.sort_by_key(|f| (f.a, f.b));
        out
    }

    /// Cuts motions at blocking contacts until none is left (see the module doc).
    fn block(&mut self, mut found: Vec<Found>, pass: bool) {
        let n = self.teeth.len();
        let mut passes = BTreeMap::new();
        let mut round = 0;
        loop {
            let stops: Vec<(usize, f32)> = found
                .iter()
                .enumerate()
                .filter_map(|(k, f)| self.blocking_time(f).map(|t| (k, t)))
                .collect();
            if pass {
                for &(k, _) in &stops {
                    let (a, b) = (found[k].a, found[k].b);
                    self.pass_load(a, b, &mut passes);
                    self.pass_load(b, a, &mut passes);
                }
            }
            if stops.is_empty() {
                break;
            }
            let hard = round >= SOFT_ROUNDS;
            for &(k, _) in &stops {
                let f = &found[k];
                self.last.blocking.retain(|b| (b.a, b.b) != (f.a, f.b));
                self.last.blocking.push(f.clone());
            }
            let mut stop = vec![1.0f32; n];
            for &(k, t) in &stops {
                let f = &found[k];
                // Only the teeth that close on the other are cut (a pushed tooth moving away is
                // not); both when neither does alone.
                let movers: Vec<usize> = [f.a, f.b]
                    .into_iter()
                    .filter(|&x| !self.motions[x].is_still())
                    .collect();
                let closers: Vec<usize> = movers
                    .iter()
                    .copied()
                    .filter(|&x| self.closes_alone(f, t, x))
                    .collect();
                let cut = if closers.is_empty() { movers } else { closers };
                for x in cut {
                    stop[x] = stop[x].min(if hard { 0.0 } else { t });
                }
            }
            for g in &self.groups {
                let least = g.members.iter().map(|&i| stop[i]).fold(1.0, f32::min);
                for &i in &g.members {
                    if !self.motions[i].is_still() {
                        stop[i] = least;
                    }
                }
            }
            let changed: Vec<bool> = stop.iter().map(|&s| s < 1.0).collect();
            if !changed.iter().any(|&c| c) {
                break;
            }
            for i in 0..n {
                if changed[i] {
                    let m = self.motions[i];
                    self.motions[i] = if stop[i] <= 0.0 {
                        Motion::still(m.start)
                    } else {
                        Motion {
                            start: m.start,
                            end: m.at(stop[i]),
                        }
                    };
                }
            }
            found = self.retest(found, &changed);
            round += 1;
        }
        for ((_, y), f) in passes {
            self.next_passed[y] += f;
        }
        self.last.contacts = found;
    }

    /// Marks same-arch contacts whose exact overlap at the end of the step would pass the IPR
    /// limit.
    fn mark_ipr_over(&mut self, found: &[Found]) {
        for f in found {
            let (ta, tb) = (&self.teeth[f.a], &self.teeth[f.b]);
            if ta.fdi.arch() != tb.fdi.arch() {
                continue;
            }
            let sep = mesh_separation(
                ta.shape.geometry.mesh_ref(),
                &self.motions[f.a].end,
                tb.shape.geometry.mesh_ref(),
                &self.motions[f.b].end,
            );
            if sep.overlapping() && sep.penetration > self.settings.ipr_limit_mm {
                self.ipr_over.insert((f.a, f.b));
            }
        }
    }
}
