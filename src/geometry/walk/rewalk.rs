//! The penetration estimate searched again at a nearby placement of the same meshes, from the
//! samples an earlier search found inside ([`InsideSamples::rewalk`]), without walking.
//!
//! Why the result is the walk's: the depth of a point inside a mesh is its distance to the
//! surface, and that distance changes by at most the distance the point moves; a point outside
//! gets in no deeper than it moves. So when every sample of a mesh moves by at most δ relative
//! to the other mesh, a sample that lay inside with a depth of at most u is now at most u + δ
//! deep, and every sample that lay outside is at most δ deep. A depth the result is known to
//! reach (the floor, for instance the last deepest sample's depth at the new placement)
//! settles the rest: samples whose bound is below it cannot be the deepest and are not
//! tested at all; the others are tested by rays and measured as the walk measures them. The
//! bounds are carried to the new placement, which the next search starts from; the bound of
//! the samples not listed grows by δ each time, and once it reaches the floor the search
//! declines (`None`) and the caller walks again.

use glam::{DQuat, DVec3, Vec3};

use super::super::{
    mesh_distance::{Deepest, MeshRef},
    pose::Pose,
};
use super::Penetration;

/// Added to every depth measured (or bounded) at one placement before it bounds a depth at
/// another (mm): covers the single-precision rounding of placing a sample and measuring its
/// distance (about 10⁻⁶ mm at a tooth's size) several times over.
const MEASURED_SLACK_MM: f32 = 2e-5;

/// The samples of each of two meshes found inside the other at one placement, with upper bounds
/// of their depths there: what [`super::mesh_penetration_near_from`] finds on its walk, kept so
/// that the same meshes at a nearby placement need not be walked again ([`Self::rewalk`]).
///
/// A mesh's samples are numbered as the walk takes them: vertex `v` is `v`, the centroid of
/// triangle `t` is the mesh's vertex count plus `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct InsideSamples {
    /// The first mesh's samples inside the second, then the second's inside the first.
    sides: [SideSamples; 2],
}

/// One mesh's samples inside the other.
#[derive(Clone, Debug, PartialEq)]
struct SideSamples {
    /// Where the bounds hold: the mesh's frame placed in the other mesh's frame.
    placed: Placement,
    /// The centre of the mesh's bounding box (its frame) and a distance no vertex lies beyond.
    centre: DVec3,
    reach: f64,
    /// A bound of the depth of every sample not listed (mm).
    rest: f64,
    /// Samples with bounds of their depths (mm).
    samples: Vec<(u32, f32)>,
}

/// A rigid map, in double precision, from one mesh's frame into another's.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Placement {
    rotation: DQuat,
    translation: DVec3,
}

impl Placement {
    /// The mesh posed by `own` seen in the frame of the mesh posed by `other`.
    fn of(own: &Pose, other: &Pose) -> Self {
        let unit = |q: glam::Quat| q.as_dquat().normalize();
        let to_other = unit(other.rotation).inverse();
        Self {
            rotation: to_other * unit(own.rotation),
            translation: to_other * (own.translation - other.translation).as_dvec3(),
        }
    }

    fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }
}

impl InsideSamples {
    /// What the two walks found (`found`: each mesh's samples inside the other with bounds of
    /// their depths) with the meshes at `poses`.
    pub(super) fn walked(
        meshes: [MeshRef; 2],
        poses: [&Pose; 2],
        found: [Vec<(u32, f32)>; 2],
    ) -> Self {
        let [found_a, found_b] = found;
        let side = |s: usize, found: Vec<(u32, f32)>| {
            let bounds = meshes[s].bvh.root_aabb();
            SideSamples {
                placed: Placement::of(poses[s], poses[1 - s]),
                centre: bounds.centre().as_dvec3(),
                reach: 0.5 * (bounds.max - bounds.min).as_dvec3().length(),
                rest: 0.0,
                samples: (found.into_iter())
                    .map(|(s, bound)| (s, bound + MEASURED_SLACK_MM))
                    .collect(),
            }
        };
        Self {
            sides: [side(0, found_a), side(1, found_b)],
        }
    }

    /// The same samples with the two meshes' roles swapped.
    pub fn swapped(&self) -> Self {
        let [a, b] = self.sides.clone();
        Self { sides: [b, a] }
    }

    /// How many samples are listed (both meshes).
    pub fn len(&self) -> usize {
        self.sides.iter().map(|s| s.samples.len()).sum()
    }

    /// How deep (mm) a sample not listed may have got since the samples were found by a walk:
    /// 0 right after a walk, growing by the teeth's relative move at each search from them.
    pub fn rest_mm(&self) -> f64 {
        self.sides[0].rest.max(self.sides[1].rest)
    }

    /// Whether no sample is listed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// [`super::mesh_penetration_near_from`] of the same two meshes at new poses, told the same
    /// `floor` (a depth some sample reaches there, greater than 0), found from these samples:
    /// the same depth, and the same points unless another sample is exactly as deep (see the
    /// module doc). `None` when the meshes moved too far relative to each other since these
    /// samples were found (every sample not listed could then reach the floor), or the floor is
    /// not positive: the caller walks.
    pub fn rewalk(
        &self,
        a: MeshRef,
        pose_a: &Pose,
        b: MeshRef,
        pose_b: &Pose,
        floor: f32,
    ) -> Option<Penetration> {
        if floor.is_nan() || floor <= 0.0 {
            return None;
        }
        let placed = [Placement::of(pose_a, pose_b), Placement::of(pose_b, pose_a)];
        let moved = [0, 1].map(|s| self.sides[s].moved(&placed[s]));
        if (0..2).any(|s| self.sides[s].rest + moved[s] >= floor as f64) {
            return None;
        }
        let (deepest_a, side_a) =
            self.sides[0].rewalk([a, b], [pose_a, pose_b], floor, moved[0], placed[0]);
        let (deepest_b, side_b) =
            self.sides[1].rewalk([b, a], [pose_b, pose_a], floor, moved[1], placed[1]);
        let inside = Self {
            sides: [side_a, side_b],
        };
        Some(Penetration::of(deepest_a, deepest_b, inside))
    }
}

impl SideSamples {
    /// A bound of how far any point of the mesh (within `reach` of `centre`) moves from where
    /// these bounds hold to `to`: the centre's move plus the largest move the turn gives a point
    /// at that distance (2 sin(θ/2) times it, θ the angle turned), with a relative and an
    /// absolute margin far above the rounding of these double-precision sums.
    fn moved(&self, to: &Placement) -> f64 {
        let shift = to
            .apply(self.centre)
            .distance(self.placed.apply(self.centre));
        let turn = to.rotation * self.placed.rotation.inverse();
        let chord = 2.0 * turn.xyz().length() * self.reach;
        (shift + chord) * (1.0 + 1e-9) + 1e-9
    }

    /// The deepest sample of `meshes[0]` inside `meshes[1]` at `poses` (as the walk's
    /// result) and the samples with their new bounds there (`placed`), every sample having
    /// moved by at most `moved` (mm).
    fn rewalk(
        &self,
        [a, b]: [MeshRef; 2],
        [pose_a, pose_b]: [&Pose; 2],
        floor: f32,
        moved: f64,
        placed: Placement,
    ) -> ((f32, Vec3, Vec3), SideSamples) {
        let mut deepest = Deepest::new(pose_a, b, pose_b).with_floor(floor);
        let vertices = a.mesh.vertices.len() as u32;
        let samples = (self.samples.iter())
            .map(|&(s, bound)| {
                // Rounded up: single precision holds the sum to a relative 6·10⁻⁸.
                let bound = ((bound as f64 + moved) * (1.0 + 1e-7)) as f32;
                if !deepest.can_exceed(bound) {
                    return (s, bound);
                }
                let local = if s < vertices {
                    a.mesh.vertices[s as usize]
                } else {
                    let [p, q, r] = a.mesh.triangle((s - vertices) as usize);
                    (p + q + r) / 3.0
                };
                let p = deepest.place(local);
                let now = if deepest.inside(p) {
                    deepest.depth(p, bound)
                } else {
                    0.0
                };
                (s, now + MEASURED_SLACK_MM)
            })
            .collect();
        let side = SideSamples {
            placed,
            centre: self.centre,
            reach: self.reach,
            rest: self.rest + moved,
            samples,
        };
        (deepest.result(), side)
    }
}

/// The search from known samples checked on real teeth (the teeth sit above this layer; the
/// layer check's test-block rule covers this use).
#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{
        crossing_triangles, mesh_penetration, mesh_penetration_near_from, sample_depth,
    };
    use crate::teeth::{Arch, ToothGeometry, ToothKind, ToothResolution};
    use glam::Quat;

    /// The walk of two teeth at these poses from their meeting triangles, told `floor`.
    fn walk([a, b]: [&ToothGeometry; 2], pose_a: &Pose, pose_b: &Pose, floor: f32) -> Penetration {
        let (near_a, near_b) = crossing_triangles(a.mesh_ref(), pose_a, b.mesh_ref(), pose_b, 1e-4);
        mesh_penetration_near_from(a.near(&near_a), pose_a, b.near(&near_b), pose_b, floor)
    }

    /// The search from known samples when it answered (it must find the walk's overlap), else
    /// the walk; `counts` counts each (found again, walked).
    fn next(
        again: Option<Penetration>,
        walked: Penetration,
        counts: &mut [u32; 2],
        step: usize,
    ) -> Penetration {
        match again {
            Some(again) => {
                let found = (again.depth, again.points, again.on_b);
                let walk = (walked.depth, walked.points, walked.on_b);
                assert_eq!(found, walk, "step {step}");
                counts[0] += 1;
                again
            }
            None => {
                counts[1] += 1;
                walked
            }
        }
    }

    /// The depth the deepest sample of `p` reaches at new poses, less a margin (as the exact
    /// query's floor).
    fn floor_of([a, b]: [&ToothGeometry; 2], p: &Penetration, poses: [&Pose; 2]) -> f32 {
        let side = usize::from(p.on_b);
        let local = poses[side].inverse().transform_point(p.points[side]);
        let other = [b, a][side].mesh_ref();
        sample_depth(local, poses[side], other, poses[1 - side]).map_or(0.0, |d| d - 1e-4)
    }

    /// From the samples a walk found inside, the overlap at nearby placements is found again
    /// without walking: the same depth and points as the walk there (whose depth is the whole
    /// meshes'), over many small moves and turns of one tooth, a move of nothing, and
    /// jumps. The search declines once the samples not listed could reach the floor, and for
    /// no floor; the bound of how far the samples moved holds for every vertex.
    #[test]
    fn known_samples_find_the_walks_overlap() {
        let res = ToothResolution { vertices: 1500 };
        let a = ToothGeometry::procedural(Arch::Lower, ToothKind::FirstMolar, res);
        let b = ToothGeometry::procedural(Arch::Lower, ToothKind::SecondPremolar, res);
        let teeth = [&a, &b];
        let reach = (a.mesh.vertices.iter()).fold(f32::MIN, |m, v| m.max(v.x))
            - (b.mesh.vertices.iter()).fold(f32::MAX, |m, v| m.min(v.x));
        let pose_a = Pose::new(Quat::from_rotation_z(0.2), Vec3::new(1.0, -2.0, 3.0));
        // Side by side along a's x axis, pushed 0.3 mm into each other.
        let base = Pose::new(
            pose_a.rotation,
            pose_a.transform_point(Vec3::new(reach - 0.3, 0.1, 0.0)),
        );
        let mut n = crate::geometry::test_numbers(17);
        let mut random = |scale: f32| Vec3::new(n(), n(), n()) * 2.0 * scale;
        let mut known = walk(teeth, &pose_a, &base, 0.0);
        assert!(known.depth > 0.2, "{}", known.depth);
        let mut pose_b = base;
        let (mut counts, mut turned) = ([0; 2], 0.0f32);
        for step in 0..60 {
            let last = pose_b;
            pose_b = match step {
                0 => pose_b,
                // Jumps.
                s if s % 20 == 19 => Pose::new(base.rotation, base.translation + random(0.15)),
                // A turn of up to about 0.6° about an axis through neither tooth.
                _ => {
                    let axis = random(1.0).normalize();
                    let turn = Quat::from_axis_angle(axis, random(0.005).x);
                    let pivot = base.translation + random(10.0);
                    let q = turn * last.rotation;
                    let t = pivot + turn * (last.translation - pivot) + random(0.004);
                    Pose::new(q.normalize(), t)
                }
            };
            turned = turned.max(last.rotation.angle_between(pose_b.rotation));
            let floor = floor_of(teeth, &known, [&pose_a, &pose_b]);
            let walked = walk(teeth, &pose_a, &pose_b, floor);
            let whole = mesh_penetration(a.mesh_ref(), &pose_a, b.mesh_ref(), &pose_b);
            assert_eq!(walked.depth, whole.0, "step {step}");

            // The bound of the move holds for every vertex of each tooth in the other's frame.
            for (s, [own, other], [own_then, other_then]) in [
                (0, [&pose_a, &pose_b], [&pose_a, &last]),
                (1, [&pose_b, &pose_a], [&last, &pose_a]),
            ] {
                let side = &known.inside.sides[s];
                let moved = side.moved(&Placement::of(own, other));
                let (now, then) = (
                    Placement::of(own, other),
                    Placement::of(own_then, other_then),
                );
                let largest = (teeth[s].mesh.vertices.iter())
                    .map(|v| now.apply(v.as_dvec3()).distance(then.apply(v.as_dvec3())))
                    .fold(0.0, f64::max);
                assert!(largest <= moved, "step {step}: {largest} > {moved}");
                assert!(
                    moved <= 3.0 * largest + 1e-6,
                    "step {step}: {moved} ≫ {largest}"
                );
            }

            let again = known
                .inside
                .rewalk(a.mesh_ref(), &pose_a, b.mesh_ref(), &pose_b, floor);
            known = next(again, walked, &mut counts, step);
        }
        assert!(
            counts[0] >= 40 && counts[1] >= 3,
            "{counts:?} (found again, walked)"
        );
        assert!(turned > 2e-3, "largest turn {turned} rad");
        for floor in [0.0, -1.0, f32::NAN] {
            let again = (known.inside).rewalk(a.mesh_ref(), &pose_a, b.mesh_ref(), &pose_b, floor);
            assert!(again.is_none(), "floor {floor}");
        }
    }
    /// A part of one mesh that lay outside the other, and so was not listed, gets in and
    /// becomes the deepest while the listed deepest stays where it was: a plank resting one end
    /// 0.2 mm deep in a block, tipped about that end so that its other end sinks past it. The
    /// samples not listed could reach the floor before they do, so the search declines in time,
    /// and every result is the walk's.
    #[test]
    fn a_part_that_gets_in_is_not_missed() {
        use crate::geometry::VertexStars;
        use crate::geometry::mesh_distance::tests::refs;
        use crate::geometry::trimesh::tests::cuboid;

        let block = refs(&cuboid(Vec3::splat(-5.0), Vec3::splat(5.0)));
        let plank = refs(&cuboid(Vec3::new(0.0, -0.5, 0.0), Vec3::new(6.0, 0.5, 1.0)));
        let stars = [&block, &plank].map(|m| VertexStars::of(&m.0));
        let (a, b) = [&block, &plank]
            .map(|m| MeshRef {
                mesh: &m.0,
                bvh: &m.1,
            })
            .into();
        let walk = |pose_b: &Pose, floor: f32| {
            let (near_a, near_b) = crossing_triangles(a, &Pose::IDENTITY, b, pose_b, 1e-4);
            let side = |mesh, stars, near| crate::geometry::NearContact { mesh, stars, near };
            mesh_penetration_near_from(
                side(a, &stars[0], &near_a),
                &Pose::IDENTITY,
                side(b, &stars[1], &near_b),
                pose_b,
                floor,
            )
        };
        // The plank's near lower edge 0.2 mm into the block's top; its far end 0.1 mm above.
        let tipped = |step: usize| {
            let angle = -(0.3f32 / 6.0).asin() + 0.002 * step as f32;
            Pose::new(Quat::from_rotation_y(angle), Vec3::new(-3.0, 0.0, 4.8))
        };
        let mut known = walk(&tipped(0), 0.0);
        assert!((known.depth - 0.2).abs() < 1e-4, "{}", known.depth);
        let mut counts = [0; 2];
        for step in 1..=40 {
            let pose_b = tipped(step);
            let side = usize::from(known.on_b);
            let poses = [Pose::IDENTITY, pose_b];
            let local = [Pose::IDENTITY, tipped(step - 1)][side]
                .inverse()
                .transform_point(known.points[side]);
            let floor = sample_depth(local, &poses[side], [b, a][side], &poses[1 - side])
                .map_or(0.0, |d| d - 1e-4);
            let walked = walk(&pose_b, floor);
            let again = known.inside.rewalk(a, &Pose::IDENTITY, b, &pose_b, floor);
            known = next(again, walked, &mut counts, step);
        }
        // The far end sank 0.48 mm from 0.1 mm above the block: now 0.38 mm deep.
        let far = tipped(40).transform_point(Vec3::new(6.0, 0.0, 0.0));
        assert!(
            known.depth > 0.35 && known.points[1].x > 2.5,
            "{known:?} (far end {far})"
        );
        assert!(
            counts[0] >= 20 && counts[1] >= 1,
            "{counts:?} (found again, walked)"
        );
    }
}
