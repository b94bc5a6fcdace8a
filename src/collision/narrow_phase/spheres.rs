//! Discrete sphere trees: simultaneous descent of both trees at the end pose, collecting every
//! overlapping leaf pair. Conservative at that pose: surfaces that touch lie in overlapping leaves
//! (the coverage invariant), and node tests allow for rounding (see [`super::lanes`]).
//!
//! The descent runs in the first tooth's local frame: its spheres are used as stored and only the
//! second tooth's are mapped, a group of siblings at a time and once per query.

use glam::{DVec3, Vec3};

use super::{
    Body, PairContact,
    lanes::{Affine32, bits, f32_slack, overlap_mask},
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

/// Calls `leaf(i, j, depth)` for every overlapping leaf pair of the two trees at the given poses,
/// with the pair's overlap (sum of radii minus centre distance; negative within the slack).
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
        cache.begin(tb.chunks.len());
        stack.clear();
        let root_b = cache.get_ref(0, || rel.apply_chunk(&tb.chunks[0]));
        let (sa, sb) = (&ta.spheres[0], &tb.spheres[0]);
        let b = Vec3::new(root_b[0][0], root_b[1][0], root_b[2][0]);
        let a_root = [
            [sa.centre.x; LANES],
            [sa.centre.y; LANES],
            [sa.centre.z; LANES],
        ];
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
        if overlap_mask(xyz3(&a_root), &[sa.radius; LANES], b, sb.radius, slack, 1) != 0 {
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
        };
        while let Some(it) = stack.pop() {
            if it.leaf_a {
                second.split(&it, cache, |child| emit(child, stack));
                continue;
            }
            // Split a; when b is inner too, split b under each of a's children that meets it.
            for c in ta.child_chunks[it.i as usize].clone() {
                let ch = &ta.chunks[c as usize];
                let xyz = [&ch.x, &ch.y, &ch.z];
                for k in bits(overlap_mask(xyz, &ch.r, it.b, it.rb, slack, ch.used())) {
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
    });
}

/// The second tree, mapped into the first tree's frame.
struct Second<'t> {
    tree: &'t CompactTree,
    rel: Affine32,
    slack: f32,
}

impl Second<'_> {
    /// Calls `emit` with `base` paired with each child of its second-tree node that meets its
    /// first-tree sphere (children mapped once per query, in `cache`).
    #[inline]
    fn split(
        &self,
        base: &Item,
        cache: &mut NodeCache<[[f32; LANES]; 3]>,
        mut emit: impl FnMut(Item),
    ) {
        for c in self.tree.child_chunks[base.j as usize].clone() {
            let ch = &self.tree.chunks[c as usize];
            let xyz = cache.get_ref(c as usize, || self.rel.apply_chunk(ch));
            let mask = overlap_mask(xyz3(xyz), &ch.r, base.a, base.ra, self.slack, ch.used());
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
    })
}
