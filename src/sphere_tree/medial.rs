//! The medial builder: leaf spheres centred on an approximation of the medial axis, chosen by a
//! weighted set cover of the surface that minimises the paper's outside volume, shrunk and polished
//! on a fine lattice of surface points, made exact, then grouped into a balanced hierarchy.
//!
//! 1. **Pieces.** Every triangle is split with [`split4`] (the split the coverage check uses) until
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
//!    ([`Columns`], all margins of a ball in one pass over the lines, skipping lines whose chord
//!    through the largest margin lies inside the tooth). A tiny sphere around each piece no
//!    candidate covers, and the smallest sphere around the whole mesh, keep the cover always
//!    feasible.
//! 4. **Cover.** Greedy weighted set cover (the most newly covered area per (outside volume + λ)),
//!    evaluated lazily over exact integer gains that are kept current as pieces are covered
//!    (`GainIndex`: a ball's margins share increments, each piece lists the increments that
//!    hold it; the heap holds one entry per ball). Then spheres whose pieces others cover are
//!    dropped. The sum of the costs is the paper's `sov_sum` (times the tooth volume) plus λ per
//!    leaf; λ is searched (from a guess predicted by each ball's best candidate alone, then on
//!    log λ against log size) so that the cover just fits 8 % over the budget B^(levels−1):
//!    polishing leaves a few spheres with no surface of their own, and step 6 drops any leaves
//!    still over the budget.
//! 5. **Shrink and polish.** The cover is decided on pieces; the spheres are then tightened on a
//!    lattice of 10 points per piece: each point goes to the sphere that holds it with the most
//!    room, each sphere shrinks to its points (radii only shrink, so the points stay covered), and
//!    each sphere's centre is moved by a pattern search that lowers its outside volume while it
//!    holds its points: eight trial centres at a time, their farthest points in one pass over the
//!    points and their outside volumes in one pass over the lattice lines gathered around the
//!    sphere ([`LocalLines`], without the lines whose chord stays inside the tooth). Piece corners
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
//! **Instruction sets.** The whole build runs through [`lanes::run`]: on a processor with AVX2 its
//! lane loops (candidate piece scans and costs, shrinking, polishing) are compiled as 256-bit
//! operations, elsewhere as SSE2 halves, with the same result bit for bit (tested).
//!
//! Guarantee: the coverage invariant holds by construction (step 6 gives every piece of the surface
//! a leaf that holds its corners; step 7 makes every ancestor hold them), with radii rounded up by a
//! relative 10⁻⁶ plus 10⁻⁵ mm so that the f32 containment test agrees. At most B^(levels−1)
//! leaves. Deterministic: fixed sampling, ties broken by index, no dependence on thread timing.
//!
//! Measured on the `normal` case (16 distinct tooth shapes, branching 8, depth 4): `sov_sum` mean
//! 0.078 (0.060–0.100), about 510 leaves; see the README for the table and the build times.

use std::{cmp::Ordering, collections::BinaryHeap};

use crate::geometry::lanes::{self, F8, Job};
use glam::Vec3;

use super::{
    coverage::split4,
    tree::{SphereTree, triangles_touching},
};
use crate::geometry::{
    Aabb, Columns, LocalLines, MeshRef, Sphere, TriMesh, TriangleBvh, closest_point_triangle,
    ray::ray_first_hit,
};

/// Growth margins of the candidates, as fractions of the leaf spacing s.
const GROWTH: [f32; 12] = [
    0.025, 0.04, 0.06, 0.08, 0.11, 0.14, 0.18, 0.23, 0.29, 0.37, 0.48, 0.63,
];
/// How many of `GROWTH` budgets of 512 leaves and more use: wider margins are never chosen there.
const GROWTH_FINE: usize = 10;
/// The same for budgets under 64 leaves, whose few spheres must each cover much more of the tooth.
const GROWTH_WIDE: [f32; 16] = [
    0.025, 0.04, 0.06, 0.08, 0.11, 0.14, 0.18, 0.23, 0.29, 0.37, 0.48, 0.63, 0.85, 1.15, 1.5, 2.0,
];
/// Largest piece edge, as a fraction of the leaf spacing s.
const PIECE_EDGE: f32 = 0.3;
/// Most pieces (finer budgets get coarser pieces than `PIECE_EDGE`).
const MAX_PIECES: usize = 60_000;
/// Medial seeds per leaf of the budget.
const SEEDS_PER_LEAF: usize = 5;
/// Most medial seeds.
const MAX_SEEDS: usize = 6_000;
/// Points per piece edge (minus one) for the shrinking rounds: a 4 × 4 lattice of points per piece.
const POINT_LATTICE: u32 = 3;
/// Shrinking rounds after the cover.
const SHRINK_ROUNDS: u32 = 1;
/// Rounds of centre polishing, each followed by a shrinking round.
const POLISH_ROUNDS: u32 = 3;
/// The polish's compass directions.
const DIRS: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];
/// Most batches of eight trial centres per sphere and polishing round.
const POLISH_BATCHES: u32 = 10;
/// The lattice lines gathered for a polish reach this much past the first batch's spheres, so
/// that the next few moves are measured without gathering again.
const REACH: f32 = 1.1;
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

/// Surface pieces (corners, centroid, face normal, area), and their corners numbered once:
/// pieces that share a corner (bit for bit, as `split4` gives neighbours) share its number.
struct Pieces {
    corners: Vec<[Vec3; 3]>,
    corner_id: Vec<[u32; 3]>,
    corner_at: Vec<Vec3>,
    centroid: Vec<Vec3>,
    normal: Vec<Vec3>,
    area: Vec<f32>,
}

fn edge_max(t: &[Vec3; 3]) -> f32 {
    t[0].distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]))
}

fn split_surface(mesh: &TriMesh, edge: f32) -> Pieces {
    let levels = |edge: f32| -> Vec<u32> {
        (0..mesh.triangles.len())
            .map(|t| {
                let e = edge_max(&mesh.triangle(t));
                if e <= edge || edge <= 0.0 {
                    0
                } else {
                    ((e / edge).log2().ceil() as u32).min(8)
                }
            })
            .collect()
    };
    let mut edge = edge;
    let mut lv = levels(edge);
    while lv.iter().map(|&l| 4usize.pow(l)).sum::<usize>() > MAX_PIECES {
        edge *= 1.5;
        lv = levels(edge);
    }
    let mut p = Pieces {
        corners: Vec::new(),
        corner_id: Vec::new(),
        corner_at: Vec::new(),
        centroid: Vec::new(),
        normal: Vec::new(),
        area: Vec::new(),
    };
    let mut ids: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    for (t, &level) in lv.iter().enumerate() {
        let tri = mesh.triangle(t);
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
        let mut stack = vec![(tri, 0u32)];
        while let Some((piece, l)) = stack.pop() {
            if l < level {
                stack.extend(split4(piece).map(|s| (s, l + 1)));
                continue;
            }
            p.corners.push(piece);
            p.corner_id.push(piece.map(|q| {
                let next = ids.len() as u32;
                *ids.entry(q.to_array().map(f32::to_bits))
                    .or_insert_with(|| {
                        p.corner_at.push(q);
                        next
                    })
            }));
            p.centroid.push((piece[0] + piece[1] + piece[2]) / 3.0);
            p.normal.push(normal);
            p.area
                .push(0.5 * (piece[1] - piece[0]).cross(piece[2] - piece[0]).length());
        }
    }
    p
}

/// How far the medial balls may cross the surface, in mm: the candidates grow each ball by at
/// least 2.5 % of the leaf spacing.
const BALL_SLACK: f32 = 2e-3;

/// The maximal inscribed ball tangent at `p` (outward normal `n`), by the shrinking-ball method
/// in one pass over the triangle tree. It starts from `start`, or from half the distance to the
/// surface straight inwards if that is less (the ball's diameter along −n runs inside the mesh,
/// so that is an upper bound and the first ball is nearly tight). Balls tangent at `p` are
/// nested as they shrink, so a box or triangle clear of the ball stays clear of every later one:
/// each node is tested against the ball as it is when the node is reached, and each triangle
/// that reaches into the ball shrinks it (to the ball through `p` and the triangle's point
/// nearest the centre) until it no longer does, or 16 times (each shrink closes most of the
/// excess, so the cap is not reached in practice). The result then has no surface nearer its
/// centre than the radius less `BALL_SLACK` (tested against a brute-force scan). The candidates do
/// not rely on it: coverage is established by the cover and made exact in step 6.
fn medial_ball(mesh: MeshRef, p: Vec3, n: Vec3, start: f32) -> Sphere {
    let t_min = 1e-4 * start;
    let mut r = ray_first_hit(mesh, p, -n, t_min).map_or(start, |t| (0.5 * t).min(start));
    let bvh = mesh.bvh;
    let mut c = p - n * r;
    // Squared radius below which surface counts as inside the ball.
    let mut inner2 = (r - BALL_SLACK).max(0.0).powi(2);
    let (mut stack, mut top) = ([0u32; 64], usize::from(!bvh.nodes.is_empty()));
    while top > 0 {
        top -= 1;
        let node = bvh.nodes[stack[top] as usize];
        if node.aabb.distance_squared_to_point(c) >= inner2 {
            continue;
        }
        if node.is_leaf() {
            for &t in bvh.leaf_triangles(&node) {
                let [a, b, d] = mesh.mesh.triangle(t as usize);
                let bounds = Aabb::from_points([a, b, d]);
                for _ in 0..16 {
                    if bounds.distance_squared_to_point(c) >= inner2 {
                        break;
                    }
                    let q = closest_point_triangle(c, a, b, d);
                    let pq = p - q;
                    let along = pq.dot(n);
                    if q.distance_squared(c) >= inner2
                        || along <= 1e-9
                        || pq.length_squared() < 1e-10
                    {
                        break;
                    }
                    let next = pq.length_squared() / (2.0 * along);
                    if next >= r {
                        break;
                    }
                    r = next;
                    c = p - n * r;
                    inner2 = (r - BALL_SLACK).max(0.0).powi(2);
                }
            }
        } else {
            let l = node.start as usize;
            let d0 = bvh.nodes[l].aabb.distance_squared_to_point(c);
            let d1 = bvh.nodes[l + 1].aabb.distance_squared_to_point(c);
            let (near, far) = if d0 < d1 { (l, l + 1) } else { (l + 1, l) };
            stack[top] = far as u32;
            stack[top + 1] = near as u32;
            top += 2;
        }
    }
    Sphere::new(c, r)
}

/// Pieces binned by centroid on a uniform grid.
struct PieceGrid {
    min: Vec3,
    cell: f32,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// The pieces' corner coordinates in `items` order (corner-major: x, y, z of the first
    /// corner, then the second, the third), padded with eight zeros, for lane-wise reading.
    corners: [Vec<f32>; 9],
}

impl PieceGrid {
    fn new(pieces: &Pieces, cell: f32) -> Self {
        let bounds = crate::geometry::Aabb::from_points(pieces.centroid.iter().copied());
        let e = bounds.extent();
        let cell = cell.max(e.max_element() / 64.0).max(1e-6);
        let dims = [
            (e.x / cell) as usize + 1,
            (e.y / cell) as usize + 1,
            (e.z / cell) as usize + 1,
        ];
        let index = |p: Vec3| {
            let q = ((p - bounds.min) / cell).as_uvec3();
            let q = [
                (q.x as usize).min(dims[0] - 1),
                (q.y as usize).min(dims[1] - 1),
                (q.z as usize).min(dims[2] - 1),
            ];
            (q[0] * dims[1] + q[1]) * dims[2] + q[2]
        };
        let mut count = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for &c in &pieces.centroid {
            count[index(c) + 1] += 1;
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; pieces.centroid.len()];
        for (k, &c) in pieces.centroid.iter().enumerate() {
            let slot = &mut fill[index(c)];
            items[*slot as usize] = k as u32;
            *slot += 1;
        }
        let corners = std::array::from_fn(|c| {
            let mut v: Vec<f32> = items
                .iter()
                .map(|&k| pieces.corners[k as usize][c / 3][c % 3])
                .collect();
            v.resize(items.len() + 8, 0.0);
            v
        });
        Self {
            min: bounds.min,
            cell,
            dims,
            start: count,
            items,
            corners,
        }
    }

    /// Calls `f(piece, reach²)` for every piece whose three corners lie within `r` of `c`
    /// (reach = distance to the farthest corner), eight pieces at a time.
    #[inline(always)]
    fn within(&self, c: Vec3, r: f32, mut f: impl FnMut(u32, f32)) {
        let lo = ((c - Vec3::splat(r) - self.min) / self.cell).floor();
        let hi = ((c + Vec3::splat(r) - self.min) / self.cell).floor();
        let clamp = |x: f32, d: usize| (x.max(0.0) as usize).min(d - 1);
        if hi.x < 0.0 || hi.y < 0.0 || hi.z < 0.0 {
            return;
        }
        let r2 = F8::splat(r * r);
        let centre = [c.x, c.y, c.z].map(F8::splat);
        let lane = F8::from(std::array::from_fn::<f32, 8, _>(|k| k as f32));
        // The distance from the centre to a run of cells along one axis, off the run's axis.
        let gap = |i: usize, axis: usize| {
            let lo = self.min[axis] + i as f32 * self.cell;
            (lo - c[axis]).max(c[axis] - lo - self.cell).max(0.0)
        };
        for x in clamp(lo.x, self.dims[0])..=clamp(hi.x, self.dims[0]) {
            for y in clamp(lo.y, self.dims[1])..=clamp(hi.y, self.dims[1]) {
                // Only the cells along z that the ball reaches (centroids lie within r).
                let room = r * r - gap(x, 0).powi(2) - gap(y, 1).powi(2);
                if room < 0.0 {
                    continue;
                }
                let half = room.sqrt();
                let (zl, zh) = (
                    ((c.z - half - self.min.z) / self.cell).floor(),
                    ((c.z + half - self.min.z) / self.cell).floor(),
                );
                if zh < 0.0 {
                    continue;
                }
                let row = (x * self.dims[1] + y) * self.dims[2];
                let (z0, z1) = (clamp(zl, self.dims[2]), clamp(zh, self.dims[2]));
                // Cells along z are consecutive in `items`.
                let (a, b) = (
                    self.start[row + z0] as usize,
                    self.start[row + z1 + 1] as usize,
                );
                let mut j = a;
                while j < b {
                    let mut reach = F8::ZERO;
                    for corner in 0..3 {
                        let d = |axis: usize| {
                            F8::load(&self.corners[corner * 3 + axis], j) - centre[axis]
                        };
                        let (dx, dy, dz) = (d(0), d(1), d(2));
                        reach = reach.max(dx * dx + dy * dy + dz * dz);
                    }
                    let valid = lane.simd_lt(F8::splat((b - j) as f32));
                    let mut mask = (reach.simd_le(r2) & valid).to_bitmask();
                    if mask != 0 {
                        let reach = reach.to_array();
                        while mask != 0 {
                            let k = mask.trailing_zeros() as usize;
                            mask &= mask - 1;
                            f(self.items[j + k], reach[k]);
                        }
                    }
                    j += 8;
                }
            }
        }
    }
}

fn reach(corners: &[Vec3; 3], c: Vec3) -> f32 {
    corners.iter().map(|p| p.distance(c)).fold(0.0f32, f32::max)
}

fn padded(r: f32) -> f32 {
    r * (1.0 + MARGIN_REL) + MARGIN_ABS
}

/// A candidate leaf: sphere, the pieces it covers (`pool[first..first + len]`) and its cost.
#[derive(Clone, Copy)]
struct Candidate {
    sphere: Sphere,
    first: u32,
    len: u32,
    cost: f64,
}

/// Candidate spheres and the pool of the pieces they cover.
struct Candidates {
    list: Vec<Candidate>,
    pool: Vec<u32>,
}

#[inline(always)]
fn candidates(
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
    for (i, _) in covered.iter().enumerate().filter(|(_, c)| !**c) {
        let e = Sphere::enclosing(&pieces.corners[i]);
        let sphere = Sphere::new(e.centre, padded(reach(&pieces.corners[i], e.centre)));
        add(&mut out, sphere, &mut std::iter::once(i as u32));
    }
    let all = Sphere::enclosing(&m.mesh.vertices);
    let all = Sphere::new(all.centre, padded(all.radius));
    add(&mut out, all, &mut (0..pieces.corners.len() as u32));
    out
}

/// Heap entry: priority (an upper bound on the candidate's key), candidate.
#[derive(PartialEq)]
struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // Ties go to the lower index, for determinism.
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// What the greedy cover keeps current: each candidate's gain as a sum of increments.
///
/// The candidates of one medial ball cover nested prefixes of one run of the pool, so candidate k
/// of a group covers the increments of the group's candidates up to k. Pieces weigh their area in
/// whole units (2⁻⁴⁰ of the tooth's area, at least one), so that gains are exact integers: when a
/// piece is covered its weight leaves every increment that holds it, and a gain is zero exactly
/// when all its pieces are covered.
struct GainIndex {
    /// The groups (one per medial ball): their candidates are `first..end`.
    groups: Vec<(u32, u32)>,
    /// Per candidate: its group.
    group: Vec<u32>,
    /// Per candidate: the weight of the pieces its increment adds to the group's previous one.
    increment: Vec<u64>,
    /// Per piece: its weight.
    weight: Vec<u64>,
    /// Per piece: the candidates whose increment holds it (`owners[start[i]..start[i + 1]]`).
    start: Vec<u32>,
    owners: Vec<u32>,
}

impl GainIndex {
    fn new(c: &Candidates, area: &[f32]) -> Self {
        let total: f64 = area.iter().map(|&a| a.max(0.0) as f64).sum();
        let unit = if total > 0.0 {
            2f64.powi(40) / total
        } else {
            1.0
        };
        let weight: Vec<u64> = area
            .iter()
            .map(|&a| ((a.max(0.0) as f64 * unit).round() as u64).max(1))
            .collect();
        let mut groups: Vec<(u32, u32)> = Vec::new();
        let mut group = Vec::with_capacity(c.list.len());
        let mut increment = Vec::with_capacity(c.list.len());
        let mut count = vec![0u32; area.len() + 1];
        let mut runs = Vec::with_capacity(c.list.len());
        for (k, x) in c.list.iter().enumerate() {
            let from = match k.checked_sub(1).map(|j| &c.list[j]) {
                Some(prev) if prev.first == x.first && prev.len <= x.len => {
                    groups.last_mut().expect("a group has begun").1 = k as u32 + 1;
                    prev.len
                }
                _ => {
                    groups.push((k as u32, k as u32 + 1));
                    0
                }
            };
            group.push(groups.len() as u32 - 1);
            let run = x.first as usize + from as usize..(x.first + x.len) as usize;
            increment.push(
                c.pool[run.clone()]
                    .iter()
                    .map(|&i| weight[i as usize])
                    .sum(),
            );
            for &i in &c.pool[run.clone()] {
                count[i as usize + 1] += 1;
            }
            runs.push(run);
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut owners = vec![0u32; count[area.len()] as usize];
        for (k, run) in runs.into_iter().enumerate() {
            for &i in &c.pool[run] {
                owners[fill[i as usize] as usize] = k as u32;
                fill[i as usize] += 1;
            }
        }
        Self {
            groups,
            group,
            increment,
            weight,
            start: count,
            owners,
        }
    }
}

/// Greedy weighted set cover: repeatedly the candidate with the most newly covered area per
/// (cost + λ), ties to the lower index; returns the chosen candidates in order.
///
/// Gains are kept exact as pieces are covered ([`GainIndex`]), and the heap is lazy (Minoux's
/// accelerated greedy) with one entry per medial ball, keyed by its best candidate: a gain only
/// falls, so a stored key is an upper bound; the top ball's candidates are re-keyed together
/// (their gains are running sums of the group's increments), and its best is taken when it still
/// beats the next bound, which makes it the true best without re-keying every candidate that
/// shares a newly covered piece. A ball whose candidate is taken goes back in the heap, since its
/// larger candidates may still cover more.
fn greedy(c: &Candidates, index: &GainIndex, lambda: f64) -> Vec<u32> {
    let mut increment = index.increment.clone();
    // A group's best candidate now: the most gain per (cost + λ), ties to the lower index.
    let best = |increment: &[u64], group: u32| -> Option<Entry> {
        let (first, end) = index.groups[group as usize];
        let mut gain = 0u64;
        let mut best: Option<Entry> = None;
        for k in first..end {
            gain += increment[k as usize];
            if gain > 0 {
                let entry = Entry(
                    gain as f64 / (c.list[k as usize].cost + lambda).max(1e-12),
                    k,
                );
                if best.as_ref().is_none_or(|b| entry > *b) {
                    best = Some(entry);
                }
            }
        }
        best
    };
    let mut heap: BinaryHeap<Entry> = (0..index.groups.len() as u32)
        .filter_map(|g| best(&increment, g))
        .collect();
    let mut open = vec![true; index.weight.len()];
    let mut uncovered = open.len();
    let mut chosen = Vec::new();
    while uncovered > 0 {
        let Some(Entry(_, k)) = heap.pop() else {
            break;
        };
        let group = index.group[k as usize];
        let Some(entry) = best(&increment, group) else {
            continue;
        };
        if heap.peek().is_some_and(|top| *top > entry) {
            heap.push(entry);
            continue;
        }
        let k = entry.1 as usize;
        let x = &c.list[k];
        for &i in &c.pool[x.first as usize..(x.first + x.len) as usize] {
            let i = i as usize;
            if open[i] {
                open[i] = false;
                uncovered -= 1;
                for &j in &index.owners[index.start[i] as usize..index.start[i + 1] as usize] {
                    increment[j as usize] -= index.weight[i];
                }
            }
        }
        chosen.push(k as u32);
        // The group's larger candidates may still cover more.
        if let Some(entry) = best(&increment, group) {
            heap.push(entry);
        }
    }
    chosen
}

/// The greedy cover, pruned, with a per-leaf cost λ that brings its size just under the budget,
/// by a search on log λ against log size that stops once a cover uses at least 95 % of the
/// budget.
///
/// The first λ is predicted without a cover ([`predicted_lambda`]). Where even a tiny λ is
/// predicted to fit, or the first cover is under 95 % of the budget before any was over it,
/// λ = 0 is tried and taken if it fits (its cover is then the largest); in the first case its
/// cover gives the guess instead: its mean cost scaled by (its size / target)^1.6. Later runs
/// follow the size as a power of λ (exponent about −1/2, measured on teeth) until a bracket is
/// found, then interpolate within the tightest bracket.
fn choose(c: &Candidates, area: &[f32], max_leaves: usize) -> Vec<u32> {
    const RUNS: usize = 10;
    let index = GainIndex::new(c, area);
    let run = |lambda: f64| {
        let mut chosen = greedy(c, &index, lambda);
        prune(c, &mut chosen, area.len());
        chosen
    };
    let target = max_leaves as f64 * 0.985;
    // (λ, size) of the tightest infeasible and feasible runs.
    let mut over: (f64, f64) = (0.0, f64::INFINITY);
    let mut lambda = match predicted_lambda(c, &index, target) {
        Some(lambda) => lambda,
        None => {
            let first = run(0.0);
            if first.len() <= max_leaves {
                return first;
            }
            over.1 = first.len() as f64;
            let mean_cost =
                first.iter().map(|&k| c.list[k as usize].cost).sum::<f64>() / first.len() as f64;
            (mean_cost * (first.len() as f64 / target).powf(1.6)).max(1e-12)
        }
    };
    let scale = lambda;
    let mut under: Option<(f64, f64)> = None;
    let mut best: Vec<u32> = Vec::new();
    for _ in 0..RUNS {
        let chosen = run(lambda);
        let n = chosen.len() as f64;
        if chosen.len() <= max_leaves {
            if under.is_none_or(|u| lambda < u.0) {
                under = Some((lambda, n));
            }
            if chosen.len() > best.len() {
                best = chosen;
            }
            if best.len() as f64 >= 0.95 * max_leaves as f64 {
                break;
            }
            if over.1.is_infinite() {
                // Nothing was over the budget yet: λ = 0 may fit, and then its cover is the
                // largest.
                let zero = run(0.0);
                if zero.len() <= max_leaves {
                    return zero;
                }
                over = (0.0, zero.len() as f64);
            }
        } else if lambda > over.0 {
            over = (lambda, n);
        }
        lambda = match under {
            Some(u) if over.0 > 0.0 => {
                let t = (over.1.ln() - target.ln()) / (over.1.ln() - u.1.ln()).max(1e-9);
                (over.0.ln() + t.clamp(0.05, 0.95) * (u.0.ln() - over.0.ln())).exp()
            }
            Some(u) => u.0 * (u.1 / target).powf(2.0),
            None => over.0 * (over.1 / target).powf(2.0),
        };
    }
    if best.is_empty() {
        // The budget was never met: raise λ until it is, then bisect back towards the largest λ
        // that was over budget, keeping the largest cover that fits.
        let mut lo = over.0.max(scale).max(1e-12);
        let mut hi = lo;
        loop {
            hi *= 4.0;
            let chosen = run(hi);
            if chosen.len() <= max_leaves {
                best = chosen;
                break;
            }
            lo = hi;
        }
        for _ in 0..RUNS {
            let mid = (lo * hi).sqrt();
            let chosen = run(mid);
            if chosen.len() <= max_leaves {
                hi = mid;
                if chosen.len() > best.len() {
                    best = chosen;
                }
            } else {
                lo = mid;
            }
        }
    }
    best
}

/// Overlap of a greedy cover at the λ that fits: its size times the mean weight of each medial
/// ball's best candidate at that λ, over the surface weight. Measured on the `normal` teeth at
/// depth 4 as 2.55–2.83.
const COVER_OVERLAP: f64 = 2.7;

/// The λ whose cover is predicted to have `target` spheres, or None when a tiny λ is predicted to
/// fit (then λ = 0 may). Each medial ball's candidates are scored alone, without the greedy's
/// interplay: at λ the ball's best candidate has the most weight per (cost + λ), and the cover is
/// predicted to need [`COVER_OVERLAP`] × (surface weight) / (mean weight of the best candidates)
/// spheres, which falls as λ grows. Solved by bisection on log λ.
fn predicted_lambda(c: &Candidates, index: &GainIndex, target: f64) -> Option<f64> {
    const STEPS: usize = 14;
    // Candidate weights: prefix sums of each group's increments.
    let mut weight = Vec::with_capacity(c.list.len());
    for &(first, end) in &index.groups {
        let mut sum = 0.0;
        for k in first..end {
            sum += index.increment[k as usize] as f64;
            weight.push(sum);
        }
    }
    let groups = &index.groups;
    if groups.is_empty() {
        return None;
    }
    let total: f64 = index.weight.iter().map(|&w| w as f64).sum();
    let needed = COVER_OVERLAP * total / target;
    let mean_best = |lambda: f64| {
        groups
            .iter()
            .map(|&(a, b)| {
                let mut best = (0.0f64, f64::NEG_INFINITY);
                for k in a as usize..b as usize {
                    let score = weight[k] / (c.list[k].cost + lambda).max(1e-300);
                    if score > best.1 {
                        best = (weight[k], score);
                    }
                }
                best.0
            })
            .sum::<f64>()
            / groups.len() as f64
    };
    let costs = c.list.iter().map(|x| x.cost).filter(|&x| x > 0.0);
    let (lo_cost, hi_cost) = costs.fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    if !(lo_cost.is_finite() && hi_cost > 0.0) {
        return None;
    }
    let (mut lo, mut hi) = ((lo_cost * 1e-3).ln(), (hi_cost * 1e3).ln());
    if mean_best(lo.exp()) >= needed || mean_best(hi.exp()) < needed {
        return None;
    }
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if mean_best(mid.exp()) >= needed {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi.exp())
}

/// Drops chosen spheres whose pieces are all covered by others, costliest first.
fn prune(c: &Candidates, chosen: &mut Vec<u32>, pieces: usize) {
    let members = |k: u32| {
        let x = &c.list[k as usize];
        &c.pool[x.first as usize..(x.first + x.len) as usize]
    };
    let mut count = vec![0u32; pieces];
    for &k in chosen.iter() {
        for &i in members(k) {
            count[i as usize] += 1;
        }
    }
    let mut order = chosen.clone();
    order.sort_by(|&a, &b| {
        c.list[b as usize]
            .cost
            .total_cmp(&c.list[a as usize].cost)
            .then(a.cmp(&b))
    });
    let mut dropped = Vec::new();
    for k in order {
        if members(k).iter().all(|&i| count[i as usize] >= 2) {
            for &i in members(k) {
                count[i as usize] -= 1;
            }
            dropped.push(k);
        }
    }
    chosen.retain(|k| !dropped.contains(k));
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
    let (leaves, corners) = cover_exact(kept, &pieces, &hint, (&lattice_owner, lattice.len), s);
    let order: Vec<usize> = (0..leaves.len()).collect();
    place(&mut tree, 0, 0, order, &leaves, &corners, mesh);
    tree
}

/// The medial seeds: `SEEDS_PER_LEAF` per leaf of the budget (at most `MAX_SEEDS`), pieces
/// spread evenly by area (`area` is the surface's).
fn seeds_by_area(pieces: &Pieces, area: f32, max_leaves: usize) -> Vec<usize> {
    let n_seeds = (SEEDS_PER_LEAF * max_leaves)
        .min(MAX_SEEDS)
        .min(pieces.corners.len());
    let mut seeds = Vec::with_capacity(n_seeds);
    let mut carry = 0.0f32;
    for (i, &a) in pieces.area.iter().enumerate() {
        carry += a / area * n_seeds as f32;
        if carry >= 1.0 {
            carry -= 1.0;
            seeds.push(i);
        }
    }
    seeds
}

/// Sphere indices binned by bounding box on a uniform grid.
struct SphereGrid {
    min: Vec3,
    cell: f32,
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl SphereGrid {
    fn new(spheres: &[Sphere], cell: f32) -> Self {
        let bounds = crate::geometry::Aabb::from_points(spheres.iter().flat_map(|s| {
            [
                s.centre - Vec3::splat(s.radius),
                s.centre + Vec3::splat(s.radius),
            ]
        }));
        let e = bounds.extent();
        let cell = cell.max(e.max_element() / 48.0).max(1e-6);
        let dims = [
            (e.x / cell) as usize + 1,
            (e.y / cell) as usize + 1,
            (e.z / cell) as usize + 1,
        ];
        let mut grid = Self {
            min: bounds.min,
            cell,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
        };
        for (k, s) in spheres.iter().enumerate() {
            let lo = grid.cell_of(s.centre - Vec3::splat(s.radius));
            let hi = grid.cell_of(s.centre + Vec3::splat(s.radius));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        grid.cells[(x * dims[1] + y) * dims[2] + z].push(k as u32);
                    }
                }
            }
        }
        grid
    }

    #[inline(always)]
    fn cell_of(&self, p: Vec3) -> [usize; 3] {
        let q = ((p - self.min) / self.cell).max(Vec3::ZERO);
        [
            (q.x as usize).min(self.dims[0] - 1),
            (q.y as usize).min(self.dims[1] - 1),
            (q.z as usize).min(self.dims[2] - 1),
        ]
    }

    fn near(&self, p: Vec3) -> &[u32] {
        let [x, y, z] = self.cell_of(p);
        &self.cells[(x * self.dims[1] + y) * self.dims[2] + z]
    }
}

/// Eight spheres of a grid cell, by coordinate (padding lanes hold nothing: r² = −1).
#[derive(Clone, Copy)]
struct SphereLanes {
    x: F8,
    y: F8,
    z: F8,
    r2: F8,
    inv_r2: F8,
    index: [u32; 8],
}

/// A [`SphereGrid`]'s cells as runs of [`SphereLanes`].
struct LaneGrid {
    start: Vec<u32>,
    lanes: Vec<SphereLanes>,
}

impl LaneGrid {
    fn new(grid: &SphereGrid, spheres: &[Sphere]) -> Self {
        let mut start = Vec::with_capacity(grid.cells.len() + 1);
        let mut lanes = Vec::new();
        for cell in &grid.cells {
            start.push(lanes.len() as u32);
            for chunk in cell.chunks(8) {
                let mut l = [[0.0f32; 8]; 5];
                l[3] = [-1.0; 8];
                let mut index = [u32::MAX; 8];
                for (k, &i) in chunk.iter().enumerate() {
                    let s = &spheres[i as usize];
                    (l[0][k], l[1][k], l[2][k]) = (s.centre.x, s.centre.y, s.centre.z);
                    l[3][k] = s.radius * s.radius;
                    l[4][k] = 1.0 / l[3][k];
                    index[k] = i;
                }
                lanes.push(SphereLanes {
                    x: l[0].into(),
                    y: l[1].into(),
                    z: l[2].into(),
                    r2: l[3].into(),
                    inv_r2: l[4].into(),
                    index,
                });
            }
        }
        start.push(lanes.len() as u32);
        Self { start, lanes }
    }

    /// Sets each sphere's r² (and its inverse) to the current radius.
    #[inline(always)]
    fn update(&mut self, spheres: &[Sphere]) {
        for l in &mut self.lanes {
            let mut r2 = l.r2.to_array();
            for (k, &i) in l.index.iter().enumerate() {
                if i != u32::MAX {
                    let r = spheres[i as usize].radius;
                    r2[k] = r * r;
                }
            }
            l.r2 = r2.into();
            l.inv_r2 = F8::ONE / l.r2;
        }
    }

    #[inline(always)]
    fn near(&self, grid: &SphereGrid, p: Vec3) -> &[SphereLanes] {
        let [x, y, z] = grid.cell_of(p);
        let cell = (x * grid.dims[1] + y) * grid.dims[2] + z;
        &self.lanes[self.start[cell] as usize..self.start[cell + 1] as usize]
    }
}

/// The lattice points of every piece with the sphere each belongs to, and each numbered piece
/// corner with its sphere. Points inside a piece edge are numbered once per edge (`shared`), so
/// that the pieces on either side of an edge place them once.
struct Surface<'a> {
    pieces: &'a Pieces,
    lattice: Lattice,
    /// Runs of `lattice.len` points per piece, in `points_on` order.
    points: Vec<Vec3>,
    /// What each point of a run is.
    roles: Vec<Role>,
    owner: Vec<u32>,
    /// Per piece: the sphere that all its points go to, or `u32::MAX` if they go to several.
    whole: Vec<u32>,
    corner_owner: Vec<u32>,
    /// Per point: its number among the edge points, or `u32::MAX` for corners and inner points.
    shared: Vec<u32>,
    /// How many edge points are numbered.
    edge_points: usize,
}

impl<'a> Surface<'a> {
    /// Every point starts with the sphere that covers its piece.
    fn new(pieces: &'a Pieces, piece_owner: &[u32], lattice: Lattice) -> Self {
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
fn shrink(spheres: &mut [Sphere], surface: &mut Surface, rounds: u32, cell: f32) {
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
fn best_of(
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

/// A lattice point: a piece corner, a point inside the edge from corner `from` to corner `to`
/// (`step` of n steps from `from`), or a point inside the piece. Corners and edges count the
/// piece's corners 0, 1, 2.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Corner(u8),
    Edge { from: u8, to: u8, step: u32 },
    Inner,
}

/// The lattice of points on each piece: n + 1 points per edge, and how many in all.
#[derive(Clone, Copy)]
struct Lattice {
    n: u32,
    len: usize,
}

impl Lattice {
    fn new(n: u32) -> Self {
        let n = n.max(1);
        let len = (n as usize + 1) * (n as usize + 2) / 2;
        Self { n, len }
    }

    /// What each lattice point is, in `points_on` order.
    fn roles(&self) -> Vec<Role> {
        let n = self.n;
        let mut roles = Vec::with_capacity(self.len);
        for u in 0..=n {
            for v in 0..=n - u {
                roles.push(match (u, v) {
                    (0, 0) => Role::Corner(0),
                    _ if u == n => Role::Corner(1),
                    _ if v == n => Role::Corner(2),
                    (_, 0) => Role::Edge {
                        from: 0,
                        to: 1,
                        step: u,
                    },
                    (0, _) => Role::Edge {
                        from: 0,
                        to: 2,
                        step: v,
                    },
                    _ if u + v == n => Role::Edge {
                        from: 1,
                        to: 2,
                        step: v,
                    },
                    _ => Role::Inner,
                });
            }
        }
        roles
    }

    /// The lattice points of a piece: a + (b − a)·u/n + (c − a)·v/n for u + v ≤ n, u major.
    fn points_on(&self, [a, b, c]: [Vec3; 3], out: &mut Vec<Vec3>) {
        let n = self.n;
        for u in 0..=n {
            for v in 0..=n - u {
                let (fu, fv) = (u as f32 / n as f32, v as f32 / n as f32);
                out.push(a + (b - a) * fu + (c - a) * fv);
            }
        }
    }
}

/// Gives every piece of the surface to a sphere that holds it (splitting pieces that no single
/// sphere holds, and growing the sphere that needs the least growth for a piece still unheld at the
/// split limit), then shrinks every sphere to its pieces. A piece whose hinted sphere (`hint`, or
/// `u32::MAX` for none) holds its corners goes to it without a search; any other piece and its
/// parts look first among the spheres of its lattice points (`lattice_owner`, `per_piece` per
/// piece; `u32::MAX` for a dropped sphere). Returns the leaves that hold pieces and the corners of
/// their pieces.
fn cover_exact(
    mut spheres: Vec<Sphere>,
    pieces: &Pieces,
    hint: &[u32],
    (lattice_owner, per_piece): (&[u32], usize),
    cell: f32,
) -> (Vec<Sphere>, Vec<Vec<Vec3>>) {
    const SPLITS: u32 = 5;
    let grid = SphereGrid::new(&spheres, cell);
    let mut owned: Vec<Vec<Vec3>> = vec![Vec::new(); spheres.len()];
    let mut stack = Vec::new();
    // A numbered corner is listed once per sphere as far as neighbouring pieces show it.
    let mut mark = vec![u32::MAX; pieces.corner_at.len()];
    for (i, ((piece, &h), ids)) in pieces
        .corners
        .iter()
        .zip(hint)
        .zip(&pieces.corner_id)
        .enumerate()
    {
        if let Some(s) = spheres.get(h as usize)
            && piece.iter().all(|&q| s.contains(q))
        {
            for (&q, &id) in piece.iter().zip(ids) {
                if mark[id as usize] != h {
                    mark[id as usize] = h;
                    owned[h as usize].push(q);
                }
            }
            continue;
        }
        let lattice = &lattice_owner[i * per_piece..(i + 1) * per_piece];
        let orphaned = lattice.contains(&u32::MAX);
        // The distinct spheres of the piece's lattice points.
        let mut owners = Vec::with_capacity(4);
        for &k in lattice {
            if k != u32::MAX && !owners.contains(&k) {
                owners.push(k);
            }
        }
        stack.push((*piece, 0u32));
        while let Some((p, depth)) = stack.pop() {
            let most_room = |among: &mut dyn Iterator<Item = u32>| {
                among
                    .filter(|&k| p.iter().all(|&q| spheres[k as usize].contains(q)))
                    .map(|k| {
                        (
                            k,
                            reach(&p, spheres[k as usize].centre) / spheres[k as usize].radius,
                        )
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            };
            // The spheres of the piece's lattice points; every sphere near it only where one of
            // those was dropped, or before the last resort of growing one.
            let near = grid.near((p[0] + p[1] + p[2]) / 3.0);
            let best = most_room(&mut owners.iter().copied()).or_else(|| {
                (orphaned || depth >= SPLITS)
                    .then(|| most_room(&mut near.iter().copied()))
                    .flatten()
            });
            if let Some((k, _)) = best {
                owned[k as usize].extend_from_slice(&p);
                continue;
            }
            if depth < SPLITS {
                stack.extend(split4(p).map(|x| (x, depth + 1)));
                continue;
            }
            let growth = |k: usize| reach(&p, spheres[k].centre) - spheres[k].radius;
            let k = near
                .iter()
                .map(|&k| k as usize)
                .chain(
                    (near.is_empty())
                        .then_some(0..spheres.len())
                        .into_iter()
                        .flatten(),
                )
                .min_by(|&a, &b| growth(a).total_cmp(&growth(b)).then(a.cmp(&b)))
                .expect("at least one sphere");
            spheres[k].radius = padded(reach(&p, spheres[k].centre)).max(spheres[k].radius);
            owned[k].extend_from_slice(&p);
        }
    }
    for (s, points) in spheres.iter_mut().zip(&owned) {
        let r = points
            .iter()
            .map(|p| p.distance(s.centre))
            .fold(0.0f32, f32::max);
        s.radius = padded(r).min(s.radius);
    }
    spheres
        .into_iter()
        .zip(owned)
        .filter(|(_, c)| !c.is_empty())
        .unzip()
}

/// Moves a leaf's centre to lower its outside volume while it keeps holding `points`: a compass
/// pattern search measuring eight trial centres at once (the six axis steps, the last move
/// repeated and doubled) and moving to the best of them, the step halving when none is better,
/// from `first_step` of the radius down to 2 %, at most `POLISH_BATCHES` batches; the radius
/// follows the farthest point. Returns the polished sphere and the longest move it made.
#[inline(always)]
fn polish(
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
fn trials(xyz: &[[[f32; 8]; 3]], o: Vec3, c: Vec3, step: f32, m: Vec3) -> [Sphere; 8] {
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
fn measure(
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
    tree.nodes[node] = Some(Sphere::new(s.centre, padded(s.radius)));
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
                    let owners =
                        &index.owners[index.start[i] as usize..index.start[i + 1] as usize];
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
}
