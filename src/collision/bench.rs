//! The collision benchmark behind `orthosim bench`, `benches/collision.rs` and the `vs_parry`
//! example: a seeded set of near-contact motions of real tooth pairs, each method's cost per pair
//! query and its errors against the exact stage, and the cost of one full-mouth step.
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

use std::{sync::Arc, time::Instant};

use glam::{Quat, Vec3};
use serde::Serialize;

use super::{
    Body, Circle, CollisionShape, Method, Motion,
    broad_phase::{BroadItem, candidate_pairs},
    query,
};
use crate::{
    geometry::{MeshRef, Pose, mesh_separation},
    sphere_tree::{SphereTree, TreeCache, TreeSettings},
    teeth::{Dentition, Fdi},
};

/// A small deterministic generator (xorshift64).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f32 / (1u64 << 53) as f32
    }

    /// Uniform in the cube [−scale, scale]³.
    pub fn vec(&mut self, scale: f32) -> Vec3 {
        Vec3::new(
            self.uniform() - 0.5,
            self.uniform() - 0.5,
            self.uniform() - 0.5,
        ) * 2.0
            * scale
    }

    /// A uniform unit vector.
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let p = self.vec(1.0);
            if p.length_squared() > 0.01 && p.length_squared() <= 1.0 {
                return p.normalize();
            }
        }
    }
}

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
pub fn bench_teeth(
    d: &Dentition,
    settings: TreeSettings,
    cache: Option<&TreeCache>,
) -> Vec<BenchTooth> {
    let visible: Vec<_> = d.visible().cloned().collect();
    let trees: Vec<SphereTree> = crate::parallel::parallel_map(&visible, |t| {
        match cache {
            Some(c) => c
                .load_or_build(&settings, &t.geometry.mesh, &t.geometry.bvh)
                .map(|x| x.0),
            None => settings.build(&t.geometry.mesh, &t.geometry.bvh),
        }
        .expect("validated settings")
    });
    visible
        .iter()
        .zip(&trees)
        .map(|(t, tree)| BenchTooth {
            fdi: t.fdi,
            shape: CollisionShape::new(Arc::clone(&t.geometry), tree),
            circle: Circle::of(&t.geometry, &t.pose),
            rest: t.pose,
        })
        .collect()
}

/// A random step near the rest pose heading roughly towards `target`: 0.01–5 mm (log-uniform),
/// up to ±15° of rotation; one in ten without translation, one in ten without rotation.
pub fn random_motion(rng: &mut Rng, rest: &Pose, target: Vec3) -> Motion {
    let start = Pose::new(
        (Quat::from_axis_angle(rng.unit(), rng.vec(2f32.to_radians()).x) * rest.rotation)
            .normalize(),
        rest.translation + rng.vec(0.3),
    );
    let kind = rng.uniform();
    let length = (0.01f32.ln() + rng.uniform() * (5.0f32.ln() - 0.01f32.ln())).exp();
    let dir = ((target - start.translation).normalize_or_zero() + rng.vec(0.6)).normalize_or_zero();
    let travel = if kind < 0.1 { Vec3::ZERO } else { dir * length };
    let angle = if kind > 0.9 {
        0.0
    } else {
        rng.vec(15f32.to_radians()).x
    };
    Motion {
        start,
        end: Pose::new(
            (Quat::from_axis_angle(rng.unit(), angle) * start.rotation).normalize(),
            start.translation + travel,
        ),
    }
}

/// Near-contact pairs: arch neighbours and occluding teeth, `n` seeded motions in all.
pub fn near_contact_pairs(
    teeth: &[BenchTooth],
    n: usize,
    seed: u64,
) -> Vec<(usize, usize, Motion, Motion)> {
    let mut candidates = Vec::new();
    let still: Vec<BroadItem> = teeth
        .iter()
        .map(|t| BroadItem {
            fdi: t.fdi,
            root: t.shape.tree.spheres[0],
            local_box: t.shape.local_box,
            motion: Motion::still(t.rest),
        })
        .collect();
    for i in 0..teeth.len() {
        for j in i + 1..teeth.len() {
            // Pairs whose rest poses are within 1 mm (root spheres grown by 1 mm meet).
            let (a, b) = (&still[i], &still[j]);
            let (ca, cb) = (
                a.motion.start.transform_point(a.root.centre),
                b.motion.start.transform_point(b.root.centre),
            );
            if ca.distance(cb) <= a.root.radius + b.root.radius + 1.0 {
                candidates.push((i, j));
            }
        }
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

/// One method's line of the report.
#[derive(Clone, Debug, Serialize)]
pub struct MethodReport {
    /// Method name.
    pub method: String,
    /// Mean time per pair query (µs, one core).
    pub us_per_pair: f64,
    /// Contacts missed (see the module doc).
    pub false_negatives: usize,
    /// Contacts reported where the meshes stay apart.
    pub false_positives: usize,
    /// Mean |gap or penetration| of the meshes at the reported contacts (mm).
    pub mean_error_mm: f64,
    /// Largest of those (mm).
    pub max_error_mm: f64,
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Pair motions measured.
    pub pairs: usize,
    /// Per method.
    pub methods: Vec<MethodReport>,
    /// One collision step of the whole mouth, every tooth moving a little (continuous, µs).
    pub full_mouth_step_us: f64,
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

/// Runs the benchmark; `progress(done, total)` is called as methods finish.
pub fn run(
    teeth: &[BenchTooth],
    pairs: &[(usize, usize, Motion, Motion)],
    progress: &dyn Fn(usize, usize),
) -> BenchReport {
    let total = Method::ALL.len() + 2;
    // Reference: the exact stage over the step, exact separation at the end pose.
    let exact: Vec<_> = pairs
        .iter()
        .map(|&(i, j, ma, mb)| query(Method::Exact, &body(&teeth[i], ma), &body(&teeth[j], mb)))
        .collect();
    let end_gap: Vec<f32> = pairs
        .iter()
        .map(|&(i, j, ma, mb)| exact_gap(&teeth[i], &ma.end, &teeth[j], &mb.end))
        .collect();
    let start_gap: Vec<f32> = pairs
        .iter()
        .map(|&(i, j, ma, mb)| exact_gap(&teeth[i], &ma.start, &teeth[j], &mb.start))
        .collect();
    progress(1, total);
    let mut methods = Vec::new();
    for (k, method) in Method::ALL.into_iter().enumerate() {
        let start = Instant::now();
        let results: Vec<_> = pairs
            .iter()
            .map(|&(i, j, ma, mb)| query(method, &body(&teeth[i], ma), &body(&teeth[j], mb)))
            .collect();
        let us_per_pair = start.elapsed().as_secs_f64() * 1e6 / pairs.len().max(1) as f64;
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
            false_negatives: fneg,
            false_positives: fpos,
            mean_error_mm: if errors.is_empty() {
                0.0
            } else {
                errors.iter().sum::<f64>() / errors.len() as f64
            },
            max_error_mm: errors.iter().copied().fold(0.0, f64::max),
        });
        progress(k + 2, total);
    }
    let full_mouth_step_us = full_mouth_step(teeth, 200, 0xf00d);
    progress(total, total);
    BenchReport {
        pairs: pairs.len(),
        methods,
        full_mouth_step_us,
    }
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
