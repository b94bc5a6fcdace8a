//! The sphere-tree descents' inner loop: one sphere against a [`Chunk`] of up to eight siblings at
//! once, in f32, written so that the compiler turns each lane loop into vector instructions.
//!
//! **Rounding.** Centres are mapped by an [`Affine32`] built in f64 and rounded to f32, so a mapped
//! centre differs from the exact image of the stored (f32) local centre. Every test therefore
//! widens the contact distance by [`f32_slack`] of the coordinate scale S (the largest translation
//! of the affine maps plus the largest node-centre distance from the local origin): the error of
//! one mapped coordinate is at most 8u(|p|₁ + |t|) with u = 2⁻²⁴ (rounding of the matrix entries
//! and translation to f32, three products and three sums), so a centre is within 24u·S of its exact
//! image and a difference of two centres within 50u·S; the slack is 128u·(S + 1). The comparison
//! itself (squares and sums, relative error below 4u) is covered by growing the contact distance by
//! a relative 10⁻⁶. Hence a lane is rejected only when the exact spheres are provably apart: the
//! tests are conservative, never exact, and a little generous (about 10⁻⁴ mm at 10⁴ mm from the
//! origin, 10⁻⁶ mm near it).

use glam::{DMat3, DQuat, DVec3, Mat3, Vec3};
use wide::f32x8;

use crate::collision::shape::{Chunk, LANES};

/// Relative growth of every contact distance: covers the rounding of the f32 comparison.
pub const GROW: f32 = 1.0 + 1e-6;

/// The slack (mm) added to contact distances for centres mapped in f32 at coordinate scale
/// `scale` (see the module doc).
pub fn f32_slack(scale: f32) -> f32 {
    128.0 * (f32::EPSILON / 2.0) * (scale.abs() + 1.0)
}

/// A rigid map rounded to f32: `m · p + t`.
#[derive(Clone, Copy, Debug)]
pub struct Affine32 {
    /// Rotation matrix.
    pub m: Mat3,
    /// Translation.
    pub t: Vec3,
}

impl Affine32 {
    /// The map p ↦ rotation · p + translation, rounded to f32.
    pub fn new(rotation: DQuat, translation: DVec3) -> Self {
        Self {
            m: DMat3::from_quat(rotation.normalize()).as_mat3(),
            t: translation.as_vec3(),
        }
    }

    /// Largest translation component (for [`f32_slack`]).
    pub fn reach(&self) -> f32 {
        self.t.abs().max_element()
    }

    /// Maps one point.
    #[inline]
    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.m * p + self.t
    }

    /// Maps every lane of a chunk: (x, y, z).
    #[inline]
    pub fn apply_chunk(&self, c: &Chunk) -> [[f32; LANES]; 3] {
        let (m, t) = (self.m, self.t);
        let (x, y, z) = (f32x8::from(c.x), f32x8::from(c.y), f32x8::from(c.z));
        let row = |a: f32, b: f32, c: f32, t: f32| {
            (f32x8::splat(a) * x + f32x8::splat(b) * y + f32x8::splat(c) * z + f32x8::splat(t))
                .to_array()
        };
        [
            row(m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x),
            row(m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y),
            row(m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z),
        ]
    }
}

/// Bit k set when lane k's sphere (centre (x[k], y[k], z[k]), radius `r[k]`) and the sphere (p, rp) are
/// within `slack` of touching, for the lanes in `used`.
#[inline]
pub fn overlap_mask(
    [x, y, z]: [&[f32; LANES]; 3],
    r: &[f32; LANES],
    p: Vec3,
    rp: f32,
    slack: f32,
    used: u32,
) -> u32 {
    let dx = f32x8::from(*x) - f32x8::splat(p.x);
    let dy = f32x8::from(*y) - f32x8::splat(p.y);
    let dz = f32x8::from(*z) - f32x8::splat(p.z);
    let rr = (f32x8::from(*r) + f32x8::splat(rp) + f32x8::splat(slack)) * f32x8::splat(GROW);
    (dx * dx + dy * dy + dz * dz).simd_le(rr * rr).to_bitmask() & used
}

/// Start and end centres and inflated radii of a chunk's lanes over a step.
#[derive(Clone, Copy, Debug, Default)]
pub struct SweptChunk {
    /// Centres at the start: x, y, z.
    pub start: [[f32; LANES]; 3],
    /// Centres at the end.
    pub end: [[f32; LANES]; 3],
    /// Radii inflated by the arc–chord bound.
    pub r: [f32; LANES],
}

impl SweptChunk {
    /// The chunk's lanes moved by `start` and `end`, radii inflated by `k` times their distance
    /// from the local origin ([`crate::collision::motion::Motion::arc_factor`]).
    #[inline]
    pub fn new(c: &Chunk, start: &Affine32, end: &Affine32, k: f32) -> Self {
        let mut r = [0.0; LANES];
        for l in 0..LANES {
            r[l] = c.r[l] + k * c.rho[l];
        }
        Self {
            start: start.apply_chunk(c),
            end: end.apply_chunk(c),
            r,
        }
    }

    /// Lane `l`'s start centre, end centre and radius.
    #[inline]
    pub fn lane(&self, l: usize) -> (Vec3, Vec3, f32) {
        (
            Vec3::new(self.start[0][l], self.start[1][l], self.start[2][l]),
            Vec3::new(self.end[0][l], self.end[1][l], self.end[2][l]),
            self.r[l],
        )
    }
}

/// Bit k set unless lane k's swept sphere provably stays apart from the sphere moving from `p0` to
/// `p1` with radius `rp`: the interval bound of |A + (E − A)·t|² over t ∈ [0, 1] (A, E the
/// relative centre at the start and end; each component ranges between them) against the contact
/// distance plus `slack`.
#[inline]
pub fn swept_mask(s: &SweptChunk, p0: Vec3, p1: Vec3, rp: f32, slack: f32, used: u32) -> u32 {
    let mut lo = f32x8::ZERO;
    for (axis, (q0, q1)) in [(p0.x, p1.x), (p0.y, p1.y), (p0.z, p1.z)]
        .into_iter()
        .enumerate()
    {
        let a = f32x8::from(s.start[axis]) - f32x8::splat(q0);
        let e = f32x8::from(s.end[axis]) - f32x8::splat(q1);
        // The nearer end when both have the same sign, else zero (the interval spans 0).
        let m = a.abs().min(e.abs()) & (a * e).simd_gt(f32x8::ZERO);
        lo += m * m;
    }
    let rr = (f32x8::from(s.r) + f32x8::splat(rp) + f32x8::splat(slack)) * f32x8::splat(GROW);
    lo.simd_le(rr * rr).to_bitmask() & used
}

/// Iterates over the set bits of a mask, lowest first.
#[inline]
pub fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            k
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapped_centres_stay_within_the_slack_of_their_exact_images() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let q = DQuat::from_xyzw(rnd(), rnd(), rnd(), rnd()).normalize();
            let far = 10f64.powf(4.0 * (rnd() + 0.5));
            let t = DVec3::new(rnd(), rnd(), rnd()) * 2.0 * far;
            let p = (DVec3::new(rnd(), rnd(), rnd()) * 60.0).as_vec3();
            let f = Affine32::new(q, t);
            let exact = q * p.as_dvec3() + t;
            let got = f.apply(p).as_dvec3();
            let chunk = Chunk {
                x: [p.x; LANES],
                y: [p.y; LANES],
                z: [p.z; LANES],
                len: 1,
                ..Default::default()
            };
            let lanes = f.apply_chunk(&chunk);
            let lane = DVec3::new(lanes[0][0] as f64, lanes[1][0] as f64, lanes[2][0] as f64);
            let scale = (f.reach() + p.length()) as f64;
            // A centre is within a fifth of the slack of its exact image (see the module doc).
            let allowed = f32_slack(scale as f32) as f64 / 5.0;
            for e in [exact.distance(got), exact.distance(lane)] {
                assert!(e <= allowed, "error {e} > {allowed} at scale {scale}");
                worst = worst.max(e / allowed);
            }
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn masks_pick_the_touching_lanes() {
        let mut c = Chunk::default();
        for k in 0..5 {
            c.x[k] = k as f32 * 2.0;
            c.r[k] = 0.5;
            c.len = k as u32 + 1;
        }
        let xyz = [&c.x, &c.y, &c.z];
        // Lanes at x = 0, 2, 4, 6, 8; a unit sphere at x = 3 is within 1.5 of lanes 1 and 2 only.
        let m = overlap_mask(xyz, &c.r, Vec3::new(3.0, 0.0, 0.0), 1.0, 0.0, c.used());
        assert_eq!(bits(m).collect::<Vec<_>>(), vec![1, 2]);
        // Unused lanes never pass, even where their (zero) spheres would.
        let m = overlap_mask(xyz, &c.r, Vec3::ZERO, 1.0, 0.0, 0b1);
        assert_eq!(m, 1);
        // Exactly touching counts; a hair beyond does not.
        let m = overlap_mask(xyz, &c.r, Vec3::new(0.0, 1.5, 0.0), 1.0, 0.0, c.used());
        assert_eq!(m, 1);
        let m = overlap_mask(xyz, &c.r, Vec3::new(0.0, 1.51, 0.0), 1.0, 0.0, c.used());
        assert_eq!(m, 0);
        // Swept: a sphere passing from y = −10 to y = 10 at x = 3 meets lanes 1 and 2; passing
        // at height 1.6 it misses all.
        let id = Affine32::new(DQuat::IDENTITY, DVec3::ZERO);
        let s = SweptChunk::new(&c, &id, &id, 0.0);
        let m = swept_mask(
            &s,
            Vec3::new(3.0, -10.0, 0.0),
            Vec3::new(3.0, 10.0, 0.0),
            1.0,
            0.0,
            c.used(),
        );
        assert_eq!(m, 0b00110);
        let m = swept_mask(
            &s,
            Vec3::new(-4.0, -10.0, 1.6),
            Vec3::new(20.0, 10.0, 1.6),
            1.0,
            0.0,
            c.used(),
        );
        assert_eq!(m, 0);
    }
}
