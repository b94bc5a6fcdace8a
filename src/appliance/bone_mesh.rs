//! Bone meshes named by a case (a CBCT segmentation's maxilla and mandible) in place of the
//! alveolar envelope ([`super::bone`]).
//!
//! Segmentations give the bone either with the sockets filled (the roots inside the solid) or
//! hollow (the teeth cut out: each root in a cavity, the socket's wall a fraction of a
//! millimetre away). Every root point keeps the side of the bone's surface it started on: a
//! tooth is held by its arch's mesh when at least half its root points lie inside the solid
//! (filled sockets; those points are held) or, failing that, at least half lie outside it within
//! [`SOCKET_MM`] of its surface (hollow sockets; those are held). Otherwise the segmentation does
//! not cover the tooth and the envelope holds it. Root points not held (outside a filled bone: a
//! dehiscence or fenestration, or a plate the segmentation thinned away) have no bone to resist
//! them; they are counted per tooth ([`BoneMeshes::uncovered`]).
//!
//! A held point within the asked tolerance of the surface on its own side, or across it, is a
//! contact at the nearest surface point: its depth the distance across (negative on its own
//! side), its inward direction back to its own side. Only the walls of the alveolus hold a root:
//! where the surface there faces within 45° of up or down (the crest, which follows an extruding
//! tooth; the basal bone, the sinus floor, a socket's fundus) it does not. A contact's plate is
//! buccal when the root presses towards the cheeks or lips (the arch axis's outward normal),
//! lingual otherwise.
//!
//! Guarantee: nearest points exact; the side by the parity of ray crossings within the
//! tolerance (retried when a ray grazes an edge), and beyond it by the nearest triangle's
//! outward normal, up to [`FAR_MM`] away (a point farther across the surface than that is not
//! seen). A point nearer the crest than the wall is judged by the crest and not held.

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

/// Fraction of a tooth's root points that must lie on the bone's side (filled sockets) or in its
/// sockets (hollow ones) for the mesh to hold the tooth.
pub const COVERED_FRACTION: f32 = 0.5;
/// A root point outside the bone's solid this near its surface is in a hollow socket (mm).
pub const SOCKET_MM: f32 = 1.0;
/// How far across the surface a point is still seen (mm).
pub const FAR_MM: f32 = 2.0;
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
    /// Per tooth held by a mesh, each root point (in the order given): `None` not held,
    /// `Some(true)` held inside the solid, `Some(false)` held outside it (in a hollow socket).
    held: BTreeMap<Fdi, Vec<Option<bool>>>,
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
            let world: Vec<Vec3> = t.roots.iter().map(|p| t.pose.transform_point(*p)).collect();
            let inside: Vec<bool> = world
                .iter()
                .map(|w| point_inside_mesh(bone.at(), *w))
                .collect();
            let enough =
                |n: usize| !world.is_empty() && n as f32 >= COVERED_FRACTION * world.len() as f32;
            if enough(inside.iter().filter(|v| **v).count()) {
                held.insert(t.fdi, inside.iter().map(|v| v.then_some(true)).collect());
                continue;
            }
            let socket: Vec<Option<bool>> = world
                .iter()
                .zip(&inside)
                .map(|(w, i)| {
                    let near = closest_point_and_triangle_within(bone.at(), *w, SOCKET_MM);
                    (!i && near.is_some()).then_some(false)
                })
                .collect();
            if enough(socket.iter().flatten().count()) {
                held.insert(t.fdi, socket);
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
            .map(|(f, h)| (*f, h.iter().filter(|v| v.is_none()).count(), h.len()))
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
        for (p, side) in roots.iter().zip(held) {
            let Some(own) = *side else {
                continue;
            };
            let w = pose.transform_point(*p);
            let Some((q, d, tri)) =
                closest_point_and_triangle_within(bone.at(), w, tolerance.max(FAR_MM))
            else {
                continue;
            };
            let [a, b, c] = bone.mesh.triangle(tri as usize);
            let outward = (b - a).cross(c - a).normalize_or_zero();
            let inside = if d <= tolerance {
                point_inside_mesh(bone.at(), w)
            } else {
                (w - q).dot(outward) < 0.0
            };
            let across = inside != own;
            if !across && d > tolerance {
                continue;
            }
            // Back to the point's own side: away from the surface on it, towards it across.
            let inward = if d > 1e-5 {
                if across { (q - w) / d } else { (w - q) / d }
            } else if own {
                -outward
            } else {
                outward
            };
            if inward.y.abs() > MOST_VERTICAL || inward == Vec3::ZERO {
                continue;
            }
            let (_, arch_out) = bone.axis.locate(Vec2::new(w.x, w.z));
            let plate = if -inward.dot(Vec3::new(arch_out.x, 0.0, arch_out.y)) >= 0.0 {
                Plate::Buccal
            } else {
                Plate::Lingual
            };
            out.push(PlateContact {
                point: w,
                inward,
                depth: if across { d } else { -d },
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

    /// The contacts (within 0.5 mm) of tooth `fdi` moved `dz` mm labially, front to back.
    fn shifted(bone: &BoneMeshes, fdi: Fdi, roots: &[Vec3], dz: f32) -> Vec<PlateContact> {
        let pose = Pose::from_translation(Vec3::Z * dz);
        let mut c = bone.contacts(fdi, &pose, roots, 0.5);
        c.sort_by(|a, b| a.point.z.total_cmp(&b.point.z));
        c
    }

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
        let at = |dz: f32| shifted(&bone, fdi, &roots, dz);
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
        // Hollow sockets: the same tooth in a cavity cut out of the bone, its walls 0.3 mm from
        // the root labially and lingually; the root points keep to the cavity.
        let outer = TriMesh::cuboid(
            Vec3::new(-10.0, -20.0, zc - 10.0),
            Vec3::new(10.0, 0.0, zc + 5.0),
        );
        let cavity = TriMesh::cuboid(
            Vec3::new(-2.0, -15.0, zc - 1.0),
            Vec3::new(2.0, -1.0, zc + 1.0),
        );
        let base = outer.vertices.len() as u32;
        let hollow = Arc::new(TriMesh::new(
            outer
                .vertices
                .iter()
                .chain(&cavity.vertices)
                .copied()
                .collect(),
            outer
                .triangles
                .iter()
                .copied()
                .chain(
                    cavity
                        .triangles
                        .iter()
                        .map(|[a, b, c]| [base + a, base + c, base + b]),
                )
                .collect(),
        ));
        let socket = [
            Vec3::new(0.0, -8.0, zc + 0.7),
            Vec3::new(0.0, -8.0, zc - 0.7),
            Vec3::new(0.0, -12.0, zc + 0.2),
        ];
        let teeth = [RootedTooth {
            fdi,
            pose: Pose::IDENTITY,
            roots: &socket,
        }];
        let bone = BoneMeshes::new(&[None, Some(hollow)], &teeth, [&curve, &curve]).unwrap();
        assert_eq!(bone.uncovered(), vec![(fdi, 0, 3)]);
        let at = |dz: f32| shifted(&bone, fdi, &socket, dz);
        let c = at(0.0);
        assert_eq!(c.len(), 2, "{c:?}");
        assert_eq!((c[0].plate, c[1].plate), (Plate::Lingual, Plate::Buccal));
        assert!((c[1].depth + 0.3).abs() < 1e-4 && c[1].inward.distance(-Vec3::Z) < 1e-5);
        // Pushed 0.2 mm into the labial wall, and 1.5 mm into it (beyond the tolerance).
        for (dz, depth) in [(0.5, 0.2), (1.8, 1.5)] {
            let c = at(dz);
            let labial = c
                .iter()
                .filter(|c| c.plate == Plate::Buccal)
                .max_by(|a, b| a.depth.total_cmp(&b.depth))
                .unwrap();
            assert!((labial.depth - depth).abs() < 1e-4, "{dz}: {labial:?}");
            assert!(labial.inward.distance(-Vec3::Z) < 1e-5, "{labial:?}");
        }
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
