//! Directional steps of the advancement (see [`Relative`]).

use glam::Vec3;

use super::PlacedTri;
use crate::collision::motion::Motion;
use crate::collision::narrow_phase::lanes::Affine32;
use crate::geometry::Aabb;

/// Directional steps: how fast the second tooth's points drift along a direction of the first
/// tooth's frame.
///
/// In the first tooth's frame a point y of the second moves with velocity
/// ẏ = U + W × (y − o) − Ω × y, where U = Rₐᵀ(V_b − V_a), W = Rₐᵀω_b, Ω = Rₐᵀω_a (V the origins'
/// velocities, ω the world angular velocities of the slerps, Rₐ the first tooth's rotation and
/// o the second tooth's origin, all at the current time). So its speed along a fixed unit n is
/// the affine function n·ẏ = c₀ + y·m with c₀ = n·U − o·(n × W) and m = n × (W − Ω). Its
/// acceleration is Rₐᵀü − 2Ω × Rₐᵀu̇ + Ω × (Ω × y) (u = w − Tₐ, w the world point), so
/// |ÿ| ≤ A = θ_b²ρ_b + 2θₐ(|V_b − V_a| + θ_bρ_b) + θₐ²Y, with θ the rotation angles, ρ_b the
/// second tooth's largest vertex radius and Y a bound on |y| over the rest of the step. A
/// candidate pair whose triangles are g apart along n (every vertex of the second beyond every
/// vertex of the first) stays at least g + sΔ − AΔ²/2 apart along n after Δ, s the least speed of
/// its vertices along n, hence at least that far apart; the step keeps that above half the
/// tolerance plus [`DRIFT_SLACK_MM`] for every candidate pair (or uses the pair's plain bound
/// (d − tolerance/2)/μ when larger), so it never passes a contact.
pub(super) struct Relative {
    /// Origins' relative velocity, world (mm per unit time).
    v: glam::DVec3,
    /// Angular velocities, world.
    omega_a: glam::DVec3,
    omega_b: glam::DVec3,
    /// Rotation angles and speeds of the origins.
    theta_a: f64,
    theta_b: f64,
    travel: f64,
    /// Largest vertex radius of the second tooth.
    rho_b: f64,
}

/// Allowance (mm) for the difference between the poses the motions produce (f32 slerp and lerp)
/// and the constant-velocity model of [`Relative`], and for the f32 projections, per mm of
/// distance from the first tooth's origin (plus a constant): far above both.
const DRIFT_SLACK_MM: f64 = 1e-4;

impl Relative {
    pub(super) fn new(a: &Motion, b: &Motion, rho_b: f64) -> Self {
        let (theta_a, theta_b) = (a.angle(), b.angle());
        let velocity = |m: &Motion| m.end.translation.as_dvec3() - m.start.translation.as_dvec3();
        Self {
            v: velocity(b) - velocity(a),
            omega_a: a.axis() * theta_a,
            omega_b: b.axis() * theta_b,
            theta_a,
            theta_b,
            travel: velocity(a).length() + velocity(b).length(),
            rho_b,
        }
    }

    /// The drift along the unit `n` (first tooth's frame) at time `t`, with the first tooth's
    /// inverse rotation and the second's map into its frame then; `None` when nothing useful can
    /// be said.
    pub(super) fn drift(
        &self,
        t: f64,
        to_a: glam::DQuat,
        n: Vec3,
        rel: &Affine32,
        h: f64,
    ) -> Option<Drift> {
        let (u, w, omega) = (to_a * self.v, to_a * self.omega_b, to_a * self.omega_a);
        let o = rel.t.as_dvec3();
        let nd = n.as_dvec3();
        let c0 = nd.dot(u) - o.dot(nd.cross(w));
        let m = nd.cross(w - omega);
        // |y| over the rest of the step: now within |o| + ρ_b, and no point moves away from
        // the first origin faster than the two origins and the second's rotation.
        let y = o.length() + self.rho_b + (1.0 - t) * (self.travel + self.theta_b * self.rho_b);
        let accel = self.theta_b * self.theta_b * self.rho_b
            + 2.0 * self.theta_a * (self.v.length() + self.theta_b * self.rho_b)
            + self.theta_a * self.theta_a * y;
        (c0.is_finite() && m.is_finite() && accel.is_finite()).then_some(Drift {
            n,
            c0,
            m,
            accel: accel * (1.0 + 1e-6),
            keep: h + DRIFT_SLACK_MM * (1.0 + y),
        })
    }
}

/// The drift of [`Relative::drift`]: speed along `n` of a point y is `c0 + y·m`, acceleration at
/// most `accel`.
#[derive(Clone, Copy)]
pub(super) struct Drift {
    pub(super) n: Vec3,
    c0: f64,
    m: glam::DVec3,
    accel: f64,
    /// Half the tolerance plus the allowance for rounding: the least gap along ±n kept.
    keep: f64,
}

impl Drift {
    /// How long (in step time) the triangles provably stay more than half the tolerance plus the
    /// margin apart along ±n; 0 when they are not that far apart along it.
    pub(super) fn step(&self, x: &PlacedTri, y: &PlacedTri) -> f64 {
        let n = self.n;
        let p = x.v.map(|v| n.dot(v) as f64);
        let q = y.v.map(|v| n.dot(v) as f64);
        let speed = y.v.map(|v| self.c0 + v.as_dvec3().dot(self.m));
        let lo = |v: [f64; 3]| v[0].min(v[1]).min(v[2]);
        let hi = |v: [f64; 3]| v[0].max(v[1]).max(v[2]);
        self.spans((lo(p), hi(p)), (lo(q), hi(q)), (lo(speed), hi(speed)))
    }

    /// The same drift seen in a frame turned by `r` (rows: the frame's axes, the last being the
    /// direction), where the direction is the third axis: for r orthonormal, y·m = (r y)·(r m).
    /// r is rounded to f32, which moves the speeds by about 10⁻⁷ of |y|·|m|, far inside the
    /// allowance.
    pub(super) fn framed(&self, r: glam::Mat3) -> Drift {
        Drift {
            n: Vec3::Z,
            m: r.as_dmat3() * self.m,
            ..*self
        }
    }

    /// [`Self::step`] for every pair of triangles of two nodes projecting on n within `p` and
    /// `q`, the second's inside box `y` (first tooth's frame): the speed, affine in the point, is
    /// extreme at a corner of the box.
    pub(super) fn step_nodes(&self, p: (f32, f32), q: (f32, f32), y: &Aabb) -> f64 {
        let (c, e) = (y.centre().as_dvec3(), (y.extent() * 0.5).as_dvec3());
        let (mid, r) = (c.dot(self.m), e.dot(self.m.abs()));
        let f = |p: (f32, f32)| (p.0 as f64, p.1 as f64);
        self.spans(f(p), f(q), (self.c0 + mid - r, self.c0 + mid + r))
    }

    /// The step for a first body projecting on `p`, a second on `q` moving along n at speeds
    /// within `s`.
    fn spans(&self, p: (f64, f64), q: (f64, f64), s: (f64, f64)) -> f64 {
        // The second beyond the first along n, its points moving at least s_lo along n; or
        // along −n, moving at least −s_hi along −n.
        let side = |gap: f64, s: f64| {
            // The positive root of AΔ²/2 − sΔ − e, written without cancellation.
            let e = gap - self.keep;
            if e <= 0.0 {
                return 0.0;
            }
            let root = (s * s + 2.0 * self.accel * e).sqrt();
            if s < 0.0 {
                2.0 * e / (root - s)
            } else if self.accel > 0.0 {
                (s + root) / self.accel
            } else {
                f64::INFINITY
            }
        };
        side(q.0 - p.1, s.0).max(side(p.0 - q.1, -s.1))
    }
}
