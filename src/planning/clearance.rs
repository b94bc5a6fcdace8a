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
//! Guarantee: every measured instant is exact (a penetration is the deepest vertex or triangle
//! centroid of either tooth inside the other, exact when the deepest point is one, and surfaces
//! that cross with none inside count [`CROSSING_MM`] deep); between measures the penetration is
//! at most the deeper of its two ends' plus b (0.01 mm). A plan's `max_penetration_mm` is the deepest
//! measured, and a transition counts as colliding when a measure finds the teeth deeper inside
//! each other than allowed.

use crate::collision::{Motion, narrow_phase::exact::GAP_TOLERANCE_MM};
use crate::geometry::{MeshRef, mesh_separation_within};

/// Gap (mm) within which two teeth count as in contact, and by which their gap may fall between
/// two measures while they are: the exact stage's tolerance.
pub const BAND_MM: f32 = GAP_TOLERANCE_MM;

/// Depth (mm) counted for surfaces that cross with no sample point (vertex or triangle centroid)
/// of either inside the other, where the penetration estimate reads 0: crossing surfaces are
/// inside each other, however shallow.
pub const CROSSING_MM: f32 = 1e-3;

/// The signed gap of a measure (mm): the distance when apart, minus the penetration when the
/// surfaces meet (at least [`CROSSING_MM`]).
pub fn signed_gap(sep: &crate::geometry::MeshSeparation) -> f32 {
    if sep.distance > 0.0 {
        sep.distance
    } else {
        -sep.penetration.max(CROSSING_MM)
    }
}

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
        let gap = signed_gap(&sep);
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

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::geometry::{Pose, TriMesh, TriangleBvh};

    fn solid(min: Vec3, max: Vec3) -> (TriMesh, TriangleBvh) {
        let m = TriMesh::cuboid(min, max);
        let b = TriangleBvh::build(&m);
        (m, b)
    }

    fn mover<'a>(s: &'a (TriMesh, TriangleBvh), start: Pose, end: Pose) -> Mover<'a> {
        let mesh = MeshRef {
            mesh: &s.0,
            bvh: &s.1,
        };
        Mover::new(mesh, Motion { start, end })
    }

    fn at(x: f32, y: f32, z: f32) -> Pose {
        Pose::from_translation(Vec3::new(x, y, z))
    }

    #[test]
    fn a_box_passing_through_another_mid_way_is_found() {
        // Apart by 18 mm at both ends; inside each other for 5 % of the motion.
        let a = solid(Vec3::splat(-0.5), Vec3::splat(0.5));
        let b = solid(Vec3::splat(-0.5), Vec3::splat(0.5));
        let c = transition(
            &mover(&a, at(-20.0, 0.0, 0.0), at(20.0, 0.0, 0.0)),
            &mover(&b, Pose::IDENTITY, Pose::IDENTITY),
        );
        assert!(c.least_gap_mm < 0.0, "{c:?}");
        assert!(c.at > 0.45 && c.at < 0.55, "{c:?}");
        assert!(c.complete);
    }

    #[test]
    fn a_turning_bar_sweeping_through_a_box_is_found() {
        // A 20 mm bar turning 90° about its middle; a box in the way at 45°, clear of the bar
        // at both ends (the bar's tip passes through it mid-turn).
        let bar = solid(Vec3::new(-10.0, -0.5, -0.5), Vec3::new(10.0, 0.5, 0.5));
        let block = solid(Vec3::splat(-0.5), Vec3::splat(0.5));
        let turn = Pose::new(
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            Vec3::ZERO,
        );
        let spot = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4) * Vec3::new(8.0, 0.0, 0.0);
        let c = transition(
            &mover(&bar, Pose::IDENTITY, turn),
            &mover(
                &block,
                Pose::from_translation(spot),
                Pose::from_translation(spot),
            ),
        );
        assert!(c.least_gap_mm < -0.1, "{c:?}");
    }

    #[test]
    fn touching_teeth_that_part_never_count_as_inside() {
        // In contact at the start (2 µm apart, within the band), then 1 mm apart: the band's
        // small steps, no overlap. (Faces exactly flush read as crossing: see CROSSING_MM.)
        let a = solid(Vec3::ZERO, Vec3::ONE);
        let b = solid(Vec3::ZERO, Vec3::ONE);
        let c = transition(
            &mover(&a, Pose::IDENTITY, at(-1.0, 0.0, 0.0)),
            &mover(&b, at(1.002, 0.0, 0.0), at(1.002, 0.0, 0.0)),
        );
        assert!(c.least_gap_mm > 0.0 && c.least_gap_mm < 0.0021, "{c:?}");
        assert!(c.complete && c.measures >= 2, "{c:?}");
        // Held still in contact: measured once, never inside.
        let still = transition(
            &mover(&a, Pose::IDENTITY, Pose::IDENTITY),
            &mover(&b, at(1.002, 0.0, 0.0), at(1.002, 0.0, 0.0)),
        );
        assert_eq!(still.measures, 1);
        assert!(still.excess(0.0) == 0.0, "{still:?}");
        // Sliding along each other in contact: never inside, within the band's steps.
        let slide = transition(
            &mover(&a, Pose::IDENTITY, at(0.0, 0.0, 0.5)),
            &mover(&b, at(1.002, 0.0, 0.0), at(1.002, 0.0, 0.0)),
        );
        assert!(slide.excess(0.0) == 0.0 && slide.complete, "{slide:?}");
        assert!(slide.measures as f32 >= 0.5 / BAND_MM, "{slide:?}");
    }

    #[test]
    fn crossing_surfaces_with_no_vertex_inside_count_as_inside() {
        // Two bars crossing edge to edge: no vertex of either inside the other.
        let a = solid(Vec3::new(-5.0, -0.5, -0.5), Vec3::new(5.0, 0.5, 0.5));
        let b = solid(Vec3::new(-0.5, -5.0, -0.5), Vec3::new(0.5, 5.0, 0.5));
        let lift = at(0.0, 0.0, 0.9);
        let c = transition(
            &mover(&a, Pose::IDENTITY, Pose::IDENTITY),
            &mover(&b, lift, lift),
        );
        assert!(c.excess(0.0) > 0.0, "{c:?}");
    }
}
