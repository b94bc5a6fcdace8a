//! The rod against beam theory, and its equilibria in slots.

use super::strain::log;
use super::*;

/// A straight wire along X from 0 to `length`, `elements` elements.
fn straight(length: f64, elements: usize, size: WireSize, m: WireMaterial) -> Rod {
    Rod::straight(DVec3::ZERO, length, elements, size, m)
}

fn load(node: usize, force: DVec3, moment: DVec3) -> NodeLoad {
    NodeLoad {
        node,
        force,
        moment,
    }
}

#[test]
fn a_cantilever_bends_as_beam_theory_says() {
    let mut rod = straight(
        10.0,
        20,
        WireSize::Round(0.016),
        WireMaterial::StainlessSteel,
    );
    let clamp = Holder::clamp(0, &rod.nodes[0].clone());
    let p = 0.1;
    let e = rod.solve(
        &[clamp],
        &[load(20, DVec3::new(0.0, -p, 0.0), DVec3::ZERO)],
        &Settings::default(),
    );
    assert!(e.converged, "{e:?}");
    let k = rod.stiffness();
    let want = p * 1000.0 / (3.0 * k[5]) + p * 10.0 / k[1];
    let got = -rod.nodes[20].x.y;
    assert!(
        (got / want - 1.0).abs() < 0.01,
        "tip {got} mm, theory {want} mm"
    );
    // The clamp holds the load and its moment.
    let r = rod.reactions(&[clamp])[0];
    assert!((r.force.y + p).abs() < 1e-6, "{r:?}");
    assert!((r.moment.z + p * 10.0).abs() < 0.01 * p * 10.0, "{r:?}");
}

#[test]
fn three_point_bending_gives_48_ei_over_l_cubed() {
    let span = 10.0;
    let mut rod = straight(
        span,
        20,
        WireSize::Round(0.016),
        WireMaterial::StainlessSteel,
    );
    let left = Holder::pin(0, &rod.nodes[0].clone());
    let mut right = Holder::pin(20, &rod.nodes[20].clone());
    right.play[0] = f64::INFINITY;
    let p = 0.5;
    let e = rod.solve(
        &[left, right],
        &[load(10, DVec3::new(0.0, 0.0, -p), DVec3::ZERO)],
        &Settings::default(),
    );
    assert!(e.converged, "{e:?}");
    let stiffness = p / -rod.nodes[10].x.z;
    let theory = 48.0 * rod.stiffness()[4] / span.powi(3);
    assert!(
        (stiffness / theory - 1.0).abs() < 0.02,
        "{stiffness} N/mm against {theory}"
    );
}

#[test]
fn pure_torsion_twists_by_tl_over_gj() {
    let mut rod = straight(
        8.0,
        16,
        WireSize::Rect(0.016, 0.022),
        WireMaterial::StainlessSteel,
    );
    let clamp = Holder::clamp(0, &rod.nodes[0].clone());
    let t = 5.0;
    let e = rod.solve(
        &[clamp],
        &[load(16, DVec3::ZERO, DVec3::new(t, 0.0, 0.0))],
        &Settings::default(),
    );
    assert!(e.converged, "{e:?}");
    let twist = log(rod.nodes[16].q).x;
    let theory = t * 8.0 / rod.stiffness()[3];
    assert!(
        (twist / theory - 1.0).abs() < 0.005,
        "{twist} rad against {theory}"
    );
    // Pure torsion moves no node.
    assert!(
        rod.nodes
            .iter()
            .all(|n| n.x.y.abs() < 1e-6 && n.x.z.abs() < 1e-6)
    );
}

/// A symmetric arch, from the patient's right (−x) to the left, 4 elements between brackets.
fn arch(material: WireMaterial, size: WireSize) -> (Rod, Vec<Holder>) {
    let n = 48;
    let nodes: Vec<RodNode> = (0..=n)
        .map(|i| {
            let u = -1.0 + 2.0 * i as f64 / n as f64;
            let x = DVec3::new(22.0 * u, 0.0, 25.0 * (1.0 - u * u));
            let t = DVec3::new(22.0, 0.0, -50.0 * u);
            RodNode::along(x, t, DVec3::Y)
        })
        .collect();
    let rod = Rod::new(nodes, size, material);
    let holders = (2..=n - 2)
        .step_by(4)
        .map(|i| {
            let mut h = Holder::clamp(i, &rod.nodes[i].clone());
            h.play = [f64::INFINITY, 0.05, 0.05, 0.1, 0.02, 0.02];
            h.stiffness = [0.0, 1e4, 1e4, 1e4, 1e4, 1e4];
            h
        })
        .collect();
    (rod, holders)
}

#[test]
fn a_passive_wire_pushes_nothing() {
    let (mut rod, holders) = arch(WireMaterial::StainlessSteel, WireSize::Rect(0.019, 0.025));
    let e = rod.solve(&holders, &[], &Settings::default());
    assert!(e.converged && e.iterations == 0, "{e:?}");
    assert!(rod.energy().abs() < 1e-12);
    for r in rod.reactions(&holders) {
        assert!(r.force.length() < 1e-9 && r.moment.length() < 1e-9, "{r:?}");
    }
}

#[test]
fn mirrored_activations_give_mirrored_forces() {
    let (mut rod, mut holders) = arch(WireMaterial::StainlessSteel, WireSize::Round(0.016));
    let last = holders.len() - 1;
    // The second bracket from each end displaced the mirror image of the other.
    let d = DVec3::new(0.3, 0.6, -0.4);
    holders[1].at += d;
    holders[last - 1].at += DVec3::new(-d.x, d.y, d.z);
    let e = rod.solve(&holders, &[], &Settings::default());
    assert!(e.converged, "{e:?}");
    let r = rod.reactions(&holders);
    let mirror = |v: DVec3| DVec3::new(-v.x, v.y, v.z);
    for i in 0..holders.len() {
        let (a, b) = (r[i], r[last - i]);
        assert!(
            (a.force - mirror(b.force)).length() < 1e-4 * (1.0 + a.force.length()),
            "{i}: {a:?} against {b:?}"
        );
        // Moments are axial: mirrored in x they keep x and turn y and z.
        let m = DVec3::new(b.moment.x, -b.moment.y, -b.moment.z);
        assert!(
            (a.moment - m).length() < 1e-3 * (1.0 + a.moment.length()),
            "{i}"
        );
    }
    // The wire pulls the displaced brackets back towards where it was passive.
    assert!(r[1].force.dot(d) < 0.0, "{:?}", r[1]);
    // Forces balance: the wire is free.
    let total: DVec3 = r.iter().map(|r| r.force).sum();
    assert!(total.length() < 1e-5, "{total}");
}

#[test]
fn the_wires_energy_falls_as_the_teeth_align() {
    let (mut rod, holders) = arch(WireMaterial::NiTi, WireSize::Round(0.014));
    let mut last = f64::INFINITY;
    let mut first = None;
    for k in (0..=4).rev() {
        let mut h = holders.clone();
        h[3].at += DVec3::new(0.0, 0.0, -0.5 * k as f64);
        let e = rod.solve(&h, &[], &Settings::default());
        assert!(e.converged, "{e:?}");
        let energy = rod.energy();
        assert!(energy < last, "{k}: {energy} after {last}");
        last = energy;
        first.get_or_insert(energy);
    }
    // Aligned, the wire is passive: what is left is the solve's tolerance.
    let first = first.unwrap_or_default();
    assert!(first > 1e-2 && last < 1e-6 * first, "{last} of {first}");
}

#[test]
fn niti_unloads_below_its_loading_force() {
    let span = 14.0;
    let mut rod = straight(span, 28, WireSize::Round(0.016), WireMaterial::NiTi);
    let left = Holder::pin(0, &rod.nodes[0].clone());
    let mut right = Holder::pin(28, &rod.nodes[28].clone());
    right.play[0] = f64::INFINITY;
    // The middle node pushed to a depth by a stiff holder free to turn.
    let push = |rod: &mut Rod, depth: f64| {
        let mut h = Holder::pin(14, &rod.nodes[14].clone());
        h.at = DVec3::new(0.5 * span, 0.0, -depth);
        h.play[0] = f64::INFINITY;
        let holders = [left, right, h];
        let e = rod.solve(&holders, &[], &Settings::default());
        assert!(e.converged, "{depth}: {e:?}");
        rod.reactions(&holders)[2].force.z
    };
    let mut loading = Vec::new();
    for d in [0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
        loading.push(push(&mut rod, d));
    }
    let unloading_2 = push(&mut rod, 2.0);
    let unloading_1 = push(&mut rod, 1.0);
    // Loading flattens onto its plateau; unloading runs below it.
    assert!(loading[5] < 1.6 * loading[2], "{loading:?}");
    assert!(
        unloading_2 < 0.8 * loading[3],
        "{unloading_2} against {loading:?}"
    );
    assert!(
        unloading_1 < unloading_2 && unloading_1 > 0.0,
        "{unloading_1} {unloading_2}"
    );
}

/// Central differences of `f` by the twelve increments of two nodes.
fn differences<const R: usize>(
    a: &RodNode,
    b: &RodNode,
    f: impl Fn(&RodNode, &RodNode) -> [f64; R],
) -> Vec<[f64; R]> {
    let h = 1e-6;
    (0..12)
        .map(|col| {
            let mut d = [0.0; 6];
            d[col % 6] = h;
            let plus = if col < 6 {
                f(&a.moved(&d), b)
            } else {
                f(a, &b.moved(&d))
            };
            d[col % 6] = -h;
            let minus = if col < 6 {
                f(&a.moved(&d), b)
            } else {
                f(a, &b.moved(&d))
            };
            std::array::from_fn(|r| (plus[r] - minus[r]) / (2.0 * h))
        })
        .collect()
}

#[test]
fn the_strains_derivatives_match_differences_even_at_large_turns() {
    for (turn, tilt) in [(0.0, 0.0), (0.05, 0.3), (1.2, -0.7), (2.5, 1.0)] {
        let a = RodNode::along(
            DVec3::new(1.0, -2.0, 0.5),
            DVec3::new(1.0, 0.2, -0.1),
            DVec3::Y,
        );
        let q = DQuat::from_scaled_axis(DVec3::new(tilt, turn, 0.3 * turn)) * a.q;
        let b = RodNode {
            x: a.x + DVec3::new(0.9, 0.3, -0.2),
            q,
        };
        let (_, jac) = strains_and_jacobian(&a, &b, 1.1);
        let fd = differences(&a, &b, |a, b| strains(a, b, 1.1));
        for (col, d) in fd.iter().enumerate() {
            for row in 0..6 {
                assert!(
                    (jac[row][col] - d[row]).abs() < 1e-6,
                    "turn {turn}: d strain {row} / d {col}: {} vs {}",
                    jac[row][col],
                    d[row]
                );
            }
        }
        let holder = Holder::clamp(0, &a);
        let hj = holder.jacobian(&b);
        let fd = differences(&b, &a, |b, _| holder.offsets(b));
        for col in 0..6 {
            for row in 0..6 {
                assert!(
                    (hj[row][col] - fd[col][row]).abs() < 1e-6,
                    "holder {row} {col}"
                );
            }
        }
    }
}

#[test]
fn a_short_span_between_brackets_keeps_its_stiffness() {
    // Two slots clamping a 5 mm span (lower incisors' brackets), one moved 0.1 mm across: the
    // S-bend's force is 12EI·δ/L³ with the shear's share, however few elements span it.
    let span = 5.0;
    let delta = 0.1;
    for elements in [2usize, 3, 5, 10, 40] {
        let mut rod = straight(
            span,
            elements,
            WireSize::Round(0.016),
            WireMaterial::StainlessSteel,
        );
        let left = Holder::clamp(0, &rod.nodes[0].clone());
        let mut right = Holder::clamp(elements, &rod.nodes[elements].clone());
        right.play[0] = f64::INFINITY;
        right.at.y += delta;
        let e = rod.solve(&[left, right], &[], &Settings::default());
        assert!(e.converged, "{e:?}");
        let k = rod.stiffness();
        let theory = delta / (span.powi(3) / (12.0 * k[5]) + span / k[1]);
        let got = rod.reactions(&[left, right])[1].force.y.abs();
        // Without the residual bending flexibility two elements would be a third too stiff.
        assert!(
            (got / theory - 1.0).abs() < 0.005,
            "{elements} elements: {got} N against {theory}"
        );
    }
}
