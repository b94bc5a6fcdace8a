//! The automatic set-up of one arch (see [`super::target`]'s module doc for the steps): the
//! teeth placed on the fitted arch form with exact contacts, crowding relieved by expansion,
//! proclination and IPR, and spaces closed as the anchorage says (anterior retraction against
//! posterior protraction).

use glam::{Mat3, Quat, Vec2, Vec3};

use super::limits::PlanLimits;
use super::target::{ArchSetup, TargetIpr};
use crate::appliance::archwire::ArchSize;
use crate::geometry::{Pose, mesh_separation};
use crate::teeth::{
    Arch, Dentition, Fdi, PlacedTooth, ShapeSet,
    arch::{ArchCurve, ArchLayout, Arrangement, BetaArch, Spaces},
};

/// Orientations within this of the arrangement's axes (degrees) are kept.
pub const KEEP_DEG: f32 = 1.0;
/// Heights within this of the levelled plane (mm) are kept.
pub const KEEP_LEVEL_MM: f32 = 0.2;
/// Distal movement of the last tooth of a side (mm) left without relief.
pub const CROWDING_SLACK_MM: f32 = 0.1;
/// Gap accuracy of the placement along the arch (mm).
const GAP_ACCURACY_MM: f32 = 0.002;

/// An arch with its crowding relieved, before its spaces are closed.
pub(super) struct Relieved {
    poses: Vec<Pose>,
    crowding: [f32; 2],
    left: [f32; 2],
    expansion: f32,
    proclination: f32,
    cuts: Vec<f32>,
}

impl Relieved {
    /// True when the arch has spaces the anchorage decides how to close (the last teeth go
    /// mesially by more than the slack on average).
    pub(super) fn has_spaces(&self) -> bool {
        0.5 * (self.left[0] + self.left[1]) < -CROWDING_SLACK_MM
    }
}

/// One arch being set up.
pub(super) struct ArchSetter<'a> {
    arch: Arch,
    teeth: &'a [&'a PlacedTooth],
    form: BetaArch,
    limits: &'a PlanLimits,
    layout: ArchLayout,
    /// The levelled plane: level = a + b·x + c·z.
    plane: [f32; 3],
    /// The midline point's arc length on the starting form.
    midline: Vec2,
    /// Index of the first tooth on the patient's left (the midline contact is before it).
    left: usize,
    /// Each position's level above the posterior plane (mm, towards occlusal), as the normal
    /// arrangement stands.
    steps: [f32; 8],
    /// Each tooth's extent along its local x (mm, at least 1): the first guess of its width
    /// along the arch.
    widths: Vec<f32>,
}

impl<'a> ArchSetter<'a> {
    pub(super) fn new(
        arch: Arch,
        teeth: &'a [&'a PlacedTooth],
        form: BetaArch,
        limits: &'a PlanLimits,
        steps: [f32; 8],
    ) -> Self {
        let layout = ArchLayout::default();
        let left = teeth
            .iter()
            .position(|t| t.fdi.arch_index() > 0)
            .unwrap_or(teeth.len());
        let xz = |t: &PlacedTooth| Vec2::new(t.pose.translation.x, t.pose.translation.z);
        let midline = if left > 0 && left < teeth.len() {
            (xz(teeth[left - 1]) + xz(teeth[left])) * 0.5
        } else {
            Vec2::new(0.0, form.front_z)
        };
        let mut s = Self {
            arch,
            teeth,
            form,
            limits,
            layout,
            plane: [0.0; 3],
            midline,
            left,
            steps,
            widths: teeth
                .iter()
                .map(|t| {
                    let x = t.geometry.mesh.aabb();
                    (x.max.x - x.min.x).max(1.0)
                })
                .collect(),
        };
        s.plane = s.fit_plane();
        s
    }

    /// +1 for the lower arch (occlusal is up), −1 for the upper.
    fn sign(&self) -> f32 {
        if self.arch == Arch::Lower { 1.0 } else { -1.0 }
    }

    fn row(&self) -> usize {
        if self.arch == Arch::Upper { 0 } else { 1 }
    }

    /// A tooth's step above the posterior plane (mm) and its inclination (degrees).
    fn anatomy(&self, f: Fdi) -> (f32, f32) {
        let k = f.position() as usize - 1;
        (self.steps[k], self.layout.inclination_deg[self.row()][k])
    }

    /// A tooth's level: its origin's height plus its crown length towards occlusal.
    fn level(&self, t: &PlacedTooth, pose: &Pose) -> f32 {
        pose.translation.y + self.sign() * t.geometry.frame.crown_length
    }

    /// Least-squares plane through the teeth's levels less their anterior steps.
    fn fit_plane(&self) -> [f32; 3] {
        let pts: Vec<Vec3> = self
            .teeth
            .iter()
            .map(|t| {
                let v = self.level(t, &t.pose) - self.sign() * self.anatomy(t.fdi).0;
                Vec3::new(t.pose.translation.x, t.pose.translation.z, v)
            })
            .collect();
        fit_plane(&pts)
    }

    /// The pose of tooth `i` at arc length `s` of `curve`.
    fn pose_at(&self, curve: &ArchCurve, i: usize, s: f32) -> Pose {
        let t = self.teeth[i];
        let (p, tangent) = curve.at(s);
        let out = Vec3::new(-tangent.y, 0.0, tangent.x);
        let up = Vec3::Y * self.sign();
        let x = up.cross(out);
        let (step, incline) = self.anatomy(t.fdi);
        let base = Quat::from_mat3(&Mat3::from_cols(x, up, out));
        let ideal = (Quat::from_axis_angle(x, incline.to_radians()) * base).normalize();
        // The crown's anatomical axes go to the ideal ones (a scanned crown's local frame is
        // not anatomical: see `ToothGeometry::axes`).
        let axes = t.geometry.axes;
        let now = (t.pose.rotation * axes).normalize();
        let rotation = if ideal.angle_between(now).to_degrees() <= KEEP_DEG {
            t.pose.rotation
        } else {
            (ideal * axes.inverse()).normalize()
        };
        let [a, b, c] = self.plane;
        let level = a + b * p.x + c * p.y + self.sign() * step;
        let mut y = level - self.sign() * t.geometry.frame.crown_length;
        if (y - t.pose.translation.y).abs() <= KEEP_LEVEL_MM {
            y = t.pose.translation.y;
        }
        let prominence = self.layout.buccal_offset[self.row()][t.fdi.position() as usize - 1];
        Pose::new(rotation, Vec3::new(p.x, y, p.y) + out * prominence)
    }

    /// Signed gap between teeth `i` and `j` at the given poses.
    fn gap(&self, i: usize, pi: &Pose, j: usize, pj: &Pose) -> f32 {
        let (a, b) = (&self.teeth[i].geometry, &self.teeth[j].geometry);
        super::clearance::signed_gap(&mesh_separation(a.mesh_ref(), pi, b.mesh_ref(), pj))
    }

    /// Places every tooth along `curve` (see the module doc): the poses, and how far the last
    /// tooth of each side goes distally of where it stands (mm; right, left).
    fn place(&self, curve: &ArchCurve, cuts: &[f32]) -> (Vec<Pose>, [f32; 2]) {
        let n = self.teeth.len();
        let gap_at = |k: usize| self.limits.contact_gap_mm.0 - cuts[k];
        let mut s = vec![0.0f32; n];
        let mut poses = vec![Pose::IDENTITY; n];
        let s_mid = curve.project(self.midline);
        let width = |i: usize| self.widths[i];
        if self.left > 0 && self.left < n {
            // The two teeth either side of the midline, symmetric about it.
            let (r, l) = (self.left - 1, self.left);
            let guess = 0.5 * (width(r) + width(l)) * 0.5;
            let u = solve(
                |u| {
                    let (pr, pl) = (
                        self.pose_at(curve, r, s_mid - u),
                        self.pose_at(curve, l, s_mid + u),
                    );
                    self.gap(r, &pr, l, &pl)
                },
                guess,
                gap_at(r),
            );
            s[r] = s_mid - u;
            s[l] = s_mid + u;
        } else if self.left == 0 {
            s[0] = curve.project(xz(&self.teeth[0].pose));
        } else {
            s[n - 1] = curve.project(xz(&self.teeth[n - 1].pose));
        }
        let first_left = if self.left < n { self.left } else { n - 1 };
        let first_right = if self.left > 0 { self.left - 1 } else { 0 };
        poses[first_left] = self.pose_at(curve, first_left, s[first_left]);
        poses[first_right] = self.pose_at(curve, first_right, s[first_right]);
        // Outwards on the left (increasing s), then on the right (decreasing s).
        for i in first_left + 1..n {
            let prev = poses[i - 1];
            let guess = 0.5 * (width(i - 1) + width(i));
            let u = solve(
                |u| self.gap(i - 1, &prev, i, &self.pose_at(curve, i, s[i - 1] + u)),
                guess,
                gap_at(i - 1),
            );
            s[i] = s[i - 1] + u;
            poses[i] = self.pose_at(curve, i, s[i]);
        }
        for i in (0..first_right).rev() {
            let next = poses[i + 1];
            let guess = 0.5 * (width(i) + width(i + 1));
            let u = solve(
                |u| self.gap(i, &self.pose_at(curve, i, s[i + 1] - u), i + 1, &next),
                guess,
                gap_at(i),
            );
            s[i] = s[i + 1] - u;
            poses[i] = self.pose_at(curve, i, s[i]);
        }
        let distal = |i: usize| s[i].abs() - curve.project(xz(&self.teeth[i].pose)).abs();
        let right = if self.left > 0 { distal(0) } else { 0.0 };
        let left = if self.left < n { distal(n - 1) } else { 0.0 };
        (poses, [right, left])
    }

    /// The arch form with `expansion` mm more width and `proclination` mm more depth at the front.
    fn form_with(&self, expansion: f32, proclination: f32) -> BetaArch {
        BetaArch {
            width: self.form.width + expansion,
            depth: self.form.depth + proclination,
            front_z: self.form.front_z + proclination,
        }
    }

    /// The curve the teeth are placed along: the arch form of [`Self::form_with`], or the
    /// chosen preformed form sized to its width and depth.
    fn curve(&self, expansion: f32, proclination: f32) -> ArchCurve {
        let f = self.form_with(expansion, proclination);
        match self.limits.arch_form.preformed() {
            None => ArchCurve::new(&f),
            Some(form) => {
                let size = ArchSize {
                    molar_width_mm: f64::from(f.width),
                    depth_mm: f64::from(f.depth),
                };
                let back = f.front_z - f.depth;
                ArchCurve::tabulate(f.width, |x| {
                    let p = form.point(&size, f64::from(x));
                    Vec2::new(x, back + p.z as f32)
                })
            }
        }
    }

    /// The arch placed with its crowding relieved (see the module doc).
    pub(super) fn relieve(&self) -> Relieved {
        let n = self.teeth.len();
        let mut cuts = vec![0.0f32; n.saturating_sub(1)];
        let worst = |d: [f32; 2]| d[0].max(d[1]);
        let attempt = |e: f32, p: f32, cuts: &[f32]| {
            let curve = self.curve(e, p);
            self.place(&curve, cuts)
        };
        let (mut poses, crowding) = attempt(0.0, 0.0, &cuts);
        let mut left = crowding;
        let (mut expansion, mut proclination) = (0.0f32, 0.0f32);
        let slack = CROWDING_SLACK_MM;
        // Expansion, then proclination: about the least that relieves the crowding.
        for means in 0..2 {
            if worst(left) <= slack {
                break;
            }
            let limit = if means == 0 {
                self.limits.expansion_mm.0
            } else {
                self.limits.proclination_mm.0
            };
            if limit <= 0.0 {
                continue;
            }
            let with = |v: f32| {
                if means == 0 {
                    attempt(v, 0.0, &cuts)
                } else {
                    attempt(expansion, v, &cuts)
                }
            };
            // The crowding falls nearly linearly with either means: secant steps from none and
            // the limit, each kept only when it relieves the crowding.
            let full = with(limit);
            let (mut lo, mut f_lo) = (0.0f32, worst(left));
            let (mut hi, mut best) = (limit, full);
            if worst(best.1) <= slack {
                for _ in 0..3 {
                    let f_hi = worst(best.1);
                    if f_lo - f_hi <= 1e-6 {
                        break;
                    }
                    // Aim a little inside the slack so the step usually lands within it.
                    let aim = 0.5 * slack;
                    let v = (lo + (hi - lo) * (f_lo - aim) / (f_lo - f_hi)).clamp(lo, hi);
                    if hi - v < 0.02 {
                        break;
                    }
                    let r = with(v);
                    if worst(r.1) <= slack {
                        hi = v;
                        best = r;
                    } else {
                        (lo, f_lo) = (v, worst(r.1));
                    }
                }
            }
            if means == 0 {
                expansion = hi;
            } else {
                proclination = hi;
            }
            (poses, left) = best;
        }
        // IPR: round-robin over each crowded side's anterior contacts.
        if worst(left) > slack && self.limits.ipr_step_mm.0 > 0.0 {
            let step = self.limits.ipr_step_mm.0;
            let anterior = |k: usize| {
                let (a, b) = (self.teeth[k].fdi, self.teeth[k + 1].fdi);
                a.position() <= 3 || b.position() <= 3
            };
            for (side, need) in left.iter().enumerate() {
                if *need <= slack {
                    continue;
                }
                // The side's contacts, from the midline outwards (the midline contact counts
                // half for each side).
                let contacts: Vec<usize> = (0..cuts.len())
                    .filter(|&k| anterior(k))
                    .filter(|&k| {
                        if side == 0 {
                            k < self.left
                        } else {
                            k + 1 >= self.left
                        }
                    })
                    .collect();
                let mut gained = 0.0f32;
                let mut progress = true;
                while gained < *need && progress {
                    progress = false;
                    for &k in &contacts {
                        if gained >= *need {
                            break;
                        }
                        let limit = self
                            .limits
                            .ipr
                            .between(self.teeth[k].fdi, self.teeth[k + 1].fdi);
                        if cuts[k] + step <= limit + 1e-4 {
                            cuts[k] += step;
                            gained += if k + 1 == self.left { 0.5 * step } else { step };
                            progress = true;
                        }
                    }
                }
            }
            (poses, left) = attempt(expansion, proclination, &cuts);
        }
        Relieved {
            poses,
            crowding,
            left,
            expansion,
            proclination,
            cuts,
        }
    }

    /// Closes the arch's spaces with `share` of them (0–1) closed by retracting the anterior
    /// teeth (the front of the arch form brought back, within `retraction_mm`; the molars' end
    /// of the form stays) and the rest by the posterior teeth coming forward: the poses, the
    /// report, and the IPR the arch needs. `anchorage` names the choice in the report.
    pub(super) fn close(
        &self,
        r: &Relieved,
        share: f32,
        anchorage: &'static str,
    ) -> (Vec<Pose>, ArchSetup, Vec<TargetIpr>) {
        let mean = |d: [f32; 2]| 0.5 * (d[0] + d[1]);
        let (mut poses, mut left, mut retraction) = (r.poses.clone(), r.left, 0.0f32);
        let limit = self.limits.retraction_mm.0;
        if r.has_spaces() && share > 0.0 && limit > 0.0 {
            let goal = (1.0 - share.min(1.0)) * mean(r.left);
            let with = |v: f32| {
                let curve = self.curve(r.expansion, r.proclination - v);
                self.place(&curve, &r.cuts)
            };
            // The last teeth's movement rises nearly linearly with the retraction: secant steps
            // from none, within the limit.
            let (mut lo, mut m_lo) = (0.0f32, mean(r.left));
            let mut v = (share * -mean(r.left)).min(limit);
            for _ in 0..5 {
                let (p, l) = with(v);
                (poses, left, retraction) = (p, l, v);
                let m = mean(l);
                if (m - goal).abs() <= 0.05 || (v >= limit && m < goal) || (m - m_lo).abs() < 1e-6 {
                    break;
                }
                let next = (lo + (v - lo) * (goal - m_lo) / (m - m_lo)).clamp(0.0, limit);
                (lo, m_lo) = (v, m);
                v = next;
            }
        }
        let share = if r.has_spaces() {
            ((mean(left) - mean(r.left)) / -mean(r.left)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let unresolved = left.map(|d| if d > CROWDING_SLACK_MM { d } else { 0.0 });
        let cuts = &r.cuts;
        let ipr = cuts
            .iter()
            .enumerate()
            .filter(|(_, c)| **c > 0.0)
            .map(|(k, c)| TargetIpr {
                a: self.teeth[k].fdi,
                b: self.teeth[k + 1].fdi,
                mm: *c,
            })
            .collect();
        let setup = ArchSetup {
            arch: if self.arch == Arch::Upper {
                "upper"
            } else {
                "lower"
            },
            crowding_mm: r.crowding,
            expansion_mm: r.expansion,
            proclination_mm: r.proclination,
            ipr_mm: cuts.iter().sum(),
            unresolved_mm: unresolved,
            anchorage,
            retraction_mm: retraction,
            retraction_share: share,
        };
        (poses, setup, ipr)
    }
}

/// The least-squares plane v = a + b·x + c·z through points (x, z, v), as [a, b, c] (level when
/// the points cannot tilt it).
fn fit_plane(pts: &[Vec3]) -> [f32; 3] {
    if pts.is_empty() {
        return [0.0; 3];
    }
    let mean = pts.iter().fold(Vec3::ZERO, |a, p| a + *p) / pts.len() as f32;
    let (mut sxx, mut sxz, mut szz, mut sxv, mut szv) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let (x, z, v) = (p.x - mean.x, p.y - mean.y, p.z - mean.z);
        sxx += x * x;
        sxz += x * z;
        szz += z * z;
        sxv += x * v;
        szv += z * v;
    }
    let det = sxx * szz - sxz * sxz;
    if pts.len() < 3 || det.abs() < 1e-6 * (sxx * szz).max(1e-12) {
        return [mean.z, 0.0, 0.0];
    }
    let b = (sxv * szz - szv * sxz) / det;
    let c = (szv * sxx - sxv * sxz) / det;
    [mean.z - b * mean.x - c * mean.y, b, c]
}

/// Each position's level above the plane of the premolars and molars (mm, towards occlusal) in
/// the normal arrangement of the case's tooth resolution, both sides averaged: the steps of a
/// levelled arch that occludes.
pub(super) fn arrangement_steps(d: &Dentition, arch: Arch) -> [f32; 8] {
    let shapes = ShapeSet::shared(d.case.case.tooth_resolution());
    let arrangement = Arrangement::shared(&shapes, &Spaces::new());
    let sign = if arch == Arch::Lower { 1.0 } else { -1.0 };
    let levels: Vec<(Fdi, Vec3)> = arrangement
        .poses
        .iter()
        .filter(|(f, _)| f.arch() == arch)
        .map(|(f, p)| {
            let crown = shapes.get(arch, f.kind()).frame.crown_length;
            let level = p.translation.y + sign * crown;
            (*f, Vec3::new(p.translation.x, p.translation.z, level))
        })
        .collect();
    let posterior: Vec<Vec3> = levels
        .iter()
        .filter(|(f, _)| f.position() >= 4)
        .map(|(_, v)| *v)
        .collect();
    let [a, b, c] = fit_plane(&posterior);
    let mut steps = [0.0f32; 8];
    let mut counts = [0u32; 8];
    for (f, v) in &levels {
        let k = f.position() as usize - 1;
        steps[k] += sign * (v.z - (a + b * v.x + c * v.y));
        counts[k] += 1;
    }
    for (s, n) in steps.iter_mut().zip(counts) {
        *s /= n.max(1) as f32;
    }
    steps
}

fn xz(p: &Pose) -> Vec2 {
    Vec2::new(p.translation.x, p.translation.z)
}

/// The u ≥ 0 at which the increasing `gap(u)` reaches `target`, from a first guess: bracketed
/// by steps of 1 mm, then regula falsi with bisection (to [`GAP_ACCURACY_MM`]).
fn solve(gap: impl Fn(f32) -> f32, guess: f32, target: f32) -> f32 {
    let f = |u: f32| gap(u) - target;
    let (mut lo, mut hi) = (guess - 1.0, guess + 1.0);
    let (mut flo, mut fhi) = (f(lo), f(hi));
    let mut tries = 0;
    while flo > 0.0 && tries < 20 {
        hi = lo;
        fhi = flo;
        lo -= 1.0;
        flo = f(lo);
        tries += 1;
    }
    while fhi < 0.0 && tries < 40 {
        lo = hi;
        flo = fhi;
        hi += 1.0;
        fhi = f(hi);
        tries += 1;
    }
    if flo > 0.0 || fhi < 0.0 {
        return if flo > 0.0 { lo } else { hi };
    }
    for i in 0..40 {
        // Regula falsi, every third step a bisection (so a flat side cannot stall it).
        let mid = if i % 3 == 2 || (fhi - flo).abs() < 1e-9 {
            0.5 * (lo + hi)
        } else {
            (lo - flo * (hi - lo) / (fhi - flo)).clamp(lo, hi)
        };
        let fm = f(mid);
        if fm.abs() <= GAP_ACCURACY_MM {
            return mid;
        }
        if fm < 0.0 {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
            fhi = fm;
        }
    }
    hi
}
