//! An element's strains and their exact derivatives, and the rotation group's tools they use.

use glam::{DMat3, DQuat, DVec3};

use super::RodNode;

/// The rotation vector of `q` (shortest way round).
pub(super) fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis()
}

/// An element's six strains between nodes `a` and `b` of rest length `length`: the chord in the
/// mean frame over the length (stretch, two shears), then the relative rotation over the length
/// (twist, two curvatures).
pub(super) fn strains(a: &RodNode, b: &RodNode, length: f64) -> [f64; 6] {
    let omega = log(a.q.inverse() * b.q);
    let mid = a.q * DQuat::from_scaled_axis(0.5 * omega);
    let gamma = mid.inverse() * (b.x - a.x) / length;
    let k = omega / length;
    [gamma.x, gamma.y, gamma.z, k.x, k.y, k.z]
}

/// Puts the 3×3 block `m` into rows `row..row + 3`, columns `col..col + 3` of `jac`.
pub(super) fn put(jac: &mut [[f64; 12]; 6], row: usize, col: usize, m: DMat3) {
    for c in 0..3 {
        let v = m.col(c);
        for r in 0..3 {
            jac[row + r][col + c] = v[r];
        }
    }
}

/// [`strains`] and their derivatives by the two nodes' twelve increments (position of `a`, turn
/// of `a`, position of `b`, turn of `b`; turns as world rotation vectors applied on the left).
pub(super) fn strains_and_jacobian(
    a: &RodNode,
    b: &RodNode,
    length: f64,
) -> ([f64; 6], [[f64; 12]; 6]) {
    let omega = log(a.q.inverse() * b.q);
    let mid = DMat3::from_quat(a.q * DQuat::from_scaled_axis(0.5 * omega));
    let ra = DMat3::from_quat(a.q);
    let chord = b.x - a.x;
    let inv = 1.0 / length;
    let mt = mid.transpose();
    let gamma = mt * chord * inv;
    let k = omega * inv;
    // ω = log(Raᵀ·Rb): dω = Jl⁻¹(ω)·Raᵀ·(dθb − dθa).
    let turn = jl_inv(omega) * ra.transpose();
    // The mean frame qa·exp(ω/2) turns by δ = dθa + ½·Ra·Jl(ω/2)·dω.
    let half = ra * jl(0.5 * omega) * turn * 0.5;
    // γ = Mᵀ·chord/L: dγ = Mᵀ·(dxb − dxa)/L + Mᵀ·[chord]×·δ/L.
    let by_turn = mt * skew(chord) * inv;
    let mut jac = [[0.0; 12]; 6];
    put(&mut jac, 0, 0, mt * -inv);
    put(&mut jac, 0, 6, mt * inv);
    put(&mut jac, 0, 3, by_turn * (DMat3::IDENTITY - half));
    put(&mut jac, 0, 9, by_turn * half);
    put(&mut jac, 3, 3, turn * -inv);
    put(&mut jac, 3, 9, turn * inv);
    ([gamma.x, gamma.y, gamma.z, k.x, k.y, k.z], jac)
}

/// The cross-product matrix of `v`: `skew(v) * w == v.cross(w)`.
pub(super) fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// The left Jacobian of the rotation group at `phi`: `exp(phi + d) ≈ exp(jl(phi)·d)·exp(phi)`.
pub(super) fn jl(phi: DVec3) -> DMat3 {
    let t2 = phi.length_squared();
    let s = skew(phi);
    let (a, b) = if t2 < 1e-8 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    DMat3::IDENTITY + s * a + s * s * b
}

/// The inverse of [`jl`]: `log(exp(d)·exp(phi)) ≈ phi + jl_inv(phi)·d`.
pub(super) fn jl_inv(phi: DVec3) -> DMat3 {
    let t2 = phi.length_squared();
    let s = skew(phi);
    let c = if t2 < 1e-8 {
        1.0 / 12.0 + t2 / 720.0
    } else {
        let t = t2.sqrt();
        1.0 / t2 - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    DMat3::IDENTITY - s * 0.5 + s * s * c
}
