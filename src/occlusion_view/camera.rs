//! The orbit camera and its presets (frontal, right, left, maxillary and mandibular occlusal).

use bevy::{
    input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll, MouseScrollUnit},
    prelude::*,
};

/// An orbit camera around a focus point, in the paper's frame (y up, +z anterior).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    /// Point looked at (mm).
    pub focus: Vec3,
    /// Distance from the focus (mm).
    pub distance: f32,
    /// Angle about the vertical axis (radians, 0 = looking from the front).
    pub yaw: f32,
    /// Angle above the occlusal plane (radians).
    pub pitch: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        CameraPreset::Frontal.orbit()
    }
}

/// The standard clinical views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CameraPreset {
    /// From the front, teeth in occlusion.
    #[default]
    Frontal,
    /// From the patient's right.
    Right,
    /// From the patient's left.
    Left,
    /// Looking up at the upper arch.
    Maxillary,
    /// Looking down at the lower arch.
    Mandibular,
}

impl CameraPreset {
    /// Every view, in key order (1–5).
    pub const ALL: [CameraPreset; 5] = [
        CameraPreset::Frontal,
        CameraPreset::Right,
        CameraPreset::Left,
        CameraPreset::Maxillary,
        CameraPreset::Mandibular,
    ];

    /// The view's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CameraPreset::Frontal => "frontal",
            CameraPreset::Right => "right",
            CameraPreset::Left => "left",
            CameraPreset::Maxillary => "maxillary",
            CameraPreset::Mandibular => "mandibular",
        }
    }

    /// The orbit of this view.
    pub fn orbit(self) -> OrbitCamera {
        let (yaw, pitch) = match self {
            CameraPreset::Frontal => (0.0, 0.05),
            CameraPreset::Right => (-std::f32::consts::FRAC_PI_2, 0.05),
            CameraPreset::Left => (std::f32::consts::FRAC_PI_2, 0.05),
            CameraPreset::Maxillary => (0.0, -1.5),
            CameraPreset::Mandibular => (0.0, 1.5),
        };
        OrbitCamera {
            focus: Vec3::new(0.0, 0.0, 0.0),
            distance: 95.0,
            yaw,
            pitch,
        }
    }

    /// Transform of a camera on `orbit`.
    pub fn transform(orbit: &OrbitCamera) -> Transform {
        let dir = Vec3::new(
            orbit.yaw.sin() * orbit.pitch.cos(),
            orbit.pitch.sin(),
            orbit.yaw.cos() * orbit.pitch.cos(),
        );
        let eye = orbit.focus + dir * orbit.distance;
        // Near-vertical views keep the anterior teeth at the top of the screen.
        let up = if orbit.pitch.abs() > 1.2 {
            -Vec3::Z * orbit.pitch.signum()
        } else {
            Vec3::Y
        };
        Transform::from_translation(eye).looking_at(orbit.focus, up)
    }
}

impl std::fmt::Display for CameraPreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The view the camera starts in.
#[derive(Resource, Clone, Copy, Debug)]
pub(super) struct InitialView(pub CameraPreset);

/// The orbit camera, in the initial view.
pub(super) fn spawn_orbit_camera(mut commands: Commands, initial: Res<InitialView>) {
    let orbit = initial.0.orbit();
    commands.spawn((
        Name::new("orbit camera"),
        Camera3d::default(),
        CameraPreset::transform(&orbit),
        orbit,
    ));
}

/// A key light from the upper front right and a fill light from below.
pub(super) fn spawn_lights(mut commands: Commands) {
    commands.spawn((
        Name::new("key light"),
        DirectionalLight {
            illuminance: 9000.0,
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::from_xyz(40.0, 80.0, 120.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Name::new("fill light"),
        DirectionalLight {
            illuminance: 3500.0,
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::from_xyz(-60.0, -80.0, 40.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

pub(super) fn camera_presets(
    keys: Res<ButtonInput<KeyCode>>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    let preset = [
        (KeyCode::Digit1, CameraPreset::Frontal),
        (KeyCode::Digit2, CameraPreset::Right),
        (KeyCode::Digit3, CameraPreset::Left),
        (KeyCode::Digit4, CameraPreset::Maxillary),
        (KeyCode::Digit5, CameraPreset::Mandibular),
    ]
    .into_iter()
    .find(|(k, _)| keys.just_pressed(*k));
    if let Some((_, p)) = preset {
        for mut orbit in &mut cameras {
            *orbit = p.orbit();
        }
    }
}

pub(super) fn orbit_camera(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut cameras: Query<(&mut OrbitCamera, &mut Transform)>,
) {
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    let pan = buttons.pressed(MouseButton::Middle) || (shift && buttons.pressed(MouseButton::Left));
    let rotate =
        !pan && (buttons.pressed(MouseButton::Left) || buttons.pressed(MouseButton::Right));
    let zoom = match scroll.unit {
        MouseScrollUnit::Line => scroll.delta.y,
        MouseScrollUnit::Pixel => scroll.delta.y / 40.0,
    };
    for (mut orbit, mut transform) in &mut cameras {
        if rotate {
            orbit.yaw -= motion.delta.x * 0.008;
            orbit.pitch = (orbit.pitch + motion.delta.y * 0.008).clamp(-1.55, 1.55);
        }
        if pan {
            let right = transform.right();
            let up = transform.up();
            let scale = orbit.distance * 0.0015;
            orbit.focus += (-right * motion.delta.x + up * motion.delta.y) * scale;
        }
        if zoom != 0.0 {
            orbit.distance = (orbit.distance * (1.0 - 0.1 * zoom)).clamp(15.0, 600.0);
        }
        if orbit.is_changed() {
            *transform = CameraPreset::transform(&orbit);
        }
    }
}
