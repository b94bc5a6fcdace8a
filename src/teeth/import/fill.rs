//! Closing holes: the triangulation of least area spanning the hole's boundary.
//!
//! A fan from the centroid folds over itself when a hole is not flat or not convex (a scan's holes
//! are neither); the least-area triangulation over the boundary's own vertices (dynamic
//! programming, O(n³) in the boundary's vertices) follows the boundary's shape instead. Boundaries
//! longer than [`MAX_DP_VERTICES`] are closed by a fan from the centroid (such holes are rare and
//! the self-intersection check after closing catches a fan that folds).

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::repair::loop_centroid;
use crate::geometry::TriMesh;

/// Longest boundary (in vertices) filled by the least-area triangulation.
pub const MAX_DP_VERTICES: usize = 400;

/// Closes the hole `l` (vertex indices in the direction its edges run in their triangles) with
/// triangles wound to match the surrounding surface.
pub(super) fn fill_hole(mesh: &mut TriMesh, l: &[u32]) {
    let n = l.len();
    if n < 3 {
        return;
    }
    if n > MAX_DP_VERTICES {
        fan(mesh, l);
        return;
    }
    let p: Vec<DVec3> = l
        .iter()
        .map(|&i| mesh.vertices[i as usize].as_dvec3())
        .collect();
    // A chord that is already an edge of the surface would give that edge four triangles.
    let position: HashMap<u32, usize> = l.iter().enumerate().map(|(k, &v)| (v, k)).collect();
    let mut existing: HashSet<(usize, usize)> = HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            if let (Some(&a), Some(&b)) = (position.get(&t[k]), position.get(&t[(k + 1) % 3])) {
                existing.insert((a.min(b), a.max(b)));
            }
        }
    }
    let blocked =
        |i: usize, j: usize| j > i + 1 && !(i == 0 && j == n - 1) && existing.contains(&(i, j));
    let size = p.iter().map(|q| q.distance(p[0])).fold(0.0, f64::max);
    // A degenerate triangle (collinear boundary points) costs more than any real closing.
    let degenerate = 1e-9 * size * size;
    let area = |i: usize, k: usize, j: usize| {
        let a = 0.5 * (p[k] - p[i]).cross(p[j] - p[i]).length();
        if a <= degenerate {
            a + 1e6 * size * size
        } else {
            a
        }
    };
    // cost[i][j]: least area closing the boundary from i to j with the chord (i, j).
    let mut cost = vec![0.0f64; n * n];
    let mut split = vec![0usize; n * n];
    for gap in 2..n {
        for i in 0..n - gap {
            let j = i + gap;
            let mut best = f64::INFINITY;
            let mut best_k = i + 1;
            if blocked(i, j) {
                cost[i * n + j] = f64::INFINITY;
                continue;
            }
            for k in i + 1..j {
                let c = cost[i * n + k] + cost[k * n + j] + area(i, k, j);
                if c < best {
                    best = c;
                    best_k = k;
                }
            }
            cost[i * n + j] = best;
            split[i * n + j] = best_k;
        }
    }
    if !cost[n - 1].is_finite() {
        // Every triangulation over the boundary reuses an edge: close with a fan instead.
        fan(mesh, l);
        return;
    }
    let mut stack = vec![(0usize, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j < i + 2 {
            continue;
        }
        let k = split[i * n + j];
        // The boundary runs i → k → j; the new triangle runs it the other way.
        mesh.triangles.push([l[j], l[k], l[i]]);
        stack.push((i, k));
        stack.push((k, j));
    }
}

/// Closes a hole with a fan from its centroid.
fn fan(mesh: &mut TriMesh, l: &[u32]) {
    let c = mesh.vertices.len() as u32;
    mesh.vertices.push(loop_centroid(mesh, l));
    for i in 0..l.len() {
        let (a, b) = (l[i], l[(i + 1) % l.len()]);
        mesh.triangles.push([b, a, c]);
    }
}
