//! The medial builder: spheres centred on an approximation of the medial axis, chosen to cover the
//! surface with little volume outside the tooth, then grouped into a balanced hierarchy.
//!
//! 1. Surface samples, uniform by area, with their face normals.
//! 2. For each sample, its maximal inscribed ball by the shrinking-ball method (Ma, Bae, Choi and
//!    Lee 2012): a ball tangent at the sample, shrunk until no surface point lies inside it. Its
//!    centre lies on the medial axis.
//! 3. Candidate leaves: each medial ball grown by a few margins. A candidate's outside volume is
//!    estimated as its growth shell times the fraction of its surface outside the tooth.
//! 4. Greedy weighted set cover of the samples: repeatedly the candidate with the most newly
//!    covered samples per outside volume.
//! 5. Repair to the exact invariant: triangles are split as in [`super::check_coverage`]; a piece
//!    that no leaf contains grows the leaf that needs the least growth to contain it.
//! 6. Hierarchy: leaves are split into B balanced groups along the longest axis of their centres,
//!    recursively; each inner sphere is the smallest sphere around the surface pieces its leaves
//!    are responsible for, so invariant (2) holds by construction.

use glam::Vec3;

use super::tree::{SphereTree, triangles_touching};
use crate::geometry::{
    MeshRef, Sphere, TriMesh,
    mesh_distance::{closest_point_on_mesh, point_inside_mesh},
};

/// Radius added to every sphere (mm), as in the octree builder.
const MARGIN_MM: f32 = 1e-3;
/// Surface samples for the set cover.
const SAMPLES: usize = 3000;
/// Growth margins of the candidates, as fractions of the mean sample spacing.
const GROWTH: [f32; 5] = [0.6, 1.0, 1.5, 2.2, 3.2];
/// Points on a candidate's surface used to estimate its outside fraction.
const SHELL_PROBES: usize = 48;

/// Area-uniform surface samples (point, unit outward normal), deterministic.
fn surface_samples(mesh: &TriMesh, n: usize) -> Vec<(Vec3, Vec3)> {
    let areas: Vec<f32> = (0..mesh.triangles.len())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let total: f32 = areas.iter().sum();
    let mut out = Vec::with_capacity(n + mesh.triangles.len());
    let mut carry = 0.0f32;
    let mut state = 0x2545_f491u32;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for (i, &area) in areas.iter().enumerate() {
        let [a, b, c] = mesh.triangle(i);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        carry += area / total * n as f32;
        // At least the centroid of every triangle, so small triangles are not missed.
        let count = (carry.floor() as usize).max(1);
        carry -= carry.floor();
        for k in 0..count {
            let (mut u, mut v) = if k == 0 {
                (1.0 / 3.0, 1.0 / 3.0)
            } else {
                (rnd(), rnd())
            };
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            out.push((a + (b - a) * u + (c - a) * v, normal));
        }
    }
    out
}

/// The maximal inscribed ball tangent at `p` (outward normal `n`), by shrinking.
fn medial_ball(mesh: MeshRef, p: Vec3, n: Vec3, start: f32) -> Sphere {
    let mut r = start;
    for _ in 0..40 {
        let c = p - n * r;
        let Some((q, d)) = closest_point_on_mesh(mesh, c) else {
            break;
        };
        if d >= r - 1e-4 || q.distance_squared(p) < 1e-10 {
            break;
        }
        let pq = p - q;
        let along = pq.dot(n);
        if along <= 1e-9 {
            break;
        }
        let next = pq.length_squared() / (2.0 * along);
        if next >= r {
            break;
        }
        r = next;
    }
    Sphere::new(p - n * r, r)
}

/// Builds a medial sphere tree with `levels` levels and branching `branching`.
pub fn build_medial(
    mesh: &TriMesh,
    bvh: &crate::geometry::TriangleBvh,
    branching: u32,
    levels: u32,
) -> SphereTree {
    let mut tree = SphereTree::empty(branching, levels.max(1));
    if mesh.triangles.is_empty() {
        return tree;
    }
    let m = MeshRef { mesh, bvh };
    let max_leaves = (branching as usize).pow(levels.max(1) - 1);
    let samples = surface_samples(mesh, SAMPLES);
    let area: f32 = (0..mesh.triangles.len())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let start = mesh.aabb().extent().length();
    // Candidates come from every second sample: enough medial balls, half the shrinking work.
    let balls: Vec<Sphere> = samples
        .iter()
        .step_by(2)
        .map(|&(p, n)| medial_ball(m, p, n, start))
        .collect();
    let probes = crate::geometry::sphere::fibonacci_directions(SHELL_PROBES);
    // Scale the growth to the leaf budget: about max_leaves spheres must cover the area.
    let mut spacing = 0.36 * (area / max_leaves as f32).sqrt();
    let mut leaves = Vec::new();
    for _attempt in 0..6 {
        leaves = greedy_cover(m, &samples, &balls, &probes, spacing);
        if leaves.len() <= max_leaves {
            break;
        }
        spacing *= 1.3;
    }
    repair_and_group(&mut tree, m, leaves, max_leaves, spacing);
    tree
}

fn greedy_cover(
    m: MeshRef,
    samples: &[(Vec3, Vec3)],
    balls: &[Sphere],
    probes: &[Vec3],
    spacing: f32,
) -> Vec<Sphere> {
    // Candidates: every medial ball, grown by each margin.
    let mut candidates: Vec<(Sphere, f32)> = Vec::new();
    for ball in balls {
        for g in GROWTH {
            let s = Sphere::new(ball.centre, ball.radius + g * spacing);
            let outside = probes
                .iter()
                .filter(|&&d| !point_inside_mesh(m, s.centre + d * s.radius))
                .count();
            let fraction = outside as f32 / probes.len() as f32;
            let shell = 4.0 / 3.0 * std::f32::consts::PI * (s.radius.powi(3) - ball.radius.powi(3));
            candidates.push((s, (fraction * shell).max(1e-6)));
        }
    }
    let covers: Vec<Vec<u32>> = candidates
        .iter()
        .map(|(s, _)| {
            (0..samples.len() as u32)
                .filter(|&i| s.contains(samples[i as usize].0))
                .collect()
        })
        .collect();
    let mut covered = vec![false; samples.len()];
    let mut left = samples.len();
    let mut chosen = Vec::new();
    while left > 0 {
        let best = (0..candidates.len())
            .map(|c| {
                let gain = covers[c].iter().filter(|&&i| !covered[i as usize]).count();
                (c, gain as f32 / candidates[c].1)
            })
            .filter(|x| x.1 > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((c, _)) = best else { break };
        for &i in &covers[c] {
            if !covered[i as usize] {
                covered[i as usize] = true;
                left -= 1;
            }
        }
        chosen.push(candidates[c].0);
    }
    chosen
}

/// Pieces of the surface, each inside one leaf: (leaf index, piece corners). A piece that no leaf
/// holds after `REPAIR_DEPTH` splits gets a new leaf (the medial ball at the piece, grown like the
/// candidates) while the budget allows, else the leaf needing the least growth grows to hold it.
fn assign_pieces(
    m: MeshRef,
    leaves: &mut Vec<Sphere>,
    max_leaves: usize,
    spacing: f32,
) -> Vec<(usize, [Vec3; 3])> {
    const REPAIR_DEPTH: u32 = 6;
    let mesh = m.mesh;
    let start = mesh.aabb().extent().length();
    let mut out = Vec::new();
    for t in 0..mesh.triangles.len() {
        let [ta, tb, tc] = mesh.triangle(t);
        let normal = (tb - ta).cross(tc - ta).normalize_or_zero();
        let mut stack = vec![(mesh.triangle(t), 0u32)];
        while let Some((piece, depth)) = stack.pop() {
            // Of the leaves holding the piece, the one it lies deepest in (relative to its radius), so
            // that leaves can shrink to their own pieces afterwards.
            let holder = leaves
                .iter()
                .enumerate()
                .filter(|(_, s)| piece.iter().all(|&p| s.contains(p)))
                .map(|(i, s)| {
                    let reach = piece
                        .iter()
                        .map(|p| p.distance(s.centre))
                        .fold(0.0f32, f32::max);
                    (i, reach / s.radius)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((i, _)) = holder {
                out.push((i, piece));
                continue;
            }
            if depth >= REPAIR_DEPTH {
                let centroid = (piece[0] + piece[1] + piece[2]) / 3.0;
                let reach = |c: Vec3| piece.iter().map(|p| p.distance(c)).fold(0.0f32, f32::max);
                if leaves.len() < max_leaves {
                    let ball = medial_ball(m, centroid, normal, start);
                    let r = (ball.radius + GROWTH[0] * spacing).max(reach(ball.centre)) + MARGIN_MM;
                    leaves.push(Sphere::new(ball.centre, r.next_up()));
                    out.push((leaves.len() - 1, piece));
                } else {
                    let (i, need) = leaves
                        .iter()
                        .enumerate()
                        .map(|(i, s)| (i, reach(s.centre)))
                        .min_by(|a, b| {
                            (a.1 - leaves[a.0].radius).total_cmp(&(b.1 - leaves[b.0].radius))
                        })
                        .expect("at least one leaf");
                    leaves[i].radius = (need + MARGIN_MM).next_up();
                    out.push((i, piece));
                }
                continue;
            }
            let [a, b, c] = piece;
            let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
            for sub in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
                stack.push((sub, depth + 1));
            }
        }
    }
    out
}

fn repair_and_group(
    tree: &mut SphereTree,
    m: MeshRef,
    mut leaves: Vec<Sphere>,
    max_leaves: usize,
    spacing: f32,
) {
    let mesh = m.mesh;
    if leaves.is_empty() {
        leaves.push(Sphere::enclosing(&mesh.vertices));
    }
    leaves.truncate(max_leaves);
    let pieces = assign_pieces(m, &mut leaves, max_leaves, spacing);
    // Piece corners per leaf, for shrinking the leaves and for the inner spheres.
    let mut corners: Vec<Vec<Vec3>> = vec![Vec::new(); leaves.len()];
    for (i, p) in &pieces {
        corners[*i].extend_from_slice(p);
    }
    // Each leaf shrinks to the pieces it is responsible for (they stay inside it); leaves left with
    // none are dropped.
    let (leaves, corners): (Vec<Sphere>, Vec<Vec<Vec3>>) = leaves
        .into_iter()
        .zip(corners)
        .filter(|(_, c)| !c.is_empty())
        .map(|(s, c)| {
            let reach = c
                .iter()
                .map(|p| p.distance(s.centre))
                .fold(0.0f32, f32::max);
            (Sphere::new(s.centre, reach.next_up().min(s.radius)), c)
        })
        .unzip();
    let order: Vec<usize> = (0..leaves.len()).collect();
    place(tree, 0, 0, order, &leaves, &corners, mesh);
}

/// Places `group` (leaf indices) at slot `node` of `level`: a single leaf sits in the slot itself;
/// a larger group gets the smallest sphere around its leaves' pieces and is split among the
/// children. Groups never exceed what the levels below can hold (balanced splits of at most
/// B^(levels−1) leaves).
fn place(
    tree: &mut SphereTree,
    node: usize,
    level: u32,
    mut group: Vec<usize>,
    leaves: &[Sphere],
    corners: &[Vec<Vec3>],
    mesh: &TriMesh,
) {
    if group.len() == 1 || level + 1 >= tree.levels {
        let i = group[0];
        tree.nodes[node] = Some(leaves[i]);
        tree.triangles[node] = triangles_touching(mesh, &leaves[i]);
        return;
    }
    let points: Vec<Vec3> = group
        .iter()
        .flat_map(|&i| corners[i].iter().copied())
        .collect();
    let s = Sphere::enclosing(&points);
    tree.nodes[node] = Some(Sphere::new(s.centre, s.radius + MARGIN_MM));
    let parts = split_balanced(&mut group, leaves, tree.branching as usize);
    let first = tree.children(node).start;
    for (k, part) in parts.into_iter().enumerate() {
        if !part.is_empty() {
            place(tree, first + k, level + 1, part, leaves, corners, mesh);
        }
    }
}

/// Splits a group into `b` parts of nearly equal size along the longest axis of the leaf centres,
/// recursively (so that each part holds at most ⌈n/b⌉ leaves).
fn split_balanced(group: &mut [usize], leaves: &[Sphere], b: usize) -> Vec<Vec<usize>> {
    if b <= 1 || group.len() <= 1 {
        let mut v = vec![group.to_vec()];
        v.resize(b.max(1), Vec::new());
        return v;
    }
    let bounds = crate::geometry::Aabb::from_points(group.iter().map(|&i| leaves[i].centre));
    let e = bounds.extent();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    group.sort_by(|&x, &y| leaves[x].centre[axis].total_cmp(&leaves[y].centre[axis]));
    let left_parts = b / 2;
    let cut = group.len() * left_parts / b;
    let (l, r) = group.split_at_mut(cut);
    let mut out = split_balanced(l, leaves, left_parts);
    out.extend(split_balanced(r, leaves, b - left_parts));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        geometry::{TriangleBvh, trimesh::tests::cuboid},
        sphere_tree::{check_coverage, coverage::DEFAULT_SPLIT_DEPTH},
    };

    #[test]
    fn medial_trees_cover_and_stay_within_the_budget() {
        let mesh = cuboid(Vec3::ZERO, Vec3::new(6.0, 3.0, 2.0));
        let bvh = TriangleBvh::build(&mesh);
        for (branching, levels) in [(8, 3), (4, 4), (2, 5)] {
            let tree = build_medial(&mesh, &bvh, branching, levels);
            let c = check_coverage(&tree, &mesh, DEFAULT_SPLIT_DEPTH);
            assert!(c.covered, "B{branching} L{levels}: {c:?}");
            let budget = (branching as usize).pow(levels - 1);
            assert!(tree.leaves().count() <= budget, "B{branching} L{levels}");
            // Medial balls lie inside the box: no leaf centre outside it.
            assert!(tree.leaves().all(|n| {
                let c = tree.nodes[n].unwrap().centre;
                c.cmpge(Vec3::splat(-1e-3)).all() && c.cmple(Vec3::new(6.0, 3.0, 2.0) + 1e-3).all()
            }));
        }
    }
}
