//! Collision queries per method on the seeded near-contact set of `orthosim bench` (medial trees of
//! depth 4, read from the user's tree cache when present), and one full-mouth step. Targets on one
//! core: spheres ≤ 2 µs, continuous ≤ 10 µs, exact ≤ 30 µs per pair; full-mouth step ≤ 200 µs.
//! Run with `cargo bench --bench collision`.

use criterion::{Criterion, criterion_group, criterion_main};
use orthosim::{
    collision::{Body, Method, bench, query},
    sphere_tree::{TreeCache, TreeMethod, TreeSettings},
    teeth::{Case, Dentition},
};

fn collision(c: &mut Criterion) {
    let d = Dentition::build(Case::resolve("normal").unwrap()).unwrap();
    let settings = TreeSettings {
        method: TreeMethod::Medial,
        branching: 8,
        depth: 4,
    };
    let teeth = bench::bench_teeth(&d, settings, TreeCache::user_default().as_ref())
        .expect("valid tree settings");
    let pairs = bench::near_contact_pairs(&teeth, 200, 0x5eed);
    let mut group = c.benchmark_group("collision_200_pairs");
    group.sample_size(10);
    for method in Method::ALL {
        group.bench_function(method.name(), |b| {
            b.iter(|| {
                pairs
                    .iter()
                    .filter(|&&(i, j, ma, mb)| {
                        let body = |k: usize, m| Body {
                            shape: &teeth[k].shape,
                            circle: teeth[k].circle,
                            motion: m,
                        };
                        query(method, &body(i, ma), &body(j, mb)).is_some()
                    })
                    .count()
            })
        });
    }
    group.finish();
    c.bench_function("full_mouth_step_continuous", |b| {
        b.iter(|| bench::full_mouth_step(&teeth, 1, 7))
    });
}

criterion_group!(benches, collision);
criterion_main!(benches);
