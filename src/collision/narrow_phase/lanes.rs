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
//!
//! **Instruction sets.** The build targets every x86-64 (SSE2), where an eight-lane vector is two
//! four-lane halves. On a processor with AVX2 and FMA (checked once at run time), [`run`] compiles
//! a descent for those instructions and hands it [`Avx2`] lanes, whose tests are single 256-bit
//! operations; elsewhere it hands it [`Portable`] lanes. Both evaluate the same f32 expressions in
//! the same order, without fused multiply-adds, so their masks are bit-identical (tested): the
//! rounding argument above holds for either. This module and `geometry::lanes` hold orthosim's only
//! `unsafe` code: calls into functions compiled for AVX2, made only after the processor was found
//! to have it (and there one SSE instruction, which every x86-64 has).

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

/// Bit k set when lane k's sphere (centre `(x[k], y[k], z[k])`, radius `r[k]`) and the sphere
/// (p, rp) are within `slack` of touching, for the lanes in `used`.
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

/// Every pair of lanes of two chunks at once: bit l of `rows[k]` is set when lane k of `a` (centre
/// `(a.x[k], a.y[k], a.z[k])`, radius `a.r[k]`) and lane l of `b` are within `slack` of touching,
/// for l in `used_b` (k over all [`LANES`]; unused lanes of `a` give rows to be masked by the
/// caller).
/// Bit k of `any` is set when `rows[k]` is not empty.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    /// Per lane of `a`, the lanes of `b` it meets.
    pub rows: [u32; LANES],
    /// Lanes of `a` that meet some lane of `b`.
    pub any: u32,
}

/// The lane tests, for one instruction set. [`Portable`] and [`Avx2`] give identical results.
pub trait Lanes: Copy {
    /// [`overlap_mask`].
    fn overlap_mask(
        self,
        xyz: [&[f32; LANES]; 3],
        r: &[f32; LANES],
        p: Vec3,
        rp: f32,
        slack: f32,
        used: u32,
    ) -> u32;

    /// [`swept_mask`].
    fn swept_mask(self, s: &SweptChunk, p0: Vec3, p1: Vec3, rp: f32, slack: f32, used: u32) -> u32;

    /// The [`Block`] of chunk `a` (local coordinates) against lanes (`b`, `rb`): eight
    /// [`Self::overlap_mask`] tests, one per lane of `a`, without branches.
    #[inline(always)]
    fn block(
        self,
        a: &Chunk,
        b: [&[f32; LANES]; 3],
        rb: &[f32; LANES],
        slack: f32,
        used_b: u32,
    ) -> Block {
        Block::of(|k| {
            let p = Vec3::new(a.x[k], a.y[k], a.z[k]);
            self.overlap_mask(b, rb, p, a.r[k], slack, used_b)
        })
    }

    /// The [`Block`] of swept lanes: bit l of `rows[k]` set when [`Self::swept_mask`] passes lane
    /// l of `b` against lane k of `a`.
    #[inline(always)]
    fn swept_block(self, a: &SweptChunk, b: &SweptChunk, slack: f32, used_b: u32) -> Block {
        Block::of(|k| {
            let (p0, p1, r) = a.lane(k);
            self.swept_mask(b, p0, p1, r, slack, used_b)
        })
    }
}

impl Block {
    /// The block whose row k is `row(k)`.
    #[inline(always)]
    fn of(mut row: impl FnMut(usize) -> u32) -> Self {
        let mut out = Self {
            rows: [0; LANES],
            any: 0,
        };
        for k in 0..LANES {
            out.rows[k] = row(k);
            out.any |= ((out.rows[k] != 0) as u32) << k;
        }
        out
    }
}

/// Lane tests in [`wide`] vectors: SSE2 on x86-64, whatever the target offers elsewhere.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl Lanes for Portable {
    #[inline(always)]
    fn overlap_mask(
        self,
        xyz: [&[f32; LANES]; 3],
        r: &[f32; LANES],
        p: Vec3,
        rp: f32,
        slack: f32,
        used: u32,
    ) -> u32 {
        overlap_mask(xyz, r, p, rp, slack, used)
    }

    #[inline(always)]
    fn swept_mask(self, s: &SweptChunk, p0: Vec3, p1: Vec3, rp: f32, slack: f32, used: u32) -> u32 {
        swept_mask(s, p0, p1, rp, slack, used)
    }
}

/// A computation over lanes, run by [`run`] with the best [`Lanes`] this processor has.
pub trait LaneTask {
    /// What it returns.
    type Output;
    /// Runs with `lanes`.
    fn run<L: Lanes>(self, lanes: L) -> Self::Output;
}

/// Runs `task` with [`Avx2`] lanes, compiled for AVX2 and FMA, when the processor has them, and
/// with [`Portable`] lanes otherwise.
#[inline]
pub fn run<T: LaneTask>(task: T) -> T::Output {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = Avx2::detect() {
        return avx2::run(avx2, task);
    }
    task.run(Portable)
}

#[cfg(target_arch = "x86_64")]
pub use avx2::Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    #![allow(
        unsafe_code,
        reason = "calls into code compiled for AVX2, after detecting it"
    )]

    use std::arch::x86_64::{
        __m256, _CMP_GT_OQ, _CMP_LE_OQ, _mm256_add_ps, _mm256_and_ps, _mm256_andnot_ps,
        _mm256_cmp_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps,
        _mm256_setzero_ps, _mm256_sub_ps,
    };

    use glam::Vec3;

    use super::{GROW, LANES, LaneTask, Lanes, SweptChunk};

    /// Lane tests in 256-bit AVX instructions. Only [`Avx2::detect`] makes one, on a processor with
    /// AVX2 and FMA: holding one is the proof that calling code compiled for them is sound.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2(());

    impl Avx2 {
        /// `Some` when this processor has AVX2 and FMA (the check is cached by the standard
        /// library).
        #[inline]
        pub fn detect() -> Option<Self> {
            (std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma"))
                .then_some(Self(()))
        }
    }

    pub(super) fn run<T: LaneTask>(lanes: Avx2, task: T) -> T::Output {
        // SAFETY: `lanes` exists, so the processor has AVX2 and FMA (see `Avx2::detect`).
        unsafe { run_avx2(lanes, task) }
    }

    #[target_feature(enable = "avx2,fma")]
    fn run_avx2<T: LaneTask>(lanes: Avx2, task: T) -> T::Output {
        task.run(lanes)
    }

    #[inline(always)]
    fn load(v: &[f32; LANES]) -> __m256 {
        bytemuck::cast(*v)
    }

    /// Bit k set when `sq[k]` is within the grown contact distance of lane k (radius `r[k]`) and
    /// a sphere of radius `rp`, for the lanes in `used`: the comparison of `super::overlap_mask`
    /// and `super::swept_mask`, in the same order.
    #[target_feature(enable = "avx2,fma")]
    fn within(sq: __m256, r: &[f32; LANES], rp: f32, slack: f32, used: u32) -> u32 {
        let reach = _mm256_add_ps(
            _mm256_add_ps(load(r), _mm256_set1_ps(rp)),
            _mm256_set1_ps(slack),
        );
        let rr = _mm256_mul_ps(reach, _mm256_set1_ps(GROW));
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(sq, _mm256_mul_ps(rr, rr))) as u32 & used
    }

    #[target_feature(enable = "avx2,fma")]
    fn overlap_mask(
        [x, y, z]: [&[f32; LANES]; 3],
        r: &[f32; LANES],
        p: Vec3,
        rp: f32,
        slack: f32,
        used: u32,
    ) -> u32 {
        let dx = _mm256_sub_ps(load(x), _mm256_set1_ps(p.x));
        let dy = _mm256_sub_ps(load(y), _mm256_set1_ps(p.y));
        let dz = _mm256_sub_ps(load(z), _mm256_set1_ps(p.z));
        let d2 = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
            _mm256_mul_ps(dz, dz),
        );
        within(d2, r, rp, slack, used)
    }

    /// The lower bound of |A + (E − A)·t|² over the step, as `super::swept_mask` computes it,
    /// against the contact distance.
    #[target_feature(enable = "avx2,fma")]
    fn swept_mask(s: &SweptChunk, p0: Vec3, p1: Vec3, rp: f32, slack: f32, used: u32) -> u32 {
        let sign = _mm256_set1_ps(-0.0);
        let mut lo = _mm256_setzero_ps();
        for (axis, (q0, q1)) in [(p0.x, p1.x), (p0.y, p1.y), (p0.z, p1.z)]
            .into_iter()
            .enumerate()
        {
            let a = _mm256_sub_ps(load(&s.start[axis]), _mm256_set1_ps(q0));
            let e = _mm256_sub_ps(load(&s.end[axis]), _mm256_set1_ps(q1));
            let near = _mm256_min_ps(_mm256_andnot_ps(sign, a), _mm256_andnot_ps(sign, e));
            let same = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_mul_ps(a, e), _mm256_setzero_ps());
            let m = _mm256_and_ps(near, same);
            lo = _mm256_add_ps(lo, _mm256_mul_ps(m, m));
        }
        within(lo, &s.r, rp, slack, used)
    }

    impl Lanes for Avx2 {
        #[inline(always)]
        fn overlap_mask(
            self,
            xyz: [&[f32; LANES]; 3],
            r: &[f32; LANES],
            p: Vec3,
            rp: f32,
            slack: f32,
            used: u32,
        ) -> u32 {
            // SAFETY: `self` exists, so the processor has AVX2 and FMA.
            unsafe { overlap_mask(xyz, r, p, rp, slack, used) }
        }

        #[inline(always)]
        fn swept_mask(
            self,
            s: &SweptChunk,
            p0: Vec3,
            p1: Vec3,
            rp: f32,
            slack: f32,
            used: u32,
        ) -> u32 {
            // SAFETY: as above.
            unsafe { swept_mask(s, p0, p1, rp, slack, used) }
        }
    }
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

    /// A chunk `a`, lanes `b` (x, y, z, r) with the used mask, a probe sphere and a slack.
    type Case = (Chunk, [[f32; LANES]; 4], u32, Vec3, f32, f32);

    /// Random chunks and probes around near-touching distances, some lanes unused.
    fn random_cases(seed: u64, n: usize) -> Vec<Case> {
        let mut s = seed;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|_| {
                let mut a = Chunk {
                    len: 1 + (rnd() * 8.0) as u32 % 8,
                    ..Default::default()
                };
                let mut b = [[0.0; LANES]; 4];
                for k in 0..LANES {
                    (a.x[k], a.y[k], a.z[k]) = (rnd() * 6.0, rnd() * 6.0, rnd() * 6.0);
                    a.r[k] = 0.2 + rnd() * 2.0;
                    for c in 0..3 {
                        b[c][k] = rnd() * 6.0;
                    }
                    b[3][k] = 0.2 + rnd() * 2.0;
                }
                let used_b = (rnd() * 256.0) as u32 & 0xff;
                let p = Vec3::new(rnd() * 6.0, rnd() * 6.0, rnd() * 6.0);
                (a, b, used_b, p, 0.2 + rnd() * 2.0, rnd() * 1e-3)
            })
            .collect()
    }

    #[test]
    fn a_block_is_eight_lane_tests() {
        let (mut pairs, mut empty_rows) = (0, 0);
        for (a, b, used_b, _, _, slack) in random_cases(7, 2000) {
            let xyz = [&b[0], &b[1], &b[2]];
            let block = Portable.block(&a, xyz, &b[3], slack, used_b);
            for k in 0..LANES {
                let p = Vec3::new(a.x[k], a.y[k], a.z[k]);
                let row = overlap_mask(xyz, &b[3], p, a.r[k], slack, used_b);
                assert_eq!(block.rows[k], row);
                assert_eq!(block.any >> k & 1 != 0, row != 0);
                pairs += row.count_ones();
                empty_rows += (row == 0) as u32;
            }
        }
        // The cases mix touching and apart lanes.
        assert!(pairs > 10_000 && empty_rows > 1000, "{pairs} {empty_rows}");
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_lanes_give_the_portable_masks() {
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this processor: only the portable lanes are used");
            return;
        };
        for (a, b, used_b, p, rp, slack) in random_cases(11, 5000) {
            let xyz = [&b[0], &b[1], &b[2]];
            assert_eq!(
                avx2.block(&a, xyz, &b[3], slack, used_b),
                Portable.block(&a, xyz, &b[3], slack, used_b)
            );
            let used = a.used();
            assert_eq!(
                avx2.overlap_mask([&a.x, &a.y, &a.z], &a.r, p, rp, slack, used),
                Portable.overlap_mask([&a.x, &a.y, &a.z], &a.r, p, rp, slack, used)
            );
            // Swept: a's lanes moving by a random step, b's lanes moving another way.
            let mut lanes_b = Chunk {
                len: LANES as u32,
                ..Default::default()
            };
            (lanes_b.x, lanes_b.y, lanes_b.z, lanes_b.r) = (b[0], b[1], b[2], b[3]);
            let shift = |d: Vec3| Affine32::new(DQuat::IDENTITY, d.as_dvec3());
            let (sa, sb) = (
                SweptChunk::new(&a, &shift(Vec3::ZERO), &shift(p - Vec3::splat(3.0)), 0.0),
                SweptChunk::new(&lanes_b, &shift(Vec3::ZERO), &shift(Vec3::ZERO), 0.01),
            );
            assert_eq!(
                avx2.swept_block(&sa, &sb, slack, used_b),
                Portable.swept_block(&sa, &sb, slack, used_b)
            );
            let (p0, p1) = (p, Vec3::new(p.y, p.z, p.x));
            assert_eq!(
                avx2.swept_mask(&sa, p0, p1, rp, slack, used),
                Portable.swept_mask(&sa, p0, p1, rp, slack, used)
            );
        }
        // On the boundary (d² equal to the grown contact distance squared) both pass the lane.
        let mut c = Chunk::default();
        c.x[0] = (0.5f32 + 1.0 + 0.0) * GROW;
        c.r[0] = 0.5;
        c.len = 1;
        let id = Affine32::new(DQuat::IDENTITY, DVec3::ZERO);
        let s = SweptChunk::new(&c, &id, &id, 0.0);
        let (p0, p1) = (Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0));
        for touching in [
            avx2.overlap_mask([&c.x, &c.y, &c.z], &c.r, Vec3::ZERO, 1.0, 0.0, 1),
            Portable.overlap_mask([&c.x, &c.y, &c.z], &c.r, Vec3::ZERO, 1.0, 0.0, 1),
            avx2.swept_mask(&s, p0, p1, 1.0, 0.0, 1),
            Portable.swept_mask(&s, p0, p1, 1.0, 0.0, 1),
        ] {
            assert_eq!(touching, 1);
        }
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
