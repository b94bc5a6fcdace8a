//! Arch forms and the normal arrangement of both arches: teeth along a beta-function curve with
//! adjacent crowns in contact, the upper arch over the lower in class I occlusion.
//!
//! Arch form: the beta function of Braun et al. (1998, *Angle Orthodontist* 68:29–36),
//! `z(x) = 3.0314 · D · (1/2 + x/W)^0.8 · (1/2 − x/W)^0.8`, where `W` is the arch width at the
//! distal of the second molars and `D` the arch depth from there to the incisors (3.0314 = 2^1.6
//! makes the curve's apex exactly `D`). The curve runs through the teeth's cervical centres; past its
//! ends it continues straight backwards. The world frame is the paper's: +x to the patient's left,
//! +y up, +z anterior, origin in the middle of the arch on the occlusal plane.
//!
//! Arrangement (all numbers are parameters in [`ArchLayout`]):
//! 1. Each arch: the central incisors are placed symmetrically about the midline, then every tooth
//!    distally slides along the curve until the exact triangle-level gap to its mesial neighbour is
//!    `contact_gap` (bisection on the arc position; the gap grows monotonically with it).
//! 2. The upper curve's width and depth are solved (Newton, on nominal tooth widths) so that the
//!    upper first molars stand `buccal_overlap` buccal to the lower ones and their mesiobuccal cusps
//!    sit over the lower first molars' buccal grooves (Angle class I); its front lies `overjet_offset`
//!    ahead of the lower front.
//! 3. The upper arch is lowered onto the lower until the least exact gap between the arches is
//!    `occlusal_gap` (bisection on its height).

use std::{collections::BTreeMap, sync::Arc};

use glam::{Mat3, Quat, Vec2, Vec3};
use serde::Serialize;

use super::{
    fdi::{Arch, Fdi, Side, ToothKind},
    memo::Memo,
    tooth_shape::{ShapeSet, ToothGeometry},
};
use crate::geometry::{Aabb, Pose, mesh_separation};

/// The beta-function arch form.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BetaArch {
    /// Width `W` at the distal of the second molars (mm).
    pub width: f32,
    /// Depth `D` from the second molars' line to the front (mm).
    pub depth: f32,
    /// World z of the curve's front point.
    pub front_z: f32,
}

impl BetaArch {
    /// The point of the curve at lateral position `x` (|x| ≤ W/2), as (x, z).
    pub fn point(&self, x: f32) -> Vec2 {
        let u = (x / self.width).clamp(-0.5, 0.5);
        let z = 2f32.powf(1.6) * self.depth * ((0.5 + u) * (0.5 - u)).max(0.0).powf(0.8);
        Vec2::new(x, self.front_z - self.depth + z)
    }
}

/// An arch curve tabulated by arc length from the midline, for placing teeth.
#[derive(Clone, Debug)]
pub struct ArchCurve {
    /// (arc length, point) along the left half, from the midline.
    table: Vec<(f32, Vec2)>,
}

impl ArchCurve {
    /// Tabulates a beta arch (x = W/2 · sin θ, dense where the curve turns backwards).
    pub fn new(form: &BetaArch) -> Self {
        const N: usize = 1500;
        let mut table = Vec::with_capacity(N + 1);
        let mut s = 0.0;
        let mut prev = form.point(0.0);
        for i in 0..=N {
            let theta = std::f32::consts::FRAC_PI_2 * i as f32 / N as f32;
            let p = form.point(0.5 * form.width * theta.sin());
            s += p.distance(prev);
            prev = p;
            table.push((s, p));
        }
        Self { table }
    }

    /// Point and unit tangent (direction of increasing arc length: from the patient's right to
    /// left) at signed arc length `s` (negative on the patient's right).
    pub fn at(&self, s: f32) -> (Vec2, Vec2) {
        let u = s.abs();
        let (end_s, end_p) = *self.table.last().expect("tabulated curve");
        let (p, dir) = if u >= end_s {
            (end_p + Vec2::new(0.0, -(u - end_s)), Vec2::new(0.0, -1.0))
        } else {
            let i = self
                .table
                .partition_point(|e| e.0 < u)
                .clamp(1, self.table.len() - 1);
            let (s0, p0) = self.table[i - 1];
            let (s1, p1) = self.table[i];
            let f = if s1 > s0 { (u - s0) / (s1 - s0) } else { 0.0 };
            (p0.lerp(p1, f), (p1 - p0).normalize_or(Vec2::X))
        };
        if s >= 0.0 {
            (p, dir)
        } else {
            (Vec2::new(-p.x, p.y), Vec2::new(dir.x, -dir.y))
        }
    }
}

/// Parameters of the normal arrangement.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArchLayout {
    /// Lower arch form.
    pub lower: BetaArch,
    /// Exact gap between adjacent crowns (mm).
    pub contact_gap: f32,
    /// Least exact gap between the arches (mm).
    pub occlusal_gap: f32,
    /// How far the upper curve's front lies ahead of the lower's at the cervical level (mm); the
    /// incisors' labial inclination adds the rest of the overjet at the incisal edges.
    pub overjet_offset: f32,
    /// How far buccal the upper first molars stand of the lower ones (mm).
    pub buccal_overlap: f32,
    /// Crown inclination (degrees, positive = crown buccal/labial), upper then lower, by position.
    pub inclination_deg: [[f32; 8]; 2],
    /// Height of each tooth's occlusal tip above (lower) or below (upper) the occlusal plane (mm),
    /// upper then lower, by position; sets the overbite of the anterior teeth.
    pub tip_level: [[f32; 8]; 2],
}

impl Default for ArchLayout {
    fn default() -> Self {
        Self {
            lower: BetaArch {
                width: 50.0,
                depth: 36.0,
                front_z: 18.0,
            },
            contact_gap: 0.05,
            occlusal_gap: 0.02,
            overjet_offset: 0.0,
            buccal_overlap: 2.2,
            inclination_deg: [
                [22.0, 18.0, 8.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                [6.0, 6.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ],
            tip_level: [
                [1.2, 1.0, 0.6, 0.0, 0.0, 0.0, 0.0, 0.0],
                [1.2, 1.0, 0.6, 0.0, 0.0, 0.0, 0.0, 0.0],
            ],
        }
    }
}

/// Occlusion measures of an arrangement (mm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OcclusionMeasures {
    /// Horizontal distance from the lower central incisors' labial surface to the upper incisal
    /// edges (mean of both sides).
    pub overjet_mm: f32,
    /// Vertical overlap of the upper incisal edges over the lower incisal edges (mean).
    pub overbite_mm: f32,
    /// Sagittal distance from the upper first molars' mesiobuccal cusp tips to the lower first
    /// molars' buccal grooves (mean; 0 is class I, positive is mesial of the groove).
    pub molar_relation_mm: f32,
}

/// Poses of all 32 teeth in normal occlusion.
#[derive(Clone, Debug)]
pub struct Arrangement {
    /// Residuals of the upper arch form's solve: buccal overlap error and class I error (mm).
    pub upper_residual: Vec2,
    /// Pose of each tooth's local frame, in FDI order (11..18, 21..28, 31..38, 41..48).
    pub poses: Vec<(Fdi, Pose)>,
    /// The upper arch form that was solved.
    pub upper: BetaArch,
    /// Occlusion measures of the result.
    pub measures: OcclusionMeasures,
}

impl Arrangement {
    /// The default-layout arrangement for a resolution and spaces, computed once per process.
    pub fn shared(shapes: &ShapeSet, spaces: &Spaces) -> Arc<Arrangement> {
        static CACHE: Memo<(u32, Vec<(Fdi, u32)>), Arrangement> = Memo::new();
        let key = (
            shapes.resolution.vertices,
            spaces.iter().map(|(f, s)| (*f, s.to_bits())).collect(),
        );
        CACHE.get_or_build(key, || arrange(shapes, &ArchLayout::default(), spaces))
    }

    /// The pose of a tooth.
    pub fn pose(&self, fdi: Fdi) -> Pose {
        self.poses
            .iter()
            .find(|(f, _)| *f == fdi)
            .map_or(Pose::IDENTITY, |(_, p)| *p)
    }
}

fn arch_row(arch: Arch) -> usize {
    match arch {
        Arch::Upper => 0,
        Arch::Lower => 1,
    }
}

/// Pose of a tooth whose cervical centre is at arc length `s` of `curve`.
fn pose_on_curve(
    curve: &ArchCurve,
    s: f32,
    fdi: Fdi,
    shape: &ToothGeometry,
    layout: &ArchLayout,
    lift: f32,
) -> Pose {
    let (p, t) = curve.at(s);
    let out = Vec3::new(-t.y, 0.0, t.x);
    let row = arch_row(fdi.arch());
    let k = fdi.position() as usize - 1;
    let tip = shape.frame.crown_length;
    let level = layout.tip_level[row][k];
    let (up, y) = match fdi.arch() {
        Arch::Lower => (Vec3::Y, level - tip),
        Arch::Upper => (-Vec3::Y, -level + tip + lift),
    };
    let x = up.cross(out);
    let base = Quat::from_mat3(&Mat3::from_cols(x, up, out));
    let incline = Quat::from_axis_angle(x, layout.inclination_deg[row][k].to_radians());
    Pose::new((incline * base).normalize(), Vec3::new(p.x, y, p.y))
}

/// Signed gap between two posed shapes (negative when they overlap).
fn gap(a: &ToothGeometry, pa: &Pose, b: &ToothGeometry, pb: &Pose) -> f32 {
    mesh_separation(a.mesh_ref(), pa, b.mesh_ref(), pb).signed_gap()
}

/// Bisection for an increasing f bracketed by f(lo) < target <= f(hi): returns a point within
/// 1e-5 of the crossing on the `hi` side, so f there is at least `target` (never closer than asked).
fn bisect_bracketed(mut f: impl FnMut(f32) -> f32, mut lo: f32, mut hi: f32, target: f32) -> f32 {
    for _ in 0..40 {
        if hi - lo < 1e-5 {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if f(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Finds x with f(x) = target for an increasing f, widening [lo, hi] until it brackets the target.
fn solve_increasing(mut f: impl FnMut(f32) -> f32, mut lo: f32, mut hi: f32, target: f32) -> f32 {
    for _ in 0..20 {
        if f(lo) <= target {
            break;
        }
        lo -= hi - lo;
    }
    for _ in 0..20 {
        if f(hi) >= target {
            break;
        }
        hi += hi - lo;
    }
    bisect_bracketed(f, lo, hi, target)
}

/// Finds x in [lo, hi] where an increasing f crosses `target`, clamped to the ends.
fn bisect_clamped(mut f: impl FnMut(f32) -> f32, lo: f32, hi: f32, target: f32) -> f32 {
    if f(lo) >= target {
        return lo;
    }
    if f(hi) <= target {
        return hi;
    }
    bisect_bracketed(f, lo, hi, target)
}

/// Places one arch along its curve with adjacent crowns `contact_gap` apart.
fn place_arch(
    arch: Arch,
    curve: &ArchCurve,
    shapes: &ShapeSet,
    layout: &ArchLayout,
    spaces: &Spaces,
) -> Vec<(Fdi, Pose, f32)> {
    let quadrant = |side: Side| match (arch, side) {
        (Arch::Upper, Side::Right) => 1,
        (Arch::Upper, Side::Left) => 2,
        (Arch::Lower, Side::Left) => 3,
        (Arch::Lower, Side::Right) => 4,
    };
    let fdi = |side, pos| Fdi::from_parts(quadrant(side), pos).expect("valid FDI");
    let shape = |pos: u8| shapes.get(arch, ToothKind::from_position(pos).expect("position 1-8"));
    let pose = |side: Side, pos: u8, u: f32| {
        let s = if side == Side::Left { u } else { -u };
        pose_on_curve(curve, s, fdi(side, pos), &shape(pos), layout, 0.0)
    };
    let central = shape(1);
    let half = 0.5 * central.anatomy.mesiodistal;
    let space = |f: Fdi| spaces.get(&f).copied().unwrap_or(0.0);
    let midline_space = space(fdi(Side::Right, 1)) + space(fdi(Side::Left, 1));
    let u1 = solve_increasing(
        |u| {
            gap(
                &central,
                &pose(Side::Right, 1, u),
                &central,
                &pose(Side::Left, 1, u),
            )
        },
        half - 1.0,
        half + 1.0 + midline_space,
        layout.contact_gap + midline_space,
    );
    let mut out = Vec::new();
    for side in [Side::Right, Side::Left] {
        let mut prev_u = u1;
        let mut prev_pose = pose(side, 1, u1);
        out.push((fdi(side, 1), prev_pose, u1));
        for pos in 2..=8u8 {
            let (prev, cur) = (shape(pos - 1), shape(pos));
            let extra = space(fdi(side, pos));
            let guess = prev_u + 0.5 * (prev.anatomy.mesiodistal + cur.anatomy.mesiodistal) + extra;
            let u = solve_increasing(
                |u| gap(&prev, &prev_pose, &cur, &pose(side, pos, u)),
                guess - 1.5,
                guess + 1.0,
                layout.contact_gap + extra,
            );
            prev_u = u;
            prev_pose = pose(side, pos, u);
            out.push((fdi(side, pos), prev_pose, u));
        }
    }
    out
}

/// Buccal overlap (upper minus lower lateral distance of the first molars' crown centres, mean of
/// both sides) and molar relation of placed arches (no lift).
fn molar_measures(shapes: &ShapeSet, upper: &[(Fdi, Pose)], lower: &[(Fdi, Pose)]) -> Vec2 {
    let centre = |teeth: &[(Fdi, Pose)], n: i64| {
        let f = Fdi::new(n).expect("valid FDI");
        let pose = teeth
            .iter()
            .find(|t| t.0 == f)
            .map_or(Pose::IDENTITY, |t| t.1);
        pose.transform_point(shapes.get(f.arch(), f.kind()).frame.crown_centre)
    };
    let overlap = [(16, 46), (26, 36)]
        .iter()
        .map(|&(u, l)| centre(upper, u).x.abs() - centre(lower, l).x.abs())
        .sum::<f32>()
        / 2.0;
    let all: Vec<(Fdi, Pose)> = upper.iter().chain(lower).copied().collect();
    Vec2::new(overlap, measure_occlusion(shapes, &all).molar_relation_mm)
}

/// Solves the upper arch form's width and depth so that the upper first molars stand
/// `buccal_overlap` buccal of the lower ones and in class I.
///
/// The fast model places teeth at their nominal arc positions (summed widths) and measures on the
/// arch curves; nested bisections solve it. The exact contact placement then moves the teeth a
/// little, so the measured errors on the placed teeth are fed back as corrections of the model's
/// targets and the model solved again (two rounds).
fn solve_upper_form(
    shapes: &ShapeSet,
    layout: &ArchLayout,
    lower: &[(Fdi, Pose)],
    spaces: &Spaces,
) -> (BetaArch, Vec2, Vec<(Fdi, Pose)>) {
    let front_z = layout.lower.front_z + layout.overjet_offset;
    let lower_curve = ArchCurve::new(&layout.lower);
    let s_lower = nominal_arc(shapes, Arch::Lower, 6);
    let s_upper = nominal_arc(shapes, Arch::Upper, 6);
    let cusp_ahead = shapes
        .get(Arch::Upper, ToothKind::FirstMolar)
        .cusp_tips
        .iter()
        .map(|c| c.x.abs())
        .fold(0.0, f32::max);
    let (lower_p, _) = lower_curve.at(s_lower);
    let model = |w: f32, d: f32, correction: Vec2| -> Vec2 {
        let c = ArchCurve::new(&BetaArch {
            width: w,
            depth: d,
            front_z,
        });
        let (p, _) = c.at(s_upper);
        let (cusp, _) = c.at(s_upper - cusp_ahead);
        Vec2::new(p.x - lower_p.x - layout.buccal_overlap, cusp.y - lower_p.y) + correction
    };
    let (w_lo, w_hi) = (layout.lower.width - 5.0, layout.lower.width + 20.0);
    let (d_lo, d_hi) = (layout.lower.depth - 15.0, layout.lower.depth + 15.0);
    let solve_model = |correction: Vec2| -> (f32, f32) {
        let width_for = |d: f32| bisect_clamped(|w| model(w, d, correction).x, w_lo, w_hi, 0.0);
        // Deeper arches put the molars further back: the class I error falls with depth.
        let d = bisect_clamped(|d| -model(width_for(d), d, correction).y, d_lo, d_hi, 0.0);
        (width_for(d), d)
    };
    let place = |w: f32, d: f32| -> Vec<(Fdi, Pose)> {
        let form = BetaArch {
            width: w,
            depth: d,
            front_z,
        };
        place_arch(Arch::Upper, &ArchCurve::new(&form), shapes, layout, spaces)
            .into_iter()
            .map(|(f, p, _)| (f, p))
            .collect()
    };
    let mut correction = Vec2::ZERO;
    let (mut w, mut d) = solve_model(correction);
    let mut upper = place(w, d);
    let mut residual =
        molar_measures(shapes, &upper, lower) - Vec2::new(layout.buccal_overlap, 0.0);
    for _ in 0..2 {
        if residual.length() < 0.05 {
            break;
        }
        correction += residual;
        let (nw, nd) = solve_model(correction);
        let candidate = place(nw, nd);
        let r = molar_measures(shapes, &candidate, lower) - Vec2::new(layout.buccal_overlap, 0.0);
        if r.length() >= residual.length() {
            break;
        }
        (w, d, upper, residual) = (nw, nd, candidate, r);
    }
    (
        BetaArch {
            width: w,
            depth: d,
            front_z,
        },
        residual,
        upper,
    )
}

/// Nominal arc position of a tooth's centre from the tooth widths alone.
fn nominal_arc(shapes: &ShapeSet, arch: Arch, position: u8) -> f32 {
    let widths: Vec<f32> = (1..=position)
        .map(|p| {
            shapes
                .get(arch, ToothKind::from_position(p).expect("1-8"))
                .anatomy
                .mesiodistal
        })
        .collect();
    widths.iter().sum::<f32>() - 0.5 * widths[widths.len() - 1]
}

/// Extra space (mm) on the mesial side of teeth (a diastema at 21 opens the 11–21 contact).
pub type Spaces = BTreeMap<Fdi, f32>;

/// Builds the arrangement of all 32 teeth, with extra spaces where asked.
pub fn arrange(shapes: &ShapeSet, layout: &ArchLayout, spaces: &Spaces) -> Arrangement {
    let lower: Vec<(Fdi, Pose)> = place_arch(
        Arch::Lower,
        &ArchCurve::new(&layout.lower),
        shapes,
        layout,
        spaces,
    )
    .into_iter()
    .map(|(f, p, _)| (f, p))
    .collect();
    let (upper_form, upper_residual, upper) = solve_upper_form(shapes, layout, &lower, spaces);
    let shape_of = |f: Fdi| shapes.get(f.arch(), f.kind());
    // Opposing pairs whose footprints come near each other.
    let footprint = |f: Fdi, p: &Pose| {
        let b = shape_of(f).bvh.root_aabb();
        let m = Mat3::from_quat(p.rotation);
        b.transformed(&m, p.translation)
    };
    let mut pairs = Vec::new();
    for (fu, pu) in &upper {
        for (fl, pl) in &lower {
            let (bu, bl) = (footprint(*fu, pu), footprint(*fl, pl));
            let flat = |b: Aabb| Aabb {
                min: b.min.with_y(0.0) - Vec3::splat(1.0),
                max: b.max.with_y(0.0) + Vec3::splat(1.0),
            };
            if flat(bu).distance_squared(&flat(bl)) == 0.0 {
                pairs.push((*fu, *pu, *fl, *pl));
            }
        }
    }
    let min_gap = |lift: f32| -> f32 {
        pairs
            .iter()
            .map(|(fu, pu, fl, pl)| {
                let raised = Pose::new(pu.rotation, pu.translation + Vec3::Y * lift);
                gap(&shape_of(*fu), &raised, &shape_of(*fl), pl)
            })
            .fold(f32::INFINITY, f32::min)
    };
    let lift = solve_increasing(min_gap, -1.0, 4.0, layout.occlusal_gap);
    let mut poses: Vec<(Fdi, Pose)> = upper
        .into_iter()
        .map(|(f, p)| (f, Pose::new(p.rotation, p.translation + Vec3::Y * lift)))
        .chain(lower)
        .collect();
    poses.sort_by_key(|(f, _)| *f);
    let measures = measure_occlusion(shapes, &poses);
    Arrangement {
        poses,
        upper: upper_form,
        upper_residual,
        measures,
    }
}

/// Overjet, overbite and molar relation of an arrangement.
pub fn measure_occlusion(shapes: &ShapeSet, poses: &[(Fdi, Pose)]) -> OcclusionMeasures {
    let pose = |n: i64| {
        let f = Fdi::new(n).expect("valid FDI");
        (
            shapes.get(f.arch(), f.kind()),
            poses
                .iter()
                .find(|(g, _)| *g == f)
                .map_or(Pose::IDENTITY, |x| x.1),
        )
    };
    let mut overjet = 0.0;
    let mut overbite = 0.0;
    let mut molar = 0.0;
    for (upper_incisor, lower_incisor, upper_molar, lower_molar) in
        [(11, 41, 16, 46), (21, 31, 26, 36)]
    {
        let (su, pu) = pose(upper_incisor);
        let (sl, pl) = pose(lower_incisor);
        let edge = pu.transform_point(su.cusp_tips[0]);
        let lower_edge = pl.transform_point(sl.cusp_tips[0]);
        overbite += lower_edge.y - edge.y;
        // The lower incisor's labial surface at the height of the upper edge.
        let labial = sl
            .mesh
            .vertices
            .iter()
            .map(|&v| pl.transform_point(v))
            .filter(|v| (v.y - edge.y).abs() < 1.0 && (v.x - edge.x).abs() < 2.0)
            .map(|v| v.z)
            .fold(f32::NEG_INFINITY, f32::max);
        overjet += if labial.is_finite() {
            edge.z - labial
        } else {
            f32::NAN
        };
        let (su, pu) = pose(upper_molar);
        let (sl, pl) = pose(lower_molar);
        let mesiobuccal = su
            .cusp_tips
            .iter()
            .map(|&c| pu.transform_point(c))
            .filter(|c| (*c - pu.translation).dot(pu.transform_vector(Vec3::Z)) > 0.0)
            .max_by(|a, b| a.z.total_cmp(&b.z))
            .unwrap_or(pu.translation);
        let groove = pl.transform_point(Vec3::new(0.0, sl.frame.crown_length, 0.0));
        molar += mesiobuccal.z - groove.z;
    }
    OcclusionMeasures {
        overjet_mm: overjet / 2.0,
        overbite_mm: overbite / 2.0,
        molar_relation_mm: molar / 2.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_beta_curve_has_its_depth_and_width() {
        let form = BetaArch {
            width: 50.0,
            depth: 36.0,
            front_z: 18.0,
        };
        assert!((form.point(0.0).y - 18.0).abs() < 1e-2);
        assert!((form.point(25.0).y - (18.0 - 36.0)).abs() < 1e-4);
        let curve = ArchCurve::new(&form);
        let (p, t) = curve.at(0.0);
        assert!((p - Vec2::new(0.0, 18.0)).length() < 1e-2, "{p}");
        assert!((t - Vec2::X).length() < 1e-2, "{t}");
        let (l, tl) = curve.at(30.0);
        let (r, tr) = curve.at(-30.0);
        assert!(
            (l.x + r.x).abs() < 1e-4 && (l.y - r.y).abs() < 1e-4,
            "mirror symmetric"
        );
        assert!(tl.y < 0.0 && tr.y > 0.0);
        // Past the end the curve runs straight back.
        let (far, tf) = curve.at(200.0);
        assert!((far.x - 25.0).abs() < 1e-3 && (tf - Vec2::new(0.0, -1.0)).length() < 1e-6);
    }
}
