//! One tooth's candidate triangles as a hierarchy of their own, for the hierarchical search
//! (`tree.rs`): the part of the tooth's triangle hierarchy above the candidates, with chains of
//! single children collapsed, and boxes refitted to the candidates alone in the search frame.
//!
//! Why refit: the stored hierarchy's boxes and slabs cover every triangle of a node and lie in
//! the mesh's axes, so near a contact, where both surfaces curve across the closest direction,
//! they overlap far more than the triangles do. Boxes of only the candidate triangles, in a frame
//! whose third axis is the closest direction, are as tight as axis-aligned boxes can be there:
//! thin along the direction and exact in the other two. The candidates are a patch of a few
//! hundred triangles, so refitting every box costs one map of the patch's vertices and one pass
//! over its nodes. Nodes of a dozen candidates or fewer are leaves ([`LEAF_CANDIDATES`]): the
//! search tests their triangles' boxes pair by pair instead of opening more node pairs.
//!
//! Rounding: each vertex is mapped in f32 (to within about 1.2·10⁻⁶ of its distance from the
//! frame's origin plus the map's translation), and every box is widened by [`Patch::pad`], an
//! absolute 10⁻⁵ mm plus a relative 4·10⁻⁶ of those sizes, so a box holds its triangles' exact
//! images and box distances never exceed the triangles' distances.

use glam::Vec3;

use crate::collision::CompactTree;
use crate::collision::motion::NodeCache;
use crate::collision::narrow_phase::lanes::Affine32;
use crate::geometry::{Aabb, Sphere, TriMesh, TriangleBvh};

/// Most candidates of a patch node that is made a leaf rather than split further. The stored
/// hierarchy's leaves hold up to 4 triangles, of which a patch keeps about 2.3 on average: a
/// search through such small leaves spends more on opening node pairs than on the triangle
/// boxes it would skip. Measured on the 300 near-contact steps at scan resolution (exact stage
/// looped, 4 interleaved runs): 8, 12 and 16 all beat splitting to the stored leaves, by 2–10 %
/// (12 by 7–9 %), 24 by 2–7 %.
const LEAF_CANDIDATES: usize = 12;

/// A node of a patch: an inner node's two children, or a leaf's range of [`Patch::order`].
#[derive(Clone, Copy, Debug)]
pub(super) struct PatchNode {
    /// Inner: the first child; leaf: the first entry of `order`.
    pub(super) a: u32,
    /// Inner: the second child; leaf: the number of entries.
    pub(super) b: u32,
    pub(super) leaf: bool,
}

/// A node of the stored hierarchy still to descend while a patch is built: the places of the
/// hierarchy's order it holds, the run of sorted candidates among them, and the patch node it
/// fills.
#[derive(Clone, Copy, Debug)]
struct Pending {
    places: (u32, u32),
    run: (u32, u32),
    slot: u32,
}

/// One tooth's candidate triangles, their hierarchy and their boxes in the search frame.
#[derive(Default)]
pub(super) struct Patch {
    /// Each candidate's mesh triangle, in listing order (a candidate's number is its place here).
    pub(super) ids: Vec<u32>,
    /// Each candidate's vertices, as places in `vertices`.
    corners: Vec<[u32; 3]>,
    /// The mesh vertices of the candidates, each once.
    vertices: Vec<u32>,
    /// Head of each candidate's list of meeting sphere-tree leaves in `links` (leaf number, next
    /// entry; `u32::MAX` ends a list).
    pub(super) heads: Vec<u32>,
    pub(super) links: Vec<(u32, u32)>,
    /// The hierarchy, parents before children; node 0 is the root.
    pub(super) nodes: Vec<PatchNode>,
    /// Candidate numbers grouped by leaf.
    pub(super) order: Vec<u32>,
    /// Vertices, candidates and nodes in the search frame (boxes widened by the pad).
    framed: Vec<Vec3>,
    pub(super) tri_box: Vec<Aabb>,
    pub(super) node_box: Vec<Aabb>,
    /// Per mesh triangle, vertex and sphere-tree leaf: its candidate number, its place in
    /// `vertices`, the leaf's number.
    cand: NodeCache<u32>,
    vertex_of: NodeCache<u32>,
    leaf_number: NodeCache<u32>,
    /// The candidates by their triangles' places in the hierarchy's order (place, candidate),
    /// while the hierarchy is built.
    by_place: Vec<(u32, u32)>,
    stack: Vec<Pending>,
    /// Sphere-tree leaves numbered so far.
    pub(super) leaves: u32,
}

impl Patch {
    /// Starts a query on `mesh` with a sphere tree of `spheres` nodes.
    pub(super) fn begin(&mut self, mesh: &TriMesh, spheres: usize) {
        self.cand.begin(mesh.triangles.len());
        self.vertex_of.begin(mesh.vertices.len());
        self.leaf_number.begin(spheres);
        self.ids.clear();
        self.corners.clear();
        self.vertices.clear();
        self.heads.clear();
        self.links.clear();
        self.nodes.clear();
        self.order.clear();
        self.leaves = 0;
    }

    /// The number of sphere-tree leaf `leaf`, listed before by [`Self::list_leaf`].
    pub(super) fn leaf_number(&mut self, leaf: usize) -> u32 {
        self.leaf_number.get(leaf, || u32::MAX)
    }

    /// Lists the triangles of sphere-tree leaf `leaf` that reach one of the spheres `near` (the
    /// other tooth's leaves meeting this one, swept over the motion, in this tooth's frame) as
    /// candidates (each triangle once, each remembering this leaf): the leaf's number. A leaf
    /// listed before keeps its first listing.
    pub(super) fn list_leaf(
        &mut self,
        tree: &CompactTree,
        leaf: usize,
        near: &[Sphere],
        mesh: &TriMesh,
    ) -> u32 {
        if self.leaf_number.has(leaf) {
            return self.leaf_number.get(leaf, || 0);
        }
        let number = self.leaves;
        self.leaves += 1;
        self.leaf_number.set(leaf, number);
        // A partner holding the whole leaf sphere passes every triangle touching it.
        let s = tree.spheres[leaf];
        let all = (near.iter()).any(|p| p.centre.distance(s.centre) + s.radius <= p.radius);
        for (&x, t) in tree.triangles(leaf).iter().zip(tree.triangle_spheres(leaf)) {
            if !all && !near.iter().any(|p| p.overlaps(t)) {
                continue;
            }
            if self.cand.has(x as usize) {
                let c = self.cand.get(x as usize, || 0) as usize;
                self.links.push((number, self.heads[c]));
                self.heads[c] = self.links.len() as u32 - 1;
                continue;
            }
            let c = self.ids.len() as u32;
            self.cand.set(x as usize, c);
            self.ids.push(x);
            self.links.push((number, u32::MAX));
            self.heads.push(self.links.len() as u32 - 1);
            let corners = mesh.triangles[x as usize].map(|v| {
                let next = self.vertices.len() as u32;
                let place = self.vertex_of.get(v as usize, || next);
                if place == next {
                    self.vertices.push(v);
                }
                place
            });
            self.corners.push(corners);
        }
        number
    }

    /// Builds the patch's hierarchy (after the listing): the part of `bvh` above the
    /// candidates, each node keeping only the candidates below it, a node with candidates
    /// under one child alone giving way to that child, and a node with at most
    /// [`LEAF_CANDIDATES`] candidates made a leaf.
    ///
    /// The shape of `bvh` follows from its places alone ([`TriangleBvh::split_of`]), so with the
    /// candidates sorted by place each node's candidates are a run of them, split between its
    /// children at the first place past the middle: the build reads no node of `bvh`.
    pub(super) fn build(&mut self, bvh: &TriangleBvh) {
        self.nodes.clear();
        self.order.clear();
        if self.ids.is_empty() {
            return;
        }
        self.by_place.clear();
        (self.by_place).extend(
            (self.ids.iter().enumerate()).map(|(c, &x)| (bvh.position[x as usize], c as u32)),
        );
        self.by_place.sort_unstable();
        let leaf = PatchNode {
            a: 0,
            b: 0,
            leaf: true,
        };
        self.nodes.push(leaf);
        self.stack.clear();
        self.stack.push(Pending {
            places: (0, bvh.order.len() as u32),
            run: (0, self.by_place.len() as u32),
            slot: 0,
        });
        while let Some(mut p) = self.stack.pop() {
            loop {
                let run = &self.by_place[p.run.0 as usize..p.run.1 as usize];
                let split = (run.len() > LEAF_CANDIDATES)
                    .then(|| TriangleBvh::split_of(p.places.0 as usize, p.places.1 as usize))
                    .flatten();
                let Some(mid) = split else {
                    let start = self.order.len() as u32;
                    self.order.extend(run.iter().map(|&(_, c)| c));
                    self.nodes[p.slot as usize] = PatchNode {
                        a: start,
                        b: run.len() as u32,
                        leaf: true,
                    };
                    break;
                };
                let mid = mid as u32;
                let split = p.run.0 + run.partition_point(|&(place, _)| place < mid) as u32;
                let first = Pending {
                    places: (p.places.0, mid),
                    run: (p.run.0, split),
                    slot: p.slot,
                };
                let second = Pending {
                    places: (mid, p.places.1),
                    run: (split, p.run.1),
                    slot: p.slot,
                };
                if split == p.run.0 {
                    p = second;
                } else if split == p.run.1 {
                    p = first;
                } else {
                    let slot = self.nodes.len() as u32;
                    self.nodes.extend([leaf, leaf]);
                    self.nodes[p.slot as usize] = PatchNode {
                        a: slot,
                        b: slot + 1,
                        leaf: false,
                    };
                    self.stack.push(Pending {
                        slot: slot + 1,
                        ..second
                    });
                    self.stack.push(Pending { slot, ..first });
                    break;
                }
            }
        }
        self.framed.resize(self.vertices.len(), Vec3::ZERO);
        self.tri_box.resize(self.ids.len(), Aabb::EMPTY);
        self.node_box.resize(self.nodes.len(), Aabb::EMPTY);
    }

    /// The mesh vertices of the candidates, each once.
    pub(super) fn vertex_ids(&self) -> &[u32] {
        &self.vertices
    }

    /// The widening of a box mapped by `map` whose framed coordinates reach `reach`.
    fn pad(map: &Affine32, reach: f32) -> f32 {
        1e-5 + 4e-6 * (reach + map.t.length())
    }

    /// Refits every box to the candidates mapped by `map` (mesh frame to search frame).
    pub(super) fn refit(&mut self, mesh: &TriMesh, map: &Affine32) {
        let mut reach = 0.0f32;
        for (f, &v) in self.framed.iter_mut().zip(&self.vertices) {
            *f = map.apply(mesh.vertices[v as usize]);
            reach = reach.max(f.abs().max_element());
        }
        let pad = Vec3::splat(Self::pad(map, reach));
        for (b, c) in self.tri_box.iter_mut().zip(&self.corners) {
            let [p, q, r] = c.map(|i| self.framed[i as usize]);
            *b = Aabb {
                min: p.min(q).min(r) - pad,
                max: p.max(q).max(r) + pad,
            };
        }
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            self.node_box[i] = if n.leaf {
                self.order[n.a as usize..(n.a + n.b) as usize]
                    .iter()
                    .fold(Aabb::EMPTY, |b, &c| b.union(self.tri_box[c as usize]))
            } else {
                self.node_box[n.a as usize].union(self.node_box[n.b as usize])
            };
        }
    }
}
