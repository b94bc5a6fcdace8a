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
//! Determinism: every loop runs in tooth order and contacts are processed sorted by pair, so the
//! same case and settings give bit-identical poses.

use std::{
    collections::{BTreeMap, BTreeSet},
    time::Instant,
};

use glam::{Mat3, Quat, Vec3};
use serde::Serialize;

use super::{
    arch_path::{ArchFrame, arc_of, frame_at, next_present_tooth},
    model::{
        Centres, Drive, StepMove, ToothConstraint, angle_between, constrain, drive_at,
        largest_fraction,
    },
    settings::{MovementSettings, Response},
};
use crate::{
    collision::{
        Body, Circle, CollisionShape, Method, Motion, PairContact,
        broad_phase::{BroadItem, candidate_pairs},
        narrow_phase::spheres,
        query,
    },
    geometry::{Pose, mesh_separation},
    teeth::{Arch, Dentition, Fdi, Load, WireModel, arch::ArchCurve},
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
    /// Contacts as the step ended (for the last motions tested of each pair).
    pub contacts: Vec<Found>,
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
}

fn row(arch: Arch) -> usize {
    match arch {
        Arch::Upper => 0,
        Arch::Lower => 1,
    }
}

impl Simulation {
    /// A simulation of the visible teeth of `d`, with a collision shape for each (`shapes` in any
    /// order, one per visible tooth).
    pub fn new(
        d: &Dentition,
        shapes: Vec<(Fdi, CollisionShape)>,
        method: Method,
        settings: MovementSettings,
    ) -> Result<Self, String> {
        settings.validate()?;
        let curves = [
            ArchCurve::new(&d.arch_forms[0]),
            ArchCurve::new(&d.arch_forms[1]),
        ];
        let case = &d.case.case;
        let mut teeth = Vec::new();
        for t in d.visible() {
            let shape = shapes
                .iter()
                .find(|(f, _)| *f == t.fdi)
                .map(|(_, s)| s.clone())
                .ok_or_else(|| format!("no collision shape for tooth {}", t.fdi))?;
            let mut constraint = ToothConstraint::default();
            for c in case
                .constraints
                .iter()
                .filter(|c| c.teeth.0.contains(&t.fdi))
            {
                let and = |a: crate::teeth::case::Freedoms, b: crate::teeth::case::Freedoms| {
                    crate::teeth::case::Freedoms {
                        mesial: a.mesial && b.mesial,
                        buccal: a.buccal && b.buccal,
                        occlusal: a.occlusal && b.occlusal,
                    }
                };
                constraint.translate = and(constraint.translate, c.translate);
                constraint.rotate = and(constraint.rotate, c.rotate);
                let min = |a: Option<f32>, b: Option<f32>| match (a, b) {
                    (Some(x), Some(y)) => Some(x.min(y)),
                    (x, None) => x,
                    (None, y) => y,
                };
                constraint.max_translation_mm = min(
                    constraint.max_translation_mm,
                    c.max_translation_mm.map(|v| v.0),
                );
                constraint.max_rotation_rad = min(
                    constraint.max_rotation_rad,
                    c.max_rotation_deg.map(|v| v.0.to_radians()),
                );
            }
            let curve = &curves[row(t.fdi.arch())];
            teeth.push(SimTooth {
                fdi: t.fdi,
                circle: Circle::of(&t.geometry, &t.pose),
                shape,
                wire: t.wire,
                load: Load {
                    force: t.force,
                    torque: t.torque,
                },
                group: t.group,
                constraint,
                initial: t.pose,
                pose: t.pose,
                arc: arc_of(curve, &t.pose),
            });
        }
        let groups = d
            .groups
            .iter()
            .map(|g| SimGroup {
                members: teeth
                    .iter()
                    .enumerate()
                    .filter(|(_, t)| g.teeth.contains(&t.fdi))
                    .map(|(i, _)| i)
                    .collect(),
                load: Load {
                    force: g.force,
                    torque: g.torque,
                },
            })
            .collect();
        let n = teeth.len();
        Ok(Self {
            motions: teeth.iter().map(|t| Motion::still(t.pose)).collect(),
            teeth,
            groups,
            curves,
            settings,
            method,
            passed: vec![Vec3::ZERO; n],
            next_passed: vec![Vec3::ZERO; n],
            effective: vec![Vec3::ZERO; n],
            steps: 0,
            last: StepOutcome::default(),
            ipr: BTreeMap::new(),
            ipr_over: BTreeSet::new(),
            still_steps: 0,
            total_impacts: 0,
            total_energy_lost_uj: 0.0,
        })
    }

    /// The index of a tooth.
    pub fn index_of(&self, fdi: Fdi) -> Option<usize> {
        self.teeth.iter().position(|t| t.fdi == fdi)
    }

    /// Replaces a tooth's own load (for the UI and messages); refuses, keeping the old one, a load
    /// that [`Load::check`] refuses.
    pub fn set_load(&mut self, i: usize, load: Load) -> Result<(), String> {
        load.check()?;
        self.teeth[i].load = load;
        Ok(())
    }

    /// Replaces a tooth's archwire model.
    pub fn set_wire(&mut self, i: usize, wire: WireModel) {
        self.teeth[i].wire = wire;
    }

    /// The same simulation with tooth `fdi` extracted (`extract`) or restored, for extracting and
    /// restoring teeth while a case runs. `d` is the case the simulation was made from; `shape` is
    /// the restored tooth's collision shape (unused when extracting).
    ///
    /// The other teeth keep their current poses, loads, wire models and displacements, and the step
    /// count, IPR record and impact totals carry over; forces passed between neighbours start
    /// afresh (the neighbours changed). A restored tooth comes back at its place in the case with
    /// its case load; it is refused, with the reason, when a tooth has moved into that place (the
    /// meshes would overlap) or when it is not a tooth of the case.
    pub fn with_extraction(
        &self,
        d: &Dentition,
        fdi: Fdi,
        extract: bool,
        shape: Option<CollisionShape>,
    ) -> Result<Self, String> {
        let Some(placed) = d.tooth(fdi) else {
            return Err(format!("tooth {fdi} is not in the case"));
        };
        let present = self.index_of(fdi).is_some();
        if extract && !present {
            return Err(format!("tooth {fdi} is already extracted"));
        }
        if !extract && present {
            return Err(format!("tooth {fdi} is already in place"));
        }
        let mut shapes: Vec<(Fdi, CollisionShape)> = self
            .teeth
            .iter()
            .filter(|t| t.fdi != fdi)
            .map(|t| (t.fdi, t.shape.clone()))
            .collect();
        if !extract {
            let shape = shape.ok_or_else(|| format!("tooth {fdi} has no collision shape yet"))?;
            let radius = shape
                .tree
                .spheres
                .first()
                .map_or(f32::INFINITY, |s| s.radius);
            let centre = shape
                .tree
                .spheres
                .first()
                .map_or(Vec3::ZERO, |s| placed.pose.transform_point(s.centre));
            for t in &self.teeth {
                let Some(root) = t.shape.tree.spheres.first() else {
                    continue;
                };
                let far =
                    t.pose.transform_point(root.centre).distance(centre) > radius + root.radius;
                if far {
                    continue;
                }
                let sep = mesh_separation(
                    shape.geometry.mesh_ref(),
                    &placed.pose,
                    t.shape.geometry.mesh_ref(),
                    &t.pose,
                );
                if sep.overlapping() {
                    return Err(format!(
                        "cannot restore tooth {fdi}: tooth {} has moved into its place \
                         (overlap {:.2} mm)",
                        t.fdi, sep.penetration
                    ));
                }
            }
            shapes.push((fdi, shape));
        }
        let mut edited = d.clone();
        for t in &mut edited.teeth {
            if t.fdi == fdi {
                t.extracted = extract;
            } else if let Some(i) = self.index_of(t.fdi) {
                t.extracted = false;
                t.pose = self.teeth[i].pose;
            } else {
                t.extracted = true;
            }
        }
        let mut next = Self::new(&edited, shapes, self.method, self.settings)?;
        // (A restored tooth starts from the case: its initial pose, load and wire.)
        for t in &mut next.teeth {
            if let Some(i) = self.index_of(t.fdi) {
                let old = &self.teeth[i];
                t.initial = old.initial;
                t.load = old.load;
                t.wire = old.wire;
            }
        }
        for (g, old) in next.groups.iter_mut().zip(&self.groups) {
            g.load = old.load;
        }
        next.steps = self.steps;
        next.ipr = self.ipr.clone();
        next.total_impacts = self.total_impacts;
        next.total_energy_lost_uj = self.total_energy_lost_uj;
        Ok(next)
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

    fn within_limits(&self, i: usize, pose: &Pose) -> bool {
        let t = &self.teeth[i];
        let c = &t.constraint;
        if let Some(max) = c.max_translation_mm {
            let p = t.shape.geometry.frame.crown_centre;
            if pose
                .transform_point(p)
                .distance(t.initial.transform_point(p))
                > max + 1e-6
            {
                return false;
            }
        }
        if let Some(max) = c.max_rotation_rad
            && angle_between(pose.rotation, t.initial.rotation) > max + 1e-7
        {
            return false;
        }
        true
    }

    /// Moves `members` by the drive `d` (constrained in the first member's frames), as far as the
    /// limits of all of them allow.
    fn move_block(&mut self, members: &[usize], d: Drive) {
        let lead = members[0];
        let frame = self.arch_frame(lead);
        let d = constrain(
            d,
            &self.teeth[lead].constraint,
            &frame,
            &self.teeth[lead].pose,
            self.teeth[lead].fdi,
        );
        let dt = self.settings.step_s;
        if d.is_zero() {
            return;
        }
        let end = |sim: &Self, i: usize, f: f32| {
            StepMove::of(&d, &frame, dt, f).apply(
                sim.curve(i),
                &sim.teeth[i].pose,
                sim.teeth[i].arc,
            )
        };
        let f = largest_fraction(|f| {
            members
                .iter()
                .all(|&i| self.within_limits(i, &end(self, i, f)))
        });
        if f <= 1e-6 {
            return;
        }
        for &i in members {
            let to = end(self, i, f);
            if to.is_finite() {
                self.motions[i] = Motion {
                    start: self.teeth[i].pose,
                    end: to,
                };
            }
        }
    }

    /// Loads and motion: each tooth's (or group's) net load and the motion it proposes this step.
    pub fn propose(&mut self) {
        let n = self.teeth.len();
        self.passed = std::mem::replace(&mut self.next_passed, vec![Vec3::ZERO; n]);
        self.motions = self.teeth.iter().map(|t| Motion::still(t.pose)).collect();
        self.ipr_over.clear();
        for i in 0..n {
            if self.teeth[i].group.is_some() {
                continue;
            }
            let t = &self.teeth[i];
            let force = t.load.force + self.passed[i];
            self.effective[i] = force;
            let d = drive_at(force, t.load.torque, t.wire, t.centres(), &self.settings);
            self.move_block(&[i], d);
        }
        for g in 0..self.groups.len() {
            let members = self.groups[g].members.clone();
            if members.is_empty() {
                continue;
            }
            let load = self.groups[g].load;
            let force = load.force + members.iter().map(|&i| self.passed[i]).sum::<Vec3>();
            let k = members.len() as f32;
            let centres = members.iter().map(|&i| self.teeth[i].centres());
            let mean = centres.fold(
                Centres {
                    crown: Vec3::ZERO,
                    tipping: Vec3::ZERO,
                    long_axis: Vec3::ZERO,
                },
                |a, c| Centres {
                    crown: a.crown + c.crown / k,
                    tipping: a.tipping + c.tipping / k,
                    long_axis: a.long_axis + c.long_axis,
                },
            );
            for &i in &members {
                self.effective[i] = force;
            }
            let wire = self.teeth[members[0]].wire;
            let d = drive_at(force, load.torque, wire, mean, &self.settings);
            self.move_block(&members, d);
        }
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

    /// The narrow phase on `pairs` with the current motions.
    pub fn narrow(&self, pairs: &[(usize, usize)]) -> Vec<Found> {
        pairs
            .iter()
            .filter_map(|&(a, b)| {
                query(self.method, &self.body(a), &self.body(b)).map(|contact| Found {
                    a,
                    b,
                    contact,
                })
            })
            .collect()
    }

    /// One whole step: propose, detect, respond, commit.
    pub fn step(&mut self) -> &StepOutcome {
        self.propose();
        let t0 = Instant::now();
        let pairs = self.broad_pairs();
        let found = self.narrow(&pairs);
        let tested = pairs.len();
        self.resolve(found);
        self.last.pairs_tested = tested;
        self.last.queries += tested;
        self.last.collision_ns = t0.elapsed().as_nanos() as u64;
        self.commit();
        &self.last
    }

    /// Whether the contact's teeth approach each other at time `t` of the step.
    fn closing(&self, f: &Found, t: f32) -> bool {
        self.approach(f, t, self.motions[f.a], self.motions[f.b])
    }

    /// Whether tooth `x` of the contact, moving alone (the other held at its start pose),
    /// approaches the other.
    fn closes_alone(&self, f: &Found, t: f32, x: usize) -> bool {
        let (ma, mb) = (self.motions[f.a], self.motions[f.b]);
        if x == f.a {
            self.approach(f, t, ma, Motion::still(mb.start))
        } else {
            self.approach(f, t, Motion::still(ma.start), mb)
        }
    }

    /// Whether the contact's features approach each other at time `t` under motions `ma`, `mb`.
    fn approach(&self, f: &Found, t: f32, ma: Motion, mb: Motion) -> bool {
        let (ma, mb) = (&ma, &mb);
        let (ta, tb) = (&self.teeth[f.a], &self.teeth[f.b]);
        let c = &f.contact;
        match self.method {
            Method::Circles => {
                let d0 = ta
                    .circle
                    .centre_at(&ma.start)
                    .distance(tb.circle.centre_at(&mb.start));
                let d1 = ta
                    .circle
                    .centre_at(&ma.end)
                    .distance(tb.circle.centre_at(&mb.end));
                d1 < d0 - 1e-7
            }
            Method::Spheres => c.leaf_pairs.iter().any(|&(u, v)| {
                let (cu, cv) = (
                    ta.shape.tree.spheres[u as usize].centre,
                    tb.shape.tree.spheres[v as usize].centre,
                );
                let d0 = ma
                    .start
                    .transform_point(cu)
                    .distance(mb.start.transform_point(cv));
                let d1 = ma
                    .end
                    .transform_point(cu)
                    .distance(mb.end.transform_point(cv));
                d1 < d0 - 1e-7
            }),
            Method::Continuous => c.leaf_pairs.iter().any(|&(u, v)| {
                let (cu, cv) = (
                    ta.shape.tree.spheres[u as usize].centre.as_dvec3(),
                    tb.shape.tree.spheres[v as usize].centre.as_dvec3(),
                );
                let at = |m: &Motion, p: glam::DVec3, end: bool| {
                    let pose = if end { &m.end } else { &m.start };
                    pose.rotation.as_dquat() * p + pose.translation.as_dvec3()
                };
                let a0 = at(mb, cv, false) - at(ma, cu, false);
                let a1 = at(mb, cv, true) - at(ma, cu, true);
                let b = a1 - a0;
                a0.dot(b) + b.length_squared() * (t as f64) < -1e-12
            }),
            Method::Exact => {
                let n = c.normal;
                let velocity = |m: &Motion, p: Vec3| {
                    let local = m.at(t).inverse().transform_point(p);
                    m.end.transform_point(local) - m.start.transform_point(local)
                };
                let rel = velocity(mb, c.points[1]) - velocity(ma, c.points[0]);
                rel.dot(n) < -1e-7
            }
        }
    }

    /// For a contact already touching at the start: whether the overlap is deeper at the end of
    /// the step than at its start (exact: the meshes overlap at the end more than at the start;
    /// continuous and spheres: the deepest overlap of leaf spheres grows, or appears). This catches
    /// what the contact points' velocities miss under rotation: other parts of the surfaces closing
    /// in.
    fn deepens(&self, f: &Found) -> bool {
        let (ta, tb) = (&self.teeth[f.a], &self.teeth[f.b]);
        let (ma, mb) = (&self.motions[f.a], &self.motions[f.b]);
        match self.method {
            Method::Exact => {
                let end = mesh_separation(
                    ta.shape.geometry.mesh_ref(),
                    &ma.end,
                    tb.shape.geometry.mesh_ref(),
                    &mb.end,
                )
                .signed_gap();
                end < 0.0 && end < -f.contact.depth_mm - 1e-6
            }
            Method::Continuous | Method::Spheres => {
                let depth = |pairs: &[(u32, u32)], pa: &Pose, pb: &Pose| {
                    pairs
                        .iter()
                        .map(|&(u, v)| {
                            let (su, sv) = (
                                ta.shape.tree.spheres[u as usize],
                                tb.shape.tree.spheres[v as usize],
                            );
                            su.radius + sv.radius
                                - pa.transform_point(su.centre)
                                    .distance(pb.transform_point(sv.centre))
                        })
                        .fold(f32::NEG_INFINITY, f32::max)
                };
                // Every overlapping leaf pair at each end of the step. The discrete contact
                // already lists those at the end; the continuous search reports only those it
                // needed.
                let at = |i: usize, pose: Pose| Body {
                    shape: &self.teeth[i].shape,
                    circle: self.teeth[i].circle,
                    motion: Motion::still(pose),
                };
                let end = if self.method == Method::Spheres {
                    depth(&f.contact.leaf_pairs, &ma.end, &mb.end)
                } else {
                    match spheres::query(&at(f.a, ma.end), &at(f.b, mb.end)) {
                        Some(c) => depth(&c.leaf_pairs, &ma.end, &mb.end),
                        None => return false,
                    }
                };
                let start = spheres::query(&at(f.a, ma.start), &at(f.b, mb.start))
                    .map_or(f32::NEG_INFINITY, |c| {
                        depth(&c.leaf_pairs, &ma.start, &mb.start)
                    });
                end > start + 1e-6
            }
            Method::Circles => false,
        }
    }

    /// The time at which the contact stops its teeth, or None when it does not block.
    fn blocking_time(&self, f: &Found) -> Option<f32> {
        let same_arch = self.teeth[f.a].fdi.arch() == self.teeth[f.b].fdi.arch();
        if self.method == Method::Circles && !same_arch {
            return None;
        }
        if self.settings.response == Response::Ipr && same_arch {
            return (self.ipr_over.contains(&(f.a, f.b)) && self.closing(f, 0.0)).then_some(0.0);
        }
        match self.method {
            Method::Circles => self.closing(f, 1.0).then_some(0.0),
            // Leaf spheres of neighbours overlap at rest and some pair of them approaches under
            // almost any motion, so, as for `continuous`, only a deepening overlap blocks.
            Method::Spheres => self.deepens(f).then_some(0.0),
            Method::Continuous | Method::Exact => {
                let t = f.contact.time_of_contact;
                if t >= 1.0 - TIME_SLACK {
                    None
                } else if t <= 1e-6 {
                    // Continuous: leaf spheres overlap at rest, and some pair of them approaches
                    // under almost any motion, so only a deepening overlap blocks (sliding along a
                    // neighbour is free). Exact: approaching contact points, or deeper overlap.
                    let blocks = match self.method {
                        Method::Continuous => self.deepens(f),
                        _ => self.closing(f, t) || self.deepens(f),
                    };
                    blocks.then_some(0.0)
                } else {
                    Some(t)
                }
            }
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
            Response::Block => self.block(found, true),
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

    /// Mass (kg), world inverse inertia about the centre of mass, velocity and angular velocity of
    /// a tooth over this step's motion.
    fn dynamics(&self, i: usize) -> (f32, Mat3, Vec3, Vec3) {
        let g = &self.teeth[i].shape.geometry;
        let m = self.motions[i];
        let rho = self.settings.density_kg_per_mm3;
        let mass = (g.frame.volume_mm3 as f32) * rho;
        let r = Mat3::from_quat(m.start.rotation);
        let inertia = r * (g.frame.inertia * rho) * r.transpose();
        let dt = self.settings.step_s;
        let com = g.frame.centre_of_mass;
        let v = (m.end.transform_point(com) - m.start.transform_point(com)) / dt;
        let dq = (m.end.rotation * m.start.rotation.inverse()).normalize();
        let w = dq.to_scaled_axis() / dt;
        (mass, inertia.inverse(), v, w)
    }

    /// Exchanges momentum at each tooth's earliest contact; returns which teeth changed motion.
    fn impulse(&mut self, found: &[Found]) -> Vec<bool> {
        let n = self.teeth.len();
        let mut events: Vec<(f32, usize)> = found
            .iter()
            .enumerate()
            .filter_map(|(k, f)| self.blocking_time(f).map(|t| (t, k)))
            .collect();
        events.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut hit = vec![false; n];
        for (t, k) in events {
            let f = &found[k];
            let (a, b) = (f.a, f.b);
            if hit[a] || hit[b] {
                continue;
            }
            let normal = f.contact.normal.normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            let point = 0.5 * (f.contact.points[0] + f.contact.points[1]);
            let (ma, ia, va, wa) = self.dynamics(a);
            let (mb, ib, vb, wb) = self.dynamics(b);
            let com = |i: usize| {
                self.motions[i]
                    .at(t)
                    .transform_point(self.teeth[i].shape.geometry.frame.centre_of_mass)
            };
            let (ca, cb) = (com(a), com(b));
            let (ra, rb) = (point - ca, point - cb);
            let rel = (vb + wb.cross(rb)) - (va + wa.cross(ra));
            let vn = rel.dot(normal);
            if vn >= 0.0 {
                continue;
            }
            let k_eff = 1.0 / ma
                + 1.0 / mb
                + normal.dot((ia * ra.cross(normal)).cross(ra))
                + normal.dot((ib * rb.cross(normal)).cross(rb));
            let j = -(1.0 + self.settings.restitution) * vn / k_eff;
            let impulse = normal * j;
            let (va2, wa2) = (va - impulse / ma, wa - ia * ra.cross(impulse));
            let (vb2, wb2) = (vb + impulse / mb, wb + ib * rb.cross(impulse));
            let energy = |v: Vec3, w: Vec3, m: f32, inv: Mat3| -> f64 {
                let i = inv.inverse();
                0.5 * (m * v.length_squared()) as f64 + 0.5 * w.dot(i * w) as f64
            };
            let before = energy(va, wa, ma, ia) + energy(vb, wb, mb, ib);
            let after = energy(va2, wa2, ma, ia) + energy(vb2, wb2, mb, ib);
            self.last.impacts.push(Impact {
                a: self.teeth[a].fdi,
                b: self.teeth[b].fdi,
                time_of_contact: t,
                velocity_before: [va, vb],
                velocity_after: [va2, vb2],
                angular_before: [wa, wb],
                angular_after: [wa2, wb2],
                energy_before_uj: before,
                energy_lost_uj: before - after,
            });
            let dt = self.settings.step_s;
            for (i, v, w, c) in [(a, va2, wa2, ca), (b, vb2, wb2, cb)] {
                let frame = self.arch_frame(i);
                let d = constrain(
                    Drive {
                        velocity: v,
                        angular: w,
                        pivot: Vec3::ZERO,
                    },
                    &self.teeth[i].constraint,
                    &frame,
                    &self.teeth[i].pose,
                    self.teeth[i].fdi,
                );
                let m = self.motions[i];
                let at = m.at(t);
                let h = (1.0 - t) * dt;
                let turn = Quat::from_scaled_axis(d.angular * h);
                let end = Pose::new(
                    (turn * at.rotation).normalize(),
                    c + d.velocity * h + turn * (at.translation - c),
                );
                if end.is_finite() && self.within_limits(i, &end) {
                    self.motions[i] = Motion {
                        start: m.start,
                        end,
                    };
                } else {
                    self.motions[i] = Motion {
                        start: m.start,
                        end: at,
                    };
                }
                hit[i] = true;
            }
        }
        hit
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
        // Standing still with the same passed loads changes nothing in later steps; loads passed
        // back and forth between blocked teeth may cycle, which settles within a pass along a
        // whole arch.
        self.last.at_rest =
            moved == 0 && (self.next_passed == self.passed || self.still_steps >= REST_STEPS);
        self.steps += 1;
    }
}
