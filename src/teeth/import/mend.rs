//! Mending what real scans contain: fins on non-manifold edges, bow-tie vertices and spikes.
//!
//! Each repair changes the surface only where the defect is: fins lose their triangles (the hole
//! left behind is closed with the other holes), a bow-tie vertex gets one copy per fan, each moved
//! [`SPLIT_NUDGE`] of its fan's size towards the fan so the fans no longer touch, and a spike's tip
//! moves to the centroid of its neighbours.

use std::collections::HashMap;

use glam::Vec3;

/// How far (as a fraction of the fan's mean edge) a split vertex's copy moves into its own fan.
pub const SPLIT_NUDGE: f32 = 0.02;
/// A vertex whose incident triangles' angles at it sum to less than this (radians) may be a
/// spike: a needle sharper than a cone of 14.5° half-angle, which no tooth surface has.
pub const SPIKE_ANGLE_SUM: f32 = std::f32::consts::FRAC_PI_2;

/// A spike also stands out of its ring of neighbours by more than this many times the ring's
/// radius (a sharp but short feature, such as an incisal corner, does not).
pub const SPIKE_HEIGHT: f32 = 2.0;

/// Drops every triangle on an edge shared by more than two triangles. Returns how many.
pub(super) fn drop_fins(triangles: &mut Vec<[u32; 3]>) -> usize {
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
    for t in triangles.iter() {
        for k in 0..3 {
            *count.entry(undirected(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let before = triangles.len();
    triangles.retain(|t| (0..3).all(|k| count[&undirected(t[k], t[(k + 1) % 3])] <= 2));
    before - triangles.len()
}

fn undirected(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Gives each fan of triangles around a vertex its own vertex (a vertex where fans meet only at
/// the point is not manifold). The first fan keeps the vertex; the others get copies moved a little
/// into their fans. Returns each split vertex's place and how far its copies moved (mm).
pub(super) fn split_bowties(vertices: &mut Vec<Vec3>, triangles: &mut [[u32; 3]]) -> Vec<[f32; 4]> {
    // Corners (triangle, slot) of the same vertex are in one fan when their triangles share an
    // edge through the vertex.
    let corners = triangles.len() * 3;
    let mut parent: Vec<usize> = (0..corners).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut edge_corners: HashMap<(u32, u32), Vec<(usize, usize)>> =
        HashMap::with_capacity(triangles.len() * 2);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edge_corners
                .entry(undirected(a, b))
                .or_default()
                .push((t * 3 + k, t * 3 + (k + 1) % 3));
        }
    }
    for list in edge_corners.values() {
        if let [(a0, b0), (a1, b1)] = list.as_slice() {
            // The two triangles may run the edge either way: join corners of equal vertices.
            let v = |c: usize| triangles[c / 3][c % 3];
            for &x in &[*a0, *b0] {
                for &y in &[*a1, *b1] {
                    if v(x) == v(y) {
                        let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
                        parent[rx] = ry;
                    }
                }
            }
        }
    }
    let mut fans: HashMap<u32, Vec<usize>> = HashMap::new();
    let mut fan_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for c in 0..corners {
        let root = find(&mut parent, c);
        let list = fan_of.entry(root).or_default();
        if list.is_empty() {
            fans.entry(triangles[c / 3][c % 3]).or_default().push(root);
        }
        list.push(c);
    }
    let mut places = Vec::new();
    let mut keys: Vec<u32> = fans.keys().copied().filter(|v| fans[v].len() > 1).collect();
    keys.sort_unstable();
    for v in keys {
        let roots = fans[&v].clone();
        let origin = vertices[v as usize];
        let mut reach = 0.0f32;
        for (n, root) in roots.iter().enumerate() {
            let fan = &fan_of[root];
            // Move towards the fan's mean opposite point by a small share of its mean edge.
            let p = vertices[v as usize];
            let mut toward = Vec3::ZERO;
            let mut edge = 0.0;
            for &c in fan {
                let tri = triangles[c / 3];
                for k in 1..3 {
                    let q = vertices[tri[(c % 3 + k) % 3] as usize];
                    toward += q;
                    edge += q.distance(p);
                }
            }
            let m = (fan.len() * 2) as f32;
            let dir = (toward / m - p).normalize_or_zero();
            let moved = p + dir * (edge / m) * SPLIT_NUDGE;
            reach = reach.max(moved.distance(origin));
            let index = if n == 0 {
                vertices[v as usize] = moved;
                v
            } else {
                vertices.push(moved);
                (vertices.len() - 1) as u32
            };
            for &c in fan {
                triangles[c / 3][c % 3] = index;
            }
        }
        places.push([origin.x, origin.y, origin.z, reach]);
    }
    places
}

/// Moves each spike's tip (an interior vertex whose triangles' angles at it sum to less than
/// [`SPIKE_ANGLE_SUM`] and which stands [`SPIKE_HEIGHT`] ring radii out of its neighbours) to the
/// centroid of its neighbours. Returns each tip's place and how far it moved (mm).
pub(super) fn smooth_spikes(vertices: &mut [Vec3], triangles: &[[u32; 3]]) -> Vec<[f32; 4]> {
    let n = vertices.len();
    let mut angle = vec![0.0f32; n];
    let mut sum = vec![Vec3::ZERO; n];
    let mut degree = vec![0u32; n];
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
    for t in triangles {
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let (p, pa, pb) = (
                vertices[v as usize],
                vertices[a as usize],
                vertices[b as usize],
            );
            angle[v as usize] += (pa - p).angle_between(pb - p);
            sum[v as usize] += pa + pb;
            degree[v as usize] += 2;
            *directed.entry((v, a)).or_default() += 1;
        }
    }
    // Boundary vertices (an edge without its reverse) are not judged: their angle sums are partial.
    let mut boundary = vec![false; n];
    for &(a, b) in directed.keys() {
        if !directed.contains_key(&(b, a)) {
            boundary[a as usize] = true;
            boundary[b as usize] = true;
        }
    }
    // The ring's spread: mean distance of the neighbours (counted twice) from their centroid.
    let mut spread = vec![0.0f32; n];
    for t in triangles {
        for k in 0..3 {
            let v = t[k] as usize;
            let centroid = sum[v] / degree[v] as f32;
            for j in 1..3 {
                spread[v] += vertices[t[(k + j) % 3] as usize].distance(centroid);
            }
        }
    }
    let mut moved = Vec::new();
    for v in 0..n {
        if degree[v] < 6 || boundary[v] || angle[v] >= SPIKE_ANGLE_SUM {
            continue;
        }
        let centroid = sum[v] / degree[v] as f32;
        let tip = vertices[v];
        if tip.distance(centroid) > SPIKE_HEIGHT * spread[v] / degree[v] as f32 {
            vertices[v] = centroid;
            moved.push([tip.x, tip.y, tip.z, tip.distance(centroid)]);
        }
    }
    moved
}
