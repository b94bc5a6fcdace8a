//! Engine-free geometry on glam: validated triangle meshes, mass properties, exact triangle queries,
//! a bounding-volume hierarchy for mesh–mesh distance, and mesh simplification.
//!
//! Nothing here touches the ECS; every function is callable from a test, a benchmark or another
//! engine. Lengths are millimetres.

pub mod aabb;
pub mod bvh;
pub mod closest;
pub mod columns;
pub mod decimate;
pub mod interval;
pub mod mass;
pub mod mesh_distance;
pub mod pose;
pub mod sphere;
pub mod trimesh;

pub use aabb::Aabb;
pub use bvh::TriangleBvh;
pub use closest::{
    FacePlane, TrianglePair, closest_point_triangle, closest_points_segment_segment,
    closest_points_triangle_triangle, plane_gap, triangle_plane_gap, triangles_intersect,
};
pub use columns::Columns;
pub use mass::MassProperties;
pub use mesh_distance::{MeshRef, MeshSeparation, mesh_penetration, mesh_separation};
pub use pose::Pose;
pub use sphere::Sphere;
pub use trimesh::{MeshError, TriMesh};
