//! The hierarchical advancement, for candidate sets too large to list pair by pair (teeth at
//! scan resolution): the candidate triangles are marked in each tooth's triangle hierarchy, and
//! each step searches the marked hierarchies together (see the parent module).

use glam::Vec3;

use super::drift::Drift;
use super::{Candidates, Frame, PlacedTri, Settle, advance_over, relative};
use crate::collision::motion::{Motion, NodeCache};
use crate::collision::narrow_phase::lanes::Affine32;
use crate::collision::narrow_phase::{Body, PairContact, continuous};
use crate::geometry::{Aabb, NO_PARENT, Slab, TriangleBvh, closest_points_facing_triangles};

/// Per-thread scratch of the advancement, indexed by mesh triangle or hierarchy node and stamped
/// per query (or per step), so nothing is cleared between queries.
#[derive(Default)]
struct Scratch {
    /// Sphere-tree leaves whose triangles are already listed.
    leaf_a: NodeCache<u32>,
    leaf_b: NodeCache<u32>,
    /// Candidate triangles: the head of each one's list of meeting leaves in `links_a` /
    /// `links_b` (leaf number, next entry).
    cand_a: NodeCache<u32>,
    cand_b: NodeCache<u32>,
    links_a: Vec<(u32, u32)>,
    links_b: Vec<(u32, u32)>,
    /// The meeting leaf pairs, one bit per (leaf of a, leaf of b) by their numbers.
    meets: Vec<u64>,
    leaves_b: usize,
    /// Triangle-hierarchy nodes holding a candidate.
    node_a: NodeCache<bool>,
    node_b: NodeCache<bool>,
    /// Candidate triangles placed in the first tooth's frame: the first's once per query, the
    /// second's once per step.
    placed_a: NodeCache<PlacedTri>,
    placed_b: NodeCache<PlacedTri>,
    /// The second tooth's node boxes and slabs in the first's frame, once per step.
    box_b: NodeCache<(Aabb, Slab)>,
    /// Nodes' projections on the search axis, once per axis.
    proj_a: NodeCache<(f32, f32)>,
    proj_b: NodeCache<(f32, f32)>,
    stack: Vec<(f32, u32, u32)>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Conservative advancement over the bodies' whole motion through the triangle hierarchies.
pub(super) fn advance(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    tol: f64,
) -> Option<PairContact> {
    SCRATCH.with_borrow_mut(|scratch| advance_with(a, b, swept, tol, scratch))
}

/// Pads a box computed in f32 from a rotated one by far more than its rounding.
#[inline]
fn padded(b: Aabb) -> Aabb {
    let pad = Vec3::splat(BOX_SLACK_MM + 1e-6 * (b.min.abs().max(b.max.abs())).max_element());
    Aabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}

/// Allowance (mm) for the rounding of a hierarchy box turned into the other tooth's frame.
const BOX_SLACK_MM: f32 = 1e-5;

/// The candidate triangles of both teeth, their hierarchies' marked nodes and the placed
/// triangles: what one advancement step searches.
struct Search<'s, 'm> {
    ma: &'m crate::geometry::TriMesh,
    mb: &'m crate::geometry::TriMesh,
    ba: &'m TriangleBvh,
    bb: &'m TriangleBvh,
    s: &'s mut Scratch,
    rel: Affine32,
    /// The search axis (first tooth's frame): near the contact both surfaces lie across it, so
    /// their nodes' projections on it are thin and bound the node pairs tightly.
    axis: Vec3,
    /// The nearest pair of the last search, measured first in the next.
    last: Option<(u32, u32)>,
}

impl Candidates for Search<'_, '_> {
    fn place(&mut self, _t: f64, frame: &Frame) {
        self.s.placed_b.begin(self.mb.triangles.len());
        self.s.box_b.begin(self.bb.nodes.len());
        self.rel = frame.rel;
    }

    fn least(&mut self, axis: Vec3, enough: f32) -> Option<(f32, Vec3, Vec3)> {
        let (d, qa, qb, pair) = self.nearest(self.last, axis, enough);
        self.last = Some(pair);
        d.is_finite().then_some((d, qa, qb))
    }

    fn nearest_drift(&mut self, drift: &Drift) -> f64 {
        self.last.map_or(0.0, |(x, y)| {
            let (tx, ty) = (self.tri_a(x), self.tri_b(y));
            drift.step(&tx, &ty)
        })
    }

    fn extend(&mut self, drift: &Drift, mu: f64, h: f64, plain: f64, first: f64) -> f64 {
        self.step(drift, mu, h, plain, first)
    }
}

impl Search<'_, '_> {
    #[inline]
    fn tri_a(&mut self, x: u32) -> PlacedTri {
        let ma = self.ma;
        *self
            .s
            .placed_a
            .get_ref(x as usize, || PlacedTri::new(ma.triangle(x as usize)))
    }

    #[inline]
    fn tri_b(&mut self, y: u32) -> PlacedTri {
        let (mb, rel) = (self.mb, self.rel);
        *self.s.placed_b.get_ref(y as usize, || {
            PlacedTri::new(mb.triangle(y as usize).map(|v| rel.apply(v)))
        })
    }

    /// The second tooth's node `n` in the first tooth's frame: its box, and its slab padded by
    /// far more than the rounding of the map (as the box is).
    #[inline]
    fn node_b(&mut self, n: u32) -> (Aabb, Slab) {
        let (bb, rel) = (self.bb, self.rel);
        self.s.box_b.get(n as usize, || {
            let b = padded(bb.nodes[n as usize].aabb.transformed(&rel.m, rel.t));
            let s = bb.slabs[n as usize];
            let normal = rel.m * s.normal;
            let shift = normal.dot(rel.t);
            let pad = BOX_SLACK_MM + 1e-6 * (b.min.abs().max(b.max.abs())).max_element();
            (
                b,
                Slab {
                    normal,
                    lo: s.lo + shift - pad,
                    hi: s.hi + shift + pad,
                },
            )
        })
    }

    /// The least and greatest projection on `n` of the vertices of leaf `node` of the first
    /// tooth (`first`) or the second (placed), candidates or not.
    #[inline]
    fn leaf_span(&mut self, node: u32, first: bool, n: Vec3) -> (f32, f32) {
        let (lo, hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let bvh = if first { self.ba } else { self.bb };
        let leaf = bvh.nodes[node as usize];
        bvh.leaf_triangles(&leaf)
            .iter()
            .fold((lo, hi), |(lo, hi), &t| {
                let tri = if first { self.tri_a(t) } else { self.tri_b(t) };
                tri.v.iter().fold((lo, hi), |(lo, hi), v| {
                    let p = n.dot(*v);
                    (lo.min(p), hi.max(p))
                })
            })
    }

    /// A lower bound of the distance between any triangle under node `na` of the first tooth and
    /// any under `nb` of the second: the larger of their boxes' distance and their slabs' gaps.
    /// Along the first's slab normal n the second's points project within α·(its slab) plus its
    /// box projected on n − α·m (m its slab normal, α = n·m), which is tight when the two
    /// patches face each other; likewise the other way. Computed in f32 and lowered by far more
    /// than the rounding (a relative 4·10⁻⁶ of the coordinates' size).
    #[inline]
    fn node_gap(&mut self, na: u32, nb: u32, cut: f32) -> f32 {
        let (pa, pb) = (self.proj(na, true), self.proj(nb, false));
        let x = &self.ba.nodes[na as usize];
        let (by, sb) = self.node_b(nb);
        let size = by.min.abs().max(by.max.abs()).max_element()
            + x.aabb.min.abs().max(x.aabb.max.abs()).max_element();
        let slack = 4e-6 * size;
        let along = (pb.0 - pa.1).max(pa.0 - pb.1) * (1.0 - 1e-6) - slack;
        if along >= cut {
            return along;
        }
        let sa = self.ba.slabs[na as usize];
        let boxes = x.aabb.distance_squared(&by).sqrt();
        let alpha = sa.normal.dot(sb.normal);
        let span = |b: &Aabb, v: Vec3| {
            let (c, r) = (b.centre().dot(v), (b.extent() * 0.5).dot(v.abs()));
            (c - r, c + r)
        };
        let scaled = |s: &Slab| {
            let (p, q) = (alpha * s.lo, alpha * s.hi);
            (p.min(q), p.max(q))
        };
        // A leaf's own vertices project exactly (its box does not, for a large triangle).
        let y = self.bb.nodes[nb as usize];
        let (bl, bh) = if y.is_leaf() {
            self.leaf_span(nb, false, sa.normal)
        } else {
            let (wl, wh) = span(&by, sa.normal - alpha * sb.normal);
            let (pl, ph) = scaled(&sb);
            (pl + wl, ph + wh)
        };
        let along_a = (bl - sa.hi).max(sa.lo - bh);
        let (al, ah) = if x.is_leaf() {
            self.leaf_span(na, true, sb.normal)
        } else {
            let (vl, vh) = span(&x.aabb, sb.normal - alpha * sa.normal);
            let (ql, qh) = scaled(&sa);
            (ql + vl, qh + vh)
        };
        let along_b = (al - sb.hi).max(sb.lo - ah);
        (boxes.max(along_a).max(along_b) * (1.0 - 1e-6) - slack).max(along)
    }

    /// Sets the search axis (unit, first tooth's frame).
    fn set_axis(&mut self, axis: Vec3) {
        self.axis = axis;
        self.s.proj_a.begin(self.ba.nodes.len());
        self.s.proj_b.begin(self.bb.nodes.len());
    }

    /// Node `n`'s projection on the search axis: exact from the vertices for a leaf; otherwise
    /// from its slab and box (axis = α·normal + w: α times the slab plus the box on w).
    #[inline]
    fn proj(&mut self, n: u32, first: bool) -> (f32, f32) {
        let cached = if first {
            self.s.proj_a.has(n as usize)
        } else {
            self.s.proj_b.has(n as usize)
        };
        if cached {
            return if first {
                self.s.proj_a.get(n as usize, || (0.0, 0.0))
            } else {
                self.s.proj_b.get(n as usize, || (0.0, 0.0))
            };
        }
        let bvh = if first { self.ba } else { self.bb };
        let axis = self.axis;
        let p = if bvh.nodes[n as usize].is_leaf() {
            self.leaf_span(n, first, axis)
        } else {
            let (b, s) = if first {
                (self.ba.nodes[n as usize].aabb, self.ba.slabs[n as usize])
            } else {
                self.node_b(n)
            };
            let alpha = axis.dot(s.normal);
            let w = axis - alpha * s.normal;
            let (c, r) = (b.centre().dot(w), (b.extent() * 0.5).dot(w.abs()));
            let (p, q) = (alpha * s.lo, alpha * s.hi);
            (p.min(q) + c - r, p.max(q) + c + r)
        };
        if first {
            self.s.proj_a.get(n as usize, || p)
        } else {
            self.s.proj_b.get(n as usize, || p)
        }
    }

    /// Whether triangles `x` (first tooth, a candidate) and `y` (second) lie in a meeting leaf
    /// pair.
    #[inline]
    fn meet(&mut self, x: u32, y: u32) -> bool {
        let s = &mut *self.s;
        if !s.cand_b.has(y as usize) {
            return false;
        }
        let mut i = s.cand_a.get(x as usize, || u32::MAX);
        while i != u32::MAX {
            let (la, next) = s.links_a[i as usize];
            let mut j = s.cand_b.get(y as usize, || u32::MAX);
            while j != u32::MAX {
                let (lb, next_b) = s.links_b[j as usize];
                let bit = la as usize * s.leaves_b + lb as usize;
                if s.meets[bit / 64] >> (bit % 64) & 1 != 0 {
                    return true;
                }
                j = next_b;
            }
            i = next;
        }
        false
    }

    /// Calls `f(tx, ty, pair, lb, between)` for each pair of triangles of leaves `na` (first
    /// tooth) and `nb` (second) that lie in a meeting leaf pair: the placed triangles, their
    /// numbers, a lower bound of their distance (bounding spheres and projections on `axis`) and
    /// the distance between their centres. Stops when `f` returns false; returns whether every
    /// pair was seen.
    #[inline]
    fn leaf_pairs(
        &mut self,
        na: u32,
        nb: u32,
        axis: Vec3,
        mut f: impl FnMut(&PlacedTri, &PlacedTri, (u32, u32), f32, f32) -> bool,
    ) -> bool {
        let (ba, bb) = (self.ba, self.bb);
        let (x, y) = (&ba.nodes[na as usize], &bb.nodes[nb as usize]);
        for &i in ba.leaf_triangles(x) {
            if !self.s.cand_a.has(i as usize) {
                continue;
            }
            let tx = self.tri_a(i);
            for &j in bb.leaf_triangles(y) {
                if !self.meet(i, j) {
                    continue;
                }
                let ty = self.tri_b(j);
                let between = tx.centre.distance(ty.centre);
                let lb = (between - tx.radius - ty.radius).max(tx.axis_gap(&ty, axis));
                if !f(&tx, &ty, (i, j), lb, between) {
                    return false;
                }
            }
        }
        true
    }

    /// Child node pairs of (na, nb) that hold candidates on both sides (the larger node split).
    #[inline]
    fn children(&mut self, na: u32, nb: u32) -> [Option<(u32, u32)>; 2] {
        let (x, y) = (&self.ba.nodes[na as usize], &self.bb.nodes[nb as usize]);
        let split_a = !x.is_leaf()
            && (y.is_leaf()
                || x.aabb.extent().length_squared() >= y.aabb.extent().length_squared());
        if split_a {
            let l = x.start;
            [l, l + 1].map(|c| self.s.node_a.has(c as usize).then_some((c, nb)))
        } else {
            let l = y.start;
            [l, l + 1].map(|c| self.s.node_b.has(c as usize).then_some((na, c)))
        }
    }

    /// The least distance between the candidate triangles of the two teeth (first tooth's frame),
    /// searched nearest node pairs first and pruned by the best so far, which starts at the
    /// distance of `first` (the previous step's nearest pair): the distance, its points and pair.
    /// The search ends early at the first pair found within `enough` (that pair is returned).
    fn nearest(
        &mut self,
        first: Option<(u32, u32)>,
        axis: Vec3,
        enough: f32,
    ) -> (f32, Vec3, Vec3, (u32, u32)) {
        self.set_axis(axis);
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO, (0, 0));
        if let Some((x, y)) = first {
            let (tx, ty) = (self.tri_a(x), self.tri_b(y));
            let p = closest_points_facing_triangles(&tx.v, &ty.v);
            best = (p.distance, p.on_first, p.on_second, (x, y));
            if best.0 <= enough {
                return best;
            }
        }
        let mut stack = std::mem::take(&mut self.s.stack);
        stack.clear();
        if self.s.node_a.has(0) && self.s.node_b.has(0) {
            stack.push((0.0, 0, 0));
        }
        while let Some((lb, na, nb)) = stack.pop() {
            if lb >= best.0 {
                continue;
            }
            let (x, y) = (self.ba.nodes[na as usize], self.bb.nodes[nb as usize]);
            if x.is_leaf() && y.is_leaf() {
                let finished = self.leaf_pairs(na, nb, axis, |tx, ty, pair, lb, between| {
                    if lb >= best.0 || tx.gap_to(ty, between) >= best.0 {
                        return true;
                    }
                    let p = closest_points_facing_triangles(&tx.v, &ty.v);
                    if p.distance < best.0 {
                        best = (p.distance, p.on_first, p.on_second, pair);
                    }
                    best.0 > enough
                });
                if !finished {
                    stack.clear();
                    break;
                }
                continue;
            }
            let mut kids = [(f32::INFINITY, 0, 0); 2];
            for (k, c) in self.children(na, nb).into_iter().enumerate() {
                if let Some((ca, cb)) = c {
                    kids[k] = (self.node_gap(ca, cb, best.0), ca, cb);
                }
            }
            // The nearer pair is searched first (pushed last).
            if kids[0].0 < kids[1].0 {
                kids.swap(0, 1);
            }
            stack.extend(kids.into_iter().filter(|k| k.0 < best.0));
        }
        self.s.stack = stack;
        best
    }

    /// The longest step, from `plain` (every pair allows it) up to `step`, that every pair of
    /// candidate triangles allows: its own plain bound (distance less h, over μ) or its drift
    /// along the direction; node pairs whose boxes allow the step are not opened.
    fn step(&mut self, drift: &Drift, mu: f64, h: f64, plain: f64, mut step: f64) -> f64 {
        self.set_axis(drift.n);
        let mut stack = std::mem::take(&mut self.s.stack);
        stack.clear();
        if self.s.node_a.has(0) && self.s.node_b.has(0) {
            stack.push((0.0, 0, 0));
        }
        let allows = |d: f32| (d as f64 - h) / mu;
        while let Some((_, na, nb)) = stack.pop() {
            if step <= plain {
                break;
            }
            let (x, y) = (self.ba.nodes[na as usize], self.bb.nodes[nb as usize]);
            let own = allows(self.node_gap(na, nb, f32::INFINITY));
            let (pa, pb) = (self.proj(na, true), self.proj(nb, false));
            if own >= step || drift.step_nodes(pa, pb, &self.node_b(nb).0) >= step {
                continue;
            }
            if x.is_leaf() && y.is_leaf() {
                self.leaf_pairs(na, nb, drift.n, |tx, ty, _, lb, between| {
                    if allows(lb) >= step {
                        return true;
                    }
                    let along = drift.step(tx, ty);
                    if along >= step || allows(tx.gap_to(ty, between)) >= step {
                        return true;
                    }
                    let d = closest_points_facing_triangles(&tx.v, &ty.v).distance;
                    step = step.min(along.max(allows(d))).max(plain);
                    true
                });
                continue;
            }
            for (ca, cb) in self.children(na, nb).into_iter().flatten() {
                stack.push((0.0, ca, cb));
            }
        }
        self.s.stack = stack;
        step
    }
}

fn advance_with(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    tol: f64,
    scratch: &mut Scratch,
) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let (ma, mb) = (&ga.mesh, &gb.mesh);
    let (ba, bb) = (&ga.bvh, &gb.bvh);
    let t = swept
        .leaf_times
        .iter()
        .map(|x| x.2)
        .fold(f64::INFINITY, f64::min);
    // Candidate triangles of each side: those of the leaves in the meeting leaf pairs, each once;
    // the hierarchy nodes above them are marked (a node is searched only if it holds one).
    scratch.leaf_a.begin(ta.spheres.len());
    scratch.leaf_b.begin(tb.spheres.len());
    scratch.cand_a.begin(ma.triangles.len());
    scratch.cand_b.begin(mb.triangles.len());
    scratch.node_a.begin(ba.nodes.len());
    scratch.node_b.begin(bb.nodes.len());
    scratch.placed_a.begin(ma.triangles.len());
    let (mut ids_a, mut ids_b) = (Vec::new(), Vec::new());
    // Each candidate triangle keeps the list of its meeting leaves, so that only the triangle
    // pairs of meeting leaf pairs count (as in the flat advancement): two teeth resting within
    // the tolerance where their leaves do not meet are not a contact.
    scratch.links_a.clear();
    scratch.links_b.clear();
    let mut leaf_pairs = Vec::with_capacity(swept.leaf_times.len());
    let (mut count_a, mut count_b) = (0u32, 0u32);
    let list = |tree: &crate::collision::CompactTree,
                leaf: usize,
                leaves: &mut NodeCache<u32>,
                count: &mut u32,
                cand: &mut NodeCache<u32>,
                links: &mut Vec<(u32, u32)>,
                nodes: &mut NodeCache<bool>,
                bvh: &TriangleBvh,
                ids: &mut Vec<u32>| {
        if leaves.has(leaf) {
            return leaves.get(leaf, || 0);
        }
        let number = *count;
        *count += 1;
        leaves.set(leaf, number);
        for &x in tree.triangles(leaf) {
            let seen = cand.has(x as usize);
            let next = if seen {
                cand.get(x as usize, || 0)
            } else {
                u32::MAX
            };
            links.push((number, next));
            cand.set(x as usize, links.len() as u32 - 1);
            if seen {
                continue;
            }
            ids.push(x);
            let mut n = bvh.leaf_of[x as usize];
            while n != NO_PARENT && !nodes.has(n as usize) {
                nodes.get(n as usize, || true);
                n = bvh.parent[n as usize];
            }
        }
        number
    };
    for &(i, j, _) in &swept.leaf_times {
        let s = &mut *scratch;
        let x = list(
            ta,
            i as usize,
            &mut s.leaf_a,
            &mut count_a,
            &mut s.cand_a,
            &mut s.links_a,
            &mut s.node_a,
            ba,
            &mut ids_a,
        );
        let y = list(
            tb,
            j as usize,
            &mut s.leaf_b,
            &mut count_b,
            &mut s.cand_b,
            &mut s.links_b,
            &mut s.node_b,
            bb,
            &mut ids_b,
        );
        leaf_pairs.push((x, y));
    }
    let words = (count_a as usize * count_b as usize).div_ceil(64);
    scratch.meets.clear();
    scratch.meets.resize(words, 0);
    scratch.leaves_b = count_b as usize;
    for (x, y) in leaf_pairs {
        let bit = x as usize * count_b as usize + y as usize;
        scratch.meets[bit / 64] |= 1 << (bit % 64);
    }
    let speed = |motion: &Motion, mesh: &crate::geometry::TriMesh, ids: &[u32]| {
        motion.speed_bound_of(ids.iter().flat_map(|&t| mesh.triangle(t as usize)))
    };
    let mu = (speed(&a.motion, ma, &ids_a) + speed(&b.motion, mb, &ids_b)) * (1.0 + 1e-6);
    let start_rel = relative(&a.motion, &b.motion, t).rel;
    let axis = swept
        .leaf_times
        .iter()
        .map(|&(i, j, _)| {
            let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
            let c = start_rel.apply(sb.centre);
            (sa.centre.distance(c) - sa.radius - sb.radius, c - sa.centre)
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(Vec3::X, |(_, v)| v.normalize_or(Vec3::X));
    let ctx = Settle {
        a,
        b,
        swept,
        tol,
        mu,
    };
    let mut search = Search {
        ma,
        mb,
        ba,
        bb,
        s: scratch,
        rel: start_rel,
        axis: Vec3::X,
        last: None,
    };
    advance_over(&ctx, t, axis, [&ids_a, &ids_b], &mut search)
}
