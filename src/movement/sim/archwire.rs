//! Archwires in the simulation: brackets bonded on an arch's teeth, the wire through them
//! brought to equilibrium at the teeth's poses every step, and what it does to each tooth.
//!
//! **Coupling.** Each step the wire is solved where the brackets stand (warm: its nodes and its
//! tangent's factor carry over from the last step); each bonded tooth then receives its slot's
//! reaction (force and moment) as an applied load at its bracket, in place of the old wire
//! model's blocking. A stiff wire over a day's step would push a tooth past where the wire is
//! passive and back again (explicit coupling is unstable once rate × ligament compliance × wire
//! stiffness passes 2), so each bonded body also carries the wire's stiffness at its bracket
//! (the slot's walls in series with the re-balanced wire, [`Rod::holder_stiffness`]) and moves
//! by backward Euler: where the wire's force at the step's end balances the ligament's motion
//! ([`crate::movement::pdl::PdlBody::twist`]). Teeth are coupled to each other through the wire
//! only via its solve at the next step (the stiffness is each bracket's own block).
//!
//! **Guarantee.** With the wire converged, the forces on the brackets are the discrete rod's
//! (see [`crate::appliance::rod`]); a tooth whose bracket is passive within its slot's play
//! feels nothing from the wire and stops. A solve that does not converge (even with
//! [`ENGAGE_ITERATIONS`]) leaves the wire where it stood and the brackets with the last step's
//! loads, and is reported in [`ArchWire::last`].

use glam::{DQuat, DVec3};

use super::{
    Simulation,
    auxiliary::{Chain, Coil},
};
use crate::{
    appliance::{
        ArchForm, ArchSize, Bracket, Equilibrium, Holder, Laid, Prescription, Reaction, Rod,
        Settings, Slot, ToothAxes, WireMaterial, WireSize, fit_form, lay, nearest_on_form,
    },
    appliance::{bracket::WALL_N_PER_MM, friction},
    geometry::{Mat6, Vec6},
    movement::{
        MovementError,
        pdl::{shifted, wrench},
    },
    teeth::{
        Arch, Fdi, Side, ToothKind,
        case::appliance::{BracketMaterial, CaseAppliance, Ligation},
    },
};

pub use crate::appliance::rod::{STEP_ITERATIONS, STEP_TOLERANCE_N, STOP_PLAY_MM};
/// Farthest a bracket is moved up or down its tooth from the bracket point to level its slot
/// (mm): about a third of a crown's height.
pub const MAX_HEIGHT_SHIFT_MM: f64 = 2.5;
/// Most Newton iterations when a wire is engaged, or a step's solve needs more.
pub const ENGAGE_ITERATIONS: usize = 200;

/// An archwire as a case or the panel chooses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WireChoice {
    /// Alloy.
    pub material: WireMaterial,
    /// Cross-section.
    pub size: WireSize,
    /// Preformed arch form.
    pub form: ArchForm,
    /// Brackets' slot.
    pub slot: Slot,
    /// Brackets' prescription.
    pub prescription: Prescription,
    /// How the wire is tied into the slots.
    pub ligation: Ligation,
    /// The brackets' material.
    pub bracket_material: BracketMaterial,
    /// Coefficient of friction in place of the materials' (see
    /// [`crate::appliance::friction::coefficient`]).
    pub friction: Option<f64>,
    /// The wire's ends cinched behind the terminal tubes: they hold the wire as its stop does
    /// (within [`STOP_PLAY_MM`]).
    pub cinched: bool,
}

impl WireChoice {
    /// The coefficient of friction between this wire and its slots.
    pub fn mu(&self) -> f64 {
        self.friction
            .unwrap_or_else(|| friction::coefficient(self.material, self.bracket_material))
    }
}

impl Default for WireChoice {
    fn default() -> Self {
        Self {
            material: WireMaterial::NiTi,
            size: WireSize::Round(0.014),
            form: ArchForm::Ovoid,
            slot: Slot::S022,
            prescription: Prescription::Mbt,
            ligation: Ligation::Elastomeric,
            bracket_material: BracketMaterial::Steel,
            friction: None,
            cinched: false,
        }
    }
}

/// A bracket bonded on a tooth and the wire node it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Bonded {
    /// The tooth (index in the simulation).
    pub tooth: usize,
    /// Its FDI number.
    pub fdi: Fdi,
    /// The bracket, in the tooth's frame.
    pub bracket: Bracket,
    /// The wire node its slot holds.
    pub node: usize,
}

/// An arch's brackets and archwire.
#[derive(Clone, Debug)]
pub struct ArchWire {
    /// The arch.
    pub arch: Arch,
    /// The wire chosen.
    pub choice: WireChoice,
    /// The wire as it stands.
    pub rod: Rod,
    /// The brackets, from the patient's right to left.
    pub brackets: Vec<Bonded>,
    /// What each bracket feels from the wire (world: force in N, moment in N·mm about its slot).
    pub reactions: Vec<Reaction>,
    /// Each bracket's stiffness against the wire (world, at its slot).
    pub stiffness: Vec<[[f64; 6]; 6]>,
    /// How the last solve ended.
    pub last: Equilibrium,
    /// The bracket whose crimped stop keeps the wire from sliding round the arch (the one
    /// nearest the midline): the wire slides [`STOP_PLAY_MM`] each way through it, and freely
    /// through the others.
    pub stop: Option<usize>,
    /// The arch form's size and place, kept for the wires that follow.
    pub form: (ArchSize, f64, f64),
    /// Each bracket's slot centre where its tooth stands aligned (world; where it stands now for
    /// a tooth with no setup): the wires that follow are laid through these.
    pub aligned_slots: Vec<DVec3>,
    /// Per bracket, whether the wire is coordinated to pass through its aligned slot (its tooth
    /// has a setup) or keeps to the form there.
    pub individual: Vec<bool>,
    /// Elastomeric chains over the brackets.
    pub chains: Vec<Chain>,
    /// NiTi coil springs between brackets.
    pub coils: Vec<Coil>,
    /// The chains' and coils' force on each bracket in the last step (N, world).
    pub chain_forces: Vec<DVec3>,
    /// Their moment on each bracket about its slot (N·mm, world; from power arms).
    pub chain_moments: Vec<DVec3>,
    /// The slot's friction on each bracket's tooth in the last step (N along the slot's axis;
    /// see `movement::sim::friction`).
    pub friction_n: Vec<f64>,

    /// Wires still to come: the clinical day each is engaged, and the wire.
    pub sequence: Vec<(f64, WireChoice)>,
    /// The wires engaged so far: the day each was, and the wire.
    pub history: Vec<(f64, WireChoice)>,
    /// Time of the last solve (ns).
    pub solve_ns: u64,
}

impl ArchWire {
    /// The index of the bracket bonded on tooth `i` (index in the simulation).
    fn bracket_on(&self, i: usize) -> Option<usize> {
        self.brackets.iter().position(|b| b.tooth == i)
    }

    /// The reaction on the bracket of tooth `i`, if bonded.
    pub fn reaction_of(&self, i: usize) -> Option<Reaction> {
        self.reactions.get(self.bracket_on(i)?).copied()
    }

    /// The slot's friction on tooth `i` in the last step (N along its slot), if bonded.
    pub fn friction_of(&self, i: usize) -> Option<f64> {
        self.friction_n.get(self.bracket_on(i)?).copied()
    }
}

impl Simulation {
    /// Bonds brackets on `teeth` of `arch` (when empty, all its teeth but third molars, as
    /// brackets and tubes are bonded from second molar to second molar) and engages `choice`'s wire
    /// through them, replacing any wire the arch had; the wire's passive shape is its arch form
    /// sized to the brackets.
    ///
    /// # Errors
    /// [`MovementError::NotInCase`] for a listed tooth the simulation lacks;
    /// [`MovementError::Appliance`] when fewer than three teeth carry brackets or a tooth has no
    /// ligament (the PDL model is off), or a listed tooth of the other arch.
    pub fn bond(
        &mut self,
        arch: Arch,
        choice: WireChoice,
        teeth: &[Fdi],
    ) -> Result<(), MovementError> {
        for f in teeth {
            if f.arch() != arch {
                return Err(MovementError::Appliance(format!(
                    "tooth {f} is not in the {arch:?} arch its wire is bonded on"
                )));
            }
            if self.index_of(*f).is_none() {
                return Err(MovementError::NotInCase(*f));
            }
        }
        self.debond(arch);
        let mut chosen: Vec<usize> = (0..self.teeth.len())
            .filter(|&i| {
                let f = self.teeth[i].fdi;
                let listed = if teeth.is_empty() {
                    f.kind() != ToothKind::ThirdMolar
                } else {
                    teeth.contains(&f)
                };
                f.arch() == arch && listed
            })
            .collect();
        chosen.sort_by_key(|&i| self.teeth[i].fdi.arch_index());
        if chosen.len() < 3 {
            return Err(MovementError::Appliance(format!(
                "an archwire needs brackets on at least three teeth of the {arch:?} arch, got {}",
                chosen.len()
            )));
        }
        // Where each tooth stands aligned (its setup) if known: brackets are bonded there as
        // indirect bonding on a setup places them, so that the wire at rest holds the teeth in
        // that row. A tooth with no setup keeps its bracket point and the prescription as they
        // are.
        let setups: Vec<Option<(DQuat, DVec3)>> = chosen
            .iter()
            .map(|&i| self.setup.get(&self.teeth[i].fdi).map(double))
            .collect();
        let mut brackets = Vec::new();
        for &i in &chosen {
            let t = &self.teeth[i];
            if t.pdl.is_none() {
                return Err(MovementError::Appliance(format!(
                    "tooth {} has no ligament: brackets need the PDL movement model",
                    t.fdi
                )));
            }
            brackets.push(Bonded {
                tooth: i,
                fdi: t.fdi,
                bracket: self.placed_bracket(i, choice, None),
                node: 0,
            });
        }
        let pose_of = |k: usize| setups[k].unwrap_or_else(|| world(&self.teeth[chosen[k]]));
        let slot_at = |k: usize, b: &Bracket| {
            let (r, x) = pose_of(k);
            x + r * b.centre
        };
        // Heights: each slot level with the others' mean where its tooth stands aligned.
        let level = |brackets: &mut Vec<Bonded>| {
            let y = (0..brackets.len())
                .map(|k| slot_at(k, &brackets[k].bracket).y)
                .sum::<f64>()
                / brackets.len() as f64;
            for (k, b) in brackets.iter_mut().enumerate() {
                let Some((r, _)) = setups[k] else {
                    continue;
                };
                let axis = self.teeth[b.tooth]
                    .shape
                    .geometry
                    .frame
                    .long_axis
                    .as_dvec3();
                let rise = (r * axis).y;
                if rise.abs() > 0.5 {
                    let shift = ((y - slot_at(k, &b.bracket).y) / rise)
                        .clamp(-MAX_HEIGHT_SHIFT_MM, MAX_HEIGHT_SHIFT_MM);
                    b.bracket.centre += axis * shift;
                }
            }
        };
        level(&mut brackets);
        let points: Vec<DVec3> = (0..brackets.len())
            .map(|k| slot_at(k, &brackets[k].bracket))
            .collect();
        let (size, z0) = fit_form(choice.form, &points).ok_or_else(|| {
            MovementError::Appliance(format!("the {arch:?} arch's brackets span no arch form"))
        })?;
        let y = points.iter().map(|p| p.y).sum::<f64>() / points.len() as f64;
        // The wire coordinated to the setup's slots, then each bracket with a setup turned to
        // the wire's run at its slot (first order) and levelled again, and the wire laid anew
        // through the slots as they then stand.
        let individual: Vec<bool> = setups.iter().map(Option::is_some).collect();
        let laid = lay_coordinated(choice.form, &size, y, z0, &points, &individual);
        for (k, b) in brackets.iter_mut().enumerate() {
            let Some((r, _)) = setups[k] else {
                continue;
            };
            let run = laid.nodes[laid.held[k]].q * DVec3::X;
            b.bracket = self.placed_bracket(b.tooth, choice, Some(r.inverse() * run));
        }
        level(&mut brackets);
        let points: Vec<DVec3> = (0..brackets.len())
            .map(|k| slot_at(k, &brackets[k].bracket))
            .collect();
        let laid = lay_coordinated(choice.form, &size, y, z0, &points, &individual);
        for (b, &node) in brackets.iter_mut().zip(&laid.held) {
            b.node = node;
        }
        let rod = Rod::new(laid.nodes, choice.size, choice.material);
        let n = brackets.len();
        let day = self.elapsed_days;
        self.wires.push(ArchWire {
            arch,
            choice,
            rod,
            brackets,
            reactions: vec![Reaction::default(); n],
            // Found by the first solve (an empty list is never reused).
            stiffness: Vec::new(),
            chains: Vec::new(),
            coils: Vec::new(),
            chain_forces: vec![DVec3::ZERO; n],
            chain_moments: vec![DVec3::ZERO; n],
            friction_n: vec![0.0; n],
            stop: (0..n).min_by(|&a, &b| points[a].x.abs().total_cmp(&points[b].x.abs())),
            last: Equilibrium {
                iterations: 0,
                residual: 0.0,
                converged: true,
            },
            form: (size, y, z0),
            aligned_slots: points,
            individual,
            sequence: Vec::new(),
            history: vec![(day, choice)],
            solve_ns: 0,
        });
        let k = self.wires.len() - 1;
        self.solve_wire(k, ENGAGE_ITERATIONS);
        self.pdl.cache.clear();
        Ok(())
    }

    /// Bonds what a case file asks for: each arch's wire through its brackets, with its wire
    /// sequence to follow.
    ///
    /// # Errors
    /// As [`Simulation::bond`].
    pub fn bond_case(&mut self, spec: &CaseAppliance) -> Result<(), MovementError> {
        for (arch, wire) in [(Arch::Upper, &spec.upper), (Arch::Lower, &spec.lower)] {
            let Some(w) = wire else {
                continue;
            };
            let choice = WireChoice {
                material: w.material,
                size: w.size,
                form: w.form,
                slot: w.slot,
                prescription: w.prescription,
                ligation: w.ligation,
                bracket_material: w.bracket_material,
                friction: w.friction.map(|f| f.0 as f64),
                cinched: w.cinched,
            };
            let teeth: Vec<Fdi> = w
                .bonded
                .0
                .iter()
                .copied()
                .filter(|f| self.index_of(*f).is_some())
                .collect();
            if !w.bonded.0.is_empty() && teeth.is_empty() {
                return Err(MovementError::Appliance(format!(
                    "none of the {arch:?} arch's bonded teeth is in the simulation"
                )));
            }
            self.bond(arch, choice, &teeth)?;
            let mut sequence: Vec<(f64, WireChoice)> = w
                .sequence
                .iter()
                .map(|c| {
                    (
                        c.day.0 as f64,
                        WireChoice {
                            material: c.material,
                            size: c.size,
                            form: c.form.unwrap_or(w.form),
                            ..choice
                        },
                    )
                })
                .collect();
            sequence.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (chains, coils) = self.auxiliaries(arch, w)?;
            if let Some(last) = self.wires.last_mut() {
                last.sequence = sequence;
                last.chains = chains;
                last.coils = coils;
            }
        }
        self.case_elastics(&spec.elastics)
    }

    /// Takes wire `k` out and engages `choice` through the same brackets, laid on the same arch
    /// form size (the patient's), at the teeth's current poses.
    pub fn change_wire(&mut self, k: usize, choice: WireChoice) {
        let Some(w) = self.wires.get(k) else {
            return;
        };
        let (size, y, z0) = w.form;
        let laid = lay_coordinated(choice.form, &size, y, z0, &w.aligned_slots, &w.individual);
        let day = self.elapsed_days;
        let w = &mut self.wires[k];
        for (b, &node) in w.brackets.iter_mut().zip(&laid.held) {
            b.node = node;
        }
        w.rod = Rod::new(laid.nodes, choice.size, choice.material);
        // The new wire's stiffness at the brackets is its own, found by its first solve.
        w.stiffness.clear();
        w.choice = choice;
        w.history.push((day, choice));
        self.solve_wire(k, ENGAGE_ITERATIONS);
    }

    /// Removes `arch`'s brackets and wire.
    pub fn debond(&mut self, arch: Arch) {
        self.wires.retain(|w| w.arch != arch);
        self.pdl.cache.clear();
    }

    /// The holders of wire `k`'s brackets at the teeth's current poses.
    fn holders(&self, k: usize) -> Vec<Holder> {
        let w = &self.wires[k];
        w.brackets
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (rotation, translation) = world(&self.teeth[b.tooth]);
                let mut h = b
                    .bracket
                    .holder(b.node, rotation, translation, w.choice.size);
                let terminal = i == 0 || i + 1 == w.brackets.len();
                if w.stop == Some(i) || (w.choice.cinched && terminal) {
                    h.play[0] = STOP_PLAY_MM;
                    h.stiffness[0] = WALL_N_PER_MM;
                }
                h
            })
            .collect()
    }

    /// Brings wire `k` to equilibrium at the teeth's poses and records its reactions and
    /// stiffnesses.
    fn solve_wire(&mut self, k: usize, iterations: usize) {
        let clock = std::time::Instant::now();
        let before = self.wires[k].rod.nodes.clone();
        let holders = self.holders(k);
        let w = &mut self.wires[k];
        w.last = equilibrium(&mut w.rod, &holders, iterations);
        if w.last.converged {
            w.reactions = w.rod.reactions(&holders);
            // A wire already in balance where the brackets now stand bears on the same walls:
            // its stiffness at the brackets is the last step's.
            if w.last.iterations > 0 || w.stiffness.len() != holders.len() {
                w.stiffness = w.rod.holder_stiffness(&holders);
            }
        } else {
            // No equilibrium found: the wire stays as it was and the brackets keep the last
            // step's loads (never forces from a wire out of balance).
            w.rod.place(before);
        }
        w.solve_ns = clock.elapsed().as_nanos() as u64;
    }

    /// Solves every wire at the teeth's current poses (each step, before the ligaments move).
    pub(super) fn solve_wires(&mut self) {
        for k in 0..self.wires.len() {
            let due = self.wires[k]
                .sequence
                .first()
                .filter(|(day, _)| *day <= self.elapsed_days + 1e-9)
                .map(|(_, c)| *c);
            if let Some(choice) = due {
                self.wires[k].sequence.remove(0);
                self.change_wire(k, choice);
            } else {
                self.solve_wire(k, STEP_ITERATIONS);
            }
            self.pull_chains(k);
        }
        self.pull_elastics();
        for k in 0..self.wires.len() {
            self.slot_friction(k);
        }
    }

    /// The wire's loads on tooth `i`: per bracket bonded on it, the slot's centre (world), its
    /// reaction and its stiffness.
    pub(super) fn wire_loads(&self, i: usize) -> Vec<(DVec3, Reaction, Mat6)> {
        let mut out = Vec::new();
        for w in &self.wires {
            for (k, b) in w.brackets.iter().enumerate() {
                if b.tooth != i {
                    continue;
                }
                let (rotation, translation) = world(&self.teeth[i]);
                let at = translation + rotation * b.bracket.centre;
                let mut r = w.reactions[k];
                r.force += w.chain_forces.get(k).copied().unwrap_or(DVec3::ZERO);
                r.moment += w.chain_moments.get(k).copied().unwrap_or(DVec3::ZERO);
                let stiffness = w.stiffness.get(k).copied().unwrap_or([[0.0; 6]; 6]);
                out.push((at, r, Mat6(stiffness)));
            }
        }
        out
    }

    /// Whether tooth `i` carries a bracket.
    pub fn is_bonded(&self, i: usize) -> bool {
        self.wires
            .iter()
            .any(|w| w.brackets.iter().any(|b| b.tooth == i))
    }
}

/// A tooth's pose as a double-precision rotation and translation.
impl Simulation {
    /// The bracket of tooth `i` for `choice`: at its bracket point, turned by the prescription from
    /// the tooth's own axes, its slot running along `along` (tooth frame) when given, else along
    /// the tooth's mesiodistal axis.
    fn placed_bracket(&self, i: usize, choice: WireChoice, along: Option<DVec3>) -> Bracket {
        let t = &self.teeth[i];
        let frame = &t.shape.geometry.frame;
        let mesial = (frame.mesiodistal * t.fdi.local_x_mesial_sign()).as_dvec3();
        let right = t.fdi.side() == Side::Right;
        let buccal = frame.buccolingual.as_dvec3();
        // A given run is kept exactly (a custom base turns the slot to it); the slot then faces
        // the tooth's buccal direction as near as that allows.
        let axes = match along {
            Some(run) => {
                let run = run.normalize();
                ToothAxes {
                    buccal: (buccal - run * buccal.dot(run)).normalize(),
                    along: run,
                    along_is_mesial: right,
                }
            }
            None => ToothAxes {
                buccal,
                along: if right { mesial } else { -mesial },
                along_is_mesial: right,
            },
        };
        let point = t.pdl.as_ref().map_or(DVec3::ZERO, |p| p.bracket.as_dvec3());
        Bracket::place(
            t.fdi.arch(),
            t.fdi.kind(),
            point,
            &axes,
            choice.prescription,
            choice.slot,
        )
    }
}

/// [`lay`] with the wire coordinated to pass through each of `points` marked `individual`: its
/// offset from the form there is the point's (see [`lay`]).
fn lay_coordinated(
    form: ArchForm,
    size: &ArchSize,
    y: f64,
    z0: f64,
    points: &[DVec3],
    individual: &[bool],
) -> Laid {
    let offsets: Vec<f64> = points
        .iter()
        .zip(individual)
        .map(|(&p, &own)| {
            if !own {
                return 0.0;
            }
            let (q, tangent) = nearest_on_form(form, size, y, z0, p);
            (DVec3::new(p.x, y, p.z) - q).dot(tangent.cross(DVec3::Y).normalize())
        })
        .collect();
    lay(form, size, y, z0, points, &offsets)
}

/// The rod's equilibrium in `holders`: `iterations` Newton iterations, then
/// [`ENGAGE_ITERATIONS`] if that was not enough.
fn equilibrium(rod: &mut Rod, holders: &[Holder], iterations: usize) -> Equilibrium {
    let settings = Settings {
        tolerance_n: STEP_TOLERANCE_N,
        max_iterations: iterations,
    };
    let first = rod.solve(holders, &[], &settings);
    if first.converged || iterations >= ENGAGE_ITERATIONS {
        return first;
    }
    rod.solve(
        holders,
        &[],
        &Settings {
            max_iterations: ENGAGE_ITERATIONS,
            ..settings
        },
    )
}

pub(super) fn world(t: &super::SimTooth) -> (DQuat, DVec3) {
    double(&t.pose)
}

/// A pose as a double-precision rotation and translation.
fn double(p: &crate::geometry::Pose) -> (DQuat, DVec3) {
    (p.rotation.as_dquat().normalize(), p.translation.as_dvec3())
}

/// The wrench about `centre` of the wire's loads, and their stiffness against the body's twist
/// about `centre` (each slot's stiffness carried there).
pub(super) fn about(loads: &[(DVec3, Reaction, Mat6)], centre: DVec3) -> (Vec6, Mat6) {
    loads
        .iter()
        .fold(([0.0; 6], Mat6::ZERO), |(w, k), (at, r, stiffness)| {
            let add = wrench(r.force, *at, r.moment, centre);
            (
                std::array::from_fn(|i| w[i] + add[i]),
                k.add_scaled(&shifted(stiffness, *at, centre), 1.0),
            )
        })
}
