//! Phase 3 of the medial builder: each medial ball grown by a series of margins into candidate
//! leaves, with the pieces each covers and its outside volume as cost.

use super::{balls::medial_ball, grids::PieceGrid, padded, pieces::Pieces, reach};
use crate::geometry::{Columns, MeshRef, Sphere};

/// Growth margins of the candidates, as fractions of the leaf spacing s.
pub(super) const GROWTH: [f32; 12] = [
    0.025, 0.04, 0.06, 0.08, 0.11, 0.14, 0.18, 0.23, 0.29, 0.37, 0.48, 0.63,
];

/// How many of `GROWTH` budgets of 512 leaves and more use: wider margins are never chosen there.
pub(super) const GROWTH_FINE: usize = 10;

/// The same for budgets under 64 leaves, whose few spheres must each cover much more of the tooth.
pub(super) const GROWTH_WIDE: [f32; 16] = [
    0.025, 0.04, 0.06, 0.08, 0.11, 0.14, 0.18, 0.23, 0.29, 0.37, 0.48, 0.63, 0.85, 1.15, 1.5, 2.0,
];

/// A candidate leaf: sphere, the pieces it covers (`pool[first..first + len]`) and its cost.
#[derive(Clone, Copy)]
pub(super) struct Candidate {
    pub(super) sphere: Sphere,
    pub(super) first: u32,
    pub(super) len: u32,
    pub(super) cost: f64,
}

/// Candidate spheres and the pool of the pieces they cover.
pub(super) struct Candidates {
    pub(super) list: Vec<Candidate>,
    pub(super) pool: Vec<u32>,
}

#[inline(always)]
pub(super) fn candidates(
    m: MeshRef,
    pieces: &Pieces,
    columns: &Columns,
    seeds: &[usize],
    s: f32,
    max_leaves: usize,
) -> Candidates {
    let start = m.mesh.aabb().extent().length();
    let grid = PieceGrid::new(pieces, s);
    let mut out = Candidates {
        list: Vec::new(),
        pool: Vec::new(),
    };
    let growth: &[f32] = if max_leaves < 64 {
        &GROWTH_WIDE
    } else if max_leaves < 512 {
        &GROWTH
    } else {
        &GROWTH[..GROWTH_FINE]
    };
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); growth.len()];
    let mut radii = Vec::with_capacity(growth.len());
    let mut costs = vec![0.0f64; growth.len()];
    let mut far = vec![0.0f32; growth.len()];
    let mut limit2 = vec![0.0f32; growth.len()];
    for &k in seeds {
        let ball = medial_ball(m, pieces.centroid[k], pieces.normal[k], start);
        let r_max = ball.radius + growth[growth.len() - 1] * s;
        // Pieces bucketed by the first growth step that reaches them (no sort needed: a
        // candidate covers whole buckets); squared distances throughout.
        for b in buckets.iter_mut() {
            b.clear();
        }
        for (l, &g) in limit2.iter_mut().zip(growth) {
            *l = (ball.radius + g * s).powi(2);
        }
        far.iter_mut().for_each(|f| *f = 0.0);
        grid.within(ball.centre, r_max, |i, r2| {
            // The first step that reaches the piece (counted without branches).
            let b = limit2
                .iter()
                .map(|&l| (r2 > l) as usize)
                .sum::<usize>()
                .min(growth.len() - 1);
            buckets[b].push(i);
            far[b] = far[b].max(r2);
        });
        // Distinct covers, each shrunk to its farthest piece.
        radii.clear();
        let mut prefixes = Vec::new();
        let first = out.pool.len() as u32;
        let mut reach_so_far = 0.0f32;
        for (b, bucket) in buckets.iter_mut().enumerate() {
            if bucket.is_empty() {
                continue;
            }
            out.pool.extend_from_slice(bucket);
            reach_so_far = reach_so_far.max(far[b].sqrt());
            prefixes.push(out.pool.len() - first as usize);
            radii.push(padded(reach_so_far));
        }
        if prefixes.is_empty() {
            continue;
        }
        columns.outside_volumes(ball.centre, &radii, &mut costs[..radii.len()]);
        for (j, &n) in prefixes.iter().enumerate() {
            out.list.push(Candidate {
                sphere: Sphere::new(ball.centre, radii[j]),
                first,
                len: n as u32,
                cost: costs[j],
            });
        }
    }
    // Feasibility: a small sphere for any piece nothing covers, and one around everything.
    let mut covered = vec![false; pieces.corners.len()];
    for &i in &out.pool {
        covered[i as usize] = true;
    }
    let add = |out: &mut Candidates, sphere: Sphere, members: &mut dyn Iterator<Item = u32>| {
        let first = out.pool.len() as u32;
        out.pool.extend(members);
        let len = out.pool.len() as u32 - first;
        out.list.push(Candidate {
            sphere,
            first,
            len,
            cost: columns.outside_volume(&sphere),
        });
    };
    // A piece is poorly covered when no medial candidate reaches it, or only ones whose outside
    // volume exceeds half a sphere of the leaf spacing (a ball from a seed whose surface around
    // it is too thin or twisted for a medial ball).
    let poor = 0.5 * 4.0 / 3.0 * std::f64::consts::PI * f64::from(s).powi(3);
    // A ball's candidates cover nested prefixes of one run and grow dearer, so each piece's
    // cheapest candidate of a ball is the first whose prefix holds it.
    let mut cheapest = vec![f64::INFINITY; pieces.corners.len()];
    let mut previous: Option<(u32, u32)> = None;
    for x in &out.list {
        let from = match previous {
            Some((first, len)) if first == x.first && len <= x.len => len,
            _ => 0,
        };
        for &i in &out.pool[(x.first + from) as usize..(x.first + x.len) as usize] {
            let c = &mut cheapest[i as usize];
            *c = c.min(x.cost);
        }
        previous = Some((x.first, x.len));
    }
    let uncovered: Vec<u32> = (0..pieces.corners.len() as u32)
        .filter(|&i| !covered[i as usize] || cheapest[i as usize] > poor)
        .collect();
    for &i in &uncovered {
        let corners = &pieces.corners[i as usize];
        let e = Sphere::enclosing(corners);
        let sphere = Sphere::new(e.centre, padded(reach(corners, e.centre)));
        add(&mut out, sphere, &mut std::iter::once(i));
    }
    // Where medial balls fail (a generated root's narrow apex, a scan's slivers), the poorly
    // covered pieces are also offered in clusters: one sphere around those of each grid cell of
    // the leaf spacing and of twice it, so that such a region costs a few leaves, not one per
    // piece (with a leaf per piece the budget is only met by the sphere around everything).
    for cell in [s, 2.0 * s] {
        let mut groups: std::collections::BTreeMap<[i32; 3], Vec<u32>> = Default::default();
        for &i in &uncovered {
            let key = (pieces.centroid[i as usize] / cell)
                .floor()
                .as_ivec3()
                .to_array();
            groups.entry(key).or_default().push(i);
        }
        for members in groups.values().filter(|m| m.len() > 1) {
            let points: Vec<glam::Vec3> = members
                .iter()
                .flat_map(|&i| pieces.corners[i as usize])
                .collect();
            let e = Sphere::enclosing(&points);
            let r = points
                .iter()
                .map(|p| p.distance(e.centre))
                .fold(0.0f32, f32::max);
            add(
                &mut out,
                Sphere::new(e.centre, padded(r)),
                &mut members.iter().copied(),
            );
        }
    }
    let all = Sphere::enclosing(&m.mesh.vertices);
    let all = Sphere::new(all.centre, padded(all.radius));
    add(&mut out, all, &mut (0..pieces.corners.len() as u32));
    out
}
