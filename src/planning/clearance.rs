//! Whether two teeth stay clear of each other while they move from one stage to the next.
//!
//! Each tooth moves from its pose at one stage to its pose at the next as a step of the
//! simulation does ([`Motion`]: translation linear, rotation slerped), and the check is
//! conservative advancement (Mirtich 1996) on the exact mesh distance
//! ([`mesh_separation_within`], exact up to f32 rounding): no point of either tooth moves faster
//! than μ, the sum of both teeth's speed bounds ([`Motion::speed_bound_of`] over their vertices),
//! so a gap g measured at time t cannot close before t + g/μ. From each measure the check steps
//! on by (g − b/2)/μ while the teeth are more than b apart (b = [`BAND_MM`], the exact stage's gap
//! tolerance), so they never meet between two such measures; teeth within b of each other, or
//! touching, step by b/μ, so their gap cannot fall by more than b between two measures. A pair
//! whose surfaces are farther apart than the rest of the motion can close is done at once
//! (the bounded query opens nothing beyond that distance).
//!
//! Guarantee: every measured instant is exact; between measures the penetration is at most the
//! deeper of its two ends' plus b (0.01 mm). A plan's `max_penetration_mm` is the deepest
//! measured, and a transition counts as colliding when a measure finds the teeth deeper inside
//! each other than allowed.

use crate::collision::{Motion, narrow_phase::exact::GAP_TOLERANCE_MM};
use crate::geometry::{MeshRef, mesh_separation_within};

/// Gap (mm) within which two teeth count as in contact, and by which their gap may fall between
/// two measures while they are: the exact stage's tolerance.
pub const BAND_MM: f32 = GAP_TOLERANCE_MM;

/// Most measures of one pair over one transition; beyond it the pair is reported as not
/// checked (never reached at the per-stage limits, where a touching pair needs a few hundred).
const MAX_MEASURES: u32 = 20_000;

/// One tooth moving over a transition.
#[derive(Clone, Copy)]
pub struct Mover<'a> {
    /// Its mesh.
    pub mesh: MeshRef<'a>,
    /// Its motion.
    pub motion: Motion,
    /// Speed bound of every point of the mesh (mm per unit time of the transition).
    pub speed: f64,
}

impl<'a> Mover<'a> {
    /// A tooth's mesh moving by `motion`.
    pub fn new(mesh: MeshRef<'a>, motion: Motion) -> Self {
        let speed = if motion.is_still() {
            0.0
        } else {
            motion.speed_bound_of(mesh.mesh.vertices.iter().copied())
        };
        Self {
            mesh,
            motion,
            speed,
        }
    }
}

/// What the check of one pair over one transition found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Least signed gap measured (mm; negative: the deepest penetration measured); infinite
    /// when the pair was never near enough to measure.
    pub least_gap_mm: f32,
    /// When it was measured (0–1 of the transition).
    pub at: f32,
    /// Exact distance queries made.
    pub measures: u32,
    /// False when the measures ran out before the end of the transition.
    pub complete: bool,
}

impl Clearance {
    /// Penetration measured beyond `allowed` mm (0 when none).
    pub fn excess(&self, allowed: f32) -> f32 {
        (-self.least_gap_mm - allowed).max(0.0)
    }
}

/// Checks a pair over one transition (see the module doc).
pub fn transition(a: &Mover, b: &Mover) -> Clearance {
    let mu = a.speed + b.speed;
    let band = BAND_MM as f64;
    let mut out = Clearance {
        least_gap_mm: f32::INFINITY,
        at: 0.0,
        measures: 0,
        complete: true,
    };
    let mut t = 0.0f64;
    loop {
        let (pa, pb) = (a.motion.at(t as f32), b.motion.at(t as f32));
        // Beyond this the pair cannot come within the band before the end.
        let reach = (mu * (1.0 - t) + 2.0 * band) as f32;
        out.measures += 1;
        let Some(sep) = mesh_separation_within(a.mesh, &pa, b.mesh, &pb, reach) else {
            return out;
        };
        let gap = sep.signed_gap();
        if gap < out.least_gap_mm {
            out.least_gap_mm = gap;
            out.at = t as f32;
        }
        if t >= 1.0 || mu <= 0.0 {
            return out;
        }
        if out.measures >= MAX_MEASURES {
            out.complete = false;
            return out;
        }
        let g = gap as f64;
        let step = if g > band {
            (g - 0.5 * band) / mu
        } else {
            band / mu
        };
        t = (t + step).min(1.0);
    }
}
