//! The target of a plan: where each tooth should end.
//!
//! **From a file**: each listed tooth moved from where it stands by a case offset (translation
//! along its mesial, buccal and occlusal axes, rotation about them through its crown centre);
//! unlisted teeth stay ([`from_offsets`]).
//!
//! **Automatic** ([`automatic`]), per arch:
//! 1. *Arch form*: the beta arch fitted to the present teeth's cervical centres (the case's
//!    fitted form), the teeth's local origins placed on it as the normal arrangement places
//!    them.
//! 2. *Axes*: each tooth turned to the arrangement's axes at its place on the curve (occlusal
//!    axis vertical, buccal axis along the curve's outward normal, then the arrangement's crown
//!    inclination for its position), which corrects rotations, tips and torques. A tooth within
//!    [`KEEP_DEG`] of those axes keeps its own orientation.
//! 3. *Levelling*: the curve of Spee levelled: each tooth's level (its cervical centre's height
//!    plus its crown length, the arrangement's measure of a tip's height) brought onto the plane
//!    fitted through the arch's levels less each position's step above the premolars and molars
//!    in the normal arrangement (the steps of a levelled arch that occludes), so the arch's mean
//!    height is kept. A tooth within [`KEEP_LEVEL_MM`] of its level keeps its height.
//! 4. *Along the arch*: the two teeth either side of the midline placed symmetrically about the
//!    midline point as it stands (the midline is kept), then each tooth outward in turn with the
//!    exact gap to its mesial neighbour set to `contact_gap_mm` (bisection on its place along the
//!    curve; exact mesh distance), so spaces close and crowding shows as the last teeth going
//!    distally.
//! 5. *Crowding*, when the last tooth of a side would go distally by more than
//!    [`CROWDING_SLACK_MM`], relieved in this order, each within its limit: expansion (the arch
//!    form widened, up to `expansion_mm` at the second molars), proclination (the curve's front
//!    brought forward, up to `proclination_mm`), then IPR (in `ipr_step_mm` steps, shared
//!    round-robin among the contacts from the midline to the canine–premolar contacts, each
//!    within its per-contact limit; a reduced contact's target gap is less by its IPR). What is
//!    left is reported as unresolved, and the last teeth go distally by it.
//!
//! Not done: the opposing arch is not consulted (the sagittal class I of canines and molars is
//! neither sought nor measured), and extraction spaces close by the posterior teeth moving
//! mesially.

use std::collections::BTreeMap;

use glam::{Mat3, Quat, Vec2, Vec3};
use serde::Serialize;

use super::limits::PlanLimits;
use crate::geometry::{Pose, mesh_separation};
use crate::teeth::{
    Arch, Dentition, Fdi, PlacedTooth, ShapeSet,
    arch::{ArchCurve, ArchLayout, Arrangement, BetaArch, Spaces},
    case::{CaseOffset, ToothMap},
};

/// Orientations within this of the arrangement's axes (degrees) are kept.
pub const KEEP_DEG: f32 = 1.0;
/// Heights within this of the levelled plane (mm) are kept.
pub const KEEP_LEVEL_MM: f32 = 0.2;
/// Distal movement of the last tooth of a side (mm) left without relief.
pub const CROWDING_SLACK_MM: f32 = 0.1;
/// Gap accuracy of the placement along the arch (mm).
const GAP_ACCURACY_MM: f32 = 0.002;

/// IPR a target needs at one contact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TargetIpr {
    /// Mesial-side tooth of the contact (nearer the patient's right).
    pub a: Fdi,
    /// The other tooth.
    pub b: Fdi,
    /// Enamel removed (mm, both teeth together).
    pub mm: f32,
}

/// How the automatic target set up one arch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArchSetup {
    /// `upper` or `lower`.
    pub arch: &'static str,
    /// How far the last teeth would go distally with no relief (mm; patient's right, left;
    /// negative: spaces to close).
    pub crowding_mm: [f32; 2],
    /// Expansion used (mm at the second molars).
    pub expansion_mm: f32,
    /// Proclination used (mm).
    pub proclination_mm: f32,
    /// IPR used (mm, sum over the arch's contacts).
    pub ipr_mm: f32,
    /// Crowding left (mm; right, left): the last teeth go distally by this.
    pub unresolved_mm: [f32; 2],
}

impl ArchSetup {
    /// One line: the crowding, the means used and what is left.
    pub fn summary(&self) -> String {
        format!(
            "{} arch: crowding {:.2} / {:.2} mm (right / left); expansion {:.2} mm, proclination {:.2} mm, IPR {:.2} mm; unresolved {:.2} / {:.2} mm",
            self.arch,
            self.crowding_mm[0],
            self.crowding_mm[1],
            self.expansion_mm,
            self.proclination_mm,
            self.ipr_mm,
            self.unresolved_mm[0],
            self.unresolved_mm[1]
        )
    }
}

/// Where each tooth should end.
#[derive(Clone, Debug)]
pub struct Target {
    /// Target pose of every present tooth (extracted teeth stay where they are).
    pub poses: BTreeMap<Fdi, Pose>,
    /// IPR the target needs.
    pub ipr: Vec<TargetIpr>,
    /// `automatic` or `file`.
    pub source: &'static str,
    /// The automatic set-up per arch (empty for a target from a file).
    pub arches: Vec<ArchSetup>,
}

/// A target from per-tooth movements (see the module doc).
pub fn from_offsets(d: &Dentition, offsets: &ToothMap<CaseOffset>) -> Target {
    let poses = d
        .teeth
        .iter()
        .map(|t| {
            let pose = match offsets.0.get(&t.fdi) {
                Some(o) if !t.extracted => t.offset_pose(o),
                _ => t.pose,
            };
            (t.fdi, pose)
        })
        .collect();
    Target {
        poses,
        ipr: Vec::new(),
        source: "file",
        arches: Vec::new(),
    }
}

/// The automatic target (see the module doc).
pub fn automatic(d: &Dentition, limits: &PlanLimits) -> Target {
    let mut poses: BTreeMap<Fdi, Pose> = d.teeth.iter().map(|t| (t.fdi, t.pose)).collect();
    let mut ipr = Vec::new();
    let mut arches = Vec::new();
    for arch in [Arch::Upper, Arch::Lower] {
        let mut row: Vec<&PlacedTooth> = d.visible().filter(|t| t.fdi.arch() == arch).collect();
        row.sort_by_key(|t| t.fdi.arch_index());
        if row.len() < 2 {
            continue;
        }
        let form = d.arch_forms[if arch == Arch::Upper { 0 } else { 1 }];
        let setter = ArchSetter::new(arch, &row, form, limits, arrangement_steps(d, arch));
        let (placed, setup, cuts) = setter.solve();
        for (t, p) in row.iter().zip(placed) {
            poses.insert(t.fdi, p);
        }
        ipr.extend(cuts);
        arches.push(setup);
    }
    Target {
        poses,
        ipr,
        source: "automatic",
        arches,
    }
}

/// One arch being set up.
struct ArchSetter<'a> {
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
    fn new(
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
        Pose::new(rotation, Vec3::new(p.x, y, p.y))
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

    /// Sets the arch up (see the module doc): poses, the report, and the IPR it needs.
    fn solve(&self) -> (Vec<Pose>, ArchSetup, Vec<TargetIpr>) {
        let n = self.teeth.len();
        let mut cuts = vec![0.0f32; n.saturating_sub(1)];
        let worst = |d: [f32; 2]| d[0].max(d[1]);
        let attempt = |e: f32, p: f32, cuts: &[f32]| {
            let curve = ArchCurve::new(&self.form_with(e, p));
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
        let unresolved = left.map(|d| if d > slack { d } else { 0.0 });
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
            crowding_mm: crowding,
            expansion_mm: expansion,
            proclination_mm: proclination,
            ipr_mm: cuts.iter().sum(),
            unresolved_mm: unresolved,
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
fn arrangement_steps(d: &Dentition, arch: Arch) -> [f32; 8] {
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

/// Reads a target file: a map from tooth to its movement, as a case's `target`
/// (`{11: (translation: (0.5, 0.0, 0.0), rotation_deg: (0.0, 0.0, 10.0))}`), checked against the
/// teeth present in `d`.
///
/// # Errors
/// [`super::PlanError::Invalid`] naming the file, line and column of the first problem.
pub fn read_target(
    path: &std::path::Path,
    d: &Dentition,
) -> Result<ToothMap<CaseOffset>, super::PlanError> {
    let origin = path.display().to_string();
    let err = |line: usize, column: usize, message: String| super::PlanError::Invalid {
        path: origin.clone(),
        line,
        column,
        message,
    };
    let source =
        std::fs::read_to_string(path).map_err(|e| err(1, 1, format!("cannot read: {e}")))?;
    let map: ToothMap<CaseOffset> = ron::from_str(&source)
        .map_err(|e| err(e.span.start.line, e.span.start.col, e.code.to_string()))?;
    for (f, o) in &map.0 {
        let (line, column) = source
            .lines()
            .enumerate()
            .find_map(|(i, l)| l.find(&format!("{f}:")).map(|c| (i + 1, c + 1)))
            .unwrap_or((1, 1));
        match d.tooth(*f) {
            None => return Err(err(line, column, format!("tooth {f} is not in the case"))),
            Some(t) if t.extracted => {
                return Err(err(line, column, format!("tooth {f} is extracted")));
            }
            _ => {}
        }
        let (t, r) = (o.translation, o.rotation_deg);
        let (mm, deg) = (
            crate::teeth::case::MAX_OFFSET_MM,
            crate::teeth::case::MAX_OFFSET_DEG,
        );
        if [t.0, t.1, t.2].iter().any(|c| c.0.abs() > mm)
            || [r.0, r.1, r.2].iter().any(|c| c.0.abs() > deg)
        {
            let m = format!("movement of tooth {f} is beyond {mm} mm or {deg}° per axis");
            return Err(err(line, column, m));
        }
    }
    Ok(map)
}
