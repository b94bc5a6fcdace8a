//! A tooth mesh written in each file format orthosim reads, for the import and fuzz tests.

use orthosim::{geometry::TriMesh, teeth::import::write_stl};

/// The mesh as (extension, bytes): binary STL, ASCII STL, OBJ, ASCII PLY.
pub(crate) fn every_format(mesh: &TriMesh) -> Vec<(&'static str, Vec<u8>)> {
    let mut stl = Vec::new();
    write_stl(mesh, &mut stl).unwrap();
    let mut ascii = String::from("solid tooth\n");
    let mut obj = String::new();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    for v in &mesh.vertices {
        obj.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
        ply.push_str(&format!("{} {} {}\n", v.x, v.y, v.z));
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
        ply.push_str(&format!("3 {} {} {}\n", t[0], t[1], t[2]));
        ascii.push_str("facet normal 0 0 0\nouter loop\n");
        for v in mesh.triangle(i) {
            ascii.push_str(&format!("vertex {} {} {}\n", v.x, v.y, v.z));
        }
        ascii.push_str("endloop\nendfacet\n");
    }
    ascii.push_str("endsolid tooth\n");
    vec![
        ("stl", stl),
        ("stl", ascii.into_bytes()),
        ("obj", obj.into_bytes()),
        ("ply", ply.into_bytes()),
    ]
}
