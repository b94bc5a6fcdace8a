//! Phase 5 of the medial builder: the cover's spheres shrunk to the lattice points they hold with
//! the most room, and their centres polished by a pattern search on the outside volume.

use glam::Vec3;

use super::{
    grids::{LaneGrid, SphereGrid},
    padded,
    pieces::{Lattice, Pieces, Role},
};
use crate::geometry::{Columns, LocalLines, Sphere, lanes::F8};

/// The polish's compass directions.
pub(super) const DIRS: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

/// Most batches of eight trial centres per sphere and polishing round.
pub(super) const POLISH_BATCHES: u32 = 10;

/// The lattice lines gathered for a polish reach this much past the first batch's spheres, so
/// that the next few moves are measured without gathering again.
pub(super) const REACH: f32 = 1.1;

/// The lattice points of every piece with the sphere each belongs to, and each numbered piece
/// corner with its sphere. Points inside a piece edge are numbered once per edge (`shared`), so
/// that the pieces on either side of an edge place them once.
pub(super) struct Surface<'a> {
    pub(super) pieces: &'a Pieces,
    pub(super) lattice: Lattice,
    /// Runs of `lattice.len` points per piece, in `points_on` order.
    pub(super) points: Vec<Vec3>,
    /// What each point of a run is.
    pub(super) roles: Vec<Role>,
    pub(super) owner: Vec<u32>,
    /// Per piece: the sphere that all its points go to, or `u32::MAX` if they go to several.
    pub(super) whole: Vec<u32>,
    pub(super) corner_owner: Vec<u32>,
    /// Per point: its number among the edge points, or `u32::MAX` for corners and inner points.
    pub(super) shared: Vec<u32>,
    /// How many edge points are numbered.
    pub(super) edge_points: usize,
}

impl<'a> Surface<'a> {
    /// Every point starts with the sphere that covers its piece.
    pub(super) fn new(pieces: &'a Pieces, piece_owner: &[u32], lattice: Lattice) -> Self {
        let (mut points, mut owner) = (Vec::new(), Vec::new());
        let mut corner_owner = vec![0u32; pieces.corner_at.len()];
        let roles = lattice.roles();
        let per_edge = lattice.n - 1;
        // Edges numbered by their corner numbers: a list of (other corner, edge) per lower corner.
        let mut head = vec![u32::MAX; pieces.corner_at.len()];
        let mut links: Vec<(u32, u32)> = Vec::new();
        let mut shared = Vec::with_capacity(pieces.corners.len() * lattice.len);
        for (i, &corners) in pieces.corners.iter().enumerate() {
            lattice.points_on(corners, &mut points);
            owner.resize(points.len(), piece_owner[i]);
            let ids = pieces.corner_id[i];
            for id in ids {
                corner_owner[id as usize] = piece_owner[i];
            }
            let mut edge = |from: u8, to: u8| {
                let (x, y) = (ids[from as usize], ids[to as usize]);
                let (lo, hi) = (x.min(y), x.max(y));
                let mut at = head[lo as usize];
                while at != u32::MAX && links[at as usize].0 != hi {
                    at = links[at as usize].1;
                }
                if at == u32::MAX {
                    at = links.len() as u32;
                    links.push((hi, head[lo as usize]));
                    head[lo as usize] = at;
                }
                (at, x == lo)
            };
            for role in &roles {
                shared.push(match *role {
                    Role::Edge { from, to, step } => {
                        let (e, forward) = edge(from, to);
                        let k = if forward { step } else { lattice.n - step };
                        e * per_edge + k - 1
                    }
                    _ => u32::MAX,
                });
            }
        }
        Self {
            pieces,
            lattice,
            points,
            roles,
            owner,
            whole: piece_owner.to_vec(),
            corner_owner,
            shared,
            edge_points: links.len() * per_edge as usize,
        }
    }
}

/// Shrinks the spheres: each point goes to the sphere that holds it with the most room (least
/// distance / radius, compared as squares) and every sphere shrinks to its own points, `rounds`
/// times. Radii never grow, so every point stays inside the sphere it belongs to.
///
/// Each numbered piece corner is placed once. A piece whose three corners go to one sphere goes
/// to it whole: the sphere holds the corners, so (being convex) the whole piece, and its farthest
/// point from the centre is a corner.
#[inline(always)]
pub(super) fn shrink(spheres: &mut [Sphere], surface: &mut Surface, rounds: u32, cell: f32) {
    let grid = SphereGrid::new(spheres, cell);
    let mut lanes = LaneGrid::new(&grid, spheres);
    let mut radius = vec![0.0f32; spheres.len()];
    let mut corner_best = vec![(0u32, 0.0f32, 0.0f32); surface.corner_owner.len()];
    let mut edge_best = vec![(u32::MAX, 0.0f32, 0.0f32); surface.edge_points];
    let lattice = surface.lattice;
    for round in 0..rounds.max(1) {
        edge_best.iter_mut().for_each(|b| b.0 = u32::MAX);
        if round > 0 {
            lanes.update(spheres);
        }
        radius.iter_mut().for_each(|r| *r = 0.0);
        for ((best, &p), own) in corner_best
            .iter_mut()
            .zip(&surface.pieces.corner_at)
            .zip(&surface.corner_owner)
        {
            *best = best_of(&lanes, &grid, spheres, p, *own as usize);
        }
        for ((((piece, own), ids), shared), whole) in surface
            .points
            .chunks(lattice.len)
            .zip(surface.owner.chunks_mut(lattice.len))
            .zip(&surface.pieces.corner_id)
            .zip(surface.shared.chunks(lattice.len))
            .zip(surface.whole.iter_mut())
        {
            let corners = ids.map(|id| corner_best[id as usize]);
            if corners.iter().all(|c| c.0 == corners[0].0) {
                let k = corners[0].0;
                *whole = k;
                own.iter_mut().for_each(|o| *o = k);
                let r = &mut radius[k as usize];
                *r = corners.iter().map(|c| c.2).fold(*r, f32::max);
                continue;
            }
            *whole = u32::MAX;
            for (((&p, o), role), &shared) in piece
                .iter()
                .zip(own.iter_mut())
                .zip(&surface.roles)
                .zip(shared)
            {
                let best = match role {
                    Role::Corner(c) => corners[*c as usize],
                    Role::Edge { .. } => {
                        let known = &mut edge_best[shared as usize];
                        if known.0 == u32::MAX {
                            *known = best_of(&lanes, &grid, spheres, p, *o as usize);
                        }
                        *known
                    }
                    Role::Inner => best_of(&lanes, &grid, spheres, p, *o as usize),
                };
                *o = best.0;
                let r = &mut radius[best.0 as usize];
                *r = r.max(best.2);
            }
        }
        for (o, best) in surface.corner_owner.iter_mut().zip(&corner_best) {
            *o = best.0;
        }
        for (s, &r2) in spheres.iter_mut().zip(&radius) {
            s.radius = padded(r2.sqrt()).min(s.radius);
        }
    }
}

/// The sphere that holds `p` with the most room (least distance / radius, compared as squares),
/// starting from its current sphere `own`: (sphere, (distance / radius)², distance²).
#[inline(always)]
pub(super) fn best_of(
    lanes: &LaneGrid,
    grid: &SphereGrid,
    spheres: &[Sphere],
    p: Vec3,
    own: usize,
) -> (u32, f32, f32) {
    let d2 = p.distance_squared(spheres[own].centre);
    let r = spheres[own].radius;
    let mut best = (own as u32, d2 / (r * r), d2);
    let (px, py, pz) = (F8::splat(p.x), F8::splat(p.y), F8::splat(p.z));
    for l in lanes.near(grid, p) {
        let (dx, dy, dz) = (l.x - px, l.y - py, l.z - pz);
        let d2 = dx * dx + dy * dy + dz * dz;
        let ratio = d2 * l.inv_r2;
        let better = d2.simd_le(l.r2) & ratio.simd_lt(F8::splat(best.1));
        let mut mask = better.to_bitmask();
        if mask == 0 {
            continue;
        }
        let (ratio, d2) = (ratio.to_array(), d2.to_array());
        while mask != 0 {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if ratio[k] < best.1 {
                best = (l.index[k], ratio[k], d2[k]);
            }
        }
    }
    best
}

/// Moves a leaf's centre to lower its outside volume while it keeps holding `points`: a compass
/// pattern search measuring eight trial centres at once (the six axis steps, the last move
/// repeated and doubled) and moving to the best of them, the step halving when none is better,
/// from `first_step` of the radius down to 2 %, at most `POLISH_BATCHES` batches; the radius
/// follows the farthest point. Returns the polished sphere and the longest move it made.
#[inline(always)]
pub(super) fn polish(
    columns: &Columns,
    local: &mut LocalLines,
    leaf: Sphere,
    points: &[Vec3],
    first_step: f32,
) -> (Sphere, f32) {
    // Points relative to the starting centre, eight to a lane (padding repeats the first point,
    // which changes no maximum). From trial centre c + m, the squared distance to point p is
    // |p − c|² − 2 m·(p − c) + |m|²: one pass over the points gives the farthest point for all
    // eight moves.
    let o = leaf.centre;
    let lanes = points.len().div_ceil(8);
    let mut xyz = vec![[[0.0f32; 8]; 3]; lanes];
    for k in 0..lanes * 8 {
        let d = points.get(k).unwrap_or(&points[0]) - o;
        for a in 0..3 {
            xyz[k / 8][a][k % 8] = d[a];
        }
    }
    let mut best = Sphere::new(o, leaf.radius);
    let mut best_cost = f64::INFINITY;
    let mut step = first_step * leaf.radius;
    let mut last_move = Vec3::ZERO;
    let mut largest = 0.0f32;
    for batch in 0..POLISH_BATCHES {
        if step <= 0.02 * leaf.radius {
            break;
        }
        let c = best.centre;
        let m = if batch > 0 { last_move } else { Vec3::ZERO };
        let spheres = trials(&xyz, o, c, step, m);
        let costs = measure(columns, local, &spheres, c, batch == 0);
        if batch == 0 {
            // Lane 6 is the start itself.
            (best, best_cost) = (spheres[6], costs[6]);
        }
        let (k, cost) = costs
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            .expect("eight lanes");
        if cost < best_cost {
            last_move = spheres[k].centre - c;
            largest = largest.max(last_move.length());
            (best, best_cost) = (spheres[k], cost);
        } else {
            step *= 0.5;
            last_move = Vec3::ZERO;
        }
    }
    (best, largest)
}

/// The eight trial spheres of a polish batch around centre `c`: ± `step` along each axis (lanes
/// 0–5), then `m` and 2m (lanes 6, 7), each as small as holds the points (`xyz`, relative to `o`,
/// eight to a lane).
#[inline(always)]
pub(super) fn trials(xyz: &[[[f32; 8]; 3]], o: Vec3, c: Vec3, step: f32, m: Vec3) -> [Sphere; 8] {
    let rel = c - o;
    let (cx, cy, cz) = (F8::splat(rel.x), F8::splat(rel.y), F8::splat(rel.z));
    let mut far = [F8::splat(f32::NEG_INFINITY); 8];
    let t = F8::splat(2.0 * step);
    let (mx, my, mz) = (
        F8::splat(2.0 * m.x),
        F8::splat(2.0 * m.y),
        F8::splat(2.0 * m.z),
    );
    for [x, y, z] in xyz {
        let (dx, dy, dz) = (F8::from(*x) - cx, F8::from(*y) - cy, F8::from(*z) - cz);
        let d2 = dx * dx + dy * dy + dz * dz;
        for (axis, d) in [dx, dy, dz].into_iter().enumerate() {
            let along = t * d;
            far[2 * axis] = far[2 * axis].max(d2 - along);
            far[2 * axis + 1] = far[2 * axis + 1].max(d2 + along);
        }
        let md = mx * dx + my * dy + mz * dz;
        far[6] = far[6].max(d2 - md);
        far[7] = far[7].max(d2 - md - md);
    }
    std::array::from_fn(|k| {
        let shift = match k {
            0..6 => DIRS[k] * step,
            6 => m,
            _ => 2.0 * m,
        };
        let r2 = far[k]
            .to_array()
            .into_iter()
            .fold(f32::NEG_INFINITY, f32::max)
            + shift.length_squared();
        Sphere::new(c + shift, padded(r2.max(0.0).sqrt()))
    })
}

/// The outside volumes of eight trial spheres, over the lines gathered around `anchor` (gathered
/// afresh when `fresh` or when a sphere leaves them, with room for the next few moves).
#[inline(always)]
pub(super) fn measure(
    columns: &Columns,
    local: &mut LocalLines,
    spheres: &[Sphere; 8],
    anchor: Vec3,
    fresh: bool,
) -> [f64; 8] {
    if fresh || !spheres.iter().all(|s| local.holds(columns, s)) {
        let need = spheres
            .iter()
            .map(|s| s.centre.distance(anchor) + s.radius)
            .fold(0.0f32, f32::max);
        columns.gather(anchor, REACH * need, local);
    }
    local.outside_volumes(columns, spheres)
}
