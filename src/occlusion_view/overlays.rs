//! Overlays drawn over the teeth: one level of every tooth's sphere tree (the paper's Figure 2), and
//! the contacts of the current step (Figure 6): the overlapping leaf spheres of each touching pair
//! and its contact points, in another colour. Drawn with gizmos, only while switched on.

use std::str::FromStr;

use bevy::prelude::*;

use super::ViewError;
use crate::{
    collision::{CollisionSettings, Contacts, Method, ToothCollider},
    geometry::Pose,
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
    /// Bounding circles in the x–z plane, drawn while the `circles` method is active (pairs whose
    /// circles meet in red).
    pub circles: bool,
    /// How roots are drawn.
    pub roots: Roots,
}

/// How roots are drawn: translucent by default, so that the crowns stay clear and roots show
/// through each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Roots {
    /// Opaque, like the crowns.
    Solid,
    /// Semi-transparent.
    #[default]
    Translucent,
    /// Not drawn.
    Hidden,
}

impl Roots {
    /// All styles, for lists.
    pub const ALL: [Roots; 3] = [Roots::Translucent, Roots::Solid, Roots::Hidden];

    /// The style's name on the command line and in the panel.
    pub fn name(self) -> &'static str {
        match self {
            Roots::Solid => "solid",
            Roots::Translucent => "translucent",
            Roots::Hidden => "hidden",
        }
    }
}

impl FromStr for Roots {
    type Err = ViewError;
    fn from_str(s: &str) -> Result<Self, ViewError> {
        Roots::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| ViewError::UnknownRoots(s.to_owned()))
    }
}

/// One overlay named on the command line: `spheres:LEVEL`, `contacts`, `occlusion-map` or
/// `circles`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlay {
    /// A sphere-tree level.
    Spheres(u32),
    /// The contacts.
    Contacts,
    /// The occlusal contact map.
    OcclusionMap,
    /// Bounding circles (while the `circles` method is active).
    Circles,
}

impl FromStr for Overlay {
    type Err = ViewError;
    fn from_str(s: &str) -> Result<Self, ViewError> {
        match s {
            "contacts" => Ok(Overlay::Contacts),
            "occlusion-map" => Ok(Overlay::OcclusionMap),
            "circles" => Ok(Overlay::Circles),
            _ => match s.strip_prefix("spheres:").map(str::parse::<u32>) {
                Some(Ok(level)) if level <= 6 => Ok(Overlay::Spheres(level)),
                _ => Err(ViewError::UnknownOverlay(s.to_owned())),
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
            Overlay::Circles => self.circles = true,
        }
        self
    }
}

/// Shows or hides each arch; extracted teeth are hidden.
pub(super) fn arch_visibility(
    overlays: Res<Overlays>,
    mut teeth: Query<(&Tooth, &mut Visibility, Has<Extracted>)>,
) {
    // Every frame: teeth are extracted and restored at any time, and there are at most 32.
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
const RESISTANCE_COLOUR: Color = Color::srgb(0.2, 0.9, 0.3);
const ROTATION_COLOUR: Color = Color::srgb(0.95, 0.2, 0.9);
const BRACKET_COLOUR: Color = Color::srgb(0.3, 0.6, 1.0);

/// Rings around the selected teeth's crowns (extracted ones are selected without a ring); under
/// the PDL model, markers at each one's bracket (blue), centre of resistance (green) and current
/// centre of rotation (magenta, while it turns).
pub(super) fn draw_selection(
    selection: Res<Selection>,
    mut gizmos: Gizmos,
    teeth: Query<(&Transform, &crate::teeth::ToothShape), Without<Extracted>>,
    state: Option<Res<crate::movement::SimulationState>>,
) {
    let sim = state
        .as_ref()
        .and_then(|s| s.sim.as_ref().map(|sim| (s, sim)));
    for e in &selection.0 {
        if let Some((s, sim)) = sim
            && let Some(i) = s.index_of(*e)
        {
            let markers = [
                (sim.bracket(i), 0.25, BRACKET_COLOUR),
                (sim.centre_of_resistance(i), 0.4, RESISTANCE_COLOUR),
                (sim.centre_of_rotation(i), 0.4, ROTATION_COLOUR),
            ];
            for (p, r, colour) in markers {
                if let Some(p) = p.filter(|p| p.is_finite() && p.length() < 200.0) {
                    gizmos.sphere(Isometry3d::from_translation(p), r, colour);
                }
            }
        }
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

const CIRCLE_COLOUR: Color = Color::srgb(0.2, 0.9, 0.5);
const CIRCLE_CONTACT_COLOUR: Color = Color::srgb(1.0, 0.2, 0.2);

/// The bounding circles of the `circles` method, at each crown's height, red for pairs in contact.
pub(super) fn draw_circles(
    overlays: Res<Overlays>,
    settings: Res<CollisionSettings>,
    mut gizmos: Gizmos,
    teeth: Query<(Entity, &Transform, &ToothCollider, &Visibility), Without<Extracted>>,
    contacts: Res<Contacts>,
) {
    if !overlays.circles || settings.method != Method::Circles {
        return;
    }
    for (e, tf, collider, visibility) in &teeth {
        if *visibility == Visibility::Hidden {
            continue;
        }
        let pose = Pose::new(tf.rotation, tf.translation);
        let c = pose.transform_point(collider.circle.centre);
        let height = pose
            .transform_point(collider.shape.geometry.frame.crown_centre)
            .y;
        let touching = contacts.list.iter().any(|c| c.a == e || c.b == e);
        gizmos.circle(
            Isometry3d::new(
                Vec3::new(c.x, height, c.z),
                Quat::from_rotation_arc(Vec3::Z, Vec3::Y),
            ),
            collider.circle.radius,
            if touching {
                CIRCLE_CONTACT_COLOUR
            } else {
                CIRCLE_COLOUR
            },
        );
    }
}

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

const WIRE_COLOUR: Color = Color::srgb(0.86, 0.88, 0.92);
/// Elastomeric chains.
const CHAIN_COLOUR: Color = Color::srgb(0.62, 0.36, 0.82);
/// NiTi coil springs.
const COIL_COLOUR: Color = Color::srgb(0.95, 0.72, 0.25);
/// Intermaxillary elastics (latex).
const ELASTIC_COLOUR: Color = Color::srgb(0.95, 0.55, 0.35);
/// Force on a bracket drawn fully red (N).
const BRACKET_FULL_N: f64 = 2.0;

/// The archwires in their deformed shape, and each bracket's slot as a box turned as the slot is,
/// coloured from blue (the wire passive in it) to red ([`BRACKET_FULL_N`] or more on it); the
/// chains over their brackets, the coils and the intermaxillary elastics once placed, as lines
/// between their slots.
pub(super) fn draw_appliances(
    mut gizmos: Gizmos,
    state: Option<Res<crate::movement::SimulationState>>,
) {
    let Some(sim) = state.as_ref().and_then(|s| s.sim.as_ref()) else {
        return;
    };
    for w in &sim.wires {
        let nodes = w.rod.nodes.iter().map(|n| n.x.as_vec3());
        if w.rod.nodes.iter().all(|n| n.x.is_finite()) {
            gizmos.linestrip(nodes, WIRE_COLOUR);
        }
        for (b, r) in w.brackets.iter().zip(&w.reactions) {
            let Some(t) = sim.teeth.get(b.tooth) else {
                continue;
            };
            let at = t.pose.transform_point(b.bracket.centre.as_vec3());
            let turn = t.pose.rotation * b.bracket.frame.as_quat();
            let f = (r.force.length() / BRACKET_FULL_N).clamp(0.0, 1.0) as f32;
            let colour = Color::srgb(0.25 + 0.75 * f, 0.55 * (1.0 - f), 1.0 - 0.8 * f);
            let size = Vec3::new(b.bracket.width_mm as f32, 1.2, 0.6);
            gizmos.cube(
                Transform::from_translation(at)
                    .with_rotation(turn)
                    .with_scale(size),
                colour,
            );
        }
    }
    let slot = |f: crate::teeth::Fdi| {
        sim.wires.iter().find_map(|w| {
            let b = w.brackets.iter().find(|b| b.fdi == f)?;
            let t = sim.teeth.get(b.tooth)?;
            Some(t.pose.transform_point(b.bracket.centre.as_vec3()))
        })
    };
    for w in &sim.wires {
        for c in w.chains.iter().filter(|c| c.placed.is_some()) {
            let ends = [c.from, c.to].map(|f| w.brackets.iter().position(|b| b.fdi == f));
            if let [Some(a), Some(b)] = ends {
                let run = &w.brackets[a.min(b)..=a.max(b)];
                gizmos.linestrip(run.iter().filter_map(|b| slot(b.fdi)), CHAIN_COLOUR);
            }
        }
        for c in w.coils.iter().filter(|c| c.placed.is_some()) {
            if let (Some(a), Some(b)) = (slot(c.from), slot(c.to)) {
                gizmos.line(a, b, COIL_COLOUR);
            }
        }
    }
    for e in sim.elastics.iter().filter(|e| e.force_n > 0.0) {
        if let (Some(a), Some(b)) = (slot(e.from), slot(e.to)) {
            gizmos.line(a, b, ELASTIC_COLOUR);
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
        assert!(
            "map"
                .parse::<Overlay>()
                .unwrap_err()
                .to_string()
                .contains("map")
        );
        let o = Overlays::default()
            .with(Overlay::Spheres(2))
            .with(Overlay::Contacts);
        assert_eq!(o.sphere_level, Some(2));
        assert!(o.contacts);
        assert_eq!("circles".parse::<Overlay>(), Ok(Overlay::Circles));
        assert!(Overlays::default().with(Overlay::Circles).circles);
    }

    #[test]
    fn root_styles_parse_and_default_to_translucent() {
        assert_eq!(Overlays::default().roots, Roots::Translucent);
        for r in Roots::ALL {
            assert_eq!(r.name().parse::<Roots>(), Ok(r));
        }
        assert!(
            "glass"
                .parse::<Roots>()
                .unwrap_err()
                .to_string()
                .contains("glass")
        );
    }
}
