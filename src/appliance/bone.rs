//! The alveolar envelope: the buccal and lingual cortical plates a root may not pass.
//!
//! A case without bone meshes gets its envelope from the arch as the simulation starts. Per arch,
//! the axis is the arch curve the simulation moves teeth along (the case's arch form, fitted to
//! imported teeth), with its straight continuation behind the last teeth, tabulated every
//! [`AXIS_STEP_MM`]. Every root point below the crest is measured from that axis: signed offset
//! `d` (positive buccal/labial) and height `y`. Per tooth and per [`CELL_MM`] of height, the buccal
//! plate lies [`BUCCAL_MM`] beyond the outermost root point of the tooth and its two neighbours
//! in the arch at that height (and the next), the lingual plate [`LINGUAL_MM`] beyond the
//! innermost: the alveolar process is as wide as the roots it holds, so a tooth blocked out of
//! line may come back into it. Heights no root reaches (below the apices) take the plates of the
//! nearest height, closing in on the axis by [`SLOPE_HEIGHT`] per mm. Between heights the plates
//! are linear.
//!
//! Along the arch there is no plate: a tooth's plates go with it as it moves mesially or
//! distally along the axis (bone remodels ahead of a root moving along the arch, and its
//! neighbours' roots bound it there). Across the arch they hold.
//!
//! Distances: the labial bone over the anterior roots is mostly 1 mm thick or less (Braut et al.
//! 2011, *Int J Periodontics Restorative Dent* 31:125, cone-beam CT of 125 patients); the lingual
//! alveolus of the lower incisors is thicker, 1–2 mm, and bounds how far incisors can be moved
//! (Handelman 1996, *Angle Orthod* 66:95, the "orthodontic walls").
//!
//! Guarantee: the envelope contains every root point as placed, at least [`BUCCAL_MM`] and
//! [`LINGUAL_MM`] inside its plates along the axis's normal; a query reports every sampled point
//! beyond a plate or within the asked tolerance of it, with its depth, exact for the piecewise-
//! linear plates.

use std::collections::BTreeMap;

use glam::{Vec2, Vec3};
use serde::Serialize;

use crate::{
    geometry::Pose,
    teeth::{Arch, Fdi, arch::ArchCurve},
};

/// Distance from the roots as placed to the buccal (labial) plate (mm).
pub const BUCCAL_MM: f32 = 1.0;
/// Distance from the roots as placed to the lingual (palatal) plate (mm).
pub const LINGUAL_MM: f32 = 1.5;
/// Height of a cell of the plates (mm).
pub const CELL_MM: f32 = 1.0;
/// Length of the straight tails past the last teeth (mm).
pub const TAIL_MM: f32 = 15.0;
/// How fast the plates close in on the axis below the deepest root (mm per mm of height).
pub const SLOPE_HEIGHT: f32 = 0.3;
/// Spacing of the axis's vertices (mm).
pub const AXIS_STEP_MM: f32 = 0.5;
/// Every how many vertices the nearest is first looked for.
const COARSE: usize = 8;

/// Which plate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Plate {
    /// Buccal (labial) plate.
    Buccal,
    /// Lingual (palatal) plate.
    Lingual,
}

/// A root point at or beyond a plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateContact {
    /// The root point (world).
    pub point: Vec3,
    /// Unit direction that takes the point back inside the envelope (the plate's inward normal,
    /// across the arch and in height).
    pub inward: Vec3,
    /// How far past the plate the point lies (mm, along the plate's normal; negative: still
    /// inside by that much).
    pub depth: f32,
    /// Which plate.
    pub plate: Plate,
}

/// One arch's axis in plan.
#[derive(Clone, Debug)]
pub(crate) struct Axis {
    arch: Arch,
    /// The axis in plan (x, z), right distal to left distal.
    path: Vec<Vec2>,
}

impl Axis {
    /// The axis along `curve` from the right end of its tail to the left one.
    pub(crate) fn along(arch: Arch, curve: &ArchCurve) -> Self {
        let end = curve.half_length() + TAIL_MM;
        let n = ((2.0 * end / AXIS_STEP_MM).ceil() as usize).max(1);
        let path = (0..=n)
            .map(|k| curve.at(-end + 2.0 * end * k as f32 / n as f32).0)
            .collect();
        Self { arch, path }
    }

    /// Signed offset (positive buccal) and outward unit normal of plan point `p`: the nearest
    /// of every [`COARSE`]th vertex, then the segments either side of it.
    pub(crate) fn locate(&self, p: Vec2) -> (f32, Vec2) {
        let last = self.path.len() - 1;
        let near = (0..=last)
            .step_by(COARSE)
            .min_by(|a, b| {
                self.path[*a]
                    .distance_squared(p)
                    .total_cmp(&self.path[*b].distance_squared(p))
            })
            .unwrap_or(0);
        let mut best = (f32::INFINITY, 0.0, Vec2::Y);
        for k in near.saturating_sub(COARSE)..(near + COARSE).min(last) {
            let (a, b) = (self.path[k], self.path[k + 1]);
            let ab = b - a;
            let len = ab.length().max(1e-6);
            let t = ((p - a).dot(ab) / (len * len)).clamp(0.0, 1.0);
            let q = a + ab * t;
            let dist = (p - q).length_squared();
            if dist < best.0 {
                let tangent = ab / len;
                // Walking from the right distal end to the left one, outward is the tangent
                // turned clockwise in plan (x right-to-left, z forward).
                let outward = Vec2::new(-tangent.y, tangent.x);
                best = (dist, (p - q).dot(outward), outward);
            }
        }
        (best.1, best.2)
    }
}

/// One tooth's plates by height.
#[derive(Clone, Debug)]
struct ToothPlates {
    y0: f32,
    buccal: Vec<f32>,
    lingual: Vec<f32>,
}

impl ToothPlates {
    /// The plates at height `y` and their slopes with height.
    fn at(&self, y: f32) -> ([f32; 2], [f32; 2]) {
        let n = self.buccal.len();
        let v = ((y - self.y0) / CELL_MM).clamp(0.0, (n - 1) as f32);
        let j = (v.floor() as usize).min(n.saturating_sub(2));
        let f = v - j as f32;
        let inside = (y - self.y0) / CELL_MM >= 0.0 && v < (n - 1) as f32;
        let lerp = |g: &[f32]| g[j] + (g[(j + 1).min(n - 1)] - g[j]) * f;
        let slope = |g: &[f32]| {
            if inside {
                (g[(j + 1).min(n - 1)] - g[j]) / CELL_MM
            } else {
                0.0
            }
        };
        (
            [lerp(&self.buccal), lerp(&self.lingual)],
            [slope(&self.buccal), slope(&self.lingual)],
        )
    }
}

/// The buccal and lingual plates of both arches (see the module doc).
#[derive(Clone, Debug)]
pub struct AlveolarEnvelope {
    axes: Vec<Axis>,
    teeth: BTreeMap<Fdi, ToothPlates>,
}

/// A tooth as the envelope is made from it: its number, pose and root points below the crest
/// (tooth frame).
pub struct RootedTooth<'a> {
    /// FDI number.
    pub fdi: Fdi,
    /// Pose as placed.
    pub pose: Pose,
    /// Root points below the crest (tooth frame).
    pub roots: &'a [Vec3],
}

impl AlveolarEnvelope {
    /// The envelope around `teeth` as placed, about the arch curves `curves` (upper, lower); an
    /// arch with fewer than two rooted teeth gets none.
    pub fn new(teeth: &[RootedTooth], curves: [&ArchCurve; 2]) -> Self {
        let mut axes = Vec::new();
        let mut plates = BTreeMap::new();
        for arch in [Arch::Upper, Arch::Lower] {
            let mut own: Vec<&RootedTooth> = teeth
                .iter()
                .filter(|t| t.fdi.arch() == arch && !t.roots.is_empty())
                .collect();
            if own.len() < 2 {
                continue;
            }
            own.sort_by_key(|t| t.fdi.arch_index());
            let world: Vec<Vec<Vec3>> = own
                .iter()
                .map(|t| t.roots.iter().map(|p| t.pose.transform_point(*p)).collect())
                .collect();
            let axis = Axis::along(arch, curves[usize::from(arch == Arch::Lower)]);
            let (ymin, ymax) = world
                .iter()
                .flatten()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p.y), hi.max(p.y))
                });
            let ny = (((ymax - ymin) / CELL_MM).ceil() as usize + 1).max(2);
            // Each tooth's own extents by height.
            let extents: Vec<[Vec<f32>; 2]> = world
                .iter()
                .map(|points| {
                    let mut out = vec![f32::NEG_INFINITY; ny];
                    let mut inn = vec![f32::INFINITY; ny];
                    for p in points {
                        let (d, _) = axis.locate(Vec2::new(p.x, p.z));
                        let j = (((p.y - ymin) / CELL_MM).round() as usize).min(ny - 1);
                        // This height and the next either side: the linear blend between
                        // heights clears every point by the plates' distances.
                        for jj in j.saturating_sub(1)..=(j + 1).min(ny - 1) {
                            out[jj] = out[jj].max(d + BUCCAL_MM);
                            inn[jj] = inn[jj].min(d - LINGUAL_MM);
                        }
                    }
                    [out, inn]
                })
                .collect();
            for (k, t) in own.iter().enumerate() {
                let near = k.saturating_sub(1)..=(k + 1).min(own.len() - 1);
                let mut buccal = vec![f32::NEG_INFINITY; ny];
                let mut lingual = vec![f32::INFINITY; ny];
                for e in &extents[near] {
                    for j in 0..ny {
                        buccal[j] = buccal[j].max(e[0][j]);
                        lingual[j] = lingual[j].min(e[1][j]);
                    }
                }
                cone(&mut buccal, 1.0);
                cone(&mut lingual, -1.0);
                plates.insert(
                    t.fdi,
                    ToothPlates {
                        y0: ymin,
                        buccal,
                        lingual,
                    },
                );
            }
            axes.push(axis);
        }
        Self {
            axes,
            teeth: plates,
        }
    }

    /// Every point of `roots` (tooth frame) of tooth `fdi` at `pose` that lies beyond a plate or
    /// within `tolerance` of it (mm), with its depth; none for a tooth the envelope was not made
    /// with.
    pub fn contacts(
        &self,
        fdi: Fdi,
        pose: &Pose,
        roots: &[Vec3],
        tolerance: f32,
    ) -> Vec<PlateContact> {
        let (Some(axis), Some(plates)) = (
            self.axes.iter().find(|a| a.arch == fdi.arch()),
            self.teeth.get(&fdi),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for p in roots {
            let w = pose.transform_point(*p);
            let (d, outward) = axis.locate(Vec2::new(w.x, w.z));
            let (at, slope) = plates.at(w.y);
            let normal = Vec3::new(outward.x, 0.0, outward.y);
            for (depth, gradient, plate) in [
                (d - at[0], normal - Vec3::Y * slope[0], Plate::Buccal),
                (at[1] - d, Vec3::Y * slope[1] - normal, Plate::Lingual),
            ] {
                if depth < -tolerance {
                    continue;
                }
                // The depth grows along its gradient, across the arch and in height (the plate
                // leans where the roots taper); along the arch it does not change.
                let length = gradient.length();
                out.push(PlateContact {
                    point: w,
                    inward: -gradient / length,
                    depth: depth / length,
                    plate,
                });
            }
        }
        out
    }
}

/// The cone envelope of a column of heights (sign 1: the largest of v − slope·distance over
/// all heights; −1: the least of v + slope·distance), with [`SLOPE_HEIGHT`].
fn cone(column: &mut [f32], sign: f32) {
    let copy = column.to_vec();
    for (i, v) in column.iter_mut().enumerate() {
        let best = copy
            .iter()
            .enumerate()
            .filter(|(_, w)| w.is_finite())
            .map(|(k, w)| sign * w - SLOPE_HEIGHT * CELL_MM * k.abs_diff(i) as f32)
            .fold(f32::NEG_INFINITY, f32::max);
        *v = sign * best;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::arch::ArchLayout;
    use glam::Quat;

    /// The built-in arrangement's lower arch form.
    fn curve() -> ArchCurve {
        ArchCurve::new(&ArchLayout::default().lower)
    }

    /// Ten incisor-like roots along the curve, 7 mm apart: points on a 3 mm-radius column,
    /// 12 mm deep.
    fn ring(curve: &ArchCurve) -> (Vec<Vec3>, Vec<(Fdi, Pose)>) {
        let mut roots = Vec::new();
        for k in 0..12 {
            for a in 0..8 {
                let t = a as f32 * std::f32::consts::TAU / 8.0;
                roots.push(Vec3::new(3.0 * t.cos(), -(k as f32), 3.0 * t.sin()));
            }
        }
        let fdis = [15, 14, 13, 12, 11, 21, 22, 23, 24, 25];
        let teeth = fdis
            .iter()
            .enumerate()
            .map(|(k, &f)| {
                let (p, _) = curve.at(7.0 * (k as f32 - 4.5));
                (
                    Fdi::new(f).unwrap(),
                    Pose::from_translation(Vec3::new(p.x, 0.0, p.y)),
                )
            })
            .collect();
        (roots, teeth)
    }

    fn envelope(curve: &ArchCurve, roots: &[Vec3], teeth: &[(Fdi, Pose)]) -> AlveolarEnvelope {
        let rooted: Vec<RootedTooth> = teeth
            .iter()
            .map(|(fdi, pose)| RootedTooth {
                fdi: *fdi,
                pose: *pose,
                roots,
            })
            .collect();
        AlveolarEnvelope::new(&rooted, [curve, curve])
    }

    /// The outward normal of the curve at a tooth.
    fn outward(curve: &ArchCurve, pose: &Pose) -> Vec3 {
        let s = curve.project(Vec2::new(pose.translation.x, pose.translation.z));
        let (_, t) = curve.at(s);
        Vec3::new(-t.y, 0.0, t.x)
    }

    #[test]
    fn roots_as_placed_are_inside_by_the_plates_distances() {
        let c = curve();
        let (roots, teeth) = ring(&c);
        let env = envelope(&c, &roots, &teeth);
        for (fdi, pose) in &teeth {
            let found = env.contacts(*fdi, pose, &roots, BUCCAL_MM - 0.01);
            assert!(found.is_empty(), "{fdi}: {found:?}");
        }
    }

    #[test]
    fn a_root_pushed_out_meets_the_plate_at_the_right_depth() {
        let c = curve();
        let (roots, teeth) = ring(&c);
        let env = envelope(&c, &roots, &teeth);
        // A premolar, where the arch bends gently (near the midline a point 5 mm inside a
        // tightly bent curve is nearer another part of it).
        let (fdi, pose) = teeth[8];
        let out = outward(&c, &pose);
        // 2 mm labial: the outermost points are 2 − 1 = 1 mm past the labial plate.
        let moved = Pose::from_translation(pose.translation + out * 2.0);
        let found = env.contacts(fdi, &moved, &roots, 0.0);
        let deepest = found.iter().map(|c| c.depth).fold(f32::MIN, f32::max);
        assert!(
            (deepest - (2.0 - BUCCAL_MM)).abs() < 0.15,
            "deepest {deepest}"
        );
        assert!(found.iter().all(|c| c.plate == Plate::Buccal));
        assert!(found.iter().all(|c| c.inward.dot(out) < -0.9));
        // 2 mm lingual: 0.5 mm past the lingual plate.
        let moved = Pose::from_translation(pose.translation - out * 2.0);
        let found = env.contacts(fdi, &moved, &roots, 0.0);
        let deepest = found.iter().map(|c| c.depth).fold(f32::MIN, f32::max);
        assert!(
            (deepest - (2.0 - LINGUAL_MM)).abs() < 0.15,
            "deepest {deepest}"
        );
        assert!(found.iter().all(|c| c.plate == Plate::Lingual));
    }

    #[test]
    fn sliding_along_the_arch_or_turning_in_place_meets_no_plate() {
        let c = curve();
        let (roots, teeth) = ring(&c);
        let env = envelope(&c, &roots, &teeth);
        let (fdi, pose) = teeth[6];
        // Along the arch into a neighbour's place (bone remodels along the arch).
        let along = Pose::from_translation(teeth[7].1.translation);
        assert!(env.contacts(fdi, &along, &roots, 0.0).is_empty());
        // A turn about the long axis keeps a round root where it was.
        let turned = Pose::new(Quat::from_rotation_y(1.0), pose.translation);
        assert!(env.contacts(fdi, &turned, &roots, 0.0).is_empty());
    }

    #[test]
    fn a_tooth_moved_into_an_extraction_site_keeps_its_plates() {
        let c = curve();
        let (roots, mut teeth) = ring(&c);
        let site = teeth.remove(2);
        let env = envelope(&c, &roots, &teeth);
        // The neighbour moved along the arch into the empty socket is inside; pushed 2 mm
        // labially there, it is out by 1 mm.
        let (fdi, _) = teeth[1];
        let found = env.contacts(fdi, &site.1, &roots, 0.0);
        assert!(found.is_empty(), "{found:?}");
        let out = Pose::from_translation(site.1.translation + outward(&c, &site.1) * 2.0);
        let found = env.contacts(fdi, &out, &roots, 0.0);
        let deepest = found.iter().map(|c| c.depth).fold(f32::MIN, f32::max);
        assert!((deepest - (2.0 - BUCCAL_MM)).abs() < 0.15, "{found:?}");
        // The removed tooth itself has no plates.
        assert!(env.contacts(site.0, &out, &roots, 0.0).is_empty());
    }

    #[test]
    fn a_tooth_blocked_out_of_line_may_come_back_between_its_neighbours() {
        let c = curve();
        let (roots, mut teeth) = ring(&c);
        // 13 stands 2 mm lingual of the arch: its plates reach its neighbours' labial extent.
        let aligned = teeth[2].1;
        let inward = -outward(&c, &aligned);
        teeth[2].1 = Pose::from_translation(aligned.translation + inward * 2.0);
        let env = envelope(&c, &roots, &teeth);
        let found = env.contacts(teeth[2].0, &aligned, &roots, 0.0);
        assert!(found.is_empty(), "{found:?}");
    }

    #[test]
    fn an_arch_of_one_tooth_has_no_envelope() {
        let c = curve();
        let (roots, teeth) = ring(&c);
        let env = envelope(&c, &roots, &teeth[..1]);
        let moved = Pose::from_translation(teeth[0].1.translation * 3.0);
        assert!(env.contacts(teeth[0].0, &moved, &roots, 0.0).is_empty());
    }
}
