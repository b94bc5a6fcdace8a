//! Meshes and materials for tooth entities: each tooth draws its crown, and a child entity its
//! root, solid, translucent (the default, so roots show through each other and the crowns stay
//! clear) or hidden.

use std::{collections::HashMap, sync::Arc};

use bevy::{
    asset::RenderAssetUsages,
    mesh::{Indices, PrimitiveTopology},
    prelude::*,
};

use super::overlays::{Overlays, Roots};
use crate::teeth::{Arch, Extracted, Tooth, ToothShape};

/// The render meshes of one tooth shape: crown and root, split at the cervical plane.
struct ShapeMeshes {
    crown: Handle<Mesh>,
    root: Handle<Mesh>,
    /// The shape's mesh vertex behind each crown vertex.
    crown_vertices: Arc<[u32]>,
}

/// Render meshes shared by teeth with the same shape, and the materials of crowns and roots.
#[derive(Resource, Default)]
pub(super) struct ToothRenderAssets {
    meshes: HashMap<usize, ShapeMeshes>,
    materials: HashMap<Arch, Handle<StandardMaterial>>,
    root_materials: HashMap<(Arch, Roots), Handle<StandardMaterial>>,
}

impl ToothRenderAssets {
    /// The shared crown mesh of a shape and the crown material of an arch, once made.
    pub(super) fn handles(
        &self,
        shape: &ToothShape,
        arch: Arch,
    ) -> (Option<Handle<Mesh>>, Option<Handle<StandardMaterial>>) {
        (self.crown_mesh(shape), self.materials.get(&arch).cloned())
    }

    /// The shared root material of an arch in a style (made on first use).
    fn root_material(
        &mut self,
        materials: &mut Assets<StandardMaterial>,
        style: Roots,
        arch: Arch,
    ) -> Handle<StandardMaterial> {
        self.root_materials
            .entry((arch, style))
            .or_insert_with(|| materials.add(root_material(style, arch)))
            .clone()
    }

    /// The shared crown mesh of a shape, once made.
    pub(super) fn crown_mesh(&self, shape: &ToothShape) -> Option<Handle<Mesh>> {
        self.meshes.get(&key(shape)).map(|m| m.crown.clone())
    }

    /// The shape's mesh vertex behind each vertex of its crown mesh, once made.
    pub(super) fn crown_vertices(&self, shape: &ToothShape) -> Option<Arc<[u32]>> {
        self.meshes
            .get(&key(shape))
            .map(|m| m.crown_vertices.clone())
    }
}

fn key(shape: &ToothShape) -> usize {
    Arc::as_ptr(&shape.0) as usize
}

/// The root of a tooth: a child entity drawn solid, translucent or not at all (see [`Roots`]).
#[derive(Component)]
pub(super) struct ToothRoot;

/// A part of a mesh being split: the mesh vertex behind each of its vertices, its triangles' indices
/// into those, and the mesh vertex → part vertex map.
type Part = (Vec<u32>, Vec<u32>, HashMap<u32, u32>);

/// The crown and root parts of a tooth mesh, split at the cervical plane (a triangle belongs to
/// the crown when its centroid lies on the occlusal side), with smooth normals of the whole mesh so
/// the seam does not show. Also the mesh vertex behind each crown vertex.
fn render_parts(shape: &ToothShape) -> (Mesh, Vec<u32>, Mesh) {
    let m = &shape.mesh;
    let normals = m.vertex_normals();
    let (cervical, axis) = (shape.frame.cervical_centre, shape.frame.long_axis);
    let mut parts: [Part; 2] = Default::default();
    for tri in &m.triangles {
        let centroid = (m.vertices[tri[0] as usize]
            + m.vertices[tri[1] as usize]
            + m.vertices[tri[2] as usize])
            / 3.0;
        let part = &mut parts[usize::from((centroid - cervical).dot(axis) < 0.0)];
        for &v in tri {
            let next = part.0.len() as u32;
            let local = *part.2.entry(v).or_insert(next);
            if local == next {
                part.0.push(v);
            }
            part.1.push(local);
        }
    }
    let mesh = |(vertices, indices, _): &Part| {
        let positions: Vec<[f32; 3]> = vertices
            .iter()
            .map(|&v| m.vertices[v as usize].to_array())
            .collect();
        let normals: Vec<[f32; 3]> = vertices
            .iter()
            .map(|&v| normals[v as usize].to_array())
            .collect();
        Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
        .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
        .with_inserted_indices(Indices::U32(indices.clone()))
    };
    (mesh(&parts[0]), parts[0].0.clone(), mesh(&parts[1]))
}

fn crown_colour(arch: Arch) -> Color {
    match arch {
        Arch::Upper => Color::srgb(0.95, 0.92, 0.84),
        Arch::Lower => Color::srgb(0.92, 0.90, 0.86),
    }
}

fn root_material(style: Roots, arch: Arch) -> StandardMaterial {
    // Cementum is yellower than enamel.
    let [r, g, b, _] = crown_colour(arch).to_srgba().to_f32_array();
    let base = Color::srgb(r * 0.97, g * 0.9, b * 0.72);
    match style {
        Roots::Translucent => StandardMaterial {
            base_color: base.with_alpha(0.35),
            alpha_mode: AlphaMode::Blend,
            perceptual_roughness: 0.6,
            ..default()
        },
        Roots::Solid | Roots::Hidden => StandardMaterial {
            base_color: base,
            perceptual_roughness: 0.6,
            ..default()
        },
    }
}

pub(super) fn attach_tooth_meshes(
    mut commands: Commands,
    mut assets: ResMut<ToothRenderAssets>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    overlays: Res<Overlays>,
    teeth: Query<(Entity, &Tooth, &ToothShape), Added<ToothShape>>,
) {
    for (entity, tooth, shape) in &teeth {
        let parts = assets.meshes.entry(key(shape)).or_insert_with(|| {
            let (crown, crown_vertices, root) = render_parts(shape);
            ShapeMeshes {
                crown: meshes.add(crown),
                root: meshes.add(root),
                crown_vertices: crown_vertices.into(),
            }
        });
        let (crown, root) = (parts.crown.clone(), parts.root.clone());
        let arch = tooth.id.arch();
        let material = assets
            .materials
            .entry(arch)
            .or_insert_with(|| {
                materials.add(StandardMaterial {
                    base_color: crown_colour(arch),
                    perceptual_roughness: 0.45,
                    reflectance: 0.4,
                    ..default()
                })
            })
            .clone();
        let root_material = assets.root_material(&mut materials, overlays.roots, arch);
        commands
            .entity(entity)
            .insert((Mesh3d(crown), MeshMaterial3d(material)))
            .with_child((
                ToothRoot,
                Mesh3d(root),
                MeshMaterial3d(root_material),
                Transform::IDENTITY,
                root_visibility(overlays.roots),
            ));
    }
}

fn root_visibility(style: Roots) -> Visibility {
    if style == Roots::Hidden {
        Visibility::Hidden
    } else {
        Visibility::Inherited
    }
}

/// Draws the roots as the overlays ask (solid, translucent or hidden).
pub(super) fn root_style(
    overlays: Res<Overlays>,
    mut assets: ResMut<ToothRenderAssets>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    teeth: Query<&Tooth>,
    mut roots: Query<
        (
            &ChildOf,
            &mut MeshMaterial3d<StandardMaterial>,
            &mut Visibility,
        ),
        With<ToothRoot>,
    >,
) {
    if !overlays.is_changed() {
        return;
    }
    for (parent, mut material, mut visibility) in &mut roots {
        let Ok(tooth) = teeth.get(parent.parent()) else {
            continue;
        };
        let arch = tooth.id.arch();
        let want = assets.root_material(&mut materials, overlays.roots, arch);
        if material.0 != want {
            material.0 = want;
        }
        let v = root_visibility(overlays.roots);
        if *visibility != v {
            *visibility = v;
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{ShapeSet, ToothKind, ToothResolution};

    #[test]
    fn crown_and_root_parts_split_the_mesh_at_the_cervical_plane() {
        let shapes = ShapeSet::shared(ToothResolution::PAPER);
        let shape = ToothShape(shapes.get(Arch::Lower, ToothKind::FirstMolar));
        let (crown, crown_vertices, root) = render_parts(&shape);
        let count = |m: &Mesh| m.indices().map_or(0, |i| i.len() / 3);
        let (c, r) = (count(&crown), count(&root));
        assert_eq!(c + r, shape.mesh.triangles.len());
        assert!(c > 0 && r > 0, "{c} crown and {r} root triangles");
        // Crown vertices are the mesh's own, and all on or above the cervical plane's side.
        let Some(bevy::mesh::VertexAttributeValues::Float32x3(positions)) =
            crown.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("positions");
        };
        assert_eq!(positions.len(), crown_vertices.len());
        let f = &shape.frame;
        let mut above = 0;
        for (p, &i) in positions.iter().zip(&crown_vertices) {
            assert_eq!(Vec3::from_array(*p), shape.mesh.vertices[i as usize]);
            if (Vec3::from_array(*p) - f.cervical_centre).dot(f.long_axis) >= 0.0 {
                above += 1;
            }
        }
        assert!(
            above * 10 >= positions.len() * 9,
            "{above} of {}",
            positions.len()
        );
    }
}
