//! Engine-free geometry on glam: validated triangle meshes, mass properties, exact triangle queries,
//! a bounding-volume hierarchy for mesh–mesh distance, and mesh simplification.
//!
//! Nothing here touches the ECS; every function is callable from a test, a benchmark or another
//! engine. Lengths are millimetres.

mod aabb;
mod bvh;
mod closest;
pub(crate) mod columns;
mod crossing;
pub(crate) mod decimate;
pub(crate) mod interval;
pub mod isosurface;
pub(crate) mod lanes;
mod mass;
mod mat6;
mod mesh_distance;
mod pose;
pub(crate) mod ray;
pub(crate) mod rng;
mod section;
pub(crate) mod sphere;
mod stars;
pub(crate) mod trimesh;
mod walk;

pub use aabb::Aabb;
pub use bvh::TriangleBvh;
pub use closest::{
    FacePlane, TrianglePair, closest_point_triangle, closest_points_facing_triangles,
    closest_points_segment_segment, closest_points_triangle_triangle, plane_gap,
    triangle_plane_gap, triangles_intersect, triangles_within,
};
pub(crate) use columns::{Columns, LocalLines};
pub use crossing::crossing_triangles;
pub use mass::{MassProperties, jacobi_eigen, symmetric_eigen};
pub use mat6::{Mat6, Vec6, halves, vec6};
pub use mesh_distance::{
    MeshRef, MeshSeparation, closest_point_and_triangle, closest_point_and_triangle_within,
    closest_point_on_mesh, closest_point_on_mesh_within, closest_triangles, mesh_penetration,
    mesh_separation, mesh_separation_within, point_inside_mesh,
};
pub use pose::Pose;
pub use section::section_loops;
pub use sphere::Sphere;
pub use stars::VertexStars;
pub use trimesh::{MeshError, TriMesh};
pub use walk::{
    CARRY_LIMIT, InsideSamples, NearContact, Penetration, mesh_penetration_near,
    mesh_penetration_near_from, sample_depth,
};

/// The geometry tests' seeded source of uniform numbers in [−0.5, 0.5) (a linear congruential
/// generator: small, fixed, and the same sequence on every machine).
#[cfg(test)]
pub(crate) fn test_numbers(seed: u32) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    }
}
