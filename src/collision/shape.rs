//! What a tooth brings to collision detection: its mesh, a compact copy of its sphere tree, and its
//! bounding circle (the paper's coarse method).

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::{
    geometry::{Pose, Sphere, TriMesh},
    sphere_tree::{SphereTree, TreeBuildError, TreeCache, TreeSettings},
    teeth::{Dentition, Fdi, ToothGeometry},
};

/// Lanes of a [`Chunk`]: the children of a node are tested against one sphere eight at a time.
pub const LANES: usize = 8;

/// Up to [`LANES`] sibling spheres in structure-of-arrays form, so that one node is tested against
/// all of them in a few vector instructions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Chunk {
    /// Centre x (local frame).
    pub x: [f32; LANES],
    /// Centre y.
    pub y: [f32; LANES],
    /// Centre z.
    pub z: [f32; LANES],
    /// Radius.
    pub r: [f32; LANES],
    /// Distance of the centre from the local origin.
    pub rho: [f32; LANES],
    /// Compact node index of each lane.
    pub node: [u32; LANES],
    /// Lanes in use (the first `len`).
    pub len: u32,
    /// Bit k set when lane k is a leaf.
    pub leaves: u32,
}

impl Chunk {
    /// Bit k set for every lane in use.
    #[inline]
    pub fn used(&self) -> u32 {
        (1u32 << self.len) - 1
    }
}

/// A sphere tree without empty slots, children stored contiguously, for fast descent.
#[derive(Clone, Debug)]
pub struct CompactTree {
    /// Node spheres (local frame); node 0 is the root.
    pub spheres: Vec<Sphere>,
    /// First child of each node.
    pub first: Vec<u32>,
    /// Number of children (0 for a leaf).
    pub count: Vec<u32>,
    /// Triangles each leaf touches, all leaves' lists in one array (node order): node i's list is
    /// `triangle_list[triangle_start[i]..triangle_start[i + 1]]` (see [`Self::triangles`]).
    triangle_list: Vec<u32>,
    /// The bounding sphere of each entry of `triangle_list` (local frame), in the same order, so
    /// that a leaf's triangles can be culled without reading the mesh.
    triangle_spheres: Vec<Sphere>,
    /// Start of each node's list in `triangle_list`, and one past the last.
    triangle_start: Vec<u32>,
    /// Sibling groups in lanes: chunk 0 holds the root alone, then each inner node's children.
    pub chunks: Vec<Chunk>,
    /// Per node, the range of chunks holding its children (empty for a leaf).
    pub child_chunks: Vec<std::ops::Range<u32>>,
    /// Largest distance of a node centre from the local origin (for rounding bounds).
    pub max_rho: f32,
}

impl CompactTree {
    /// Copies the used slots of `tree` (built on `mesh`) in breadth-first order.
    pub fn new(tree: &SphereTree, mesh: &TriMesh) -> Self {
        let mut out = Self {
            spheres: Vec::new(),
            first: Vec::new(),
            count: Vec::new(),
            triangle_list: Vec::new(),
            triangle_spheres: Vec::new(),
            triangle_start: vec![0],
            chunks: Vec::new(),
            child_chunks: Vec::new(),
            max_rho: 0.0,
        };
        let Some(root) = tree.root() else {
            return out;
        };
        // Breadth-first: node k of the queue is compact node k.
        let mut queue = std::collections::VecDeque::from([0usize]);
        let mut next = 1u32;
        out.spheres.push(root);
        while let Some(n) = queue.pop_front() {
            let kids: Vec<usize> = tree
                .children(n)
                .filter(|&c| tree.nodes[c].is_some())
                .collect();
            out.first.push(next);
            out.count.push(kids.len() as u32);
            next += kids.len() as u32;
            if kids.is_empty() {
                out.triangle_list.extend_from_slice(&tree.triangles[n]);
            }
            out.triangle_start.push(out.triangle_list.len() as u32);
            for c in kids {
                out.spheres.push(tree.nodes[c].expect("filtered above"));
                queue.push_back(c);
            }
        }
        out.triangle_spheres = (out.triangle_list.iter())
            .map(|&x| Sphere::enclosing(&mesh.triangle(x as usize)))
            .collect();
        out.max_rho = out
            .spheres
            .iter()
            .map(|s| s.centre.length())
            .fold(0.0, f32::max);
        out.pack();
        out
    }

    /// Fills `chunks` and `child_chunks` from the node arrays.
    fn pack(&mut self) {
        let lane = |chunk: &mut Chunk, k: usize, node: usize, s: &Sphere| {
            chunk.x[k] = s.centre.x;
            chunk.y[k] = s.centre.y;
            chunk.z[k] = s.centre.z;
            chunk.r[k] = s.radius;
            chunk.rho[k] = s.centre.length();
            chunk.node[k] = node as u32;
            chunk.len = k as u32 + 1;
        };
        let leaf = |chunk: &mut Chunk, k: usize, node: usize, count: &[u32]| {
            if count[node] == 0 {
                chunk.leaves |= 1 << k;
            }
        };
        let mut root = Chunk::default();
        lane(&mut root, 0, 0, &self.spheres[0]);
        leaf(&mut root, 0, 0, &self.count);
        self.chunks = vec![root];
        self.child_chunks = Vec::with_capacity(self.spheres.len());
        for i in 0..self.spheres.len() {
            let start = self.chunks.len() as u32;
            let kids: Vec<usize> = self.children(i).collect();
            for group in kids.chunks(LANES) {
                let mut c = Chunk::default();
                for (k, &n) in group.iter().enumerate() {
                    lane(&mut c, k, n, &self.spheres[n]);
                    leaf(&mut c, k, n, &self.count);
                }
                self.chunks.push(c);
            }
            self.child_chunks.push(start..self.chunks.len() as u32);
        }
    }

    /// The triangles leaf `i` touches (none for an inner node).
    #[inline]
    pub fn triangles(&self, i: usize) -> &[u32] {
        &self.triangle_list[self.triangle_start[i] as usize..self.triangle_start[i + 1] as usize]
    }

    /// The bounding spheres of [`Self::triangles`] of leaf `i`, in the same order.
    #[inline]
    pub fn triangle_spheres(&self, i: usize) -> &[Sphere] {
        &self.triangle_spheres[self.triangle_start[i] as usize..self.triangle_start[i + 1] as usize]
    }

    /// True when node `i` has no children.
    #[inline]
    pub fn is_leaf(&self, i: usize) -> bool {
        self.count[i] == 0
    }

    /// Children of node `i`.
    #[inline]
    pub fn children(&self, i: usize) -> std::ops::Range<usize> {
        let f = self.first[i] as usize;
        f..f + self.count[i] as usize
    }

    /// True when the tree has no spheres (the tooth is not ready).
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }
}

/// The paper's bounding circle in the horizontal (x–z) plane: centre as a point of the tooth (local
/// frame, so it moves with the tooth) and radius. Computed at a reference pose; it bounds the
/// tooth's projection exactly at that pose and approximately under tipping (the method is coarse
/// by design).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre, local frame.
    pub centre: Vec3,
    /// Radius (mm).
    pub radius: f32,
}

impl Circle {
    /// The smallest circle around the x–z projection of the mesh at `pose`.
    pub fn of(geometry: &ToothGeometry, pose: &Pose) -> Self {
        let pts: Vec<Vec3> = geometry
            .mesh
            .vertices
            .iter()
            .map(|&v| {
                let w = pose.transform_point(v);
                Vec3::new(w.x, 0.0, w.z)
            })
            .collect();
        let s = Sphere::enclosing(&pts);
        let centre_world = Vec3::new(s.centre.x, pose.translation.y, s.centre.z);
        Self {
            centre: pose.inverse().transform_point(centre_world),
            radius: s.radius,
        }
    }

    /// Centre in the x–z plane at a pose.
    pub fn centre_at(&self, pose: &Pose) -> Vec2 {
        let c = pose.transform_point(self.centre);
        Vec2::new(c.x, c.z)
    }
}

/// A tooth ready for collision queries: geometry, compact tree, circle.
#[derive(Clone, Debug)]
pub struct CollisionShape {
    /// Mesh, triangle hierarchy and frame.
    pub geometry: Arc<ToothGeometry>,
    /// The sphere tree, compacted.
    pub tree: Arc<CompactTree>,
    /// Largest distance of a vertex from the local origin (bounds point speeds under rotation).
    pub max_rho: f32,
    /// Bounding box of the mesh (local frame).
    pub local_box: crate::geometry::Aabb,
}

impl CollisionShape {
    /// A shape from a tooth's geometry and its sphere tree.
    pub fn new(geometry: Arc<ToothGeometry>, tree: &SphereTree) -> Self {
        let max_rho = geometry
            .mesh
            .vertices
            .iter()
            .map(|v| v.length())
            .fold(0.0, f32::max);
        Self {
            local_box: geometry.mesh.aabb(),
            tree: Arc::new(CompactTree::new(tree, &geometry.mesh)),
            geometry,
            max_rho,
        }
    }
}

/// Collision shapes of the visible teeth of `d`, each distinct tooth shape's tree built once (in
/// parallel) or read from `cache`.
pub fn collision_shapes(
    d: &Dentition,
    trees: TreeSettings,
    cache: Option<&TreeCache>,
) -> Result<Vec<(Fdi, CollisionShape)>, TreeBuildError> {
    trees.validate()?;
    let mut distinct: Vec<Arc<ToothGeometry>> = Vec::new();
    for t in d.visible() {
        if !distinct.iter().any(|g| Arc::ptr_eq(g, &t.geometry)) {
            distinct.push(t.geometry.clone());
        }
    }
    let built = crate::parallel::parallel_map(&distinct, |g| match cache {
        Some(c) => c.load_or_build(&trees, &g.mesh, &g.bvh).map(|x| x.0),
        None => trees.build(&g.mesh, &g.bvh),
    });
    let mut shapes = Vec::with_capacity(distinct.len());
    for (g, tree) in distinct.iter().zip(built) {
        shapes.push(CollisionShape::new(g.clone(), &tree?));
    }
    Ok(d.visible()
        .map(|t| {
            let k = distinct
                .iter()
                .position(|g| Arc::ptr_eq(g, &t.geometry))
                .expect("listed above");
            (t.fdi, shapes[k].clone())
        })
        .collect())
}
