//! Eight f32 lanes ([`F8`]) written as plain loops over arrays, so that the compiler turns each
//! operation into vector instructions of whatever instruction set the calling function is compiled
//! for: two four-lane SSE2 halves in the portable build, one 256-bit operation inside a function
//! compiled for AVX2 (see [`run`]).
//!
//! Every operation is an IEEE one per lane (no fused multiply-adds, no approximations), so a
//! computation gives bit-identical results in either instruction set. `max` and `min` return the
//! second operand when the first is not greater (or less): the rule of the SSE and AVX
//! instructions, so that they compile to one instruction each.

use std::ops::{Add, AddAssign, BitAnd, Div, Mul, Sub};

/// Eight f32 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F8(pub [f32; 8]);

/// Eight lane masks (all bits set or none), from the comparisons of [`F8`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8(pub [u32; 8]);

macro_rules! lanewise {
    ($a:expr, $b:expr, |$x:ident, $y:ident| $e:expr) => {{
        let (a, b) = ($a, $b);
        let mut out = [0.0f32; 8];
        for k in 0..8 {
            let ($x, $y) = (a.0[k], b.0[k]);
            out[k] = $e;
        }
        F8(out)
    }};
}

macro_rules! compare {
    ($a:expr, $b:expr, |$x:ident, $y:ident| $e:expr) => {{
        let (a, b) = ($a, $b);
        let mut out = [0u32; 8];
        for k in 0..8 {
            let ($x, $y) = (a.0[k], b.0[k]);
            out[k] = if $e { u32::MAX } else { 0 };
        }
        M8(out)
    }};
}

impl F8 {
    /// All lanes zero.
    pub const ZERO: Self = Self([0.0; 8]);
    /// All lanes one.
    pub const ONE: Self = Self([1.0; 8]);

    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f32) -> Self {
        Self([x; 8])
    }

    /// Lanes 0–7 in order.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        self.0
    }

    /// Eight consecutive values from `v[at..at + 8]` (panics past the end).
    #[inline(always)]
    pub fn load(v: &[f32], at: usize) -> Self {
        let mut out = [0.0f32; 8];
        out.copy_from_slice(&v[at..at + 8]);
        Self(out)
    }

    /// The larger per lane (`other` when `self` is not greater).
    #[inline(always)]
    pub fn max(self, other: Self) -> Self {
        lanewise!(self, other, |x, y| if x > y { x } else { y })
    }

    /// The smaller per lane (`other` when `self` is not less).
    #[inline(always)]
    pub fn min(self, other: Self) -> Self {
        lanewise!(self, other, |x, y| if x < y { x } else { y })
    }

    /// The square root per lane.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        let mut out = self.0;
        for x in &mut out {
            *x = x.sqrt();
        }
        Self(out)
    }

    /// Lanes where `self ≤ other`.
    #[inline(always)]
    pub fn simd_le(self, other: Self) -> M8 {
        compare!(self, other, |x, y| x <= y)
    }

    /// Lanes where `self < other`.
    #[inline(always)]
    pub fn simd_lt(self, other: Self) -> M8 {
        compare!(self, other, |x, y| x < y)
    }
}

impl F8 {
    /// The sum of the lanes, as two sums of four in lane order added last (a fixed order).
    #[inline(always)]
    pub fn reduce_add(self) -> f32 {
        let half = |h: &[f32]| h.iter().fold(0.0f32, |s, &x| s + x);
        half(&self.0[..4]) + half(&self.0[4..])
    }
}

impl From<[f32; 8]> for F8 {
    #[inline(always)]
    fn from(v: [f32; 8]) -> Self {
        Self(v)
    }
}

impl M8 {
    /// Bit k set when lane k is.
    #[inline(always)]
    pub fn to_bitmask(self) -> u32 {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__m128, _mm_movemask_ps};
            let [lo, hi]: [__m128; 2] = bytemuck::cast(self.0);
            // SAFETY: SSE is part of every x86-64 processor.
            #[allow(unsafe_code, reason = "an SSE instruction, which every x86-64 has")]
            let (lo, hi) = unsafe { (_mm_movemask_ps(lo), _mm_movemask_ps(hi)) };
            (lo | (hi << 4)) as u32
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let mut m = 0;
            for k in 0..8 {
                m |= (self.0[k] >> 31) << k;
            }
            m
        }
    }
}

impl M8 {
    /// `if_one` in the set lanes, `if_zero` in the others.
    #[inline(always)]
    pub fn select(self, if_one: F8, if_zero: F8) -> F8 {
        let mut out = [0.0f32; 8];
        for k in 0..8 {
            out[k] = f32::from_bits(
                (if_one.0[k].to_bits() & self.0[k]) | (if_zero.0[k].to_bits() & !self.0[k]),
            );
        }
        F8(out)
    }
}

impl BitAnd for M8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        let mut out = self.0;
        for k in 0..8 {
            out[k] &= o.0[k];
        }
        Self(out)
    }
}

impl Add for F8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        lanewise!(self, o, |x, y| x + y)
    }
}

impl Sub for F8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        lanewise!(self, o, |x, y| x - y)
    }
}

impl Mul for F8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        lanewise!(self, o, |x, y| x * y)
    }
}

impl Div for F8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        lanewise!(self, o, |x, y| x / y)
    }
}

impl AddAssign for F8 {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

/// Work whose lane loops should use the widest vectors the processor has: [`run`] compiles
/// [`Job::run`] (which must be `#[inline(always)]`, as must everything it calls that holds lane
/// loops) once for AVX2 and once portably, and picks one at run time.
pub trait Job {
    /// What the work gives.
    type Output;
    /// Does the work.
    fn run(self) -> Self::Output;
}

/// Runs `job` compiled for AVX2 and FMA when this processor has them (checked once, cached by the
/// standard library), else as built. Both give the same results (see the module doc).
pub fn run<J: Job>(job: J) -> J::Output {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
        #[allow(
            unsafe_code,
            reason = "calls code compiled for AVX2, after detecting it"
        )]
        // SAFETY: the processor has AVX2 and FMA (checked just above).
        return unsafe { run_avx2(job) };
    }
    job.run()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn run_avx2<J: Job>(job: J) -> J::Output {
    job.run()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes(seed: u32, scale: f32) -> F8 {
        let mut rng = crate::geometry::test_numbers(seed);
        F8(std::array::from_fn(|_| rng() * scale))
    }

    /// Each operation is the scalar one per lane; max and min take the second operand on ties.
    #[test]
    fn lanes_compute_what_scalars_compute() {
        for seed in 0..20 {
            let (a, b) = (lanes(seed, 10.0), lanes(seed + 100, 10.0));
            let b = F8(std::array::from_fn(
                |k| if k == 3 { a.0[3] } else { b.0[k] },
            ));
            for k in 0..8 {
                let (x, y) = (a.0[k], b.0[k]);
                assert_eq!((a + b).0[k], x + y);
                assert_eq!((a - b).0[k], x - y);
                assert_eq!((a * b).0[k], x * y);
                assert_eq!((a / b).0[k], x / y);
                assert_eq!(a.max(b).0[k], if x > y { x } else { y });
                assert_eq!(a.min(b).0[k], if x < y { x } else { y });
                assert_eq!((a * a).sqrt().0[k], (x * x).sqrt());
            }
            let (le, lt) = (a.simd_le(b).to_bitmask(), a.simd_lt(b).to_bitmask());
            for k in 0..8 {
                assert_eq!(le >> k & 1 == 1, a.0[k] <= b.0[k]);
                assert_eq!(lt >> k & 1 == 1, a.0[k] < b.0[k]);
            }
            // Lane 3 is a tie: ≤ holds, < does not.
            assert_eq!((le >> 3 & 1, lt >> 3 & 1), (1, 0));
            assert_eq!((a.simd_le(b) & b.simd_le(a)).to_bitmask(), 1 << 3);
            let picked = a.simd_lt(b).select(a, b);
            assert_eq!(picked, a.min(b));
            let sum = (a.0[0] + a.0[1] + a.0[2] + a.0[3]) + (a.0[4] + a.0[5] + a.0[6] + a.0[7]);
            assert_eq!(a.reduce_add(), sum);
        }
        assert_eq!(
            F8::load(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1).0[7],
            9.0
        );
    }

    /// A job gives the same answer whichever instruction set [`run`] picks.
    #[test]
    fn jobs_give_the_same_answer_in_either_instruction_set() {
        struct Norms(Vec<F8>);
        impl Job for Norms {
            type Output = Vec<u32>;
            #[inline(always)]
            fn run(self) -> Vec<u32> {
                self.0
                    .iter()
                    .map(|v| {
                        let r = (*v * *v + F8::splat(1.5)).sqrt();
                        (r.reduce_add().to_bits()) ^ r.simd_le(F8::splat(2.0)).to_bitmask()
                    })
                    .collect()
            }
        }
        let data: Vec<F8> = (0..64).map(|s| lanes(s, 5.0)).collect();
        assert_eq!(run(Norms(data.clone())), Norms(data).run());
    }
}
