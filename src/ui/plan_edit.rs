//! Editing a plan's target in the viewer. With **edit target** on, the teeth stand at the target
//! and the selected tooth gets handles: an arrow along each of its mesial (red), buccal (green)
//! and occlusal (blue) axes moves it along that axis as the arrow is dragged, a ring about each
//! turns it about its crown centre (torque, tip, rotation). Its gaps to every tooth near it,
//! both arches, are measured exactly as it moves and drawn between the closest points (red:
//! overlapping, yellow: in contact within 0.05 mm, green: apart). The window nudges the same six
//! movements by steps, plans to the edited target, and saves it as a target file (each tooth's
//! movement from where the case has it, the map `orthosim plan --target` reads).

use std::path::Path;

use bevy::prelude::*;
use bevy_egui::input::EguiWantsInput;

use super::plan::PlanView;
use crate::{
    geometry::{Pose, mesh_separation},
    movement::SimulationState,
    occlusion_view::Selection,
    planning::Target,
    teeth::{
        ActiveCase, Dentition, Fdi, PlacedTooth, Tooth,
        case::{CaseOffset, ToothMap},
    },
};

/// Length of the arrows and radius of the rings (mm).
const HANDLE_MM: f32 = 6.0;
const RING_MM: f32 = 4.5;
/// How near the cursor must come to a handle to take it (pixels).
const GRAB_PX: f32 = 10.0;
/// Teeth whose crown centres lie within this of the edited tooth's are measured (mm).
const NEAR_MM: f32 = 16.0;
/// Gaps up to this are listed and drawn (mm).
pub(super) const SHOWN_GAP_MM: f32 = 1.0;
/// Contact within this counts as touching (mm).
pub(super) const TOUCH_MM: f32 = 0.05;
/// The axes' colours: mesial, buccal, occlusal.
const AXIS_COLOURS: [Color; 3] = [
    Color::srgb(0.9, 0.2, 0.2),
    Color::srgb(0.2, 0.8, 0.3),
    Color::srgb(0.25, 0.45, 1.0),
];

/// The handles' and gaps' lines: over the teeth (the handles start inside the crown), thicker.
#[derive(Default, Reflect, GizmoConfigGroup)]
pub(super) struct HandleGizmos;

/// Draws [`HandleGizmos`] in front of everything, 3 pixels wide.
pub(super) fn setup_handle_gizmos(mut store: ResMut<GizmoConfigStore>) {
    let (config, _) = store.config_mut::<HandleGizmos>();
    config.depth_bias = -1.0;
    config.line.width = 3.0;
}

/// A movement of the edited tooth: along an axis (mm) or about it (degrees); axes 0 mesial,
/// 1 buccal, 2 occlusal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Grip {
    /// Along the axis.
    Move(usize),
    /// About the axis, through the crown centre.
    Turn(usize),
}

/// A handle being dragged.
#[derive(Clone, Copy, Debug)]
pub(super) struct Grab {
    handle: Grip,
    /// Cursor at the last frame (viewport pixels).
    cursor: Vec2,
}

/// A gap of the edited tooth to a tooth near it, measured exactly.
#[derive(Clone, Copy, Debug)]
pub(super) struct EditContact {
    /// The other tooth.
    pub other: Fdi,
    /// Signed gap (mm; negative: overlapping).
    pub gap_mm: f32,
    /// Closest points, on the edited tooth and on the other.
    pub points: [Vec3; 2],
}

/// The target editor's state.
pub(super) struct TargetEditor {
    /// Editing is on: the teeth stand at the target.
    pub active: bool,
    /// The handle being dragged.
    pub grab: Option<Grab>,
    /// A handle took the last press: the click it ends selects no tooth.
    pub took_press: bool,
    /// The tooth being edited and its pose when its contacts were measured.
    pub measured: Option<(Fdi, Pose)>,
    /// Its gaps up to [`SHOWN_GAP_MM`], nearest first.
    pub contacts: Vec<EditContact>,
    /// The target changed since it was planned.
    pub changed: bool,
    /// Where the target is saved.
    pub path: String,
    /// What the last save said.
    pub saved: Option<String>,
}

impl Default for TargetEditor {
    fn default() -> Self {
        Self {
            active: false,
            grab: None,
            took_press: false,
            measured: None,
            contacts: Vec::new(),
            changed: false,
            path: "target.ron".into(),
            saved: None,
        }
    }
}

/// The tooth's mesial, buccal and occlusal axes at `pose` (world) and its crown centre there.
fn frame(t: &PlacedTooth, pose: &Pose) -> ([Vec3; 3], Vec3) {
    (
        t.anatomical_axes_at(pose),
        pose.transform_point(t.geometry.frame.crown_centre),
    )
}

/// Moves tooth `fdi` of the target by `amount` (mm, or degrees for a turn) of `handle`.
pub(super) fn nudge(target: &mut Target, d: &Dentition, fdi: Fdi, handle: Grip, amount: f32) {
    let (Some(t), Some(pose)) = (d.tooth(fdi), target.poses.get_mut(&fdi)) else {
        return;
    };
    let (axes, centre) = frame(t, pose);
    *pose = match handle {
        Grip::Move(i) => Pose::new(pose.rotation, pose.translation + axes[i] * amount),
        Grip::Turn(i) => {
            let turn = Quat::from_axis_angle(axes[i], amount.to_radians());
            Pose::turn_about(centre, turn).mul(pose)
        }
    };
}

/// The target as a target file: each tooth's movement from where the case has it (teeth that
/// do not move are left out).
pub(super) fn target_file(d: &Dentition, target: &Target) -> String {
    let mut map = ToothMap::<CaseOffset>(Default::default());
    for t in d.visible() {
        let Some(pose) = target.poses.get(&t.fdi) else {
            continue;
        };
        let o = t.offset_between(pose);
        let (a, b) = (o.translation, o.rotation_deg);
        let size = [a.0, a.1, a.2, b.0, b.1, b.2]
            .iter()
            .fold(0.0f32, |m, v| m.max(v.0.abs()));
        if size > 1e-4 {
            map.0.insert(t.fdi, o);
        }
    }
    let config = ron::ser::PrettyConfig::new().depth_limit(1);
    ron::ser::to_string_pretty(&map, config).unwrap_or_default()
}

/// Writes the target file; what to tell the user.
pub(super) fn save_target(d: &Dentition, target: &Target, path: &Path) -> String {
    match std::fs::write(path, target_file(d, target)) {
        Ok(()) => format!("wrote {}", path.display()),
        Err(e) => format!("cannot write {}: {e}", path.display()),
    }
}

/// Distance (pixels) from `p` to the segment `a`–`b`.
fn to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-6)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// How far (mm) dragging the cursor `from` → `to` moves a tooth along an arrow drawn on the
/// screen from `centre` to `tip` ([`HANDLE_MM`] long): the drag's share along the arrow.
fn move_amount(centre: Vec2, tip: Vec2, from: Vec2, to: Vec2) -> f32 {
    let along = tip - centre;
    let px = along.length().max(1.0);
    (to - from).dot(along / px) * HANDLE_MM / px
}

/// How far (degrees) dragging the cursor `from` → `to` turns a tooth about an axis through
/// `centre`: the angle swept about it, positive anticlockwise as seen when the axis points at the
/// viewer (`facing`; the right-hand rule), clockwise when it points away. Screen y runs down.
fn turn_amount(centre: Vec2, from: Vec2, to: Vec2, facing: bool) -> f32 {
    let (a, b) = (from - centre, to - centre);
    let swept = a.perp_dot(b).atan2(a.dot(b));
    if facing { -swept } else { swept }.to_degrees()
}

/// The exact gaps of tooth `fdi` at `pose` to the teeth near it at the target.
fn measure(d: &Dentition, target: &Target, fdi: Fdi, pose: &Pose) -> Vec<EditContact> {
    let Some(t) = d.tooth(fdi) else {
        return Vec::new();
    };
    let centre = pose.transform_point(t.geometry.frame.crown_centre);
    let mut found: Vec<EditContact> = d
        .visible()
        .filter(|o| o.fdi != fdi)
        .filter_map(|o| {
            let p = target.poses.get(&o.fdi).copied().unwrap_or(o.pose);
            if p.transform_point(o.geometry.frame.crown_centre)
                .distance(centre)
                > NEAR_MM
            {
                return None;
            }
            let s = mesh_separation(t.geometry.mesh_ref(), pose, o.geometry.mesh_ref(), &p);
            let gap_mm = s.signed_gap();
            (gap_mm <= SHOWN_GAP_MM).then_some(EditContact {
                other: o.fdi,
                gap_mm,
                points: [s.point_a, s.point_b],
            })
        })
        .collect();
    found.sort_by(|a, b| a.gap_mm.total_cmp(&b.gap_mm));
    found
}

/// The colour of a gap: red overlapping, yellow touching, green apart.
pub(super) fn gap_colour(gap: f32) -> [u8; 3] {
    if gap < 0.0 {
        [230, 60, 40]
    } else if gap <= TOUCH_MM {
        [240, 200, 40]
    } else {
        [80, 200, 100]
    }
}

/// True unless a target handle is being dragged: the camera may orbit.
pub(super) fn no_grab(view: Option<Res<PlanView>>) -> bool {
    view.is_none_or(|v| v.edit.grab.is_none())
}

/// Draws the selected tooth's handles, drags them, places the edited tooth and measures its
/// gaps (see the module doc).
#[allow(clippy::too_many_arguments)]
pub(super) fn target_handles(
    mut view: ResMut<PlanView>,
    selection: Res<Selection>,
    case: Option<Res<ActiveCase>>,
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    windows: Query<&Window>,
    cameras: Query<(&Camera, &GlobalTransform), With<Camera3d>>,
    wants: Option<Res<EguiWantsInput>>,
    mut teeth: Query<(&Tooth, &mut Transform)>,
    mut state: ResMut<SimulationState>,
    mut gizmos: Gizmos<HandleGizmos>,
) {
    let view = &mut *view;
    // Each press starts untaken; a handle below takes it.
    if buttons.just_pressed(MouseButton::Left) {
        view.edit.took_press = false;
    }
    if !view.edit.active || view.target.is_none() {
        view.edit.grab = None;
        view.edit.measured = None;
        view.edit.contacts.clear();
        return;
    }
    let Some(case) = case else {
        return;
    };
    let d = &case.0;
    let fdi = selection
        .0
        .first()
        .and_then(|e| teeth.get(*e).ok())
        .map(|(t, _)| t.id);
    let Some((fdi, t)) = fdi.and_then(|f| Some((f, d.tooth(f).filter(|t| !t.extracted)?))) else {
        view.edit.grab = None;
        view.edit.measured = None;
        view.edit.contacts.clear();
        return;
    };
    let Some(target) = view.target.as_mut() else {
        return;
    };
    let Some(&pose) = target.poses.get(&fdi) else {
        return;
    };
    let (axes, centre) = frame(t, &pose);
    let camera = cameras.iter().find(|(c, _)| c.is_active);
    let cursor = windows.iter().find_map(Window::cursor_position);
    // Each handle's outline on the screen.
    let ring = |i: usize, k: usize| {
        let turn = Quat::from_rotation_arc(Vec3::Z, axes[i]);
        let a = k as f32 / 48.0 * std::f32::consts::TAU;
        centre + turn * (Vec3::new(a.cos(), a.sin(), 0.0) * RING_MM)
    };
    let screen = |p: Vec3| camera.and_then(|(c, g)| c.world_to_viewport(g, p).ok());
    let near = |handle: Grip, at: Vec2| -> Option<f32> {
        match handle {
            Grip::Move(i) => Some(to_segment(
                at,
                screen(centre)?,
                screen(centre + axes[i] * HANDLE_MM)?,
            )),
            Grip::Turn(i) => (0..48)
                .filter_map(|k| Some(to_segment(at, screen(ring(i, k))?, screen(ring(i, k + 1))?)))
                .reduce(f32::min),
        }
    };
    let handles = [0, 1, 2]
        .map(Grip::Move)
        .into_iter()
        .chain([0, 1, 2].map(Grip::Turn));
    let egui_wants = wants.is_some_and(|w| w.wants_any_pointer_input());
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    if buttons.just_pressed(MouseButton::Left)
        && let Some(at) = cursor.filter(|_| !egui_wants && !shift)
    {
        let best = handles
            .clone()
            .filter_map(|h| Some((h, near(h, at)?)))
            .filter(|(_, px)| *px <= GRAB_PX)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((handle, _)) = best {
            view.edit.grab = Some(Grab { handle, cursor: at });
            view.edit.took_press = true;
        }
    }
    if !buttons.pressed(MouseButton::Left) {
        view.edit.grab = None;
    }
    if let (Some(mut grab), Some(at)) = (view.edit.grab, cursor)
        && at != grab.cursor
        && let (Some(c), Some(cam)) = (screen(centre), camera)
    {
        let amount = match grab.handle {
            Grip::Move(i) => {
                screen(centre + axes[i] * HANDLE_MM).map(|tip| move_amount(c, tip, grab.cursor, at))
            }
            Grip::Turn(i) => {
                let facing = axes[i].dot(cam.1.translation() - centre) > 0.0;
                Some(turn_amount(c, grab.cursor, at, facing))
            }
        };
        if let Some(amount) = amount.filter(|a| a.is_finite() && *a != 0.0) {
            nudge(target, d, fdi, grab.handle, amount);
            view.edit.changed = true;
        }
        grab.cursor = at;
        view.edit.grab = Some(grab);
    }
    let pose = target.poses[&fdi];
    // The edited tooth where the target has it, in the scene and the simulation.
    for (tooth, mut tf) in &mut teeth {
        if tooth.id == fdi && (tf.translation != pose.translation || tf.rotation != pose.rotation) {
            tf.translation = pose.translation;
            tf.rotation = pose.rotation;
            if let Some(sim) = state.sim.as_mut()
                && let Some(s) = sim.teeth.iter().position(|t| t.fdi == fdi)
            {
                sim.place_teeth(&[(s, pose)]);
            }
        }
    }
    if view.edit.measured != Some((fdi, pose)) {
        view.edit.contacts = measure(d, target, fdi, &pose);
        view.edit.measured = Some((fdi, pose));
    }
    let (axes, centre) = frame(t, &pose);
    let grabbed = view.edit.grab.map(|g| g.handle);
    for i in 0..3 {
        let colour = |h: Grip| {
            if grabbed == Some(h) {
                Color::WHITE
            } else {
                AXIS_COLOURS[i]
            }
        };
        gizmos.arrow(centre, centre + axes[i] * HANDLE_MM, colour(Grip::Move(i)));
        let turn = Quat::from_rotation_arc(Vec3::Z, axes[i]);
        gizmos
            .circle(
                Isometry3d::new(centre, turn),
                RING_MM,
                colour(Grip::Turn(i)),
            )
            .resolution(48);
    }
    for c in &view.edit.contacts {
        let [r, g, b] = gap_colour(c.gap_mm);
        let colour = Color::srgb_u8(r, g, b);
        gizmos.line(c.points[0], c.points[1], colour);
        gizmos.sphere(Isometry3d::from_translation(c.points[1]), 0.15, colour);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::{PlanLimits, automatic, from_offsets, target::read_target};
    use crate::teeth::Case;

    #[test]
    fn dragging_maps_to_movement_along_and_about_the_handles() {
        let c = Vec2::new(100.0, 100.0);
        // An arrow drawn 60 px long: dragging 30 px along it is half the arrow, 30 px across
        // it nothing.
        let tip = Vec2::new(160.0, 100.0);
        let half = move_amount(c, tip, Vec2::new(120.0, 90.0), Vec2::new(150.0, 90.0));
        assert!((half - 0.5 * HANDLE_MM).abs() < 1e-5, "{half}");
        assert_eq!(move_amount(c, tip, c, Vec2::new(100.0, 130.0)), 0.0);
        // A quarter turn up from the right of the centre (anticlockwise as seen) is +90° about
        // an axis pointing at the viewer and −90° about one pointing away.
        let (from, to) = (Vec2::new(130.0, 100.0), Vec2::new(100.0, 70.0));
        assert!((turn_amount(c, from, to, true) - 90.0).abs() < 1e-3);
        assert!((turn_amount(c, from, to, false) + 90.0).abs() < 1e-3);
        assert_eq!(turn_amount(c, from, from, true), 0.0);
        assert!((to_segment(Vec2::new(130.0, 110.0), c, tip) - 10.0).abs() < 1e-5);
        assert!((to_segment(Vec2::new(170.0, 100.0), c, tip) - 10.0).abs() < 1e-5);
    }

    #[test]
    fn an_edited_target_moves_the_tooth_and_saves_as_a_target_file_that_reads_back() {
        let d = Dentition::build(Case::resolve("crowded").unwrap()).unwrap();
        let mut target = automatic(&d, &PlanLimits::default());
        let f = Fdi::new(42).unwrap();
        let t = d.tooth(f).unwrap();
        let before = target.poses[&f];
        let ([mesial, _, occlusal], centre) = frame(t, &before);
        nudge(&mut target, &d, f, Grip::Move(0), 0.5);
        let moved = target.poses[&f];
        let (_, c) = frame(t, &moved);
        assert!((c - centre - mesial * 0.5).length() < 1e-4);
        nudge(&mut target, &d, f, Grip::Turn(2), 10.0);
        let turned = target.poses[&f];
        let (axes, c2) = frame(t, &turned);
        assert!(c2.distance(c) < 1e-4, "turns about the crown centre");
        assert!(
            (axes[2].dot(occlusal) - 1.0).abs() < 1e-4,
            "about the occlusal axis"
        );
        assert!((turned.rotation.angle_between(moved.rotation).to_degrees() - 10.0).abs() < 0.01);
        // Saved, read back as `orthosim plan --target` reads it, and made a target again.
        let path = std::env::temp_dir().join(format!("orthosim-edit-{}.ron", std::process::id()));
        assert!(save_target(&d, &target, &path).starts_with("wrote"));
        let map = read_target(&path, &d).unwrap();
        let again = from_offsets(&d, &map);
        for (fdi, pose) in &target.poses {
            let p = again.poses[fdi];
            assert!(p.translation.distance(pose.translation) < 2e-3, "{fdi}");
            assert!(
                p.rotation.angle_between(pose.rotation).to_degrees() < 0.02,
                "{fdi}"
            );
        }
        let _ = std::fs::remove_file(path);
    }
}
