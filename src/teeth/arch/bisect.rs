//! Bisection on increasing functions, used to slide teeth into contact and solve arch forms.

/// Bisection for an increasing f bracketed by f(lo) < target <= f(hi): returns a point within
/// 1e-5 of the crossing on the `hi` side, so f there is at least `target` (never closer than asked).
fn bisect_bracketed(mut f: impl FnMut(f32) -> f32, mut lo: f32, mut hi: f32, target: f32) -> f32 {
    for _ in 0..40 {
        if hi - lo < 1e-5 {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if f(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Finds x with f(x) = target for an increasing f, widening [lo, hi] until it brackets the target.
pub(super) fn solve_increasing(
    mut f: impl FnMut(f32) -> f32,
    mut lo: f32,
    mut hi: f32,
    target: f32,
) -> f32 {
    for _ in 0..20 {
        if f(lo) <= target {
            break;
        }
        lo -= hi - lo;
    }
    for _ in 0..20 {
        if f(hi) >= target {
            break;
        }
        hi += hi - lo;
    }
    bisect_bracketed(f, lo, hi, target)
}

/// Finds x in [lo, hi] where an increasing f crosses `target`, clamped to the ends.
pub(super) fn bisect_clamped(mut f: impl FnMut(f32) -> f32, lo: f32, hi: f32, target: f32) -> f32 {
    if f(lo) >= target {
        return lo;
    }
    if f(hi) <= target {
        return hi;
    }
    bisect_bracketed(f, lo, hi, target)
}
