//! The bite: the mandible closed about its condyles onto the upper arch under a bite force, until
//! it is stable (`orthosim occlusion --settle`).
//!
//! Quasi-static settle. The mandible (the lower arch) is one rigid body under a bite force of
//! [`BITE_FORCE_N`] along the occlusal direction (+y) through the centroid of its crown centres,
//! held by its condyles and by the teeth it meets. Each condyle rests in its fossa at
//! [`condyle_seat`] (the excursion model's condyles): the fossa's roof, the posterior slope of the
//! articular eminence (at the condylar guidance angle) and its medial wall stop it going up, back
//! or towards the midline, so a seated condyle can only turn in place, drop, or slide forwards
//! and down the eminence; each stop is a contact of the condyle with the skull while the condyle
//! is within [`CONTACT_MM`] of it. So the mandible closes about the hinge through its condyles,
//! and slides within the condylar guidance where the teeth push it.
//!
//! Every opposing pair of teeth whose boxes come near carries a lower bound on its gap; each
//! iteration measures with the exact mesh distance the pairs whose bound is near contact (queries
//! bounded to [`SETTLE_LIMIT_MM`]: a farther pair only learns that it is farther); pairs within
//! [`CONTACT_MM`] are contacts, each pushing along its normal (from the upper tooth's closest point
//! to the lower's). The mandible's motion is the bite force's, less what the contacts and the
//! condyles take (the contact solve of the PDL model on two bodies: the skull fixed, the mandible
//! with a mobility of 1 mm per N in translation and 1/R² in rotation, R = [`TURN_RADIUS_MM`]). It
//! moves by conservative advancement: a step never longer than the smallest gap of the pairs not
//! in contact, less [`TARGET_GAP_MM`], divided by the fastest speed any point of the arch can
//! have; pairs in contact are checked afterwards and a step that brings any pair closer than
//! [`TARGET_GAP_MM`] / 2 is halved. So the arches never interpenetrate (the exact stage's
//! guarantee, tested). The bite is stable when the contacts and condyles take the whole force (the
//! motion left is under [`STILL_MM`] per unit step): the line of the bite force then lies inside
//! their support. The loads on the condyles are reported.
//!
//! Arches that start interpenetrating (as segmentations of real patients do) are first opened
//! about the hinge until every pair is at least [`TARGET_GAP_MM`] apart; that opening (at the
//! incisors) is reported. A settle asked to start open turns the mandible open about the hinge
//! until its crown centroid has dropped by the opening asked.
//!
//! Why a bite cannot become stable is said: the arches do not meet within the travel, or the
//! lower arch keeps sliding off its contacts after [`MAX_ITERATIONS`].

use glam::{DMat3, DVec3, Quat, Vec2, Vec3};
use serde::Serialize;

use super::{
    excursion::{
        CONDYLAR_GUIDANCE_DEG, CONDYLE_ABOVE_MM, CONDYLE_BEHIND_MM, CONDYLE_HALF_WIDTH_MM,
    },
    measures::{Posed, occlusal_contacts},
};
use crate::{
    geometry::{Mat6, Pose, halves, mesh_separation, mesh_separation_within, vec6},
    movement::pdl::{ContactRow, PdlBody, SolveParams, solve_contacts},
    teeth::{Arch, Fdi, ToothKind},
};

/// The bite force of a settle (N): a moderate clench.
pub const BITE_FORCE_N: f64 = 100.0;

/// Where the condyle of `side` (+1: the patient's left, −1: the right) sits in its fossa, in the
/// frame where the case places the lower arch.
pub fn condyle_seat(side: f32) -> Vec3 {
    Vec3::new(
        side * CONDYLE_HALF_WIDTH_MM,
        CONDYLE_ABOVE_MM,
        -CONDYLE_BEHIND_MM,
    )
}

/// The directions in which the skull pushes a seated condyle of `side`: down and back off the
/// eminence's posterior slope, forwards off the fossa's back, and outwards off its medial wall.
fn condyle_stops(side: f32) -> [DVec3; 3] {
    let (sin, cos) = f64::from(CONDYLAR_GUIDANCE_DEG).to_radians().sin_cos();
    [
        DVec3::new(0.0, -cos, -sin),
        DVec3::Z,
        DVec3::new(f64::from(side), 0.0, 0.0),
    ]
}

/// Loads on the condyles (N).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CondyleLoads {
    /// The patient's left condyle.
    pub left: f32,
    /// The right condyle.
    pub right: f32,
}

/// Pairs this close (mm) are in contact.
pub const CONTACT_MM: f32 = 0.02;
/// Gap (mm) the advancement aims at before contacts take the force.
pub const TARGET_GAP_MM: f32 = 0.005;
/// Radius (mm) turning the lower arch's rotations into millimetres (about the arch's size).
pub const TURN_RADIUS_MM: f64 = 25.0;
/// Motion per unit step (mm) below which the bite is stable.
pub const STILL_MM: f64 = 1e-4;
/// Most iterations of a settle.
pub const MAX_ITERATIONS: usize = 400;
/// Surface within this distance (mm) of the opposing tooth counts towards a contact's area.
pub const AREA_TOLERANCE_MM: f32 = 0.05;
/// A settle measures opposing pairs exactly only when they are this near (mm); a farther pair's
/// bound is this distance. It limits the settle's step to about this much motion.
pub const SETTLE_LIMIT_MM: f32 = 1.0;

/// One opposing pair in the bite.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiteContact {
    /// Upper tooth.
    pub upper: Fdi,
    /// Lower tooth.
    pub lower: Fdi,
    /// Upper tooth's surface within 0.05 mm of the lower tooth (mm²).
    pub area_mm2: f32,
    /// Exact gap (mm; negative: penetration).
    pub min_gap_mm: f32,
}

/// Contacting teeth per side (upper teeth with a contact).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SideCounts {
    /// The patient's left (quadrant 2).
    pub left: usize,
    /// The patient's right (quadrant 1).
    pub right: usize,
}

/// The bite of a case.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bite {
    /// Case name.
    pub case: String,
    /// Whether the contacts hold the bite force (see the module doc).
    pub stable: bool,
    /// Why not, when not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why: Option<String>,
    /// Deepest exact penetration between the arches (mm, 0 when none).
    pub max_penetration_mm: f32,
    /// Least gap between the upper and lower incisors (mm).
    pub incisor_gap_mm: f32,
    /// Contacting upper teeth per side.
    pub contact_teeth: SideCounts,
    /// Pairs in contact (within 0.05 mm).
    pub contacts: Vec<BiteContact>,
    /// How far the settle moved the lower arch: travel of its crown centroid (mm) and turn
    /// (degrees); zero without a settle.
    pub lower_travel_mm: f32,
    /// Turn of the lower arch (degrees).
    pub lower_turn_deg: f32,
    /// Iterations of the settle.
    pub iterations: usize,
    /// How far the arches were opened about the hinge before the settle because they started
    /// interpenetrating (mm, at the lower incisors; 0 when they did not).
    pub opened_mm: f32,
    /// Loads the condyles carry in the bite (N, under [`BITE_FORCE_N`]; 0 without a settle).
    pub condyles: CondyleLoads,
    /// Where the lower arch ended, relative to where the case placed it.
    #[serde(skip)]
    pub lower_pose: Pose,
    /// The jaw's excursion from this bite, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub excursion: Option<super::excursion::Excursion>,
}

fn upper(t: &Posed) -> bool {
    t.fdi.arch() == Arch::Upper
}

/// The opposing pairs a settle or an excursion may bring together, each with a lower bound on its
/// gap: measured exactly when it may be near, otherwise its last measure (or the distance of the
/// two teeth's boxes) less how far any lower point has moved since. The bound is conservative, so
/// a pair left unmeasured cannot be in contact.
pub(super) struct Tracker<'a, 'b> {
    teeth: &'b [Posed<'a>],
    pub(super) pairs: Vec<(usize, usize)>,
    pub(super) bound: Vec<f32>,
    /// The exact separation at the current pose, when measured there.
    pub(super) last: Vec<Option<crate::geometry::MeshSeparation>>,
    /// Whether `bound` was found at the current pose (exactly, or as a query's limit).
    pub(super) fresh: Vec<bool>,
}

impl<'a, 'b> Tracker<'a, 'b> {
    /// Pairs whose boxes come within `margin` at `moved`, none measured: each bound is the
    /// distance between the two teeth's boxes (0 for boxes that overlap).
    pub(super) fn boxed(teeth: &'b [Posed<'a>], moved: &Pose, margin: f32) -> Self {
        let boxes: Vec<_> = teeth
            .iter()
            .map(|t| {
                let p = if upper(t) { t.pose } else { moved.mul(&t.pose) };
                t.geometry
                    .mesh
                    .aabb()
                    .transformed(&glam::Mat3::from_quat(p.rotation), p.translation)
            })
            .collect();
        let mut tracker = Self {
            teeth,
            pairs: Vec::new(),
            bound: Vec::new(),
            last: Vec::new(),
            fresh: Vec::new(),
        };
        for (i, _) in teeth.iter().enumerate().filter(|(_, t)| upper(t)) {
            for (j, _) in teeth.iter().enumerate().filter(|(_, t)| !upper(t)) {
                let d = boxes[i].distance_squared(&boxes[j]).sqrt();
                if d <= margin {
                    tracker.pairs.push((i, j));
                    tracker.bound.push(d);
                    tracker.last.push(None);
                    tracker.fresh.push(false);
                }
            }
        }
        tracker
    }

    /// Measures pair `k` at `moved` if its gap is `limit` or less; otherwise its bound becomes the
    /// limit (a query that opens only the parts of the two hierarchies within the limit).
    pub(super) fn measure_within(&mut self, k: usize, moved: &Pose, limit: f32) {
        let (u, l) = (&self.teeth[self.pairs[k].0], &self.teeth[self.pairs[k].1]);
        let s = mesh_separation_within(
            u.geometry.mesh_ref(),
            &u.pose,
            l.geometry.mesh_ref(),
            &moved.mul(&l.pose),
            limit,
        );
        self.bound[k] = s.map_or(limit.max(self.bound[k]), |s| s.signed_gap());
        self.last[k] = s;
        self.fresh[k] = true;
    }

    /// Makes sure of every pair whose bound is `near` or less, at `moved`: measured exactly if its
    /// gap is `limit` (at least `near`) or less, otherwise its bound raised to `limit`.
    pub(super) fn refresh_within(&mut self, moved: &Pose, near: f32, limit: f32) {
        for k in 0..self.pairs.len() {
            let known = self.last[k].is_some() || self.fresh[k] && self.bound[k] >= near;
            if self.bound[k] <= near && !known {
                self.measure_within(k, moved, limit.max(near));
            }
        }
    }

    /// The lower arch moved (the caller lowered the bounds): the last measures are stale.
    pub(super) fn forget(&mut self) {
        self.last.fill(None);
        self.fresh.fill(false);
    }

    /// The least gap measured exactly at the current pose (infinite if none is).
    pub(super) fn least_measured(&self) -> f32 {
        self.last
            .iter()
            .flatten()
            .map(|s| s.signed_gap())
            .fold(f32::INFINITY, f32::min)
    }

    /// The least bound.
    pub(super) fn least(&self) -> f32 {
        self.bound.iter().copied().fold(f32::INFINITY, f32::min)
    }

    /// Tries `next`, reached with no lower point moving more than `delta`: measures the pairs
    /// that could come near; true (and the bounds updated) when none comes closer than `floor`
    /// (or than it already was, if closer).
    fn try_step(&mut self, next: &Pose, delta: f32, floor: f32) -> bool {
        let mut measured = Vec::new();
        for k in 0..self.pairs.len() {
            if self.bound[k] - delta <= 2.0 * CONTACT_MM {
                let (u, l) = (&self.teeth[self.pairs[k].0], &self.teeth[self.pairs[k].1]);
                let s = mesh_separation_within(
                    u.geometry.mesh_ref(),
                    &u.pose,
                    l.geometry.mesh_ref(),
                    &next.mul(&l.pose),
                    SETTLE_LIMIT_MM,
                );
                // A pair already closer than the floor may not get closer still.
                if s.is_some_and(|s| s.signed_gap() < floor.min(self.bound[k] - 1e-6)) {
                    return false;
                }
                measured.push((k, s));
            }
        }
        for b in &mut self.bound {
            *b -= delta;
        }
        self.forget();
        for (k, s) in measured {
            self.bound[k] = s.map_or(SETTLE_LIMIT_MM, |s| s.signed_gap());
            self.last[k] = s;
            self.fresh[k] = true;
        }
        true
    }
}

/// The bite of `teeth` as they stand (`settle` false) or with the mandible closed about its
/// condyles onto the upper arch from `opening_mm` apart (see the module doc).
pub fn bite(case: &str, teeth: &[Posed], settle: bool, opening_mm: f32) -> Bite {
    let lower: Vec<&Posed> = teeth.iter().filter(|t| !upper(t)).collect();
    let centre = lower
        .iter()
        .map(|t| t.pose.transform_point(t.geometry.frame.crown_centre))
        .sum::<Vec3>()
        / lower.len().max(1) as f32;
    let lower_points = || {
        lower.iter().flat_map(|t| {
            t.geometry
                .mesh
                .vertices
                .iter()
                .map(|v| t.pose.transform_point(*v))
        })
    };
    // Farthest a lower-arch point lies from the centre: bounds a point's speed under a turn.
    let reach = lower_points()
        .map(|p| p.distance(centre))
        .fold(0.0f32, f32::max) as f64;
    // The hinge: turning by φ about the axis through the seated condyles (positive opens).
    let right = condyle_seat(-1.0);
    let hinge = |phi: f32| Pose::turn_about(right, Quat::from_axis_angle(Vec3::X, phi));
    let from_hinge = |p: Vec3| Vec2::new(p.y - right.y, p.z - right.z).length();
    let incisal = lower_points()
        .max_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap_or(centre);
    let mut moved = Pose::IDENTITY;
    let mut opened_mm = 0.0;
    let listed = |moved: &Pose| {
        let mut pairs = Tracker::boxed(teeth, moved, opening_mm.max(0.0) + 3.0);
        pairs.refresh_within(moved, f32::INFINITY, SETTLE_LIMIT_MM);
        pairs
    };
    if settle {
        moved = hinge(opening_mm.max(0.0) / from_hinge(centre).max(1.0));
    }
    let mut pairs = listed(&moved);
    // Interpenetrating arches are opened along the hinge until every pair is clear.
    if settle && pairs.least_measured() < TARGET_GAP_MM {
        let least_at = |phi: f32| {
            let pose = hinge(phi).mul(&moved);
            let mut pairs = Tracker::boxed(teeth, &pose, 0.0);
            pairs.refresh_within(&pose, f32::INFINITY, TARGET_GAP_MM);
            pairs.least_measured()
        };
        let (mut shut, mut open) = (0.0f32, 0.25f32.to_radians());
        while least_at(open) < TARGET_GAP_MM && open < 20f32.to_radians() {
            (shut, open) = (open, 2.0 * open);
        }
        for _ in 0..24 {
            let mid = 0.5 * (shut + open);
            if least_at(mid) < TARGET_GAP_MM {
                shut = mid;
            } else {
                open = mid;
            }
        }
        moved = hinge(open).mul(&moved);
        opened_mm = open * from_hinge(incisal);
        pairs = listed(&moved);
    }
    let mut iterations = 0;
    let mut why = None;
    let mut stable = false;
    let mut condyles = CondyleLoads::default();
    let mobility = {
        let mut m = Mat6::identity();
        for k in 3..6 {
            m.0[k][k] = 1.0 / (TURN_RADIUS_MM * TURN_RADIUS_MM);
        }
        m
    };
    let params = SolveParams {
        rate: 1.0,
        threshold_kpa: 0.0,
        saturation_kpa: f64::INFINITY,
        tolerance: 1e-12,
        max_sweeps: 2_000,
    };
    let travel_limit = opening_mm.max(0.0) + 10.0;
    let start = moved.transform_point(centre);
    loop {
        pairs.refresh_within(&moved, 2.0 * CONTACT_MM, SETTLE_LIMIT_MM);
        let c = moved.transform_point(centre).as_dvec3();
        let mut contacts: Vec<ContactRow> = pairs
            .last
            .iter()
            .flatten()
            .filter(|s| s.signed_gap() <= CONTACT_MM)
            .filter_map(|s| {
                let n = (s.point_b - s.point_a).as_dvec3().try_normalize()?;
                Some(ContactRow {
                    a: 0,
                    b: 1,
                    point: ((s.point_a + s.point_b) * 0.5).as_dvec3(),
                    normal: n,
                    bias: 0.0,
                })
            })
            .collect();
        let touching = contacts.len();
        // The condyles' stops (only while settling: as placed, the bite is the teeth's).
        let mut sides = Vec::new();
        if settle {
            for side in [1.0f32, -1.0] {
                let seat = condyle_seat(side);
                let at = moved.transform_point(seat);
                for normal in condyle_stops(side) {
                    if (at - seat).as_dvec3().dot(normal) <= f64::from(CONTACT_MM) {
                        contacts.push(ContactRow {
                            a: 0,
                            b: 1,
                            point: at.as_dvec3(),
                            normal,
                            bias: 0.0,
                        });
                        sides.push(side);
                    }
                }
            }
        }
        let bodies = [
            PdlBody {
                centre: DVec3::ZERO,
                compliance: Mat6::ZERO,
                area: 1.0,
                mean_spring: 1.0,
                applied: [0.0; 6],
                appliance_stiffness: None,
            },
            PdlBody {
                centre: c,
                compliance: mobility,
                area: 1.0,
                mean_spring: 1.0,
                applied: vec6(DVec3::Y, DVec3::ZERO),
                appliance_stiffness: None,
            },
        ];
        let solve = solve_contacts(&bodies, &contacts, None, &params);
        let (u, w) = halves(&solve.twists[1]);
        let speed = u.length() + w.length() * reach;
        if touching > 0 && speed < STILL_MM {
            stable = true;
            // Each condyle's load: the force its stops exert together.
            let mut on = [DVec3::ZERO; 2];
            for ((f, row), side) in solve.forces[touching..]
                .iter()
                .zip(&contacts[touching..])
                .zip(&sides)
            {
                on[usize::from(*side < 0.0)] += row.normal * *f * BITE_FORCE_N;
            }
            condyles = CondyleLoads {
                left: on[0].length() as f32,
                right: on[1].length() as f32,
            };
            break;
        }
        if !settle {
            why = Some(if touching == 0 {
                "the arches do not touch".to_owned()
            } else {
                "the contacts do not hold the bite force: the lower arch would slide or tilt"
                    .to_owned()
            });
            break;
        }
        if iterations >= MAX_ITERATIONS {
            why = Some(format!(
                "the lower arch still slides after {MAX_ITERATIONS} steps ({touching} contacts)"
            ));
            break;
        }
        iterations += 1;
        // Conservative advancement against the pairs not in contact; the rest checked after.
        let free_gap = pairs
            .bound
            .iter()
            .copied()
            .filter(|g| *g > CONTACT_MM)
            .fold(f32::INFINITY, f32::min);
        let mut step = if free_gap.is_finite() {
            ((free_gap - TARGET_GAP_MM) as f64 / speed).max(0.0)
        } else {
            1.0 / speed
        };
        // Sliding on contacts: small steps, at most 0.05 mm at the fastest point.
        if touching > 0 {
            step = step.min(0.05 / speed);
        }
        let mut accepted = false;
        for _ in 0..30 {
            let turn =
                DMat3::from_axis_angle(w.try_normalize().unwrap_or(DVec3::Y), w.length() * step);
            let q = glam::DQuat::from_mat3(&turn).as_quat();
            let delta = Pose::new(q, (c + u * step - turn * c).as_vec3());
            let next = delta.mul(&moved);
            if pairs.try_step(&next, (speed * step) as f32, TARGET_GAP_MM * 0.5) {
                moved = next;
                accepted = true;
                break;
            }
            step *= 0.5;
        }
        let risen = start.distance(moved.transform_point(centre));
        if !accepted || step * speed < 1e-7 {
            why = Some(
                "the lower arch is wedged: no step along the bite force keeps the arches apart"
                    .to_owned(),
            );
            break;
        }
        if touching == 0 && risen > travel_limit {
            why = Some(format!(
                "the arches do not meet within {travel_limit:.0} mm of closing"
            ));
            break;
        }
    }
    let posed: Vec<Posed> = teeth
        .iter()
        .map(|t| Posed {
            fdi: t.fdi,
            geometry: t.geometry,
            pose: if upper(t) { t.pose } else { moved.mul(&t.pose) },
        })
        .collect();
    let incisor = |f: Fdi| {
        matches!(
            f.kind(),
            ToothKind::CentralIncisor | ToothKind::LateralIncisor
        )
    };
    // Every pair within the area tolerance, measured exactly; the incisors at any gap.
    let mut listed = Tracker::boxed(teeth, &moved, AREA_TOLERANCE_MM);
    for k in 0..listed.pairs.len() {
        let (i, j) = listed.pairs[k];
        let limit = if incisor(teeth[i].fdi) && incisor(teeth[j].fdi) {
            f32::INFINITY
        } else {
            AREA_TOLERANCE_MM
        };
        listed.measure_within(k, &moved, limit);
    }
    let seps: Vec<_> = listed
        .pairs
        .iter()
        .zip(&listed.last)
        .filter_map(|(&(i, j), s)| s.map(|s| (i, j, s)))
        .collect();
    let mut contacts = Vec::new();
    let mut max_penetration = 0.0f32;
    let mut incisor_gap = f32::INFINITY;
    for (i, j, s) in &seps {
        let gap = s.signed_gap();
        max_penetration = max_penetration.max(-gap);
        let (u, l) = (&posed[*i], &posed[*j]);
        if incisor(u.fdi) && incisor(l.fdi) {
            incisor_gap = incisor_gap.min(gap);
        }
        if gap <= AREA_TOLERANCE_MM {
            let pair = [*u, *l];
            let area = occlusal_contacts(&pair, AREA_TOLERANCE_MM)
                .first()
                .map_or(0.0, |c| c.area_mm2);
            contacts.push(BiteContact {
                upper: u.fdi,
                lower: l.fdi,
                area_mm2: area,
                min_gap_mm: gap,
            });
        }
    }
    if !incisor_gap.is_finite() {
        // Incisors too far apart for their boxes to meet: measure them directly.
        for u in posed.iter().filter(|t| upper(t) && incisor(t.fdi)) {
            for l in posed.iter().filter(|t| !upper(t) && incisor(t.fdi)) {
                let s = mesh_separation(
                    u.geometry.mesh_ref(),
                    &u.pose,
                    l.geometry.mesh_ref(),
                    &l.pose,
                );
                incisor_gap = incisor_gap.min(s.signed_gap());
            }
        }
    }
    let mut side = SideCounts::default();
    let mut counted: Vec<Fdi> = Vec::new();
    for c in &contacts {
        if counted.contains(&c.upper) {
            continue;
        }
        counted.push(c.upper);
        if c.upper.quadrant() == 2 {
            side.left += 1;
        } else {
            side.right += 1;
        }
    }
    let angle = 2.0 * moved.rotation.w.abs().min(1.0).acos();
    let shift = if settle {
        moved.transform_point(centre).distance(start)
    } else {
        0.0
    };
    Bite {
        case: case.to_owned(),
        stable,
        why,
        max_penetration_mm: max_penetration,
        incisor_gap_mm: incisor_gap,
        contact_teeth: side,
        contacts,
        lower_travel_mm: shift,
        lower_turn_deg: angle.to_degrees(),
        iterations,
        opened_mm,
        condyles,
        lower_pose: moved,
        excursion: None,
    }
}
