//! Plane sections of a closed mesh: how many closed loops a plane cuts (one for a section through
//! a single root, one per root below a furcation).

use std::collections::HashMap;

use glam::Vec3;

use super::TriMesh;

/// The number of closed loops in which the plane through `point` with normal `normal` cuts the
/// mesh. Vertices exactly on the plane count as above it, so every crossing is an edge crossing
/// and each loop is counted once; exact for a closed manifold mesh.
pub fn section_loops(mesh: &TriMesh, point: Vec3, normal: Vec3) -> usize {
    let side: Vec<bool> = mesh
        .vertices
        .iter()
        .map(|&v| (v - point).dot(normal) >= 0.0)
        .collect();
    // Each crossing edge is a node; each triangle that crosses links its two crossing edges.
    let mut ids: HashMap<(u32, u32), usize> = HashMap::new();
    let mut parent: Vec<usize> = Vec::new();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for t in &mesh.triangles {
        let mut crossing = Vec::with_capacity(2);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if side[a as usize] != side[b as usize] {
                let key = (a.min(b), a.max(b));
                let next = parent.len();
                let id = *ids.entry(key).or_insert(next);
                if id == next {
                    parent.push(next);
                }
                crossing.push(id);
            }
        }
        if let [x, y] = crossing[..] {
            let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
            parent[rx] = ry;
        }
    }
    (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_solid_is_cut_in_one_loop_and_two_solids_in_two() {
        // An octahedron, outward wound.
        let s = TriMesh::new(
            vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z],
            vec![
                [0, 2, 4],
                [2, 1, 4],
                [1, 3, 4],
                [3, 0, 4],
                [2, 0, 5],
                [1, 2, 5],
                [3, 1, 5],
                [0, 3, 5],
            ],
        );
        assert_eq!(section_loops(&s, Vec3::ZERO, Vec3::Y), 1);
        assert_eq!(section_loops(&s, Vec3::new(0.0, 2.0, 0.0), Vec3::Y), 0);
        let far = s.map_vertices(|v| v + Vec3::new(5.0, 0.0, 0.0));
        let mut two = s.clone();
        let n = two.vertices.len() as u32;
        two.vertices.extend(far.vertices);
        two.triangles
            .extend(far.triangles.iter().map(|t| t.map(|i| i + n)));
        assert_eq!(section_loops(&two, Vec3::new(0.0, 0.3, 0.0), Vec3::Y), 2);
    }
}
