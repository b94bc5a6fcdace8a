use glam::Vec3;

use super::{
    LINES, PIECE_EDGE,
    balls::{BALL_SLACK, medial_ball},
    build, build_medial,
    candidates::{Candidate, Candidates, candidates},
    cover::{GainIndex, greedy, predicted_lambda, prune},
    pieces::{Lattice, Role, seeds_by_area, split_surface},
    polish::Surface,
};
use crate::{
    geometry::{
        Columns, MeshRef, Sphere, TriMesh, TriangleBvh, closest_point_triangle,
        trimesh::tests::cuboid,
    },
    sphere_tree::{check_coverage, coverage::DEFAULT_SPLIT_DEPTH},
};

/// Medial balls are inscribed (no triangle, by brute force, nearer the centre than the radius
/// less the slack) and maximal (a ball tangent at the seed 10 µm larger holds surface), on a
/// box, where the answer is known, and on a molar.
#[test]
fn medial_balls_are_maximal_inscribed_balls() {
    use crate::teeth::{Arch, ShapeSet, ToothKind, ToothResolution};
    let gap = |mesh: &TriMesh, c: Vec3| {
        (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, d] = mesh.triangle(t);
                closest_point_triangle(c, a, b, d).distance(c)
            })
            .fold(f32::INFINITY, f32::min)
    };
    let boxed = cuboid(Vec3::ZERO, Vec3::new(2.0, 2.0, 8.0));
    let bvh = TriangleBvh::build(&boxed);
    let m = MeshRef {
        mesh: &boxed,
        bvh: &bvh,
    };
    // Centred on a long face: the ball touches the opposite face (radius 1). Nearer a side:
    // the side limits it (radius 0.5, reached from above within the slack).
    let centred = medial_ball(m, Vec3::new(0.0, 1.0, 4.0), Vec3::NEG_X, 100.0);
    assert!((centred.radius - 1.0).abs() < 1e-5, "{centred:?}");
    let side = medial_ball(m, Vec3::new(0.0, 0.5, 3.0), Vec3::NEG_X, 100.0);
    assert!(
        side.radius >= 0.5 && side.radius <= 0.5 + BALL_SLACK,
        "{side:?}"
    );
    assert!((side.centre - Vec3::new(side.radius, 0.5, 3.0)).length() < 1e-6);
    let g = ShapeSet::shared(ToothResolution::PAPER).get(Arch::Upper, ToothKind::ALL[7]);
    let m = MeshRef {
        mesh: &g.mesh,
        bvh: &g.bvh,
    };
    let pieces = split_surface(&g.mesh, 0.5);
    let start = g.mesh.aabb().extent().length();
    for k in (0..pieces.centroid.len()).step_by(7) {
        let (p, n) = (pieces.centroid[k], pieces.normal[k]);
        let ball = medial_ball(m, p, n, start);
        assert!(ball.radius > 0.0 && (ball.centre - (p - n * ball.radius)).length() < 1e-4);
        assert!(
            gap(&g.mesh, ball.centre) >= ball.radius - BALL_SLACK - 1e-5,
            "piece {k}"
        );
        let larger = ball.radius + 0.01;
        assert!(
            gap(&g.mesh, p - n * larger) < larger - 1e-4,
            "piece {k} not maximal"
        );
    }
}

/// The lazy cover picks what the plain greedy picks: at every turn the candidate with the
/// most newly covered area per (cost + λ), ties to the lower index.
#[test]
fn lazy_cover_picks_what_the_plain_greedy_picks() {
    let mut rng = crate::geometry::test_numbers(7);
    let pieces = 300;
    let area: Vec<f32> = (0..pieces).map(|_| rng() + 0.6).collect();
    let mut c = Candidates {
        list: Vec::new(),
        pool: Vec::new(),
    };
    // Groups of one to four candidates over nested prefixes of one member run, as a medial
    // ball's margins give.
    for k in 0..400 {
        let first = c.pool.len() as u32;
        let len = ((rng() + 0.5) * 30.0) as u32 + 1;
        let mut members: Vec<u32> = (0..len)
            .map(|_| ((rng() + 0.5) * pieces as f32) as u32 % pieces as u32)
            .collect();
        members.sort_unstable();
        members.dedup();
        c.pool.extend(&members);
        let n = members.len() as u32;
        let sizes = 1 + k % 4;
        for j in 1..=sizes {
            let len = (n * j as u32).div_ceil(sizes as u32);
            if c.list
                .last()
                .is_some_and(|l| l.first == first && l.len == len)
            {
                continue;
            }
            c.list.push(Candidate {
                sphere: Sphere::new(Vec3::ZERO, 1.0),
                first,
                len,
                cost: ((rng() + 0.5) * 3.0) as f64 * ((k + j) % 3) as f64,
            });
        }
    }
    // Everything coverable: one candidate per piece.
    for i in 0..pieces as u32 {
        c.list.push(Candidate {
            sphere: Sphere::new(Vec3::ZERO, 1.0),
            first: c.pool.len() as u32,
            len: 1,
            cost: 5.0,
        });
        c.pool.push(i);
    }
    let members = |k: usize| {
        let x = &c.list[k];
        &c.pool[x.first as usize..(x.first + x.len) as usize]
    };
    let index = GainIndex::new(&c, &area);
    // The index counts each piece once per candidate that holds it.
    for (k, x) in c.list.iter().enumerate() {
        let held = (0..pieces)
            .filter(|&i| {
                let owners = &index.owners[index.start[i] as usize..index.start[i + 1] as usize];
                let first = index.groups[index.group[k] as usize].0;
                (first..=k as u32).any(|j| owners.contains(&j))
            })
            .count();
        assert_eq!(held, x.len as usize, "candidate {k}");
    }
    for lambda in [0.0, 0.3, 4.0] {
        let lazy = greedy(&c, &index, lambda);
        let mut open: Vec<u64> = index.weight.clone();
        let mut plain = Vec::new();
        while open.iter().any(|&a| a > 0) {
            let key = |k: usize| {
                let gain = members(k).iter().map(|&i| open[i as usize]).sum::<u64>() as f64;
                gain / (c.list[k].cost + lambda).max(1e-12)
            };
            let best = (0..c.list.len())
                .max_by(|&a, &b| key(a).total_cmp(&key(b)).then(b.cmp(&a)))
                .unwrap();
            for &i in members(best) {
                open[i as usize] = 0;
            }
            plain.push(best as u32);
        }
        assert_eq!(lazy, plain, "λ {lambda}");
        assert!(lazy.len() > 10);
    }
}

#[test]
fn medial_trees_cover_and_stay_within_the_budget() {
    let mesh = cuboid(Vec3::ZERO, Vec3::new(6.0, 3.0, 2.0));
    let bvh = TriangleBvh::build(&mesh);
    for (branching, levels) in [(8, 3), (4, 4), (2, 5), (8, 1), (8, 2)] {
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

/// The build compiled for AVX2 (taken on processors that have it) and the portable build give
/// the same tree, bit for bit: the lanes round alike in both (see `geometry::lanes`).
#[test]
fn instruction_sets_build_the_same_tree() {
    let mesh = crate::teeth::ShapeSet::shared(crate::teeth::ToothResolution::PAPER)
        .get(crate::teeth::Arch::Upper, crate::teeth::ToothKind::ALL[5])
        .mesh
        .clone();
    let bvh = TriangleBvh::build(&mesh);
    let chosen = build_medial(&mesh, &bvh, 8, 3);
    let portable = build(&mesh, &bvh, 8, 3);
    assert!(chosen.leaves().count() > 30);
    assert_eq!(chosen.nodes, portable.nodes);
    assert_eq!(chosen.triangles, portable.triangles);
}

/// On a tooth, the predicted λ gives a cover near its target size without a λ = 0 cover, and
/// a larger target is predicted a smaller λ.
#[test]
fn predicted_lambda_lands_the_cover_near_its_target() {
    use crate::teeth::{Arch, ShapeSet, ToothKind, ToothResolution};
    let g = ShapeSet::shared(ToothResolution::PAPER).get(Arch::Lower, ToothKind::ALL[6]);
    let m = MeshRef {
        mesh: &g.mesh,
        bvh: &g.bvh,
    };
    let max_leaves = 64;
    let area = g.mesh.area() as f32;
    let s = (area / max_leaves as f32).sqrt();
    let pieces = split_surface(&g.mesh, PIECE_EDGE * s);
    let seeds = seeds_by_area(&pieces, area, max_leaves);
    let columns = Columns::build(&g.mesh, LINES);
    let c = candidates(m, &pieces, &columns, &seeds, s, max_leaves);
    let index = GainIndex::new(&c, &pieces.area);
    let size = |lambda: f64| {
        let mut chosen = greedy(&c, &index, lambda);
        prune(&c, &mut chosen, pieces.area.len());
        chosen.len() as f64
    };
    let target = 60.0;
    let lambda = predicted_lambda(&c, &index, target).expect("a λ for 60 spheres");
    let n = size(lambda);
    assert!(
        (0.75 * target..=1.25 * target).contains(&n),
        "{n} spheres at λ {lambda}"
    );
    let wider = predicted_lambda(&c, &index, 2.0 * target).expect("a λ for 120 spheres");
    assert!(wider < lambda && size(wider) > n, "{wider} vs {lambda}");
    assert!(size(0.0) > 2.0 * target, "λ = 0 is far over both");
}

/// Points inside piece edges are numbered once for the two pieces on either side: on a cube,
/// whose pieces meet edge to edge, every number is used twice, at one place.
#[test]
fn edge_points_are_numbered_once_for_both_pieces() {
    let roles = Lattice::new(3).roles();
    let count = |f: fn(&Role) -> bool| roles.iter().filter(|r| f(r)).count();
    assert_eq!(count(|r| matches!(r, Role::Corner(_))), 3);
    assert_eq!(roles[0], Role::Corner(0));
    assert_eq!(roles[9], Role::Corner(1));
    assert_eq!(roles[3], Role::Corner(2));
    assert_eq!(count(|r| matches!(r, Role::Edge { .. })), 6);
    assert_eq!(count(|r| *r == Role::Inner), 1);
    let mesh = cuboid(Vec3::ZERO, Vec3::splat(2.0));
    let pieces = split_surface(&mesh, 0.3);
    let owner = vec![0u32; pieces.corners.len()];
    let surface = Surface::new(&pieces, &owner, Lattice::new(3));
    assert_eq!(surface.edge_points, 3 * pieces.corners.len());
    let mut seen: Vec<Vec<Vec3>> = vec![Vec::new(); surface.edge_points];
    for (p, &k) in surface.points.iter().zip(&surface.shared) {
        if k != u32::MAX {
            seen[k as usize].push(*p);
        }
    }
    assert!(
        seen.iter()
            .all(|v| v.len() == 2 && v[0].distance(v[1]) < 1e-5)
    );
}
