//! Closed surfaces from sampled fields: marching tetrahedra on a regular grid.
//!
//! Each cube of the grid is cut into six tetrahedra about its main diagonal (the Kuhn
//! triangulation, which is conforming: neighbouring cubes cut their shared face along the same
//! diagonal). In each tetrahedron whose corners change sign the zero set is one triangle or a quad
//! (two triangles split along the diagonal between opposite edges, which is interior to the
//! tetrahedron), through points interpolated linearly on the crossed edges; a crossing point is
//! shared by every tetrahedron around its grid edge.
//!
//! Guarantee: when every value on the grid's outer layer is positive (outside), the result is a
//! closed, 2-manifold, consistently outward-wound surface. In exact arithmetic it does not meet
//! itself either: each triangle lies in its tetrahedron, the tetrahedra meet only on shared faces,
//! and there the pieces on either side meet along the same segment. Values of zero count as
//! outside; a crossing is kept [`MIN_T`] of an edge away from its corners so no triangle
//! collapses to a point.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use super::TriMesh;

/// A crossing is placed at least this fraction of its edge from either corner.
pub const MIN_T: f32 = 1e-3;

/// A regular grid of samples: point (i, j, k) is `origin + cell · (i, j, k)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleGrid {
    /// The point of sample (0, 0, 0).
    pub origin: Vec3,
    /// Spacing (mm).
    pub cell: f32,
    /// Samples along x, y and z.
    pub dims: [usize; 3],
}

impl SampleGrid {
    /// The number of the sample (i, j, k) in a field laid out x fastest, then y, then z.
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// The position of sample (i, j, k).
    pub fn point(&self, i: usize, j: usize, k: usize) -> Vec3 {
        self.origin + self.cell * Vec3::new(i as f32, j as f32, k as f32)
    }

    /// Samples in all.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// True when the grid has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Cube corners by bits (x = 1, y = 2, z = 4).
const CORNERS: [[usize; 3]; 8] = [
    [0, 0, 0],
    [1, 0, 0],
    [0, 1, 0],
    [1, 1, 0],
    [0, 0, 1],
    [1, 0, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// The six tetrahedra of a cube about its diagonal 0–7.
const TETRAHEDRA: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 3, 2, 7],
    [0, 2, 6, 7],
    [0, 6, 4, 7],
    [0, 4, 5, 7],
    [0, 5, 1, 7],
];

/// The zero set of `values` (one per sample of `grid`, negative inside) as a triangle mesh (see
/// the module doc for what is guaranteed).
///
/// # Panics
/// When `values` does not hold one value per sample.
pub fn marching_tetrahedra(grid: &SampleGrid, values: &[f32]) -> TriMesh {
    assert_eq!(values.len(), grid.len(), "one value per sample");
    let [nx, ny, nz] = grid.dims;
    let inside = |v: f32| v < 0.0;
    let mut mesh = TriMesh::default();
    let mut crossings: HashMap<(u32, u32), u32> = HashMap::new();
    if nx < 2 || ny < 2 || nz < 2 {
        return mesh;
    }
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let ids = CORNERS.map(|[a, b, c]| grid.index(i + a, j + b, k + c));
                let first = inside(values[ids[0]]);
                if ids.iter().all(|&n| inside(values[n]) == first) {
                    continue;
                }
                for tet in TETRAHEDRA {
                    let corners = tet.map(|c| ids[c]);
                    let (ins, outs): (Vec<usize>, Vec<usize>) =
                        corners.iter().partition(|&&n| inside(values[n]));
                    if ins.is_empty() || outs.is_empty() {
                        continue;
                    }
                    let mut point = |a: usize, b: usize| {
                        crossing(grid, values, &mut mesh, &mut crossings, a, b)
                    };
                    let away = centre(grid, &outs) - centre(grid, &ins);
                    match (ins.len(), outs.len()) {
                        (1, 3) => {
                            let t = [
                                point(ins[0], outs[0]),
                                point(ins[0], outs[1]),
                                point(ins[0], outs[2]),
                            ];
                            push_facing(&mut mesh, t, away);
                        }
                        (3, 1) => {
                            let t = [
                                point(ins[0], outs[0]),
                                point(ins[1], outs[0]),
                                point(ins[2], outs[0]),
                            ];
                            push_facing(&mut mesh, t, away);
                        }
                        _ => {
                            // Quad ac, ad, bd, bc (cyclic), split along ac–bd.
                            let (a, b, c, d) = (ins[0], ins[1], outs[0], outs[1]);
                            let (ac, ad, bd, bc) =
                                (point(a, c), point(a, d), point(b, d), point(b, c));
                            push_facing(&mut mesh, [ac, ad, bd], away);
                            push_facing(&mut mesh, [ac, bd, bc], away);
                        }
                    }
                }
            }
        }
    }
    mesh
}

/// The mean position of some samples (by number), in f64.
fn centre(grid: &SampleGrid, samples: &[usize]) -> DVec3 {
    let [nx, ny, _] = grid.dims;
    let sum: DVec3 = samples
        .iter()
        .map(|&n| grid.point(n % nx, (n / nx) % ny, n / (nx * ny)).as_dvec3())
        .sum();
    sum / samples.len() as f64
}

/// The vertex where the field crosses zero on the edge between samples `a` and `b`, made once.
fn crossing(
    grid: &SampleGrid,
    values: &[f32],
    mesh: &mut TriMesh,
    made: &mut HashMap<(u32, u32), u32>,
    a: usize,
    b: usize,
) -> u32 {
    let key = (a.min(b) as u32, a.max(b) as u32);
    *made.entry(key).or_insert_with(|| {
        let (lo, hi) = (key.0 as usize, key.1 as usize);
        let (va, vb) = (values[lo], values[hi]);
        let t = (va / (va - vb)).clamp(MIN_T, 1.0 - MIN_T);
        let [nx, ny, _] = grid.dims;
        let at = |n: usize| grid.point(n % nx, (n / nx) % ny, n / (nx * ny));
        let (p, q) = (at(lo), at(hi));
        mesh.vertices.push(p + (q - p) * t);
        (mesh.vertices.len() - 1) as u32
    })
}

/// Adds the triangle wound so that its normal points along `away` (from inside to outside).
fn push_facing(mesh: &mut TriMesh, t: [u32; 3], away: DVec3) {
    let [a, b, c] = t.map(|i| mesh.vertices[i as usize].as_dvec3());
    let n = (b - a).cross(c - a);
    if n.dot(away) >= 0.0 {
        mesh.triangles.push(t);
    } else {
        mesh.triangles.push([t[0], t[2], t[1]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere_field(radius: f32, centre: Vec3, cell: f32) -> (SampleGrid, Vec<f32>) {
        let n = (2.0 * radius / cell).ceil() as usize + 5;
        let grid = SampleGrid {
            origin: centre - Vec3::splat(cell * (n as f32 - 1.0) / 2.0),
            cell,
            dims: [n, n, n],
        };
        let mut values = vec![0.0; grid.len()];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    values[grid.index(i, j, k)] = grid.point(i, j, k).distance(centre) - radius;
                }
            }
        }
        (grid, values)
    }

    #[test]
    fn a_sphere_becomes_a_closed_outward_surface_near_it() {
        let centre = Vec3::new(0.31, -0.17, 0.05);
        for cell in [0.5, 0.23] {
            let (grid, values) = sphere_field(3.0, centre, cell);
            let mesh = marching_tetrahedra(&grid, &values);
            mesh.validate_solid()
                .expect("closed, manifold, no crossing");
            let volume = mesh.signed_volume();
            let exact = 4.0 / 3.0 * std::f64::consts::PI * 27.0;
            assert!(volume > 0.0, "outward");
            assert!((volume / exact - 1.0).abs() < 0.05, "{volume} vs {exact}");
            for v in &mesh.vertices {
                let off = (v.distance(centre) - 3.0).abs();
                assert!(off < 0.1 * cell + 0.01, "{off} at cell {cell}");
            }
        }
    }

    #[test]
    fn samples_on_the_surface_and_touching_shells_stay_manifold() {
        // Two balls whose surfaces pass through samples and touch at one sample: zeros count as
        // outside, so the two stay apart, each closed.
        let grid = SampleGrid {
            origin: Vec3::ZERO,
            cell: 1.0,
            dims: [12, 8, 8],
        };
        let mut values = vec![1.0; grid.len()];
        for k in 0..8 {
            for j in 0..8 {
                for i in 0..12 {
                    let p = grid.point(i, j, k);
                    let a = p.distance(Vec3::new(3.0, 3.5, 3.5)) - 2.5;
                    let b = p.distance(Vec3::new(8.0, 3.5, 3.5)) - 2.5;
                    values[grid.index(i, j, k)] = a.min(b).round();
                }
            }
        }
        let mesh = marching_tetrahedra(&grid, &values);
        mesh.validate_solid()
            .expect("closed, manifold, no crossing");
        let (_, pieces) = mesh.edge_pieces();
        assert_eq!(pieces, 2);
    }

    #[test]
    fn a_field_with_no_sign_change_gives_nothing() {
        let grid = SampleGrid {
            origin: Vec3::ZERO,
            cell: 1.0,
            dims: [3, 3, 3],
        };
        assert!(marching_tetrahedra(&grid, &[1.0; 27]).triangles.is_empty());
        let tiny = SampleGrid {
            dims: [1, 3, 3],
            ..grid
        };
        assert!(marching_tetrahedra(&tiny, &[-1.0; 9]).triangles.is_empty());
    }
}
