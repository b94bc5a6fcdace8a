//! The inside of a closed mesh as intervals along parallel lines ("columns"), for fast volume
//! queries such as "how much of this sphere lies outside the tooth".
//!
//! The lines run along the mesh's longest bounding-box axis, one through the centre of each cell of
//! a square lattice over the other two axes. Every triangle is rasterised onto the lattice; where a
//! line crosses it, the crossing and its direction (entering or leaving the solid, from the sign of
//! the face normal) become an event, and the events of each line, sorted, give its inside intervals
//! by the winding number. Lines through a shared edge or vertex are counted by exactly one of the
//! triangles that share it (a fill rule on canonically ordered edges, evaluated in f64), so a closed
//! mesh gives exact intervals on every line.
//!
//! Volumes over a region are the midpoint rule over the lattice: exact along each line, with an
//! error of the order of (boundary length in the lattice plane) × cell² for the region, which the
//! tests bound.

use super::lanes::F8;
use glam::{DVec3, Vec3};

use super::{Sphere, TriMesh};

/// Inside intervals of a closed mesh along the lines of a lattice.
#[derive(Clone, Debug)]
pub struct Columns {
    /// Axis of the lines (0 = x, 1 = y, 2 = z); the lattice spans axes (axis+1)%3 and (axis+2)%3.
    axis: usize,
    /// Lattice corner in the lattice plane (u, v).
    origin: [f32; 2],
    /// Lattice spacing (mm).
    cell: f32,
    /// Lines per lattice axis.
    dims: [usize; 2],
    /// Intervals of line k: `spans[offsets[k]..offsets[k + 1]]`.
    offsets: Vec<u32>,
    /// Inside intervals along the axis, sorted and disjoint per line.
    spans: Vec<[f32; 2]>,
    /// Every line's first two intervals, dense by line for lane-wise reading (an absent interval
    /// is empty: lo = +∞, hi = −∞), padded with `LANES` empty lines.
    lo0: Vec<f32>,
    hi0: Vec<f32>,
    lo1: Vec<f32>,
    hi1: Vec<f32>,
    /// Lines with more than two intervals (their others are added one by one).
    more: Vec<bool>,
}

/// Lines measured at once.
const LANES: usize = 8;

impl Columns {
    /// Rasterises `mesh` with `lines` lattice lines across the longer of its two short extents.
    pub fn build(mesh: &TriMesh, lines: usize) -> Self {
        let bounds = mesh.aabb();
        let e = bounds.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let span = e[u].max(e[v]);
        let cell = if span > 0.0 {
            span / lines.max(1) as f32
        } else {
            1.0
        };
        let origin = [bounds.min[u] - cell, bounds.min[v] - cell];
        let dims = [
            ((e[u] / cell).ceil() as usize + 2).max(1),
            ((e[v] / cell).ceil() as usize + 2).max(1),
        ];
        Self::with_lattice(mesh, axis, origin, cell, dims)
    }

    /// Rasterises `mesh` on a given lattice: line (i, j) runs along `axis` through
    /// origin + (i + ½, j + ½)·cell in the plane of axes (axis+1)%3, (axis+2)%3.
    pub fn with_lattice(
        mesh: &TriMesh,
        axis: usize,
        origin: [f32; 2],
        cell: f32,
        dims: [usize; 2],
    ) -> Self {
        let mut columns = Self {
            axis,
            origin,
            cell,
            dims,
            offsets: vec![0; dims[0] * dims[1] + 1],
            spans: Vec::new(),
            lo0: Vec::new(),
            hi0: Vec::new(),
            lo1: Vec::new(),
            hi1: Vec::new(),
            more: Vec::new(),
        };
        columns.rasterise(mesh);
        columns
    }

    /// Centre of lattice line (i, j) in the lattice plane.
    fn line_centre(&self, i: i64, j: i64) -> [f64; 2] {
        [
            self.origin[0] as f64 + (i as f64 + 0.5) * self.cell as f64,
            self.origin[1] as f64 + (j as f64 + 0.5) * self.cell as f64,
        ]
    }

    fn rasterise(&mut self, mesh: &TriMesh) {
        let (axis, u, v) = (self.axis, (self.axis + 1) % 3, (self.axis + 2) % 3);
        // (line, position along the axis, +1 entering / −1 leaving)
        let mut events: Vec<(u32, f32, i8)> = Vec::new();
        let proj = |p: Vec3| [p[u] as f64, p[v] as f64];
        for tri in &mesh.triangles {
            let pts = [
                mesh.vertices[tri[0] as usize],
                mesh.vertices[tri[1] as usize],
                mesh.vertices[tri[2] as usize],
            ];
            let q = pts.map(proj);
            let orient = cross2(q[0], q[1], q[2]);
            if orient == 0.0 || !orient.is_finite() {
                continue;
            }
            // The normal's component along the axis has the sign of `orient` (u, v, axis is a
            // right-handed cyclic order): an outward normal against the axis means entering.
            let sign: i8 = if orient < 0.0 { 1 } else { -1 };
            let d = pts.map(|p| p.as_dvec3());
            let n: DVec3 = (d[1] - d[0]).cross(d[2] - d[0]);
            // Edges in canonical order (lower vertex index first) and the side of each that is
            // inside the projected triangle.
            let edges: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];
            let canon = edges.map(|(a, b)| {
                let forward = tri[a] < tri[b];
                let (p, r) = if forward { (a, b) } else { (b, a) };
                let side = if (orient > 0.0) == forward { 1.0 } else { -1.0 };
                (q[p], q[r], side)
            });
            let lo = [
                q.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min),
                q.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min),
            ];
            let hi = [
                q.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max),
                q.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max),
            ];
            let range = |k: usize| {
                let c = self.cell as f64;
                let o = self.origin[k] as f64;
                let first = ((lo[k] - o) / c - 0.5).ceil().max(0.0) as i64;
                let last = (((hi[k] - o) / c - 0.5).floor() as i64).min(self.dims[k] as i64 - 1);
                first..=last
            };
            for i in range(0) {
                for j in range(1) {
                    let x = self.line_centre(i, j);
                    let inside = canon.iter().all(|&(p, r, side)| {
                        let e = cross2(p, r, x) * side;
                        if e != 0.0 {
                            return e > 0.0;
                        }
                        // On the edge: exactly one of the two triangles sharing it claims the line.
                        let (du, dv) = (r[0] - p[0], r[1] - p[1]);
                        let up = dv > 0.0 || (dv == 0.0 && du > 0.0);
                        up == (side > 0.0)
                    });
                    if !inside {
                        continue;
                    }
                    let at =
                        d[0][axis] - (n[u] * (x[0] - d[0][u]) + n[v] * (x[1] - d[0][v])) / n[axis];
                    let line = (i as usize * self.dims[1] + j as usize) as u32;
                    events.push((line, at as f32, sign));
                }
            }
        }
        events.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(b.2.cmp(&a.2)));
        let mut k = 0;
        for line in 0..self.dims[0] * self.dims[1] {
            self.offsets[line] = self.spans.len() as u32;
            let mut winding = 0i32;
            let mut start = 0.0f32;
            while k < events.len() && events[k].0 as usize == line {
                let (_, at, s) = events[k];
                let before = winding;
                winding += s as i32;
                if before <= 0 && winding > 0 {
                    start = at;
                } else if before > 0 && winding <= 0 && at > start {
                    self.spans.push([start, at]);
                }
                k += 1;
            }
        }
        let n = self.dims[0] * self.dims[1];
        self.offsets[n] = self.spans.len() as u32;
        let empty = [f32::INFINITY, f32::NEG_INFINITY];
        let nth = |line: usize, k: usize| self.spans_of(line).get(k).copied().unwrap_or(empty);
        let (mut lo0, mut hi0, mut lo1, mut hi1) = (vec![], vec![], vec![], vec![]);
        for line in 0..n {
            let (first, second) = (nth(line, 0), nth(line, 1));
            lo0.push(first[0]);
            hi0.push(first[1]);
            lo1.push(second[0]);
            hi1.push(second[1]);
        }
        for v in [&mut lo0, &mut lo1] {
            v.resize(n + LANES, empty[0]);
        }
        for v in [&mut hi0, &mut hi1] {
            v.resize(n + LANES, empty[1]);
        }
        self.more = (0..n).map(|line| self.spans_of(line).len() > 2).collect();
        (self.lo0, self.hi0, self.lo1, self.hi1) = (lo0, hi0, lo1, hi1);
    }

    /// The inside intervals (sorted, disjoint) along lattice line (i, j): `i` counts along axis
    /// (axis+1)%3, `j` along (axis+2)%3; empty beyond the lattice.
    pub fn spans(&self, i: usize, j: usize) -> &[[f32; 2]] {
        if i >= self.dims[0] || j >= self.dims[1] {
            return &[];
        }
        self.spans_of(i * self.dims[1] + j)
    }

    /// The intervals of a line.
    fn spans_of(&self, line: usize) -> &[[f32; 2]] {
        &self.spans[self.offsets[line] as usize..self.offsets[line + 1] as usize]
    }

    /// True when one inside interval of the line holds the whole of lo..hi.
    #[inline(always)]
    fn holds_chord(&self, line: usize, lo: f32, hi: f32) -> bool {
        (self.lo0[line] <= lo && self.hi0[line] >= hi)
            || (self.lo1[line] <= lo && self.hi1[line] >= hi)
            || (self.more[line]
                && self.spans_of(line)[2..]
                    .iter()
                    .any(|s| s[0] <= lo && s[1] >= hi))
    }

    /// Inside length of the line's intervals after its first two, between `lo` and `hi`.
    fn more_inside(&self, line: usize, lo: f32, hi: f32) -> f32 {
        clipped_length(&self.spans_of(line)[2..], lo, hi)
    }

    /// Inside length of line (i, j) between `lo` and `hi` along the axis.
    fn inside_length(&self, i: i64, j: i64, lo: f32, hi: f32) -> f32 {
        self.line(i, j)
            .map_or(0.0, |line| clipped_length(self.spans_of(line), lo, hi))
    }

    /// Volume of each sphere (common `centre`, the given `radii`) outside the solid, written to
    /// `out` (mm³), by the midpoint rule over the lattice (the sphere's own volume included, so the
    /// result is never negative). Radii are measured sixteen at a time, one per lane, in one pass
    /// over the lines.
    #[inline(always)]
    pub fn outside_volumes(&self, centre: Vec3, radii: &[f32], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for (radii, out) in radii.chunks(2 * LANES).zip(out.chunks_mut(2 * LANES)) {
            self.outside_volumes_lanes(centre, radii, out);
        }
    }

    /// [`Columns::outside_volumes`] for at most 2 × `LANES` radii.
    #[inline(always)]
    fn outside_volumes_lanes(&self, centre: Vec3, radii: &[f32], out: &mut [f64]) {
        let (u, v) = ((self.axis + 1) % 3, (self.axis + 2) % 3);
        let Some(r_max) = radii.iter().copied().reduce(f32::max) else {
            return;
        };
        let mut r2 = [[0.0f32; LANES]; 2];
        for (k, &r) in radii.iter().enumerate() {
            r2[k / LANES][k % LANES] = r * r;
        }
        let halves = radii.len().div_ceil(LANES);
        let r2 = r2.map(F8::from);
        let c = self.cell as f64;
        let (cu, cv, ca) = (centre[u] as f64, centre[v] as f64, centre[self.axis]);
        let ca8 = F8::splat(ca);
        let (i0, i1) = self.index_range(cu, r_max, 0);
        let (j0, j1) = self.index_range(cv, r_max, 1);
        let mut total = [0.0f64; 2 * LANES];
        for i in i0..=i1 {
            let mut row = [F8::ZERO; 2];
            let du = (self.line_centre(i, 0)[0] - cu).powi(2);
            for j in j0..=j1 {
                let x = self.line_centre(i, j);
                let d2 = (du + (x[1] - cv).powi(2)) as f32;
                if d2 >= r_max * r_max {
                    continue;
                }
                let line = self.line(i, j);
                // A line whose chord through the largest sphere lies inside the solid adds
                // nothing for any radius.
                if let Some(line) = line {
                    let h = (r_max * r_max - d2).sqrt();
                    if self.holds_chord(line, ca - h, ca + h) {
                        continue;
                    }
                }
                for (half, acc) in row.iter_mut().enumerate().take(halves) {
                    let h = (r2[half] - F8::splat(d2)).max(F8::ZERO).sqrt();
                    let (a, b) = (ca8 - h, ca8 + h);
                    let mut inside = F8::ZERO;
                    if let Some(line) = line {
                        let span = |lo: f32, hi: f32| {
                            (F8::splat(hi).min(b) - F8::splat(lo).max(a)).max(F8::ZERO)
                        };
                        inside = span(self.lo0[line], self.hi0[line])
                            + span(self.lo1[line], self.hi1[line]);
                        if self.more[line] {
                            let (ha, hb) = (a.to_array(), b.to_array());
                            let extra: [f32; LANES] =
                                std::array::from_fn(|k| self.more_inside(line, ha[k], hb[k]));
                            inside += F8::from(extra);
                        }
                    }
                    *acc += (h + h - inside).max(F8::ZERO);
                }
            }
            for (half, acc) in row.iter().enumerate().take(halves) {
                for (k, r) in acc.to_array().into_iter().enumerate() {
                    total[half * LANES + k] += r as f64;
                }
            }
        }
        for (o, t) in out.iter_mut().zip(total) {
            *o += t * c * c;
        }
    }

    /// Volume of the sphere outside the solid (mm³); see [`Columns::outside_volumes`]. Lines are
    /// measured eight at a time along each row of the lattice.
    pub fn outside_volume(&self, s: &Sphere) -> f64 {
        let (u, v) = ((self.axis + 1) % 3, (self.axis + 2) % 3);
        let c = self.cell as f64;
        let (cu, cv, ca) = (s.centre[u] as f64, s.centre[v] as f64, s.centre[self.axis]);
        let r = s.radius;
        if r.is_nan() || r <= 0.0 {
            return 0.0;
        }
        let (r2, ca8) = (F8::splat(r * r), F8::splat(ca));
        let lane = F8::from(std::array::from_fn::<f32, LANES, _>(|k| k as f32));
        let (i0, i1) = self.index_range(cu, r, 0);
        let (j0, j1) = self.index_range(cv, r, 1);
        let mut total = 0.0f64;
        for i in i0..=i1 {
            let du = ((self.line_centre(i, 0)[0] - cu).powi(2)) as f32;
            if du >= r * r {
                continue;
            }
            let mut row = F8::ZERO;
            // The part of the row inside the lattice, eight lines at a time; the rest (no
            // inside intervals) one by one.
            let inner = if i >= 0 && (i as usize) < self.dims[0] {
                (j0.max(0), j1.min(self.dims[1] as i64 - 1))
            } else {
                (0, -1)
            };
            for j in (j0..=j1).filter(|&j| j < inner.0 || j > inner.1) {
                let dv = (self.line_centre(i, j)[1] - cv) as f32;
                let h2 = r * r - du - dv * dv;
                if h2 > 0.0 {
                    total += 2.0 * h2.sqrt() as f64;
                }
            }
            let mut j = inner.0;
            while j <= inner.1 {
                let line = i as usize * self.dims[1] + j as usize;
                let left = (inner.1 - j + 1) as f32;
                let y0 = (self.line_centre(i, j)[1] - cv) as f32;
                let dv = F8::splat(y0) + lane * F8::splat(self.cell);
                let valid = lane.simd_lt(F8::splat(left));
                let h2 = r2 - F8::splat(du) - dv * dv;
                let h = valid.select(h2.max(F8::ZERO).sqrt(), F8::ZERO);
                let (a, b) = (ca8 - h, ca8 + h);
                let load = |v: &[f32]| F8::load(v, line);
                let inside = (load(&self.hi0).min(b) - load(&self.lo0).max(a)).max(F8::ZERO)
                    + (load(&self.hi1).min(b) - load(&self.lo1).max(a)).max(F8::ZERO);
                row += (h + h - inside).max(F8::ZERO);
                let lines = line..line + (left as usize).min(LANES);
                if self.more[lines.clone()].contains(&true) {
                    for (k, hk) in lines.zip(h.to_array()) {
                        if self.more[k] && hk > 0.0 {
                            total -= self.more_inside(k, ca - hk, ca + hk) as f64;
                        }
                    }
                }
                j += LANES as i64;
            }
            total += row.reduce_add() as f64;
        }
        total.max(0.0) * c * c
    }

    /// Lattice indices (along lattice axis `k`) of the lines within `r` of `x`, as an inclusive
    /// range (empty when first > last).
    fn index_range(&self, x: f64, r: f32, k: usize) -> (i64, i64) {
        let c = self.cell as f64;
        let index = |x: f64| (x - self.origin[k] as f64) / c - 0.5;
        (
            index(x - r as f64).ceil() as i64,
            index(x + r as f64).floor() as i64,
        )
    }

    /// Index of lattice line (i, j), if it is on the lattice.
    fn line(&self, i: i64, j: i64) -> Option<usize> {
        (i >= 0 && j >= 0 && (i as usize) < self.dims[0] && (j as usize) < self.dims[1])
            .then(|| i as usize * self.dims[1] + j as usize)
    }

    /// Volume of the union of `spheres` outside the solid (mm³), each point counted once: along
    /// every lattice line (inside the lattice or not) the spheres' chords are merged and the inside
    /// intervals subtracted, exactly; then the midpoint rule across lines.
    pub fn union_outside_volume(&self, spheres: &[Sphere]) -> f64 {
        let (u, v) = ((self.axis + 1) % 3, (self.axis + 2) % 3);
        let c = self.cell as f64;
        let mut chords: std::collections::HashMap<(i64, i64), Vec<[f32; 2]>> =
            std::collections::HashMap::new();
        for s in spheres {
            let (cu, cv, ca) = (s.centre[u] as f64, s.centre[v] as f64, s.centre[self.axis]);
            let r = s.radius as f64;
            let index = |x: f64, o: f32| (x - o as f64) / c - 0.5;
            for i in index(cu - r, self.origin[0]).ceil() as i64
                ..=index(cu + r, self.origin[0]).floor() as i64
            {
                for j in index(cv - r, self.origin[1]).ceil() as i64
                    ..=index(cv + r, self.origin[1]).floor() as i64
                {
                    let x = self.line_centre(i, j);
                    let h2 =
                        s.radius * s.radius - ((x[0] - cu).powi(2) + (x[1] - cv).powi(2)) as f32;
                    if h2 > 0.0 {
                        let half = h2.sqrt();
                        chords
                            .entry((i, j))
                            .or_default()
                            .push([ca - half, ca + half]);
                    }
                }
            }
        }
        let mut total = 0.0f64;
        for ((i, j), mut list) in chords {
            list.sort_by(|a, b| a[0].total_cmp(&b[0]));
            let mut merged: Vec<[f32; 2]> = Vec::with_capacity(list.len());
            for iv in list {
                match merged.last_mut() {
                    Some(last) if iv[0] <= last[1] => last[1] = last[1].max(iv[1]),
                    _ => merged.push(iv),
                }
            }
            for iv in merged {
                total += (iv[1] - iv[0] - self.inside_length(i, j, iv[0], iv[1])).max(0.0) as f64;
            }
        }
        total * c * c
    }

    /// Volume of the solid (mm³), by the same rule.
    #[cfg(test)]
    pub fn volume(&self) -> f64 {
        let len: f64 = self.spans.iter().map(|s| (s[1] - s[0]) as f64).sum();
        len * (self.cell as f64).powi(2)
    }
}

/// The lattice lines within some reach of one place, gathered by [`Columns::gather`] so that
/// eight nearby spheres are measured at once, one per lane, in one pass over them. Coordinates are
/// kept relative to the place, in the order (lattice u, lattice v, axis).
#[derive(Clone, Debug, Default)]
pub struct LocalLines {
    anchor: [f32; 3],
    reach: f32,
    /// Per line: its offsets from the anchor across the lattice (u, v), then its first two
    /// inside intervals along the axis relative to the anchor (lo0, hi0, lo1, hi1).
    lines: Vec<[f32; 6]>,
    /// Scratch for a gather: the lattice columns' offsets from the anchor.
    columns_v: Vec<f32>,
    /// Lines with more than two intervals: (gathered index, lattice line).
    more: Vec<(u32, u32)>,
    cell2: f64,
}

impl Columns {
    /// Gathers what measures any sphere inside the ball of radius `reach` around `centre` (see
    /// [`LocalLines::holds`]): every lattice line (on the lattice or off it) that crosses the ball,
    /// except those whose chord through the ball lies inside the solid, which no such sphere's
    /// chord leaves.
    #[inline(always)]
    pub fn gather(&self, centre: Vec3, reach: f32, out: &mut LocalLines) {
        let (u, v) = ((self.axis + 1) % 3, (self.axis + 2) % 3);
        let (cu, cv) = (centre[u] as f64, centre[v] as f64);
        out.anchor = [centre[u], centre[v], centre[self.axis]];
        out.reach = reach;
        out.cell2 = (self.cell as f64).powi(2);
        out.lines.clear();
        out.more.clear();
        let (i0, i1) = self.index_range(cu, reach, 0);
        let (j0, j1) = self.index_range(cv, reach, 1);
        let ca = centre[self.axis];
        // Offsets across the lattice, once per row and column.
        let mut dvs = std::mem::take(&mut out.columns_v);
        dvs.clear();
        dvs.extend((j0..=j1).map(|j| (self.line_centre(0, j)[1] - cv) as f32));
        for i in i0..=i1 {
            let du = (self.line_centre(i, 0)[0] - cu) as f32;
            let room = reach * reach - du * du;
            if room <= 0.0 {
                continue;
            }
            // The row's lines within the ball: a range a cell wider each way than the circle's,
            // then the exact test below.
            let (a, b) = self.index_range(cv, room.sqrt(), 1);
            let (a, b) = ((a - 1).max(j0), (b + 1).min(j1));
            for j in a..=b {
                let dv = dvs[(j - j0) as usize];
                let h2 = room - dv * dv;
                if h2 <= 0.0 {
                    continue;
                }
                let h = h2.sqrt();
                let line = self.line(i, j);
                if let Some(line) = line
                    && self.holds_chord(line, ca - h, ca + h)
                {
                    continue;
                }
                let k = out.lines.len() as u32;
                let (mut first, mut second) = (
                    [f32::INFINITY, f32::NEG_INFINITY],
                    [f32::INFINITY, f32::NEG_INFINITY],
                );
                if let Some(line) = line {
                    first = [self.lo0[line] - ca, self.hi0[line] - ca];
                    second = [self.lo1[line] - ca, self.hi1[line] - ca];
                    if self.more[line] {
                        out.more.push((k, line as u32));
                    }
                }
                out.lines
                    .push([du, dv, first[0], first[1], second[0], second[1]]);
            }
        }
        out.columns_v = dvs;
    }
}

impl LocalLines {
    /// True when `s` lies inside the gathered ball, so that [`LocalLines::outside_volumes`]
    /// measures it as [`Columns::outside_volume`] does.
    pub fn holds(&self, columns: &Columns, s: &Sphere) -> bool {
        let (u, v, a) = ((columns.axis + 1) % 3, (columns.axis + 2) % 3, columns.axis);
        let d = Vec3::new(
            s.centre[u] - self.anchor[0],
            s.centre[v] - self.anchor[1],
            s.centre[a] - self.anchor[2],
        );
        d.length() + s.radius <= self.reach
    }

    /// Volumes of eight spheres outside the solid (mm³), one per lane, by the rule of
    /// [`Columns::outside_volume`] (to f32 rounding). Each sphere must pass
    /// [`LocalLines::holds`]; a lane of radius 0 gives 0.
    #[inline(always)]
    pub fn outside_volumes(&self, columns: &Columns, spheres: &[Sphere; 8]) -> [f64; 8] {
        let (u, v, a) = ((columns.axis + 1) % 3, (columns.axis + 2) % 3, columns.axis);
        let lane = |f: &dyn Fn(&Sphere) -> f32| F8::from(spheres.each_ref().map(f));
        let cu = lane(&|s| s.centre[u] - self.anchor[0]);
        let cv = lane(&|s| s.centre[v] - self.anchor[1]);
        let ca = lane(&|s| s.centre[a] - self.anchor[2]);
        let r2 = lane(&|s| s.radius * s.radius);
        let mut acc = F8::ZERO;
        for &[lu, lv, lo0, hi0, lo1, hi1] in &self.lines {
            let (du, dv) = (F8::splat(lu) - cu, F8::splat(lv) - cv);
            let h = (r2 - du * du - dv * dv).max(F8::ZERO).sqrt();
            let (lo, hi) = (ca - h, ca + h);
            let inside = (F8::splat(hi0).min(hi) - F8::splat(lo0).max(lo)).max(F8::ZERO)
                + (F8::splat(hi1).min(hi) - F8::splat(lo1).max(lo)).max(F8::ZERO);
            acc += (h + h - inside).max(F8::ZERO);
        }
        let mut out = acc.to_array().map(|x| x as f64);
        for &(k, line) in &self.more {
            let k = k as usize;
            for (lane, s) in spheres.iter().enumerate() {
                let (du, dv) = (
                    self.lines[k][0] - (s.centre[u] - self.anchor[0]),
                    self.lines[k][1] - (s.centre[v] - self.anchor[1]),
                );
                let h2 = s.radius * s.radius - du * du - dv * dv;
                if h2 > 0.0 {
                    let (h, c) = (h2.sqrt(), s.centre[a]);
                    out[lane] -= columns.more_inside(line as usize, c - h, c + h) as f64;
                }
            }
        }
        out.map(|x| x.max(0.0) * self.cell2)
    }
}

/// Total length of the intervals within [lo, hi].
fn clipped_length(spans: &[[f32; 2]], lo: f32, hi: f32) -> f32 {
    spans
        .iter()
        .map(|s| (s[1].min(hi) - s[0].max(lo)).max(0.0))
        .sum()
}

/// Twice the signed area of the 2D triangle (a, b, c).
fn cross2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[cfg(test)]
mod tests;
