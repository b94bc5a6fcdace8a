//! The impulse response: momentum exchanged along the contact normal at each tooth's earliest
//! contact, with the coefficient of restitution; the rest of the step travelled at the velocities
//! after impact.

use glam::{Mat3, Quat, Vec3};

use super::{Found, Impact, Simulation};
use crate::{
    collision::Motion,
    geometry::Pose,
    movement::model::{Drive, constrain},
};

impl Simulation {
    /// Mass (kg), world inverse inertia about the centre of mass, velocity and angular velocity of
    /// a tooth over this step's motion.
    fn dynamics(&self, i: usize) -> (f32, Mat3, Vec3, Vec3) {
        let g = &self.teeth[i].shape.geometry;
        let m = self.motions[i];
        let rho = self.settings.density_kg_per_mm3;
        let mass = (g.frame.volume_mm3 as f32) * rho;
        let r = Mat3::from_quat(m.start.rotation);
        let inertia = r * (g.frame.inertia * rho) * r.transpose();
        let dt = self.settings.step_s;
        let com = g.frame.centre_of_mass;
        let v = (m.end.transform_point(com) - m.start.transform_point(com)) / dt;
        let dq = (m.end.rotation * m.start.rotation.inverse()).normalize();
        let w = dq.to_scaled_axis() / dt;
        (mass, inertia.inverse(), v, w)
    }

    /// Exchanges momentum at each tooth's earliest contact; returns which teeth changed motion.
    pub(super) fn impulse(&mut self, found: &[Found]) -> Vec<bool> {
        let n = self.teeth.len();
        let mut events: Vec<(f32, usize)> = found
            .iter()
            .enumerate()
            .filter_map(|(k, f)| self.blocking_time(f).map(|t| (t, k)))
            .collect();
        events.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut hit = vec![false; n];
        for (t, k) in events {
            let f = &found[k];
            let (a, b) = (f.a, f.b);
            if hit[a] || hit[b] {
                continue;
            }
            let normal = f.contact.normal.normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            let point = 0.5 * (f.contact.points[0] + f.contact.points[1]);
            let (ma, ia, va, wa) = self.dynamics(a);
            let (mb, ib, vb, wb) = self.dynamics(b);
            let com = |i: usize| {
                self.motions[i]
                    .at(t)
                    .transform_point(self.teeth[i].shape.geometry.frame.centre_of_mass)
            };
            let (ca, cb) = (com(a), com(b));
            let (ra, rb) = (point - ca, point - cb);
            let rel = (vb + wb.cross(rb)) - (va + wa.cross(ra));
            let vn = rel.dot(normal);
            if vn >= 0.0 {
                continue;
            }
            let k_eff = 1.0 / ma
                + 1.0 / mb
                + normal.dot((ia * ra.cross(normal)).cross(ra))
                + normal.dot((ib * rb.cross(normal)).cross(rb));
            let j = -(1.0 + self.settings.restitution) * vn / k_eff;
            let impulse = normal * j;
            let (va2, wa2) = (va - impulse / ma, wa - ia * ra.cross(impulse));
            let (vb2, wb2) = (vb + impulse / mb, wb + ib * rb.cross(impulse));
            let energy = |v: Vec3, w: Vec3, m: f32, inv: Mat3| -> f64 {
                let i = inv.inverse();
                0.5 * (m * v.length_squared()) as f64 + 0.5 * w.dot(i * w) as f64
            };
            let before = energy(va, wa, ma, ia) + energy(vb, wb, mb, ib);
            let after = energy(va2, wa2, ma, ia) + energy(vb2, wb2, mb, ib);
            self.last.impacts.push(Impact {
                a: self.teeth[a].fdi,
                b: self.teeth[b].fdi,
                time_of_contact: t,
                velocity_before: [va, vb],
                velocity_after: [va2, vb2],
                angular_before: [wa, wb],
                angular_after: [wa2, wb2],
                energy_before_uj: before,
                energy_lost_uj: before - after,
            });
            let dt = self.settings.step_s;
            for (i, v, w, c) in [(a, va2, wa2, ca), (b, vb2, wb2, cb)] {
                let frame = self.arch_frame(i);
                let d = constrain(
                    Drive {
                        velocity: v,
                        angular: w,
                        pivot: Vec3::ZERO,
                    },
                    &self.teeth[i].constraint,
                    &frame,
                    &self.teeth[i].pose,
                    self.teeth[i].fdi,
                );
                let m = self.motions[i];
                let at = m.at(t);
                let h = (1.0 - t) * dt;
                let turn = Quat::from_scaled_axis(d.angular * h);
                let end = Pose::new(
                    (turn * at.rotation).normalize(),
                    c + d.velocity * h + turn * (at.translation - c),
                );
                if end.is_finite() && self.within_limits(i, &end) {
                    self.motions[i] = Motion {
                        start: m.start,
                        end,
                    };
                } else {
                    self.motions[i] = Motion {
                        start: m.start,
                        end: at,
                    };
                }
                hit[i] = true;
            }
        }
        hit
    }
}
