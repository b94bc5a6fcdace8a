//! Overlays drawn over the teeth: one level of every tooth's sphere tree (the paper's Figure 2), and
//! the contacts of the current step (Figure 6): the overlapping leaf spheres of each touching pair
//! and its contact points, in another colour. Drawn with gizmos, only while switched on.

use std::str::FromStr;

use bevy::prelude::*;

use crate::{
    collision::{Contacts, ToothCollider},
    sphere_tree::ToothSphereTree,
    teeth::{Extracted, Tooth},
};

/// Which overlays are shown, and which arches.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overlays {
    /// Hide the upper arch.
    pub hide_upper: bool,
    /// Hide the lower arch.
    pub hide_lower: bool,
    /// Sphere-tree level to draw (0 = root), if any.
    pub sphere_level: Option<u32>,
    /// Contact points and overlapping leaf spheres of the current step.
    pub contacts: bool,
    /// Tooth surfaces coloured by their distance to the opposing arch.
    pub occlusion_map: bool,
}

/// One overlay named on the command line: `spheres:LEVEL`, `contacts` or `occlusion-map`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlay {
    /// A sphere-tree level.
    Spheres(u32),
    /// The contacts.
    Contacts,
    /// The occlusal contact map.
    OcclusionMap,
}

impl FromStr for Overlay {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "contacts" => Ok(Overlay::Contacts),
            "occlusion-map" => Ok(Overlay::OcclusionMap),
            _ => match s.strip_prefix("spheres:").map(str::parse::<u32>) {
                Some(Ok(level)) if level <= 6 => Ok(Overlay::Spheres(level)),
                _ => Err(format!(
                    "unknown overlay '{s}': use spheres:LEVEL (0–6), contacts or occlusion-map"
                )),
            },
        }
    }
}

impl Overlays {
    /// Switches an overlay on.
    pub fn with(mut self, o: Overlay) -> Self {
        match o {
            Overlay::Spheres(l) => self.sphere_level = Some(l),
            Overlay::Contacts => self.contacts = true,
            Overlay::OcclusionMap => self.occlusion_map = true,
        }
        self
    }
}

/// Shows or hides each arch (extracted teeth stay hidden).
pub(super) fn arch_visibility(
    overlays: Res<Overlays>,
    mut teeth: Query<(&Tooth, &mut Visibility, Has<Extracted>)>,
    added: Query<(), Added<Tooth>>,
) {
    if !overlays.is_changed() && added.is_empty() {
        return;
    }
    for (tooth, mut v, extracted) in &mut teeth {
        let hidden = extracted
            || match tooth.id.arch() {
                crate::teeth::Arch::Upper => overlays.hide_upper,
                crate::teeth::Arch::Lower => overlays.hide_lower,
            };
        let want = if hidden {
            Visibility::Hidden
        } else {
            Visibility::Inherited
        };
        if *v != want {
            *v = want;
        }
    }
}

/// Teeth selected in the viewer (by clicking or from the FDI chart), in selection order.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection(pub Vec<Entity>);

impl Selection {
    /// Selects only `e`, or with `add` toggles it in the selection.
    pub fn pick(&mut self, e: Entity, add: bool) {
        if add {
            if let Some(i) = self.0.iter().position(|x| *x == e) {
                self.0.remove(i);
            } else {
                self.0.push(e);
            }
        } else {
            self.0 = vec![e];
        }
    }
}

const SELECTION_COLOUR: Color = Color::srgb(1.0, 0.85, 0.1);

/// Rings around the selected teeth's crowns.
pub(super) fn draw_selection(
    selection: Res<Selection>,
    mut gizmos: Gizmos,
    teeth: Query<(&Transform, &crate::teeth::ToothShape)>,
) {
    for e in &selection.0 {
        let Ok((tf, shape)) = teeth.get(*e) else {
            continue;
        };
        let centre = tf.transform_point(shape.frame.crown_centre);
        let axis = (tf.rotation * shape.frame.long_axis).normalize_or(Vec3::Y);
        let radius = 0.6 * shape.anatomy.mesiodistal.max(shape.anatomy.buccolingual);
        gizmos.circle(
            Isometry3d::new(centre, Quat::from_rotation_arc(Vec3::Z, axis)),
            radius,
            SELECTION_COLOUR,
        );
        gizmos.sphere(Isometry3d::from_translation(centre), 0.3, SELECTION_COLOUR);
    }
}

const SPHERE_COLOUR: Color = Color::srgba(0.35, 0.65, 1.0, 0.55);
const LEAF_CONTACT_COLOUR: Color = Color::srgb(1.0, 0.55, 0.1);
const POINT_COLOUR: Color = Color::srgb(1.0, 0.1, 0.1);

/// Present teeth with their trees.
type TreeQuery<'w, 's> = Query<
    'w,
    's,
    (Entity, &'static Transform, &'static ToothSphereTree),
    (With<Tooth>, Without<Extracted>),
>;

pub(super) fn draw_overlays(
    overlays: Res<Overlays>,
    mut gizmos: Gizmos,
    teeth: TreeQuery,
    visible: Query<&Visibility>,
    colliders: Query<(&Transform, &ToothCollider)>,
    contacts: Res<Contacts>,
) {
    if let Some(level) = overlays.sphere_level {
        for (e, tf, tree) in &teeth {
            if level >= tree.levels || visible.get(e).is_ok_and(|v| *v == Visibility::Hidden) {
                continue;
            }
            for s in tree.level(level) {
                gizmos.sphere(
                    Isometry3d::from_translation(tf.transform_point(s.centre)),
                    s.radius,
                    SPHERE_COLOUR,
                );
            }
        }
    }
    if overlays.contacts {
        for c in &contacts.list {
            for (e, side) in [(c.a, 0usize), (c.b, 1usize)] {
                let Ok((tf, collider)) = colliders.get(e) else {
                    continue;
                };
                for pair in &c.leaf_pairs {
                    let node = if side == 0 { pair.0 } else { pair.1 } as usize;
                    if let Some(s) = collider.shape.tree.spheres.get(node) {
                        gizmos.sphere(
                            Isometry3d::from_translation(tf.transform_point(s.centre)),
                            s.radius,
                            LEAF_CONTACT_COLOUR,
                        );
                    }
                }
            }
            for p in c.points {
                gizmos.sphere(Isometry3d::from_translation(p), 0.15, POINT_COLOUR);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlay_names_parse() {
        assert_eq!("contacts".parse::<Overlay>(), Ok(Overlay::Contacts));
        assert_eq!(
            "occlusion-map".parse::<Overlay>(),
            Ok(Overlay::OcclusionMap)
        );
        assert_eq!("spheres:3".parse::<Overlay>(), Ok(Overlay::Spheres(3)));
        assert!("spheres:x".parse::<Overlay>().is_err());
        assert!("map".parse::<Overlay>().unwrap_err().contains("map"));
        let o = Overlays::default()
            .with(Overlay::Spheres(2))
            .with(Overlay::Contacts);
        assert_eq!(o.sphere_level, Some(2));
        assert!(o.contacts);
    }
}
