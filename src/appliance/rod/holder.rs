//! What holds the wire: a slot, a tube or a clamp, with its play and its walls.

use glam::{DMat3, DQuat, DVec3};

use super::RodNode;
use super::strain::{jl_inv, log};

/// Width over which a holder's wall comes into play (mm for offsets, radians for turns).
pub const EDGE_BLEND: f64 = 1e-2;

/// What holds a node of the wire: a bracket's slot, a tube, a clamp. Its frame's X runs along
/// the slot (the way the wire runs), Y across the slot's height, Z into its depth. Each of the
/// node's six offsets from the holder (three of position, three of rotation, in the holder's
/// frame) moves freely within its play and meets the holder's stiffness beyond it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Holder {
    /// The node held.
    pub node: usize,
    /// The slot's centre (mm).
    pub at: DVec3,
    /// The slot's frame.
    pub frame: DQuat,
    /// Free play each way of the six offsets: along, across, into (mm), then about the slot's
    /// axis (torque play), about its height and about its depth (radians);
    /// `f64::INFINITY` where the holder does not hold.
    pub play: [f64; 6],
    /// Stiffness beyond the play: N/mm for offsets, N·mm/rad for turns.
    pub stiffness: [f64; 6],
}

impl Holder {
    /// A clamp: the node fixed in place and turn.
    pub fn clamp(node: usize, at: &RodNode) -> Self {
        Self {
            node,
            at: at.x,
            frame: at.q,
            play: [0.0; 6],
            stiffness: [1e6, 1e6, 1e6, 1e6, 1e6, 1e6],
        }
    }

    /// A pin: the node held in place, free to turn.
    pub fn pin(node: usize, at: &RodNode) -> Self {
        let mut h = Self::clamp(node, at);
        h.play[3..].fill(f64::INFINITY);
        h
    }

    /// The node's six offsets from the holder.
    pub(super) fn offsets(&self, n: &RodNode) -> [f64; 6] {
        let inv = self.frame.inverse();
        let d = inv * (n.x - self.at);
        let t = log(inv * n.q);
        [d.x, d.y, d.z, t.x, t.y, t.z]
    }

    /// The offsets' derivatives by the node's six increments (rows: offsets): the holder's
    /// frame turns positions; a turn's rotation vector moves by Jl⁻¹ of itself.
    pub(super) fn jacobian(&self, n: &RodNode) -> [[f64; 6]; 6] {
        let inv = DMat3::from_quat(self.frame.inverse());
        let t = log(self.frame.inverse() * n.q);
        let turn = jl_inv(t) * inv;
        let mut jac = [[0.0; 6]; 6];
        for c in 0..3 {
            for r in 0..3 {
                jac[r][c] = inv.col(c)[r];
                jac[3 + r][3 + c] = turn.col(c)[r];
            }
        }
        jac
    }

    /// Generalised force of each offset: the stiffness times how far past its play it is, and
    /// its derivative. The edge of a play is rounded over [`EDGE_BLEND`] (a quadratic blend: a
    /// force of a thousandth of a newton where a wire just meets a wall), so the force's
    /// derivative has no jump for Newton's method to chatter on; a clamp (no play) is linear
    /// through zero.
    pub(super) fn resultants(&self, c: &[f64; 6]) -> ([f64; 6], [f64; 6]) {
        let mut f = [0.0; 6];
        let mut k = [0.0; 6];
        for i in 0..6 {
            let (play, stiff) = (self.play[i], self.stiffness[i]);
            if play <= 0.0 {
                f[i] = stiff * c[i];
                k[i] = stiff;
                continue;
            }
            let w = EDGE_BLEND.min(play);
            let excess = c[i].abs() - play;
            if excess >= 0.5 * w {
                f[i] = stiff * excess * c[i].signum();
                k[i] = stiff;
            } else if excess > -0.5 * w {
                let into = excess + 0.5 * w;
                f[i] = stiff * into * into / (2.0 * w) * c[i].signum();
                k[i] = stiff * into / w;
            }
        }
        (f, k)
    }
}
