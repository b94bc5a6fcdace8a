//! Phase 1 of the medial builder: the surface split into pieces with their corners numbered once,
//! the medial seeds spread by area, and the lattice of points on each piece that shrinking and
//! polishing work on.

use glam::Vec3;

use crate::{geometry::TriMesh, sphere_tree::coverage::split4};

/// Most pieces (finer budgets get coarser pieces than `PIECE_EDGE`).
pub(super) const MAX_PIECES: usize = 60_000;

/// Medial seeds per leaf of the budget.
pub(super) const SEEDS_PER_LEAF: usize = 5;

/// Most medial seeds.
pub(super) const MAX_SEEDS: usize = 6_000;

/// Surface pieces (corners, centroid, face normal, area), and their corners numbered once:
/// pieces that share a corner (bit for bit, as `split4` gives neighbours) share its number.
pub(super) struct Pieces {
    pub(super) corners: Vec<[Vec3; 3]>,
    pub(super) corner_id: Vec<[u32; 3]>,
    pub(super) corner_at: Vec<Vec3>,
    pub(super) centroid: Vec<Vec3>,
    pub(super) normal: Vec<Vec3>,
    pub(super) area: Vec<f32>,
}

pub(super) fn edge_max(t: &[Vec3; 3]) -> f32 {
    t[0].distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]))
}

pub(super) fn split_surface(mesh: &TriMesh, edge: f32) -> Pieces {
    let levels = |edge: f32| -> Vec<u32> {
        (0..mesh.triangles.len())
            .map(|t| {
                let e = edge_max(&mesh.triangle(t));
                if e <= edge || edge <= 0.0 {
                    0
                } else {
                    ((e / edge).log2().ceil() as u32).min(8)
                }
            })
            .collect()
    };
    let mut edge = edge;
    let mut lv = levels(edge);
    while lv.iter().map(|&l| 4usize.pow(l)).sum::<usize>() > MAX_PIECES {
        edge *= 1.5;
        lv = levels(edge);
    }
    let mut p = Pieces {
        corners: Vec::new(),
        corner_id: Vec::new(),
        corner_at: Vec::new(),
        centroid: Vec::new(),
        normal: Vec::new(),
        area: Vec::new(),
    };
    let mut ids: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    for (t, &level) in lv.iter().enumerate() {
        let tri = mesh.triangle(t);
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
        let mut stack = vec![(tri, 0u32)];
        while let Some((piece, l)) = stack.pop() {
            if l < level {
                stack.extend(split4(piece).map(|s| (s, l + 1)));
                continue;
            }
            p.corners.push(piece);
            p.corner_id.push(piece.map(|q| {
                let next = ids.len() as u32;
                *ids.entry(q.to_array().map(f32::to_bits))
                    .or_insert_with(|| {
                        p.corner_at.push(q);
                        next
                    })
            }));
            p.centroid.push((piece[0] + piece[1] + piece[2]) / 3.0);
            p.normal.push(normal);
            p.area
                .push(0.5 * (piece[1] - piece[0]).cross(piece[2] - piece[0]).length());
        }
    }
    p
}

/// The medial seeds: `SEEDS_PER_LEAF` per leaf of the budget (at most `MAX_SEEDS`), pieces
/// spread evenly by area (`area` is the surface's).
pub(super) fn seeds_by_area(pieces: &Pieces, area: f32, max_leaves: usize) -> Vec<usize> {
    let n_seeds = (SEEDS_PER_LEAF * max_leaves)
        .min(MAX_SEEDS)
        .min(pieces.corners.len());
    let mut seeds = Vec::with_capacity(n_seeds);
    let mut carry = 0.0f32;
    for (i, &a) in pieces.area.iter().enumerate() {
        carry += a / area * n_seeds as f32;
        if carry >= 1.0 {
            carry -= 1.0;
            seeds.push(i);
        }
    }
    seeds
}

/// A lattice point: a piece corner, a point inside the edge from corner `from` to corner `to`
/// (`step` of n steps from `from`), or a point inside the piece. Corners and edges count the
/// piece's corners 0, 1, 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Role {
    Corner(u8),
    Edge { from: u8, to: u8, step: u32 },
    Inner,
}

/// The lattice of points on each piece: n + 1 points per edge, and how many in all.
#[derive(Clone, Copy)]
pub(super) struct Lattice {
    pub(super) n: u32,
    pub(super) len: usize,
}

impl Lattice {
    pub(super) fn new(n: u32) -> Self {
        let n = n.max(1);
        let len = (n as usize + 1) * (n as usize + 2) / 2;
        Self { n, len }
    }

    /// What each lattice point is, in `points_on` order.
    pub(super) fn roles(&self) -> Vec<Role> {
        let n = self.n;
        let mut roles = Vec::with_capacity(self.len);
        for u in 0..=n {
            for v in 0..=n - u {
                roles.push(match (u, v) {
                    (0, 0) => Role::Corner(0),
                    _ if u == n => Role::Corner(1),
                    _ if v == n => Role::Corner(2),
                    (_, 0) => Role::Edge {
                        from: 0,
                        to: 1,
                        step: u,
                    },
                    (0, _) => Role::Edge {
                        from: 0,
                        to: 2,
                        step: v,
                    },
                    _ if u + v == n => Role::Edge {
                        from: 1,
                        to: 2,
                        step: v,
                    },
                    _ => Role::Inner,
                });
            }
        }
        roles
    }

    /// The lattice points of a piece: a + (b − a)·u/n + (c − a)·v/n for u + v ≤ n, u major.
    pub(super) fn points_on(&self, [a, b, c]: [Vec3; 3], out: &mut Vec<Vec3>) {
        let n = self.n;
        for u in 0..=n {
            for v in 0..=n - u {
                let (fu, fv) = (u as f32 / n as f32, v as f32 / n as f32);
                out.push(a + (b - a) * fu + (c - a) * fv);
            }
        }
    }
}
