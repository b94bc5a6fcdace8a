//! Bone meshes named by a case (a CBCT segmentation's maxilla and mandible) in place of the
//! alveolar envelope ([`super::bone`]).
//!
//! A tooth is held by its arch's bone mesh when most of its root points lie inside the mesh as
//! placed (otherwise the segmentation does not cover it and the envelope holds it). Root points
//! already outside the bone as placed (a dehiscence or fenestration, or a segmentation that
//! thinned the labial plate away) are not held: there is no bone there to resist them; they are
//! counted per tooth ([`BoneMeshes::uncovered`]). Every held root point within the asked
//! tolerance of the bone's surface, or outside it, is a contact with the surface at its nearest
//! point: its depth the distance outside (negative inside), its inward direction towards the
//! nearest point (away from it inside). Only the walls of the alveolus hold a root: where the
//! surface faces up or down (within 45° of vertical: the crest, which follows an extruding
//! tooth, and the basal bone and sinus floor) it does not. A contact's plate is buccal when the
//! wall faces the cheeks or lips (the arch axis's outward normal), lingual otherwise.
//!
//! Guarantee: exact for the mesh as given (nearest points exact; inside by the parity of ray
//! crossings, retried when a ray grazes an edge).

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::bone::{Axis, Plate, PlateContact, RootedTooth};
use crate::{
    geometry::{
        MeshRef, Pose, TriMesh, TriangleBvh, closest_point_and_triangle_within, point_inside_mesh,
    },
    teeth::{Arch, Fdi, arch::ArchCurve},
};

/// Fraction of a tooth's root points that must lie inside its arch's bone mesh for the mesh to
/// hold the tooth.
pub const COVERED_FRACTION: f32 = 0.5;
/// A wall whose normal is nearer vertical than this (its vertical component's size) does not
/// hold a root: the crest and the basal bone.
const MOST_VERTICAL: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// One arch's bone.
#[derive(Clone, Debug)]
struct ArchBone {
    arch: Arch,
    mesh: Arc<TriMesh>,
    bvh: Arc<TriangleBvh>,
    axis: Axis,
}

impl ArchBone {
    fn at(&self) -> MeshRef<'_> {
        MeshRef {
            mesh: &self.mesh,
            bvh: &self.bvh,
        }
    }
}

/// The case's bone meshes and which root points of which teeth they hold.
#[derive(Clone, Debug)]
pub struct BoneMeshes {
    arches: Vec<ArchBone>,
    /// Per tooth held by a mesh: which of its root points (in the order given) are held.
    held: BTreeMap<Fdi, Vec<bool>>,
}

impl BoneMeshes {
    /// The meshes `meshes` (upper, lower; world frame, closed) about the arch curves `curves`,
    /// for `teeth` as placed. None when no tooth is held by a mesh.
    pub fn new(
        meshes: &[Option<Arc<TriMesh>>; 2],
        teeth: &[RootedTooth],
        curves: [&ArchCurve; 2],
    ) -> Option<Self> {
        let mut arches = Vec::new();
        for (k, arch) in [Arch::Upper, Arch::Lower].into_iter().enumerate() {
            if let Some(mesh) = &meshes[k] {
                arches.push(ArchBone {
                    arch,
                    bvh: Arc::new(TriangleBvh::build(mesh)),
                    mesh: mesh.clone(),
                    axis: Axis::along(arch, curves[k]),
                });
            }
        }
        let mut held = BTreeMap::new();
        for t in teeth {
            let Some(bone) = arches.iter().find(|a| a.arch == t.fdi.arch()) else {
                continue;
            };
            let inside: Vec<bool> = t
                .roots
                .iter()
                .map(|p| point_inside_mesh(bone.at(), t.pose.transform_point(*p)))
                .collect();
            let count = inside.iter().filter(|v| **v).count();
            if !inside.is_empty() && count as f32 >= COVERED_FRACTION * inside.len() as f32 {
                held.insert(t.fdi, inside);
            }
        }
        (!held.is_empty()).then_some(Self { arches, held })
    }

    /// True when a bone mesh holds tooth `fdi`.
    pub fn holds(&self, fdi: Fdi) -> bool {
        self.held.contains_key(&fdi)
    }

    /// Per tooth held by a mesh: how many of its root points lay outside the bone as placed (not
    /// held), and how many it has.
    pub fn uncovered(&self) -> Vec<(Fdi, usize, usize)> {
        self.held
            .iter()
            .map(|(f, h)| (*f, h.iter().filter(|v| !**v).count(), h.len()))
            .collect()
    }

    /// Every held point of `roots` (tooth frame) of tooth `fdi` at `pose` that lies outside the
    /// bone's walls or within `tolerance` of them (mm), with its depth (see the module doc);
    /// none for a tooth no mesh holds.
    pub fn contacts(
        &self,
        fdi: Fdi,
        pose: &Pose,
        roots: &[Vec3],
        tolerance: f32,
    ) -> Vec<PlateContact> {
        let (Some(bone), Some(held)) = (
            self.arches.iter().find(|a| a.arch == fdi.arch()),
            self.held.get(&fdi),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (p, _) in roots.iter().zip(held).filter(|(_, h)| **h) {
            let w = pose.transform_point(*p);
            let Some((q, d, tri)) = closest_point_and_triangle_within(bone.at(), w, tolerance)
            else {
                continue;
            };
            let inside = point_inside_mesh(bone.at(), w);
            let inward = if d > 1e-5 {
                if inside { (w - q) / d } else { (q - w) / d }
            } else {
                // On the surface: against the face's outward normal.
                let [a, b, c] = bone.mesh.triangle(tri as usize);
                -(b - a).cross(c - a).normalize_or_zero()
            };
            if inward.y.abs() > MOST_VERTICAL || inward == Vec3::ZERO {
                continue;
            }
            let (_, outward) = bone.axis.locate(Vec2::new(w.x, w.z));
            let plate = if -inward.dot(Vec3::new(outward.x, 0.0, outward.y)) >= 0.0 {
                Plate::Buccal
            } else {
                Plate::Lingual
            };
            out.push(PlateContact {
                point: w,
                inward,
                depth: if inside { -d } else { d },
                plate,
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::arch::ArchLayout;

    #[test]
    fn walls_hold_the_roots_they_cover_and_the_crest_and_missing_bone_do_not() {
        let curve = ArchCurve::new(&ArchLayout::default().lower);
        let zc = curve.at(0.0).0.y;
        let mesh = Arc::new(TriMesh::cuboid(
            Vec3::new(-10.0, -20.0, zc - 10.0),
            Vec3::new(10.0, 0.0, zc + 1.0),
        ));
        let fdi = Fdi::new(41).unwrap();
        let roots = [
            Vec3::new(0.0, -10.0, zc + 0.8), // 0.2 inside the labial wall
            Vec3::new(0.0, -10.0, zc + 1.3), // outside as placed: no bone there
            Vec3::new(0.0, -0.2, zc - 5.0),  // just under the crest
            Vec3::new(0.0, -10.0, zc - 5.0), // deep in the bone
            Vec3::new(0.0, -10.0, zc - 9.8), // 0.2 inside the lingual wall
        ];
        let teeth = [RootedTooth {
            fdi,
            pose: Pose::IDENTITY,
            roots: &roots,
        }];
        let bone = BoneMeshes::new(&[None, Some(mesh)], &teeth, [&curve, &curve]).unwrap();
        assert!(bone.holds(fdi) && !bone.holds(Fdi::new(11).unwrap()));
        assert_eq!(bone.uncovered(), vec![(fdi, 1, 5)]);
        let at = |dz: f32| {
            let pose = Pose::from_translation(Vec3::Z * dz);
            let mut c = bone.contacts(fdi, &pose, &roots, 0.5);
            c.sort_by(|a, b| a.point.z.total_cmp(&b.point.z));
            c
        };
        // As placed: the labial and lingual walls, 0.2 mm inside each; not the crest, not the
        // point outside, not the deep one.
        let c = at(0.0);
        assert_eq!(c.len(), 2, "{c:?}");
        assert_eq!((c[0].plate, c[1].plate), (Plate::Lingual, Plate::Buccal));
        assert!((c[0].depth + 0.2).abs() < 1e-4 && (c[1].depth + 0.2).abs() < 1e-4);
        assert!(c[0].inward.distance(Vec3::Z) < 1e-5 && c[1].inward.distance(-Vec3::Z) < 1e-5);
        // On the wall (the nearest point is the point itself) and past it.
        let on = at(0.2);
        assert!(on[1].depth.abs() < 1e-4 && on[1].inward.distance(-Vec3::Z) < 1e-5);
        let past = at(0.5);
        let labial = past.iter().find(|c| c.plate == Plate::Buccal).unwrap();
        assert!((labial.depth - 0.3).abs() < 1e-4, "{labial:?}");
        assert!(labial.inward.distance(-Vec3::Z) < 1e-5);
        // A tooth mostly outside the mesh is left to the envelope.
        let out = [Vec3::new(0.0, -10.0, zc + 3.0); 3];
        let stray = [RootedTooth {
            fdi,
            pose: Pose::IDENTITY,
            roots: &out,
        }];
        let mesh = Arc::new(TriMesh::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0)));
        assert!(BoneMeshes::new(&[None, Some(mesh)], &stray, [&curve, &curve]).is_none());
    }
}
