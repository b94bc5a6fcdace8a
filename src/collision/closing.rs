//! Whether a contact closes: for a contact the narrow phase reported, per method, whether its
//! teeth approach each other ([`approaching`]) and whether their overlap deepens over the step
//! ([`deepens`]). A response that blocks only closing contacts lets teeth that touch move apart or
//! slide along each other.
//!
//! | method | approaching | deepens |
//! |---|---|---|
//! | circles | the circle centres get closer over the step (by more than [`APPROACH_MM`]) | never |
//! | spheres | some overlapping leaf pair's centres get closer over the step (by more than [`APPROACH_MM`]) | the deepest leaf-sphere overlap at the end exceeds the deepest at the start by more than [`DEEPEN_MM`] |
//! | continuous | some overlapping leaf pair's centres approach at time t of the step (half the rate of change of their squared distance, in f64, below −[`APPROACH_MM2`]) | as for spheres, with the end's overlapping leaves found afresh |
//! | exact | the contact points' relative velocity along the normal, at time t, is below −[`APPROACH_MM`] per step | the meshes overlap at the end more deeply than the contact's depth by more than [`DEEPEN_MM`] (the overlap the query found on the way when the contact carries it for these end poses, else searched here) |
//!
//! [`closes_in`] combines them for a contact that touches at the start of the step (for the
//! discrete methods: at its end): whether it should stop its teeth.
//!
//! The tolerances keep rounding noise of a tooth standing still, or sliding exactly along a
//! neighbour, from counting as closing.

use glam::{DVec3, Vec3};

use super::{
    motion::Motion,
    narrow_phase::{Body, Method, PairContact, spheres},
};
use crate::geometry::{Pose, crossing_triangles, mesh_penetration_near};

/// A distance must fall by more than this (mm per step) to count as approaching.
pub const APPROACH_MM: f32 = 1e-7;
/// The continuous test's threshold on half the rate of change of a squared distance (mm² per
/// step, in f64).
pub const APPROACH_MM2: f64 = 1e-12;
/// An overlap must grow by more than this (mm) to count as deepening.
pub const DEEPEN_MM: f32 = 1e-6;

/// Whether the contact's features approach each other at time `t` of the step under the bodies'
/// motions (see the module doc for each method's test). `contact` is what `method` reported for
/// `a` and `b`.
pub fn approaching(method: Method, a: &Body, b: &Body, contact: &PairContact, t: f32) -> bool {
    let (ma, mb) = (&a.motion, &b.motion);
    match method {
        Method::Circles => {
            let d0 = a
                .circle
                .centre_at(&ma.start)
                .distance(b.circle.centre_at(&mb.start));
            let d1 = a
                .circle
                .centre_at(&ma.end)
                .distance(b.circle.centre_at(&mb.end));
            d1 < d0 - APPROACH_MM
        }
        Method::Spheres => contact.leaf_pairs.iter().any(|&(u, v)| {
            let (cu, cv) = (
                a.shape.tree.spheres[u as usize].centre,
                b.shape.tree.spheres[v as usize].centre,
            );
            let d0 = ma
                .start
                .transform_point(cu)
                .distance(mb.start.transform_point(cv));
            let d1 = ma
                .end
                .transform_point(cu)
                .distance(mb.end.transform_point(cv));
            d1 < d0 - APPROACH_MM
        }),
        Method::Continuous => contact.leaf_pairs.iter().any(|&(u, v)| {
            let (cu, cv) = (
                a.shape.tree.spheres[u as usize].centre.as_dvec3(),
                b.shape.tree.spheres[v as usize].centre.as_dvec3(),
            );
            let at = |m: &Motion, p: DVec3, end: bool| {
                let pose = if end { &m.end } else { &m.start };
                pose.rotation.as_dquat() * p + pose.translation.as_dvec3()
            };
            let a0 = at(mb, cv, false) - at(ma, cu, false);
            let a1 = at(mb, cv, true) - at(ma, cu, true);
            let d = a1 - a0;
            a0.dot(d) + d.length_squared() * (t as f64) < -APPROACH_MM2
        }),
        Method::Exact => {
            let n = contact.normal;
            let velocity = |m: &Motion, p: Vec3| {
                let local = m.at(t).inverse().transform_point(p);
                m.end.transform_point(local) - m.start.transform_point(local)
            };
            let rel = velocity(mb, contact.points[1]) - velocity(ma, contact.points[0]);
            rel.dot(n) < -APPROACH_MM
        }
    }
}

/// Distance (mm) within which triangles count as meeting the other surface in [`end_gap`]: far
/// above the rounding of a triangle pair's closest points, far below any depth that matters.
const MEETING_MM: f32 = 1e-4;

/// Minus the depth of the meshes' overlap at the end of the step, the same estimate as
/// [`crate::geometry::mesh_separation`]'s, found from where the surfaces meet: the walk over the
/// part of each surface inside the other ([`mesh_penetration_near`], which also finds a solid
/// wholly inside the other) instead of sampling both whole meshes. 0 when they do not overlap,
/// whatever their gap (only an overlap can deepen).
fn end_gap(a: &Body, b: &Body) -> f32 {
    let (ga, gb) = (&a.shape.geometry, &b.shape.geometry);
    let (pa, pb) = (&a.motion.end, &b.motion.end);
    let (near_a, near_b) = crossing_triangles(ga.mesh_ref(), pa, gb.mesh_ref(), pb, MEETING_MM);
    let (depth, _, _) = mesh_penetration_near(ga.near(&near_a), pa, gb.near(&near_b), pb);
    -depth
}

/// For a contact already touching at the start of the step: whether the overlap is deeper at the
/// end of the step than at its start (exact: the meshes overlap at the end more than the
/// contact's depth, taken from [`PairContact::end_overlap`] when it was found for these end
/// poses; continuous and spheres: the deepest overlap of leaf spheres grows, or
/// appears; circles: never). This catches what the contact points' velocities miss under
/// rotation: other parts of the surfaces closing in.
pub fn deepens(method: Method, a: &Body, b: &Body, contact: &PairContact) -> bool {
    let (ma, mb) = (&a.motion, &b.motion);
    match method {
        Method::Exact => {
            let end = match &contact.end_overlap {
                Some(e) if e.poses == [ma.end, mb.end] => -e.depth_mm,
                _ => end_gap(a, b),
            };
            end < 0.0 && end < -contact.depth_mm - DEEPEN_MM
        }
        Method::Continuous | Method::Spheres => {
            let depth = |pairs: &[(u32, u32)], pa: &Pose, pb: &Pose| {
                pairs
                    .iter()
                    .map(|&(u, v)| {
                        let (su, sv) = (
                            a.shape.tree.spheres[u as usize],
                            b.shape.tree.spheres[v as usize],
                        );
                        su.radius + sv.radius
                            - pa.transform_point(su.centre)
                                .distance(pb.transform_point(sv.centre))
                    })
                    .fold(f32::NEG_INFINITY, f32::max)
            };
            // Every overlapping leaf pair at each end of the step. The discrete contact already
            // lists those at the end; the continuous search reports only those it needed.
            fn at<'a>(body: &Body<'a>, pose: Pose) -> Body<'a> {
                Body {
                    motion: Motion::still(pose),
                    ..*body
                }
            }
            let end = if method == Method::Spheres {
                depth(&contact.leaf_pairs, &ma.end, &mb.end)
            } else {
                match spheres::query(&at(a, ma.end), &at(b, mb.end)) {
                    Some(c) => depth(&c.leaf_pairs, &ma.end, &mb.end),
                    None => return false,
                }
            };
            let start = spheres::query(&at(a, ma.start), &at(b, mb.start))
                .map_or(f32::NEG_INFINITY, |c| {
                    depth(&c.leaf_pairs, &ma.start, &mb.start)
                });
            end > start + DEEPEN_MM
        }
        Method::Circles => false,
    }
}

/// For a contact that touches at the start of the step (for the discrete methods, which see only
/// the end pose: at its end), whether its teeth close in on each other, so that a response should
/// stop them:
/// - circles: the circles got closer over the step;
/// - spheres and continuous: the leaf-sphere overlap deepens. Leaf spheres of neighbours overlap
///   at rest and some pair of them approaches under almost any motion, so only a deepening
///   overlap counts (sliding along a neighbour is free);
/// - exact: the contact points approach (at the contact's time), or the meshes overlap deeper.
pub fn closes_in(method: Method, a: &Body, b: &Body, contact: &PairContact) -> bool {
    match method {
        Method::Circles => approaching(method, a, b, contact, 1.0),
        Method::Spheres | Method::Continuous => deepens(method, a, b, contact),
        Method::Exact => {
            approaching(method, a, b, contact, contact.time_of_contact)
                || deepens(method, a, b, contact)
        }
    }
}
