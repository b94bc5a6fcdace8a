//! The flat advancement: every candidate triangle pair listed once, each carrying its last
//! distance as a bound (see the parent module). Fastest when the candidates are few, as at the
//! paper's resolution.

use glam::Vec3;

use super::drift::Drift;
use super::{
    Aim, Candidates, Frame, MEETING_MM, PlacedTri, Settle, advance_over, marked, relative,
};
use crate::collision::motion::{Motion, NodeCache};
use crate::collision::narrow_phase::Body;
use crate::collision::narrow_phase::lanes::Affine32;
use crate::collision::narrow_phase::{PairContact, continuous};
use crate::geometry::closest_points_facing_triangles;

/// Allowance (mm) for the f32 rounding of a stored triangle-pair distance and of the poses it was
/// measured at, far above either, when it is carried forward as a bound.
const LIPSCHITZ_SLACK_MM: f64 = 1e-4;

/// Per-thread scratch of the advancement: each mesh triangle's index among the candidates, the
/// triangle pairs already listed (one bit per pair of candidates) and the candidate pairs.
#[derive(Default)]
struct Scratch {
    slot_a: NodeCache<u32>,
    slot_b: NodeCache<u32>,
    leaf_a: NodeCache<(u32, u32)>,
    leaf_b: NodeCache<(u32, u32)>,
    local_a: Vec<u32>,
    local_b: Vec<u32>,
    listed: Vec<u64>,
    candidates: Vec<Candidate>,
}

/// A candidate triangle pair (indices among the candidate triangles of each side) and its last
/// measured distance or lower bound `d` with the time `t` of it (−∞ before the first look).
#[derive(Clone, Copy)]
struct Candidate {
    x: u32,
    y: u32,
    d: f32,
    t: f64,
}

/// Candidate lists up to this many entries (and listed-pair bit sets up to this many words) are
/// kept per thread between queries.
const KEEP_CANDIDATES: usize = 1 << 16;

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Conservative advancement over the bodies' whole motion with flat candidate lists.
pub(super) fn advance(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    aim: Aim,
) -> Option<PairContact> {
    SCRATCH.with_borrow_mut(|scratch| {
        let contact = advance_with(a, b, swept, aim, scratch);
        // Lists of deep contacts between large meshes are not kept.
        if scratch.candidates.capacity() > KEEP_CANDIDATES {
            scratch.candidates = Vec::new();
        }
        if scratch.listed.capacity() > KEEP_CANDIDATES {
            scratch.listed = Vec::new();
        }
        contact
    })
}

fn advance_with(
    a: &Body,
    b: &Body,
    swept: &continuous::SweptContact,
    aim: Aim,
    scratch: &mut Scratch,
) -> Option<PairContact> {
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let (ma, mb) = (&a.shape.geometry.mesh, &b.shape.geometry.mesh);
    let Scratch {
        slot_a,
        slot_b,
        leaf_a,
        leaf_b,
        local_a,
        local_b,
        listed,
        candidates,
    } = scratch;
    let t = swept.earliest();
    // Leaf pairs nearest first at the start, so that the first triangle pairs measured are near
    // ones and the bounds cull the rest.
    let start_rel = relative(&a.motion, &b.motion, t).rel;
    let mut order: Vec<(f32, usize)> = swept
        .leaf_times
        .iter()
        .enumerate()
        .map(|(k, &(i, j, _))| {
            let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
            let gap = sa.centre.distance(start_rel.apply(sb.centre)) - sa.radius - sb.radius;
            (gap, k)
        })
        .collect();
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    // Candidate triangles of each side (ids_a / ids_b), numbered in order of first use; each
    // leaf's triangles as those numbers, once per leaf (leaves recur in many leaf pairs), in
    // `local_a` / `local_b` at the span its cache holds.
    slot_a.begin(ma.triangles.len());
    slot_b.begin(mb.triangles.len());
    leaf_a.begin(ta.spheres.len());
    leaf_b.begin(tb.spheres.len());
    let (mut ids_a, mut ids_b) = (Vec::new(), Vec::new());
    local_a.clear();
    local_b.clear();
    let number = |tree: &crate::collision::CompactTree,
                  leaf: usize,
                  slot: &mut NodeCache<u32>,
                  ids: &mut Vec<u32>,
                  local: &mut Vec<u32>| {
        let at = local.len();
        for &x in tree.triangles(leaf) {
            local.push(slot.get(x as usize, || {
                ids.push(x);
                ids.len() as u32 - 1
            }));
        }
        (at as u32, local.len() as u32)
    };
    let mut spans: Vec<((u32, u32), (u32, u32))> = Vec::with_capacity(order.len());
    for &(_, k) in &order {
        let (i, j, _) = swept.leaf_times[k];
        let xs = leaf_a.get(i as usize, || {
            number(ta, i as usize, slot_a, &mut ids_a, local_a)
        });
        let ys = leaf_b.get(j as usize, || {
            number(tb, j as usize, slot_b, &mut ids_b, local_b)
        });
        spans.push((xs, ys));
    }
    // Candidate triangle pairs, each once (leaf pairs share triangles): marked in a bit matrix
    // (a row of b's numbers for each of a's), then listed row by row; near leaf pairs' triangles
    // have the low numbers, so they come first. Rows of up to 64 take one word per leaf pair and
    // triangle of a.
    let (nx, ny) = (ids_a.len(), ids_b.len());
    let row_words = ny.div_ceil(64);
    let words = nx * row_words;
    if listed.len() < words {
        listed.resize(words, 0);
    }
    listed[..words].fill(0);
    for &((x0, x1), (y0, y1)) in &spans {
        let (xs, ys) = (
            &local_a[x0 as usize..x1 as usize],
            &local_b[y0 as usize..y1 as usize],
        );
        if row_words == 1 {
            let mask = ys.iter().fold(0u64, |m, &yi| m | 1 << yi);
            for &xi in xs {
                listed[xi as usize] |= mask;
            }
        } else {
            for &xi in xs {
                let row = &mut listed[xi as usize * row_words..][..row_words];
                for &yi in ys {
                    row[yi as usize / 64] |= 1u64 << (yi % 64);
                }
            }
        }
    }
    candidates.clear();
    for (w, &word) in listed[..words].iter().enumerate() {
        let (xi, base) = (w / row_words, (w % row_words) * 64);
        let mut bits = word;
        while bits != 0 {
            let yi = base + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            candidates.push(Candidate {
                x: xi as u32,
                y: yi as u32,
                d: f32::NEG_INFINITY,
                t,
            });
        }
    }
    let speed = |motion: &Motion, mesh: &crate::geometry::TriMesh, ids: &[u32]| {
        motion.speed_bound_of(ids.iter().flat_map(|&t| mesh.triangle(t as usize)))
    };
    let mu = (speed(&a.motion, ma, &ids_a) + speed(&b.motion, mb, &ids_b)) * (1.0 + 1e-6);
    let tris_a: Vec<PlacedTri> = ids_a.iter().map(|&x| place(ma, x, None)).collect();
    // The direction between the closest points of the previous step's nearest pair (a's frame):
    // projections on it bound most pairs near the contact. Before the first step, the direction
    // between the nearest leaf pair's centres.
    let axis = order.first().map_or(Vec3::X, |&(_, k)| {
        let (i, j, _) = swept.leaf_times[k];
        let (sa, sb) = (ta.spheres[i as usize], tb.spheres[j as usize]);
        (start_rel.apply(sb.centre) - sa.centre).normalize_or(Vec3::X)
    });
    let ctx = Settle {
        a,
        b,
        swept,
        aim,
        mu,
    };
    let mut search = Flat {
        tris_a,
        tris_b: Vec::with_capacity(ids_b.len()),
        ids_a: &ids_a,
        ids_b: &ids_b,
        mb,
        candidates,
        nearest: None,
        t,
        mu,
    };
    advance_over(&ctx, t, axis, [&ids_a, &ids_b], &mut search)
}

/// The first tooth's candidate triangle `id` as stored, or the second's mapped by `map`.
fn place(mesh: &crate::geometry::TriMesh, id: u32, map: Option<&Affine32>) -> PlacedTri {
    let [p, q, r] = mesh.triangle(id as usize);
    PlacedTri::new(match map {
        Some(m) => [m.apply(p), m.apply(q), m.apply(r)],
        None => [p, q, r],
    })
}

/// The flat search: every candidate pair looked at in each step.
struct Flat<'x> {
    /// The first tooth's candidate triangles as stored, the second's placed anew each step.
    tris_a: Vec<PlacedTri>,
    tris_b: Vec<PlacedTri>,
    /// Their mesh triangle numbers.
    ids_a: &'x [u32],
    ids_b: &'x [u32],
    mb: &'x crate::geometry::TriMesh,
    candidates: &'x mut Vec<Candidate>,
    /// The nearest pair of the previous step, measured first in the next.
    nearest: Option<usize>,
    /// The current time and the bound on the closing speed.
    t: f64,
    mu: f64,
}

impl Candidates for Flat<'_> {
    fn place(&mut self, t: f64, frame: &Frame) {
        self.t = t;
        let (mb, rel) = (self.mb, frame.rel);
        self.tris_b.clear();
        self.tris_b
            .extend(self.ids_b.iter().map(|&y| place(mb, y, Some(&rel))));
    }

    fn least(&mut self, axis: Vec3, _enough: f32) -> Option<(f32, f32, Vec3, Vec3)> {
        let (t, mu) = (self.t, self.mu);
        let (tris_a, tris_b) = (&self.tris_a, &self.tris_b);
        let mut best = (f32::INFINITY, Vec3::ZERO, Vec3::ZERO);
        let mut best_k = None;
        // No pair's distance shrinks faster than μ, so its last distance d, measured at t₀,
        // bounds it now by d − μ·(t − t₀): pairs that cannot beat the best are not measured.
        let mut look = |k: usize, c: &mut Candidate| {
            if c.d as f64 - mu * (t - c.t) - LIPSCHITZ_SLACK_MM >= best.0 as f64 {
                return;
            }
            c.t = t;
            let (tx, ty) = (&tris_a[c.x as usize], &tris_b[c.y as usize]);
            let between = tx.centre.distance(ty.centre);
            let lb = (between - tx.radius - ty.radius).max(tx.axis_gap(ty, axis));
            if lb >= best.0 {
                c.d = lb.max(0.0);
                return;
            }
            // Facing triangles: the plane gap is nearly the distance and far cheaper.
            let lb = tx.gap_to(ty, between);
            if lb >= best.0 {
                c.d = lb;
                return;
            }
            // The pairs measured are the nearest candidates, mostly facing each other.
            let p = closest_points_facing_triangles(&tx.v, &ty.v);
            c.d = p.distance;
            if p.distance < best.0 {
                best = (p.distance, p.on_first, p.on_second);
                best_k = Some(k);
            }
        };
        if self.nearest.is_none() {
            // First step: the pair whose bounding spheres are nearest is measured first.
            self.nearest = self
                .candidates
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let (tx, ty) = (&tris_a[c.x as usize], &tris_b[c.y as usize]);
                    (tx.centre.distance_squared(ty.centre), k)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .map(|x| x.1);
        }
        let nearest = self.nearest;
        if let Some(k) = nearest {
            look(k, &mut self.candidates[k]);
        }
        for (k, c) in self.candidates.iter_mut().enumerate() {
            if Some(k) != nearest {
                look(k, c);
            }
        }
        self.nearest = best_k;
        let (d, qa, qb) = best;
        d.is_finite().then_some((d, d, qa, qb))
    }

    fn nearest_drift(&mut self, drift: &Drift) -> f64 {
        self.nearest.map_or(0.0, |k| {
            let c = &self.candidates[k];
            drift.step(&self.tris_a[c.x as usize], &self.tris_b[c.y as usize])
        })
    }

    /// Every candidate in a candidate pair that two lower bounds of its distance (bounding
    /// spheres, planes) do not put more than [`MEETING_MM`] apart at the placement: every pair
    /// that meets there among them.
    fn meeting_at(&mut self, frame: &Frame) -> Option<[Vec<u32>; 2]> {
        self.place(1.0, frame);
        let mut hit = [vec![false; self.ids_a.len()], vec![false; self.ids_b.len()]];
        for c in self.candidates.iter() {
            let (x, y) = (c.x as usize, c.y as usize);
            let (tx, ty) = (&self.tris_a[x], &self.tris_b[y]);
            let between = tx.centre.distance(ty.centre);
            if between - tx.radius - ty.radius <= MEETING_MM && tx.gap_to(ty, between) <= MEETING_MM
            {
                hit[0][x] = true;
                hit[1][y] = true;
            }
        }
        Some([marked(&hit[0], self.ids_a), marked(&hit[1], self.ids_b)])
    }

    fn extend(&mut self, drift: &Drift, mu: f64, h: f64, plain: f64, first: f64) -> f64 {
        let mut step = first;
        for c in self.candidates.iter() {
            if step <= plain {
                break;
            }
            // Pairs whose own distance bound already allows the step need no more.
            let bound = c.d as f64 - mu * (self.t - c.t) - LIPSCHITZ_SLACK_MM;
            if bound - h >= mu * step {
                continue;
            }
            let own = drift.step(&self.tris_a[c.x as usize], &self.tris_b[c.y as usize]);
            step = step.min(own.max((bound - h) / mu)).max(plain);
        }
        step
    }
}
