//! Closed intervals of f64 with outward rounding: every operation's result contains every value the
//! operation can take on members of its operands, despite rounding (each bound is moved one ulp
//! outward, which covers the half-ulp error of a correctly rounded operation).

/// The closed interval [lo, hi].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

impl Interval {
    /// [lo, hi] (swapped if given the wrong way round).
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Self { lo, hi }
        } else {
            Self { lo: hi, hi: lo }
        }
    }

    /// The single value `x`.
    pub fn point(x: f64) -> Self {
        Self { lo: x, hi: x }
    }

    /// True when `x` lies in the interval.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Sum.
    #[allow(clippy::should_implement_trait)]
    pub fn add(self, o: Self) -> Self {
        Self {
            lo: (self.lo + o.lo).next_down(),
            hi: (self.hi + o.hi).next_up(),
        }
    }

    /// Difference.
    #[allow(clippy::should_implement_trait)]
    pub fn sub(self, o: Self) -> Self {
        Self {
            lo: (self.lo - o.hi).next_down(),
            hi: (self.hi - o.lo).next_up(),
        }
    }

    /// Product.
    #[allow(clippy::should_implement_trait)]
    pub fn mul(self, o: Self) -> Self {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Self {
            lo: p.iter().copied().fold(f64::INFINITY, f64::min).next_down(),
            hi: p
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max)
                .next_up(),
        }
    }

    /// Square (tighter than `self.mul(self)`: never negative).
    pub fn sqr(self) -> Self {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo <= 0.0 && self.hi >= 0.0 {
            Self {
                lo: 0.0,
                hi: a.max(b).next_up(),
            }
        } else {
            Self {
                lo: a.min(b).next_down().max(0.0),
                hi: a.max(b).next_up(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #[test]
        fn operations_contain_every_sampled_value(
            a in -1e4f64..1e4, b in -1e4f64..1e4, c in -1e4f64..1e4, d in -1e4f64..1e4,
            s in 0.0f64..=1.0, u in 0.0f64..=1.0,
        ) {
            let x = Interval::new(a, b);
            let y = Interval::new(c, d);
            let xv = x.lo + (x.hi - x.lo) * s;
            let yv = y.lo + (y.hi - y.lo) * u;
            prop_assert!(x.add(y).contains(xv + yv));
            prop_assert!(x.sub(y).contains(xv - yv));
            prop_assert!(x.mul(y).contains(xv * yv));
            prop_assert!(x.sqr().contains(xv * xv));
            prop_assert!(x.sqr().lo >= 0.0);
        }
    }

    #[test]
    fn rounding_goes_outward() {
        // 0.1 + 0.2 is not 0.3 in binary; the interval must still hold the exact sum's neighbours.
        let s = Interval::point(0.1).add(Interval::point(0.2));
        assert!(s.lo < 0.1 + 0.2 && s.hi > 0.1 + 0.2);
        let sq = Interval::new(-2.0, 1.0).sqr();
        assert_eq!(sq.lo, 0.0);
        assert!(sq.hi >= 4.0);
    }
}
