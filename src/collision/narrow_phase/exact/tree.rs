//! The hierarchical advancement, for candidate sets too large to list pair by pair (teeth at
//! scan resolution): each tooth's candidate triangles form a patch with a hierarchy of its own
//! (`patch.rs`), and each step searches the two patches together (see the parent module).

use glam::{Mat3, Vec3};

use super::drift::Drift;
use super::patch::{Patch, PatchNode};
use super::{
    Aim, Candidates, Frame, MEETING_MM, PlacedTri, Settle, advance_over, marked, relative,
};
use crate::collision::CompactTree;
use crate::collision::motion::NodeCache;
use crate::collision::narrow_phase::lanes::Affine32;
use crate::collision::narrow_phase::{Body, PairContact, continuous};
use crate::geometry::{Aabb, Pose, Sphere, TriMesh, closest_points_facing_triangles};

/// Per-thread scratch of the advancement, reused between queries.
#[derive(Default)]
struct Scratch {
    /// The candidate patches of the two teeth.
    pa: Patch,
    pb: Patch,
    /// The meeting leaf pairs, one bit per (leaf of a, leaf of b) by their numbers.
    meets: Vec<u64>,
    /// When the second tooth has at most 64 meeting leaves: per candidate of the first tooth, a
    /// bit for each leaf of the second that one of its leaves meets; per candidate of the
    /// second, a bit for each of its own leaves (so a pair meets when the two share a bit).
    partners_a: Vec<u64>,
    own_b: Vec<u64>,
    masks: bool,
    /// Per meeting leaf of the first tooth, its partners' bits (while the masks are made).
    rows: Vec<u64>,
    /// Candidates placed in the first tooth's frame: the first's once per query, the second's
    /// once per step.
    placed_a: NodeCache<PlacedTri>,
    placed_b: NodeCache<PlacedTri>,
    stack: Vec<(f32, u32, u32)>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Conservative advancement over the bodies' whole motion through the candidate patches.
pub(super) fn advance(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    aim: Aim,
) -> Option<PairContact> {
    SCRATCH.with_borrow_mut(|scratch| advance_with(a, b, swept, aim, scratch))
}

/// The rotation taking the unit `n` to the third axis (rows: two axes across n, then n).
pub(super) fn frame_of(n: Vec3) -> Mat3 {
    let (u, v) = n.any_orthonormal_pair();
    Mat3::from_cols(u, v, n).transpose()
}

/// The two patches and the placed triangles: what one advancement step searches.
struct Search<'s, 'm> {
    ma: &'m TriMesh,
    mb: &'m TriMesh,
    /// Each candidate's mesh triangle, per tooth.
    ids: [&'m [u32]; 2],
    s: &'s mut Scratch,
    rel: Affine32,
    /// The search frame (first tooth's frame to it) and the axis each patch's boxes are framed
    /// on (`None` for the second after it moves).
    frame: Mat3,
    framed: [Option<Vec3>; 2],
    /// The nearest pair of the last search (candidate numbers), measured first in the next.
    last: Option<(u32, u32)>,
}

impl Candidates for Search<'_, '_> {
    fn place(&mut self, _t: f64, frame: &Frame) {
        self.s.placed_b.begin(self.ids[1].len());
        self.rel = frame.rel;
        self.framed[1] = None;
    }

    fn least(&mut self, axis: Vec3, enough: f32) -> Option<(f32, f32, Vec3, Vec3)> {
        let (d, qa, qb, pair) = self.nearest(self.last, axis, enough);
        self.last = Some(pair);
        // No pair left unmeasured is nearer than the pruning limit (less the rounding of
        // squaring it and of the square roots compared with it).
        let low = (d * (1.0 - NEAREST_SLACK)) * (1.0 - 1e-6);
        d.is_finite().then_some((d, low, qa, qb))
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

    fn touching(&mut self) -> Option<[Vec<u32>; 2]> {
        Some(self.meeting())
    }

    fn meeting_at(&mut self, frame: &Frame) -> Option<[Vec<u32>; 2]> {
        self.place(1.0, frame);
        // The first patch keeps its framing; only the second is refitted to its new placement.
        self.set_frame(self.framed[0].unwrap_or(Vec3::Z));
        Some(self.meeting())
    }
}

impl Search<'_, '_> {
    /// Candidate `x` of the first tooth, placed.
    #[inline]
    fn tri_a(&mut self, x: u32) -> PlacedTri {
        let (ma, id) = (self.ma, self.ids[0][x as usize]);
        *self
            .s
            .placed_a
            .get_ref(x as usize, || PlacedTri::new(ma.triangle(id as usize)))
    }

    /// Candidate `y` of the second tooth, placed in the first's frame.
    #[inline]
    fn tri_b(&mut self, y: u32) -> PlacedTri {
        let (mb, id, rel) = (self.mb, self.ids[1][y as usize], self.rel);
        *self.s.placed_b.get_ref(y as usize, || {
            PlacedTri::new(mb.triangle(id as usize).map(|v| rel.apply(v)))
        })
    }

    /// Frames both patches' boxes on the unit `axis` (first tooth's frame), refitting only what
    /// changed.
    fn set_frame(&mut self, axis: Vec3) {
        if self.framed == [Some(axis); 2] {
            return;
        }
        let r = frame_of(axis);
        self.frame = r;
        if self.framed[0] != Some(axis) {
            let map = Affine32 {
                m: r,
                t: Vec3::ZERO,
            };
            self.s.pa.refit(self.ma, &map);
        }
        if self.framed[1] != Some(axis) {
            let map = Affine32 {
                m: r * self.rel.m,
                t: r * self.rel.t,
            };
            self.s.pb.refit(self.mb, &map);
        }
        self.framed = [Some(axis); 2];
    }

    /// Whether candidates `x` (first tooth) and `y` (second) lie in a meeting leaf pair.
    #[inline]
    fn meet(&self, x: u32, y: u32) -> bool {
        if self.s.masks {
            let m = self.s.partners_a[x as usize] & self.s.own_b[y as usize] != 0;
            // The unit tests check the masks against the lists.
            if cfg!(test) {
                assert_eq!(m, self.meet_through_links(x, y), "pair ({x}, {y})");
            }
            return m;
        }
        self.meet_through_links(x, y)
    }

    /// [`Self::meet`] from the candidates' lists of leaves and the bit matrix of meeting leaf
    /// pairs.
    fn meet_through_links(&self, x: u32, y: u32) -> bool {
        let (pa, pb) = (&self.s.pa, &self.s.pb);
        let mut i = pa.heads[x as usize];
        while i != u32::MAX {
            let (la, next) = pa.links[i as usize];
            let mut j = pb.heads[y as usize];
            while j != u32::MAX {
                let (lb, next_b) = pb.links[j as usize];
                let bit = la as usize * pb.leaves as usize + lb as usize;
                if self.s.meets[bit / 64] >> (bit % 64) & 1 != 0 {
                    return true;
                }
                j = next_b;
            }
            i = next;
        }
        false
    }

    /// The nodes of both patches.
    #[inline]
    fn nodes(&self, na: u32, nb: u32) -> (PatchNode, PatchNode) {
        (self.s.pa.nodes[na as usize], self.s.pb.nodes[nb as usize])
    }

    /// The squared distance between the boxes of node `na` (first tooth) and `nb` (second).
    #[inline]
    fn gap2(&self, na: u32, nb: u32) -> f32 {
        self.s.pa.node_box[na as usize].distance_squared(&self.s.pb.node_box[nb as usize])
    }

    /// Child node pairs of (na, nb): both nodes split when both are inner (four pairs), else
    /// the inner one; the pairs and how many there are.
    #[inline]
    fn children(&self, na: u32, nb: u32) -> ([(u32, u32); 4], usize) {
        let (x, y) = self.nodes(na, nb);
        match (x.leaf, y.leaf) {
            (false, false) => ([(x.a, y.a), (x.a, y.b), (x.b, y.a), (x.b, y.b)], 4),
            (false, true) => ([(x.a, nb), (x.b, nb), (0, 0), (0, 0)], 2),
            _ => ([(na, y.a), (na, y.b), (0, 0), (0, 0)], 2),
        }
    }

    /// Calls `f(x, y)` for each pair of candidates of leaves `na` (first tooth) and `nb` (second)
    /// that lie in a meeting leaf pair and whose boxes pass `near(box x, box y)`; stops when `f`
    /// returns false and returns whether every pair was seen.
    #[inline]
    fn leaf_pairs(
        &mut self,
        na: u32,
        nb: u32,
        near: impl Fn(&Aabb, &Aabb) -> bool,
        mut f: impl FnMut(&mut Self, u32, u32) -> bool,
    ) -> bool {
        let (x, y) = self.nodes(na, nb);
        let whole_b = self.s.pb.node_box[nb as usize];
        for k in x.a..x.a + x.b {
            let i = self.s.pa.order[k as usize];
            let box_i = self.s.pa.tri_box[i as usize];
            if !near(&box_i, &whole_b) {
                continue;
            }
            for l in y.a..y.a + y.b {
                let j = self.s.pb.order[l as usize];
                if !near(&box_i, &self.s.pb.tri_box[j as usize]) || !self.meet(i, j) {
                    continue;
                }
                if !f(self, i, j) {
                    return false;
                }
            }
        }
        true
    }

    /// The least distance between the candidate triangles of the two teeth (first tooth's frame),
    /// searched nearest node pairs first on boxes framed on `axis` and pruned by the best so far,
    /// which starts at the distance of `first` (the previous step's nearest pair): the distance,
    /// its points and pair. The search ends early at the first pair found within `enough` (that
    /// pair is returned).
    ///
    /// Pruning is at [`NEAREST_SLACK`] below the best so far: what is left unmeasured is at least
    /// that far, which is all a step needs, and the search does not spend most of its node
    /// pairs proving that nothing is a little nearer. So the distance returned is the least
    /// within that fraction (exact when it is 0: a pair that meets has no gap to prune at).
    fn nearest(
        &mut self,
        first: Option<(u32, u32)>,
        axis: Vec3,
        enough: f32,
    ) -> (f32, Vec3, Vec3, (u32, u32)) {
        self.set_frame(axis);
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO, (0, 0));
        if let Some((x, y)) = first {
            let (tx, ty) = (self.tri_a(x), self.tri_b(y));
            let p = closest_points_facing_triangles(&tx.v, &ty.v);
            best = (p.distance, p.on_first, p.on_second, (x, y));
            if best.0 <= enough {
                return best;
            }
        }
        if self.s.pa.nodes.is_empty() || self.s.pb.nodes.is_empty() {
            return best;
        }
        let mut stack = std::mem::take(&mut self.s.stack);
        stack.clear();
        stack.push((0.0, 0, 0));
        // The pruning limit below the best so far, and its square (box distances are squared).
        let limit = |best: f32| best * (1.0 - NEAREST_SLACK);
        let limit2 = |best: f32| limit(best) * limit(best);
        while let Some((lb2, na, nb)) = stack.pop() {
            if lb2 >= limit2(best.0) {
                continue;
            }
            let (x, y) = self.nodes(na, nb);
            if x.leaf && y.leaf {
                let cut = std::cell::Cell::new(limit2(best.0));
                let finished = self.leaf_pairs(
                    na,
                    nb,
                    |p, q| p.distance_squared(q) < cut.get(),
                    |s, i, j| {
                        let (tx, ty) = (s.tri_a(i), s.tri_b(j));
                        if tx.gap_to(&ty, tx.centre.distance(ty.centre)) >= limit(best.0) {
                            return true;
                        }
                        let p = closest_points_facing_triangles(&tx.v, &ty.v);
                        if p.distance < best.0 {
                            best = (p.distance, p.on_first, p.on_second, (i, j));
                            cut.set(limit2(best.0));
                        }
                        best.0 > enough
                    },
                );
                if !finished {
                    break;
                }
                continue;
            }
            let (pairs, n) = self.children(na, nb);
            let mut kids = [(0.0, 0, 0); 4];
            for (k, &(ca, cb)) in pairs[..n].iter().enumerate() {
                kids[k] = (self.gap2(ca, cb), ca, cb);
            }
            // The nearest pair is searched first (pushed last).
            kids[..n].sort_unstable_by(|p, q| q.0.total_cmp(&p.0));
            stack.extend(kids[..n].iter().filter(|k| k.0 < limit2(best.0)));
        }
        self.s.stack = stack;
        best
    }

    /// The longest step, from `plain` (every pair allows it) up to `step`, that every pair of
    /// candidate triangles allows: its own plain bound (distance less h, over μ) or its drift
    /// along the direction; node pairs whose boxes (framed on the direction) allow the step are
    /// not opened.
    fn step(&mut self, drift: &Drift, mu: f64, h: f64, plain: f64, step: f64) -> f64 {
        self.set_frame(drift.n);
        let framed = drift.framed(self.frame);
        let allows = |d2: f32| (d2.sqrt() as f64 - h) / mu;
        let step = std::cell::Cell::new(step);
        // Whether boxes p (first tooth) and q (second) allow the step.
        let boxes_allow = |p: &Aabb, q: &Aabb| {
            allows(p.distance_squared(q)) >= step.get()
                || framed.step_nodes((p.min.z, p.max.z), (q.min.z, q.max.z), q) >= step.get()
        };
        let mut stack = std::mem::take(&mut self.s.stack);
        stack.clear();
        if !self.s.pa.nodes.is_empty() && !self.s.pb.nodes.is_empty() {
            stack.push((0.0, 0, 0));
        }
        while let Some((_, na, nb)) = stack.pop() {
            if step.get() <= plain {
                break;
            }
            let (pa, pb) = (
                self.s.pa.node_box[na as usize],
                self.s.pb.node_box[nb as usize],
            );
            if boxes_allow(&pa, &pb) {
                continue;
            }
            let (x, y) = self.nodes(na, nb);
            if x.leaf && y.leaf {
                self.leaf_pairs(
                    na,
                    nb,
                    |p, q| !boxes_allow(p, q),
                    |s, i, j| {
                        let (tx, ty) = (s.tri_a(i), s.tri_b(j));
                        let along = drift.step(&tx, &ty);
                        let gap = tx.gap_to(&ty, tx.centre.distance(ty.centre));
                        if along >= step.get() || allows(gap * gap) >= step.get() {
                            return true;
                        }
                        let d = closest_points_facing_triangles(&tx.v, &ty.v).distance;
                        step.set(step.get().min(along.max(allows(d * d))).max(plain));
                        step.get() > plain
                    },
                );
                continue;
            }
            let (pairs, n) = self.children(na, nb);
            stack.extend(pairs[..n].iter().map(|&(ca, cb)| (0.0, ca, cb)));
        }
        self.s.stack = stack;
        step.get()
    }
}

/// The fraction below the best distance so far at which [`Search::nearest`] prunes (its result
/// is the least distance within it). At most a quarter, so that a search finding no pair within
/// the tolerance leaves a lower bound above half of it (see `Settle::settle`).
pub(super) const NEAREST_SLACK: f32 = 0.02;

impl Search<'_, '_> {
    /// Every candidate of each tooth (mesh triangle numbers) with a candidate of the other whose
    /// box comes within [`MEETING_MM`] of its box and that neither triangle's plane puts more than
    /// that beyond it. That holds every pair that meets (a triangle wholly beyond the other's
    /// plane is at least that far from it), and a few that do not, which the walk allows: the
    /// planes are already placed, and the nine edge axes of a full separating-axis test cost
    /// more than the walk's extra starts. Found by descending the patches where their boxes (as
    /// last framed, which [`Self::least`] left at the current placement) overlap.
    fn meeting(&mut self) -> [Vec<u32>; 2] {
        let (na, nb) = (self.ids[0].len(), self.ids[1].len());
        let mut hit = [vec![false; na], vec![false; nb]];
        let mut stack = std::mem::take(&mut self.s.stack);
        stack.clear();
        if na > 0 && nb > 0 {
            stack.push((0.0, 0, 0));
        }
        let near = |p: &Aabb, q: &Aabb| p.distance_squared(q) <= MEETING_MM * MEETING_MM;
        while let Some((_, x, y)) = stack.pop() {
            if !near(
                &self.s.pa.node_box[x as usize],
                &self.s.pb.node_box[y as usize],
            ) {
                continue;
            }
            let (px, py) = self.nodes(x, y);
            if !(px.leaf && py.leaf) {
                let (pairs, n) = self.children(x, y);
                stack.extend(pairs[..n].iter().map(|&(ca, cb)| (0.0, ca, cb)));
                continue;
            }
            for k in px.a..px.a + px.b {
                let i = self.s.pa.order[k as usize];
                for l in py.a..py.a + py.b {
                    let j = self.s.pb.order[l as usize];
                    if (hit[0][i as usize] && hit[1][j as usize])
                        || !near(
                            &self.s.pa.tri_box[i as usize],
                            &self.s.pb.tri_box[j as usize],
                        )
                    {
                        continue;
                    }
                    let (tx, ty) = (self.tri_a(i), self.tri_b(j));
                    let m = MEETING_MM as f64;
                    if tx.plane.beyond(&ty.v) <= m && ty.plane.beyond(&tx.v) <= m {
                        hit[0][i as usize] = true;
                        hit[1][j as usize] = true;
                    }
                }
            }
        }
        self.s.stack = stack;
        [marked(&hit[0], self.ids[0]), marked(&hit[1], self.ids[1])]
    }
}

/// Lists each tooth's candidates from the meeting leaf pairs of `swept` (the motion searched from
/// `t`, the earliest leaf time) into the patches of `s`, builds their hierarchies and marks the
/// meeting leaf pairs.
fn list_candidates(a: &Body, b: &Body, swept: &continuous::SweptContact, t: f64, s: &mut Scratch) {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let (ma, mb) = (&ga.mesh, &gb.mesh);
    // Candidate triangles of each side: those of the leaves in the meeting leaf pairs, each once,
    // each keeping the list of its meeting leaves, so that only the triangle pairs of meeting
    // leaf pairs count (as in the flat advancement): two teeth resting within the tolerance where
    // their leaves do not meet are not a contact.
    //
    // A leaf's triangle can only touch the other tooth inside one of the other's leaves that
    // meets it (coverage invariant): so each leaf lists only its triangles whose bounding
    // spheres reach one of those leaves' spheres, swept over the rest of the motion. From the
    // middle of [t, 1] no point of either tooth moves more than half its speed bound times the
    // length, so each partner is placed there and grown by both teeth's travel (and far more than
    // the f32 rounding of the placement).
    s.pa.begin(ma, ta.spheres.len());
    s.pb.begin(mb, tb.spheres.len());
    let mid = relative(&a.motion, &b.motion, 0.5 * (t + 1.0));
    let (a_to_b, b_to_a) = (
        mid.pose_b.inverse().mul(&mid.pose_a),
        mid.pose_a.inverse().mul(&mid.pose_b),
    );
    let travel =
        a.motion.speed_bound(a.shape.max_rho as f64) + b.motion.speed_bound(b.shape.max_rho as f64);
    let grow = (0.5 * travel * (1.0 - t)) as f32 * (1.0 + 1e-4)
        + 1e-3
        + 1e-5 * (a.shape.max_rho + b.shape.max_rho + a_to_b.translation.length());
    let swept_sphere = |tree: &CompactTree, leaf: u32, map: &Pose| {
        let s = tree.spheres[leaf as usize];
        Sphere::new(map.transform_point(s.centre), s.radius + grow)
    };
    let mut near = Vec::new();
    let mut pairs: Vec<(u32, u32)> = swept.leaf_times.iter().map(|&(i, j, _)| (i, j)).collect();
    pairs.sort_unstable();
    for group in pairs.chunk_by(|x, y| x.0 == y.0) {
        near.clear();
        near.extend(group.iter().map(|p| swept_sphere(tb, p.1, &b_to_a)));
        s.pa.list_leaf(ta, group[0].0 as usize, &near, ma);
    }
    pairs.sort_unstable_by_key(|p| (p.1, p.0));
    for group in pairs.chunk_by(|x, y| x.1 == y.1) {
        near.clear();
        near.extend(group.iter().map(|p| swept_sphere(ta, p.0, &a_to_b)));
        s.pb.list_leaf(tb, group[0].1 as usize, &near, mb);
    }
    let leaf_pairs: Vec<(u32, u32)> = (swept.leaf_times.iter())
        .map(|&(i, j, _)| (s.pa.leaf_number(i as usize), s.pb.leaf_number(j as usize)))
        .collect();
    s.pa.build(&ga.bvh);
    s.pb.build(&gb.bvh);
    let leaves_b = s.pb.leaves as usize;
    s.meets.clear();
    s.meets
        .resize((s.pa.leaves as usize * leaves_b).div_ceil(64), 0);
    for &(x, y) in &leaf_pairs {
        let bit = x as usize * leaves_b + y as usize;
        s.meets[bit / 64] |= 1 << (bit % 64);
    }
    s.masks = leaves_b <= 64;
    if s.masks {
        // Each leaf of the first tooth's partners, then each candidate's through its leaves.
        let mut rows = std::mem::take(&mut s.rows);
        rows.clear();
        rows.resize(s.pa.leaves as usize, 0);
        for &(x, y) in &leaf_pairs {
            rows[x as usize] |= 1 << y;
        }
        let through = |patch: &Patch, c: usize, bit: &dyn Fn(u32) -> u64| {
            let mut m = 0;
            let mut i = patch.heads[c];
            while i != u32::MAX {
                let (leaf, next) = patch.links[i as usize];
                m |= bit(leaf);
                i = next;
            }
            m
        };
        s.partners_a.clear();
        s.partners_a
            .extend((0..s.pa.ids.len()).map(|c| through(&s.pa, c, &|leaf| rows[leaf as usize])));
        s.own_b.clear();
        s.own_b
            .extend((0..s.pb.ids.len()).map(|c| through(&s.pb, c, &|leaf| 1 << leaf)));
        s.rows = rows;
    }
}

/// The candidate triangles (mesh triangle numbers) the hierarchical search lists for the meeting
/// leaf pairs of `swept`, per tooth.
#[cfg(test)]
pub(super) fn candidates(a: &Body, b: &Body, swept: &continuous::SweptContact) -> [Vec<u32>; 2] {
    let t = swept.earliest();
    SCRATCH.with_borrow_mut(|s| {
        list_candidates(a, b, swept, t, s);
        [s.pa.ids.clone(), s.pb.ids.clone()]
    })
}

/// At the earliest leaf time of `swept`, the first step's search over the listed candidates:
/// its gap and lower bound ([`Candidates::least`]), and the least distance of every candidate
/// pair in a meeting leaf pair, measured one by one.
#[cfg(test)]
pub(super) fn least_at_start(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
) -> Option<(f32, f32, f32)> {
    let t = swept.earliest();
    SCRATCH.with_borrow_mut(|s| {
        list_candidates(a, b, swept, t, s);
        let (ids_a, ids_b) = (std::mem::take(&mut s.pa.ids), std::mem::take(&mut s.pb.ids));
        s.placed_a.begin(ids_a.len());
        let frame = relative(&a.motion, &b.motion, t);
        let mut search = Search {
            ma: &a.shape.geometry.mesh,
            mb: &b.shape.geometry.mesh,
            ids: [&ids_a, &ids_b],
            s,
            rel: frame.rel,
            frame: Mat3::IDENTITY,
            framed: [None; 2],
            last: None,
        };
        search.place(t, &frame);
        let (d, low, _, _) = search.least(Vec3::X, -1.0)?;
        let mut least = f32::INFINITY;
        for x in 0..ids_a.len() as u32 {
            for y in 0..ids_b.len() as u32 {
                if search.meet(x, y) {
                    let (tx, ty) = (search.tri_a(x), search.tri_b(y));
                    least = least.min(closest_points_facing_triangles(&tx.v, &ty.v).distance);
                }
            }
        }
        (s.pa.ids, s.pb.ids) = (ids_a, ids_b);
        Some((d, low, least))
    })
}

fn advance_with(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    aim: Aim,
    s: &mut Scratch,
) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let (ma, mb) = (&ga.mesh, &gb.mesh);
    let t = swept.earliest();
    list_candidates(a, b, swept, t, s);
    let speed = |motion: &crate::collision::Motion, mesh: &TriMesh, patch: &Patch| {
        motion.speed_bound_of(
            patch
                .vertex_ids()
                .iter()
                .map(|&v| mesh.vertices[v as usize]),
        )
    };
    let mu = (speed(&a.motion, ma, &s.pa) + speed(&b.motion, mb, &s.pb)) * (1.0 + 1e-6);
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
        aim,
        mu,
    };
    // The candidates' triangle numbers are lent to the search (and the report) and put back.
    let (ids_a, ids_b) = (std::mem::take(&mut s.pa.ids), std::mem::take(&mut s.pb.ids));
    s.placed_a.begin(ids_a.len());
    let mut search = Search {
        ma,
        mb,
        ids: [&ids_a, &ids_b],
        s,
        rel: start_rel,
        frame: Mat3::IDENTITY,
        framed: [None; 2],
        last: None,
    };
    let contact = advance_over(&ctx, t, axis, [&ids_a, &ids_b], &mut search);
    (s.pa.ids, s.pb.ids) = (ids_a, ids_b);
    contact
}
