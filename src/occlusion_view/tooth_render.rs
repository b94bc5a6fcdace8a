//! Meshes and materials for tooth entities.

use std::collections::HashMap;

use bevy::{
    asset::RenderAssetUsages,
    mesh::{Indices, PrimitiveTopology},
    prelude::*,
};

use crate::teeth::{Arch, Extracted, Tooth, ToothShape};

/// Render meshes shared by teeth with the same shape, and the two arch materials.
#[derive(Resource, Default)]
pub(super) struct ToothRenderAssets {
    meshes: HashMap<usize, Handle<Mesh>>,
    materials: HashMap<Arch, Handle<StandardMaterial>>,
}

impl ToothRenderAssets {
    /// The shared mesh of a shape and the material of an arch, once made.
    pub(super) fn handles(
        &self,
        shape: &ToothShape,
        arch: Arch,
    ) -> (Option<Handle<Mesh>>, Option<Handle<StandardMaterial>>) {
        let key = std::sync::Arc::as_ptr(&shape.0) as usize;
        (
            self.meshes.get(&key).cloned(),
            self.materials.get(&arch).cloned(),
        )
    }
}

/// A Bevy mesh with smooth normals from a tooth's triangle mesh.
pub(super) fn render_mesh(shape: &ToothShape) -> Mesh {
    let m = &shape.mesh;
    let positions: Vec<[f32; 3]> = m.vertices.iter().map(|v| v.to_array()).collect();
    let normals: Vec<[f32; 3]> = m.vertex_normals().iter().map(|n| n.to_array()).collect();
    let indices: Vec<u32> = m.triangles.iter().flatten().copied().collect();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_indices(Indices::U32(indices))
}

pub(super) fn attach_tooth_meshes(
    mut commands: Commands,
    mut assets: ResMut<ToothRenderAssets>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    teeth: Query<(Entity, &Tooth, &ToothShape), Added<ToothShape>>,
) {
    for (entity, tooth, shape) in &teeth {
        let key = std::sync::Arc::as_ptr(&shape.0) as usize;
        let mesh = assets
            .meshes
            .entry(key)
            .or_insert_with(|| meshes.add(render_mesh(shape)))
            .clone();
        let material = assets
            .materials
            .entry(tooth.id.arch())
            .or_insert_with(|| {
                let colour = match tooth.id.arch() {
                    Arch::Upper => Color::srgb(0.95, 0.92, 0.84),
                    Arch::Lower => Color::srgb(0.92, 0.90, 0.86),
                };
                materials.add(StandardMaterial {
                    base_color: colour,
                    perceptual_roughness: 0.45,
                    reflectance: 0.4,
                    ..default()
                })
            })
            .clone();
        commands
            .entity(entity)
            .insert((Mesh3d(mesh), MeshMaterial3d(material)));
    }
}

/// Extracted teeth whose visibility was just set (e.g. when their mesh was attached).
type NewlyShownExtracted = (With<Tooth>, With<Extracted>, Changed<Visibility>);

pub(super) fn hide_extracted(mut teeth: Query<&mut Visibility, NewlyShownExtracted>) {
    for mut v in &mut teeth {
        if *v != Visibility::Hidden {
            *v = Visibility::Hidden;
        }
    }
}
