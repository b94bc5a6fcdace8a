//! Roots kept out of each other: the generated roots of neighbouring scanned crowns are turned
//! apart and shortened, within anatomical limits, until they no longer reach into each other.
//!
//! Each round measures every pair of teeth of one arch whose boxes overlap with the exact
//! mesh–mesh query. A pair inside each other by more than [`CROSSING_TOLERANCE_MM`] at a point
//! deeper (along a tooth's root axis) than [`ROOT_ZONE_MM`] below the tooth's deepest crown
//! vertex is a root crossing for that tooth: its root turns [`TILT_STEP_DEG`] further away from the other tooth
//! (about its cervical centre, up to [`MAX_TILT_DEG`] in all), and once turned that far, loses
//! [`SHORTEN_STEP`] of its template length (up to [`MAX_SHORTEN`]). The turned teeth are closed
//! again, for at most [`ROUNDS`] rounds. Where crowns themselves overlap in the scan, nothing is
//! changed: the crowns are the patient's. What is left shows in `inspect`'s neighbour gaps, and
//! each tooth's turn and shortening in its root report.

use glam::Vec3;

use super::{ImportError, Prepared, RepairLimits, RootGuide, prepare_or_rebuild};
use crate::geometry::{MeshRef, Pose, TriMesh, TriangleBvh, mesh_separation};
use crate::teeth::fdi::Fdi;

/// Penetration (mm) below which two teeth are taken as touching, not crossing.
pub const CROSSING_TOLERANCE_MM: f32 = 0.005;
/// Depth (mm) below a tooth's deepest crown vertex from which a crossing is in its root.
pub const ROOT_ZONE_MM: f32 = 0.5;
/// Turn per round (degrees).
pub const TILT_STEP_DEG: f32 = 2.0;
/// Largest turn (degrees) of a root away from its neighbours.
pub const MAX_TILT_DEG: f32 = 10.0;
/// Share of the template's root length taken off per round once the turn is used up.
pub const SHORTEN_STEP: f32 = 0.06;
/// Largest share of the root length taken off.
pub const MAX_SHORTEN: f32 = 0.24;
/// Most rounds.
pub const ROUNDS: usize = 8;

/// Turns apart and shortens the roots of `teeth` (their inputs, results and guides; results that
/// failed are left alone) until no two of one arch cross in their roots. Returns the rounds run.
pub fn keep_roots_apart(
    fdis: &[Fdi],
    inputs: &[TriMesh],
    results: &mut [Result<Prepared, ImportError>],
    guides: &mut [RootGuide],
    limits: &RepairLimits,
) -> usize {
    let n = fdis.len();
    for round in 0..ROUNDS {
        let bvhs: Vec<Option<TriangleBvh>> = crate::parallel::parallel_map(results, |r| {
            r.as_ref().ok().map(|p| TriangleBvh::build(&p.mesh))
        });
        let boxes: Vec<Option<crate::geometry::Aabb>> = results
            .iter()
            .map(|r| r.as_ref().ok().map(|p| p.mesh.aabb()))
            .collect();
        let mut pairs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if fdis[i].arch() != fdis[j].arch() {
                    continue;
                }
                if let (Some(a), Some(b)) = (&boxes[i], &boxes[j])
                    && a.distance_squared(b) == 0.0
                {
                    pairs.push((i, j));
                }
            }
        }
        let crossings: Vec<Option<(Vec3, f32)>> =
            crate::parallel::parallel_map(&pairs, |&(i, j)| {
                let (Ok(a), Ok(b), Some(ba), Some(bb)) =
                    (&results[i], &results[j], &bvhs[i], &bvhs[j])
                else {
                    return None;
                };
                let s = mesh_separation(
                    MeshRef {
                        mesh: &a.mesh,
                        bvh: ba,
                    },
                    &Pose::IDENTITY,
                    MeshRef {
                        mesh: &b.mesh,
                        bvh: bb,
                    },
                    &Pose::IDENTITY,
                );
                (s.signed_gap() < -CROSSING_TOLERANCE_MM)
                    .then(|| ((s.point_a + s.point_b) * 0.5, -s.signed_gap()))
            });
        let mut turned = vec![false; n];
        for (&(i, j), crossing) in pairs.iter().zip(&crossings) {
            let Some((at, _)) = crossing else {
                continue;
            };
            for (k, other) in [(i, j), (j, i)] {
                let (Ok(p), Ok(q)) = (&results[k], &results[other]) else {
                    continue;
                };
                let (Some(c), Some(a)) = (p.cervical, p.apical) else {
                    continue;
                };
                let templated = p
                    .repairs
                    .root
                    .as_ref()
                    .is_some_and(|r| r.kind == "template");
                // Below the crown's deepest point: the crown and the collar hanging from its
                // margin are the scan's, only the root's body can move.
                let deepest = inputs[k]
                    .vertices
                    .iter()
                    .map(|v| (*v - c).dot(a))
                    .fold(0.0, f32::max);
                if !templated || (*at - c).dot(a) < deepest + ROOT_ZONE_MM {
                    continue;
                }
                // Away from the other tooth, across this root's axis.
                let from = q.cervical.unwrap_or_else(|| q.mesh.aabb().centre());
                let away = c - from;
                let away = (away - a * away.dot(a)).normalize_or_zero();
                let axis = a.cross(away).normalize_or_zero();
                let g = &mut guides[k];
                if g.turned_apart + 1e-4 < MAX_TILT_DEG.to_radians() && axis != Vec3::ZERO {
                    let step = TILT_STEP_DEG
                        .to_radians()
                        .min(MAX_TILT_DEG.to_radians() - g.turned_apart);
                    g.tilt += axis * step;
                    g.turned_apart += step;
                    turned[k] = true;
                } else if g.shorten + 1e-4 < MAX_SHORTEN {
                    g.shorten = (g.shorten + SHORTEN_STEP).min(MAX_SHORTEN);
                    turned[k] = true;
                }
            }
        }
        let again: Vec<usize> = (0..n).filter(|&k| turned[k]).collect();
        if again.is_empty() {
            return round;
        }
        let redone = crate::parallel::parallel_map(&again, |&k| {
            prepare_or_rebuild(&inputs[k], fdis[k], limits, guides[k])
        });
        for (k, r) in again.into_iter().zip(redone) {
            // A tooth that fails once turned keeps its earlier root.
            if r.is_ok() {
                results[k] = r;
            }
        }
    }
    ROUNDS
}
