//! Running a case to rest and measuring the result: the `simulate` command's JSON.
//!
//! Measures: `moved` lists teeth whose crown centre travelled more than [`MOVED_MM`];
//! `centre_distance_mm` is the paper's distance between adjacent crown centres in the x–z plane;
//! `surface_gap_mm` is the exact minimal distance between the meshes (negative: penetration);
//! `max_penetration_mm` is the exact triangle-level penetration depth, the largest over every pair
//! of teeth whose boxes overlap at the end.

use std::{collections::BTreeMap, time::Instant};

use serde::Serialize;

use super::{
    MovementError,
    settings::MovementSettings,
    sim::{CorticalContact, Simulation, WireChoice},
};
use crate::{
    appliance::ArchForm,
    collision::{Method, shape::collision_shapes},
    geometry::mesh_separation,
    sphere_tree::{TreeCache, TreeSettings},
    teeth::{Arch, Case, Dentition, Fdi},
};

/// Crown-centre travel above which a tooth counts as moved (mm).
pub const MOVED_MM: f32 = 0.1;

/// Distance between two adjacent teeth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairDistance {
    /// First tooth (the patient's right of the two).
    pub a: Fdi,
    /// Second tooth.
    pub b: Fdi,
    /// Distance of the crown centres in the x–z plane (mm).
    pub centre_distance_mm: f32,
    /// Exact surface gap (mm); negative when they overlap.
    pub surface_gap_mm: f32,
}

/// How far one tooth went: its crown tip and root apex (points on its long axis), world frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ToothTravel {
    /// FDI number.
    pub fdi: Fdi,
    /// Displacement of the crown tip (mm, world x, y, z).
    pub crown_displacement_mm: [f32; 3],
    /// Displacement of the root apex (mm, world x, y, z): opposite to the crown's when the tooth
    /// tipped, the same when it translated.
    pub apex_displacement_mm: [f32; 3],
    /// Rotation from the initial pose (degrees).
    pub rotation_deg: f32,
}

/// Crown-tip and apex travel of every tooth of a simulation.
pub fn tooth_travel(sim: &Simulation) -> Vec<ToothTravel> {
    sim.teeth
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let f = &t.shape.geometry.frame;
            let tip = f.cervical_centre + f.long_axis * f.crown_length;
            let moved = |p: glam::Vec3| {
                (t.pose.transform_point(p) - t.initial.transform_point(p)).to_array()
            };
            ToothTravel {
                fdi: t.fdi,
                crown_displacement_mm: moved(tip),
                apex_displacement_mm: moved(f.apex),
                rotation_deg: sim.rotation_deg(i),
            }
        })
        .collect()
}

/// The result of `orthosim simulate`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SimulationReport {
    /// Case name.
    pub case: String,
    /// Narrow-phase method.
    pub algorithm: String,
    /// Collision response.
    pub response: String,
    /// Movement model (`pdl` or `paper`).
    pub model: String,
    /// Steps taken.
    pub steps: u64,
    /// Clinical (PDL) or simulated (paper) time elapsed (days).
    pub days: f64,
    /// True when the teeth came to rest before the step limit.
    pub at_rest: bool,
    /// Teeth whose crown centre moved more than 0.1 mm.
    pub moved: Vec<Fdi>,
    /// Crown-centre travel per tooth (mm), keyed by FDI number.
    pub displacement_mm: BTreeMap<String, f32>,
    /// Largest exact penetration between any two teeth at the end (mm).
    pub max_penetration_mm: f32,
    /// Adjacent teeth along each arch.
    pub distances: Vec<PairDistance>,
    /// Sum of the adjacent centre distances (mm).
    pub total_centre_distance_mm: f32,
    /// Mean collision detection and response time per step (µs).
    pub collision_us_per_step: f64,
    /// Mean time per step, everything included (µs).
    pub step_us: f64,
    /// Interproximal reduction per contact (mm), keyed "a-b" (`ipr` response).
    pub ipr_mm: BTreeMap<String, f32>,
    /// Impacts (`impulse` response).
    pub impacts: usize,
    /// Kinetic energy lost in all impacts (µJ).
    pub energy_lost_uj: f64,
    /// Crown-tip and apex travel and rotation per tooth.
    pub teeth: Vec<ToothTravel>,
    /// Brackets and archwires, when the case bonds any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub appliance: Option<ApplianceReport>,
    /// Every root that reached a cortical plate of the alveolar envelope (PDL model).
    pub cortical_contacts: Vec<CorticalContact>,
    /// The case's bone meshes, when it names any (PDL model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bone_meshes: Option<BoneMeshReport>,
}

/// What a case's bone meshes hold.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoneMeshReport {
    /// The teeth the meshes hold (the others keep the alveolar envelope).
    pub teeth: Vec<Fdi>,
    /// Held teeth with root points outside the bone as placed, which the mesh does not hold.
    pub outside: Vec<BoneOutside>,
}

/// A tooth's root points outside its bone mesh as placed (a dehiscence, or a plate the
/// segmentation thinned away).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoneOutside {
    /// The tooth.
    pub fdi: Fdi,
    /// Root points outside the bone.
    pub points: usize,
    /// Root points sampled.
    pub of: usize,
}

/// A wire as the report names it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WireReport {
    /// Alloy.
    pub material: &'static str,
    /// Section as clinicians write it.
    pub size: String,
    /// Arch form.
    pub form: ArchForm,
    /// Brackets' slot.
    pub slot: &'static str,
    /// Clinical day it was engaged.
    pub day: f64,
}

impl WireReport {
    fn of(day: f64, c: &WireChoice) -> Self {
        Self {
            material: c.material.name(),
            size: c.size.label(),
            form: c.form,
            slot: c.slot.label(),
            day,
        }
    }
}

/// What the wire does to one bracket at the end of the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BracketReport {
    /// The tooth.
    pub fdi: Fdi,
    /// Force on the bracket (N, world).
    pub force_n: [f64; 3],
    /// Moment on the bracket about its slot (N·mm, world).
    pub moment_nmm: [f64; 3],
    /// True when the wire bears on the slot (outside its play).
    pub engaged: bool,
    /// The slot's friction on the tooth in the last step (N along the slot's axis, which runs
    /// mesially on the patient's right and distally on the left).
    pub friction_n: f64,
}

/// An elastomeric chain at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChainReport {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth.
    pub to: Fdi,
    /// Clinical day it was placed, if it was.
    pub placed_day: Option<f64>,
    /// Tension (N).
    pub tension_n: f64,
}

/// A coil spring at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoilReport {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth.
    pub to: Fdi,
    /// "closed" or "open".
    pub kind: crate::appliance::coil::CoilKind,
    /// Clinical day it was placed, if it was.
    pub placed_day: Option<f64>,
    /// Force (N).
    pub force_n: f64,
}

/// An intermaxillary elastic at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ElasticReport {
    /// One end's tooth.
    pub from: Fdi,
    /// The other end's tooth.
    pub to: Fdi,
    /// Clinical day it was first worn, if it was.
    pub placed_day: Option<f64>,
    /// Force (N; 0 when not worn).
    pub force_n: f64,
}

/// The appliances at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ApplianceReport {
    /// The wire in place at the end (the lower arch's when both arches carry one).
    pub wire: WireReport,
    /// Each arch's wires in the order they were engaged.
    pub wires: BTreeMap<&'static str, Vec<WireReport>>,
    /// Every bracket, upper arch first, each from the patient's right.
    pub brackets: Vec<BracketReport>,
    /// Elastomeric chains at the end: ends and tension (N; 0 before it is placed or when slack).
    pub chains: Vec<ChainReport>,
    /// Coil springs at the end: ends, kind and force (N; 0 before placed or once spent).
    pub coils: Vec<CoilReport>,
    /// Intermaxillary elastics at the end: ends and force (N).
    pub elastics: Vec<ElasticReport>,
    /// Wire solves per step, all arches (µs: median and most), measured in this run.
    pub solve_us_per_step: [f64; 2],
    /// The median wire solve over the median collision step of this run.
    pub solve_over_collision: f64,
    /// Whether every wire solve of the run converged.
    pub converged: bool,
    /// Little's irregularity index of each arch over the run: `[day, mm]` at the start, at each
    /// whole day and at the end (empty for an arch missing an anterior tooth).
    pub irregularity_mm: Irregularity,
    /// Every root that reached a cortical plate (as the run's `cortical_contacts`).
    pub cortical_contacts: Vec<CorticalContact>,
}

/// Little's irregularity index of both arches over a run (see
/// [`crate::teeth::arch::irregularity`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Irregularity {
    /// Upper arch: `[day, mm]`.
    pub upper: Vec<[f64; 2]>,
    /// Lower arch: `[day, mm]`.
    pub lower: Vec<[f64; 2]>,
}

impl Irregularity {
    /// Adds both arches' index where the teeth of `sim` stand now.
    pub fn record(&mut self, sim: &Simulation) {
        for (arch, series) in [
            (Arch::Upper, &mut self.upper),
            (Arch::Lower, &mut self.lower),
        ] {
            if let Some(mm) = sim.irregularity_mm(arch) {
                series.push([sim.elapsed_days, f64::from(mm)]);
            }
        }
    }

    /// The first day the lower arch's index is under `mm`, if it gets there: the time to
    /// alignment as clinical trials count it.
    pub fn lower_aligned_day(&self, mm: f64) -> Option<f64> {
        self.lower.iter().find(|p| p[1] < mm).map(|p| p[0])
    }
}

/// How long a run may go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunLimit {
    /// Most steps.
    pub max_steps: u64,
    /// Most clinical days (PDL model), if limited.
    pub max_days: Option<f64>,
}

/// Adjacent present teeth along each arch, from the patient's right to left (indices).
pub fn neighbour_pairs(sim: &Simulation) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for arch in [Arch::Upper, Arch::Lower] {
        let mut row: Vec<usize> = (0..sim.teeth.len())
            .filter(|&i| sim.teeth[i].fdi.arch() == arch)
            .collect();
        row.sort_by_key(|&i| sim.teeth[i].fdi.arch_index());
        out.extend(row.windows(2).map(|w| (w[0], w[1])));
    }
    out
}

/// Centre distances and exact gaps of adjacent teeth.
pub fn pair_distances(sim: &Simulation) -> Vec<PairDistance> {
    neighbour_pairs(sim)
        .into_iter()
        .map(|(i, j)| {
            let (a, b) = (&sim.teeth[i], &sim.teeth[j]);
            let (ca, cb) = (a.crown_centre(), b.crown_centre());
            let centre = glam::Vec2::new(ca.x - cb.x, ca.z - cb.z).length();
            let gap = mesh_separation(
                a.shape.geometry.mesh_ref(),
                &a.pose,
                b.shape.geometry.mesh_ref(),
                &b.pose,
            )
            .signed_gap();
            PairDistance {
                a: a.fdi,
                b: b.fdi,
                centre_distance_mm: centre,
                surface_gap_mm: gap,
            }
        })
        .collect()
}

/// The largest exact penetration depth between any two teeth (0 when none overlap).
pub fn max_penetration(sim: &Simulation) -> f32 {
    let boxes: Vec<_> = sim
        .teeth
        .iter()
        .map(|t| {
            t.shape
                .local_box
                .transformed(&glam::Mat3::from_quat(t.pose.rotation), t.pose.translation)
        })
        .collect();
    let mut worst = 0.0f32;
    for i in 0..sim.teeth.len() {
        for j in i + 1..sim.teeth.len() {
            let (bi, bj) = (&boxes[i], &boxes[j]);
            if !(bi.min.cmple(bj.max).all() && bj.min.cmple(bi.max).all()) {
                continue;
            }
            let (a, b) = (&sim.teeth[i], &sim.teeth[j]);
            let sep = mesh_separation(
                a.shape.geometry.mesh_ref(),
                &a.pose,
                b.shape.geometry.mesh_ref(),
                &b.pose,
            );
            if sep.overlapping() {
                worst = worst.max(sep.penetration);
            }
        }
    }
    worst
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn appliance_report(
    sim: &Simulation,
    collision_steps: Vec<f64>,
    wire_steps: Vec<f64>,
    converged: bool,
    irregularity_mm: Irregularity,
) -> Option<ApplianceReport> {
    let last = sim
        .wires
        .iter()
        .find(|w| w.arch == Arch::Lower)
        .or(sim.wires.first())?;
    let wire = WireReport::of(last.history.last().map_or(0.0, |h| h.0), &last.choice);
    let mut wires = BTreeMap::new();
    let mut brackets = Vec::new();
    let coils = sim
        .wires
        .iter()
        .flat_map(|w| &w.coils)
        .map(|c| CoilReport {
            from: c.from,
            to: c.to,
            kind: c.kind,
            placed_day: c.placed.map(|p| p.0),
            force_n: c.force_n,
        })
        .collect();
    let chains = sim
        .wires
        .iter()
        .flat_map(|w| &w.chains)
        .map(|c| ChainReport {
            from: c.from,
            to: c.to,
            placed_day: c.placed.map(|p| p.0),
            tension_n: c.tension_n,
        })
        .collect();
    for arch in [Arch::Upper, Arch::Lower] {
        let Some(w) = sim.wires.iter().find(|w| w.arch == arch) else {
            continue;
        };
        let name = if arch == Arch::Upper {
            "upper"
        } else {
            "lower"
        };
        wires.insert(
            name,
            w.history
                .iter()
                .map(|(d, c)| WireReport::of(*d, c))
                .collect(),
        );
        for (j, (b, r)) in w.brackets.iter().zip(&w.reactions).enumerate() {
            brackets.push(BracketReport {
                fdi: b.fdi,
                force_n: r.force.to_array(),
                moment_nmm: r.moment.to_array(),
                engaged: r.force.length() > 1e-9 || r.moment.length() > 1e-9,
                friction_n: w.friction_n.get(j).copied().unwrap_or(0.0),
            });
        }
    }
    let most = wire_steps.iter().copied().fold(0.0, f64::max);
    let solve = median(wire_steps);
    let collision = median(collision_steps);
    Some(ApplianceReport {
        wire,
        wires,
        brackets,
        chains,
        coils,
        elastics: sim
            .elastics
            .iter()
            .map(|e| ElasticReport {
                from: e.from,
                to: e.to,
                placed_day: e.placed.map(|(d, _)| d),
                force_n: e.force_n,
            })
            .collect(),
        solve_us_per_step: [solve, most],
        solve_over_collision: if collision > 0.0 {
            solve / collision
        } else {
            0.0
        },
        converged,
        irregularity_mm,
        cortical_contacts: sim.cortical.clone(),
    })
}

/// A finished run: the report and the simulation in its final state.
pub struct CaseRun {
    /// The measures.
    pub report: SimulationReport,
    /// The simulation at the end.
    pub simulation: Simulation,
}

/// Loads a case, builds its teeth's trees (`cache` if given), and steps until the teeth rest or
/// `max_steps` pass; `progress(step)` is called after every step.
///
/// # Errors
/// The case cannot be read or built, its trees cannot be built, or the simulation cannot be made
/// (each [`MovementError`] names the case or file).
pub fn run_case(
    case: &str,
    method: Method,
    settings: MovementSettings,
    trees: TreeSettings,
    cache: Option<&TreeCache>,
    max_steps: u64,
    progress: impl FnMut(u64),
) -> Result<CaseRun, MovementError> {
    let limit = RunLimit {
        max_steps,
        max_days: None,
    };
    run_case_for(case, method, settings, trees, cache, limit, progress)
}

/// [`run_case`] to a [`RunLimit`]: the run also stops when its clinical time reaches
/// `max_days`, and does not count as at rest while a wire change is still to come.
///
/// # Errors
/// As [`run_case`].
pub fn run_case_for(
    case: &str,
    method: Method,
    settings: MovementSettings,
    trees: TreeSettings,
    cache: Option<&TreeCache>,
    limit: RunLimit,
    mut progress: impl FnMut(u64),
) -> Result<CaseRun, MovementError> {
    let max_steps = limit.max_steps;
    let loaded = Case::resolve(case)?;
    let name = loaded.case.name.clone();
    let d = Dentition::build(loaded)?;
    let shapes = collision_shapes(&d, trees, cache)?;
    let mut sim =
        Simulation::new(&d, shapes, method, settings).map_err(|e| MovementError::InCase {
            case: case.to_owned(),
            source: Box::new(e),
        })?;
    let start = Instant::now();
    let mut collision_ns = 0u64;
    let mut at_rest = false;
    let mut collision_steps = Vec::new();
    let mut wire_steps = Vec::new();
    let mut converged = true;
    let mut irregularity = Irregularity::default();
    irregularity.record(&sim);
    let mut next_day = 1.0;
    while sim.steps < max_steps && limit.max_days.is_none_or(|d| sim.elapsed_days < d - 1e-9) {
        let out = sim.step();
        collision_ns += out.collision_ns;
        collision_steps.push(out.collision_ns as f64 / 1e3);
        at_rest = out.at_rest && sim.wires.iter().all(|w| w.sequence.is_empty());
        if !sim.wires.is_empty() {
            wire_steps.push(sim.wires.iter().map(|w| w.solve_ns).sum::<u64>() as f64 / 1e3);
            converged &= sim.wires.iter().all(|w| w.last.converged);
        }
        progress(sim.steps);
        if sim.elapsed_days >= next_day {
            irregularity.record(&sim);
            next_day = sim.elapsed_days.floor() + 1.0;
        }
        if at_rest {
            break;
        }
    }
    if irregularity
        .lower
        .last()
        .is_some_and(|p| p[0] < sim.elapsed_days)
        || irregularity
            .upper
            .last()
            .is_some_and(|p| p[0] < sim.elapsed_days)
    {
        irregularity.record(&sim);
    }
    let elapsed = start.elapsed().as_secs_f64() * 1e6;
    let steps = sim.steps.max(1) as f64;
    let distances = pair_distances(&sim);
    let report = SimulationReport {
        case: name,
        algorithm: method.name().to_owned(),
        response: settings.response.name().to_owned(),
        model: settings.model.name().to_owned(),
        steps: sim.steps,
        days: sim.elapsed_days,
        at_rest,
        moved: sim
            .teeth
            .iter()
            .filter(|t| t.displacement_mm() > MOVED_MM)
            .map(|t| t.fdi)
            .collect(),
        displacement_mm: sim
            .teeth
            .iter()
            .map(|t| (t.fdi.to_string(), t.displacement_mm()))
            .collect(),
        max_penetration_mm: max_penetration(&sim),
        total_centre_distance_mm: distances.iter().map(|d| d.centre_distance_mm).sum(),
        distances,
        collision_us_per_step: collision_ns as f64 / 1e3 / steps,
        step_us: elapsed / steps,
        ipr_mm: sim
            .ipr
            .iter()
            .map(|((a, b), v)| (format!("{a}-{b}"), *v))
            .collect(),
        impacts: sim.total_impacts,
        energy_lost_uj: sim.total_energy_lost_uj,
        teeth: tooth_travel(&sim),
        appliance: appliance_report(&sim, collision_steps, wire_steps, converged, irregularity),
        cortical_contacts: sim.cortical.clone(),
        bone_meshes: sim.bone_meshes.as_ref().map(|m| {
            let held = m.uncovered();
            BoneMeshReport {
                teeth: held.iter().map(|h| h.0).collect(),
                outside: held
                    .iter()
                    .filter(|h| h.1 > 0)
                    .map(|&(fdi, points, of)| BoneOutside { fdi, points, of })
                    .collect(),
            }
        }),
    };
    Ok(CaseRun {
        report,
        simulation: sim,
    })
}
