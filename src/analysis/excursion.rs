//! The jaw's excursions from a bite: protrusion and right and left laterals in 0.5 mm steps, with
//! the teeth that guide the lower arch and the contacts that interfere.
//!
//! Hinge-and-slide condyles: the condyles sit [`CONDYLE_HALF_WIDTH_MM`] either side of the
//! midline, [`CONDYLE_BEHIND_MM`] behind the frame's origin and [`CONDYLE_ABOVE_MM`] above the
//! occlusal plane. In protrusion by h both slide forward h and down h·tan(θ), θ =
//! [`CONDYLAR_GUIDANCE_DEG`]. In a lateral by h the mandible turns about the vertical through the
//! working condyle (the side the jaw moves to; the Bennett movement without immediate side shift)
//! until the incisal point has moved h sideways, so the working-side teeth move outwards and a
//! little forwards (the arms of a gothic-arch tracing) and the other condyle travels forwards
//! and drops down its eminence by its travel·tan(θ), tilting the arch about the anteroposterior
//! line through the working condyle. At each
//! step the lower arch then closes about the axis through the condyles until its teeth meet the
//! upper arch (conservative advancement on the closing angle with the exact mesh distance, so the
//! arches never interpenetrate).
//!
//! The closing is lazy: every opposing pair whose boxes come within a few millimetres carries a
//! lower bound on its gap (first the distance of the boxes, then its last exact measure less how
//! far its lower tooth can have moved), and a pair is measured only when its bound would shorten
//! the step, with a query bounded to the distance that matters (parts of the two teeth farther
//! than that are never opened). The step taken is the least any bound allows, so it stays
//! conservative whichever pairs were measured.
//!
//! Guidance at each step (contacts within [`super::bite::AREA_TOLERANCE_MM`]): in protrusion,
//! `anterior` when incisors or canines touch each other and `posterior` when only posterior teeth
//! guide; in laterals, `anterior` when only incisors and canines touch, `canine` when on the working side only the canine touches,
//! `group function` when premolars or molars of the working side touch too, `none` when nothing
//! touches. Interferences: posterior contacts in protrusion, non-working-side contacts in
//! laterals.

use glam::{Quat, Vec3};
use serde::Serialize;

use super::{
    bite::{AREA_TOLERANCE_MM, TARGET_GAP_MM, Tracker, condyle_seat},
    measures::Posed,
};
use crate::{
    geometry::Pose,
    teeth::{Fdi, ToothKind},
};

/// Half the distance between the condyles (mm).
pub const CONDYLE_HALF_WIDTH_MM: f32 = 50.0;
/// How far behind the frame's origin the condyles sit (mm).
pub const CONDYLE_BEHIND_MM: f32 = 75.0;
/// How far above the occlusal plane the condyles sit (mm).
pub const CONDYLE_ABOVE_MM: f32 = 25.0;
/// Slope of the condyles' path, below the horizontal (degrees).
pub const CONDYLAR_GUIDANCE_DEG: f32 = 35.0;
/// Step of the excursion (mm).
pub const STEP_MM: f32 = 0.5;
/// Longest excursion (mm).
pub const MAX_MM: f32 = 6.0;
/// Opposing pairs whose boxes come this near (mm) are followed while the arch closes.
const LIST_MARGIN_MM: f32 = 3.0;
/// Closing travel (mm, at the farthest lower point) after which the pairs are listed again.
const RELIST_MM: f32 = 2.5;

/// Which way the jaw moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ExcursionKind {
    /// Forwards.
    Protrusive,
    /// To the patient's right.
    Right,
    /// To the patient's left.
    Left,
}

impl ExcursionKind {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Protrusive => "protrusive",
            Self::Right => "right",
            Self::Left => "left",
        }
    }
}

/// One step of an excursion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExcursionStep {
    /// How far the jaw has moved (mm).
    pub mm: f32,
    /// Opposing pairs in contact, [upper, lower].
    pub contacts: Vec<[Fdi; 2]>,
    /// `anterior`, `canine`, `group function` or `none`.
    pub guidance: &'static str,
    /// Pairs that interfere, [upper, lower].
    pub interferences: Vec<[Fdi; 2]>,
    /// Least gap between the arches (mm; negative: penetration).
    pub min_gap_mm: f32,
    /// Where the lower arch stands at this step, relative to where its teeth were given.
    #[serde(skip)]
    pub lower_pose: Pose,
    /// How far the lower arch has opened at the incisors since the bite (mm).
    pub opening_mm: f32,
}

/// An excursion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Excursion {
    /// Which.
    pub kind: ExcursionKind,
    /// Its steps, from 0.5 mm to `mm`.
    pub steps: Vec<ExcursionStep>,
}

fn side_of(f: Fdi) -> i32 {
    // +1: the patient's left (quadrants 2 and 3), −1: the right.
    if matches!(f.quadrant(), 2 | 3) { 1 } else { -1 }
}

fn anterior(f: Fdi) -> bool {
    matches!(
        f.kind(),
        ToothKind::CentralIncisor | ToothKind::LateralIncisor | ToothKind::Canine
    )
}

/// The excursion `kind` up to `mm` (at most 6) from the bite where the lower arch stands at
/// `bite` (relative to where the case placed it).
pub fn excursion(teeth: &[Posed], bite: &Pose, kind: ExcursionKind, mm: f32) -> Excursion {
    let tan = CONDYLAR_GUIDANCE_DEG.to_radians().tan();
    let condyle = condyle_seat;
    let incisal = Vec3::new(0.0, 0.0, 20.0);
    let lower = |t: &Posed| t.fdi.arch() == crate::teeth::Arch::Lower;
    // Each lower tooth's vertices at the bite, and which of them each tooth is.
    let lower_points: Vec<Vec<Vec3>> = teeth
        .iter()
        .filter(|t| lower(t))
        .map(|t| {
            let pose = bite.mul(&t.pose);
            t.geometry
                .mesh
                .vertices
                .iter()
                .map(|v| pose.transform_point(*v))
                .collect()
        })
        .collect();
    let mut lower_of = vec![usize::MAX; teeth.len()];
    for (k, (i, _)) in teeth
        .iter()
        .enumerate()
        .filter(|(_, t)| lower(t))
        .enumerate()
    {
        lower_of[i] = k;
    }
    let count = ((mm.clamp(0.0, MAX_MM) / STEP_MM) + 1e-3).floor() as usize;
    let mut steps = Vec::new();
    let mut angle = 0.0f32;
    for k in 1..=count {
        let h = k as f32 * STEP_MM;
        // The slide: the arch's placement before it closes, and the condyles after it.
        let (slide, left, right) = match kind {
            ExcursionKind::Protrusive => {
                let d = Vec3::new(0.0, -h * tan, h);
                (
                    Pose::from_translation(d),
                    condyle(1.0) + d,
                    condyle(-1.0) + d,
                )
            }
            ExcursionKind::Right | ExcursionKind::Left => {
                let s = if kind == ExcursionKind::Left {
                    1.0
                } else {
                    -1.0
                };
                // The mandible turns about the vertical through the working condyle (side s)
                // until the incisal point has moved h sideways; the other condyle travels
                // forwards, drops down its eminence, and the arch tilts about the
                // anteroposterior line through the working condyle.
                let working = condyle(s);
                let spin = Quat::from_rotation_y(s * h / (incisal.z - working.z));
                let turn = Pose::turn_about(working, spin);
                let forward = turn.transform_point(condyle(-s)).z - condyle(-s).z;
                let drop = forward.max(0.0) * tan;
                let tilt = Quat::from_rotation_z(s * (drop / (2.0 * CONDYLE_HALF_WIDTH_MM)).atan());
                let slide = Pose::turn_about(working, tilt).mul(&turn);
                (
                    slide,
                    slide.transform_point(condyle(1.0)),
                    slide.transform_point(condyle(-1.0)),
                )
            }
        };
        let axis = (left - right).normalize();
        // Closing turns the front of the arch up: about +x through the condyles.
        let close = |phi: f32| {
            Pose::turn_about(right, Quat::from_axis_angle(axis, -phi))
                .mul(&slide)
                .mul(bite)
        };
        // How far each lower tooth's points lie from the hinge axis (1 mm spare): bounds their
        // speed per radian, so a pair's gap shrinks by at most its lower tooth's reach per radian
        // of closing; `reach` is the largest, bounding every lower point.
        let tooth_reach: Vec<f32> = lower_points
            .iter()
            .map(|points| {
                points
                    .iter()
                    .map(|p| {
                        let q = slide.transform_point(*p) - right;
                        (q - axis * q.dot(axis)).length()
                    })
                    .fold(0.0f32, f32::max)
                    + 1.0
            })
            .collect();
        let reach = tooth_reach.iter().copied().fold(0.0f32, f32::max);
        // Start open by 1° and close; open further while the slide alone brings the teeth
        // together.
        let mut phi = angle - 1f32.to_radians();
        let listed = |phi: f32| {
            let mut pairs = Tracker::boxed(teeth, &close(phi), LIST_MARGIN_MM);
            pairs.refresh_within(&close(phi), TARGET_GAP_MM, TARGET_GAP_MM);
            pairs
        };
        let mut pairs = listed(phi);
        while pairs.least_measured() < TARGET_GAP_MM && phi > angle - 30f32.to_radians() {
            phi -= 2f32.to_radians();
            pairs = listed(phi);
        }
        // Motion since the pairs were listed: past RELIST_MM a pair beyond the margin could come
        // near, so they are listed again.
        let mut travelled = 0.0f32;
        for _ in 0..400 {
            if travelled > RELIST_MM {
                pairs = Tracker::boxed(teeth, &close(phi), LIST_MARGIN_MM);
                travelled = 0.0;
            }
            let here = close(phi);
            pairs.refresh_within(&here, 2.0 * TARGET_GAP_MM, 2.0 * TARGET_GAP_MM);
            if pairs.least_measured() <= 2.0 * TARGET_GAP_MM || phi > angle + 10f32.to_radians() {
                break;
            }
            // Conservative advancement on the angle, pair by pair. In order of the closing their
            // bounds allow, each pair that could allow less than the least found so far is
            // measured, only as far as twice that least (so the bound it gets will not hold the
            // next, shorter steps back); any bound is safe to step by, the queries only lengthen
            // the step.
            let cap = (LIST_MARGIN_MM - TARGET_GAP_MM - travelled) / reach;
            let allows = |pairs: &Tracker, k: usize| {
                (pairs.bound[k] - TARGET_GAP_MM).max(0.0) / tooth_reach[lower_of[pairs.pairs[k].1]]
            };
            let mut order: Vec<(f32, usize)> = (0..pairs.pairs.len())
                .map(|k| (allows(&pairs, k), k))
                .filter(|(d, _)| *d < cap)
                .collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut dphi = cap;
            for (d, k) in order {
                if d >= dphi {
                    break;
                }
                let limit = TARGET_GAP_MM + 2.0 * dphi * tooth_reach[lower_of[pairs.pairs[k].1]];
                if pairs.last[k].is_none() && !(pairs.fresh[k] && pairs.bound[k] >= limit) {
                    pairs.measure_within(k, &here, limit);
                }
                dphi = dphi.min(allows(&pairs, k));
            }
            phi += dphi;
            let (pair_list, bounds) = (&pairs.pairs, &mut pairs.bound);
            for (&(_, j), b) in pair_list.iter().zip(bounds.iter_mut()) {
                *b -= dphi * tooth_reach[lower_of[j]];
            }
            pairs.forget();
            travelled += dphi * reach;
        }
        pairs.refresh_within(&close(phi), AREA_TOLERANCE_MM, AREA_TOLERANCE_MM);
        angle = phi;
        let placed = close(phi);
        let mut contacts = Vec::new();
        for (k, s) in pairs.last.iter().enumerate() {
            if let Some(s) = s
                && s.signed_gap() <= AREA_TOLERANCE_MM
            {
                let (i, j) = pairs.pairs[k];
                contacts.push([teeth[i].fdi, teeth[j].fdi]);
            }
        }
        let least_gap = pairs.least();
        contacts.sort();
        let working = match kind {
            ExcursionKind::Left => 1,
            ExcursionKind::Right => -1,
            ExcursionKind::Protrusive => 0,
        };
        let interferences: Vec<[Fdi; 2]> = contacts
            .iter()
            .copied()
            .filter(|[u, l]| match kind {
                ExcursionKind::Protrusive => !anterior(*u) || !anterior(*l),
                _ => side_of(*u) != working && side_of(*l) != working,
            })
            .collect();
        let guidance = if contacts.is_empty() {
            "none"
        } else if kind == ExcursionKind::Protrusive {
            if contacts.iter().any(|[u, l]| anterior(*u) && anterior(*l)) {
                "anterior"
            } else {
                "posterior"
            }
        } else {
            let on_working: Vec<&[Fdi; 2]> = contacts
                .iter()
                .filter(|[u, _]| side_of(*u) == working)
                .collect();
            if on_working
                .iter()
                .any(|[u, l]| !anterior(*u) || !anterior(*l))
            {
                "group function"
            } else if on_working
                .iter()
                .any(|[u, _]| u.kind() == ToothKind::Canine)
            {
                "canine"
            } else {
                "anterior"
            }
        };
        let front = |p: &Pose| p.transform_point(incisal);
        steps.push(ExcursionStep {
            min_gap_mm: least_gap,
            lower_pose: placed,
            mm: h,
            contacts,
            guidance,
            interferences,
            opening_mm: front(bite).y - front(&placed).y,
        });
    }
    Excursion { kind, steps }
}
