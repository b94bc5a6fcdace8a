//! `VertexStars`: the triangles around each vertex of a mesh, and one vertex of each connected
//! piece, for walks over the surface (the exact stage's penetration search floods from the
//! triangles at a contact through them).

use super::TriMesh;

/// The triangles around each vertex (its star), in compressed rows, and one vertex of each piece
/// of the mesh connected through shared vertices.
#[derive(Clone, Debug, Default)]
pub struct VertexStars {
    /// Row starts: the star of vertex v is `triangles[offsets[v]..offsets[v + 1]]`.
    offsets: Vec<u32>,
    triangles: Vec<u32>,
    pieces: Vec<u32>,
}

impl VertexStars {
    /// The stars of `mesh`'s vertices (indices must be in range, as [`TriMesh::validate`] checks).
    pub fn of(mesh: &TriMesh) -> Self {
        let n = mesh.vertices.len();
        let mut offsets = vec![0u32; n + 1];
        for t in &mesh.triangles {
            for &v in t {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            offsets[v + 1] += offsets[v];
        }
        let mut fill = offsets.clone();
        let mut triangles = vec![0u32; offsets[n] as usize];
        for (i, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                triangles[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        let mut stars = Self {
            offsets,
            triangles,
            pieces: Vec::new(),
        };
        // One vertex of each piece: the first vertex not yet reached by a walk from the others.
        let mut seen = vec![false; n];
        let mut stack = Vec::new();
        for start in 0..n {
            if seen[start] {
                continue;
            }
            stars.pieces.push(start as u32);
            seen[start] = true;
            stack.push(start as u32);
            while let Some(v) = stack.pop() {
                for &t in stars.around(v as usize) {
                    for u in mesh.triangles[t as usize] {
                        if !seen[u as usize] {
                            seen[u as usize] = true;
                            stack.push(u);
                        }
                    }
                }
            }
        }
        stars
    }

    /// The triangles that have vertex `v` as a corner.
    #[inline]
    pub fn around(&self, v: usize) -> &[u32] {
        &self.triangles[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// One vertex of each connected piece of the mesh.
    pub fn pieces(&self) -> &[u32] {
        &self.pieces
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trimesh::tests::cuboid;
    use glam::Vec3;

    #[test]
    fn stars_list_each_triangle_at_its_corners() {
        let mut mesh = cuboid(Vec3::ZERO, Vec3::ONE);
        let stars = VertexStars::of(&mesh);
        for (v, _) in mesh.vertices.iter().enumerate() {
            let expected: Vec<u32> = (0..mesh.triangles.len() as u32)
                .filter(|&t| mesh.triangles[t as usize].contains(&(v as u32)))
                .collect();
            assert_eq!(stars.around(v), expected, "vertex {v}");
        }
        assert_eq!(stars.pieces(), [0]);
        // A second box, apart: two pieces, the second starting at its first vertex.
        let other = cuboid(Vec3::splat(3.0), Vec3::splat(4.0));
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(other.vertices);
        mesh.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
        assert_eq!(VertexStars::of(&mesh).pieces(), [0, base]);
    }
}
