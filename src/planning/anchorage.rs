//! Class I where the opposing arch allows: the sagittal relations of canines and first molars,
//! and the choice of which teeth close each arch's spaces.
//!
//! An arch with spaces (extraction spaces, spacing) can close them by retracting its anterior
//! teeth or by bringing its posterior teeth forward; the share taken by the anterior teeth is its
//! anchorage. [`Anchorage::Auto`](super::limits::Anchorage) tries the shares in
//! [`AUTO_SHARES`] for each such arch, sets both arches up with every combination, and keeps the
//! one whose canines and first molars are nearest class I ([`Relations::class_error`]), among
//! those whose incisors keep their overjet: not under [`OVERJET_MIN_MM`] (or under what the
//! least retraction gives, when that is already less), not past [`OVERJET_MAX_MM`] (or past the
//! least retraction's). A tie goes to the least retraction. An arch without spaces has one way to
//! stand, so its relation to the opposing arch is reported, not changed: moving a whole arch
//! sagittally (distalization, intermaxillary elastics) is not part of the automatic set-up.

use std::collections::BTreeMap;

use serde::Serialize;

use super::target::{ArchSetup, TargetIpr};
use crate::geometry::Pose;
use crate::teeth::{
    Dentition, Fdi,
    arch::{canine_relation, incisor_relation, molar_relation},
};

/// The shares of an arch's spaces closed by its anterior teeth that the automatic anchorage
/// tries.
pub const AUTO_SHARES: [f32; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// Overjet the automatic anchorage keeps at least (mm).
pub const OVERJET_MIN_MM: f32 = 1.0;
/// Overjet the automatic anchorage keeps at most (mm).
pub const OVERJET_MAX_MM: f32 = 4.0;
/// Cost of retraction in the choice (per whole arch's spaces), so that a tie goes to the least.
const RETRACTION_TIE: f32 = 0.05;

/// Canine and first-molar relations and the overjet, as the teeth stand (mm; see
/// `teeth::arch::occlusion` for each measure's sign: 0 is class I, positive class II).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Relations {
    /// First molars (right, left); None where one is missing.
    pub molar_mm: [Option<f32>; 2],
    /// Canines (right, left); None where a canine or the lower tooth distal to it is missing.
    pub canine_mm: [Option<f32>; 2],
    /// Mean overjet of the central incisors (at the height of the upper incisal edge, or to the
    /// lower incisor's most labial point where nothing of it is at that height); None where a
    /// central incisor is missing.
    pub overjet_mm: Option<f32>,
}

impl Relations {
    /// Measures the relations with the teeth of `d` at `poses` (teeth not in `poses` where they
    /// stand).
    pub fn measure(d: &Dentition, poses: &BTreeMap<Fdi, Pose>) -> Self {
        let at = |n: i64| {
            let f = Fdi::new(n).ok()?;
            let t = d.tooth(f).filter(|t| !t.extracted)?;
            Some((
                t.geometry.as_ref(),
                poses.get(&f).copied().unwrap_or(t.pose),
            ))
        };
        let molar_mm = [(16, 46), (26, 36)].map(|(u, l)| {
            let ((gu, pu), (gl, pl)) = (at(u)?, at(l)?);
            Some(molar_relation((gu, &pu), (gl, &pl)))
        });
        let canine_mm = [(13, 43, [44, 45]), (23, 33, [34, 35])].map(|(u, l, distal)| {
            let ((gu, pu), (gl, pl)) = (at(u)?, at(l)?);
            let (gd, pd) = distal.iter().find_map(|&n| at(n))?;
            Some(canine_relation((gu, &pu), (gl, &pl), (gd, &pd)))
        });
        let jets: Vec<f32> = [(11, 41), (21, 31)]
            .iter()
            .filter_map(|&(u, l)| {
                let ((gu, pu), (gl, pl)) = (at(u)?, at(l)?);
                incisor_relation((gu, &pu), (gl, &pl)).0.or_else(|| {
                    // No lower labial surface at the height of the upper edge (an open bite or
                    // a deep overjet): to the lower incisor's most labial point instead.
                    let edge = gu.cusp_tips.first().map(|&c| pu.transform_point(c))?;
                    let labial = gl
                        .mesh
                        .vertices
                        .iter()
                        .map(|&v| pl.transform_point(v).z)
                        .fold(f32::NEG_INFINITY, f32::max);
                    Some(edge.z - labial)
                })
            })
            .collect();
        let overjet_mm = (!jets.is_empty()).then(|| jets.iter().sum::<f32>() / jets.len() as f32);
        Self {
            molar_mm,
            canine_mm,
            overjet_mm,
        }
    }

    /// How far canines and first molars are from class I: the sum of the measured relations'
    /// sizes (mm).
    pub fn class_error(&self) -> f32 {
        self.molar_mm
            .iter()
            .chain(&self.canine_mm)
            .flatten()
            .map(|v| v.abs())
            .sum()
    }
}

/// One way of setting up an arch: its teeth's target poses, the report and the IPR it needs.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The arch's teeth.
    pub fdis: Vec<Fdi>,
    /// Their target poses.
    pub poses: Vec<Pose>,
    /// The report.
    pub setup: ArchSetup,
    /// The IPR it needs.
    pub ipr: Vec<TargetIpr>,
}

impl Candidate {
    fn apply(&self, poses: &mut BTreeMap<Fdi, Pose>) {
        for (f, p) in self.fdis.iter().zip(&self.poses) {
            poses.insert(*f, *p);
        }
    }
}

/// The candidates of each arch kept (see the module doc): an index into each list (a missing
/// arch has an empty list and gets 0), and the relations the choice gives.
pub fn choose(
    d: &Dentition,
    poses: &BTreeMap<Fdi, Pose>,
    upper: &[Candidate],
    lower: &[Candidate],
) -> ([usize; 2], Relations) {
    let nu = upper.len().max(1);
    let nl = lower.len().max(1);
    let measure = |i: usize, j: usize| {
        let mut p = poses.clone();
        upper.get(i).into_iter().for_each(|c| c.apply(&mut p));
        lower.get(j).into_iter().for_each(|c| c.apply(&mut p));
        Relations::measure(d, &p)
    };
    let reference = measure(0, 0);
    let mut best = ([0, 0], reference, f32::INFINITY);
    for i in 0..nu {
        for j in 0..nl {
            let r = if (i, j) == (0, 0) {
                reference
            } else {
                measure(i, j)
            };
            if let (Some(jet), Some(least)) = (r.overjet_mm, reference.overjet_mm)
                && (jet < OVERJET_MIN_MM.min(least) - 1e-3
                    || jet > OVERJET_MAX_MM.max(least) + 1e-3)
            {
                continue;
            }
            let share = |c: Option<&Candidate>| c.map_or(0.0, |c| c.setup.retraction_share);
            let cost =
                r.class_error() + RETRACTION_TIE * (share(upper.get(i)) + share(lower.get(j)));
            if cost < best.2 {
                best = ([i, j], r, cost);
            }
        }
    }
    (best.0, best.1)
}
