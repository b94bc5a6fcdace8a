//! CCD stress suite: sphere-pair motions, random and adversarial, against an exact rational
//! reference computed independently of the code under test.
//!
//! For relative centre A + B·t and contact distance R, g(t) = |B|²t² + 2(A·B)t + |A|² − R² is
//! evaluated exactly (every f64 is a rational; `num-rational`), so the reference knows whether the
//! spheres come within R during [0, 1) and can check that a reported time t' is not after the
//! first contact t*: t' = 0 when they start within R, otherwise g(t') ≥ 0 and t' is not past the
//! vertex of g (so t' ≤ t*). Asserted: zero false negatives, no time after the true one, and false
//! positives only for near misses (passing within the distance the code was given, plus a relative
//! 10⁻⁹ of the squared sizes; for centres rounded to f32 far from the origin, plus their rounding
//! slack).
//!
//! The normal run checks 60,000 motions; `cargo test --release --test it -- --ignored
//! ten_million` checks 10⁷.

use glam::DVec3;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use orthosim::internals::{GROW, Interval, f32_slack, first_contact, may_meet};
use proptest::prelude::*;

fn q(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

struct Exact {
    a: [BigRational; 3],
    b: [BigRational; 3],
    r: BigRational,
}

fn dot(x: &[BigRational; 3], y: &[BigRational; 3]) -> BigRational {
    &x[0] * &y[0] + &x[1] * &y[1] + &x[2] * &y[2]
}

impl Exact {
    fn of(a: [f64; 3], b: [f64; 3], r: f64) -> Self {
        Self {
            a: a.map(q),
            b: b.map(q),
            r: q(r),
        }
    }

    /// (|B|², A·B, |A|² − R²)
    fn coefficients(&self) -> (BigRational, BigRational, BigRational) {
        (
            dot(&self.b, &self.b),
            dot(&self.a, &self.b),
            dot(&self.a, &self.a) - &self.r * &self.r,
        )
    }

    fn g(&self, t: &BigRational) -> BigRational {
        let (bb, ab, c) = self.coefficients();
        &bb * t * t + BigRational::from_integer(BigInt::from(2)) * ab * t + c
    }

    /// Whether |A + B·t| ≤ R for some t in [0, 1).
    fn contact(&self) -> bool {
        let (bb, ab, c) = self.coefficients();
        if !c.is_positive() {
            return true;
        }
        if !ab.is_negative() {
            return false;
        }
        let disc = &ab * &ab - &bb * &c;
        if disc.is_negative() {
            return false;
        }
        // Vertex −A·B/|B|² before 1: the minimum g(v) = −disc/|B|² ≤ 0 lies in the step.
        (-&ab) < bb
            || self
                .g(&BigRational::from_integer(BigInt::from(1)))
                .is_negative()
    }

    /// Whether `t` is not after the first contact (given that there is one).
    fn not_after_first(&self, t: f64) -> bool {
        let (bb, ab, c) = self.coefficients();
        let t = q(t);
        if !c.is_positive() {
            return t.is_zero();
        }
        !self.g(&t).is_negative() && !(&bb * &t + &ab).is_positive()
    }

    /// Whether the spheres pass within `widened` (≥ R, the distance the code was given), or a
    /// relative 10⁻⁹ more, during [0, 1].
    fn near_miss(&self, widened: f64) -> bool {
        let (bb, ab, _) = self.coefficients();
        let zero = BigRational::zero();
        let one = BigRational::from_integer(BigInt::from(1));
        let v = if bb.is_zero() {
            zero.clone()
        } else {
            -&ab / &bb
        };
        let v = if v < zero {
            zero
        } else if v > one {
            one
        } else {
            v
        };
        let size = dot(&self.a, &self.a) + &bb + &self.r * &self.r;
        let widened = q(widened);
        self.g(&v) <= &widened * &widened - &self.r * &self.r + size * q(1e-9)
    }
}

/// splitmix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.uniform()).exp()
    }
    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if (0.01..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

#[derive(Default, Debug)]
struct Tally {
    cases: usize,
    contacts: usize,
    false_negatives: usize,
    late: usize,
    broad_misses: usize,
    false_positives: usize,
    far_false_positives: usize,
}

/// One motion: the inputs the code sees, and the exact ones (the same unless rounded from
/// absolute coordinates).
fn check(tally: &mut Tally, seen: (DVec3, DVec3, f64), exact: &Exact) {
    check_near(tally, seen, exact, seen.2);
}

/// [`check`], counting a false positive as a near miss when the exact spheres pass within `near`.
fn check_near(tally: &mut Tally, seen: (DVec3, DVec3, f64), exact: &Exact, near: f64) {
    tally.cases += 1;
    let got = first_contact(seen.0, seen.1, seen.2);
    if exact.contact() {
        tally.contacts += 1;
        // The broad phase's test must let every contact through.
        if !may_meet(seen.0, seen.1, seen.2) {
            tally.broad_misses += 1;
        }
        match got {
            None => tally.false_negatives += 1,
            Some(t) if !exact.not_after_first(t) => tally.late += 1,
            Some(_) => {}
        }
    } else if got.is_some() {
        tally.false_positives += 1;
        if !exact.near_miss(near) {
            tally.far_false_positives += 1;
        }
    }
}

fn plain(tally: &mut Tally, a: DVec3, b: DVec3, r: f64) {
    check(tally, (a, b, r), &Exact::of(a.to_array(), b.to_array(), r));
}

/// `n` motions of each kind.
fn run(n: usize, seed: u64) -> Tally {
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    for _ in 0..n {
        let r = rng.log(1e-3, 1e2);
        // Random, near contact: start within a few radii, move up to a few radii towards it.
        let a = rng.unit() * r * rng.range(0.5, 3.0);
        let b = (rng.unit() - a.normalize()) * r * rng.range(0.0, 4.0);
        plain(&mut tally, a, b, r);
        // Grazing tangency: passes at exactly R (axis-aligned, so the distance is exact).
        let l = r * rng.range(0.1, 10.0);
        let side = if rng.uniform() < 0.5 { r } else { -r };
        plain(
            &mut tally,
            DVec3::new(-l, side, 0.0),
            DVec3::new(2.0 * l, 0.0, 0.0),
            r,
        );
        // Grazing along a random direction: just inside or just outside.
        let u = rng.unit();
        let w = u.any_orthonormal_vector();
        let miss = r * (1.0 + rng.range(-1e-9, 1e-9));
        plain(&mut tally, -u * l + w * miss, u * 2.0 * l, r);
        // Zero relative velocity, apart, touching or overlapping.
        let d = r * rng.range(0.9, 1.1);
        plain(&mut tally, rng.unit() * d, DVec3::ZERO, r);
        // Starting in contact, moving any way.
        plain(
            &mut tally,
            rng.unit() * r * rng.range(0.0, 1.0),
            rng.unit() * r * rng.range(0.0, 10.0),
            r,
        );
        // Tunnelling: 10 to 1000 radii in one step, straight through.
        let far = r * rng.range(5.0, 500.0);
        let u = rng.unit();
        plain(
            &mut tally,
            u * far + u.any_orthonormal_vector() * r * rng.range(0.0, 0.99),
            -u * 2.0 * far,
            r,
        );
        // Near-cancellation in Eq. 2: starting a hair outside, approaching very slowly.
        let u = rng.unit();
        plain(
            &mut tally,
            u * r * (1.0 + rng.log(1e-15, 1e-6)),
            -u * r * rng.log(1e-12, 1e-3),
            r,
        );
        // Far from the origin (up to 10⁴ mm): the narrow phase maps centres in f32 (relative to a
        // point near them, here the origin itself for the worst case) and widens the contact
        // distance by the f32 slack and growth of `lanes`; the reference uses the exact centres.
        let origin = rng.unit() * rng.range(1e3, 1e4);
        let c1 = [origin, origin + rng.unit() * r * rng.range(0.0, 4.0)];
        let c2 = [
            origin + rng.unit() * r * rng.range(0.5, 3.0),
            origin + rng.unit() * r * rng.range(0.0, 3.0),
        ];
        let f32s = |c: DVec3| c.as_vec3().as_dvec3();
        let a = f32s(c1[0]) - f32s(c2[0]);
        let b = (f32s(c1[1]) - f32s(c2[1])) - a;
        let scale = c1
            .iter()
            .chain(&c2)
            .map(|c| c.abs().max_element())
            .fold(0.0, f64::max);
        let exact = {
            let sub = |x: DVec3, y: DVec3| [0, 1, 2].map(|k| q(x[k]) - q(y[k]));
            let a = sub(c1[0], c2[0]);
            let end = sub(c1[1], c2[1]);
            let b = [0, 1, 2].map(|k| &end[k] - &a[k]);
            Exact { a, b, r: q(r) }
        };
        let slack = f32_slack(scale as f32) as f64;
        let widened = (r + slack) * GROW as f64;
        // The f32 centres themselves are off by up to the slack: a near miss passes within it
        // twice.
        check_near(&mut tally, (a, b, widened), &exact, widened + slack);
    }
    tally
}

fn assert_sound(t: &Tally) {
    assert_eq!(t.false_negatives, 0, "{t:?}");
    assert_eq!(t.late, 0, "{t:?}");
    assert_eq!(t.broad_misses, 0, "{t:?}");
    assert_eq!(t.far_false_positives, 0, "{t:?}");
    // The suite exercises both outcomes.
    assert!(
        t.contacts * 5 > t.cases && t.contacts * 5 < 4 * t.cases,
        "{t:?}"
    );
}

#[test]
fn sphere_pair_ccd_never_misses_and_is_never_late() {
    let t = run(7_500, 0x5eed);
    println!("{t:?}");
    assert_eq!(t.cases, 60_000);
    assert_sound(&t);
}

#[test]
#[ignore]
fn ten_million_sphere_pair_motions() {
    let t = run(1_250_000, 0xc0ffee);
    println!("{t:?}");
    assert_sound(&t);
}

/// f64 values across many magnitudes, both signs, zero and subnormals.
fn wide() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-1e4f64..1e4),
        (-300i32..300, -1.0f64..1.0).prop_map(|(e, m)| m * 2f64.powi(e)),
        Just(0.0),
        Just(f64::MIN_POSITIVE / 4.0),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Interval operations contain the exact (rational) result for members of their operands: the
    /// outward rounding is checked against exact arithmetic, not against f64 results.
    #[test]
    fn interval_bounds_contain_the_exact_results(a in wide(), b in wide(), c in wide(), d in wide(),
                                                 s in 0.0f64..=1.0, u in 0.0f64..=1.0) {
        let (x, y) = (Interval::new(a, b), Interval::new(c, d));
        // Members: the ends and a point between.
        let pick = |i: Interval, f: f64| [i.lo, i.hi, (i.lo + (i.hi - i.lo) * f).clamp(i.lo, i.hi)];
        for xv in pick(x, s) {
            for yv in pick(y, u) {
                let (qx, qy) = (q(xv), q(yv));
                let inside = |i: Interval, v: BigRational| q(i.lo) <= v && v <= q(i.hi);
                prop_assert!(inside(x.add(y), &qx + &qy));
                prop_assert!(inside(x.sub(y), &qx - &qy));
                prop_assert!(inside(x.mul(y), &qx * &qy));
                prop_assert!(inside(x.sqr(), &qx * &qx));
            }
        }
    }
}
