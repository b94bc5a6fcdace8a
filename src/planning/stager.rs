//! Staging: from the initial teeth to the target in stages within the limits, with no two teeth
//! of an arch passing through each other at any stage or between stages.
//!
//! 1. Each tooth's movement is split into the fewest stages its limits allow ([`ToothMove`]);
//!    the sequence sets when each starts (and a case's `wait` delays a tooth further).
//! 2. Every transition from one stage to the next is checked for every pair of teeth of an arch
//!    that can come near during it ([`clearance::transition`]: conservative advancement on the
//!    exact mesh distance). A pair may overlap by what it already overlapped in the scan
//!    (never deeper) and, from the stage its IPR is done, by the enamel removed; beyond that, plus
//!    `tolerance_mm`, it collides.
//! 3. The earliest collision is resolved, and the plan checked again (the measures of transitions
//!    that did not change are kept): a pair whose target needs IPR gets it at the stage of the
//!    collision (done before the teeth move on from it); otherwise one of the two teeth that
//!    moves in that transition waits a stage, the one whose wait takes the pair's first
//!    collision furthest (each tooth waits at most as many stages as the plan had before any
//!    wait); when no wait takes it later, the contact gets IPR in `ipr_step_mm` steps within its
//!    limit; failing that the pair is reported as blocked, with the stage, depth and reason, and
//!    the plan goes on without it.
//!
//! The opposing arch is not checked: stages move the teeth of one arch among themselves (the
//! bite open, as it is while aligners are worn). The plan reports how deep opposing teeth
//! overlap, and the first molars' relation, as scanned and at the target.

use std::collections::{BTreeMap, HashMap};
use std::time::Instant;

use glam::{Vec2, Vec3};
use serde::Serialize;

use super::anchorage::Relations;
use super::clearance::{self, BAND_MM, Clearance, Mover};
use super::limits::{PlanLimits, group};
use super::moves::ToothMove;
use super::target::{ArchSetup, Target};
use crate::collision::Motion;
use crate::geometry::{Pose, Sphere, mesh_separation};
use crate::teeth::{Arch, Dentition, Fdi, PlacedTooth, arch::ArchCurve};

/// Most resolution rounds before the remaining collisions are reported as blocked.
const MAX_ROUNDS: usize = 2000;

/// A tooth of the plan.
#[derive(Clone, Debug, Serialize)]
pub struct PlanTooth {
    /// The tooth.
    pub fdi: Fdi,
    /// Crown-centre travel from the initial to the target place (mm).
    pub total_mm: f32,
    /// Rotation from the initial to the target orientation (degrees).
    pub total_deg: f32,
    /// The movement's components in the arch's frame at the tooth (mesio-distal, bucco-lingual,
    /// vertical mm; rotation, tip, torque degrees).
    pub components: [f32; 6],
    /// The stage it starts moving after (0: from the first stage).
    pub start: u32,
    /// Stages it moves in.
    pub moving_stages: u32,
    /// Where it stands at each stage, 0 (initial) to the last: the crown centre's displacement
    /// from the initial place (x, y, z mm, world) and the rotation from the initial orientation
    /// as a rotation vector (x, y, z degrees, world).
    pub stages: Vec<[f32; 6]>,
}

/// IPR at one contact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PlanIpr {
    /// One tooth of the contact (nearer the patient's right).
    pub a: Fdi,
    /// The other.
    pub b: Fdi,
    /// The stage at which it is done (before the teeth move on from it).
    pub stage: u32,
    /// Enamel removed (mm, both teeth together, half from each).
    pub mm: f32,
}

/// A pair the plan could not take past each other.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Blocked {
    /// One tooth.
    pub a: Fdi,
    /// The other.
    pub b: Fdi,
    /// The transition from this stage to the next where they collide.
    pub stage: u32,
    /// How deep they go inside each other beyond what is allowed (mm).
    pub depth_mm: f32,
    /// Why the stager could not resolve it.
    pub why: String,
}

/// A staged plan.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// The case's name.
    pub case: String,
    /// Number of stages after the initial one.
    pub stages: u32,
    /// The limits it was planned within.
    pub limits: PlanLimits,
    /// `automatic` or `file`.
    pub target: &'static str,
    /// How the automatic target set up each arch.
    pub setup: Vec<ArchSetup>,
    /// IPR, by stage.
    pub ipr: Vec<PlanIpr>,
    /// Every present tooth.
    pub teeth: Vec<PlanTooth>,
    /// Deepest penetration measured anywhere in the plan beyond what is allowed (mm; 0: none).
    pub max_penetration_mm: f32,
    /// Deepest overlap of two teeth in the scan as it stands (mm; 0: none).
    pub scan_overlap_mm: f32,
    /// Deepest overlap between an upper and a lower tooth (mm; 0: none) with the arches where
    /// the case places them: as the scan stands, then at the target. The stages do not check
    /// the opposing arch; this says whether the target's bite closes into itself.
    pub opposing_overlap_mm: [f32; 2],
    /// The first molars' sagittal relation (mm; the upper mesiobuccal cusp tip ahead of the
    /// lower buccal groove, 0 in class I, positive towards class II), patient's right then left,
    /// as scanned and at the target; `None` where a first molar is missing.
    pub molar_relation_mm: [[Option<f32>; 2]; 2],
    /// The canines' sagittal relation (mm; the upper cusp tip mesial of the embrasure between
    /// the lower canine and the tooth distal to it, 0 in class I, positive towards class II),
    /// right then left, as scanned and at the target; `None` where a tooth is missing.
    pub canine_relation_mm: [[Option<f32>; 2]; 2],
    /// The central incisors' mean overjet (mm) as scanned and at the target; `None` where it
    /// cannot be measured.
    pub overjet_mm: [Option<f32>; 2],
    /// Pairs the plan could not take past each other.
    pub blocked: Vec<Blocked>,
    /// Exact distance queries made.
    pub measures: u64,
    /// Resolution rounds.
    pub rounds: usize,
    /// Time to set up the target (ms).
    pub target_ms: f64,
    /// Time to stage and check (ms).
    pub plan_ms: f64,
    /// The movements, for stage meshes and the viewer.
    #[serde(skip)]
    pub moves: Vec<ToothMove>,
}

impl Plan {
    /// Every present tooth's pose at stage `k`.
    pub fn poses_at(&self, k: u32) -> Vec<(Fdi, Pose)> {
        self.moves.iter().map(|m| (m.fdi, m.pose_at(k))).collect()
    }

    /// How much tooth `i` (of [`Plan::moves`]) still has to move at stage `k`: 0 when done, 1 for
    /// 2 mm of crown travel or 10° of rotation or more (what the pictures and the viewer colour).
    pub fn still_to_move(&self, i: usize, k: u32) -> f32 {
        let m = &self.moves[i];
        let (mm, deg) = m.totals();
        ((1.0 - m.fraction_at(k)) * (mm / 2.0).max(deg / 10.0)).clamp(0.0, 1.0)
    }

    /// One line: canine and first-molar relations (right / left) and overjet, as scanned and at
    /// the target.
    pub fn relations_summary(&self) -> String {
        let v = |v: Option<f32>| v.map_or("–".to_owned(), |v| format!("{v:.2}"));
        let pair = |p: [Option<f32>; 2]| format!("{} / {}", v(p[0]), v(p[1]));
        let [(m0, c0), (m1, c1)] =
            [0, 1].map(|k| (self.molar_relation_mm[k], self.canine_relation_mm[k]));
        format!(
            "relations (right / left, mm; 0 is class I, positive towards class II): canines {} as scanned, {} at the target; first molars {} as scanned, {} at the target; overjet {} mm as scanned, {} mm at the target",
            pair(c0),
            pair(c1),
            pair(m0),
            pair(m1),
            v(self.overjet_mm[0]),
            v(self.overjet_mm[1])
        )
    }
}

/// The arch's mesial and buccal unit directions at a tooth's place on its arch's `curves`
/// (upper, lower).
fn arch_axes(curves: &[ArchCurve; 2], t: &PlacedTooth) -> [Vec3; 2] {
    let curve = &curves[if t.fdi.arch() == Arch::Upper { 0 } else { 1 }];
    let s = curve.project(Vec2::new(t.pose.translation.x, t.pose.translation.z));
    let (_, tangent) = curve.at(s);
    let along = Vec3::new(tangent.x, 0.0, tangent.y);
    let out = Vec3::new(-tangent.y, 0.0, tangent.x);
    let mesial = if s > 0.0 { -along } else { along };
    [mesial, out]
}

/// Cache key of one pair over one transition: the teeth and their fractions done at both ends.
type Key = (usize, usize, [u32; 4]);

struct Stager<'a> {
    teeth: Vec<&'a PlacedTooth>,
    moves: Vec<ToothMove>,
    spheres: Vec<(Vec3, f32)>,
    pairs: Vec<(usize, usize)>,
    limits: &'a PlanLimits,
    /// Overlap each pair had in the scan (mm, ≥ 0).
    scan_overlap: HashMap<(usize, usize), f32>,
    /// IPR the target needs per pair (mm).
    target_ipr: HashMap<(usize, usize), f32>,
    /// IPR scheduled per pair: (stage, mm).
    ipr: BTreeMap<(usize, usize), (u32, f32)>,
    cache: HashMap<Key, Clearance>,
    speeds: HashMap<(usize, [u32; 2]), f64>,
    measures: u64,
    /// Stages each tooth has been made to wait.
    waited: Vec<u32>,
    /// Most stages a tooth is made to wait: as many as the plan had before any wait.
    wait_cap: u32,
    /// Pairs given up on.
    blocked: Vec<Blocked>,
}

/// Plans the movement from the dentition as it stands to `target` (see the module doc).
pub fn plan(d: &Dentition, target: &Target, limits: &PlanLimits, target_ms: f64) -> Plan {
    let started = Instant::now();
    let teeth: Vec<&PlacedTooth> = d.visible().collect();
    let per_stage = limits.per_stage();
    let curves = d.arch_forms.map(|f| ArchCurve::new(&f));
    let mut moves: Vec<ToothMove> = teeth
        .iter()
        .map(|t| {
            let end = target.poses.get(&t.fdi).copied().unwrap_or(t.pose);
            let pivot = t.geometry.frame.crown_centre;
            ToothMove::new(t.fdi, t.pose, end, pivot, arch_axes(&curves, t), &per_stage)
        })
        .collect();
    let mut group_stages = [0u32; 4];
    for m in &moves {
        let g = group(m.fdi.kind());
        group_stages[g] = group_stages[g].max(m.steps);
    }
    for m in &mut moves {
        m.start_stage = limits.start_stage(m.fdi, group_stages);
    }
    let mut pairs = Vec::new();
    for i in 0..teeth.len() {
        for j in i + 1..teeth.len() {
            if teeth[i].fdi.arch() == teeth[j].fdi.arch() {
                pairs.push((i, j));
            }
        }
    }
    let index = |f: Fdi| teeth.iter().position(|t| t.fdi == f);
    let target_ipr = target
        .ipr
        .iter()
        .filter_map(|c| Some((ordered(index(c.a)?, index(c.b)?), c.mm)))
        .collect();
    let spheres = teeth
        .iter()
        .map(|t| {
            let s = Sphere::enclosing(&t.geometry.mesh.vertices);
            (s.centre, s.radius)
        })
        .collect();
    let mut s = Stager {
        waited: vec![0; teeth.len()],
        wait_cap: 0,
        teeth,
        moves,
        spheres,
        pairs,
        limits,
        scan_overlap: HashMap::new(),
        target_ipr,
        ipr: BTreeMap::new(),
        cache: HashMap::new(),
        speeds: HashMap::new(),
        measures: 0,
        blocked: Vec::new(),
    };
    s.measure_scan();
    s.wait_cap = s.stages().max(1);
    let mut rounds = 0;
    while rounds < MAX_ROUNDS {
        let Some((k, i, j, excess)) = s.first_collision() else {
            break;
        };
        rounds += 1;
        s.resolve(k, i, j, excess);
    }
    if rounds >= MAX_ROUNDS {
        while let Some((k, i, j, excess)) = s.first_collision() {
            s.block(
                k,
                i,
                j,
                excess,
                format!("still colliding after {MAX_ROUNDS} rounds"),
            );
        }
    }
    s.finish(d, target, limits, rounds, target_ms, started)
}

fn ordered(i: usize, j: usize) -> (usize, usize) {
    (i.min(j), i.max(j))
}

impl<'a> Stager<'a> {
    fn stages(&self) -> u32 {
        self.moves.iter().map(|m| m.end_stage()).max().unwrap_or(0)
    }

    /// The signed gap (mm, [`clearance::signed_gap`]) of teeth `i` and `j` at the given poses, or
    /// `None` when their bounding spheres are apart.
    fn gap_near(&mut self, i: usize, pi: &Pose, j: usize, pj: &Pose) -> Option<f32> {
        let ((ci, ri), (cj, rj)) = (self.spheres[i], self.spheres[j]);
        if pi.transform_point(ci).distance(pj.transform_point(cj)) > ri + rj {
            return None;
        }
        self.measures += 1;
        let (a, b) = (&self.teeth[i].geometry, &self.teeth[j].geometry);
        Some(clearance::signed_gap(&mesh_separation(
            a.mesh_ref(),
            pi,
            b.mesh_ref(),
            pj,
        )))
    }

    /// The overlap of every pair as the scan stands.
    fn measure_scan(&mut self) {
        for p in 0..self.pairs.len() {
            let (i, j) = self.pairs[p];
            let (pi, pj) = (self.teeth[i].pose, self.teeth[j].pose);
            if let Some(gap) = self.gap_near(i, &pi, j, &pj)
                && gap < 0.0
            {
                self.scan_overlap.insert((i, j), -gap);
            }
        }
    }

    /// Canine and molar relations at stage `k`.
    fn relations(&self, d: &Dentition, k: u32) -> Relations {
        let poses = self
            .teeth
            .iter()
            .zip(&self.moves)
            .map(|(t, m)| (t.fdi, m.pose_at(k)))
            .collect();
        Relations::measure(d, &poses)
    }

    /// The deepest overlap between an upper and a lower tooth at stage `k` (mm).
    fn opposing_overlap(&mut self, k: u32) -> f32 {
        let mut deepest = 0.0f32;
        for i in 0..self.teeth.len() {
            for j in i + 1..self.teeth.len() {
                if self.teeth[i].fdi.arch() == self.teeth[j].fdi.arch() {
                    continue;
                }
                let (pi, pj) = (self.moves[i].pose_at(k), self.moves[j].pose_at(k));
                if let Some(gap) = self.gap_near(i, &pi, j, &pj) {
                    deepest = deepest.max(-gap);
                }
            }
        }
        deepest
    }

    /// Penetration allowed to pair (i, j) during the transition from stage `k`.
    fn allowed(&self, i: usize, j: usize, k: u32) -> f32 {
        let scan = self.scan_overlap.get(&(i, j)).copied().unwrap_or(0.0);
        let ipr = match self.ipr.get(&(i, j)) {
            Some(&(stage, mm)) if stage <= k => mm,
            _ => 0.0,
        };
        scan + ipr + self.limits.tolerance_mm.0
    }

    fn speed(&mut self, i: usize, fr: [f32; 2]) -> f64 {
        let key = (i, fr.map(f32::to_bits));
        if let Some(s) = self.speeds.get(&key) {
            return *s;
        }
        let m = &self.moves[i];
        let motion = Motion {
            start: m.at_fraction(fr[0]),
            end: m.at_fraction(fr[1]),
        };
        let speed = Mover::new(self.teeth[i].geometry.mesh_ref(), motion).speed;
        self.speeds.insert(key, speed);
        speed
    }

    /// The check of pair (i, j) over the transition from stage k (cached).
    fn check(&mut self, i: usize, j: usize, k: u32) -> Option<Clearance> {
        let (mi, mj) = (&self.moves[i], &self.moves[j]);
        let fi = [mi.fraction_at(k), mi.fraction_at(k + 1)];
        let fj = [mj.fraction_at(k), mj.fraction_at(k + 1)];
        if fi[0] == fi[1] && fj[0] == fj[1] {
            // Neither moves: as at the end of the last transition that moved them.
            return None;
        }
        let key = (i, j, [fi[0], fi[1], fj[0], fj[1]].map(f32::to_bits));
        if let Some(c) = self.cache.get(&key) {
            return Some(*c);
        }
        let (si, sj) = (self.speed(i, fi), self.speed(j, fj));
        let (mi, mj) = (&self.moves[i], &self.moves[j]);
        let (pi0, pj0) = (mi.at_fraction(fi[0]), mj.at_fraction(fj[0]));
        let ((ci, ri), (cj, rj)) = (self.spheres[i], self.spheres[j]);
        let apart = pi0.transform_point(ci).distance(pj0.transform_point(cj)) - ri - rj;
        let c = if apart as f64 > si + sj + 2.0 * BAND_MM as f64 {
            Clearance {
                least_gap_mm: f32::INFINITY,
                at: 0.0,
                measures: 0,
                complete: true,
            }
        } else {
            let a = Mover {
                mesh: self.teeth[i].geometry.mesh_ref(),
                motion: Motion {
                    start: pi0,
                    end: mi.at_fraction(fi[1]),
                },
                speed: si,
            };
            let b = Mover {
                mesh: self.teeth[j].geometry.mesh_ref(),
                motion: Motion {
                    start: pj0,
                    end: mj.at_fraction(fj[1]),
                },
                speed: sj,
            };
            clearance::transition(&a, &b)
        };
        self.measures += c.measures as u64;
        self.cache.insert(key, c);
        Some(c)
    }

    /// The earliest transition with a colliding pair: (stage, i, j, depth beyond allowed).
    fn first_collision(&mut self) -> Option<(u32, usize, usize, f32)> {
        let n = self.stages();
        for k in 0..n {
            for p in 0..self.pairs.len() {
                let (i, j) = self.pairs[p];
                if self.is_blocked(i, j) {
                    continue;
                }
                let Some(c) = self.check(i, j, k) else {
                    continue;
                };
                let excess = c.excess(self.allowed(i, j, k));
                if excess > 0.0 || !c.complete {
                    return Some((k, i, j, excess));
                }
            }
        }
        None
    }

    fn is_blocked(&self, i: usize, j: usize) -> bool {
        let (a, b) = (self.teeth[i].fdi, self.teeth[j].fdi);
        self.blocked.iter().any(|x| x.a == a && x.b == b)
    }

    fn block(&mut self, k: u32, i: usize, j: usize, excess: f32, why: String) {
        self.blocked.push(Blocked {
            a: self.teeth[i].fdi,
            b: self.teeth[j].fdi,
            stage: k,
            depth_mm: excess,
            why,
        });
    }

    /// True when i and j are neighbours along their arch (nothing present between them).
    fn neighbours(&self, i: usize, j: usize) -> bool {
        let (a, b) = (
            self.teeth[i].fdi.arch_index(),
            self.teeth[j].fdi.arch_index(),
        );
        let (lo, hi) = (a.min(b), a.max(b));
        !self.teeth.iter().any(|t| {
            t.fdi.arch() == self.teeth[i].fdi.arch()
                && t.fdi.arch_index() > lo
                && t.fdi.arch_index() < hi
        })
    }

    /// The first transition at which pair (i, j) collides, if any.
    fn pair_collision(&mut self, i: usize, j: usize) -> Option<u32> {
        (0..self.stages()).find(|&k| {
            self.check(i, j, k)
                .is_some_and(|c| c.excess(self.allowed(i, j, k)) > 0.0 || !c.complete)
        })
    }

    /// Resolves the collision of pair (i, j) at the transition from stage `k` (see the module
    /// doc).
    fn resolve(&mut self, k: u32, i: usize, j: usize, excess: f32) {
        // The target's own IPR, done before the teeth first collide.
        if let Some(&mm) = self.target_ipr.get(&(i, j)) {
            let done = self.ipr.get(&(i, j)).copied();
            if !done.is_some_and(|(stage, have)| stage <= k && have >= mm) {
                let have = done.map_or(0.0, |x| x.1);
                self.ipr.insert((i, j), (k, mm.max(have)));
                return;
            }
        }
        // A tooth that moves in this transition waits a stage, if that takes the pair's first
        // collision later; of the two, the one that takes it furthest.
        let mut best: Option<(usize, u32)> = None;
        for who in [i, j] {
            let m = &self.moves[who];
            if m.fraction_at(k) == m.fraction_at(k + 1) || self.waited[who] >= self.wait_cap {
                continue;
            }
            self.moves[who].start_stage += 1;
            let next = self.pair_collision(i, j).unwrap_or(u32::MAX);
            self.moves[who].start_stage -= 1;
            if next > k && best.is_none_or(|(_, b)| next > b) {
                best = Some((who, next));
            }
        }
        if let Some((who, _)) = best {
            self.moves[who].start_stage += 1;
            self.waited[who] += 1;
            return;
        }
        // IPR at the contact, in steps, within its limit.
        let step = self.limits.ipr_step_mm.0;
        let limit = self
            .limits
            .ipr
            .between(self.teeth[i].fdi, self.teeth[j].fdi);
        let have = self.ipr.get(&(i, j)).map_or(0.0, |x| x.1);
        let want = have + (excess / step).ceil().max(1.0) * step;
        if self.neighbours(i, j) && want <= limit + 1e-4 {
            let stage = self.ipr.get(&(i, j)).map_or(k, |x| x.0.min(k));
            self.ipr.insert((i, j), (stage, want));
            return;
        }
        let why = if !self.neighbours(i, j) {
            "no wait parts them, and they are not neighbours, so IPR cannot".to_owned()
        } else {
            format!(
                "no wait parts them, and IPR of {want:.2} mm would pass the contact's {limit:.2} mm limit"
            )
        };
        self.block(k, i, j, excess, why);
    }

    fn finish(
        self,
        d: &Dentition,
        target: &Target,
        limits: &PlanLimits,
        rounds: usize,
        target_ms: f64,
        started: Instant,
    ) -> Plan {
        let n = self.stages();
        let mut max_excess = 0.0f32;
        let mut stager = self;
        for k in 0..n {
            for p in 0..stager.pairs.len() {
                let (i, j) = stager.pairs[p];
                if let Some(c) = stager.check(i, j, k) {
                    max_excess =
                        max_excess.max(c.excess(stager.allowed(i, j, k) - limits.tolerance_mm.0));
                }
            }
        }
        let teeth = stager
            .moves
            .iter()
            .map(|m| {
                let c0 = m.start.transform_point(m.pivot);
                let stages = (0..=n)
                    .map(|k| {
                        let p = m.pose_at(k);
                        let d = p.transform_point(m.pivot) - c0;
                        let mut q = p.rotation * m.start.rotation.inverse();
                        if q.w < 0.0 {
                            q = -q;
                        }
                        let r = q.to_scaled_axis() * 180.0 / std::f32::consts::PI;
                        [d.x, d.y, d.z, r.x, r.y, r.z]
                    })
                    .collect();
                let (total_mm, total_deg) = m.totals();
                PlanTooth {
                    fdi: m.fdi,
                    total_mm,
                    total_deg,
                    components: m.components,
                    start: m.start_stage,
                    moving_stages: m.steps,
                    stages,
                }
            })
            .collect();
        let ipr = stager
            .ipr
            .iter()
            .map(|(&(i, j), &(stage, mm))| PlanIpr {
                a: stager.teeth[i].fdi,
                b: stager.teeth[j].fdi,
                stage,
                mm,
            })
            .collect();
        let scan_overlap_mm = stager.scan_overlap.values().copied().fold(0.0, f32::max);
        let opposing_overlap_mm = [stager.opposing_overlap(0), stager.opposing_overlap(n)];
        let relations = [stager.relations(d, 0), stager.relations(d, n)];
        let molar_relation_mm = relations.map(|r| r.molar_mm);
        let canine_relation_mm = relations.map(|r| r.canine_mm);
        let overjet_mm = relations.map(|r| r.overjet_mm);
        Plan {
            case: d.case.case.name.clone(),
            stages: n,
            limits: limits.clone(),
            target: target.source,
            setup: target.arches.clone(),
            ipr,
            teeth,
            max_penetration_mm: max_excess,
            scan_overlap_mm,
            opposing_overlap_mm,
            molar_relation_mm,
            canine_relation_mm,
            overjet_mm,
            blocked: stager.blocked,
            measures: stager.measures,
            rounds,
            target_ms,
            plan_ms: started.elapsed().as_secs_f64() * 1e3,
            moves: stager.moves,
        }
    }
}
