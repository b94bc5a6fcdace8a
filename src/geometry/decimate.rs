//! Mesh simplification by quadric error metrics (Garland and Heckbert 1997), with guards that keep
//! a closed manifold mesh closed, manifold and free of folds.
//!
//! Guarantee: the output is closed and manifold whenever the input is (edge collapses are taken only
//! when the link condition holds). With a `star_centre`, every output triangle faces away from that
//! point, so a mesh that is star-shaped about it (every ray from the centre crosses the surface
//! once) stays star-shaped, which rules out self-intersection.

use std::{cmp::Ordering, collections::BinaryHeap};

use glam::{DMat3, DVec3, Vec3};

use super::trimesh::TriMesh;

/// Settings for [`decimate`].
#[derive(Clone, Copy, Debug)]
pub struct DecimateOptions {
    /// Stop when this many vertices remain.
    pub target_vertices: usize,
    /// Keep every triangle oriented outward as seen from this point (for star-shaped meshes).
    pub star_centre: Option<Vec3>,
    /// Smallest allowed triangle quality (1 = equilateral, 0 = degenerate).
    pub min_quality: f64,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            target_vertices: 125,
            star_centre: None,
            min_quality: 0.08,
        }
    }
}

/// A symmetric 4×4 quadric stored as its ten distinct entries.
#[derive(Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: DVec3, d: f64) -> Self {
        let (a, b, c) = (n.x, n.y, n.z);
        Self([
            a * a,
            a * b,
            a * c,
            a * d,
            b * b,
            b * c,
            b * d,
            c * c,
            c * d,
            d * d,
        ])
    }

    fn add(&self, o: &Self) -> Self {
        let mut r = [0.0; 10];
        for (k, r) in r.iter_mut().enumerate() {
            *r = self.0[k] + o.0[k];
        }
        Self(r)
    }

    fn error(&self, p: DVec3) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }

    /// The point minimising the error, when the system is well conditioned.
    fn minimiser(&self) -> Option<DVec3> {
        let q = &self.0;
        let m = DMat3::from_cols(
            DVec3::new(q[0], q[1], q[2]),
            DVec3::new(q[1], q[4], q[5]),
            DVec3::new(q[2], q[5], q[7]),
        );
        let det = m.determinant();
        let scale = (q[0] + q[4] + q[7]).powi(3);
        (det.abs() > 1e-9 * scale.max(1e-300)).then(|| m.inverse() * -DVec3::new(q[3], q[6], q[8]))
    }
}

#[derive(PartialEq)]
struct Candidate {
    cost: f64,
    u: u32,
    v: u32,
    stamp: (u32, u32),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost.total_cmp(&self.cost)
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

struct State {
    pos: Vec<DVec3>,
    quadric: Vec<Quadric>,
    faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    vertex_faces: Vec<Vec<u32>>,
    vertex_alive: Vec<bool>,
    stamp: Vec<u32>,
    edge_weight: f64,
    opts: DecimateOptions,
}

/// Simplifies a closed manifold mesh to about `opts.target_vertices` vertices (fewer collapses may
/// be possible when the guards refuse them; the result then has more vertices than asked).
pub fn decimate(mesh: &TriMesh, opts: DecimateOptions) -> TriMesh {
    let pos: Vec<DVec3> = mesh.vertices.iter().map(|v| v.as_dvec3()).collect();
    let mut vertex_faces = vec![Vec::new(); pos.len()];
    let mut quadric = vec![Quadric::default(); pos.len()];
    let mut mean_edge = 0.0;
    for (f, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        let n = (b - a).cross(c - a);
        let area = 0.5 * n.length();
        let n = n.normalize_or_zero();
        let q = Quadric::plane(n, -n.dot(a));
        let q = Quadric(q.0.map(|x| x * area));
        for &v in t {
            vertex_faces[v as usize].push(f as u32);
            quadric[v as usize] = quadric[v as usize].add(&q);
        }
        mean_edge += (b - a).length();
    }
    mean_edge /= mesh.triangles.len().max(1) as f64;
    let mut s = State {
        pos,
        quadric,
        faces: mesh.triangles.clone(),
        face_alive: vec![true; mesh.triangles.len()],
        vertex_faces,
        vertex_alive: vec![true; mesh.vertices.len()],
        stamp: vec![0; mesh.vertices.len()],
        // A small edge-length term spreads vertices over flat regions instead of leaving slivers.
        edge_weight: 0.05 * mean_edge * mean_edge,
        opts,
    };
    let mut heap = BinaryHeap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            if u < v {
                s.push(&mut heap, u, v);
            }
        }
    }
    let mut alive = mesh.vertices.len();
    while alive > opts.target_vertices.max(4) {
        let Some(c) = heap.pop() else { break };
        if !s.vertex_alive[c.u as usize]
            || !s.vertex_alive[c.v as usize]
            || (s.stamp[c.u as usize], s.stamp[c.v as usize]) != c.stamp
        {
            continue;
        }
        if s.collapse(c.u, c.v) {
            alive -= 1;
            for w in s.neighbours(c.u) {
                let (a, b) = (c.u.min(w), c.u.max(w));
                s.push(&mut heap, a, b);
            }
        }
    }
    s.compact()
}

impl State {
    fn positions(&self, u: u32, v: u32) -> Vec<DVec3> {
        let q = self.quadric[u as usize].add(&self.quadric[v as usize]);
        let (pu, pv) = (self.pos[u as usize], self.pos[v as usize]);
        let mut c = vec![pu, pv, (pu + pv) * 0.5];
        if let Some(m) = q.minimiser() {
            // Keep the optimum only when it stays near the edge.
            if (m - (pu + pv) * 0.5).length() <= (pu - pv).length() {
                c.push(m);
            }
        }
        c
    }

    fn cost(&self, u: u32, v: u32, p: DVec3) -> f64 {
        let q = self.quadric[u as usize].add(&self.quadric[v as usize]);
        let len2 = (self.pos[u as usize] - self.pos[v as usize]).length_squared();
        q.error(p).max(0.0) + self.edge_weight * len2
    }

    fn push(&self, heap: &mut BinaryHeap<Candidate>, u: u32, v: u32) {
        let cost = self
            .positions(u, v)
            .into_iter()
            .map(|p| self.cost(u, v, p))
            .fold(f64::INFINITY, f64::min);
        heap.push(Candidate {
            cost,
            u,
            v,
            stamp: (self.stamp[u as usize], self.stamp[v as usize]),
        });
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.vertex_faces[v as usize]
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// Collapses edge (u, v) into u at the best valid position; false when no position is valid.
    fn collapse(&mut self, u: u32, v: u32) -> bool {
        // Link condition: common neighbours are exactly the two apexes of the edge's faces.
        let nu = self.neighbours(u);
        let nv = self.neighbours(v);
        let common = nu.iter().filter(|w| nv.binary_search(w).is_ok()).count();
        let shared: Vec<u32> = self.vertex_faces[u as usize]
            .iter()
            .copied()
            .filter(|&f| self.faces[f as usize].contains(&v))
            .collect();
        if shared.len() != 2 || common != 2 || nu.len() + nv.len() <= 6 {
            return false;
        }
        let mut options: Vec<(f64, DVec3)> = self
            .positions(u, v)
            .into_iter()
            .map(|p| (self.cost(u, v, p), p))
            .collect();
        options.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(p) = options
            .into_iter()
            .map(|o| o.1)
            .find(|&p| self.valid(u, v, p))
        else {
            return false;
        };
        for &f in &shared {
            self.face_alive[f as usize] = false;
        }
        let moved: Vec<u32> = self.vertex_faces[v as usize].clone();
        for f in moved {
            if !self.face_alive[f as usize] {
                continue;
            }
            for x in self.faces[f as usize].iter_mut() {
                if *x == v {
                    *x = u;
                }
            }
            self.vertex_faces[u as usize].push(f);
        }
        for w in self.faces_of_edge_apexes(&shared) {
            self.vertex_faces[w as usize].retain(|f| !shared.contains(f));
        }
        let faces = std::mem::take(&mut self.vertex_faces[u as usize]);
        self.vertex_faces[u as usize] = faces
            .into_iter()
            .filter(|&f| self.face_alive[f as usize])
            .collect();
        self.vertex_faces[v as usize].clear();
        self.vertex_alive[v as usize] = false;
        self.pos[u as usize] = p;
        self.quadric[u as usize] = self.quadric[u as usize].add(&self.quadric[v as usize]);
        self.stamp[u as usize] += 1;
        true
    }

    fn faces_of_edge_apexes(&self, shared: &[u32]) -> Vec<u32> {
        shared
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .collect()
    }

    /// Would moving u and v to p keep every surviving face well shaped and unflipped?
    fn valid(&self, u: u32, v: u32, p: DVec3) -> bool {
        for &w in &[u, v] {
            for &f in &self.vertex_faces[w as usize] {
                let face = self.faces[f as usize];
                if !self.face_alive[f as usize] || (face.contains(&u) && face.contains(&v)) {
                    continue;
                }
                let old = face.map(|i| self.pos[i as usize]);
                let new = face.map(|i| {
                    if i == u || i == v {
                        p
                    } else {
                        self.pos[i as usize]
                    }
                });
                let n_old = (old[1] - old[0]).cross(old[2] - old[0]);
                let n_new = (new[1] - new[0]).cross(new[2] - new[0]);
                if n_new.dot(n_old) <= 0.2 * n_new.length() * n_old.length() {
                    return false;
                }
                if quality(&new) < self.opts.min_quality.min(quality(&old) * 0.9) {
                    return false;
                }
                if let Some(c) = self.opts.star_centre {
                    let c = c.as_dvec3();
                    let det = (new[0] - c).dot((new[1] - c).cross(new[2] - c));
                    let scale =
                        (new[0] - c).length() * (new[1] - c).length() * (new[2] - c).length();
                    if det <= 1e-4 * scale {
                        return false;
                    }
                }
            }
        }
        true
    }

    fn compact(&self) -> TriMesh {
        let mut remap = vec![u32::MAX; self.pos.len()];
        let mut vertices = Vec::new();
        for (i, &alive) in self.vertex_alive.iter().enumerate() {
            if alive && !self.vertex_faces[i].is_empty() {
                remap[i] = vertices.len() as u32;
                vertices.push(self.pos[i].as_vec3());
            }
        }
        let triangles = self
            .faces
            .iter()
            .zip(&self.face_alive)
            .filter(|(_, a)| **a)
            .map(|(f, _)| f.map(|i| remap[i as usize]))
            .collect();
        TriMesh::new(vertices, triangles)
    }
}

/// Triangle quality: 4√3·area / (sum of squared edges); 1 for equilateral, 0 for degenerate.
fn quality(t: &[DVec3; 3]) -> f64 {
    let area2 = (t[1] - t[0]).cross(t[2] - t[0]).length();
    let edges = (t[1] - t[0]).length_squared()
        + (t[2] - t[1]).length_squared()
        + (t[0] - t[2]).length_squared();
    if edges <= 0.0 {
        return 0.0;
    }
    2.0 * 3f64.sqrt() * area2 / edges
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A UV sphere of radius r with `rings` latitude rings of `segments` vertices.
    fn uv_sphere(r: f32, rings: usize, segments: usize) -> TriMesh {
        let mut v = vec![Vec3::Y * r];
        for i in 1..=rings {
            let phi = std::f32::consts::PI * i as f32 / (rings + 1) as f32;
            for j in 0..segments {
                let th = std::f32::consts::TAU * j as f32 / segments as f32;
                v.push(r * Vec3::new(phi.sin() * th.cos(), phi.cos(), phi.sin() * th.sin()));
            }
        }
        v.push(-Vec3::Y * r);
        let s = segments as u32;
        let idx = |i: usize, j: u32| 1 + (i as u32) * s + (j % s);
        let mut t = Vec::new();
        for j in 0..s {
            t.push([0, idx(0, j + 1), idx(0, j)]);
        }
        for i in 0..rings - 1 {
            for j in 0..s {
                t.push([idx(i, j), idx(i, j + 1), idx(i + 1, j + 1)]);
                t.push([idx(i, j), idx(i + 1, j + 1), idx(i + 1, j)]);
            }
        }
        let last = v.len() as u32 - 1;
        for j in 0..s {
            t.push([last, idx(rings - 1, j), idx(rings - 1, j + 1)]);
        }
        TriMesh::new(v, t)
    }

    #[test]
    fn a_sphere_decimates_to_a_valid_closed_mesh() {
        let sphere = uv_sphere(5.0, 30, 40);
        let volume = sphere.validate_solid().unwrap().volume;
        let out = decimate(
            &sphere,
            DecimateOptions {
                target_vertices: 120,
                star_centre: Some(Vec3::ZERO),
                ..Default::default()
            },
        );
        let r = out.validate_solid().unwrap();
        assert!(r.vertices <= 130, "{} vertices left", r.vertices);
        assert!(
            (r.volume - volume).abs() < 0.15 * volume,
            "{} vs {volume}",
            r.volume
        );
        for (i, t) in out.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|k| out.vertices[k as usize]);
            assert!(a.dot(b.cross(c)) > 0.0, "triangle {i} faces the centre");
        }
    }
}
