//! `TriMesh`: an indexed triangle mesh and its validation (closed, manifold, outward, finite).

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use thiserror::Error;

use super::aabb::Aabb;

/// An indexed triangle mesh in millimetres. Triangles are counter-clockwise seen from outside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// Why a mesh is not a valid closed solid.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshError {
    /// No vertices or no triangles.
    #[error("mesh is empty ({vertices} vertices, {triangles} triangles)")]
    Empty {
        /// Number of vertices.
        vertices: usize,
        /// Number of triangles.
        triangles: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// Index of the vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertices} vertices")]
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The bad vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A triangle has (nearly) zero area or repeats a vertex.
    #[error("triangle {triangle} is degenerate (area {area:.3e} mm²)")]
    Degenerate {
        /// Index of the triangle.
        triangle: usize,
        /// Its area.
        area: f32,
    },
    /// Some edges belong to only one triangle: the surface has holes.
    #[error("mesh is open: {boundary_edges} boundary edges, e.g. vertices {edge:?}")]
    Open {
        /// One boundary edge.
        edge: (u32, u32),
        /// How many edges are on a boundary.
        boundary_edges: usize,
    },
    /// An edge is shared by more than two triangles, or a vertex joins separate fans.
    #[error("mesh is non-manifold at {what}")]
    NonManifold {
        /// Where: an edge or a vertex.
        what: String,
    },
    /// Two triangles sharing an edge run it in the same direction.
    #[error("inconsistent winding: edge {edge:?} runs the same way in two triangles")]
    InconsistentWinding {
        /// The edge.
        edge: (u32, u32),
    },
    /// The enclosed volume is negative (inward-facing triangles) or zero.
    #[error("mesh is inverted or flat: signed volume {volume:.4} mm³")]
    Inverted {
        /// Signed volume.
        volume: f64,
    },
    /// Two non-adjacent triangles intersect.
    #[error("mesh intersects itself: triangles {a} and {b}")]
    SelfIntersecting {
        /// First triangle.
        a: usize,
        /// Second triangle.
        b: usize,
    },
}

/// What validation measured on a valid closed mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshReport {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Enclosed volume (mm³), positive.
    pub volume: f64,
}

impl TriMesh {
    /// A mesh from vertices and triangles (not validated; call [`TriMesh::validate`]).
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            vertices,
            triangles,
        }
    }

    /// An axis-aligned box from `min` to `max`: 8 vertices, 12 triangles wound outwards (a
    /// closed solid for tests and rigs).
    pub fn cuboid(min: Vec3, max: Vec3) -> Self {
        let v = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                )
            })
            .collect();
        // -z, +z, -y, +y, -x, +x.
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Self::new(v, t)
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Axis-aligned bounds of all vertices.
    pub fn aabb(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().copied())
    }

    /// Signed enclosed volume (mm³) by the divergence theorem; positive for outward winding.
    pub fn signed_volume(&self) -> f64 {
        let origin = self.aabb().centre().as_dvec3();
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize].as_dvec3() - origin);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Total surface area (mm²).
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i).map(|v| v.as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Checks that the mesh is a closed, edge- and vertex-manifold, consistently and outward wound
    /// solid with finite coordinates and no degenerate triangles. Self-intersection is checked
    /// separately by [`TriMesh::find_self_intersection`] because it costs more.
    pub fn validate(&self) -> Result<MeshReport, MeshError> {
        if self.vertices.is_empty() || self.triangles.is_empty() {
            return Err(MeshError::Empty {
                vertices: self.vertices.len(),
                triangles: self.triangles.len(),
            });
        }
        if let Some(vertex) = self.vertices.iter().position(|v| !v.is_finite()) {
            return Err(MeshError::NonFinite { vertex });
        }
        let n = self.vertices.len();
        for (triangle, t) in self.triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= n) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    vertices: n,
                });
            }
        }
        let scale = self.aabb().extent().max_element().max(f32::MIN_POSITIVE) as f64;
        for triangle in 0..self.triangles.len() {
            let [a, b, c] = self.triangle(triangle).map(|v| v.as_dvec3());
            let area = 0.5 * (b - a).cross(c - a).length();
            let t = self.triangles[triangle];
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area <= 1e-12 * scale * scale {
                return Err(MeshError::Degenerate {
                    triangle,
                    area: area as f32,
                });
            }
        }
        self.check_edges()?;
        self.check_vertex_fans()?;
        let volume = self.signed_volume();
        if volume <= 0.0 {
            return Err(MeshError::Inverted { volume });
        }
        Ok(MeshReport {
            vertices: self.vertices.len(),
            triangles: self.triangles.len(),
            volume,
        })
    }

    /// Every undirected edge must be used once in each direction.
    fn check_edges(&self) -> Result<(), MeshError> {
        let mut directed: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(self.triangles.len() * 3);
        for t in &self.triangles {
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                *directed.entry(e).or_insert(0) += 1;
            }
        }
        let mut boundary = Vec::new();
        let mut edges: Vec<_> = directed.iter().map(|(&e, &c)| (e, c)).collect();
        edges.sort_unstable();
        for ((a, b), count) in edges {
            let reverse = directed.get(&(b, a)).copied().unwrap_or(0);
            if count > 1 {
                let undirected = count + reverse;
                return Err(if undirected > 2 {
                    MeshError::NonManifold {
                        what: format!("edge ({a}, {b}) shared by {undirected} triangles"),
                    }
                } else {
                    MeshError::InconsistentWinding { edge: (a, b) }
                });
            }
            if reverse == 0 {
                boundary.push((a, b));
            }
        }
        if let Some(&edge) = boundary.first() {
            return Err(MeshError::Open {
                edge,
                boundary_edges: boundary.len(),
            });
        }
        Ok(())
    }

    /// The triangles around each vertex must form one closed fan (no "bow-tie" vertices).
    fn check_vertex_fans(&self) -> Result<(), MeshError> {
        // For each vertex, map "edge leaving v to x" -> "next neighbour" and walk one cycle.
        let mut next: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 3);
        let mut degree = vec![0u32; self.vertices.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                next.insert((v, a), b);
                degree[v as usize] += 1;
            }
        }
        let mut start: Vec<Option<u32>> = vec![None; self.vertices.len()];
        for t in &self.triangles {
            for k in 0..3 {
                start[t[k] as usize].get_or_insert(t[(k + 1) % 3]);
            }
        }
        for (v, first) in start.iter().enumerate() {
            let Some(first) = *first else { continue };
            let mut steps = 0u32;
            let mut cur = first;
            loop {
                let Some(&n) = next.get(&(v as u32, cur)) else {
                    return Err(MeshError::NonManifold {
                        what: format!("vertex {v} (its fan is not closed)"),
                    });
                };
                steps += 1;
                cur = n;
                if cur == first || steps > degree[v] {
                    break;
                }
            }
            if steps != degree[v] {
                return Err(MeshError::NonManifold {
                    what: format!(
                        "vertex {v} (it joins {} separate fans)",
                        degree[v].div_ceil(steps.max(1))
                    ),
                });
            }
        }
        Ok(())
    }

    /// The first pair of non-adjacent triangles (sharing no vertex) that intersect, if any.
    /// Triangles that share a vertex are not tested against each other.
    pub fn find_self_intersection(&self) -> Option<(usize, usize)> {
        let bvh = super::bvh::TriangleBvh::build(self);
        let mut found = None;
        bvh.self_pairs(&mut |i, j| {
            let (ti, tj) = (self.triangles[i], self.triangles[j]);
            if ti.iter().any(|v| tj.contains(v)) {
                return true;
            }
            if super::closest::triangles_intersect(&self.triangle(i), &self.triangle(j)) {
                found = Some((i.min(j), i.max(j)));
                return false;
            }
            true
        });
        found
    }

    /// Every pair of non-adjacent triangles (sharing no vertex) that intersect, up to `limit`
    /// pairs, each as (smaller index, larger index), sorted. The same test as
    /// [`TriMesh::find_self_intersection`], for repairs that need all the places at once.
    pub fn self_intersections(&self, limit: usize) -> Vec<(usize, usize)> {
        let bvh = super::bvh::TriangleBvh::build(self);
        let mut found = Vec::new();
        bvh.self_pairs(&mut |i, j| {
            let (ti, tj) = (self.triangles[i], self.triangles[j]);
            if ti.iter().any(|v| tj.contains(v)) {
                return true;
            }
            if super::closest::triangles_intersect(&self.triangle(i), &self.triangle(j)) {
                found.push((i.min(j), i.max(j)));
            }
            found.len() < limit
        });
        found.sort_unstable();
        found
    }

    /// [`TriMesh::validate`] followed by the self-intersection check.
    pub fn validate_solid(&self) -> Result<MeshReport, MeshError> {
        let report = self.validate()?;
        if let Some((a, b)) = self.find_self_intersection() {
            return Err(MeshError::SelfIntersecting { a, b });
        }
        Ok(report)
    }

    /// Area-weighted vertex normals (unit length), for smooth shading.
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        let mut normals = vec![DVec3::ZERO; self.vertices.len()];
        for (i, t) in self.triangles.iter().enumerate() {
            let [a, b, c] = self.triangle(i).map(|v| v.as_dvec3());
            let n = (b - a).cross(c - a);
            for &v in t {
                normals[v as usize] += n;
            }
        }
        normals
            .into_iter()
            .map(|n| n.normalize_or_zero().as_vec3())
            .collect()
    }

    /// Mean length of the triangles' edges (each edge counted once per triangle; 0 when empty).
    pub fn mean_edge_length(&self) -> f32 {
        let mut sum = 0.0f64;
        for i in 0..self.triangles.len() {
            let [a, b, c] = self.triangle(i);
            sum += f64::from(a.distance(b) + b.distance(c) + c.distance(a));
        }
        (sum / (3 * self.triangles.len().max(1)) as f64) as f32
    }

    /// The pieces of the surface joined along edges (a piece touching another at one vertex only
    /// is separate): the piece of each triangle, numbered from 0 in order of first triangle, and
    /// the number of pieces.
    pub fn edge_pieces(&self) -> (Vec<u32>, usize) {
        let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (i, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                by_edge
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(i as u32);
            }
        }
        let mut piece = vec![u32::MAX; self.triangles.len()];
        let mut count = 0;
        let mut stack = Vec::new();
        for start in 0..self.triangles.len() {
            if piece[start] != u32::MAX {
                continue;
            }
            piece[start] = count;
            stack.push(start);
            while let Some(i) = stack.pop() {
                let t = self.triangles[i];
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    for &j in &by_edge[&(a.min(b), a.max(b))] {
                        if piece[j as usize] == u32::MAX {
                            piece[j as usize] = count;
                            stack.push(j as usize);
                        }
                    }
                }
            }
            count += 1;
        }
        (piece, count as usize)
    }

    /// The triangles of one piece (`piece` numbers each triangle's piece, as
    /// [`TriMesh::edge_pieces`] gives them), every vertex kept.
    pub fn keeping_piece(&self, piece: &[u32], keep: u32) -> Self {
        let triangles = self
            .triangles
            .iter()
            .zip(piece)
            .filter(|(_, p)| **p == keep)
            .map(|(t, _)| *t)
            .collect();
        Self::new(self.vertices.clone(), triangles)
    }

    /// The edges used by one triangle only (the openings' edges), as (smaller, larger) vertex
    /// index, whatever the triangles' winding.
    pub fn open_edges(&self) -> Vec<(u32, u32)> {
        let mut count: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut open: Vec<(u32, u32)> = count
            .into_iter()
            .filter(|(_, n)| *n == 1)
            .map(|(e, _)| e)
            .collect();
        open.sort_unstable();
        open
    }

    /// The same surface without the vertices no triangle uses, the rest numbered in order of
    /// first use by the triangles.
    pub fn without_unused_vertices(&self) -> Self {
        let mut map = vec![u32::MAX; self.vertices.len()];
        let mut vertices = Vec::with_capacity(self.vertices.len());
        let triangles = self
            .triangles
            .iter()
            .map(|t| {
                t.map(|v| {
                    if map[v as usize] == u32::MAX {
                        map[v as usize] = vertices.len() as u32;
                        vertices.push(self.vertices[v as usize]);
                    }
                    map[v as usize]
                })
            })
            .collect();
        Self::new(vertices, triangles)
    }

    /// The same surface with its triangles in `order` (a permutation of their indices) and its
    /// vertices renumbered in order of first use (unused ones dropped). Listed in a hierarchy's
    /// leaf order, the triangles of one patch of the surface, and their vertices, lie together in
    /// memory, so a query reading a patch reads a few cache lines instead of one per corner.
    pub fn in_triangle_order(&self, order: &[u32]) -> Self {
        debug_assert_eq!(order.len(), self.triangles.len());
        let triangles = order.iter().map(|&t| self.triangles[t as usize]).collect();
        Self::new(self.vertices.clone(), triangles).without_unused_vertices()
    }

    /// A copy with every vertex mapped by `f` (e.g. a pose).
    pub fn map_vertices(&self, f: impl Fn(Vec3) -> Vec3) -> Self {
        Self::new(
            self.vertices.iter().map(|&v| f(v)).collect(),
            self.triangles.clone(),
        )
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An axis-aligned box from `min` to `max`, outward wound.
    pub(crate) fn cuboid(min: Vec3, max: Vec3) -> TriMesh {
        TriMesh::cuboid(min, max)
    }

    #[test]
    fn a_box_is_valid_with_its_volume() {
        let m = cuboid(Vec3::ZERO, Vec3::new(2.0, 3.0, 4.0));
        let r = m.validate_solid().unwrap();
        assert!((r.volume - 24.0).abs() < 1e-9);
        assert!((m.area() - 52.0).abs() < 1e-9);
    }

    #[test]
    fn empty_meshes_are_refused() {
        assert!(matches!(
            TriMesh::default().validate(),
            Err(MeshError::Empty { .. })
        ));
    }

    #[test]
    fn non_finite_vertices_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        m.vertices[3].y = f32::NAN;
        assert_eq!(m.validate(), Err(MeshError::NonFinite { vertex: 3 }));
        m.vertices[3].y = f32::INFINITY;
        assert_eq!(m.validate(), Err(MeshError::NonFinite { vertex: 3 }));
    }

    #[test]
    fn bad_indices_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        m.triangles[5][1] = 99;
        assert!(matches!(
            m.validate(),
            Err(MeshError::IndexOutOfRange {
                triangle: 5,
                index: 99,
                ..
            })
        ));
    }

    #[test]
    fn holes_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        m.triangles.pop();
        assert!(matches!(
            m.validate(),
            Err(MeshError::Open {
                boundary_edges: 3,
                ..
            })
        ));
    }

    #[test]
    fn flipped_triangles_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        m.triangles[0].swap(1, 2);
        assert!(matches!(
            m.validate(),
            Err(MeshError::InconsistentWinding { .. })
        ));
    }

    #[test]
    fn inside_out_meshes_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        assert!(matches!(m.validate(), Err(MeshError::Inverted { .. })));
    }

    #[test]
    fn degenerate_triangles_are_refused() {
        let mut m = cuboid(Vec3::ZERO, Vec3::ONE);
        m.triangles[0][1] = m.triangles[0][0];
        assert!(matches!(
            m.validate(),
            Err(MeshError::Degenerate { triangle: 0, .. })
        ));
    }

    #[test]
    fn edges_shared_by_four_triangles_are_non_manifold() {
        let a = cuboid(Vec3::ZERO, Vec3::ONE);
        // A second box sharing the edge x=1,y=1 (vertices 3 and 7 of `a`), glued by index.
        let mut b = cuboid(Vec3::ONE.with_z(0.0), Vec3::new(2.0, 2.0, 1.0));
        let offset = a.vertices.len() as u32;
        let mut m = a.clone();
        m.vertices.append(&mut b.vertices);
        for t in b.triangles {
            m.triangles.push(t.map(|i| match i {
                0 => 3,
                4 => 7,
                _ => i + offset,
            }));
        }
        assert!(
            matches!(m.validate(), Err(MeshError::NonManifold { .. })),
            "{:?}",
            m.validate()
        );
    }

    #[test]
    fn bow_tie_vertices_are_non_manifold() {
        let a = cuboid(Vec3::ZERO, Vec3::ONE);
        let b = cuboid(Vec3::ONE, Vec3::splat(2.0));
        // b's vertex 0 is a's vertex 7: glue them into one index.
        let offset = a.vertices.len() as u32;
        let mut m = a.clone();
        m.vertices.extend(b.vertices.iter().copied());
        for t in &b.triangles {
            m.triangles
                .push(t.map(|i| if i == 0 { 7 } else { i + offset }));
        }
        assert!(
            matches!(m.validate(), Err(MeshError::NonManifold { .. })),
            "{:?}",
            m.validate()
        );
    }

    #[test]
    fn self_intersection_is_found() {
        let a = cuboid(Vec3::ZERO, Vec3::ONE);
        let b = cuboid(Vec3::splat(0.5), Vec3::splat(1.5));
        let offset = a.vertices.len() as u32;
        let mut m = a.clone();
        m.vertices.extend(b.vertices.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|i| i + offset)));
        assert!(m.validate().is_ok());
        assert!(matches!(
            m.validate_solid(),
            Err(MeshError::SelfIntersecting { .. })
        ));
    }

    #[test]
    fn reordering_keeps_the_surface_and_numbers_vertices_by_first_use() {
        let mut m = cuboid(Vec3::ZERO, Vec3::new(2.0, 3.0, 4.0));
        // An unused vertex, dropped by the reorder.
        m.vertices.push(Vec3::splat(9.0));
        let order: Vec<u32> = (0..m.triangles.len() as u32).rev().collect();
        let r = m.in_triangle_order(&order);
        assert_eq!(r.vertices.len(), 8);
        assert_eq!(r.triangles.len(), m.triangles.len());
        assert!((r.validate_solid().unwrap().volume - 24.0).abs() < 1e-9);
        // Triangle k of the result is triangle order[k] of the input, same corners in turn.
        for (k, &t) in order.iter().enumerate() {
            assert_eq!(r.triangle(k), m.triangle(t as usize));
        }
        // First use numbers the vertices 0, 1, 2, … as the triangles are read.
        let mut next = 0;
        for &i in r.triangles.iter().flatten() {
            assert!(i <= next);
            next = next.max(i + 1);
        }
    }
}
