//! Discrete sphere trees: simultaneous descent of both trees at the end pose, collecting every
//! overlapping leaf pair. Conservative at that pose: surfaces that touch lie in overlapping leaves
//! (the coverage invariant), and node tests allow for rounding (see `super::lanes`).
//!
//! The descent runs in the first tooth's local frame: its spheres are used as stored and only the
//! second tooth's are mapped, a group of siblings at a time and once per query.
//!
//! **Pruning.** A node pair (A, B) with inner nodes on both sides is split into the pairs of their
//! children that meet, keeping only children of A that meet B and children of B that meet A. That
//! is safe: a surface point where the teeth touch lies in a leaf of each tree and, by the coverage
//! invariant, in every ancestor of either leaf, so every pair of those ancestors meets. The
//! children are tested all against all, 8 × 8 lanes in eight vector tests without branches (see
//! `Lanes::block`), which costs less than testing only the candidates one by one.

use glam::{DVec3, Vec3};

use super::{
    Body, PairContact,
    lanes::{self, Affine32, LaneTask, Lanes, bits, f32_slack},
};
use crate::collision::{
    motion::{DPose, NodeCache},
    shape::{CompactTree, LANES},
};

/// A node pair on the descent stack: nodes, centres (first tooth's frame) and radii.
#[derive(Clone, Copy)]
struct Item {
    i: u32,
    j: u32,
    leaf_a: bool,
    leaf_b: bool,
    a: Vec3,
    ra: f32,
    b: Vec3,
    rb: f32,
}

/// Calls `leaf(i, j, depth)` for every overlapping leaf pair of the two trees at the given poses
/// (after the pruning of the module doc), with the pair's overlap (sum of radii minus centre
/// distance; negative within the slack).
pub fn overlapping_leaves(
    ta: &CompactTree,
    pa: &DPose,
    tb: &CompactTree,
    pb: &DPose,
    mut leaf: impl FnMut(usize, usize, f32),
) {
    if ta.is_empty() || tb.is_empty() {
        return;
    }
    // b in a's frame: pa⁻¹ ∘ pb.
    let inv = pa.rotation.inverse();
    let rel = Affine32::new(inv * pb.rotation, inv * (pb.translation - pa.translation));
    let slack = f32_slack(ta.max_rho + tb.max_rho + rel.reach());
    CACHE.with_borrow_mut(|(cache, stack)| {
        lanes::run(Descent {
            ta,
            tb,
            rel,
            slack,
            cache,
            stack,
            leaf: &mut leaf,
        });
    });
}

/// One query's descent.
struct Descent<'q, F> {
    ta: &'q CompactTree,
    tb: &'q CompactTree,
    /// The second tree's frame in the first's.
    rel: Affine32,
    slack: f32,
    /// The second tree's chunks, mapped on first use.
    cache: &'q mut NodeCache<[[f32; LANES]; 3]>,
    stack: &'q mut Vec<Item>,
    leaf: &'q mut F,
}

impl<F: FnMut(usize, usize, f32)> LaneTask for Descent<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) {
        let Descent {
            ta,
            tb,
            rel,
            slack,
            cache,
            stack,
            leaf,
        } = self;
        cache.begin(tb.chunks.len());
        stack.clear();
        // Leaf pairs are reported as they are found; only pairs with an inner node are stacked.
        let mut emit = |it: Item, stack: &mut Vec<Item>| {
            if it.leaf_a && it.leaf_b {
                leaf(
                    it.i as usize,
                    it.j as usize,
                    it.ra + it.rb - it.a.distance(it.b),
                );
            } else {
                stack.push(it);
            }
        };
        let root_b = cache.get_ref(0, || rel.apply_chunk(&tb.chunks[0]));
        let (sa, sb) = (&ta.spheres[0], &tb.spheres[0]);
        let b = Vec3::new(root_b[0][0], root_b[1][0], root_b[2][0]);
        let a_root = [
            [sa.centre.x; LANES],
            [sa.centre.y; LANES],
            [sa.centre.z; LANES],
        ];
        if lanes.overlap_mask(xyz3(&a_root), &[sa.radius; LANES], b, sb.radius, slack, 1) != 0 {
            emit(
                Item {
                    i: 0,
                    j: 0,
                    leaf_a: ta.is_leaf(0),
                    leaf_b: tb.is_leaf(0),
                    a: sa.centre,
                    ra: sa.radius,
                    b,
                    rb: sb.radius,
                },
                stack,
            );
        }
        let second = Second {
            tree: tb,
            rel,
            slack,
            lanes,
        };
        while let Some(it) = stack.pop() {
            if it.leaf_a {
                second.split(&it, cache, |child| emit(child, stack));
                continue;
            }
            let (rca, rcb) = (
                ta.child_chunks[it.i as usize].clone(),
                tb.child_chunks[it.j as usize].clone(),
            );
            if !it.leaf_b && rca.len() == 1 && rcb.len() == 1 {
                // Both inner with up to eight children each: all pairs of children at once.
                let ca = &ta.chunks[rca.start as usize];
                let cb = &tb.chunks[rcb.start as usize];
                let xb = cache.get_ref(rcb.start as usize, || rel.apply_chunk(cb));
                let xa = [&ca.x, &ca.y, &ca.z];
                let ma = lanes.overlap_mask(xa, &ca.r, it.b, it.rb, slack, ca.used());
                let mb = lanes.overlap_mask(xyz3(xb), &cb.r, it.a, it.ra, slack, cb.used());
                let block = lanes.block(ca, xyz3(xb), &cb.r, slack, mb);
                for k in bits(block.any & ma) {
                    let a = Vec3::new(ca.x[k], ca.y[k], ca.z[k]);
                    for l in bits(block.rows[k]) {
                        emit(
                            Item {
                                i: ca.node[k],
                                j: cb.node[l],
                                leaf_a: ca.leaves >> k & 1 != 0,
                                leaf_b: cb.leaves >> l & 1 != 0,
                                a,
                                ra: ca.r[k],
                                b: Vec3::new(xb[0][l], xb[1][l], xb[2][l]),
                                rb: cb.r[l],
                            },
                            stack,
                        );
                    }
                }
                continue;
            }
            // Split a; when b is inner too, split b under each of a's children that meets it.
            for c in rca {
                let ch = &ta.chunks[c as usize];
                let xyz = [&ch.x, &ch.y, &ch.z];
                for k in bits(lanes.overlap_mask(xyz, &ch.r, it.b, it.rb, slack, ch.used())) {
                    let child = Item {
                        i: ch.node[k],
                        a: Vec3::new(ch.x[k], ch.y[k], ch.z[k]),
                        ra: ch.r[k],
                        leaf_a: ch.leaves >> k & 1 != 0,
                        ..it
                    };
                    if it.leaf_b {
                        emit(child, stack);
                    } else {
                        second.split(&child, cache, |grandchild| emit(grandchild, stack));
                    }
                }
            }
        }
    }
}

/// The second tree, mapped into the first tree's frame.
struct Second<'t, L> {
    tree: &'t CompactTree,
    rel: Affine32,
    slack: f32,
    lanes: L,
}

impl<L: Lanes> Second<'_, L> {
    /// Calls `emit` with `base` paired with each child of its second-tree node that meets its
    /// first-tree sphere (children mapped once per query, in `cache`).
    #[inline(always)]
    fn split(
        &self,
        base: &Item,
        cache: &mut NodeCache<[[f32; LANES]; 3]>,
        mut emit: impl FnMut(Item),
    ) {
        for c in self.tree.child_chunks[base.j as usize].clone() {
            let ch = &self.tree.chunks[c as usize];
            let xyz = cache.get_ref(c as usize, || self.rel.apply_chunk(ch));
            let mask =
                self.lanes
                    .overlap_mask(xyz3(xyz), &ch.r, base.a, base.ra, self.slack, ch.used());
            for k in bits(mask) {
                emit(Item {
                    j: ch.node[k],
                    b: Vec3::new(xyz[0][k], xyz[1][k], xyz[2][k]),
                    rb: ch.r[k],
                    leaf_b: ch.leaves >> k & 1 != 0,
                    ..*base
                });
            }
        }
    }
}

#[inline]
fn xyz3(v: &[[f32; LANES]; 3]) -> [&[f32; LANES]; 3] {
    [&v[0], &v[1], &v[2]]
}

type Scratch = (NodeCache<[[f32; LANES]; 3]>, Vec<Item>);

thread_local! {
    /// The leaf pairs of a query, copied out once at their final length.
    static PAIRS: std::cell::RefCell<Vec<(u32, u32)>> = const { std::cell::RefCell::new(Vec::new()) };
    static CACHE: std::cell::RefCell<Scratch> =
        const { std::cell::RefCell::new((NodeCache::new(), Vec::new())) };
}

/// Overlapping leaves at the end pose; the contact is reported at the deepest leaf pair.
pub fn query(a: &Body, b: &Body) -> Option<PairContact> {
    let (pa, pb) = (
        DPose::from_pose(&a.motion.end),
        DPose::from_pose(&b.motion.end),
    );
    let (ta, tb) = (&*a.shape.tree, &*b.shape.tree);
    let mut deepest: Option<(f32, usize, usize)> = None;
    let pairs = PAIRS.with_borrow_mut(|pairs| {
        pairs.clear();
        overlapping_leaves(ta, &pa, tb, &pb, |i, j, depth| {
            pairs.push((i as u32, j as u32));
            if deepest.is_none_or(|d| depth > d.0) {
                deepest = Some((depth, i, j));
            }
        });
        pairs.to_vec()
    });
    let (_, i, j) = deepest?;
    let (ca, cb) = (
        pa.apply(ta.spheres[i].centre),
        pb.apply(tb.spheres[j].centre),
    );
    let (ra, rb) = (ta.spheres[i].radius as f64, tb.spheres[j].radius as f64);
    let depth = ra + rb - ca.distance(cb);
    let n = (cb - ca).try_normalize().unwrap_or(DVec3::X);
    Some(PairContact {
        time_of_contact: 1.0,
        points: [(ca + n * ra).as_vec3(), (cb - n * rb).as_vec3()],
        normal: n.as_vec3(),
        depth_mm: depth as f32,
        leaf_pairs: pairs,
        end_overlap: None,
    })
}
