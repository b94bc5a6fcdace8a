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
//! elements shorten; with one-point strain sampling and the shear softened by the residual
//! bending flexibility (MacNeal), a straight span loaded at its nodes bends as beam theory says
//! however few elements it has (a 5 mm span between two slots within 0.5 % in two elements;
//! tests check cantilever, three-point bending, torsion and that span). A wire in its passive
//! shape, held where it lies, carries no force at all. The strains' derivatives are exact (the
//! rotation group's left Jacobian). Far from equilibrium the tangent is their Gauss–Newton
//! part (positive semi-definite, so every step goes downhill); once a full step is taken the
//! geometric stiffness (the stress resultants on the strains' curvature, by differences of the
//! exact derivatives) is added for Newton's quadratic convergence. A line search on the energy
//! keeps every step monotone, and the tangent's factor is reused while it quarters the residual.
//! A step the line search cuts below half stiffens the next tangent's diagonal
//! (Levenberg–Marquardt: a wire free within its slots' play is nearly a mechanism, and an
//! undamped tangent sends it millimetres along the arch); longer steps relax the damping back to
//! pure Newton.

use glam::{DQuat, DVec3};

use super::banded::{Banded, Factor};

mod holder;
mod strain;

use super::material::{Transformation, WireMaterial};
use super::section::WireSize;
pub use holder::{EDGE_BLEND, Holder};
use strain::{strains, strains_and_jacobian};

/// Timoshenko's shear coefficient (round sections 0.9, rectangles 0.83; shear hardly matters in a
/// slender wire).
const SHEAR_FACTOR: f64 = 0.85;
/// Forward-difference step for the geometric stiffness (mm and radians).
const GEOMETRIC_STEP: f64 = 1e-6;
/// Degrees of freedom per node: three of position, three of rotation.
const DOF: usize = 6;

/// The stiffness of the equilibrium equations in two parts: the material part JᵀCJ (positive
/// semi-definite) and the geometric part Σ fᵢ∇²sᵢ (the stress resultants on the strains'
/// curvature, indefinite under compression).
struct Tangent {
    material: Banded,
    geometric: Banded,
}

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

#[derive(Clone, Debug)]
struct Element {
    length: f64,
    rest: [f64; 6],
    /// Shear stiffness across the height and across the depth (N), less its residual bending
    /// flexibility (see [`Rod::new`]).
    shear: [f64; 2],
    state: Transformation,
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

/// Residual force (N, and N·mm for moments) a simulation step's wire solve stops at: under a
/// percent of the 0.3–2 N a wire moves teeth with, and a hundred times looser than
/// [`Settings::default`], which the beam-theory checks use (a step's Newton iterations mostly go
/// to the last digits, against slots' walls that switch on and off).
pub const STEP_TOLERANCE_N: f64 = 1e-3;
/// Most Newton iterations of a simulation step's solve, before the simulation tries again with
/// more.
pub const STEP_ITERATIONS: usize = 40;

/// How far the wire slides each way through the bracket carrying its stop before the stop bears
/// on the bracket (mm): a stop crimped on the wire half a millimetre from each side.
pub const STOP_PLAY_MM: f64 = 0.5;

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
    /// The last tangent's factor, reused from iteration to iteration and solve to solve while it
    /// still converges fast: a simulation's brackets move little between solves.
    factor: Option<Factor>,
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
                // MacNeal's residual bending flexibility: a two-node element with its curvature
                // sampled once is too stiff in bending by a shear-like h²/12EI, which softening
                // its shear by as much cancels (nodal displacements of a linear beam under end
                // loads then exact at any element length). Shear across the height pairs with
                // bending about the depth axis and the other way round.
                let soften = |ga: f64, ei: f64| 1.0 / (1.0 / ga + length * length / (12.0 * ei));
                Element {
                    length,
                    rest: strains(&w[0], &w[1], length),
                    shear: [
                        soften(stiffness[1], stiffness[5]),
                        soften(stiffness[2], stiffness[4]),
                    ],
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
            factor: None,
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

    /// Puts the wire's nodes back where they were (as many as it has), forgetting its tangent;
    /// the transformation state of NiTi elements is kept (it changes only at equilibria).
    pub fn place(&mut self, nodes: Vec<RodNode>) {
        if nodes.len() == self.nodes.len() {
            self.nodes = nodes;
            self.factor = None;
        }
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
        let k = [
            self.stiffness[0],
            e.shear[0],
            e.shear[1],
            self.stiffness[3],
            self.stiffness[4],
            self.stiffness[5],
        ];
        for i in 0..6 {
            d[i] = s[i] - e.rest[i];
            c[i][i] = k[i];
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
            f[i] = k[i] * d[i];
        }
        f[4] = self.stiffness[4] * scale * d[4];
        f[5] = self.stiffness[5] * scale * d[5];
        (f, c)
    }

    /// The residual (internal less external generalised forces per degree of freedom) and, when
    /// asked (`Some`), the tangent stiffness, with its geometric part when `Some(true)`.
    fn assemble(
        &self,
        holders: &[Holder],
        loads: &[NodeLoad],
        tangent: Option<bool>,
    ) -> (Vec<f64>, Option<Tangent>) {
        let geometric_too = tangent == Some(true);
        let n = self.nodes.len() * DOF;
        let mut g = vec![0.0; n];
        let mut k = tangent.map(|_| Tangent {
            material: Banded::zeros(n, 2 * DOF - 1),
            geometric: Banded::zeros(n, 2 * DOF - 1),
        });
        for (i, e) in self.elements.iter().enumerate() {
            let (a, b) = (self.nodes[i], self.nodes[i + 1]);
            let (s, jac) = strains_and_jacobian(&a, &b, e.length);
            let (f, stiff) = self.resultants(e, &s);
            let base = i * DOF;
            let own: [f64; 12] =
                std::array::from_fn(|col| (0..6).map(|row| jac[row][col] * f[row]).sum::<f64>());
            for col in 0..12 {
                g[base + col] += e.length * own[col];
            }
            if let Some(Tangent {
                material: k,
                geometric,
            }) = k.as_mut()
            {
                // The resultants held, the strains' curvature: forward differences of Jᵀ·f,
                // made symmetric.
                let mut geo = [[0.0; 12]; 12];
                for (col, column) in geo.iter_mut().enumerate().filter(|_| geometric_too) {
                    let mut d = [0.0; DOF];
                    d[col % DOF] = GEOMETRIC_STEP;
                    let (_, moved) = if col < DOF {
                        strains_and_jacobian(&a.moved(&d), &b, e.length)
                    } else {
                        strains_and_jacobian(&a, &b.moved(&d), e.length)
                    };
                    for (c1, v) in column.iter_mut().enumerate() {
                        let turned: f64 = (0..6).map(|row| moved[row][c1] * f[row]).sum();
                        *v = e.length * (turned - own[c1]) / GEOMETRIC_STEP;
                    }
                }
                for c1 in 0..12 {
                    for c2 in c1..12 {
                        geometric.add(base + c1, base + c2, 0.5 * (geo[c1][c2] + geo[c2][c1]));
                    }
                }
                // C·J first (C is diagonal but for NiTi's two bending strains), then Jᵀ·(C·J).
                let mut cj = [[0.0; 12]; 6];
                for (r1, row) in cj.iter_mut().enumerate() {
                    for (r2, c) in stiff[r1].iter().enumerate() {
                        if *c != 0.0 {
                            for (v, j) in row.iter_mut().zip(&jac[r2]) {
                                *v += c * j;
                            }
                        }
                    }
                }
                for c1 in 0..12 {
                    for c2 in c1..12 {
                        let v: f64 = (0..6).map(|r| jac[r][c1] * cj[r][c2]).sum();
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
            if let Some(Tangent {
                material: k,
                geometric,
            }) = k.as_mut()
            {
                let mut geo = [[0.0; 6]; 6];
                for (col, column) in geo.iter_mut().enumerate().filter(|_| geometric_too) {
                    let mut d = [0.0; DOF];
                    d[col] = GEOMETRIC_STEP;
                    let moved = h.jacobian(&node.moved(&d));
                    for (c1, v) in column.iter_mut().enumerate() {
                        let turned: f64 = (0..6).map(|r| (moved[r][c1] - jac[r][c1]) * f[r]).sum();
                        *v = turned / GEOMETRIC_STEP;
                    }
                }
                for c1 in 0..6 {
                    for c2 in c1..6 {
                        geometric.add(base + c1, base + c2, 0.5 * (geo[c1][c2] + geo[c2][c1]));
                    }
                }
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

    /// The tangent at the wire as it stands, factored: Newton's full tangent where it is positive
    /// definite (a wire not buckling), otherwise its material part alone, still a descent
    /// direction. A little of the diagonal keeps a wire free within its play solvable: it stays
    /// where it is in the directions nothing holds.
    fn tangent_factor(
        &self,
        holders: &[Holder],
        loads: &[NodeLoad],
        geometric_too: bool,
        damping: f64,
    ) -> Option<Factor> {
        let Tangent {
            material: mut k,
            geometric,
        } = self.assemble(holders, loads, Some(geometric_too)).1?;
        let n = k.order();
        let largest = (0..n).map(|i| k.get(i, i)).fold(0.0f64, f64::max).max(1.0);
        for i in 0..n {
            let d = k.get(i, i);
            k.add(i, i, damping * d + 1e-10 * largest + 1e-9);
        }
        if geometric_too {
            let mut full = k.clone();
            full.add_matrix(&geometric);
            if let Some(f) = full.factor() {
                return Some(f);
            }
        }
        k.factor()
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
        let mut g = self.assemble(holders, loads, None).0;
        let mut residual = worst(&g);
        let mut iterations = 0;
        if self.factor.as_ref().map(Factor::order) != Some(g.len()) {
            self.factor = None;
        }
        // The material part of the tangent alone (Gauss–Newton: a descent direction wherever
        // the wire stands) until a full step is taken, then Newton's full tangent for its
        // quadratic convergence near equilibrium, back to the material part when a step is cut
        // short.
        let mut geometric_too = false;
        let mut damping = 0.0f64;
        while residual > settings.tolerance_n && iterations < settings.max_iterations {
            iterations += 1;
            let mut step: Vec<f64> = g.iter().map(|v| -v).collect();
            match &self.factor {
                Some(f) => f.solve(&mut step),
                None => step.fill(0.0),
            }
            let descends = g.iter().zip(&step).map(|(a, b)| a * b).sum::<f64>() < 0.0;
            if self.factor.is_none() || !descends {
                let Some(f) = self.tangent_factor(holders, loads, geometric_too, damping) else {
                    break;
                };
                step = g.iter().map(|v| -v).collect();
                f.solve(&mut step);
                self.factor = Some(f);
            }
            // At most 1 mm or 0.3 rad at once; then along the step to where the energy stops
            // falling: the residual is the energy's gradient, so its projection on the step is
            // the slope, bracketed and narrowed by false position.
            let longest = step.iter().enumerate().fold(0.0f64, |m, (i, v)| {
                let limit = if i % DOF < 3 { 1.0 } else { 0.3 };
                m.max(v.abs() / limit)
            });
            let dot = |g: &[f64]| g.iter().zip(&step).map(|(a, b)| a * b).sum::<f64>();
            let before = residual;
            let start = self.nodes.clone();
            let at = |rod: &mut Self, alpha: f64| {
                for (i, node) in rod.nodes.iter_mut().enumerate() {
                    let d: [f64; DOF] = std::array::from_fn(|j| alpha * step[i * DOF + j]);
                    *node = start[i].moved(&d);
                }
                rod.assemble(holders, loads, None).0
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
                let at_alpha = at(self, alpha);
                let s_alpha = dot(&at_alpha);
                if s_alpha < 0.0 {
                    (lo, s_lo) = (alpha, s_alpha);
                    if s_alpha.abs() < 0.05 * slope0.abs() {
                        (hi, trial, s_hi) = (alpha, at_alpha, s_alpha);
                        break;
                    }
                } else {
                    (hi, trial, s_hi) = (alpha, at_alpha, s_alpha);
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
            // The tangent is kept while its full steps quarter the residual; otherwise the next
            // iteration builds it afresh where the wire now stands.
            if hi < 1.0 || residual > 0.25 * before {
                self.factor = None;
            }
            geometric_too = hi >= 1.0;
            // Levenberg–Marquardt: a step the line search cut below half means the tangent
            // promised too much (a wire free within its slots' play is soft in whole-wire
            // slides and turns); the next tangent stiffens its diagonal, and a step kept at
            // least half relaxes it.
            damping = if hi < 0.5 {
                (damping * 10.0).clamp(1e-4, 1.0)
            } else if damping < 1e-8 {
                0.0
            } else {
                damping * 0.1
            };
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

    /// The stiffness each holder meets when it moves and the wire follows to its new
    /// equilibrium (world; rows: force, then moment on the holder; columns: its translation, then
    /// its turn), from the material tangent where the wire stands (kept for the next solve): the
    /// holder's own walls in series with the rest of the wire, `A − A·S·A` for the holder's
    /// stiffness `A` at its node and the node's block `S` of the tangent's inverse. Zero for a
    /// holder the wire does not bear on. Exact to first order about the last equilibrium.
    pub fn holder_stiffness(&mut self, holders: &[Holder]) -> Vec<[[f64; 6]; 6]> {
        // A fresh material tangent where the wire stands: a stale one may lack walls the wire
        // now bears on (its inverse would then exceed the walls' and the result turn negative).
        self.factor = self.tangent_factor(holders, &[], false, 0.0);
        // The inverse's diagonal blocks, all at once.
        let inverse = self.factor.as_ref().map(Factor::inverse_band);
        holders
            .iter()
            .map(|h| {
                let mut out = [[0.0; 6]; 6];
                let (Some(z), Some(node)) = (&inverse, self.nodes.get(h.node)) else {
                    return out;
                };
                let (_, k) = h.resultants(&h.offsets(node));
                if k.iter().all(|v| *v == 0.0) {
                    return out;
                }
                let jac = h.jacobian(node);
                let a: [[f64; 6]; 6] = std::array::from_fn(|i| {
                    std::array::from_fn(|j| (0..6).map(|r| jac[r][i] * k[r] * jac[r][j]).sum())
                });
                let base = h.node * DOF;
                let inv: [[f64; 6]; 6] =
                    std::array::from_fn(|i| std::array::from_fn(|j| z.get(base + i, base + j)));
                let mul = |x: &[[f64; 6]; 6], y: &[[f64; 6]; 6]| -> [[f64; 6]; 6] {
                    std::array::from_fn(|i| {
                        std::array::from_fn(|j| (0..6).map(|m| x[i][m] * y[m][j]).sum())
                    })
                };
                let asa = mul(&mul(&a, &inv), &a);
                for i in 0..6 {
                    for j in 0..6 {
                        out[i][j] = a[i][j] - 0.5 * (asa[i][j] + asa[j][i]);
                    }
                }
                out
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
