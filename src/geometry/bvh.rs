//! `TriangleBvh`: a binary bounding-box hierarchy over a mesh's triangles, in the mesh's local frame.

use glam::Vec3;

use super::{aabb::Aabb, trimesh::TriMesh};

/// Most triangles kept in one leaf.
const LEAF_SIZE: usize = 4;

/// One node: its box and either two children or a range of `order`.
#[derive(Clone, Copy, Debug)]
pub struct BvhNode {
    /// Bounds of every triangle below this node.
    pub aabb: Aabb,
    /// Leaf: index of the first triangle in [`TriangleBvh::order`]; inner: index of the left child
    /// (the right child is `left + 1`).
    pub start: u32,
    /// Number of triangles for a leaf, 0 for an inner node.
    pub count: u32,
}

impl BvhNode {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Bounding-box hierarchy over triangles, built by median splits on the longest axis.
#[derive(Clone, Debug, Default)]
pub struct TriangleBvh {
    /// Nodes; node 0 is the root.
    pub nodes: Vec<BvhNode>,
    /// Triangle indices, grouped by leaf.
    pub order: Vec<u32>,
    /// The place of each triangle in `order`.
    pub position: Vec<u32>,
}

impl TriangleBvh {
    /// Builds the hierarchy for `mesh`'s triangles.
    pub fn build(mesh: &TriMesh) -> Self {
        let boxes: Vec<Aabb> = (0..mesh.triangles.len())
            .map(|i| Aabb::from_points(mesh.triangle(i)))
            .collect();
        let centres: Vec<Vec3> = boxes.iter().map(Aabb::centre).collect();
        let mut bvh = Self {
            nodes: Vec::with_capacity(2 * mesh.triangles.len() / LEAF_SIZE + 1),
            order: (0..mesh.triangles.len() as u32).collect(),
            position: vec![0; mesh.triangles.len()],
        };
        if mesh.triangles.is_empty() {
            return bvh;
        }
        bvh.nodes.push(BvhNode {
            aabb: Aabb::EMPTY,
            start: 0,
            count: 0,
        });
        let n = bvh.order.len();
        bvh.split(0, 0, n, &boxes, &centres);
        for (k, &t) in bvh.order.iter().enumerate() {
            bvh.position[t as usize] = k as u32;
        }
        bvh
    }

    fn split(&mut self, node: usize, lo: usize, hi: usize, boxes: &[Aabb], centres: &[Vec3]) {
        let aabb = self.order[lo..hi]
            .iter()
            .fold(Aabb::EMPTY, |b, &t| b.union(boxes[t as usize]));
        let Some(mid) = Self::split_of(lo, hi) else {
            self.nodes[node] = BvhNode {
                aabb,
                start: lo as u32,
                count: (hi - lo) as u32,
            };
            return;
        };
        let cb = Aabb::from_points(self.order[lo..hi].iter().map(|&t| centres[t as usize]));
        let e = cb.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        self.order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
            centres[a as usize][axis].total_cmp(&centres[b as usize][axis])
        });
        let left = self.nodes.len();
        let empty = BvhNode {
            aabb: Aabb::EMPTY,
            start: 0,
            count: 0,
        };
        self.nodes.push(empty);
        self.nodes.push(empty);
        self.nodes[node] = BvhNode {
            aabb,
            start: left as u32,
            count: 0,
        };
        self.split(left, lo, mid, boxes, centres);
        self.split(left + 1, mid, hi, boxes, centres);
    }

    /// How the node holding the places `lo..hi` of [`Self::order`] splits them (the root holds
    /// all of `order`): `None` for a leaf (`lo..hi` is then `start..start + count`), else `mid`,
    /// its first child holding `lo..mid` and its second `mid..hi`. So the shape of the hierarchy
    /// follows from the number of triangles alone, and the node holding a triangle from its
    /// place.
    #[inline]
    pub fn split_of(lo: usize, hi: usize) -> Option<usize> {
        (hi - lo > LEAF_SIZE).then_some((lo + hi) / 2)
    }

    /// The same hierarchy over the mesh with its triangles in this hierarchy's leaf order
    /// (`mesh.in_triangle_order(&self.order)`, see [`TriMesh::in_triangle_order`]): triangle k of
    /// that mesh is triangle `order[k]` of this one, so the nodes and their boxes stand and only
    /// the numbering changes; no rebuild.
    pub fn in_leaf_order(&self) -> Self {
        Self {
            nodes: self.nodes.clone(),
            order: (0..self.order.len() as u32).collect(),
            position: (0..self.order.len() as u32).collect(),
        }
    }

    /// The triangles of a leaf node.
    #[inline]
    pub fn leaf_triangles(&self, node: &BvhNode) -> &[u32] {
        &self.order[node.start as usize..(node.start + node.count) as usize]
    }

    /// Bounds of the whole mesh.
    pub fn root_aabb(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.aabb)
    }

    /// Calls `f(i, j)` (i ≠ j, each unordered pair once) for every pair of triangles whose boxes
    /// overlap; `f` returns false to stop.
    pub fn self_pairs(&self, f: &mut impl FnMut(usize, usize) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0u32, 0u32)];
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            if na.aabb.distance_squared(&nb.aabb) > 0.0 {
                continue;
            }
            match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => {
                    let (ta, tb) = (self.leaf_triangles(na), self.leaf_triangles(nb));
                    for (x, &i) in ta.iter().enumerate() {
                        let others = if a == b { &tb[x + 1..] } else { tb };
                        for &j in others {
                            if !f(i as usize, j as usize) {
                                return;
                            }
                        }
                    }
                }
                _ if a == b => {
                    let l = na.start;
                    stack.extend([(l, l), (l + 1, l + 1), (l, l + 1)]);
                }
                (false, _)
                    if nb.is_leaf() || na.aabb.extent().length() >= nb.aabb.extent().length() =>
                {
                    stack.extend([(na.start, b), (na.start + 1, b)]);
                }
                _ => stack.extend([(a, nb.start), (a, nb.start + 1)]),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tilted flat sheet of `n`×`n` quads.
    fn sheet(n: u32) -> TriMesh {
        let v = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i as f32 * 0.3, j as f32 * 0.25)))
            .map(|(x, y)| Vec3::new(x, y, 0.3 * x + 0.2 * y + 1.0))
            .collect();
        let at = |i: u32, j: u32| i * (n + 1) + j;
        let t = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .flat_map(|(i, j)| {
                [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
            .collect();
        TriMesh::new(v, t)
    }

    /// The splits and places agree with the nodes: every triangle sits in the leaf its place
    /// gives and under each of its ancestors, whose boxes hold it.
    #[test]
    fn nodes_hold_the_triangles_their_places_give() {
        let mesh = sheet(12);
        holds_its_triangles(&mesh, &TriangleBvh::build(&mesh));
    }

    /// The hierarchy carried over to the mesh in its leaf order holds that mesh's triangles as a
    /// hierarchy built for it would, and reads its leaves in plain order.
    #[test]
    fn a_hierarchy_carries_over_to_its_leaf_order() {
        let mesh = sheet(12);
        let bvh = TriangleBvh::build(&mesh);
        assert!(bvh.order.windows(2).any(|w| w[0] > w[1]));
        let ordered = mesh.in_triangle_order(&bvh.order);
        let carried = bvh.in_leaf_order();
        holds_its_triangles(&ordered, &carried);
        assert!(carried.order.windows(2).all(|w| w[0] + 1 == w[1]));
    }

    fn holds_its_triangles(mesh: &TriMesh, bvh: &TriangleBvh) {
        assert!(bvh.nodes.len() > 7);
        // Each node holds the places of `order` that the splits give it, and their triangles lie
        // in its box; `position` inverts `order`.
        let mut stack = vec![(0u32, 0, bvh.order.len(), 0)];
        let mut leaves = 0;
        while let Some((n, lo, hi, depth)) = stack.pop() {
            let node = bvh.nodes[n as usize];
            for &t in &bvh.order[lo..hi] {
                for v in mesh.triangle(t as usize) {
                    let b = node.aabb;
                    assert!(b.distance_squared_to_point(v) == 0.0, "{v} outside {b:?}");
                }
            }
            match TriangleBvh::split_of(lo, hi) {
                None => {
                    assert!(node.is_leaf() && depth >= 2);
                    assert_eq!((node.start as usize, node.count as usize), (lo, hi - lo));
                    leaves += hi - lo;
                }
                Some(mid) => {
                    assert!(!node.is_leaf() && lo < mid && mid < hi);
                    let d = depth + 1;
                    stack.extend([(node.start, lo, mid, d), (node.start + 1, mid, hi, d)]);
                }
            }
        }
        assert_eq!(leaves, mesh.triangles.len());
        for (k, &t) in bvh.order.iter().enumerate() {
            assert_eq!(bvh.position[t as usize], k as u32);
        }
    }
}
