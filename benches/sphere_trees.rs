//! Sphere-tree build times, per tooth on one core: the medial builder (target: ≤ 100 ms per
//! default-resolution tooth, ≤ 2 s per 20,000-triangle tooth) and the octree, at branching 8 and
//! depth 4. Run with `cargo bench --bench sphere_trees`.

use criterion::{Criterion, criterion_group, criterion_main};
use orthosim::{
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Arch, ShapeSet, ToothKind, ToothResolution},
};

fn settings(method: TreeMethod) -> TreeSettings {
    TreeSettings {
        method,
        branching: 8,
        depth: 4,
    }
}

fn default_resolution(c: &mut Criterion) {
    let shapes = ShapeSet::shared(ToothResolution::PAPER);
    let mut group = c.benchmark_group("trees_default_resolution");
    group.sample_size(10);
    for kind in [ToothKind::CentralIncisor, ToothKind::FirstMolar] {
        let g = shapes.get(Arch::Upper, kind);
        for method in [TreeMethod::Medial, TreeMethod::Octree] {
            group.bench_function(format!("{method:?}/{kind:?}"), |b| {
                b.iter(|| settings(method).build(&g.mesh, &g.bvh).unwrap())
            });
        }
    }
    group.finish();
}

fn scan_resolution(c: &mut Criterion) {
    let shapes = ShapeSet::shared(ToothResolution::DENSE);
    let g = shapes.get(Arch::Upper, ToothKind::FirstMolar);
    let mut group = c.benchmark_group("trees_scan_resolution");
    group.sample_size(10);
    group.bench_function(
        format!("Medial/FirstMolar/{}_triangles", g.mesh.triangles.len()),
        |b| b.iter(|| settings(TreeMethod::Medial).build(&g.mesh, &g.bvh).unwrap()),
    );
    // The triangle hierarchy (boxes and slabs) every tooth also gets.
    group.bench_function(
        format!(
            "TriangleBvh/FirstMolar/{}_triangles",
            g.mesh.triangles.len()
        ),
        |b| b.iter(|| orthosim::geometry::TriangleBvh::build(&g.mesh)),
    );
    group.finish();
}

criterion_group!(benches, default_resolution, scan_resolution);
criterion_main!(benches);
