//! The collision benchmark behind `orthosim bench`, `benches/collision.rs` and the `vs_parry`
//! example: seeded motions of real tooth pairs, each method's cost per pair query and its errors
//! against the exact stage, and the cost of one full-mouth step.
//!
//! Two sets. The **near-contact set** ([`near_contact_pairs`]) is what a running simulation asks:
//! short steps (≤ 0.5 mm, ≤ 2°) that end within about 0.1 mm of contact, often with the surfaces
//! nearly parallel over a wide area. The **stress set** ([`stress_pairs`]) is the oracle tests'
//! distribution: steps up to 5 mm and ±15° that start in contact, end deep or tunnel through. The
//! report's `methods` are measured on the first; `stress` holds the same measures on the second.
//!
//! Reference: the exact stage ([`Method::Exact`]) and exact mesh separation at the reported pose.
//! A false negative is a pair the exact stage finds touching during the step (for the discrete
//! methods: meshes touching or overlapping at the end pose) that the method misses; a false
//! positive is a reported contact where the exact gap stays above zero (discrete: at the end pose;
//! continuous: the exact stage finds no contact in the step). The error of a reported contact is
//! the exact gap or penetration depth (mm) of the meshes at the reported time: how far from just
//! touching the teeth are when the method says "contact". Motions that start with the teeth already
//! interpenetrating are left out of the error (no method can undo a start pose), not out of the
//! counts.

use std::time::Instant;

use glam::{Quat, Vec3};
use serde::Serialize;

use super::{
    Body, Circle, CollisionShape, Method, Motion, PairContact,
    broad_phase::{BroadItem, candidate_pairs},
    query,
    sampling::{Rng, random_motion},
};
use crate::{
    geometry::{MeshRef, Pose, mesh_separation},
    sphere_tree::{TreeBuildError, TreeCache, TreeSettings},
    teeth::{Dentition, Fdi},
};

/// A tooth placed for the benchmark.
#[derive(Clone, Debug)]
pub struct BenchTooth {
    /// FDI number.
    pub fdi: Fdi,
    /// Shape for queries.
    pub shape: CollisionShape,
    /// Bounding circle.
    pub circle: Circle,
    /// Rest pose in the case.
    pub rest: Pose,
}

/// The teeth of a dentition with trees built (or read from `cache`) with `settings`.
///
/// # Errors
/// The settings are invalid ([`TreeSettings::validate`]).
pub fn bench_teeth(
    d: &Dentition,
    settings: TreeSettings,
    cache: Option<&TreeCache>,
) -> Result<Vec<BenchTooth>, TreeBuildError> {
    let shapes = super::shape::collision_shapes(d, settings, cache)?;
    Ok(d.visible()
        .zip(shapes)
        .map(|(t, (_, shape))| BenchTooth {
            fdi: t.fdi,
            shape,
            circle: Circle::of(&t.geometry, &t.pose),
            rest: t.pose,
        })
        .collect())
}

/// Pairs of teeth whose rest poses are within 1 mm (root spheres grown by 1 mm meet): arch
/// neighbours and occluding teeth.
fn close_pairs(teeth: &[BenchTooth]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for i in 0..teeth.len() {
        for j in i + 1..teeth.len() {
            let (a, b) = (&teeth[i], &teeth[j]);
            let ca = a.rest.transform_point(a.shape.tree.spheres[0].centre);
            let cb = b.rest.transform_point(b.shape.tree.spheres[0].centre);
            let r = a.shape.tree.spheres[0].radius + b.shape.tree.spheres[0].radius;
            if ca.distance(cb) <= r + 1.0 {
                out.push((i, j));
            }
        }
    }
    out
}

/// The stress set of the oracle tests: `n` seeded motions of close pairs, each tooth stepping
/// 0.01–5 mm towards the other with up to ±15° of rotation ([`random_motion`]), so that many steps
/// start in contact, end deep inside the other tooth or would tunnel through it.
pub fn stress_pairs(
    teeth: &[BenchTooth],
    n: usize,
    seed: u64,
) -> Vec<(usize, usize, Motion, Motion)> {
    let candidates = close_pairs(teeth);
    if candidates.is_empty() {
        return Vec::new();
    }
    let mut rng = Rng(seed);
    (0..n)
        .map(|k| {
            let (i, j) = candidates[k % candidates.len()];
            let ma = random_motion(&mut rng, &teeth[i].rest, teeth[j].rest.translation);
            let mb = if rng.uniform() < 0.5 {
                Motion::still(teeth[j].rest)
            } else {
                random_motion(&mut rng, &teeth[j].rest, teeth[i].rest.translation)
            };
            (i, j, ma, mb)
        })
        .collect()
}

/// The benchmark's near-contact set: `n` seeded steps of close pairs that end near contact, as a
/// simulation step does when teeth push each other.
///
/// Each pair starts from its rest poses perturbed (±2°, ±0.3 mm). The first tooth is then moved
/// along a direction towards the other (with noise) by conservative advancement until the exact
/// gap is 0.001 mm, and on by a further −0.1 to 0.1 mm: the end pose, between 0.1 mm apart and
/// about 0.1 mm deep. Its step ends there: 0.01–0.5 mm long (log-uniform) along that direction
/// with up to ±2° of rotation. In half the pairs the second tooth moves too (up to 0.1 mm and
/// ±1°, ending at its perturbed pose). About half the steps touch.
pub fn near_contact_pairs(
    teeth: &[BenchTooth],
    n: usize,
    seed: u64,
) -> Vec<(usize, usize, Motion, Motion)> {
    let candidates = close_pairs(teeth);
    let mut rng = Rng(seed);
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    // Every close pair yields near-contact steps for most directions; the cap only guards
    // against a dentition where none does.
    while out.len() < n && !candidates.is_empty() && k < 100 * (n + candidates.len()) {
        let (i, j) = candidates[k % candidates.len()];
        k += 1;
        let (a, b) = (&teeth[i], &teeth[j]);
        let pa = rng.perturb(&a.rest, 2.0, 0.3);
        let pb = rng.perturb(&b.rest, 2.0, 0.3);
        let dir = ((pb.translation - pa.translation).normalize_or_zero() + rng.vec(0.6))
            .normalize_or_zero();
        let extra = rng.vec(0.1).x;
        let length = rng.log_uniform(0.01, 0.5);
        let angle = rng.vec(2f32.to_radians()).x;
        let axis = rng.unit();
        let moves_b = rng.uniform() < 0.5;
        let b_travel = rng.vec(0.1);
        let b_axis = rng.unit();
        let b_angle = rng.vec(1f32.to_radians()).x;
        if dir == Vec3::ZERO {
            continue;
        }
        // Back off until apart, then advance by the gap (which no translation shorter than it
        // can close) until the teeth are 0.001 mm apart.
        let at = |s: f32| Pose::new(pa.rotation, pa.translation + dir * s);
        let mut s = -6.0f32;
        if exact_gap(a, &at(s), b, &pb) <= 0.0 {
            continue;
        }
        let mut reached = false;
        // Grazing directions converge slowly; they are skipped after a few steps.
        for _ in 0..24 {
            let gap = exact_gap(a, &at(s), b, &pb);
            if gap <= 0.002 {
                reached = gap > 0.0;
                break;
            }
            s += gap - 0.001;
        }
        if !reached {
            continue;
        }
        let end = at(s + extra);
        let start = Pose::new(
            (Quat::from_axis_angle(axis, -angle) * end.rotation).normalize(),
            end.translation - dir * length,
        );
        let mb = if moves_b {
            Motion {
                start: Pose::new(
                    (Quat::from_axis_angle(b_axis, -b_angle) * pb.rotation).normalize(),
                    pb.translation - b_travel,
                ),
                end: pb,
            }
        } else {
            Motion::still(pb)
        };
        out.push((i, j, Motion { start, end }, mb));
    }
    out
}

/// One method's line of the report.
#[derive(Clone, Debug, Serialize)]
pub struct MethodReport {
    /// Method name.
    pub method: String,
    /// Median over [`METHOD_PASSES`] timed passes of the mean time per pair query (µs, one core).
    pub us_per_pair: f64,
    /// Fastest and slowest of those passes (µs per pair).
    pub range_us: [f64; 2],
    /// Contacts missed (see the module doc).
    pub false_negatives: usize,
    /// Contacts reported where the meshes stay apart.
    pub false_positives: usize,
    /// Mean |gap or penetration| of the meshes at the reported contacts (mm).
    pub mean_error_mm: f64,
    /// Largest of those (mm).
    pub max_error_mm: f64,
}

/// Costs and errors of every method on one set of pair motions.
#[derive(Clone, Debug, Serialize)]
pub struct SetReport {
    /// Pair motions measured.
    pub pairs: usize,
    /// Per method.
    pub methods: Vec<MethodReport>,
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Pair motions in the near-contact set ([`near_contact_pairs`]).
    pub pairs: usize,
    /// Per method, on the near-contact set.
    pub methods: Vec<MethodReport>,
    /// One collision step of the whole mouth, every tooth moving a little (continuous, µs).
    pub full_mouth_step_us: f64,
    /// The same measures on the oracle tests' stress set ([`stress_pairs`]).
    pub stress: SetReport,
}

fn body<'a>(t: &'a BenchTooth, motion: Motion) -> Body<'a> {
    Body {
        shape: &t.shape,
        circle: t.circle,
        motion,
    }
}

/// Signed exact gap of two teeth at poses (negative: penetration depth).
fn exact_gap(a: &BenchTooth, pa: &Pose, b: &BenchTooth, pb: &Pose) -> f32 {
    let ga = &a.shape.geometry;
    let gb = &b.shape.geometry;
    mesh_separation(
        MeshRef {
            mesh: &ga.mesh,
            bvh: &ga.bvh,
        },
        pa,
        MeshRef {
            mesh: &gb.mesh,
            bvh: &gb.bvh,
        },
        pb,
    )
    .signed_gap()
}

/// Runs the benchmark on the near-contact and stress sets; `progress(done, total)` is called as
/// each measure finishes.
pub fn run(
    teeth: &[BenchTooth],
    near: &[(usize, usize, Motion, Motion)],
    stress: &[(usize, usize, Motion, Motion)],
    progress: &dyn Fn(usize, usize),
) -> BenchReport {
    let total = 2 * (Method::ALL.len() + 1) + 1;
    let near_report = measure(teeth, near, &|k| progress(k, total));
    let stress_report = measure(teeth, stress, &|k| {
        progress(Method::ALL.len() + 1 + k, total)
    });
    let full_mouth_step_us = full_mouth_step(teeth, 200, 0xf00d);
    progress(total, total);
    BenchReport {
        pairs: near_report.pairs,
        methods: near_report.methods,
        full_mouth_step_us,
        stress: stress_report,
    }
}

/// The exact gap of each pair at the start (or, with `end`, the end) of its step.
fn pose_gaps(
    teeth: &[BenchTooth],
    pairs: &[(usize, usize, Motion, Motion)],
    end: bool,
) -> Vec<f32> {
    pairs
        .iter()
        .map(|&(i, j, ma, mb)| {
            let (pa, pb) = if end {
                (ma.end, mb.end)
            } else {
                (ma.start, mb.start)
            };
            exact_gap(&teeth[i], &pa, &teeth[j], &pb)
        })
        .collect()
}

/// Mean of `x`, 0 when empty.
fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        x.iter().sum::<f64>() / x.len() as f64
    }
}

/// Timed passes per method of `orthosim bench`: on a shared machine one pass swings by 15 % and
/// more, the median of five far less.
pub const METHOD_PASSES: usize = 5;

/// Every method on one set; `done(k)` after the reference and after each method.
fn measure(
    teeth: &[BenchTooth],
    pairs: &[(usize, usize, Motion, Motion)],
    done: &dyn Fn(usize),
) -> SetReport {
    // Reference: the exact stage over the step, exact separation at the end pose.
    let exact: Vec<_> = pairs
        .iter()
        .map(|&(i, j, ma, mb)| query(Method::Exact, &body(&teeth[i], ma), &body(&teeth[j], mb)))
        .collect();
    let (start_gap, end_gap) = (
        pose_gaps(teeth, pairs, false),
        pose_gaps(teeth, pairs, true),
    );
    done(1);
    let mut methods = Vec::new();
    for (k, method) in Method::ALL.into_iter().enumerate() {
        // The results' storage is allocated and touched before the clock starts, and one untimed
        // pass warms the caches and the allocator (as a running simulation's earlier steps do):
        // the measure is the queries (their own allocations included), not the first touch of
        // fresh pages.
        let mut results: Vec<Option<PairContact>> = pairs
            .iter()
            .map(|&(i, j, ma, mb)| query(method, &body(&teeth[i], ma), &body(&teeth[j], mb)))
            .collect();
        let mut times = Vec::with_capacity(METHOD_PASSES);
        for _ in 0..METHOD_PASSES {
            results.clear();
            let start = Instant::now();
            results.extend(
                pairs.iter().map(|&(i, j, ma, mb)| {
                    query(method, &body(&teeth[i], ma), &body(&teeth[j], mb))
                }),
            );
            times.push(start.elapsed().as_secs_f64() * 1e6 / pairs.len().max(1) as f64);
        }
        times.sort_by(f64::total_cmp);
        let us_per_pair = times[times.len() / 2];
        let discrete = matches!(method, Method::Circles | Method::Spheres);
        let (mut fneg, mut fpos, mut errors) = (0, 0, Vec::new());
        for (p, r) in results.iter().enumerate() {
            let (i, j, ma, mb) = pairs[p];
            let truth = if discrete {
                end_gap[p] <= 0.0
            } else {
                exact[p].is_some()
            };
            match r {
                None if truth => fneg += 1,
                None => {}
                Some(c) => {
                    if !truth && (discrete || exact[p].is_none()) {
                        fpos += 1;
                    }
                    if start_gap[p] >= 0.0 {
                        let t = c.time_of_contact;
                        errors.push(
                            exact_gap(&teeth[i], &ma.at(t), &teeth[j], &mb.at(t)).abs() as f64
                        );
                    }
                }
            }
        }
        methods.push(MethodReport {
            method: method.name().into(),
            us_per_pair,
            range_us: [times[0], times[times.len() - 1]],
            false_negatives: fneg,
            false_positives: fpos,
            mean_error_mm: mean(&errors),
            max_error_mm: errors.iter().copied().fold(0.0, f64::max),
        });
        done(k + 2);
    }
    SetReport {
        pairs: pairs.len(),
        methods,
    }
}

/// Timed passes per tolerance of `orthosim bench --sweep` and of the report's sweep.
pub const SWEEP_PASSES: usize = 3;

/// Tolerances of `orthosim bench --sweep` (mm).
pub const SWEEP_TOLERANCES_MM: [f64; 6] = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05];

/// One tolerance of the sweep: what the exact stage costs and how close it leaves the teeth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParetoPoint {
    /// Largest gap the exact stage may leave at a reported contact (mm).
    pub tolerance_mm: f64,
    /// Median over the timed passes of the mean time per pair query (µs, one core).
    pub us_per_pair: f64,
    /// Fastest and slowest pass (µs per pair).
    pub range_us: [f64; 2],
    /// Contacts reported.
    pub contacts: usize,
    /// Largest |gap or penetration| of the meshes at the reported contacts (mm).
    pub max_error_mm: f64,
    /// Mean of those (mm).
    pub mean_error_mm: f64,
    /// Steps whose meshes touch or overlap at the start or end pose that report no contact.
    pub false_negatives: usize,
}

/// Run time against error: the exact stage at each of `tolerances` (mm) on `pairs`, timed over
/// `passes` passes interleaved across the tolerances (so a machine's drift spreads over all of
/// them) after one untimed pass each; `done(k)` after each timed pass over all tolerances.
///
/// The error of a contact is the exact gap or penetration of the meshes at the reported time,
/// from [`mesh_separation`], independent of the exact stage; steps that start interpenetrating
/// are left out of it (as in [`run`]). A false negative is a step whose meshes touch or overlap
/// at its start or end pose (by the same exact separation) that reports no contact; a step that
/// touches only in between is not counted, so the count is a lower bound on misses (the oracle
/// tests check the rest against parry3d).
pub fn sweep(
    teeth: &[BenchTooth],
    pairs: &[(usize, usize, Motion, Motion)],
    tolerances: &[f64],
    passes: usize,
    done: &dyn Fn(usize),
) -> Vec<ParetoPoint> {
    let (start_gap, end_gap) = (
        pose_gaps(teeth, pairs, false),
        pose_gaps(teeth, pairs, true),
    );
    let run_all = |tolerance: f64, out: &mut Vec<Option<PairContact>>| {
        out.clear();
        out.extend(pairs.iter().map(|&(i, j, ma, mb)| {
            super::narrow_phase::exact::query_with(
                &body(&teeth[i], ma),
                &body(&teeth[j], mb),
                tolerance as f32,
            )
        }));
    };
    let mut results: Vec<Vec<Option<PairContact>>> = vec![Vec::new(); tolerances.len()];
    for (k, &tol) in tolerances.iter().enumerate() {
        run_all(tol, &mut results[k]);
    }
    let mut times = vec![Vec::with_capacity(passes); tolerances.len()];
    for pass in 0..passes.max(1) {
        for (k, &tol) in tolerances.iter().enumerate() {
            let start = Instant::now();
            run_all(tol, &mut results[k]);
            times[k].push(start.elapsed().as_secs_f64() * 1e6 / pairs.len().max(1) as f64);
        }
        done(pass + 1);
    }
    tolerances
        .iter()
        .zip(results)
        .zip(times)
        .map(|((&tol, found), mut t)| {
            t.sort_by(f64::total_cmp);
            let mut errors = Vec::new();
            let mut false_negatives = 0;
            for (p, r) in found.iter().enumerate() {
                let (i, j, ma, mb) = pairs[p];
                match r {
                    None if start_gap[p] <= 0.0 || end_gap[p] <= 0.0 => false_negatives += 1,
                    None => {}
                    Some(c) if start_gap[p] >= 0.0 => {
                        let at = c.time_of_contact;
                        let gap = exact_gap(&teeth[i], &ma.at(at), &teeth[j], &mb.at(at));
                        errors.push(gap.abs() as f64);
                    }
                    Some(_) => {}
                }
            }
            ParetoPoint {
                tolerance_mm: tol,
                us_per_pair: t[t.len() / 2],
                range_us: [t[0], t[t.len() - 1]],
                contacts: found.iter().filter(|r| r.is_some()).count(),
                max_error_mm: errors.iter().copied().fold(0.0, f64::max),
                mean_error_mm: mean(&errors),
                false_negatives,
            }
        })
        .collect()
}

/// Mean time of one collision step (broad phase + continuous narrow phase) with every tooth moving
/// by a small random motion (up to 0.05 mm and 0.5°), over `steps` steps (µs).
pub fn full_mouth_step(teeth: &[BenchTooth], steps: usize, seed: u64) -> f64 {
    let mut rng = Rng(seed);
    let mut pairs = Vec::new();
    let mut items: Vec<BroadItem> = Vec::with_capacity(teeth.len());
    let mut total = 0.0;
    let mut contacts = 0usize;
    for _ in 0..steps {
        items.clear();
        for t in teeth {
            let end = Pose::new(
                (Quat::from_axis_angle(rng.unit(), rng.vec(0.5f32.to_radians()).x)
                    * t.rest.rotation)
                    .normalize(),
                t.rest.translation + rng.vec(0.05),
            );
            items.push(BroadItem {
                fdi: t.fdi,
                root: t.shape.tree.spheres[0],
                local_box: t.shape.local_box,
                motion: Motion { start: t.rest, end },
            });
        }
        let start = Instant::now();
        candidate_pairs(&items, &mut pairs);
        for &(i, j) in &pairs {
            if query(
                Method::Continuous,
                &body(&teeth[i], items[i].motion),
                &body(&teeth[j], items[j].motion),
            )
            .is_some()
            {
                contacts += 1;
            }
        }
        total += start.elapsed().as_secs_f64();
    }
    std::hint::black_box(contacts);
    total * 1e6 / steps.max(1) as f64
}
