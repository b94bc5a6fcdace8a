//! Exact minimal distance between two posed meshes, with a penetration estimate when they overlap.
//!
//! Guarantees:
//! - `distance` of a separated pair is the exact minimal surface-to-surface distance (up to f32
//!   rounding): a branch-and-bound descent of both [`TriangleBvh`]s whose box bounds are
//!   conservative, finished by exact triangle–triangle closest points.
//! - A pair whose surfaces intersect, or where one solid lies inside the other, is reported as
//!   overlapping; its `penetration` is the largest distance from a vertex or triangle centroid of
//!   one mesh lying inside the other to that other's surface: a lower bound of the true penetration
//!   depth that is exact when the deepest point is a vertex (the usual case for convex tips).
//! - [`super::mesh_penetration_near`] gives the same estimate from the triangles at the contact, walking
//!   only the part of each surface that lies inside the other (see its doc for why that finds
//!   every sample point the whole-mesh search would).

use glam::{Mat3, Vec3};

use super::{
    aabb::Aabb,
    bvh::TriangleBvh,
    closest::{
        TrianglePair, closest_point_triangle, closest_points_triangle_triangle, triangle_plane_gap,
    },
    pose::Pose,
    trimesh::TriMesh,
};

/// A mesh with its hierarchy, ready for queries.
#[derive(Clone, Copy)]
pub struct MeshRef<'a> {
    /// The mesh, in its local frame.
    pub mesh: &'a TriMesh,
    /// Its triangle hierarchy.
    pub bvh: &'a TriangleBvh,
}

/// The second mesh of a query seen from the first's frame (pose_a⁻¹ ∘ pose_b), where the
/// hierarchy searches work: the first mesh's triangles and boxes as stored, the second's mapped.
pub(super) struct InFirst<'a> {
    mesh: MeshRef<'a>,
    rel: Pose,
    rot: Mat3,
}

impl<'a> InFirst<'a> {
    /// `b` (posed by `pose_b`) in the frame of a mesh posed by `pose_a`.
    pub(super) fn new(pose_a: &Pose, b: MeshRef<'a>, pose_b: &Pose) -> Self {
        let rel = pose_a.inverse().mul(pose_b);
        Self {
            mesh: b,
            rel,
            rot: Mat3::from_quat(rel.rotation),
        }
    }

    /// Triangle `j`, mapped.
    #[inline]
    pub(super) fn triangle(&self, j: u32) -> [Vec3; 3] {
        self.mesh
            .mesh
            .triangle(j as usize)
            .map(|v| self.rel.transform_point(v))
    }

    /// The box of hierarchy node `node`, mapped (it holds the mapped node's triangles).
    #[inline]
    pub(super) fn node_box(&self, node: u32) -> Aabb {
        self.mesh.bvh.nodes[node as usize]
            .aabb
            .transformed(&self.rot, self.rel.translation)
    }
}

/// Result of [`mesh_separation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSeparation {
    /// Minimal surface distance (mm); 0 when the meshes overlap.
    pub distance: f32,
    /// Penetration depth estimate (mm) when overlapping, else 0.
    pub penetration: f32,
    /// Closest (or deepest) point on the first mesh, world frame.
    pub point_a: Vec3,
    /// Closest (or deepest) point on the second mesh, world frame.
    pub point_b: Vec3,
}

impl MeshSeparation {
    /// Signed gap: positive distance when apart, negative penetration when overlapping.
    pub fn signed_gap(&self) -> f32 {
        if self.penetration > 0.0 || self.distance == 0.0 {
            -self.penetration
        } else {
            self.distance
        }
    }

    /// True when the solids touch or overlap.
    pub fn overlapping(&self) -> bool {
        self.distance == 0.0
    }
}

/// The minimal distance between two posed meshes, searching only closer than `max_distance`
/// (use `f32::INFINITY` for no limit). Returns `None` when the meshes are farther apart than that.
pub fn closest_triangles(
    a: MeshRef,
    pose_a: &Pose,
    b: MeshRef,
    pose_b: &Pose,
    max_distance: f32,
) -> Option<(TrianglePair, usize, usize)> {
    if a.bvh.nodes.is_empty() || b.bvh.nodes.is_empty() {
        return None;
    }
    // Work in a's frame.
    let in_a = InFirst::new(pose_a, b, pose_b);
    let mut best: Option<(TrianglePair, usize, usize)> = None;
    let mut best_d2 = if max_distance.is_finite() {
        max_distance * max_distance
    } else {
        f32::INFINITY
    };
    let mut stack: Vec<(f32, u32, u32, Aabb)> = vec![(0.0, 0, 0, in_a.node_box(0))];
    while let Some((d2, na, nb, box_b)) = stack.pop() {
        if d2 > best_d2 {
            continue;
        }
        let node_a = a.bvh.nodes[na as usize];
        let node_b = b.bvh.nodes[nb as usize];
        if node_a.is_leaf() && node_b.is_leaf() {
            for &i in a.bvh.leaf_triangles(&node_a) {
                let ta = a.mesh.triangle(i as usize);
                for &j in b.bvh.leaf_triangles(&node_b) {
                    let tb = in_a.triangle(j);
                    if best.is_some() {
                        let lb = triangle_plane_gap(&ta, &tb);
                        if lb * lb > best_d2 {
                            continue;
                        }
                    }
                    let pair = closest_points_triangle_triangle(&ta, &tb);
                    let pd2 = pair.distance * pair.distance;
                    if pd2 < best_d2 || best.is_none() && pd2 <= best_d2 {
                        best_d2 = pd2;
                        best = Some((pair, i as usize, j as usize));
                        if pd2 == 0.0 {
                            return best.map(|(p, i, j)| (to_world(p, pose_a), i, j));
                        }
                    }
                }
            }
            continue;
        }
        let split_a = !node_a.is_leaf()
            && (node_b.is_leaf() || node_a.aabb.extent().length() >= box_b.extent().length());
        let mut children: [(f32, u32, u32, Aabb); 2] = if split_a {
            let l = node_a.start;
            [l, l + 1].map(|c| {
                let cb = &a.bvh.nodes[c as usize].aabb;
                (cb.distance_squared(&box_b), c, nb, box_b)
            })
        } else {
            let l = node_b.start;
            [l, l + 1].map(|c| {
                let cb = in_a.node_box(c);
                (node_a.aabb.distance_squared(&cb), na, c, cb)
            })
        };
        // Visit the nearer child first (pushed last).
        if children[0].0 < children[1].0 {
            children.swap(0, 1);
        }
        for c in children {
            if c.0 <= best_d2 {
                stack.push(c);
            }
        }
    }
    best.map(|(p, i, j)| (to_world(p, pose_a), i, j))
}

fn to_world(p: TrianglePair, pose: &Pose) -> TrianglePair {
    TrianglePair {
        distance: p.distance,
        on_first: pose.transform_point(p.on_first),
        on_second: pose.transform_point(p.on_second),
    }
}

/// Closest point on the mesh surface to `p` (mesh frame), with its distance. Exact.
pub fn closest_point_on_mesh(m: MeshRef, p: Vec3) -> Option<(Vec3, f32)> {
    closest_point_on_mesh_within(m, p, f32::INFINITY)
}

/// [`closest_point_on_mesh`] among the surface points nearer than `limit` (None if there are
/// none): boxes farther than the limit are never opened.
pub fn closest_point_on_mesh_within(m: MeshRef, p: Vec3, limit: f32) -> Option<(Vec3, f32)> {
    closest_on_mesh_within(m, p, limit).map(|(q, d, _)| (q, d))
}

/// [`closest_point_on_mesh`] with the number of the triangle the point lies on. Exact.
pub fn closest_point_and_triangle(m: MeshRef, p: Vec3) -> Option<(Vec3, f32, u32)> {
    closest_on_mesh_within(m, p, f32::INFINITY)
}

/// [`closest_point_on_mesh_within`] with the number of the triangle the point lies on. Exact.
pub fn closest_point_and_triangle_within(
    m: MeshRef,
    p: Vec3,
    limit: f32,
) -> Option<(Vec3, f32, u32)> {
    closest_on_mesh_within(m, p, limit)
}

/// [`closest_point_on_mesh_within`] with the number of the triangle the point lies on.
fn closest_on_mesh_within(m: MeshRef, p: Vec3, limit: f32) -> Option<(Vec3, f32, u32)> {
    let mut best: Option<(Vec3, f32, u32)> = None;
    let mut best_d2 = limit * limit;
    if m.bvh.nodes.is_empty() {
        return None;
    }
    // Depth-first, at most one pending sibling per level of a balanced tree (see `ray_parity`).
    let (mut stack, mut top) = ([0u32; 64], 1);
    while top > 0 {
        top -= 1;
        let node = m.bvh.nodes[stack[top] as usize];
        if node.aabb.distance_squared_to_point(p) > best_d2 {
            continue;
        }
        if node.is_leaf() {
            for &t in m.bvh.leaf_triangles(&node) {
                let [a, b, c] = m.mesh.triangle(t as usize);
                // The triangle's box is a lower bound: a triangle clearly beyond the best so far
                // (by more than the rounding of `d2`) is passed over without the exact query.
                if Aabb::from_points([a, b, c]).distance_squared_to_point(p)
                    > best_d2 * (1.0 + 1e-5)
                {
                    continue;
                }
                let q = closest_point_triangle(p, a, b, c);
                let d2 = q.distance_squared(p);
                if d2 < best_d2 {
                    best_d2 = d2;
                    best = Some((q, d2.sqrt(), t));
                }
            }
        } else {
            let l = node.start;
            let (d0, d1) = (
                m.bvh.nodes[l as usize].aabb.distance_squared_to_point(p),
                m.bvh.nodes[l as usize + 1]
                    .aabb
                    .distance_squared_to_point(p),
            );
            let (near, far) = if d0 < d1 { (l, l + 1) } else { (l + 1, l) };
            stack[top] = far;
            stack[top + 1] = near;
            top += 2;
        }
    }
    best
}

/// True when `p` (mesh frame) lies inside the closed mesh: the parity of crossings along a ray,
/// retried along other directions when a ray grazes an edge or vertex.
pub fn point_inside_mesh(m: MeshRef, p: Vec3) -> bool {
    point_inside_mesh_along(m, p, None)
}

/// [`point_inside_mesh`] casting its first ray along `first` (a unit vector with no component
/// near zero; for example away from the mesh's middle, where a ray from a point near the
/// surface meets few boxes), then along the fixed directions if that ray grazes an edge.
fn point_inside_mesh_along(m: MeshRef, p: Vec3, first: Option<Vec3>) -> bool {
    if m.bvh.nodes.is_empty() || m.bvh.root_aabb().distance_squared_to_point(p) > 0.0 {
        return false;
    }
    if let Some(dir) = first
        && let Some(inside) = super::ray::ray_parity(m, p, dir)
    {
        return inside;
    }
    const DIRECTIONS: [Vec3; 4] = [
        Vec3::new(0.573_462_4, 0.608_519_3, 0.548_867_6),
        Vec3::new(-0.401_734_5, 0.817_405_3, -0.412_889_2),
        Vec3::new(0.709_123_8, -0.301_952_2, -0.637_128_4),
        Vec3::new(-0.222_617_9, -0.531_411_1, 0.817_324_6),
    ];
    let mut votes = 0;
    for (k, dir) in DIRECTIONS.iter().enumerate() {
        match super::ray::ray_parity(m, p, *dir) {
            Some(inside) => return inside,
            None if k == DIRECTIONS.len() - 1 => votes += 1,
            None => {}
        }
    }
    votes > 0
}

/// Minimal distance, or penetration estimate, between two posed closed meshes (see the module doc
/// for the guarantees).
pub fn mesh_separation(a: MeshRef, pose_a: &Pose, b: MeshRef, pose_b: &Pose) -> MeshSeparation {
    mesh_separation_within(a, pose_a, b, pose_b, f32::INFINITY).unwrap_or(MeshSeparation {
        distance: f32::INFINITY,
        penetration: 0.0,
        point_a: pose_a.translation,
        point_b: pose_b.translation,
    })
}

/// [`mesh_separation`] of meshes nearer than `limit`: `None` when their surfaces are farther apart
/// than that and neither solid holds the other (so their gap exceeds `limit`). Parts of the
/// hierarchies farther than the limit are never opened, which makes a far pair cheap.
pub fn mesh_separation_within(
    a: MeshRef,
    pose_a: &Pose,
    b: MeshRef,
    pose_b: &Pose,
    limit: f32,
) -> Option<MeshSeparation> {
    // Containment without surface contact: one vertex of either inside the other.
    let contained = || {
        let b_in_a = pose_a.inverse().mul(pose_b);
        let a_in_b = b_in_a.inverse();
        !a.mesh.vertices.is_empty()
            && !b.mesh.vertices.is_empty()
            && (point_inside_mesh(a, b_in_a.transform_point(b.mesh.vertices[0]))
                || point_inside_mesh(b, a_in_b.transform_point(a.mesh.vertices[0])))
    };
    let pair = match closest_triangles(a, pose_a, b, pose_b, limit) {
        Some((pair, _, _)) => pair,
        None if contained() => {
            let (penetration, point_a, point_b) = mesh_penetration(a, pose_a, b, pose_b);
            return Some(MeshSeparation {
                distance: 0.0,
                penetration,
                point_a,
                point_b,
            });
        }
        None => return None,
    };
    if pair.distance > 0.0 && !contained() {
        return Some(MeshSeparation {
            distance: pair.distance,
            penetration: 0.0,
            point_a: pair.on_first,
            point_b: pair.on_second,
        });
    }
    let (penetration, point_a, point_b) = mesh_penetration(a, pose_a, b, pose_b);
    Some(MeshSeparation {
        distance: 0.0,
        penetration,
        point_a: if penetration > 0.0 {
            point_a
        } else {
            pair.on_first
        },
        point_b: if penetration > 0.0 {
            point_b
        } else {
            pair.on_second
        },
    })
}

/// The penetration estimate of [`mesh_separation`] for meshes already known to touch or overlap:
/// the deepest vertex or triangle centroid of either mesh inside the other, its depth, and the
/// deepest point with the nearest point of the other's surface as (point on a, point on b), world
/// frame. Depth 0 (and the local origins) when no sample point lies inside.
pub fn mesh_penetration(a: MeshRef, pose_a: &Pose, b: MeshRef, pose_b: &Pose) -> (f32, Vec3, Vec3) {
    let (da, pa, qa) = deepest_point(a, pose_a, b, pose_b);
    let (db, pb, qb) = deepest_point(b, pose_b, a, pose_a);
    if da >= db { (da, pa, qa) } else { (db, qb, pb) }
}

/// The deepest of the sample points of one mesh (its local frame) that lie inside another, b.
pub(super) struct Deepest<'a> {
    b: MeshRef<'a>,
    a_in_b: Pose,
    pose_b: Pose,
    b_box: Aabb,
    /// Depth, deepest point (b's frame) and its nearest point on b's surface (b's frame).
    best: (f32, Vec3, Vec3),
    /// The triangle of b's surface (b's frame) nearest the last sample measured: no sample is
    /// deeper than its distance from it.
    last: Option<[Vec3; 3]>,
    /// A depth the result is known to reach (0 when none is known): samples whose bound is
    /// below it are not measured.
    floor: f32,
}

impl<'a> Deepest<'a> {
    pub(super) fn new(pose_a: &Pose, b: MeshRef<'a>, pose_b: &Pose) -> Self {
        let to_b = pose_b.inverse();
        let origin = to_b.transform_point(pose_a.translation);
        Self {
            b,
            a_in_b: to_b.mul(pose_a),
            pose_b: *pose_b,
            b_box: b.bvh.root_aabb(),
            best: (0.0, origin, origin),
            last: None,
            floor: 0.0,
        }
    }

    /// The same search, told that the deepest sample reaches at least `floor` (mm): a sample
    /// whose bound is below it cannot be the deepest and is not measured. The result is the same
    /// for every floor up to the deepest sample's depth (the deepest sample's bound is never
    /// below it); with a higher floor the result may be shallower than the true one.
    pub(super) fn with_floor(mut self, floor: f32) -> Self {
        self.floor = floor;
        self
    }

    /// A point of the first mesh (its frame) in b's frame.
    #[inline]
    pub(super) fn place(&self, local: Vec3) -> Vec3 {
        self.a_in_b.transform_point(local)
    }

    /// Whether `p` (b's frame) lies inside b.
    pub(super) fn inside(&self, p: Vec3) -> bool {
        if self.b_box.distance_squared_to_point(p) > 0.0 {
            return false;
        }
        // Samples inside lie near b's surface: a ray away from b's middle leaves it at once.
        let out = (p - self.b_box.centre()).normalize_or_zero();
        let first = (out.abs().min_element() > 1e-3).then_some(out);
        point_inside_mesh_along(self.b, p, first)
    }

    /// The depth of `p` (b's frame, inside b), known to be at most `bound`: measured only when
    /// it could exceed the deepest so far (the deepest is kept), else an upper bound of it is
    /// returned. The deepest found is the same as measuring every sample.
    ///
    /// The triangle of b's surface nearest the last sample measured bounds the depth too: the
    /// distance to its nearest point (which lies on b's surface, up to the rounding of the
    /// closest-point query, which the margins of 10⁻⁵ cover many times). Samples come in walking
    /// order, so it is usually the sample's own nearest triangle or beside it, and the bound is
    /// then the depth itself or close above it: it prunes samples shallower than the deepest and
    /// narrows the search of the others.
    pub(super) fn depth(&mut self, p: Vec3, bound: f32) -> f32 {
        let near = self.last.map_or(f32::INFINITY, |[a, b, c]| {
            p.distance(closest_point_triangle(p, a, b, c)) * (1.0 + 1e-5) + 1e-5
        });
        let bound = bound.min(near);
        if !self.can_exceed(bound) {
            return bound;
        }
        let limit = bound * (1.0 + 1e-5) + 1e-5;
        let Some((q, d, t)) = closest_on_mesh_within(self.b, p, limit)
            .or_else(|| closest_on_mesh_within(self.b, p, f32::INFINITY))
        else {
            return bound;
        };
        self.last = Some(self.b.mesh.triangle(t as usize));
        if d > self.best.0 {
            self.best = (d, p, q);
        }
        d
    }

    /// Whether a sample whose depth is at most `bound` could be deeper than the deepest so far
    /// and reach the floor: [`Self::depth`] measures only such samples.
    pub(super) fn can_exceed(&self, bound: f32) -> bool {
        bound > self.best.0 && bound >= self.floor
    }

    /// Whether the point (the first mesh's frame) lies inside b; the deepest so far is kept.
    fn sample(&mut self, local: Vec3) -> bool {
        let p = self.place(local);
        let inside = self.inside(p);
        if inside {
            self.depth(p, f32::INFINITY);
        }
        inside
    }

    /// Depth, point (world) and nearest point of b's surface (world); depth 0 and the first
    /// mesh's origin when no sample lay inside.
    pub(super) fn result(self) -> (f32, Vec3, Vec3) {
        let (d, p, q) = self.best;
        (
            d,
            self.pose_b.transform_point(p),
            self.pose_b.transform_point(q),
        )
    }
}

/// The deepest sample point of `a` (vertices and triangle centroids) inside `b`: its depth, the point
/// (world) and the nearest point of b's surface (world).
fn deepest_point(a: MeshRef, pose_a: &Pose, b: MeshRef, pose_b: &Pose) -> (f32, Vec3, Vec3) {
    let mut deepest = Deepest::new(pose_a, b, pose_b);
    let centroids = (0..a.mesh.triangles.len()).map(|i| {
        let [p, q, r] = a.mesh.triangle(i);
        (p + q + r) / 3.0
    });
    for local in a.mesh.vertices.iter().copied().chain(centroids) {
        deepest.sample(local);
    }
    deepest.result()
}

#[cfg(test)]
pub(super) mod tests;
