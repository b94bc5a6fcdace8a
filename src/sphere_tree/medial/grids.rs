//! The medial builder's uniform grids: pieces binned by centroid (the candidates' scans, eight
//! pieces to a lane) and spheres binned by bounding box (shrinking and the exact cover, eight
//! spheres to a lane).

use glam::Vec3;

use super::pieces::Pieces;
use crate::geometry::{Aabb, Sphere, lanes::F8};

/// Pieces binned by centroid on a uniform grid.
pub(super) struct PieceGrid {
    pub(super) min: Vec3,
    pub(super) cell: f32,
    pub(super) dims: [usize; 3],
    pub(super) start: Vec<u32>,
    pub(super) items: Vec<u32>,
    /// The pieces' corner coordinates in `items` order (corner-major: x, y, z of the first
    /// corner, then the second, the third), padded with eight zeros, for lane-wise reading.
    pub(super) corners: [Vec<f32>; 9],
}

impl PieceGrid {
    pub(super) fn new(pieces: &Pieces, cell: f32) -> Self {
        let bounds = Aabb::from_points(pieces.centroid.iter().copied());
        let e = bounds.extent();
        let cell = cell.max(e.max_element() / 64.0).max(1e-6);
        let dims = [
            (e.x / cell) as usize + 1,
            (e.y / cell) as usize + 1,
            (e.z / cell) as usize + 1,
        ];
        let index = |p: Vec3| {
            let q = ((p - bounds.min) / cell).as_uvec3();
            let q = [
                (q.x as usize).min(dims[0] - 1),
                (q.y as usize).min(dims[1] - 1),
                (q.z as usize).min(dims[2] - 1),
            ];
            (q[0] * dims[1] + q[1]) * dims[2] + q[2]
        };
        let mut count = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for &c in &pieces.centroid {
            count[index(c) + 1] += 1;
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; pieces.centroid.len()];
        for (k, &c) in pieces.centroid.iter().enumerate() {
            let slot = &mut fill[index(c)];
            items[*slot as usize] = k as u32;
            *slot += 1;
        }
        let corners = std::array::from_fn(|c| {
            let mut v: Vec<f32> = items
                .iter()
                .map(|&k| pieces.corners[k as usize][c / 3][c % 3])
                .collect();
            v.resize(items.len() + 8, 0.0);
            v
        });
        Self {
            min: bounds.min,
            cell,
            dims,
            start: count,
            items,
            corners,
        }
    }

    /// Calls `f(piece, reach²)` for every piece whose three corners lie within `r` of `c`
    /// (reach = distance to the farthest corner), eight pieces at a time.
    #[inline(always)]
    pub(super) fn within(&self, c: Vec3, r: f32, mut f: impl FnMut(u32, f32)) {
        let lo = ((c - Vec3::splat(r) - self.min) / self.cell).floor();
        let hi = ((c + Vec3::splat(r) - self.min) / self.cell).floor();
        let clamp = |x: f32, d: usize| (x.max(0.0) as usize).min(d - 1);
        if hi.x < 0.0 || hi.y < 0.0 || hi.z < 0.0 {
            return;
        }
        let r2 = F8::splat(r * r);
        let centre = [c.x, c.y, c.z].map(F8::splat);
        let lane = F8::from(std::array::from_fn::<f32, 8, _>(|k| k as f32));
        // The distance from the centre to a run of cells along one axis, off the run's axis.
        let gap = |i: usize, axis: usize| {
            let lo = self.min[axis] + i as f32 * self.cell;
            (lo - c[axis]).max(c[axis] - lo - self.cell).max(0.0)
        };
        for x in clamp(lo.x, self.dims[0])..=clamp(hi.x, self.dims[0]) {
            for y in clamp(lo.y, self.dims[1])..=clamp(hi.y, self.dims[1]) {
                // Only the cells along z that the ball reaches (centroids lie within r).
                let room = r * r - gap(x, 0).powi(2) - gap(y, 1).powi(2);
                if room < 0.0 {
                    continue;
                }
                let half = room.sqrt();
                let (zl, zh) = (
                    ((c.z - half - self.min.z) / self.cell).floor(),
                    ((c.z + half - self.min.z) / self.cell).floor(),
                );
                if zh < 0.0 {
                    continue;
                }
                let row = (x * self.dims[1] + y) * self.dims[2];
                let (z0, z1) = (clamp(zl, self.dims[2]), clamp(zh, self.dims[2]));
                // Cells along z are consecutive in `items`.
                let (a, b) = (
                    self.start[row + z0] as usize,
                    self.start[row + z1 + 1] as usize,
                );
                let mut j = a;
                while j < b {
                    let mut reach = F8::ZERO;
                    for corner in 0..3 {
                        let d = |axis: usize| {
                            F8::load(&self.corners[corner * 3 + axis], j) - centre[axis]
                        };
                        let (dx, dy, dz) = (d(0), d(1), d(2));
                        reach = reach.max(dx * dx + dy * dy + dz * dz);
                    }
                    let valid = lane.simd_lt(F8::splat((b - j) as f32));
                    let mut mask = (reach.simd_le(r2) & valid).to_bitmask();
                    if mask != 0 {
                        let reach = reach.to_array();
                        while mask != 0 {
                            let k = mask.trailing_zeros() as usize;
                            mask &= mask - 1;
                            f(self.items[j + k], reach[k]);
                        }
                    }
                    j += 8;
                }
            }
        }
    }
}

/// Sphere indices binned by bounding box on a uniform grid.
pub(super) struct SphereGrid {
    pub(super) min: Vec3,
    pub(super) cell: f32,
    pub(super) dims: [usize; 3],
    pub(super) cells: Vec<Vec<u32>>,
}

impl SphereGrid {
    pub(super) fn new(spheres: &[Sphere], cell: f32) -> Self {
        let bounds = Aabb::from_points(spheres.iter().flat_map(|s| {
            [
                s.centre - Vec3::splat(s.radius),
                s.centre + Vec3::splat(s.radius),
            ]
        }));
        let e = bounds.extent();
        let cell = cell.max(e.max_element() / 48.0).max(1e-6);
        let dims = [
            (e.x / cell) as usize + 1,
            (e.y / cell) as usize + 1,
            (e.z / cell) as usize + 1,
        ];
        let mut grid = Self {
            min: bounds.min,
            cell,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
        };
        for (k, s) in spheres.iter().enumerate() {
            let lo = grid.cell_of(s.centre - Vec3::splat(s.radius));
            let hi = grid.cell_of(s.centre + Vec3::splat(s.radius));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        grid.cells[(x * dims[1] + y) * dims[2] + z].push(k as u32);
                    }
                }
            }
        }
        grid
    }

    #[inline(always)]
    pub(super) fn cell_of(&self, p: Vec3) -> [usize; 3] {
        let q = ((p - self.min) / self.cell).max(Vec3::ZERO);
        [
            (q.x as usize).min(self.dims[0] - 1),
            (q.y as usize).min(self.dims[1] - 1),
            (q.z as usize).min(self.dims[2] - 1),
        ]
    }

    pub(super) fn near(&self, p: Vec3) -> &[u32] {
        let [x, y, z] = self.cell_of(p);
        &self.cells[(x * self.dims[1] + y) * self.dims[2] + z]
    }
}

/// Eight spheres of a grid cell, by coordinate (padding lanes hold nothing: r² = −1).
#[derive(Clone, Copy)]
pub(super) struct SphereLanes {
    pub(super) x: F8,
    pub(super) y: F8,
    pub(super) z: F8,
    pub(super) r2: F8,
    pub(super) inv_r2: F8,
    pub(super) index: [u32; 8],
}

/// A [`SphereGrid`]'s cells as runs of [`SphereLanes`].
pub(super) struct LaneGrid {
    pub(super) start: Vec<u32>,
    pub(super) lanes: Vec<SphereLanes>,
}

impl LaneGrid {
    pub(super) fn new(grid: &SphereGrid, spheres: &[Sphere]) -> Self {
        let mut start = Vec::with_capacity(grid.cells.len() + 1);
        let mut lanes = Vec::new();
        for cell in &grid.cells {
            start.push(lanes.len() as u32);
            for chunk in cell.chunks(8) {
                let mut l = [[0.0f32; 8]; 5];
                l[3] = [-1.0; 8];
                let mut index = [u32::MAX; 8];
                for (k, &i) in chunk.iter().enumerate() {
                    let s = &spheres[i as usize];
                    (l[0][k], l[1][k], l[2][k]) = (s.centre.x, s.centre.y, s.centre.z);
                    l[3][k] = s.radius * s.radius;
                    l[4][k] = 1.0 / l[3][k];
                    index[k] = i;
                }
                lanes.push(SphereLanes {
                    x: l[0].into(),
                    y: l[1].into(),
                    z: l[2].into(),
                    r2: l[3].into(),
                    inv_r2: l[4].into(),
                    index,
                });
            }
        }
        start.push(lanes.len() as u32);
        Self { start, lanes }
    }

    /// Sets each sphere's r² (and its inverse) to the current radius.
    #[inline(always)]
    pub(super) fn update(&mut self, spheres: &[Sphere]) {
        for l in &mut self.lanes {
            let mut r2 = l.r2.to_array();
            for (k, &i) in l.index.iter().enumerate() {
                if i != u32::MAX {
                    let r = spheres[i as usize].radius;
                    r2[k] = r * r;
                }
            }
            l.r2 = r2.into();
            l.inv_r2 = F8::ONE / l.r2;
        }
    }

    #[inline(always)]
    pub(super) fn near(&self, grid: &SphereGrid, p: Vec3) -> &[SphereLanes] {
        let [x, y, z] = grid.cell_of(p);
        let cell = (x * grid.dims[1] + y) * grid.dims[2] + z;
        &self.lanes[self.start[cell] as usize..self.start[cell + 1] as usize]
    }
}
