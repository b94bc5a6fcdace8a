//! The medial builder: leaf spheres centred on an approximation of the medial axis, chosen by a
//! weighted set cover of the surface that minimises the paper's outside volume, shrunk and polished
//! on a fine lattice of surface points, made exact, then grouped into a balanced hierarchy.
//!
//! 1. **Pieces.** Every triangle is split with `split4` (the split the coverage check uses) until
//!    its pieces are shorter than 0.3 s, where s = √(area / leaf budget) is the leaf spacing.
//! 2. **Medial centres.** For 5 seeds per leaf of the budget, spread evenly by area, the maximal
//!    inscribed ball tangent at the seed, by the shrinking-ball method (Ma, Bae, Choi and Lee
//!    2012), starting from half the distance to the surface straight inwards (an upper bound on
//!    the radius) and shrinking in a single pass over the triangle tree, since the balls tangent
//!    at the seed are nested as they shrink. Its centre lies on the medial axis; a sphere there,
//!    slightly larger than the ball, bulges out of the tooth only as a flat cap around the
//!    tangent points, which is what makes medial spheres tight.
//! 3. **Candidates.** Each medial ball grown by a geometric series of margins (fractions of s). A
//!    candidate covers the pieces whose three corners it holds and is shrunk to the farthest of
//!    them; its cost is its volume outside the tooth, by exact line integrals over a lattice
//!    (`Columns`, all margins of a ball in one pass over the lines, skipping lines whose chord
//!    through the largest margin lies inside the tooth). A tiny sphere around each piece no
//!    candidate covers, and the smallest sphere around the whole mesh, keep the cover always
//!    feasible. Pieces that no candidate reaches, or only ones whose outside volume exceeds half a
//!    sphere of the leaf spacing (where medial balls fail: a generated root's narrow apex, a
//!    scan's slivers), are also offered as spheres of their own and in clusters by grid cells of
//!    s and 2s, so that such a region costs a few leaves rather than one per piece.
//! 4. **Cover.** Greedy weighted set cover (the most newly covered area per (outside volume + λ)),
//!    evaluated lazily over exact integer gains that are kept current as pieces are covered
//!    (`GainIndex`: a ball's margins share increments, each piece lists the increments that
//!    hold it; the heap holds one entry per ball). Then spheres whose pieces others cover are
//!    dropped. The sum of the costs is the paper's `sov_sum` (times the tooth volume) plus λ per
//!    leaf; λ is searched (from a guess predicted by each ball's best candidate alone, then on
//!    log λ against log size) so that the cover just fits 8 % over the budget B^(levels−1):
//!    polishing leaves a few spheres with no surface of their own, and step 6 drops any leaves
//!    still over the budget. Should the cover still jump, as λ grows, from over the budget to a
//!    handful of spheres (under a quarter of a budget of 64 or more), the smallest cover over the
//!    budget (at most twice it) is kept, and step 6 trims it.
//! 5. **Shrink and polish.** The cover is decided on pieces; the spheres are then tightened on a
//!    lattice of 10 points per piece: each point goes to the sphere that holds it with the most
//!    room, each sphere shrinks to its points (radii only shrink, so the points stay covered), and
//!    each sphere's centre is moved by a pattern search that lowers its outside volume while it
//!    holds its points: eight trial centres at a time, their farthest points in one pass over the
//!    points and their outside volumes in one pass over the lattice lines gathered around the
//!    sphere (`LocalLines`, without the lines whose chord stays inside the tooth). Piece corners
//!    are numbered once, so a corner shared by six pieces is placed once, and so are the points
//!    inside a piece edge, which the pieces on either side share. A piece whose three corners go
//!    to one sphere goes to it whole, without testing its inner points: the sphere holds its
//!    corners, so the whole piece, whose farthest point from the centre is a corner. One shrinking
//!    round, then three rounds of polish and shrink; after the first, a sphere's search starts at
//!    twice the longest move it made the round before, and in the third a sphere
//!    whose moves the round before were all at most 2 % of its radius is not polished again.
//! 6. **Exact cover.** Spheres that hold no points go; if more than the budget hold some, those
//!    holding the fewest pieces go too. A piece that the lattice gave wholly to a kept sphere goes
//!    to it; every other triangle piece is split as the coverage check splits it until each part
//!    lies in one sphere (the one with the most room among the spheres of the piece's lattice
//!    points, or among all near spheres where one of those was dropped); a part no sphere holds
//!    after five splits — a sliver between the points — goes to the near sphere with the most
//!    room that holds it, else grows the one that needs the least growth. Each sphere then
//!    shrinks to the pieces it is responsible for.
//! 7. **Hierarchy.** Leaves are split into B balanced groups along the longest axis of their
//!    centres, recursively; each inner sphere is the smallest sphere around the pieces its leaves
//!    are responsible for, so invariant (2) holds by construction.
//!
//! **Instruction sets.** The whole build runs through `lanes::run`: on a processor with AVX2 its
//! lane loops (candidate piece scans and costs, shrinking, polishing) are compiled as 256-bit
//! operations, elsewhere as SSE2 halves, with the same result bit for bit (tested).
//!
//! Guarantee: the coverage invariant holds by construction (step 6 gives every piece of the surface
//! a leaf that holds its corners; step 7 makes every ancestor hold them), with radii rounded up by a
//! relative 10⁻⁶ plus 10⁻⁵ mm so that the f32 containment test agrees. At most B^(levels−1)
//! leaves. Deterministic: fixed sampling, ties broken by index, no dependence on thread timing.
//!
//! Measured on the `normal` case (16 distinct tooth shapes, branching 8, depth 4): `sov_sum` mean
//! 0.077 (0.060–0.098), about 510 leaves; see the guide (`docs/sphere-trees.md`) for the table and the build times.

//!
//! One file per phase: `pieces` (pieces, seeds and the point lattice), `balls` (medial balls),
//! `grids` (the piece and sphere grids), `candidates`, `cover` (the greedy cover and its λ),
//! `polish` (shrinking and polishing), `exact_cover` and `hierarchy`; this file holds the
//! builder's parameters and runs the phases in order.

mod balls;
mod candidates;
mod cover;
mod exact_cover;
mod grids;
mod hierarchy;
mod pieces;
mod polish;
#[cfg(test)]
mod tests;

use glam::Vec3;

use self::{
    candidates::candidates,
    cover::choose,
    exact_cover::cover_exact,
    hierarchy::place,
    pieces::{Lattice, seeds_by_area, split_surface},
    polish::{Surface, polish, shrink},
};
use super::tree::SphereTree;
use crate::geometry::{
    Columns, LocalLines, MeshRef, Sphere, TriMesh, TriangleBvh,
    lanes::{self, Job},
};

/// Largest piece edge, as a fraction of the leaf spacing s.
const PIECE_EDGE: f32 = 0.3;

/// Points per piece edge (minus one) for the shrinking rounds: a 4 × 4 lattice of points per piece.
const POINT_LATTICE: u32 = 3;

/// Shrinking rounds after the cover.
const SHRINK_ROUNDS: u32 = 1;

/// Rounds of centre polishing, each followed by a shrinking round.
const POLISH_ROUNDS: u32 = 3;

/// Lattice lines across the tooth for outside volumes (the candidates' costs and the polish).
const LINES: usize = 48;

/// The same for budgets over 512 leaves, whose smaller spheres need a finer lattice.
const FINE_LINES: usize = 64;

/// The cover aims this much over the leaf budget: a few spheres lose all their surface to
/// neighbours while polishing, and any still over the budget at the end are dropped.
const COVER_OVERSHOOT: f32 = 1.08;

/// First pattern-search step of the polish, as a fraction of the radius; later rounds start at
/// twice the largest step that moved the sphere last time, but not below `LEAST_FIRST_STEP`.
const FIRST_STEP: f32 = 0.12;

const LEAST_FIRST_STEP: f32 = 0.04;

/// Radius rounding so that f32 containment agrees with the distances used here.
const MARGIN_REL: f32 = 1e-6;

const MARGIN_ABS: f32 = 1e-5;

fn reach(corners: &[Vec3; 3], c: Vec3) -> f32 {
    corners.iter().map(|p| p.distance(c)).fold(0.0f32, f32::max)
}

fn padded(r: f32) -> f32 {
    r * (1.0 + MARGIN_REL) + MARGIN_ABS
}

/// Builds a medial sphere tree with `levels` levels and branching `branching`.
pub fn build_medial(mesh: &TriMesh, bvh: &TriangleBvh, branching: u32, levels: u32) -> SphereTree {
    struct Build<'a>(&'a TriMesh, &'a TriangleBvh, u32, u32);
    impl Job for Build<'_> {
        type Output = SphereTree;
        #[inline(always)]
        fn run(self) -> SphereTree {
            build(self.0, self.1, self.2, self.3)
        }
    }
    lanes::run(Build(mesh, bvh, branching, levels))
}

/// [`build_medial`], compiled into each instruction set's caller.
#[inline(always)]
fn build(mesh: &TriMesh, bvh: &TriangleBvh, branching: u32, levels: u32) -> SphereTree {
    let levels = levels.max(1);
    let mut tree = SphereTree::empty(branching, levels);
    if mesh.triangles.is_empty() {
        return tree;
    }
    let m = MeshRef { mesh, bvh };
    let max_leaves = (branching as usize).pow(levels - 1);
    let area = mesh.area() as f32;
    let s = (area / max_leaves as f32).sqrt();
    let pieces = split_surface(mesh, PIECE_EDGE * s);
    let columns = Columns::build(mesh, if max_leaves > 512 { FINE_LINES } else { LINES });
    let seeds = seeds_by_area(&pieces, area, max_leaves);
    let cands = candidates(m, &pieces, &columns, &seeds, s, max_leaves);
    let chosen = choose(
        &cands,
        &pieces.area,
        (max_leaves as f32 * COVER_OVERSHOOT) as usize,
    );
    let mut spheres: Vec<Sphere> = chosen
        .iter()
        .map(|&k| cands.list[k as usize].sphere)
        .collect();
    // Shrinking works on a lattice of points over every piece, each starting with a sphere that
    // covers its piece.
    let mut owner = vec![0u32; pieces.corners.len()];
    for (j, &k) in chosen.iter().enumerate() {
        let x = &cands.list[k as usize];
        for &i in &cands.pool[x.first as usize..(x.first + x.len) as usize] {
            owner[i as usize] = j as u32;
        }
    }
    let mut surface = Surface::new(&pieces, &owner, Lattice::new(POINT_LATTICE));
    shrink(&mut spheres, &mut surface, SHRINK_ROUNDS, s);
    let mut steps = vec![FIRST_STEP; spheres.len()];
    let mut mark = vec![u32::MAX; pieces.corner_at.len()];
    let mut owned: Vec<Vec<Vec3>> = vec![Vec::new(); spheres.len()];
    for round in 0..POLISH_ROUNDS {
        mark.fill(u32::MAX);
        // A piece owned whole is represented by its corners (its farthest points from any centre),
        // each corner once per sphere as far as neighbouring pieces show it.
        owned.iter_mut().for_each(Vec::clear);
        let lattice = surface.lattice;
        for (((piece, own), ids), &whole) in surface
            .points
            .chunks(lattice.len)
            .zip(surface.owner.chunks(lattice.len))
            .zip(&pieces.corner_id)
            .zip(&surface.whole)
        {
            if whole != u32::MAX {
                for id in ids {
                    if mark[*id as usize] != whole {
                        mark[*id as usize] = whole;
                        owned[whole as usize].push(pieces.corner_at[*id as usize]);
                    }
                }
            } else {
                for (p, &o) in piece.iter().zip(own) {
                    owned[o as usize].push(*p);
                }
            }
        }
        let mut local = LocalLines::default();
        for ((sphere, points), step) in spheres.iter_mut().zip(&owned).zip(&mut steps) {
            // In the third round, a sphere that barely moved the round before stays.
            let still = round >= 2 && *step <= LEAST_FIRST_STEP;
            if points.is_empty() || still {
                continue;
            }
            let (polished, moved) = polish(&columns, &mut local, *sphere, points, *step);
            *sphere = polished;
            *step = (2.0 * moved / sphere.radius).clamp(LEAST_FIRST_STEP, FIRST_STEP);
        }
        shrink(&mut spheres, &mut surface, 1, s);
    }
    // The spheres' shares of the surface: a piece wholly in one sphere is its hint for the
    // exact cover. Spheres left with nothing go; if more than the budget hold something, those
    // holding the fewest pieces go too, and the others take their pieces over.
    let lattice = surface.lattice;
    let mut hint = vec![u32::MAX; pieces.corners.len()];
    let mut held = vec![0usize; spheres.len()];
    for (i, own) in surface.owner.chunks(lattice.len).enumerate() {
        if surface.whole[i] != u32::MAX {
            hint[i] = surface.whole[i];
            held[surface.whole[i] as usize] += 1;
        } else {
            for (j, &o) in own.iter().enumerate() {
                if !own[..j].contains(&o) {
                    held[o as usize] += 1;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..spheres.len()).filter(|&k| held[k] > 0).collect();
    if order.len() > max_leaves {
        order.sort_by_key(|&k| (std::cmp::Reverse(held[k]), k));
        order.truncate(max_leaves);
        order.sort_unstable();
    }
    let mut index = vec![u32::MAX; spheres.len()];
    for (j, &k) in order.iter().enumerate() {
        index[k] = j as u32;
    }
    let hint: Vec<u32> = hint
        .iter()
        .map(|&h| index.get(h as usize).copied().unwrap_or(u32::MAX))
        .collect();
    let kept: Vec<Sphere> = order.iter().map(|&k| spheres[k]).collect();
    let lattice_owner: Vec<u32> = surface
        .owner
        .iter()
        .map(|&o| index.get(o as usize).copied().unwrap_or(u32::MAX))
        .collect();
    let (leaves, mut corners) = cover_exact(kept, &pieces, &hint, (&lattice_owner, lattice.len), s);
    // Pieces share corners: each leaf's distinct ones are enough for the inner spheres.
    for points in &mut corners {
        points.sort_unstable_by_key(|p| p.to_array().map(f32::to_bits));
        points.dedup_by_key(|p| p.to_array().map(f32::to_bits));
    }
    let order: Vec<usize> = (0..leaves.len()).collect();
    place(&mut tree, 0, 0, order, &leaves, &corners, m);
    tree
}
