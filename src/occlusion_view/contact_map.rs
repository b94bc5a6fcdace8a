//! The occlusal contact map (the paper's Figure 7, as planning software shows it): every tooth
//! surface coloured by its distance to the opposing arch, red at contact (or overlap) through
//! yellow and green to blue at [`MAP_RANGE_MM`] and beyond.
//!
//! Only done while shown: each tooth then gets its own coloured copy of its crown mesh (teeth
//! otherwise share one mesh per shape; roots keep their own look), and a tooth's colours are
//! measured again only when it or one of its antagonists moved (at most [`REFRESH_S`] apart).
//! Distances are exact (closest point on the antagonist's triangles, inside test for overlap) at
//! the crown's mesh vertices.

use std::collections::HashMap;

use bevy::{mesh::VertexAttributeValues, prelude::*};

use super::{Overlays, tooth_render::ToothRenderAssets};
use crate::{
    geometry::{MeshRef, closest_point_on_mesh, point_inside_mesh},
    teeth::{Extracted, Tooth, ToothShape},
};

/// Distance shown as the far end of the colour ramp (mm).
pub const MAP_RANGE_MM: f32 = 0.5;
/// Least time between two measurements (s).
pub const REFRESH_S: f32 = 0.2;

/// A tooth's own coloured mesh while the map is shown.
#[derive(Component)]
pub(super) struct MapMesh(Handle<Mesh>);

/// Map state: its material, when it was last measured, the poses it was measured at.
#[derive(Resource, Default)]
pub(super) struct MapState {
    material: Option<Handle<StandardMaterial>>,
    timer: f32,
    measured: HashMap<Entity, Transform>,
    shown: bool,
}

/// The ramp: red (0) → yellow → green → blue (≥ range).
pub fn ramp(distance_mm: f32) -> [f32; 4] {
    let t = (distance_mm / MAP_RANGE_MM).clamp(0.0, 1.0);
    let stops = [
        [0.85, 0.1, 0.1],
        [0.95, 0.85, 0.15],
        [0.2, 0.75, 0.3],
        [0.2, 0.4, 0.9],
    ];
    let x = t * 3.0;
    let i = (x.floor() as usize).min(2);
    let f = x - i as f32;
    let (a, b) = (stops[i], stops[i + 1]);
    [
        a[0] + (b[0] - a[0]) * f,
        a[1] + (b[1] - a[1]) * f,
        a[2] + (b[2] - a[2]) * f,
        1.0,
    ]
}

type Teeth<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Tooth,
        &'static ToothShape,
        &'static Transform,
        Option<&'static MapMesh>,
    ),
    // Only teeth whose render mesh is attached (so the map replaces it, not the reverse).
    (Without<Extracted>, With<Mesh3d>),
>;

#[allow(clippy::too_many_arguments)]
pub(super) fn update_contact_map(
    mut commands: Commands,
    overlays: Res<Overlays>,
    time: Res<Time<Real>>,
    mut state: ResMut<MapState>,
    assets: Res<ToothRenderAssets>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    teeth: Teeth,
) {
    if !overlays.occlusion_map {
        if state.shown {
            // Back to the shared meshes and arch materials.
            for (e, tooth, shape, _, map) in &teeth {
                if let Some(map) = map {
                    meshes.remove(&map.0);
                    let (mesh, material) = assets.handles(shape, tooth.id.arch());
                    if let (Some(mesh), Some(material)) = (mesh, material) {
                        commands
                            .entity(e)
                            .remove::<MapMesh>()
                            .insert((Mesh3d(mesh), MeshMaterial3d(material)));
                    }
                }
            }
            state.measured.clear();
            state.shown = false;
        }
        return;
    }
    state.shown = true;
    state.timer -= time.delta_secs();
    if state.timer > 0.0 {
        return;
    }
    state.timer = REFRESH_S;
    let material = state
        .material
        .get_or_insert_with(|| {
            materials.add(StandardMaterial {
                base_color: Color::WHITE,
                perceptual_roughness: 0.6,
                ..default()
            })
        })
        .clone();
    let all: Vec<_> = teeth.iter().collect();
    let moved = |e: Entity, tf: &Transform| state.measured.get(&e) != Some(tf);
    let mut updates = Vec::new();
    for &(e, tooth, shape, tf, map) in &all {
        let antagonists: Vec<_> = all
            .iter()
            .filter(|o| o.1.id.arch() != tooth.id.arch())
            .collect();
        let stale = map.is_none() || moved(e, tf) || antagonists.iter().any(|o| moved(o.0, o.3));
        if !stale {
            continue;
        }
        let Some(crown) = assets.crown_vertices(shape) else {
            continue;
        };
        // World to each antagonist's frame, once per tooth rather than per vertex.
        let to_local: Vec<_> = antagonists
            .iter()
            .map(|o| (o.3.compute_affine().inverse(), o.2))
            .collect();
        let colours: Vec<[f32; 4]> = crown
            .iter()
            .map(|&i| {
                let p = tf.transform_point(shape.mesh.vertices[i as usize]);
                let mut best = f32::INFINITY;
                for (inverse, other) in &to_local {
                    let local = inverse.transform_point3(p);
                    let m = MeshRef {
                        mesh: &other.mesh,
                        bvh: &other.bvh,
                    };
                    if let Some((_, d)) = closest_point_on_mesh(m, local) {
                        let d = if d <= 1.0 && point_inside_mesh(m, local) {
                            0.0
                        } else {
                            d
                        };
                        best = best.min(d);
                    }
                }
                ramp(best)
            })
            .collect();
        updates.push((e, shape.clone(), map.map(|m| m.0.clone()), colours));
    }
    for (e, shape, existing, colours) in updates {
        let updated = match &existing {
            Some(h) => match meshes.get_mut(h) {
                Some(mut mesh) => {
                    mesh.insert_attribute(
                        Mesh::ATTRIBUTE_COLOR,
                        VertexAttributeValues::Float32x4(colours.clone()),
                    );
                    true
                }
                None => false,
            },
            None => false,
        };
        if !updated {
            // A coloured copy of the shape's shared crown mesh.
            let Some(mesh) = assets
                .crown_mesh(&shape)
                .and_then(|h| meshes.get(&h).cloned())
            else {
                continue;
            };
            let mesh = mesh.with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, colours);
            let handle = meshes.add(mesh);
            commands.entity(e).insert((
                MapMesh(handle.clone()),
                Mesh3d(handle),
                MeshMaterial3d(material.clone()),
            ));
        }
        if let Some((_, _, _, tf, _)) = all.iter().find(|x| x.0 == e) {
            state.measured.insert(e, **tf);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_runs_red_to_blue() {
        assert_eq!(ramp(0.0), [0.85, 0.1, 0.1, 1.0]);
        assert_eq!(ramp(-1.0), ramp(0.0));
        assert_eq!(ramp(MAP_RANGE_MM), [0.2, 0.4, 0.9, 1.0]);
        assert_eq!(ramp(f32::INFINITY), ramp(MAP_RANGE_MM));
        let mid = ramp(MAP_RANGE_MM / 3.0);
        assert!((mid[0] - 0.95).abs() < 1e-5 && (mid[1] - 0.85).abs() < 1e-5);
    }
}
