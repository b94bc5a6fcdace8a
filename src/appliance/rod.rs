//! The archwire as an elastic rod: a chain of nodes, each with a position and a material frame,
//! joined by two-node Cosserat (Timoshenko) rod elements, held by slots and tubes
//! ([`Holder`]) and brought to static equilibrium by Newton's method.
//!
//! **Model.** A node's frame has the wire's tangent as its first axis, the slot's height
//! direction (occluso-gingival) as its second and the slot's depth direction (bucco-lingual) as
//! its third. An element's strains are measured at its middle: the chord, seen in the mean of its
//! nodes' frames and divided by its rest length, gives stretch and the two shears; the rotation
//! from one node's frame to the other's, divided by the rest length, gives twist and the two
//! curvatures. Each strain less its value in the wire's passive shape (its arch form) times the
//! section's stiffness (EA, κGA, GJ, EI; [`super::WireSize::properties`]) is the element's stress
//! resultant. Large rotations are exact (rotation vectors of relative rotations, frames as
//! quaternions); strains stay small, as in an archwire. Superelastic NiTi scales the bending
//! moments by its flag-shaped law ([`WireMaterial::bending_scale`]), each element keeping its
//! transformation state from solve to solve.
//!
//! **Guarantee.** [`Rod::solve`] returns when every nodal force is below
//! [`Settings::tolerance_n`] (N, and N·mm for moments), or says it did not converge; with
//! steel and TMA, the equilibrium is that of the discrete model, which converges to beam theory as
//! elements shorten (one-point strain sampling: a cantilever's tip deflection within 1 % at 20
//! elements; tests check cantilever, three-point bending and torsion). A wire in its passive
//! shape, held where it lies, carries no force at all. The element Jacobians are central
//! differences (step 10⁻⁶): exact to about 10⁻⁹ of the strains, far below any force reported.

use glam::{DQuat, DVec3};

use super::banded::Banded;
use super::material::{Transformation, WireMaterial};
use super::section::WireSize;

/// Timoshenko's shear coefficient (round sections 0.9, rectangles 0.83; shear hardly matters in a
/// slender wire).
const SHEAR_FACTOR: f64 = 0.85;
/// Central-difference step for the element Jacobians (mm and radians).
const STEP: f64 = 1e-6;
/// Degrees of freedom per node: three of position, three of rotation.
const DOF: usize = 6;

/// One node of the wire: where it is and how its cross-section is turned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodNode {
    /// Position (mm).
    pub x: DVec3,
    /// Material frame: X the tangent, Y the section's height, Z its width.
    pub q: DQuat,
}

impl RodNode {
    /// The node at `x` with its frame's tangent along `tangent` and its height direction as near
    /// `up` as the tangent allows.
    pub fn along(x: DVec3, tangent: DVec3, up: DVec3) -> Self {
        let t = tangent.normalize();
        let z = t.cross(up).normalize();
        let y = z.cross(t);
        Self {
            x,
            q: DQuat::from_mat3(&glam::DMat3::from_cols(t, y, z)).normalize(),
        }
    }

    /// Moved by `d` (position increments, then world rotation increments).
    fn moved(&self, d: &[f64]) -> Self {
        Self {
            x: self.x + DVec3::new(d[0], d[1], d[2]),
            q: (DQuat::from_scaled_axis(DVec3::new(d[3], d[4], d[5])) * self.q).normalize(),
        }
    }
}

/// The rotation vector of `q` (shortest way round).
fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis()
}

#[derive(Clone, Debug)]
struct Element {
    length: f64,
    rest: [f64; 6],
    state: Transformation,
}

/// An element's six strains between nodes `a` and `b` of rest length `length`: the chord in the
/// mean frame over the length (stretch, two shears), then the relative rotation over the length
/// (twist, two curvatures).
fn strains(a: &RodNode, b: &RodNode, length: f64) -> [f64; 6] {
    let omega = log(a.q.inverse() * b.q);
    let mid = a.q * DQuat::from_scaled_axis(0.5 * omega);
    let gamma = mid.inverse() * (b.x - a.x) / length;
    let k = omega / length;
    [gamma.x, gamma.y, gamma.z, k.x, k.y, k.z]
}

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
    fn offsets(&self, n: &RodNode) -> [f64; 6] {
        let inv = self.frame.inverse();
        let d = inv * (n.x - self.at);
        let t = log(inv * n.q);
        [d.x, d.y, d.z, t.x, t.y, t.z]
    }

    /// The offsets' derivatives by the node's six increments (rows: offsets), by central
    /// differences.
    fn jacobian(&self, n: &RodNode) -> [[f64; 6]; 6] {
        let mut jac = [[0.0; 6]; 6];
        let mut d = [0.0; 6];
        for col in 0..6 {
            d.fill(0.0);
            d[col] = STEP;
            let plus = self.offsets(&n.moved(&d));
            d[col] = -STEP;
            let minus = self.offsets(&n.moved(&d));
            for row in 0..6 {
                jac[row][col] = (plus[row] - minus[row]) / (2.0 * STEP);
            }
        }
        jac
    }

    /// Generalised force of each offset: the stiffness times how far past its play it is.
    fn resultants(&self, c: &[f64; 6]) -> ([f64; 6], [f64; 6]) {
        let mut f = [0.0; 6];
        let mut k = [0.0; 6];
        for i in 0..6 {
            let excess = c[i].abs() - self.play[i];
            // At the edge of the play (a clamp's is zero) the holder already resists.
            if excess >= 0.0 {
                f[i] = self.stiffness[i] * excess * c[i].signum();
                k[i] = self.stiffness[i];
            }
        }
        (f, k)
    }
}

/// A force and a moment (about the node) applied to a node from outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeLoad {
    /// The node.
    pub node: usize,
    /// Force (N).
    pub force: DVec3,
    /// Moment (N·mm).
    pub moment: DVec3,
}

/// What a holder feels from the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reaction {
    /// Force on the holder (N).
    pub force: DVec3,
    /// Moment on the holder about its slot's centre (N·mm).
    pub moment: DVec3,
}

/// How hard [`Rod::solve`] works.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Largest nodal force (N) or moment (N·mm) left at equilibrium.
    pub tolerance_n: f64,
    /// Most Newton iterations.
    pub max_iterations: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            tolerance_n: 1e-5,
            max_iterations: 60,
        }
    }
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equilibrium {
    /// Newton iterations run.
    pub iterations: usize,
    /// Largest nodal force or moment left (N, N·mm).
    pub residual: f64,
    /// True when the residual is within the tolerance.
    pub converged: bool,
}

/// An archwire: its nodes, its passive shape and its section and alloy.
#[derive(Clone, Debug)]
pub struct Rod {
    /// The nodes as they stand.
    pub nodes: Vec<RodNode>,
    elements: Vec<Element>,
    /// Cross-section.
    pub size: WireSize,
    /// Alloy.
    pub material: WireMaterial,
    /// EA, κGA, κGA, GJ, EI about the height axis (in-plane), EI about the width axis.
    stiffness: [f64; 6],
}

impl Rod {
    /// A rod whose passive shape is `rest` (at least two nodes, consecutive ones apart), standing
    /// there.
    ///
    /// # Panics
    /// Never on user input: callers build `rest` from arch forms and checked sizes; two
    /// coincident nodes give an element of zero length, which is skipped.
    pub fn new(rest: Vec<RodNode>, size: WireSize, material: WireMaterial) -> Self {
        let p = size.properties();
        let (e, g) = (material.young(), material.shear());
        let stiffness = [
            e * p.area,
            SHEAR_FACTOR * g * p.area,
            SHEAR_FACTOR * g * p.area,
            g * p.torsion,
            e * p.i_width,
            e * p.i_height,
        ];
        let elements = rest
            .windows(2)
            .map(|w| {
                let length = w[0].x.distance(w[1].x).max(1e-9);
                Element {
                    length,
                    rest: strains(&w[0], &w[1], length),
                    state: Transformation::default(),
                }
            })
            .collect();
        Self {
            nodes: rest,
            elements,
            size,
            material,
            stiffness,
        }
    }

    /// A straight passive wire of `length` mm along +x from `from`, in `elements` elements (its
    /// height across y): the wire of bench tests.
    pub fn straight(
        from: DVec3,
        length: f64,
        elements: usize,
        size: WireSize,
        material: WireMaterial,
    ) -> Self {
        let elements = elements.max(1);
        let nodes = (0..=elements)
            .map(|i| {
                let x = from + DVec3::X * (length * i as f64 / elements as f64);
                RodNode::along(x, DVec3::X, DVec3::Y)
            })
            .collect();
        Self::new(nodes, size, material)
    }

    /// The section's stiffnesses: EA, κGA, κGA (N), GJ, EI in the arch's plane, EI across it
    /// (N·mm²).
    pub fn stiffness(&self) -> [f64; 6] {
        self.stiffness
    }

    /// Element `e`'s stress resultants (N, N·mm) at strains `s`, and its tangent stiffness
    /// (diagonal but for the two bending strains, which NiTi's law couples).
    fn resultants(&self, e: &Element, s: &[f64; 6]) -> ([f64; 6], [[f64; 6]; 6]) {
        let mut c = [[0.0; 6]; 6];
        let mut d = [0.0; 6];
        for i in 0..6 {
            d[i] = s[i] - e.rest[i];
            c[i][i] = self.stiffness[i];
        }
        let bend = (d[4] * d[4] + d[5] * d[5]).sqrt();
        let scale = self.material.bending_scale(bend, self.size, &e.state);
        if scale < 1.0 && bend > 0.0 {
            // M = scale(κ)·EI·κ: EI·scale across the bend, EI·dM/dκ along it.
            let moment = |k: f64| self.material.bending_scale(k, self.size, &e.state) * k;
            let h = 1e-6 * bend;
            let slope = (moment(bend + h) - moment((bend - h).max(0.0))) / (2.0 * h);
            let n = [d[4] / bend, d[5] / bend];
            for (a, i) in [(0, 4), (1, 5)] {
                for (b, j) in [(0, 4), (1, 5)] {
                    let along = n[a] * n[b];
                    let across = if a == b { 1.0 } else { 0.0 } - along;
                    let ei = (self.stiffness[i] * self.stiffness[j]).sqrt();
                    c[i][j] = ei * (scale * across + slope * along);
                }
            }
        }
        let mut f = [0.0; 6];
        for i in 0..4 {
            f[i] = self.stiffness[i] * d[i];
        }
        f[4] = self.stiffness[4] * scale * d[4];
        f[5] = self.stiffness[5] * scale * d[5];
        (f, c)
    }

    /// The residual (internal less external generalised forces per degree of freedom) and, when
    /// asked, the tangent stiffness.
    fn assemble(
        &self,
        holders: &[Holder],
        loads: &[NodeLoad],
        tangent: bool,
    ) -> (Vec<f64>, Option<Banded>) {
        let n = self.nodes.len() * DOF;
        let mut g = vec![0.0; n];
        let mut k = tangent.then(|| Banded::zeros(n, 2 * DOF - 1));
        for (i, e) in self.elements.iter().enumerate() {
            let (a, b) = (self.nodes[i], self.nodes[i + 1]);
            let s = strains(&a, &b, e.length);
            let (f, stiff) = self.resultants(e, &s);
            // J: 6 strains × 12 degrees of freedom, by central differences.
            let mut jac = [[0.0; 12]; 6];
            let mut d = [0.0; 6];
            for col in 0..12 {
                let node = col / DOF;
                d.fill(0.0);
                d[col % DOF] = STEP;
                let plus = if node == 0 {
                    strains(&a.moved(&d), &b, e.length)
                } else {
                    strains(&a, &b.moved(&d), e.length)
                };
                d[col % DOF] = -STEP;
                let minus = if node == 0 {
                    strains(&a.moved(&d), &b, e.length)
                } else {
                    strains(&a, &b.moved(&d), e.length)
                };
                for row in 0..6 {
                    jac[row][col] = (plus[row] - minus[row]) / (2.0 * STEP);
                }
            }
            let base = i * DOF;
            for col in 0..12 {
                let mut v = 0.0;
                for row in 0..6 {
                    v += jac[row][col] * f[row];
                }
                g[base + col] += e.length * v;
            }
            if let Some(k) = k.as_mut() {
                for c1 in 0..12 {
                    for c2 in c1..12 {
                        let mut v = 0.0;
                        for r1 in 0..6 {
                            for r2 in 0..6 {
                                v += jac[r1][c1] * stiff[r1][r2] * jac[r2][c2];
                            }
                        }
                        k.add(base + c1, base + c2, e.length * v);
                    }
                }
            }
        }
        for h in holders.iter().filter(|h| h.node < self.nodes.len()) {
            let node = self.nodes[h.node];
            let c = h.offsets(&node);
            let (f, stiff) = h.resultants(&c);
            if f.iter().all(|v| *v == 0.0) && stiff.iter().all(|v| *v == 0.0) {
                continue;
            }
            let jac = h.jacobian(&node);
            let base = h.node * DOF;
            for col in 0..6 {
                g[base + col] += (0..6).map(|row| jac[row][col] * f[row]).sum::<f64>();
            }
            if let Some(k) = k.as_mut() {
                for c1 in 0..6 {
                    for c2 in c1..6 {
                        let v: f64 = (0..6).map(|r| jac[r][c1] * stiff[r] * jac[r][c2]).sum();
                        k.add(base + c1, base + c2, v);
                    }
                }
            }
        }
        for l in loads.iter().filter(|l| l.node < self.nodes.len()) {
            let base = l.node * DOF;
            for i in 0..3 {
                g[base + i] -= l.force[i];
                g[base + 3 + i] -= l.moment[i];
            }
        }
        (g, k)
    }

    /// Brings the wire to equilibrium in its `holders` under `loads`, starting from where it
    /// stands, then records each NiTi element's transformation.
    pub fn solve(
        &mut self,
        holders: &[Holder],
        loads: &[NodeLoad],
        settings: &Settings,
    ) -> Equilibrium {
        let worst = |g: &[f64]| g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (mut g, _) = self.assemble(holders, loads, false);
        let mut residual = worst(&g);
        let mut iterations = 0;
        while residual > settings.tolerance_n && iterations < settings.max_iterations {
            iterations += 1;
            let (_, Some(mut k)) = self.assemble(holders, loads, true) else {
                break;
            };
            // A little of the diagonal keeps a wire free within its play solvable: it stays
            // where it is in the directions nothing holds.
            let n = k.order();
            let largest = (0..n).map(|i| k.get(i, i)).fold(0.0f64, f64::max).max(1.0);
            for i in 0..n {
                k.add(i, i, 1e-10 * largest + 1e-9);
            }
            let mut step: Vec<f64> = g.iter().map(|v| -v).collect();
            if !k.solve(&mut step) {
                break;
            }
            // At most 1 mm or 0.3 rad at once; then along the step to where the energy stops
            // falling: the residual is the energy's gradient, so its projection on the step is
            // the slope, bracketed and narrowed by false position.
            let longest = step.iter().enumerate().fold(0.0f64, |m, (i, v)| {
                let limit = if i % DOF < 3 { 1.0 } else { 0.3 };
                m.max(v.abs() / limit)
            });
            let dot = |g: &[f64]| g.iter().zip(&step).map(|(a, b)| a * b).sum::<f64>();
            let start = self.nodes.clone();
            let at = |rod: &mut Self, alpha: f64| {
                for (i, node) in rod.nodes.iter_mut().enumerate() {
                    let d: Vec<f64> = step[i * DOF..(i + 1) * DOF]
                        .iter()
                        .map(|v| alpha * v)
                        .collect();
                    *node = start[i].moved(&d);
                }
                rod.assemble(holders, loads, false).0
            };
            let slope0 = dot(&g);
            if slope0 >= 0.0 {
                break;
            }
            let (mut lo, mut s_lo) = (0.0, slope0);
            let mut hi = if longest > 1.0 { 1.0 / longest } else { 1.0 };
            let mut trial = at(self, hi);
            let mut s_hi = dot(&trial);
            for _ in 0..10 {
                if s_hi <= 0.0 || s_hi.abs() < 0.05 * slope0.abs() {
                    break;
                }
                let width = hi - lo;
                let guess = lo - s_lo * width / (s_hi - s_lo);
                let alpha = guess.clamp(lo + 0.05 * width, hi - 0.05 * width);
                let g_alpha = at(self, alpha);
                let s_alpha = dot(&g_alpha);
                if s_alpha < 0.0 {
                    (lo, s_lo) = (alpha, s_alpha);
                    if s_alpha.abs() < 0.05 * slope0.abs() {
                        (hi, trial, s_hi) = (alpha, g_alpha, s_alpha);
                        break;
                    }
                } else {
                    (hi, trial, s_hi) = (alpha, g_alpha, s_alpha);
                }
            }
            if s_hi > 0.0 && s_hi.abs() >= 0.05 * slope0.abs() {
                // The bracket narrowed without meeting the minimum: take its falling end.
                trial = at(self, lo.max(1e-12));
            } else if !(self.nodes.iter().all(|n| n.x.is_finite())) {
                self.nodes = start;
                break;
            }
            let _ = hi;
            g = trial;
            residual = worst(&g);
        }
        let converged = residual <= settings.tolerance_n;
        if converged && self.material.superelastic() {
            for i in 0..self.elements.len() {
                let s = strains(&self.nodes[i], &self.nodes[i + 1], self.elements[i].length);
                let e = &mut self.elements[i];
                let bend = ((s[4] - e.rest[4]).powi(2) + (s[5] - e.rest[5]).powi(2)).sqrt();
                self.material.advance(&mut e.state, bend, self.size);
            }
        }
        Equilibrium {
            iterations,
            residual,
            converged,
        }
    }

    /// What each holder feels from the wire as it stands: force, and moment about the slot's
    /// centre.
    pub fn reactions(&self, holders: &[Holder]) -> Vec<Reaction> {
        holders
            .iter()
            .map(|h| {
                let Some(node) = self.nodes.get(h.node) else {
                    return Reaction::default();
                };
                let c = h.offsets(node);
                let (f, _) = h.resultants(&c);
                // The generalised forces on the node, back in the world frame.
                let jac = h.jacobian(node);
                let g: [f64; 6] =
                    std::array::from_fn(|col| (0..6).map(|r| jac[r][col] * f[r]).sum());
                // The wire feels −g; the holder feels +g, its moment taken about the slot.
                let force = DVec3::new(g[0], g[1], g[2]);
                let moment = DVec3::new(g[3], g[4], g[5]) + (node.x - h.at).cross(force);
                Reaction { force, moment }
            })
            .collect()
    }

    /// The elastic energy stored in the wire (N·mm), linear-elastic parts exactly, NiTi's bending
    /// by its secant: what falls as the teeth align.
    pub fn energy(&self) -> f64 {
        self.elements
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let s = strains(&self.nodes[i], &self.nodes[i + 1], e.length);
                let (f, _) = self.resultants(e, &s);
                0.5 * e.length * (0..6).map(|k| f[k] * (s[k] - e.rest[k])).sum::<f64>()
            })
            .sum()
    }
}

#[cfg(test)]
mod tests;
