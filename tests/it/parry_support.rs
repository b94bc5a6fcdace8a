//! Shared by the parry3d oracle tests: our values handed to parry through plain arrays, so its glam
//! version does not matter.

use glam::Vec3;
use orthosim::geometry::{Pose, TriMesh};
use parry3d::{
    math::{Pose as PPose, Rot3, Vector},
    shape::TriMesh as PMesh,
};

/// A point or vector.
pub fn v(p: Vec3) -> Vector {
    let [x, y, z] = p.to_array();
    Vector::new(x, y, z)
}

/// A pose.
pub fn ppose(p: &Pose) -> PPose {
    let [x, y, z, w] = p.rotation.to_array();
    PPose::from_parts(v(p.translation), Rot3::from_xyzw(x, y, z, w))
}

/// A mesh.
pub fn pmesh(m: &TriMesh) -> PMesh {
    PMesh::new(
        m.vertices.iter().map(|&p| v(p)).collect(),
        m.triangles.clone(),
    )
    .expect("valid mesh")
}
