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
//!    `contact_gap` (bisection on the arc position; the gap grows monotonically with it); a tooth
//!    with a `buccal_offset` stands that far out of the curve.
//! 2. The upper curve's width and depth are solved so that the upper first molars stand
//!    `buccal_overlap` buccal to the lower ones and their mesiobuccal cusps sit over the lower first
//!    molars' buccal grooves (Angle class I): nested bisections on a fast model (teeth at their
//!    summed widths along the curves), corrected by what the exact placement then measures. Its
//!    front lies `overjet_offset` ahead of the lower front.
//! 3. The upper arch is lowered onto the lower until the least exact gap between the posterior
//!    teeth is `occlusal_gap` (bisection on its height).
//! 4. The bite is levelled as a settled class I bite is: each lower premolar and molar is raised or
//!    lowered until its exact gap to the upper arch is `occlusal_gap`, each lower incisor until its
//!    gap is its `anterior_gap` (the incisors just out of contact), and a lower canine closer than
//!    its gap is lowered to it (or, with `raise_canines`, levelled to it both ways); then each
//!    upper premolar and molar still farther than `occlusal_gap` from the lower arch comes down
//!    to it, so every posterior tooth of both arches meets its antagonists. Both arches are then
//!    placed along their curves again at the new heights, so adjacent crowns keep their
//!    `contact_gap`, and the levelling is repeated until no tooth moves by more than 0.001 mm (at
//!    most four rounds).

use std::{collections::BTreeMap, sync::Arc};

use glam::{Mat3, Quat, Vec2, Vec3};
use serde::Serialize;

use super::{
    fdi::{Arch, Fdi, Side, ToothKind},
    memo::Memo,
    tooth_shape::{ShapeSet, ToothGeometry},
};
use crate::geometry::{Aabb, Pose, mesh_separation};

mod bisect;
mod form;
pub mod irregularity;
mod occlusion;

use bisect::{bisect_clamped, solve_increasing};
pub use form::{ArchCurve, BetaArch};
pub use occlusion::{Placed, canine_relation, incisor_relation, measure_occlusion, molar_relation};

/// Parameters of the normal arrangement.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArchLayout {
    /// Lower arch form.
    pub lower: BetaArch,
    /// Exact gap between adjacent crowns (mm).
    pub contact_gap: f32,
    /// Exact gap (mm) between each lower premolar and molar and the upper arch.
    pub occlusal_gap: f32,
    /// Exact gap (mm) between each lower central incisor, lateral incisor and canine and the upper
    /// arch (a lower canine farther than its gap stays where it is unless `raise_canines`).
    pub anterior_gap: [f32; 3],
    /// Whether the lower canines are raised to their gap as the incisors are, not only lowered to
    /// it.
    pub raise_canines: bool,
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
    /// How far buccal (labial) of its curve each tooth stands (mm), upper then lower, by
    /// position: the upper canines' prominence, which puts their lingual surfaces over the lower
    /// canines' labial surfaces.
    pub buccal_offset: [[f32; 8]; 2],
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
            occlusal_gap: 0.01,
            anterior_gap: [0.12, 0.12, 0.12],
            raise_canines: false,
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
            buccal_offset: [[0.0; 8]; 2],
        }
    }
}

impl ArchLayout {
    /// The layout whose canines guide the jaw's lateral excursions (canine-protected
    /// occlusion): the upper canines stand 1.8 mm labial of their curve (the canine eminence)
    /// with their tips 0.9 mm below the occlusal plane, and the lower canines are raised until
    /// their labial surfaces are 0.05 mm under the upper canines' lingual surfaces; the lower
    /// lateral incisors stand 0.2 mm from the upper arch, so the canines meet first. Not yet the
    /// built-in cases' layout (see the guide's occlusion chapter).
    pub fn canine_guided() -> Self {
        let mut layout = Self::default();
        layout.tip_level[0][2] = 0.9;
        layout.buccal_offset[0][2] = 1.8;
        layout.anterior_gap = [0.12, 0.2, 0.05];
        layout.raise_canines = true;
        layout
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
    raise: f32,
) -> Pose {
    let (p, t) = curve.at(s);
    let out = Vec3::new(-t.y, 0.0, t.x);
    let row = arch_row(fdi.arch());
    let k = fdi.position() as usize - 1;
    let tip = shape.frame.crown_length;
    let level = layout.tip_level[row][k];
    let (up, y) = match fdi.arch() {
        Arch::Lower => (Vec3::Y, level - tip + raise),
        Arch::Upper => (-Vec3::Y, -level + tip + raise),
    };
    let x = up.cross(out);
    let base = Quat::from_mat3(&Mat3::from_cols(x, up, out));
    let incline = Quat::from_axis_angle(x, layout.inclination_deg[row][k].to_radians());
    let at = Vec3::new(p.x, y, p.y) + out * layout.buccal_offset[row][k];
    Pose::new((incline * base).normalize(), at)
}

/// Signed gap between two posed shapes (negative when they overlap).
fn gap(a: &ToothGeometry, pa: &Pose, b: &ToothGeometry, pb: &Pose) -> f32 {
    mesh_separation(a.mesh_ref(), pa, b.mesh_ref(), pb).signed_gap()
}

/// Places one arch along its curve with adjacent crowns `contact_gap` apart, each tooth raised by
/// its entry in `raise` (mm, world +y; none is 0).
fn place_arch(
    arch: Arch,
    curve: &ArchCurve,
    shapes: &ShapeSet,
    layout: &ArchLayout,
    spaces: &Spaces,
    raise: &BTreeMap<Fdi, f32>,
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
        let f = fdi(side, pos);
        let r = raise.get(&f).copied().unwrap_or(0.0);
        pose_on_curve(curve, s, f, &shape(pos), layout, r)
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
        place_arch(
            Arch::Upper,
            &ArchCurve::new(&form),
            shapes,
            layout,
            spaces,
            &BTreeMap::new(),
        )
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

/// Opposing pairs (upper index, lower index) whose footprints in the occlusal plane come within
/// 1 mm of each other.
fn antagonists(
    shapes: &ShapeSet,
    upper: &[(Fdi, Pose)],
    lower: &[(Fdi, Pose)],
) -> Vec<(usize, usize)> {
    let flat = |f: Fdi, p: &Pose| {
        let b = shapes
            .get(f.arch(), f.kind())
            .bvh
            .root_aabb()
            .transformed(&Mat3::from_quat(p.rotation), p.translation);
        Aabb {
            min: b.min.with_y(0.0) - Vec3::splat(1.0),
            max: b.max.with_y(0.0) + Vec3::splat(1.0),
        }
    };
    let mut pairs = Vec::new();
    for (i, (fu, pu)) in upper.iter().enumerate() {
        for (j, (fl, pl)) in lower.iter().enumerate() {
            if flat(*fu, pu).distance_squared(&flat(*fl, pl)) == 0.0 {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// The pose moved by `dy` along world +y.
fn lifted(p: &Pose, dy: f32) -> Pose {
    Pose::new(p.rotation, p.translation + Vec3::Y * dy)
}

/// How far (mm, along −y) a lower tooth must drop for `least(drop)`, its least gap to the upper
/// arch, to be `target`: secant steps from the guess that the gap follows the drop one to one,
/// bisection when they do not settle. The result's gap is at least `target` − 1e-4 mm.
fn drop_to(mut least: impl FnMut(f32) -> f32, target: f32) -> f32 {
    let (mut x0, mut g0) = (0.0f32, least(0.0));
    if (g0 - target).abs() < 1e-4 {
        return 0.0;
    }
    let mut x1 = target - g0;
    for _ in 0..8 {
        let g1 = least(x1);
        if (g1 - target).abs() < 1e-4 && g1 >= target - 1e-4 {
            return x1;
        }
        let slope = (g1 - g0) / (x1 - x0);
        if !(0.05..=20.0).contains(&slope) {
            break;
        }
        (x0, g0) = (x1, g1);
        x1 += ((target - g1) / slope).clamp(-1.0, 1.0);
    }
    solve_increasing(least, -1.0, 1.0, target)
}

/// Builds the arrangement of all 32 teeth, with extra spaces where asked.
pub fn arrange(shapes: &ShapeSet, layout: &ArchLayout, spaces: &Spaces) -> Arrangement {
    let lower_curve = ArchCurve::new(&layout.lower);
    let place = |arch: Arch, curve: &ArchCurve, raise: &BTreeMap<Fdi, f32>| -> Vec<(Fdi, Pose)> {
        place_arch(arch, curve, shapes, layout, spaces, raise)
            .into_iter()
            .map(|(f, p, _)| (f, p))
            .collect()
    };
    let mut raise = BTreeMap::new();
    let mut lower = place(Arch::Lower, &lower_curve, &raise);
    let (upper_form, upper_residual, upper) = solve_upper_form(shapes, layout, &lower, spaces);
    let upper_curve = ArchCurve::new(&upper_form);
    let shape_of = |f: Fdi| shapes.get(f.arch(), f.kind());
    let posterior = |f: Fdi| f.position() >= 4;
    // The upper arch comes down until its first posterior contact.
    let pairs = antagonists(shapes, &upper, &lower);
    let min_gap = |lift: f32| -> f32 {
        pairs
            .iter()
            .filter(|(i, j)| posterior(upper[*i].0) && posterior(lower[*j].0))
            .map(|(i, j)| {
                let ((fu, pu), (fl, pl)) = (&upper[*i], &lower[*j]);
                gap(&shape_of(*fu), &lifted(pu, lift), &shape_of(*fl), pl)
            })
            .fold(f32::INFINITY, f32::min)
    };
    let lift = solve_increasing(min_gap, -1.0, 4.0, layout.occlusal_gap);
    raise.extend(upper.iter().map(|(f, _)| (*f, lift)));
    let mut upper: Vec<(Fdi, Pose)> = upper.iter().map(|(f, p)| (*f, lifted(p, lift))).collect();
    // Each lower tooth is levelled against the upper arch, then each upper premolar and molar not
    // yet meeting the lower arch comes down onto it; both arches are then placed along their
    // curves again at the new heights (which keeps the crowns' proximal contacts), until the
    // levels hold.
    for _ in 0..LEVELLING_ROUNDS {
        let pairs = antagonists(shapes, &upper, &lower);
        // The upper teeth facing lower tooth `k` (`of_lower`), or the lower teeth facing upper `k`.
        let facing = |k: usize, of_lower: bool| -> Vec<usize> {
            pairs
                .iter()
                .filter(|(u, l)| if of_lower { *l == k } else { *u == k })
                .map(|(u, l)| if of_lower { *u } else { *l })
                .collect()
        };
        let mut largest = 0.0f32;
        for (j, (fl, pl)) in lower.iter().enumerate() {
            let facing = facing(j, true);
            if facing.is_empty() {
                continue;
            }
            let least = |drop: f32| -> f32 {
                facing
                    .iter()
                    .map(|i| {
                        let (fu, pu) = &upper[*i];
                        gap(&shape_of(*fu), pu, &shape_of(*fl), &lifted(pl, -drop))
                    })
                    .fold(f32::INFINITY, f32::min)
            };
            let target = match fl.kind() {
                _ if posterior(*fl) => layout.occlusal_gap,
                ToothKind::Canine
                    if !layout.raise_canines && least(0.0) >= layout.anterior_gap[2] =>
                {
                    continue;
                }
                _ => layout.anterior_gap[fl.position() as usize - 1],
            };
            let drop = drop_to(least, target);
            *raise.entry(*fl).or_insert(0.0) -= drop;
            largest = largest.max(drop.abs());
        }
        lower = place(Arch::Lower, &lower_curve, &raise);
        for (i, (fu, pu)) in upper.iter().enumerate() {
            let facing = facing(i, false);
            if !posterior(*fu) || facing.is_empty() {
                continue;
            }
            let least = |up: f32| -> f32 {
                facing
                    .iter()
                    .map(|j| {
                        let (fl, pl) = &lower[*j];
                        gap(&shape_of(*fu), &lifted(pu, up), &shape_of(*fl), pl)
                    })
                    .fold(f32::INFINITY, f32::min)
            };
            if least(0.0) <= layout.occlusal_gap + 1e-3 {
                continue;
            }
            let up = drop_to(least, layout.occlusal_gap);
            *raise.entry(*fu).or_insert(0.0) += up;
            largest = largest.max(up.abs());
        }
        upper = place(Arch::Upper, &upper_curve, &raise);
        if largest < 1e-3 {
            break;
        }
    }
    let mut poses: Vec<(Fdi, Pose)> = upper.into_iter().chain(lower).collect();
    poses.sort_by_key(|(f, _)| *f);
    let measures = measure_occlusion(shapes, &poses);
    Arrangement {
        poses,
        upper: upper_form,
        upper_residual,
        measures,
    }
}

/// Most rounds of levelling the lower teeth against the upper arch.
const LEVELLING_ROUNDS: usize = 4;
