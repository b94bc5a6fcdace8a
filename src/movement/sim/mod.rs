//! The simulation step, engine-free: loads → motion → broad phase → narrow phase → response →
//! commit, over all teeth of a case. The `simulate` command and the tests drive it directly;
//! [`super::plugin::MovementPlugin`] runs the same stages in the ECS sets.
//!
//! ## Responses and their guarantees
//! - **block** (the paper's): each moving tooth stops at the first time of contact of its pairs;
//!   its step is cut there (the end pose is the pose at that time). Cutting one tooth changes its
//!   motion, so the pairs it is in are tested again with the new motions, until no pair blocks;
//!   after [`SOFT_ROUNDS`] rounds every tooth still in a blocking contact stands still instead,
//!   which ends the loop (each round stops at least one more tooth, and standing still is always
//!   safe since the step started without overlap). With `continuous` and `exact` no pair
//!   interpenetrates beyond what the method tolerates: `exact` leaves moving teeth touching with a
//!   gap of at most 0.01 mm, `continuous` at the touching of leaf spheres. Contacts whose time is
//!   within [`TIME_SLACK`] of the step's end are accepted as touching (at most that fraction of one
//!   step of travel). Discrete methods (`circles`, `spheres`) only see the end pose: a step that
//!   ends in an approaching overlap is undone (the tooth stays where it was), the backtracking the
//!   paper names. The blocked tooth passes [`MovementSettings::passed_fraction`] of its force (its
//!   component from its centre of mass towards the other's, in the occlusal plane) to the tooth it
//!   hit when that tooth is the next present one along the arch in the force's direction and the
//!   passed force exceeds the movement threshold; it acts in the next step.
//! - **impulse**: at the earliest contact of each tooth, momentum is exchanged along the contact
//!   normal with the coefficient of restitution (masses and inertias from the meshes), the rest of
//!   the step is travelled at the velocities after impact, and the result is then blocked as above
//!   so nothing interpenetrates. Each [`Impact`] reports velocities before and after and the
//!   kinetic energy lost, which is never negative.
//! - **ipr**: teeth of the same arch may overlap; each contact's overlap (exact penetration depth)
//!   is recorded as interproximal reduction. A contact whose overlap would pass
//!   [`MovementSettings::ipr_limit_mm`] blocks (the step is undone), as do contacts between the
//!   arches.
//!
//! A contact already touching at the start of the step blocks only if the teeth close in on each
//! other, so teeth can always move apart or slide along each other: with `exact` when the contact
//! points approach along the normal or the meshes overlap deeper at the end of the step than at
//! its start; with `continuous` when the deepest overlap of leaf spheres grows over the step (leaf
//! spheres of neighbours overlap at rest, and some pair of them approaches under almost any
//! motion); with `spheres` likewise when the deepest overlap of leaf spheres at the end of the step
//! is deeper than at its start (a step into a new overlap always blocks); with `circles` when the
//! circles got closer. With `circles`, pairs of opposite
//! arches never block: the paper's circles ignore height and would lock every tooth against its
//! antagonist.
//!
//! Files: this one holds the types and the step; `editing` makes and edits a simulation,
//! `proposal` proposes each step's motions, `blocking` is the response's blocking and load passing,
//! `impulse` the impulse response. Whether a contact closes is collision's
//! ([`crate::collision::closing`]).
//!
//! Determinism: every loop runs in tooth order and contacts are processed sorted by pair, so the
//! same case and settings give bit-identical poses.

use std::{
    collections::{BTreeMap, BTreeSet},
    time::Instant,
};

use glam::Vec3;
use serde::Serialize;

mod archwire;
mod auxiliary;
mod blocking;
mod bone;
mod editing;
mod elastics;
mod friction;
mod impulse;
mod pdl_step;
mod proposal;

pub use archwire::{ArchWire, Bonded, STEP_ITERATIONS, STEP_TOLERANCE_N, WireChoice};
pub use auxiliary::{Chain, Coil};
pub use bone::{CorticalContact, PLATE_CONTACT_MM, RETURN_MM_PER_STEP};
pub use elastics::Elastic;
pub use pdl_step::{MAX_SWEEPS, PUSH_BIAS_MM, PdlState, SOLVE_TOLERANCE_MM};

use super::{
    arch_path::{ArchFrame, arc_of, frame_at},
    model::{Centres, ToothConstraint},
    pdl::PdlStiffness,
    settings::{MovementModel, MovementSettings, Response},
};
use crate::{
    collision::broad_phase::{BroadItem, candidate_pairs},
    collision::{
        Body, Circle, CollisionShape, EndOverlap, Method, Motion, PairContact, query_knowing,
    },
    geometry::{Pose, mesh_separation},
    teeth::{
        Arch, Fdi, Load, WireModel,
        arch::{
            ArchCurve,
            irregularity::{Anterior, ContactPoints, irregularity_mm},
        },
    },
};

/// Rounds of cutting steps at contact times before blocked teeth are stopped outright.
pub const SOFT_ROUNDS: usize = 6;
/// Contacts this close to the step's end (as a fraction of the step) are accepted as touching.
pub const TIME_SLACK: f32 = 1e-3;
/// Steps without movement after which cycling passed loads count as rest (a push travels one
/// tooth per step, and an arch has 16).
pub const REST_STEPS: u32 = 16;
/// A motion that moves no point farther than this (mm) is not made: the tooth stands still (f32
/// poses of teeth 20–50 mm from the origin resolve about 4·10⁻⁶ mm).
pub const STILL_MM: f64 = 1e-4;

/// One tooth in the simulation.
#[derive(Clone, Debug)]
pub struct SimTooth {
    /// FDI number.
    pub fdi: Fdi,
    /// Geometry and sphere tree.
    pub shape: CollisionShape,
    /// Bounding circle (for [`Method::Circles`]).
    pub circle: Circle,
    /// Archwire model.
    pub wire: WireModel,
    /// The tooth's own load (world frame).
    pub load: Load,
    /// Index of the group it moves with, if any.
    pub group: Option<usize>,
    /// Allowed movements.
    pub constraint: ToothConstraint,
    /// Pose when the simulation started.
    pub initial: Pose,
    /// Current pose.
    pub pose: Pose,
    /// Arc length of its local origin on its arch curve.
    pub arc: f32,
    /// Moment-to-force ratio at the bracket (mm) under a rectangular wire (PDL model); None: the
    /// wire's engagement decides.
    pub mf: Option<f32>,
    /// The tooth's ligament (PDL model), shared between teeth of one shape.
    pub pdl: Option<std::sync::Arc<PdlStiffness>>,
}

impl SimTooth {
    /// Crown centre (world) at the current pose.
    pub fn crown_centre(&self) -> Vec3 {
        self.pose
            .transform_point(self.shape.geometry.frame.crown_centre)
    }

    /// Crown-centre travel from the initial pose (mm).
    pub fn displacement_mm(&self) -> f32 {
        let c = self.shape.geometry.frame.crown_centre;
        self.pose
            .transform_point(c)
            .distance(self.initial.transform_point(c))
    }

    fn centres(&self) -> Centres {
        let f = &self.shape.geometry.frame;
        Centres {
            crown: self.pose.transform_point(f.crown_centre),
            tipping: self.pose.transform_point(f.centre_of_tipping),
            long_axis: self.pose.transform_vector(f.long_axis),
        }
    }
}

/// Teeth that move as one block, with the group's load.
#[derive(Clone, Debug, PartialEq)]
pub struct SimGroup {
    /// Members (tooth indices).
    pub members: Vec<usize>,
    /// The group's load (world frame).
    pub load: Load,
}

/// A contact found between teeth `a` and `b` (indices, `a < b`).
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// First tooth.
    pub a: usize,
    /// Second tooth.
    pub b: usize,
    /// What the narrow phase reported.
    pub contact: PairContact,
}

/// An impact of the `impulse` response.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Impact {
    /// First tooth.
    pub a: Fdi,
    /// Second tooth.
    pub b: Fdi,
    /// Time of contact within the step.
    pub time_of_contact: f32,
    /// Linear velocities of the centres of mass (mm/s) before: a, b.
    pub velocity_before: [Vec3; 2],
    /// Linear velocities after.
    pub velocity_after: [Vec3; 2],
    /// Angular velocities (rad/s) before: a, b.
    pub angular_before: [Vec3; 2],
    /// Angular velocities after.
    pub angular_after: [Vec3; 2],
    /// Kinetic energy before the impact (µJ = kg·mm²/s²).
    pub energy_before_uj: f64,
    /// Kinetic energy lost in the impact (µJ), never negative.
    pub energy_lost_uj: f64,
}

/// What the last step did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepOutcome {
    /// Teeth that moved.
    pub moved: usize,
    /// Nothing moved and the loads passed on are unchanged: further steps change nothing.
    pub at_rest: bool,
    /// Candidate pairs tested by the narrow phase (first pass).
    pub pairs_tested: usize,
    /// Narrow-phase queries run in all (first pass and re-tests).
    pub queries: usize,
    /// Time spent in collision detection and response (ns).
    pub collision_ns: u64,
    /// Time spent on loads and motion (ns): under the PDL model the bodies, the contact solve
    /// and the motions.
    pub motion_ns: u64,
    /// Of which the contact solve (ns, PDL model).
    pub contact_solve_ns: u64,
    /// Contacts as the step ended (for the last motions tested of each pair).
    pub contacts: Vec<Found>,
    /// Contacts that stopped a tooth in this step, as found when they stopped it.
    pub blocking: Vec<Found>,
    /// Impacts (`impulse`).
    pub impacts: Vec<Impact>,
}

/// A case being simulated.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// The teeth (visible ones, in FDI order).
    pub teeth: Vec<SimTooth>,
    /// Groups moving as one block.
    pub groups: Vec<SimGroup>,
    /// Arch curves: upper, lower.
    curves: [ArchCurve; 2],
    /// Movement parameters.
    pub settings: MovementSettings,
    /// Narrow-phase method.
    pub method: Method,
    /// This step's motions (proposed by [`Simulation::propose`], cut by the response).
    pub motions: Vec<Motion>,
    /// Forces each tooth received from blocked neighbours, acting this step.
    passed: Vec<Vec3>,
    /// Forces passed on in this step, acting in the next.
    next_passed: Vec<Vec3>,
    /// Net force on each tooth this step (own or group load plus received).
    effective: Vec<Vec3>,
    /// Steps taken.
    pub steps: u64,
    /// What the last step did.
    pub last: StepOutcome,
    /// Largest overlap per contact recorded by the `ipr` response (mm), by tooth pair.
    pub ipr: BTreeMap<(Fdi, Fdi), f32>,
    /// Pairs whose overlap passed the IPR limit this step (they block).
    ipr_over: BTreeSet<(usize, usize)>,
    /// Consecutive steps in which nothing moved.
    still_steps: u32,
    /// Impacts in all steps (`impulse`).
    pub total_impacts: usize,
    /// Kinetic energy lost in all impacts (µJ).
    pub total_energy_lost_uj: f64,
    /// The PDL model's contacts, forces and twists between steps.
    pub pdl: PdlState,
    /// Clinical (PDL) or simulated (paper) time elapsed (days).
    pub elapsed_days: f64,
    /// The overlaps found at the end of the last step for its contacts that touched at their
    /// start (exact method), by tooth pair: the next step's queries start from them.
    /// (Each holds the geometries it was found for; a query ignores one of other meshes.)
    known: BTreeMap<(usize, usize), EndOverlap>,
    /// Archwires with their brackets, at most one per arch.
    pub wires: Vec<ArchWire>,
    /// Intermaxillary elastics between the arches' brackets.
    pub elastics: Vec<Elastic>,
    /// The anterior teeth's anatomic contact points (Little's irregularity index).
    pub contact_points: ContactPoints,
    /// Where teeth stand aligned, where known ([`crate::teeth::Dentition::setup`]): brackets are
    /// bonded so that their slots are level there.
    pub setup: BTreeMap<Fdi, crate::geometry::Pose>,
    /// The alveolar envelope whose cortical plates hold the roots (made at the first PDL step).
    pub bone: Option<crate::appliance::AlveolarEnvelope>,
    /// The case's bone meshes (upper, lower), as the dentition places them.
    pub bone_files: [Option<std::sync::Arc<crate::geometry::TriMesh>>; 2],
    /// The bone meshes' hold on the roots they cover, in place of the envelope's (made with it).
    pub bone_meshes: Option<crate::appliance::bone_mesh::BoneMeshes>,
    /// Every root that reached a cortical plate, in the order they did.
    pub cortical: Vec<CorticalContact>,
}

fn row(arch: Arch) -> usize {
    match arch {
        Arch::Upper => 0,
        Arch::Lower => 1,
    }
}

impl Simulation {
    /// The index of a tooth.
    pub fn index_of(&self, fdi: Fdi) -> Option<usize> {
        self.teeth.iter().position(|t| t.fdi == fdi)
    }

    /// Little's irregularity index of `arch` where the teeth stand now (mm), or None when one of
    /// its six anterior teeth is missing.
    pub fn irregularity_mm(&self, arch: Arch) -> Option<f32> {
        let anteriors: Vec<Anterior> = self
            .teeth
            .iter()
            .filter(|t| t.fdi.arch() == arch && t.fdi.position() <= 3)
            .map(|t| Anterior {
                fdi: t.fdi,
                geometry: &t.shape.geometry,
                pose: t.pose,
            })
            .collect();
        irregularity_mm(&anteriors, &self.contact_points, arch)
    }

    /// Forces received from blocked neighbours, acting in the coming step.
    pub fn passed_forces(&self) -> &[Vec3] {
        &self.next_passed
    }

    fn curve(&self, i: usize) -> &ArchCurve {
        &self.curves[row(self.teeth[i].fdi.arch())]
    }

    fn arch_frame(&self, i: usize) -> ArchFrame {
        frame_at(self.curve(i), self.teeth[i].arc)
    }

    fn body(&self, i: usize) -> Body<'_> {
        Body {
            shape: &self.teeth[i].shape,
            circle: self.teeth[i].circle,
            motion: self.motions[i],
        }
    }

    /// Candidate pairs for the current motions.
    pub fn broad_pairs(&self) -> Vec<(usize, usize)> {
        let items: Vec<BroadItem> = self
            .teeth
            .iter()
            .zip(&self.motions)
            .map(|(t, m)| BroadItem {
                fdi: t.fdi,
                root: t
                    .shape
                    .tree
                    .spheres
                    .first()
                    .copied()
                    .unwrap_or(crate::geometry::Sphere::new(Vec3::ZERO, 0.0)),
                local_box: t.shape.local_box,
                motion: *m,
            })
            .collect();
        let mut pairs = Vec::new();
        candidate_pairs(&items, &mut pairs);
        pairs
    }

    /// The narrow phase on `pairs` with the current motions, each pair starting from the
    /// overlap its contact carried at the end of the last step (which the query uses only for
    /// the same meshes).
    pub fn narrow(&self, pairs: &[(usize, usize)]) -> Vec<Found> {
        pairs
            .iter()
            .filter_map(|&(a, b)| {
                let known = self.known.get(&(a, b));
                query_knowing(self.method, &self.body(a), &self.body(b), known)
                    .map(|contact| Found { a, b, contact })
            })
            .collect()
    }

    /// Keeps the overlaps the last step's contacts carried, for the next step's queries.
    fn keep_overlaps(&mut self) {
        self.known = (self.last.contacts.iter())
            .filter_map(|f| Some(((f.a, f.b), f.contact.end_overlap.clone()?)))
            .collect();
    }

    /// One whole step: propose, detect, respond, commit.
    pub fn step(&mut self) -> &StepOutcome {
        let t = Instant::now();
        self.propose();
        let motion_ns = t.elapsed().as_nanos() as u64;
        let t0 = Instant::now();
        let pairs = self.broad_pairs();
        let found = self.narrow(&pairs);
        let tested = pairs.len();
        self.resolve(found);
        self.keep_overlaps();
        self.last.pairs_tested = tested;
        self.last.queries += tested;
        self.last.collision_ns = t0.elapsed().as_nanos() as u64;
        self.last.motion_ns = motion_ns;
        self.last.contact_solve_ns = self.pdl.solve_ns;
        self.commit();
        &self.last
    }

    /// Writes the end poses: the step is done.
    pub fn commit(&mut self) {
        let mut moved = 0;
        for i in 0..self.teeth.len() {
            let m = self.motions[i];
            if m.is_still() {
                continue;
            }
            // Moves below the f32 resolution of a pose are dropped (staying is always safe), so
            // blocked teeth do not jitter by rounding.
            if m.speed_bound(self.teeth[i].shape.max_rho as f64) <= STILL_MM {
                self.motions[i] = Motion::still(m.start);
                continue;
            }
            moved += 1;
            self.teeth[i].pose = m.end;
            self.teeth[i].arc = arc_of(self.curve(i), &m.end);
        }
        if self.settings.response == Response::Ipr {
            for f in &self.last.contacts {
                let (ta, tb) = (&self.teeth[f.a], &self.teeth[f.b]);
                if ta.fdi.arch() != tb.fdi.arch() {
                    continue;
                }
                let sep = mesh_separation(
                    ta.shape.geometry.mesh_ref(),
                    &ta.pose,
                    tb.shape.geometry.mesh_ref(),
                    &tb.pose,
                );
                if sep.overlapping() && sep.penetration > 0.0 {
                    // Keyed in arch order (the patient's right first), as distances are.
                    let key = if ta.fdi.arch_index() < tb.fdi.arch_index() {
                        (ta.fdi, tb.fdi)
                    } else {
                        (tb.fdi, ta.fdi)
                    };
                    let e = self.ipr.entry(key).or_insert(0.0);
                    *e = e.max(sep.penetration);
                }
            }
        }
        self.total_impacts += self.last.impacts.len();
        self.total_energy_lost_uj += self
            .last
            .impacts
            .iter()
            .map(|i| i.energy_lost_uj)
            .sum::<f64>();
        self.last.moved = moved;
        self.still_steps = if moved == 0 { self.still_steps + 1 } else { 0 };
        self.elapsed_days += match self.settings.model {
            MovementModel::Pdl => self.settings.pdl.step_days(),
            MovementModel::Paper => self.settings.step_s as f64 / 86_400.0,
        };
        if self.settings.model == MovementModel::Pdl {
            let before: Vec<(usize, usize)> =
                self.pdl.touching.iter().map(|f| (f.a, f.b)).collect();
            self.carry_contacts();
            let after: Vec<(usize, usize)> = self.pdl.touching.iter().map(|f| (f.a, f.b)).collect();
            // Nothing moved and the contacts are the same: the next solve is this one again.
            self.last.at_rest = moved == 0 && (before == after || self.still_steps >= 2);
            self.steps += 1;
            return;
        }
        // Standing still with the same passed loads changes nothing in later steps; loads passed
        // back and forth between blocked teeth may cycle, which settles within a pass along a
        // whole arch.
        self.last.at_rest =
            moved == 0 && (self.next_passed == self.passed || self.still_steps >= REST_STEPS);
        self.steps += 1;
    }
}
