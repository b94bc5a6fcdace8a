//! `ToothGeometry`: a tooth's mesh, its triangle hierarchy and its anatomical frame, shared by every
//! tooth of the same type (mirrored teeth included) through an `Arc`.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::{
    anatomy::{ToothAnatomy, anatomy},
    fdi::{Arch, ToothKind},
    frame::{CentreParameters, ToothFrame},
    memo::Memo,
    shape::{ToothResolution, ToothSolid},
};
use crate::geometry::{MeshRef, NearContact, TriMesh, TriangleBvh, VertexStars};

/// The geometry of one tooth in its local frame (see [`super::shape`] for the frame).
#[derive(Debug)]
pub struct ToothGeometry {
    /// Arch the shape was made for.
    pub arch: Arch,
    /// Tooth type.
    pub kind: ToothKind,
    /// Dimensions it was made from.
    pub anatomy: ToothAnatomy,
    /// Closed, outward-wound surface (mm).
    pub mesh: TriMesh,
    /// Triangle hierarchy for exact queries.
    pub bvh: TriangleBvh,
    /// The triangles around each vertex (for walks over the surface from a contact).
    pub stars: VertexStars,
    /// Data computed from the mesh.
    pub frame: ToothFrame,
    /// Cusp tips and incisal points in the local frame (for occlusion measures).
    pub cusp_tips: Vec<Vec3>,
    /// The crown's anatomical axes in the local frame: the rotation from the local frame to the
    /// frame whose x, y and z are the crown's mesio-distal, occlusal and buccal axes (the
    /// procedural tooth's local frame). Identity where the local frame is anatomical (procedural
    /// teeth); for a scanned crown, its fitted template's orientation (identity without one), as
    /// its local frame takes its buccal axis from the arch and cannot show the crown's rotation.
    pub axes: Quat,
}

impl ToothGeometry {
    /// Builds the procedural shape of a tooth type.
    pub fn procedural(arch: Arch, kind: ToothKind, resolution: ToothResolution) -> Self {
        let an = anatomy(arch, kind);
        let solid = ToothSolid::new(arch, kind, an);
        let mesh = solid.mesh(resolution);
        Self::from_local_mesh(arch, kind, mesh, solid.cusp_tips())
    }

    /// The geometry of an imported tooth from its closed mesh in its local frame (origin at the
    /// cervical centre, y occlusal, z buccal; see [`super::import`]). Dimensions are the anatomy
    /// table's for the type.
    pub fn imported(arch: Arch, kind: ToothKind, mesh: TriMesh) -> Self {
        let cusp_tips = super::import::cusp_tips(&mesh, kind);
        Self::from_local_mesh(arch, kind, mesh, cusp_tips)
    }

    /// A tooth from its closed mesh in its local frame (cervical centre at the origin, y occlusal,
    /// z buccal): frame, triangle hierarchy and the type's anatomy.
    fn from_local_mesh(arch: Arch, kind: ToothKind, mesh: TriMesh, cusp_tips: Vec<Vec3>) -> Self {
        let frame = ToothFrame::from_mesh(
            &mesh,
            Vec3::ZERO,
            Vec3::Y,
            Vec3::Z,
            CentreParameters::default(),
        );
        // Triangles and vertices in the hierarchy's leaf order: the surface's patches lie
        // together in memory (see [`TriMesh::in_triangle_order`]), whatever order the file had.
        let bvh = TriangleBvh::build(&mesh);
        let mesh = mesh.in_triangle_order(&bvh.order);
        let bvh = bvh.in_leaf_order();
        let stars = VertexStars::of(&mesh);
        Self {
            arch,
            kind,
            anatomy: anatomy(arch, kind),
            cusp_tips,
            axes: Quat::IDENTITY,
            mesh,
            bvh,
            stars,
            frame,
        }
    }

    /// The mesh with its hierarchy, for geometry queries.
    pub fn mesh_ref(&self) -> MeshRef<'_> {
        MeshRef {
            mesh: &self.mesh,
            bvh: &self.bvh,
        }
    }

    /// This tooth's side of a penetration walk ([`crate::geometry::mesh_penetration_near`])
    /// from its triangles `near`, which must hold every triangle meeting the other surface.
    pub fn near<'a>(&'a self, near: &'a [u32]) -> NearContact<'a> {
        NearContact {
            mesh: self.mesh_ref(),
            stars: &self.stars,
            near,
        }
    }
}

/// The sixteen procedural shapes (8 kinds × 2 arches) at one resolution.
#[derive(Debug)]
pub struct ShapeSet {
    /// Resolution of every shape.
    pub resolution: ToothResolution,
    shapes: Vec<Arc<ToothGeometry>>,
}

impl ShapeSet {
    /// The shape of a tooth type.
    pub fn get(&self, arch: Arch, kind: ToothKind) -> Arc<ToothGeometry> {
        let i = match arch {
            Arch::Upper => 0,
            Arch::Lower => 8,
        } + kind as usize;
        self.shapes[i].clone()
    }

    /// Builds all sixteen shapes, on all cores.
    fn build(resolution: ToothResolution) -> Self {
        let jobs: Vec<(Arch, ToothKind)> = [Arch::Upper, Arch::Lower]
            .into_iter()
            .flat_map(|a| ToothKind::ALL.into_iter().map(move |k| (a, k)))
            .collect();
        let shapes = crate::parallel::parallel_map(&jobs, |&(arch, kind)| {
            Arc::new(ToothGeometry::procedural(arch, kind, resolution))
        });
        Self { resolution, shapes }
    }

    /// The shared set for a resolution, built once per process.
    pub fn shared(resolution: ToothResolution) -> Arc<ShapeSet> {
        static CACHE: Memo<ToothResolution, ShapeSet> = Memo::new();
        CACHE.get_or_build(resolution, || Self::build(resolution))
    }
}
