//! A tooth's periodontal ligament as a layer of springs over the root below the alveolar crest
//! (a Winkler foundation), integrated over the root triangles into a 6×6 stiffness; from it the
//! centre of resistance, the compliance and the bilinear initial displacement.
//!
//! Each root surface element dA with outward normal n resists a displacement δ with the force
//! −(k_t δ + (k_n − k_t)(n·δ) n) dA. A rigid motion (u, θ) about a point c moves a root point p
//! by δ = u + θ × (p − c), so the stiffness about c is K = ∫ Jᵀ S J dA with J = [I, −[p − c]×]
//! and S = k_t I + (k_n − k_t) n nᵀ. The integrand is quadratic in p and n is constant on a
//! triangle, so the three-edge-midpoint rule is exact: the stiffness is exact for the mesh (up
//! to rounding), with triangles crossing the crest clipped at it.
//!
//! Centre of resistance: a 3D root has no single point where every force translates without
//! rotation; orthosim takes the centre of elasticity, the point c about which the coupling block
//! of K is symmetric. It solves (tr(A) I − A) c = v, where A is the translational block and v
//! the axial vector of Bᵀ − B for the coupling block B about the tooth's origin. For a root with
//! an axis of symmetry it is the point on the axis where a force across the axis translates the
//! tooth; for a real root, a force across the axis through it turns the tooth by a few percent of
//! what it does at the bracket (tested under 2 %).

use glam::{DMat3, DVec3, Vec3};
use thiserror::Error;

use super::settings::PdlSettings;
use crate::{
    geometry::{Mat6, MeshRef, TriMesh, Vec6, halves, ray::ray_first_hit, vec6},
    teeth::{ToothFrame, ToothGeometry},
};

/// A tooth whose ligament cannot be made.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum PdlError {
    /// Nothing of the root lies below the alveolar crest.
    #[error(
        "no root below the alveolar crest ({crest_mm:.2} mm below the cervical line; the root reaches {root_mm:.2} mm): the periodontal ligament has nothing to hold"
    )]
    NoRoot {
        /// Crest depth below the cervical line (mm).
        crest_mm: f32,
        /// How deep the root reaches below the cervical line (mm).
        root_mm: f32,
    },
    /// The ligament's stiffness is singular (a root too thin or flat to resist every motion).
    #[error("the ligament's stiffness is singular: the root below the crest cannot hold the tooth")]
    Singular,
}

/// One quadrature point of the root surface below the crest (tooth frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootPoint {
    /// Position (mm).
    pub position: DVec3,
    /// Outward unit normal.
    pub normal: DVec3,
    /// Area it stands for (mm²).
    pub area: f64,
}

/// The quadrature points of the root surface below `crest_level` (along `axis` from `origin`;
/// negative: apical), three per (clipped) triangle.
pub fn root_points(mesh: &TriMesh, origin: Vec3, axis: Vec3, crest_level: f32) -> Vec<RootPoint> {
    let (origin, axis, crest) = (origin.as_dvec3(), axis.as_dvec3(), crest_level as f64);
    let mut out = Vec::new();
    for i in 0..mesh.triangles.len() {
        let tri = mesh.triangle(i).map(|v| v.as_dvec3());
        let cross = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        let Some(normal) = cross.try_normalize() else {
            continue;
        };
        let level = |p: DVec3| (p - origin).dot(axis) - crest;
        // The part of the triangle at or below the crest (Sutherland–Hodgman on one plane).
        let mut poly: Vec<DVec3> = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let (la, lb) = (level(a), level(b));
            if la <= 0.0 {
                poly.push(a);
            }
            if (la < 0.0 && lb > 0.0) || (la > 0.0 && lb < 0.0) {
                poly.push(a + (b - a) * (la / (la - lb)));
            }
        }
        for k in 1..poly.len().saturating_sub(1) {
            let (a, b, c) = (poly[0], poly[k], poly[k + 1]);
            let area = 0.5 * (b - a).cross(c - a).length();
            if area <= 0.0 {
                continue;
            }
            for p in [(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5] {
                out.push(RootPoint {
                    position: p,
                    normal,
                    area: area / 3.0,
                });
            }
        }
    }
    out
}

fn skew(d: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, d.z, -d.y),
        DVec3::new(-d.z, 0.0, d.x),
        DVec3::new(d.y, -d.x, 0.0),
    )
}

fn set_block(m: &mut Mat6, r: usize, c: usize, b: DMat3) {
    for j in 0..3 {
        let col = b.col(j);
        for i in 0..3 {
            m.0[3 * r + i][3 * c + j] += col[i];
        }
    }
}

/// The stiffness about `centre` of springs `(kn, kt)` per area at `points`, with `scale(k)`
/// multiplying point k's springs (1 for a linear ligament).
pub fn stiffness_about(
    points: &[RootPoint],
    centre: DVec3,
    kn: f64,
    kt: f64,
    scale: impl Fn(usize) -> f64,
) -> Mat6 {
    let (mut a, mut b, mut c) = (DMat3::ZERO, DMat3::ZERO, DMat3::ZERO);
    for (k, p) in points.iter().enumerate() {
        let w = p.area * scale(k);
        let n = p.normal;
        let s = DMat3::from_diagonal(DVec3::splat(kt))
            + DMat3::from_cols(n * n.x, n * n.y, n * n.z) * (kn - kt);
        let x = skew(p.position - centre);
        let sw = s * w;
        a += sw;
        b -= sw * x;
        c -= x * sw * x;
    }
    let mut m = Mat6::ZERO;
    set_block(&mut m, 0, 0, a);
    set_block(&mut m, 0, 1, b);
    set_block(&mut m, 1, 0, b.transpose());
    set_block(&mut m, 1, 1, c);
    m
}

/// The centre of elasticity of a stiffness `k` given about `origin` (see the module doc).
pub fn centre_of_elasticity(k: &Mat6, origin: DVec3) -> Option<DVec3> {
    let a = k.block(0, 0);
    let b = k.block(0, 1);
    let w = b.transpose() - b;
    let v = DVec3::new(w.col(1).z, w.col(2).x, w.col(0).y);
    let trace = a.col(0).x + a.col(1).y + a.col(2).z;
    let m = DMat3::from_diagonal(DVec3::splat(trace)) - a;
    if m.determinant().abs() <= 1e-18 * trace.powi(3).max(f64::MIN_POSITIVE) {
        return None;
    }
    Some(origin + m.inverse() * v)
}

/// A tooth's ligament: stiffness and compliance about its centre of resistance, in the tooth's
/// frame, with the places loads act at.
#[derive(Clone, Debug, PartialEq)]
pub struct PdlStiffness {
    /// Stiffness about the centre of resistance (N/mm, N/rad, N·mm/rad blocks).
    pub stiffness: Mat6,
    /// Its inverse: the initial twist (mm, rad) per wrench (N, N·mm) at the centre of resistance.
    pub compliance: Mat6,
    /// Centre of resistance (tooth frame).
    pub centre_of_resistance: Vec3,
    /// The bracket: on the buccal crown surface at the configured height (tooth frame).
    pub bracket: Vec3,
    /// Level of the alveolar crest along the long axis from the cervical centre (mm, negative).
    pub crest_level: f32,
    /// Root length below the crest, along the long axis (mm).
    pub root_below_crest_mm: f32,
    /// Root area held by the ligament (mm²).
    pub root_area_mm2: f64,
    /// Mean spring stiffness per area, (k_n + 2 k_t)/3 (N/mm³), for the ligament pressure.
    pub mean_spring: f64,
    /// Up to [`ROOT_SAMPLES`] points of the root below the crest, spread over it (tooth frame):
    /// where the bone's plates are checked.
    pub root_samples: Vec<Vec3>,
}

/// Most root points checked against the bone's plates per tooth.
pub const ROOT_SAMPLES: usize = 48;

/// Up to [`ROOT_SAMPLES`] points spread over the root of `geometry` below a crest `crest_mm`
/// below its cervical line (tooth frame), as [`PdlStiffness::root_samples`].
pub fn root_samples(geometry: &ToothGeometry, crest_mm: f32) -> Vec<Vec3> {
    let f = &geometry.frame;
    let points = root_points(&geometry.mesh, f.cervical_centre, f.long_axis, -crest_mm);
    spread(
        &points
            .iter()
            .map(|p| p.position.as_vec3())
            .collect::<Vec<_>>(),
        ROOT_SAMPLES,
    )
}

/// Up to `n` of `points` spread over them: farthest-point sampling from the first.
fn spread(points: &[Vec3], n: usize) -> Vec<Vec3> {
    let Some(&first) = points.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut nearest: Vec<f32> = points.iter().map(|p| p.distance_squared(first)).collect();
    while out.len() < n {
        let (k, &d) = nearest
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("points are not empty");
        if d <= 0.0 {
            break;
        }
        let p = points[k];
        out.push(p);
        for (q, m) in points.iter().zip(nearest.iter_mut()) {
            *m = m.min(q.distance_squared(p));
        }
    }
    out
}

impl PdlStiffness {
    /// The ligament of `geometry` under `settings`: one pass over the root triangles for the
    /// centre of resistance, one for the stiffness about it.
    ///
    /// # Errors
    /// [`PdlError::NoRoot`] when no root lies below the crest; [`PdlError::Singular`] when the
    /// root cannot resist every rigid motion.
    pub fn of(geometry: &ToothGeometry, settings: &PdlSettings) -> Result<Self, PdlError> {
        let crest_mm = settings.crest_mm.of(geometry.kind);
        Self::of_mesh(geometry.mesh_ref(), &geometry.frame, crest_mm, settings)
    }

    /// [`PdlStiffness::of`] for a mesh, its frame and a crest depth (mm below the cervical line).
    ///
    /// # Errors
    /// As [`PdlStiffness::of`].
    pub fn of_mesh(
        m: MeshRef,
        frame: &ToothFrame,
        crest_mm: f32,
        settings: &PdlSettings,
    ) -> Result<Self, PdlError> {
        let axis = frame.long_axis;
        let origin = frame.cervical_centre;
        let crest_level = -crest_mm;
        let root_mm = frame.root_length;
        let points = root_points(m.mesh, origin, axis, crest_level);
        let root_area_mm2: f64 = points.iter().map(|p| p.area).sum();
        if root_mm <= crest_mm || root_area_mm2 <= 1e-6 {
            return Err(PdlError::NoRoot { crest_mm, root_mm });
        }
        let (kn, kt) = settings.layer_stiffness(settings.youngs_modulus_mpa);
        let about_origin = stiffness_about(&points, origin.as_dvec3(), kn, kt, |_| 1.0);
        let cres =
            centre_of_elasticity(&about_origin, origin.as_dvec3()).ok_or(PdlError::Singular)?;
        let stiffness = stiffness_about(&points, cres, kn, kt, |_| 1.0);
        let compliance = stiffness.inverse().ok_or(PdlError::Singular)?;
        let crown_height = frame.crown_length * settings.bracket_height;
        let from = origin + axis * crown_height;
        let bracket = ray_first_hit(m, from, frame.buccolingual, 0.0)
            .map_or(frame.crown_centre, |t| from + frame.buccolingual * t);
        Ok(Self {
            stiffness,
            compliance,
            centre_of_resistance: cres.as_vec3(),
            bracket,
            crest_level,
            root_below_crest_mm: root_mm - crest_mm,
            root_area_mm2,
            mean_spring: (kn + 2.0 * kt) / 3.0,
            root_samples: spread(
                &points
                    .iter()
                    .map(|p| p.position.as_vec3())
                    .collect::<Vec<_>>(),
                ROOT_SAMPLES,
            ),
        })
    }

    /// Mean ligament pressure (kPa) a wrench `w` at the centre of resistance causes, taken from
    /// the elastic energy: √(wᵀ C w · k̄ / A) (for a force through the centre of resistance on
    /// a uniform ligament, the force over the root area).
    pub fn pressure_kpa(compliance: &Mat6, mean_spring: f64, area: f64, w: &Vec6) -> f64 {
        (compliance.quadratic(w).max(0.0) * mean_spring / area).sqrt() * 1e3
    }

    /// Where the tooth turns under the initial twist `t` (about the centre of resistance): the
    /// distance along the long axis from the centre of resistance, positive apical, of the axis
    /// point that moves least (least squares); None for a translation.
    pub fn centre_of_rotation_along_axis(t: &Vec6, axis: DVec3) -> Option<f64> {
        let (u, theta) = halves(t);
        let g = theta.cross(axis);
        let gg = g.length_squared();
        (gg > 1e-30 * u.length_squared().max(1e-30)).then(|| u.dot(g) / gg)
    }

    /// Initial twist (tooth frame, about the centre of resistance) under a wrench `w` (about the
    /// centre of resistance) for a bilinear ligament: secant iterations, each spring's modulus
    /// set from its strain |δ|/t, until the twist changes by less than 10⁻⁹ of itself.
    pub fn bilinear_twist(
        &self,
        mesh: &TriMesh,
        frame: &ToothFrame,
        settings: &PdlSettings,
        w: &Vec6,
    ) -> Option<Vec6> {
        let points = root_points(
            mesh,
            frame.cervical_centre,
            frame.long_axis,
            self.crest_level,
        );
        let cres = self.centre_of_resistance.as_dvec3();
        let (kn, kt) = settings.layer_stiffness(settings.youngs_modulus_mpa);
        let (e1, e2) = (
            settings.youngs_modulus_mpa as f64,
            settings.youngs_modulus_past_knee_mpa as f64,
        );
        let knee = settings.knee_strain as f64;
        let t = settings.thickness_mm as f64;
        let mut scale = vec![1.0; points.len()];
        let mut twist = self.compliance.mul_vec(w);
        for _ in 0..100 {
            let (u, theta) = halves(&twist);
            for (s, p) in scale.iter_mut().zip(&points) {
                let strain = (u + theta.cross(p.position - cres)).length() / t;
                *s = if strain <= knee {
                    1.0
                } else {
                    (e1 * knee + e2 * (strain - knee)) / (strain * e1)
                };
            }
            let k = stiffness_about(&points, cres, kn, kt, |i| scale[i]);
            let next = k.solve(w)?;
            let change: f64 = next.iter().zip(&twist).map(|(a, b)| (a - b).abs()).sum();
            let size: f64 = next.iter().map(|a| a.abs()).sum();
            twist = next;
            if change <= 1e-9 * size {
                break;
            }
        }
        Some(twist)
    }
}

/// The twist (about the centre of resistance) as a displacement of point `p`.
pub fn displacement_at(t: &Vec6, cres: DVec3, p: DVec3) -> DVec3 {
    let (u, theta) = halves(t);
    u + theta.cross(p - cres)
}

/// The wrench about `centre` of a force `f` at `at` and a couple `m`.
pub fn wrench(f: DVec3, at: DVec3, m: DVec3, centre: DVec3) -> Vec6 {
    vec6(f, m + (at - centre).cross(f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{Arch, ToothKind, ToothResolution};

    fn incisor() -> ToothGeometry {
        ToothGeometry::procedural(
            Arch::Upper,
            ToothKind::CentralIncisor,
            ToothResolution { vertices: 2000 },
        )
    }

    #[test]
    fn a_force_through_the_centre_of_resistance_translates_the_tooth() {
        let g = incisor();
        let s = PdlSettings::default();
        let p = PdlStiffness::of(&g, &s).unwrap();
        let lingual = -g.frame.buccolingual.as_dvec3();
        let c = p.centre_of_resistance.as_dvec3();
        let h = p.root_below_crest_mm as f64;
        // A root with different tapers mesiodistally and labiolingually has no single point that
        // translates under every force: through the centre of elasticity a force across the axis
        // turns the tooth by under 2 % of what it does at the bracket.
        for dir in [lingual, g.frame.mesiodistal.as_dvec3()] {
            let t = p.compliance.mul_vec(&vec6(dir, DVec3::ZERO));
            let (u, theta) = halves(&t);
            let at_bracket =
                p.compliance
                    .mul_vec(&wrench(dir, p.bracket.as_dvec3(), DVec3::ZERO, c));
            assert!(u.dot(dir) > 0.0);
            assert!(
                theta.length() < 0.02 * halves(&at_bracket).1.length(),
                "{u} {theta}"
            );
        }
        // The same force at the bracket tips the crown lingually and the apex labially.
        let w = wrench(lingual, p.bracket.as_dvec3(), DVec3::ZERO, c);
        let t = p.compliance.mul_vec(&w);
        let crown = displacement_at(&t, c, p.bracket.as_dvec3());
        let apex = displacement_at(&t, c, g.frame.apex.as_dvec3());
        assert!(crown.dot(lingual) > 0.0 && apex.dot(lingual) < 0.0);
        let y = PdlStiffness::centre_of_rotation_along_axis(&t, g.frame.long_axis.as_dvec3());
        assert!(y.is_some_and(|y| y > 0.0 && y < h), "{y:?}");
        // A counter-couple past the bracket's distance puts the centre of rotation occlusal.
        let axis = g.frame.long_axis.as_dvec3();
        let couple = -axis.cross(lingual) * 20.0;
        let t = p
            .compliance
            .mul_vec(&wrench(lingual, p.bracket.as_dvec3(), couple, c));
        let y = PdlStiffness::centre_of_rotation_along_axis(&t, axis);
        assert!(y.is_some_and(|y| y < 0.0), "{y:?}");
    }

    #[test]
    fn the_stiffness_is_symmetric_and_its_inverse_is_the_compliance() {
        let g = incisor();
        let p = PdlStiffness::of(&g, &PdlSettings::default()).unwrap();
        for r in 0..6 {
            for c in 0..6 {
                let (a, b) = (p.stiffness.0[r][c], p.stiffness.0[c][r]);
                assert!((a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0));
                let id: f64 = (0..6)
                    .map(|k| p.stiffness.0[r][k] * p.compliance.0[k][c])
                    .sum();
                assert!(
                    (id - if r == c { 1.0 } else { 0.0 }).abs() < 1e-8,
                    "{r} {c} {id}"
                );
            }
            assert!(p.stiffness.0[r][r] > 0.0);
        }
        // About the centre of resistance the coupling block is symmetric.
        let b = p.stiffness.block(0, 1);
        assert!((b - b.transpose()).abs_diff_eq(DMat3::ZERO, 1e-6 * p.stiffness.0[0][0]));
    }

    #[test]
    fn the_crest_decides_the_root_that_holds_the_tooth() {
        let g = incisor();
        let at = |crest: f32| {
            let mut s = PdlSettings::default();
            s.crest_mm.incisor = crest;
            PdlStiffness::of(&g, &s)
        };
        let (shallow, deep) = (at(0.5).unwrap(), at(4.0).unwrap());
        assert!(deep.root_area_mm2 < shallow.root_area_mm2);
        assert!(deep.centre_of_resistance.y < shallow.centre_of_resistance.y);
        // Less root: more compliant.
        assert!(deep.compliance.0[2][2] > shallow.compliance.0[2][2]);
        let e = at(g.frame.root_length + 0.5).unwrap_err();
        assert!(matches!(e, PdlError::NoRoot { .. }), "{e}");
        assert!(e.to_string().contains("no root below the alveolar crest"));
    }

    #[test]
    fn a_bilinear_ligament_stiffens_past_its_knee() {
        let g = incisor();
        let s = PdlSettings::default();
        let p = PdlStiffness::of(&g, &s).unwrap();
        let lingual = -g.frame.buccolingual.as_dvec3();
        let c = p.centre_of_resistance.as_dvec3();
        let at = |n: f64| {
            let w = wrench(lingual * n, p.bracket.as_dvec3(), DVec3::ZERO, c);
            let linear = displacement_at(&p.compliance.mul_vec(&w), c, p.bracket.as_dvec3());
            let bilinear = p.bilinear_twist(&g.mesh, &g.frame, &s, &w).unwrap();
            (
                linear.length(),
                displacement_at(&bilinear, c, p.bracket.as_dvec3()).length(),
            )
        };
        // Tiny load: every spring below the knee, as linear.
        let (l, b) = at(0.001);
        assert!((l - b).abs() <= 1e-6 * l.max(1e-12), "{l} {b}");
        // 5 N: stiffer than linear, but no stiffer than the modulus past the knee allows.
        let (l, b) = at(5.0);
        let ratio = (s.youngs_modulus_past_knee_mpa / s.youngs_modulus_mpa) as f64;
        assert!(b < l && b > l / ratio, "{l} {b}");
        // A linear ligament (equal moduli) does not stiffen.
        let linear = PdlSettings {
            youngs_modulus_past_knee_mpa: s.youngs_modulus_mpa,
            ..s
        };
        let w = wrench(lingual * 5.0, p.bracket.as_dvec3(), DVec3::ZERO, c);
        let t = p.bilinear_twist(&g.mesh, &g.frame, &linear, &w).unwrap();
        let lin = p.compliance.mul_vec(&w);
        assert!(
            t.iter()
                .zip(&lin)
                .all(|(a, b)| (a - b).abs() <= 1e-6 * b.abs().max(1e-9))
        );
    }
}
