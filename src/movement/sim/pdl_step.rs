//! The PDL model's loads and motion for a step: each tooth (or group) as a body on its ligament,
//! the contact forces of the touching teeth solved together, and the twist of each body in the
//! step's clinical time, applied as a rigid motion about its centre of resistance.
//!
//! Contacts are those the last step's narrow phase reported (where the teeth touched as the step
//! ended), and earlier ones between teeth that have not moved since. The solve asks touching teeth
//! that move together to open by [`PUSH_BIAS_MM`] per step, so that rounding never makes the
//! pushed tooth trail its pusher; teeth at rest are never pushed apart.

use std::sync::Arc;

use glam::{DMat3, DVec3, Vec3};

use super::{Found, Simulation};
use crate::{
    collision::Motion,
    geometry::{Pose, Vec6, halves, vec6},
    movement::{
        MovementError,
        model::{Drive, angle_between},
        pdl::{
            ContactRow, PdlBody, PdlStiffness, SolveParams, blocked, centre_of_elasticity,
            constrained_compliance, rotated, shifted, solve_contacts, wrench,
        },
    },
    teeth::WireModel,
};

/// Opening speed asked of touching teeth that move together (mm per step).
pub const PUSH_BIAS_MM: f64 = 1e-5;
/// How many times its own stiffness a bonded tooth's motion is damped by: the wire couples each
/// bracket to its neighbours, and a bracket's stiffness matrix over the arch (a continuous beam's,
/// rows like 1, −4, 6, −4, 1) has eigenvalues up to about 2.7 times its diagonal; damping by
/// three times the diagonal keeps every tooth's step from overshooting whatever its neighbours
/// do at once, at the price of a slower approach under very stiff wires.
pub const WIRE_COUPLING: f64 = 3.0;
/// Convergence tolerance of the contact solve (mm per step).
pub const SOLVE_TOLERANCE_MM: f64 = 1e-9;
/// Most sweeps of the contact solve.
pub const MAX_SWEEPS: usize = 200;

/// The PDL state of a simulation between steps.
#[derive(Clone, Debug, Default)]
pub struct PdlState {
    /// Contacts carried into the next step's solve (touching as the last step ended).
    pub touching: Vec<Found>,
    /// The forces of the last solve, one per touching contact (N).
    pub forces: Vec<f64>,
    /// Each tooth's twist in the last step (world, about its centre of resistance; mm, rad).
    pub twists: Vec<Vec6>,
    /// Each tooth's net wrench in the last step (world, about its centre of resistance).
    pub wrenches: Vec<Vec6>,
    /// Sweeps of the last contact solve.
    pub sweeps: usize,
    /// Time of the last contact solve (ns).
    pub solve_ns: u64,
    /// Each single tooth's body as last made, with what it was made from (a body is made again
    /// only when its pose, load, wire or M/F change).
    pub cache: Vec<Option<(BodyKey, PdlBody)>>,
}

/// The directions among `axes` (orthonormal) that the wire holds when the appliance's own load
/// is `load`: all of them, less the load's own direction within their span (the load is what the
/// appliance delivers, so the wire does not resist it; it resists everything else).
fn held_directions<const N: usize>(axes: [Vec3; N], load: Vec3) -> Vec<DVec3> {
    let axes = axes.map(|a| a.as_dvec3());
    let load = load.as_dvec3();
    let within: DVec3 = axes.iter().map(|a| *a * a.dot(load)).sum();
    let Some(free) = within
        .try_normalize()
        .filter(|_| within.length() > 1e-6 * load.length())
    else {
        return axes.to_vec();
    };
    // An orthonormal basis of the span without `free`: Gram–Schmidt on the axes.
    let mut out: Vec<DVec3> = Vec::new();
    for a in axes {
        let mut v = a - free * free.dot(a);
        for o in &out {
            v -= *o * o.dot(v);
        }
        if let Some(v) = v.try_normalize().filter(|_| v.length() > 1e-6) {
            out.push(v);
        }
    }
    out
}

/// What a tooth's body depends on besides the settings and its constraints.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyKey {
    pose: Pose,
    load: crate::teeth::Load,
    wire: WireModel,
    mf: Option<f32>,
}

/// One body of the step: its members and its ligament.
struct Unit {
    members: Vec<usize>,
    body: PdlBody,
}

impl Simulation {
    /// Computes the ligament of every tooth that has none, once per distinct shape (a simulation
    /// remade for an extraction or restoration keeps the ligaments it had).
    ///
    /// # Errors
    /// [`MovementError::Pdl`] naming the tooth whose root cannot carry a ligament.
    pub(crate) fn prepare_pdl(&mut self) -> Result<(), MovementError> {
        let mut made: Vec<(*const crate::teeth::ToothGeometry, Arc<PdlStiffness>)> = Vec::new();
        for t in &mut self.teeth {
            if t.pdl.is_some() {
                continue;
            }
            let g = &t.shape.geometry;
            let key = Arc::as_ptr(g);
            if let Some((_, p)) = made.iter().find(|(k, _)| *k == key) {
                t.pdl = Some(p.clone());
                continue;
            }
            let p = Arc::new(
                PdlStiffness::of(g, &self.settings.pdl)
                    .map_err(|source| MovementError::Pdl { fdi: t.fdi, source })?,
            );
            made.push((key, p.clone()));
            t.pdl = Some(p);
        }
        Ok(())
    }

    /// World centre of resistance of tooth `i` at its current pose.
    pub fn centre_of_resistance(&self, i: usize) -> Option<Vec3> {
        let t = &self.teeth[i];
        Some(t.pose.transform_point(t.pdl.as_ref()?.centre_of_resistance))
    }

    /// World bracket point of tooth `i` at its current pose.
    pub fn bracket(&self, i: usize) -> Option<Vec3> {
        let t = &self.teeth[i];
        Some(t.pose.transform_point(t.pdl.as_ref()?.bracket))
    }

    /// The current centre of rotation of tooth `i` (world): the point of its last step's screw
    /// axis nearest its centre of resistance; None when it did not turn (or translated).
    pub fn centre_of_rotation(&self, i: usize) -> Option<Vec3> {
        let t = self.pdl.twists.get(i)?;
        let c = self.centre_of_resistance(i)?.as_dvec3();
        let (u, theta) = halves(t);
        let tt = theta.length_squared();
        // A turn that moves the tooth less than its translation over 100 mm counts as none.
        if tt <= 0.0 || theta.length() * 100.0 < u.length() {
            return None;
        }
        Some((c + theta.cross(u) / tt).as_vec3())
    }

    /// The orthonormal twists tooth `i` may make (constraints: arch-frame translations, rotations
    /// about its anatomical axes).
    fn allowed_twists(&self, i: usize) -> Vec<Vec6> {
        let t = &self.teeth[i];
        let c = &t.constraint;
        let frame = self.arch_frame(i);
        let anatomical = [
            t.pose
                .transform_vector(Vec3::X * t.fdi.local_x_mesial_sign()),
            t.pose.transform_vector(Vec3::Z),
            t.pose.transform_vector(Vec3::Y),
        ];
        let flags = |f: crate::teeth::case::Freedoms| [f.mesial, f.buccal, f.occlusal];
        let mut out = Vec::new();
        for (axis, on) in [frame.tangent, frame.buccal, frame.up]
            .into_iter()
            .zip(flags(c.translate))
        {
            if on {
                out.push(vec6(axis.as_dvec3().normalize(), DVec3::ZERO));
            }
        }
        for (axis, on) in anatomical.into_iter().zip(flags(c.rotate)) {
            if on {
                out.push(vec6(DVec3::ZERO, axis.as_dvec3().normalize()));
            }
        }
        out
    }

    /// The body of `members` (one tooth, or a group led by the first) under `force` at the
    /// bracket(s) and `torque`, and the archwire's loads on the members that carry brackets
    /// (which replace the old wire model's blocking for the whole body).
    fn unit(&self, members: Vec<usize>, force: Vec3, torque: Vec3) -> Option<Unit> {
        let wire: Vec<_> = members.iter().flat_map(|&i| self.wire_loads(i)).collect();
        let lead = members[0];
        let s = &self.settings.pdl;
        let mut parts = Vec::new();
        for &i in &members {
            let t = &self.teeth[i];
            let p = t.pdl.as_ref()?;
            let r = DMat3::from_quat(t.pose.rotation.as_dquat());
            let c = t.pose.transform_point(p.centre_of_resistance).as_dvec3();
            parts.push((rotated(&p.stiffness, r), c, p));
        }
        let n = parts.len() as f64;
        let mean = parts.iter().map(|(_, c, _)| *c).sum::<DVec3>() / n;
        let sum = parts
            .iter()
            .fold(crate::geometry::Mat6::ZERO, |acc, (k, c, _)| {
                acc.add_scaled(&shifted(k, *c, mean), 1.0)
            });
        let centre = if members.len() == 1 {
            parts[0].1
        } else {
            centre_of_elasticity(&sum, mean)?
        };
        let k = shifted(&sum, mean, centre);
        let mut compliance = constrained_compliance(&k, &self.allowed_twists(lead))?;
        let t = &self.teeth[lead];
        let bracket = members
            .iter()
            .filter_map(|&i| self.bracket(i))
            .sum::<Vec3>()
            / n as f32;
        let axis = t.pose.transform_vector(t.shape.geometry.frame.long_axis);
        if s.wire_holds_brackets && wire.is_empty() {
            let frame = self.arch_frame(lead);
            let b = bracket.as_dvec3() - centre;
            let across: Vec<Vec6> = held_directions([frame.buccal, frame.up], force)
                .into_iter()
                .map(|n| vec6(n, b.cross(n)))
                .collect();
            compliance = blocked(&compliance, &across, 1.0);
        }
        let mut couple = torque.as_dvec3();
        let model = if wire.is_empty() { Some(t.wire) } else { None };
        match (model, t.mf) {
            (Some(WireModel::Rectangular), Some(mf)) => {
                couple -= (axis.cross(force) * mf).as_dvec3();
            }
            (Some(WireModel::Rectangular), None) => {
                let turns: Vec<Vec6> = held_directions([Vec3::X, Vec3::Y, Vec3::Z], torque)
                    .into_iter()
                    .map(|n| vec6(DVec3::ZERO, n))
                    .collect();
                compliance = blocked(&compliance, &turns, s.wire_engagement as f64);
            }
            (Some(WireModel::Round), _) | (None, _) => {}
        }
        let mut applied = wrench(force.as_dvec3(), bracket.as_dvec3(), couple, centre);
        let mut appliance_stiffness = None;
        if !wire.is_empty() {
            let (w, k) = super::archwire::about(&wire, centre);
            for (a, b) in applied.iter_mut().zip(w) {
                *a += b;
            }
            // Backward Euler against the wire's stiffness, K taken [`WIRE_COUPLING`] times over
            // for the neighbours pulled along through the wire.
            let mut stiff = k;
            for row in stiff.0.iter_mut() {
                for v in row.iter_mut() {
                    *v *= WIRE_COUPLING;
                }
            }
            appliance_stiffness = Some(stiff);
        }
        let area = parts.iter().map(|(_, _, p)| p.root_area_mm2).sum();
        Some(Unit {
            members,
            body: PdlBody {
                centre,
                compliance,
                area,
                mean_spring: parts[0].2.mean_spring,
                applied,
                appliance_stiffness,
            },
        })
    }

    /// Loads and motion under the PDL model (see the module doc).
    pub(super) fn propose_pdl(&mut self) {
        let n = self.teeth.len();
        // Only loaded teeth and teeth in contact can move: the others are not bodies this step.
        let loaded = |l: &crate::teeth::Load| l.force != Vec3::ZERO || l.torque != Vec3::ZERO;
        self.solve_wires();
        self.ensure_bone();
        let mut needed: Vec<bool> = (0..n)
            .map(|i| loaded(&self.teeth[i].load) || self.is_bonded(i))
            .collect();
        for f in &self.pdl.touching {
            needed[f.a] = true;
            needed[f.b] = true;
        }
        if self.pdl.cache.len() != n {
            self.pdl.cache = vec![None; n];
        }
        let mut units = Vec::new();
        for i in 0..n {
            let t = &self.teeth[i];
            if t.group.is_some() || !needed[i] {
                continue;
            }
            let key = BodyKey {
                pose: t.pose,
                load: t.load,
                wire: t.wire,
                mf: t.mf,
            };
            let bonded = self.is_bonded(i);
            let cached = self.pdl.cache[i]
                .as_ref()
                .filter(|(k, _)| *k == key && !bonded)
                .map(|(_, b)| b.clone());
            let body = match cached {
                Some(b) => Some(b),
                None => {
                    let made = self
                        .unit(vec![i], t.load.force, t.load.torque)
                        .map(|u| u.body);
                    self.pdl.cache[i] = made.clone().map(|b| (key, b));
                    made
                }
            };
            units.extend(body.map(|body| Unit {
                members: vec![i],
                body,
            }));
        }
        for g in &self.groups {
            let wanted = g.members.iter().any(|&i| needed[i]) || loaded(&g.load);
            if !g.members.is_empty() && wanted {
                units.extend(self.unit(g.members.clone(), g.load.force, g.load.torque));
            }
        }
        let mut body_of = vec![usize::MAX; n];
        for (u, unit) in units.iter().enumerate() {
            for &i in &unit.members {
                body_of[i] = u;
            }
        }
        let mut rows = Vec::new();
        let mut row_of = Vec::new();
        for (k, f) in self.pdl.touching.iter().enumerate() {
            let (a, b) = (body_of[f.a], body_of[f.b]);
            let normal = f.contact.normal.as_dvec3();
            if a == usize::MAX || b == usize::MAX || a == b || normal.length_squared() < 0.5 {
                continue;
            }
            rows.push(ContactRow {
                a,
                b,
                point: ((f.contact.points[0] + f.contact.points[1]) * 0.5).as_dvec3(),
                normal: normal.normalize(),
                bias: 0.0,
            });
            row_of.push(k);
        }
        let (members, mut bodies): (Vec<Vec<usize>>, Vec<PdlBody>) =
            units.into_iter().map(|u| (u.members, u.body)).unzip();
        // The bone's plates: rows against one more body, which never moves.
        let tooth_rows = rows.len();
        let plates = self.plate_rows(&members, bodies.len());
        if !plates.is_empty() {
            bodies.push(PdlBody::fixed(DVec3::ZERO));
            rows.extend(plates);
        }
        let s = &self.settings.pdl;
        let params = SolveParams {
            rate: s.remodelling_per_day as f64 * s.step_days(),
            threshold_kpa: s.threshold_kpa as f64,
            saturation_kpa: s.saturation_kpa as f64,
            tolerance: SOLVE_TOLERANCE_MM,
            max_sweeps: MAX_SWEEPS,
        };
        let mut warm: Vec<f64> = row_of
            .iter()
            .map(|&k| self.pdl.forces.get(k).copied().unwrap_or(0.0))
            .collect();
        warm.resize(rows.len(), 0.0);
        let clock = std::time::Instant::now();
        let mut solve = solve_contacts(&bodies, &rows, Some(&warm), &params);
        // Touching teeth that move together open by the bias (see the module doc).
        let moving = |t: &Vec6| t.iter().any(|v| *v != 0.0);
        let pushing: Vec<bool> = rows[..tooth_rows]
            .iter()
            .zip(&solve.forces)
            .map(|(r, f)| *f > 0.0 && (moving(&solve.twists[r.a]) || moving(&solve.twists[r.b])))
            .collect();
        if pushing.iter().any(|&p| p) {
            for (r, p) in rows.iter_mut().zip(&pushing) {
                if *p {
                    r.bias = PUSH_BIAS_MM;
                }
            }
            solve = solve_contacts(&bodies, &rows, Some(&solve.forces), &params);
        }
        self.pdl.sweeps = solve.sweeps;
        self.pdl.solve_ns = clock.elapsed().as_nanos() as u64;
        let mut forces = vec![0.0; self.pdl.touching.len()];
        for (r, &k) in row_of.iter().enumerate() {
            forces[k] = solve.forces[r];
        }
        self.pdl.forces = forces;
        self.pdl.twists = vec![[0.0; 6]; n];
        self.pdl.wrenches = vec![[0.0; 6]; n];
        for (u, group) in members.iter().enumerate() {
            for &i in group {
                self.pdl.twists[i] = solve.twists[u];
                self.pdl.wrenches[i] = solve.wrenches[u];
                self.effective[i] = halves(&solve.wrenches[u]).0.as_vec3();
            }
        }
        for (u, group) in members.iter().enumerate() {
            let (v, w) = halves(&solve.twists[u]);
            let d = Drive {
                velocity: v.as_vec3(),
                angular: w.as_vec3(),
                pivot: bodies[u].centre.as_vec3(),
            };
            if !d.is_zero() {
                self.move_rigid(group, d);
            }
        }
    }

    /// Moves `members` rigidly by the per-step twist `d` about its pivot, as far as the limits of
    /// all of them allow.
    fn move_rigid(&mut self, members: &[usize], d: Drive) {
        let end = |pose: &Pose, f: f32| {
            let turn = glam::Quat::from_scaled_axis(d.angular * f);
            Pose::new(
                (turn * pose.rotation).normalize(),
                d.pivot + d.velocity * f + turn * (pose.translation - d.pivot),
            )
        };
        let f = crate::movement::model::largest_fraction(|f| {
            members
                .iter()
                .all(|&i| self.within_limits(i, &end(&self.teeth[i].pose, f)))
        });
        if f <= 1e-6 {
            return;
        }
        for &i in members {
            let to = end(&self.teeth[i].pose, f);
            if to.is_finite() {
                self.motions[i] = Motion {
                    start: self.teeth[i].pose,
                    end: to,
                };
            }
        }
    }

    /// Carries contacts into the next step: those found in this step (at its end, or where they
    /// stopped a tooth), and earlier ones between teeth that did not move.
    pub(super) fn carry_contacts(&mut self) {
        let mut next: Vec<Found> = self.last.contacts.clone();
        for b in &self.last.blocking {
            if !next.iter().any(|f| (f.a, f.b) == (b.a, b.b)) {
                next.push(b.clone());
            }
        }
        next.sort_by_key(|f| (f.a, f.b));
        let mut forces: Vec<f64> = next
            .iter()
            .map(|f| {
                self.pdl
                    .touching
                    .iter()
                    .position(|o| (o.a, o.b) == (f.a, f.b))
                    .map_or(0.0, |k| self.pdl.forces.get(k).copied().unwrap_or(0.0))
            })
            .collect();
        for (k, old) in self.pdl.touching.iter().enumerate() {
            let still = self.motions[old.a].is_still() && self.motions[old.b].is_still();
            if still && !next.iter().any(|f| (f.a, f.b) == (old.a, old.b)) {
                next.push(old.clone());
                forces.push(self.pdl.forces.get(k).copied().unwrap_or(0.0));
            }
        }
        self.pdl.touching = next;
        self.pdl.forces = forces;
    }

    /// Rotation of tooth `i` from its initial pose (degrees).
    pub fn rotation_deg(&self, i: usize) -> f32 {
        let t = &self.teeth[i];
        angle_between(t.pose.rotation, t.initial.rotation).to_degrees()
    }
}
