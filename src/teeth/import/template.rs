//! Template roots: the procedural tooth of a scanned crown's FDI number ([`ToothSolid`]), fitted
//! to the crown, tells where its root goes.
//!
//! A scan sees the crown above the gum only. The root a crown gets follows the template's long
//! axis and reaches the template's apex, with the template's cross-sections below the collar
//! (and its two or three roots where it has them), so roots follow the tooth's
//! anatomy instead of the margin's normal (which a scalloped or bleeding gum line tilts by tens of
//! degrees). [`super::sweep::close_with_template`] builds the root from a [`Fit`].
//!
//! Fit: the template's surface (a mesh of [`TEMPLATE_VERTICES`] vertices) is brought onto the
//! scanned crown by iterative closest points: each of up to [`SAMPLES`] crown vertices is paired
//! with the nearest point of the template (crown points find their match even though the scan
//! holds only part of the template's crown), then a rigid step minimises the point-to-plane
//! distances (linearised, least squares) and a scale step fits the template's widths about its
//! cervical centre, each within [`SCALE_LIMITS`] (anatomical variation), for [`ITERATIONS`]
//! rounds. Pairs farther than three times the median distance are left out of each step (labels
//! bleeding into gum or a neighbour are not the crown). The fit starts from the arrangement's pose
//! of the tooth and from the margin's axis when that pose is known, else from the margin's axis
//! turned four ways about itself; the start that ends nearest the crown wins.
//!
//! Guarantee: none about the fit's quality beyond its reported rms distance; the root built from
//! it is checked exactly like every other root, and the cone root is the fallback.

use std::sync::Arc;

use glam::{DVec3, Mat3, Quat, Vec3};

use super::super::{
    anatomy::{ToothAnatomy, anatomy},
    fdi::{Arch, Fdi, ToothKind},
    memo::Memo,
    shape::{ToothResolution, ToothSolid},
};
use crate::geometry::{
    Mat6, MeshRef, Pose, TriMesh, TriangleBvh, Vec6, closest_point_and_triangle, halves, vec6,
};

/// Vertices of the template mesh the crown is fitted to.
pub const TEMPLATE_VERTICES: u32 = 1_500;
/// Most crown vertices the fit pairs with the template.
pub const SAMPLES: usize = 400;
/// Rounds of the fit.
pub const ITERATIONS: usize = 16;
/// Least and greatest scale of the template's mesiodistal (x), cervico-occlusal (y) and
/// buccolingual (z) axes. The long axis keeps the anatomy table's length: a scan holds the crown
/// from the gum up, so its height says little about where the cementoenamel junction is, and a
/// free height scale trades off against the fit's shift along the axis (on crowns cut from the
/// templates themselves it lengthened roots by 8 %).
pub const SCALE_LIMITS: [(f32, f32); 3] = [(0.75, 1.3), (1.0, 1.0), (0.75, 1.3)];

/// Farthest (mm, root mean square) a crown may lie from its fitted template for the template's
/// root to be used.
pub const MAX_FIT_RMS_MM: f32 = 1.0;
/// Where the margin's centre may lie relative to the fitted template's cementoenamel junction
/// (mm along the axis, positive occlusal): the gum line stands up to a few millimetres above it,
/// or a little below where the gum has receded. A fit outside this slid along the tooth.
pub const MARGIN_HEIGHT_MM: (f32, f32) = (-2.5, 5.0);

/// Why a crown gets no template root.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NoTemplate {
    /// The fit stays far from the crown.
    #[error("the crown lies {rms_mm:.2} mm (rms) from its template, more than {MAX_FIT_RMS_MM} mm")]
    TooFar {
        /// Root-mean-square distance (mm).
        rms_mm: f32,
    },
    /// The fit turned far from the arrangement's axis.
    #[error(
        "the fitted template's axis is {deg:.0}° from the arrangement's, more than {MAX_TURN_FROM_GUESS_DEG}°"
    )]
    Turned {
        /// Angle between the axes (degrees).
        deg: f32,
    },
    /// The fit slid along the tooth.
    #[error(
        "the fitted template's cementoenamel junction lies {height_mm:.1} mm apical of the margin's centre, outside {} to {} mm",
        MARGIN_HEIGHT_MM.0,
        MARGIN_HEIGHT_MM.1
    )]
    Slid {
        /// Where the margin's centre lies above the fitted junction (mm, negative below).
        height_mm: f32,
    },
    /// The crown has too few vertices to fit.
    #[error("too few vertices to fit a template")]
    TooFew,
    /// The template root was not asked for.
    #[error("the cone was asked for")]
    NotAsked,
    /// The template root could not be closed without meeting the crown.
    #[error("the template root could not be closed: {0}")]
    NotClosed(Box<super::error::ImportError>),
}

/// Largest angle (degrees) between the fitted template's axis and the axis of the tooth's pose in
/// the arrangement, when that is known: patients' teeth stand tipped and crowded, but a fit
/// turned farther than this went astray on a crown far from its type's shape.
pub const MAX_TURN_FROM_GUESS_DEG: f32 = 35.0;

/// A tooth type's template: its solid and a mesh of its surface with a hierarchy.
pub struct Template {
    /// The implicit solid (local frame: cervical centre at the origin, y occlusal, z buccal).
    pub solid: ToothSolid,
    /// Its anatomy (root length, widths).
    pub anatomy: ToothAnatomy,
    mesh: TriMesh,
    bvh: TriangleBvh,
}

impl Template {
    /// The shared template of a tooth type.
    pub fn of(arch: Arch, kind: ToothKind) -> Arc<Template> {
        static CACHE: Memo<(Arch, ToothKind), Template> = Memo::new();
        CACHE.get_or_build((arch, kind), || {
            let an = anatomy(arch, kind);
            let solid = ToothSolid::new(arch, kind, an);
            let mesh = solid.mesh(ToothResolution {
                vertices: TEMPLATE_VERTICES,
            });
            let bvh = TriangleBvh::build(&mesh);
            Template {
                solid,
                anatomy: an,
                mesh,
                bvh,
            }
        })
    }

    /// Nearest template surface point to `p` (local, unscaled) and the surface normal there.
    fn nearest(&self, p: Vec3) -> Option<(Vec3, Vec3)> {
        let m = MeshRef {
            mesh: &self.mesh,
            bvh: &self.bvh,
        };
        let (q, _, t) = closest_point_and_triangle(m, p)?;
        let [a, b, c] = self.mesh.triangle(t as usize);
        Some((q, (b - a).cross(c - a).normalize_or_zero()))
    }
}

/// The template placed on a crown: world = origin + rotation · (scale ⊙ local).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The template's orientation.
    pub rotation: Quat,
    /// Scale of the template's x, y and z axes.
    pub scale: Vec3,
    /// Where the template's cervical centre lands (world).
    pub origin: Vec3,
    /// Root-mean-square distance (mm) of the paired crown vertices to the fitted template.
    pub rms_mm: f32,
}

impl Fit {
    /// A template point (local) in the world.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.origin + self.rotation * (self.scale * local)
    }

    /// A world point in the template's (unscaled) local frame.
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        (self.rotation.inverse() * (world - self.origin)) / self.scale
    }

    /// The template's apical direction (unit, world): its long axis from crown to root.
    pub fn apical(&self) -> Vec3 {
        self.rotation * Vec3::NEG_Y
    }

    /// How far (mm) the margin's centre lies occlusal of the template's cervical centre, along the
    /// template's axis (the gum line stands on or above the cementoenamel junction).
    pub fn margin_height(&self, margin_centre: Vec3) -> f32 {
        (self.origin - margin_centre).dot(self.apical())
    }

    /// Whether the fit can carry a root: near enough the crown, its cementoenamel junction where
    /// the margin says.
    ///
    /// # Errors
    /// Why it cannot ([`NoTemplate`]).
    pub fn usable(&self, margin_centre: Vec3, guess: Option<Pose>) -> Result<(), NoTemplate> {
        if self.rms_mm > MAX_FIT_RMS_MM {
            return Err(NoTemplate::TooFar {
                rms_mm: self.rms_mm,
            });
        }
        if let Some(g) = guess {
            let deg = self
                .apical()
                .angle_between(g.rotation * Vec3::NEG_Y)
                .to_degrees();
            if deg > MAX_TURN_FROM_GUESS_DEG {
                return Err(NoTemplate::Turned { deg });
            }
        }
        let height_mm = self.margin_height(margin_centre);
        let (lo, hi) = MARGIN_HEIGHT_MM;
        if !(lo..=hi).contains(&height_mm) {
            return Err(NoTemplate::Slid { height_mm });
        }
        Ok(())
    }

    /// The template's root length (mm, scaled), from its cervical centre to its deepest apex.
    pub fn root_length(&self, template: &Template) -> f32 {
        template.anatomy.root_length * self.scale.y
    }
}

/// Fits `fdi`'s template to the scanned `crown` (world frame), starting from `guess` (the pose of
/// the tooth's local frame in the arrangement, when known) and from the margin's `centre` and
/// `apical` direction. None when the crown has too few vertices to fit.
pub fn fit(
    crown: &TriMesh,
    fdi: Fdi,
    guess: Option<Pose>,
    centre: Vec3,
    apical: Vec3,
) -> Option<Fit> {
    let template = Template::of(fdi.arch(), fdi.kind());
    let n = crown.vertices.len();
    if n < 12 {
        return None;
    }
    let stride = n.div_ceil(SAMPLES);
    let samples: Vec<Vec3> = crown.vertices.iter().step_by(stride).copied().collect();
    let mut starts: Vec<(Quat, Vec3)> = Vec::new();
    if let Some(g) = guess {
        starts.push((g.rotation, g.translation));
    }
    // From the margin: y against the apical direction, the origin a little below the margin's
    // centre (the gum stands above the cementoenamel junction), four turns about the axis.
    let y = -apical.normalize_or(Vec3::Y);
    let x0 = y.any_orthonormal_vector();
    // With the arrangement's pose to start from, one turn from the margin is enough to catch a
    // tooth the arrangement does not know well; without it, four.
    let turns = if guess.is_some() { 1 } else { 4 };
    for k in 0..turns {
        let turn = Quat::from_axis_angle(y, k as f32 * std::f32::consts::FRAC_PI_2);
        let x = turn * x0;
        let z = x.cross(y);
        let r = Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize();
        starts.push((r, centre - y));
    }
    starts
        .into_iter()
        .filter_map(|(r, o)| refine(&template, &samples, r, o))
        .min_by(|a, b| a.rms_mm.total_cmp(&b.rms_mm))
}

/// Iterative closest points from one start.
fn refine(template: &Template, samples: &[Vec3], rotation: Quat, origin: Vec3) -> Option<Fit> {
    let mut fit = Fit {
        rotation,
        scale: Vec3::ONE,
        origin,
        rms_mm: f32::INFINITY,
    };
    for round in 0..=ITERATIONS {
        // Pairs: each sample with its nearest template point (both world) and the normal there.
        let mut pairs: Vec<(Vec3, Vec3, Vec3, Vec3)> = Vec::with_capacity(samples.len());
        for &p in samples {
            let Some((q, n)) = template.nearest(fit.to_local(p)) else {
                continue;
            };
            let world = fit.to_world(q);
            let normal = (fit.rotation * (n / fit.scale)).normalize_or_zero();
            pairs.push((p, world, normal, q));
        }
        if pairs.len() < 12 {
            return None;
        }
        let mut d: Vec<f32> = pairs.iter().map(|(p, q, _, _)| p.distance(*q)).collect();
        let rms = (d.iter().map(|x| x * x).sum::<f32>() / d.len() as f32).sqrt();
        fit.rms_mm = rms;
        if round == ITERATIONS {
            break;
        }
        d.sort_by(f32::total_cmp);
        let limit = (3.0 * d[d.len() / 2]).max(0.05);
        pairs.retain(|(p, q, _, _)| p.distance(*q) <= limit);
        // Rigid step: point-to-plane, linearised about the pairs' centroid.
        let m: DVec3 =
            pairs.iter().map(|(_, q, _, _)| q.as_dvec3()).sum::<DVec3>() / pairs.len() as f64;
        let mut a = Mat6([[0.0; 6]; 6]);
        let mut b: Vec6 = [0.0; 6];
        for (p, q, n, _) in &pairs {
            let (p, q, n) = (p.as_dvec3(), q.as_dvec3(), n.as_dvec3());
            let row = vec6((q - m).cross(n), n);
            let r = n.dot(p - q);
            for i in 0..6 {
                b[i] += row[i] * r;
                for j in 0..6 {
                    a.0[i][j] += row[i] * row[j];
                }
            }
        }
        // A little damping keeps directions the crown does not pin (a round crown's turn about
        // its axis) where they are.
        let trace: f64 = (0..6).map(|i| a.0[i][i]).sum::<f64>() / 6.0;
        for i in 0..6 {
            a.0[i][i] += 1e-3 * trace + 1e-9;
        }
        let x = a.solve(&b)?;
        let (w, t) = halves(&x);
        let turn = Quat::from_scaled_axis(w.as_vec3());
        let m = m.as_vec3();
        fit.origin = m + turn * (fit.origin - m) + t.as_vec3();
        fit.rotation = (turn * fit.rotation).normalize();
        // Scale step: per template axis, least squares about the cervical centre.
        let inverse = fit.rotation.inverse();
        let (mut num, mut den) = (Vec3::ZERO, Vec3::ZERO);
        for (p, _, _, q) in &pairs {
            let target = inverse * (*p - fit.origin);
            num += *q * target;
            den += *q * *q;
        }
        let mut scale = fit.scale;
        for (k, (lo, hi)) in SCALE_LIMITS.iter().enumerate() {
            if den[k] > 1e-6 {
                let s = (num[k] / den[k]).clamp(*lo, *hi);
                scale[k] = 0.5 * (scale[k] + s);
            }
        }
        fit.scale = scale;
    }
    fit.rms_mm.is_finite().then_some(fit)
}

/// The template's cross-section at `depth` mm below its cervical centre along the world unit
/// `axis` (a direction close to the template's apical one): the distance from the section's
/// centre (where the template's long axis crosses the plane) to the outermost surface point in
/// each world direction `dirs` (unit, across `axis`), at least `min_mm`. Returns the centre too.
pub fn section(
    template: &Template,
    fit: &Fit,
    axis: Vec3,
    depth: f32,
    dirs: &[Vec3],
    min_mm: f32,
) -> (Vec3, Vec<f32>) {
    let apical = fit.apical();
    let along = apical.dot(axis).max(0.2);
    let centre = fit.origin + apical * (depth / along);
    let reaches = vec![reach_of(template, fit); dirs.len()];
    (
        centre,
        section_from(template, fit, centre, dirs, &reaches, min_mm),
    )
}

/// Distance (mm) beyond which no part of the fitted template lies from its axis.
pub fn reach_of(template: &Template, fit: &Fit) -> f32 {
    0.8 * (template
        .anatomy
        .mesiodistal
        .max(template.anatomy.buccolingual))
        * fit.scale.max_element()
        + 2.0
}

/// The distance from `centre` (world) to the fitted template's outermost surface point in each
/// world direction `dirs` (unit), looking no farther than `reaches` (mm, per direction), at least
/// `min_mm`.
pub fn section_from(
    template: &Template,
    fit: &Fit,
    centre: Vec3,
    dirs: &[Vec3],
    reaches: &[f32],
    min_mm: f32,
) -> Vec<f32> {
    let inside = |p: Vec3| template.solid.distance(fit.to_local(p)) < 0.0;
    dirs.iter()
        .zip(reaches)
        .map(|(&dir, &reach)| {
            // March inwards from the reach: the first point inside is on the outermost surface;
            // bisection then finds it to 0.01 mm.
            const STEP: f32 = 0.25;
            let mut outer = reach;
            let mut r = reach - STEP;
            while r > 0.0 && !inside(centre + dir * r) {
                outer = r;
                r -= STEP;
            }
            if r <= 0.0 {
                return min_mm;
            }
            let (mut lo, mut hi) = (r, outer);
            while hi - lo > 0.01 {
                let mid = 0.5 * (lo + hi);
                if inside(centre + dir * mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo.max(min_mm)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_template_fits_its_own_crown_where_it_stands() {
        // The crown of a lower canine, placed tilted and moved; the fit finds the pose back.
        let fdi = Fdi::new(43).unwrap();
        let template = Template::of(fdi.arch(), fdi.kind());
        let pose = Pose::new(
            Quat::from_euler(glam::EulerRot::XYZ, 0.2, 0.4, -0.15),
            Vec3::new(3.0, -1.0, 12.0),
        );
        let crown_only: Vec<Vec3> = template
            .mesh
            .vertices
            .iter()
            .filter(|v| v.y > 1.0)
            .map(|v| pose.transform_point(*v))
            .collect();
        let crown = TriMesh::new(crown_only, Vec::new());
        let apical = pose.rotation * Vec3::NEG_Y;
        // Start from a guess 10° and 1.5 mm off.
        let guess = Pose::new(
            Quat::from_axis_angle(Vec3::X, 0.17) * pose.rotation,
            pose.translation + Vec3::new(1.0, 0.5, -1.0),
        );
        let f = fit(&crown, fdi, Some(guess), pose.translation, apical).unwrap();
        assert!(f.rms_mm < 0.05, "{f:?}");
        let angle = f.apical().angle_between(apical).to_degrees();
        assert!(angle < 2.0, "axis off by {angle}°");
        assert!(f.origin.distance(pose.translation) < 0.3, "{f:?}");
        assert!((f.scale - Vec3::ONE).abs().max_element() < 0.05, "{f:?}");
    }

    #[test]
    fn a_molar_section_below_the_furcation_has_lobes() {
        // Lower first molar: mesial and distal roots; across the tooth mesiodistally the section
        // reaches far, between the roots (buccally at the middle) it is thin.
        let fdi = Fdi::new(36).unwrap();
        let template = Template::of(fdi.arch(), fdi.kind());
        let f = Fit {
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            origin: Vec3::ZERO,
            rms_mm: 0.0,
        };
        let rl = template.anatomy.root_length;
        let dirs = [Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::NEG_Z];
        let (_, r) = section(&template, &f, Vec3::NEG_Y, 0.8 * rl, &dirs, 0.2);
        assert!(r[0] > 3.0 && r[1] > 3.0, "{r:?}");
        assert!(r[2] < 1.0 && r[3] < 1.0, "{r:?}");
        // Near the cervix the trunk is one body.
        let (_, r) = section(&template, &f, Vec3::NEG_Y, 1.0, &dirs, 0.2);
        assert!(r.iter().all(|&x| x > 2.5), "{r:?}");
    }
}
