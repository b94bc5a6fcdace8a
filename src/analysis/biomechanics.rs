//! `orthosim validate`: the PDL model against published biomechanics, on the built-in anatomy.
//!
//! Each row is a quantity the literature measured, computed here from the teeth's meshes and
//! the ligament's parameters (nothing fitted per row), beside the published range. The rows and
//! their sources:
//!
//! | name | what | reference |
//! |---|---|---|
//! | `cres_from_crest` | centre of resistance, fraction of the root length below the crest, from the crest | 0.33–0.42 (Papageorgiou et al. 2005, review), 0.43 (FE); accepted 0.31–0.44 |
//! | `cres_to_furcation_mm` | upper first molar: centre of resistance above the trifurcation (+ occlusal) | 0.19 ± 1.75 mm (Dermaut et al. 1986, 50 molars) |
//! | `bracket_to_cres_mm` | distance d from the bracket to the centre of resistance along the long axis | — |
//! | `crot_from_cres_mm` | centre of rotation along the long axis (+ apical) under a lingual force at the bracket with a counter-couple M/F | the hyperbola y (d − M/F) = σ² (Nägerl & Burstone 1991; Choy et al. 2000), σ² as accepted below |
//! | `mf_translation` | M/F at the bracket that translates the tooth | 8–12 mm (Smith & Burstone 1984) |
//! | `sigma2_over_root_length2` | σ²/h², σ² = y·d at M/F = 0 | 0.056 (cone) – 0.068 (paraboloid); accepted 0.050–0.075 |
//! | `crown_displacement_mm_5n` | upper lateral incisor: initial displacement of the incisal edge under 5 N lingual at the bracket, bilinear ligament | 0.175 mm (AADR 2012, in vivo and FE); accepted 0.12–0.23 |
//! | `canine_retraction_mm_per_month_1n` | upper canine, first premolar extracted, 1 N distal on a rectangular wire: distal travel of its crown in 30 days | 0.71 mm (Monini et al. 2019, maxilla); accepted 0.6–0.8 |
//! | `wire_three_point_stiffness_n_per_mm` | the archwire rod, 0.016" steel, centre-loaded on a 10 mm span | 48EI/L³ ± 10 % ([`super::appliance_rows`]) |
//! | `niti_unloading_force_n` | the rod, 0.016" NiTi, three-bracket test (7 mm spans) unloading at 2 mm after 3.1 mm | 0.8–1.8 N (Materials Research 2015: 98–151 gf) |
//! | `chain_force_fraction_day21` | the elastomeric chain's decay at a fixed stretch ([`crate::appliance::chain`]) | 0.25–0.65 (Buchmann 2012: 37–75 % lost) |
//! | `power_arm_bodily_mm` | upper central incisor retracted lingually by a force hooked on a power arm along its long axis from the bracket (0.019×0.025" wire in a 0.022" slot, free within its torque play): the arm's length at which it moves bodily | 9–14 mm (Tominaga et al. 2014: 11.6 mm) |
//! | `torque_play_deg` | the torque play of 0.019×0.025" in a 0.022" slot, and of 0.016×0.022" in a 0.018" slot, from the bevelled wire's corners and the slot's measured height ([`crate::appliance::torque_play_rad`]) | 5–15° (Archambault et al. 2010); 15–22° (Meling et al. 1997: 16.6–20.4°) |
//! | `twist_for_20nmm_deg` | 0.016×0.022" steel through a 0.018" bracket, twisted at grips 7 mm either side: the twist at which the bracket holds 20 N·mm ([`super::appliance_rows::torque_rig`]) | 22–32° (Meling et al. 1997: 24.6–29.2°) |
//! | `sliding_force_loss` | case 1's upper canine retracted along 0.016" steel (0.022" slots, elastomeric modules, μ 0.2) by a 2 N closed coil: share of the pull the slot's friction takes, days 7–60 | 0.4–0.85 (Kojima & Fukui 2005, finite elements: about 70 %) |
//! | `crowded_alignment_days` | the `crowded` case with its wire sequence, as `simulate --algorithm exact` runs it: first day the lower Little index is under 1 mm | 60–240 days (clinical trials) |
//!
//! h is the root length below the crest. `reference` in the output is the accepted range: the
//! published one with the tolerance the row's source states. The canine row is what the
//! remodelling rate β is calibrated on; the others do not depend on β.

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::AnalysisError;
use crate::{
    collision::{Method, collision_shapes},
    geometry::{halves, section_loops},
    movement::{
        MovementError, MovementModel, MovementSettings, Simulation,
        pdl::{PdlStiffness, displacement_at, wrench},
    },
    sphere_tree::{TreeMethod, TreeSettings},
    teeth::{Arch, Case, Dentition, Fdi, ToothGeometry, ToothKind, ToothResolution, WireModel},
};

/// Accepted σ²/h²: the 2D Winkler values of a cone (0.056) and a paraboloid (0.068), each
/// widened by 10 % for the root's width, which turns about the centre of resistance too (shear
/// of its sides) and which a 2D root ignores.
pub const SIGMA2_ACCEPTED: [f64; 2] = [0.050, 0.075];

/// One row of `orthosim validate`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ValidationRow {
    /// What is measured (a fixed key).
    pub name: &'static str,
    /// FDI number of the tooth (0 for the archwire's rows, which measure a wire alone).
    pub tooth: u8,
    /// Moment-to-force ratio at the bracket (mm), where the row has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mf: Option<f32>,
    /// The value orthosim computes.
    pub value: f64,
    /// Its unit.
    pub unit: &'static str,
    /// The accepted range (the published range, with the tolerance `source` states), where
    /// there is one.
    pub reference: Option<[f64; 2]>,
    /// Where the reference comes from.
    pub source: &'static str,
}

impl ValidationRow {
    /// Whether the value is inside the reference range (true when there is none).
    pub fn passes(&self) -> bool {
        self.reference
            .is_none_or(|[lo, hi]| self.value >= lo && self.value <= hi)
    }
}

/// The table of `orthosim validate`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Validation {
    /// The movement model validated (`pdl`).
    pub model: &'static str,
    /// Mesh resolution of the teeth measured (target vertices per tooth).
    pub vertices: u32,
    /// The rows.
    pub rows: Vec<ValidationRow>,
}

/// Lingual force direction and tipping axis of a tooth (tooth frame).
struct ToothAxes {
    axis: DVec3,
    lingual: DVec3,
}

fn axes(g: &ToothGeometry) -> ToothAxes {
    ToothAxes {
        axis: g.frame.long_axis.as_dvec3(),
        lingual: -g.frame.buccolingual.as_dvec3(),
    }
}

/// Level along the long axis from the cervical centre (mm, + occlusal).
fn level(g: &ToothGeometry, p: Vec3) -> f64 {
    ((p - g.frame.cervical_centre).dot(g.frame.long_axis)) as f64
}

/// The furcation of a multi-rooted tooth: the highest level (mm along the long axis from the
/// cervical centre, negative) whose section cuts the mesh in more than one loop, searched in
/// 0.05 mm steps; None for a single root.
pub fn furcation_level(g: &ToothGeometry) -> Option<f64> {
    let f = &g.frame;
    let steps = (f.root_length / 0.05) as usize;
    (1..steps).map(|k| -(k as f32) * 0.05).find_map(|l| {
        let at = f.cervical_centre + f.long_axis * l;
        (section_loops(&g.mesh, at, f.long_axis) > 1).then_some(l as f64)
    })
}

/// Centre of rotation (+ apical of the centre of resistance, mm) under 1 N lingual at the
/// bracket with the counter-couple M/F, and the rotation about the tipping axis.
fn crot(g: &ToothGeometry, p: &PdlStiffness, mf: f64) -> (Option<f64>, f64) {
    let a = axes(g);
    let c = p.centre_of_resistance.as_dvec3();
    let couple = -a.axis.cross(a.lingual) * mf;
    let w = wrench(a.lingual, p.bracket.as_dvec3(), couple, c);
    let t = p.compliance.mul_vec(&w);
    let tip = a.axis.cross(a.lingual).normalize();
    (
        PdlStiffness::centre_of_rotation_along_axis(&t, a.axis),
        halves(&t).1.dot(tip),
    )
}

/// The tipping rotation (radians) of a tooth retracted lingually by 1 N hooked on a power arm
/// `arm` mm long, bonded at the bracket and reaching along the long axis towards the apex.
fn power_arm_tip(g: &ToothGeometry, p: &PdlStiffness, arm: f64) -> f64 {
    let a = axes(g);
    let c = p.centre_of_resistance.as_dvec3();
    let hook = p.bracket.as_dvec3() - a.axis * arm;
    let t = p
        .compliance
        .mul_vec(&wrench(a.lingual, hook, DVec3::ZERO, c));
    halves(&t).1.dot(a.axis.cross(a.lingual).normalize())
}

/// The power arm (mm) on which an upper central incisor's retraction is bodily, its
/// 0.019×0.025" wire in a 0.022" slot: the wire leaves the tooth free within its torque play
/// (NaN when the wire would take up the tipping instead), so the ligament decides where the
/// force's line must pass.
fn power_arm_bodily_mm(g: &ToothGeometry, p: &PdlStiffness) -> f64 {
    let play = crate::appliance::torque_play_rad(
        crate::appliance::WireSize::Rect(0.019, 0.025),
        crate::appliance::Slot::S022,
    );
    if play.is_none_or(|v| v <= 0.0) {
        return f64::NAN;
    }
    // The tipping is linear in the arm's length: zero where the arm's couple meets the force's.
    let (r0, r1) = (power_arm_tip(g, p, 0.0), power_arm_tip(g, p, 1.0));
    r0 / (r0 - r1)
}

fn geometry(
    arch: Arch,
    kind: ToothKind,
    resolution: ToothResolution,
) -> std::sync::Arc<ToothGeometry> {
    crate::teeth::ShapeSet::shared(resolution).get(arch, kind)
}

/// Case 1 (first premolars extracted) with none of its loads, constraints or appliances: the
/// teeth alone, for a rig to load.
///
/// # Errors
/// The case cannot be built.
pub(super) fn bare_case1() -> Result<Dentition, AnalysisError> {
    let mut loaded = Case::resolve("case1")?;
    loaded.case.loads.clear();
    loaded.case.constraints.clear();
    loaded.case.appliance = Default::default();
    Ok(Dentition::build(loaded)?)
}

pub(super) fn tooth(n: u8) -> Fdi {
    Fdi::new(n as i64).expect("a valid FDI number")
}

/// Computes the validation table under `settings.pdl` for the built-in teeth at `resolution`
/// (the canine retraction runs at the cases' default resolution).
///
/// # Errors
/// A tooth cannot carry a ligament, or the canine retraction case cannot be built or run.
pub fn validate(
    settings: &MovementSettings,
    resolution: ToothResolution,
) -> Result<Validation, AnalysisError> {
    let s = &settings.pdl;
    let pdl = |fdi: Fdi| -> Result<(std::sync::Arc<ToothGeometry>, PdlStiffness), AnalysisError> {
        let g = geometry(fdi.arch(), fdi.kind(), resolution);
        let p = PdlStiffness::of(&g, s).map_err(|source| MovementError::Pdl { fdi, source })?;
        Ok((g, p))
    };
    let mut rows = Vec::new();
    for n in [11, 13, 31] {
        let (g, p) = pdl(tooth(n))?;
        let from_crest = p.crest_level as f64 - level(&g, p.centre_of_resistance);
        rows.push(ValidationRow {
            name: "cres_from_crest",
            tooth: n,
            mf: None,
            value: from_crest / p.root_below_crest_mm as f64,
            unit: "fraction of root length",
            reference: Some([0.31, 0.44]),
            source: "0.33–0.42 (Papageorgiou et al. 2005, review), 0.43 (3D FE, upper central incisor); ±0.02 for one root shape",
        });
    }
    {
        let (g, p) = pdl(tooth(16))?;
        let furcation = furcation_level(&g).unwrap_or(f64::NAN);
        rows.push(ValidationRow {
            name: "cres_to_furcation_mm",
            tooth: 16,
            mf: None,
            value: level(&g, p.centre_of_resistance) - furcation,
            unit: "mm",
            reference: Some([0.19 - 1.75, 0.19 + 1.75]),
            source: "Dermaut et al. 1986, 50 upper first molars",
        });
    }
    let (g11, p11) = pdl(tooth(11))?;
    let d = level(&g11, p11.bracket) - level(&g11, p11.centre_of_resistance);
    let h = p11.root_below_crest_mm as f64;
    rows.push(ValidationRow {
        name: "bracket_to_cres_mm",
        tooth: 11,
        mf: None,
        value: d,
        unit: "mm",
        reference: None,
        source: "the bracket at mid-crown on the labial surface",
    });
    let (y0, _) = crot(&g11, &p11, 0.0);
    let sigma2 = y0.unwrap_or(f64::NAN) * d;
    for mf in [0.0, 2.0, 4.0, 6.0, 8.0, 12.0] {
        let (y, _) = crot(&g11, &p11, mf);
        let ends = [
            SIGMA2_ACCEPTED[0] * h * h / (d - mf),
            SIGMA2_ACCEPTED[1] * h * h / (d - mf),
        ];
        rows.push(ValidationRow {
            name: "crot_from_cres_mm",
            tooth: 11,
            mf: Some(mf as f32),
            value: y.unwrap_or(f64::INFINITY),
            unit: "mm (+ apical)",
            reference: Some([ends[0].min(ends[1]), ends[0].max(ends[1])]),
            source: "hyperbola y·(d − M/F) = σ² (Nägerl & Burstone 1991; Choy et al. 2000), σ² as accepted below",
        });
    }
    for n in [11, 13] {
        let (g, p) = pdl(tooth(n))?;
        // The rotation is linear in M/F: zero where the force's rotation meets the couple's.
        let (_, r0) = crot(&g, &p, 0.0);
        let (_, r1) = crot(&g, &p, 1.0);
        rows.push(ValidationRow {
            name: "mf_translation",
            tooth: n,
            mf: None,
            value: r0 / (r0 - r1),
            unit: "mm",
            reference: Some([8.0, 12.0]),
            source: "Smith & Burstone 1984",
        });
    }
    rows.push(ValidationRow {
        name: "sigma2_over_root_length2",
        tooth: 11,
        mf: None,
        value: sigma2 / (h * h),
        unit: "",
        reference: Some(SIGMA2_ACCEPTED),
        source: "0.056 (conical root) to 0.068 (paraboloid), 2D Winkler layer; ±10 % for the root's width",
    });
    {
        let (g, p) = pdl(tooth(12))?;
        let a = axes(&g);
        let c = p.centre_of_resistance.as_dvec3();
        let w = wrench(a.lingual * 5.0, p.bracket.as_dvec3(), DVec3::ZERO, c);
        let t = p
            .bilinear_twist(&g.mesh, &g.frame, s, &w)
            .ok_or(MovementError::Pdl {
                fdi: tooth(12),
                source: crate::movement::pdl::PdlError::Singular,
            })?;
        let tip = (g.frame.cervical_centre + g.frame.long_axis * g.frame.crown_length).as_dvec3();
        rows.push(ValidationRow {
            name: "crown_displacement_mm_5n",
            tooth: 12,
            mf: None,
            value: displacement_at(&t, c, tip).length(),
            unit: "mm",
            reference: Some([0.12, 0.23]),
            source: "0.175 mm, upper lateral incisor, in vivo and FE (AADR 2012 abstract 157852); ±30 %",
        });
    }
    rows.push(ValidationRow {
        name: "canine_retraction_mm_per_month_1n",
        tooth: 13,
        mf: None,
        value: canine_retraction(settings, 30.0)?,
        unit: "mm",
        reference: Some([0.6, 0.8]),
        source: "0.71 mm/month at 100 g, maxilla (Monini et al., Angle Orthod 2019;89:559); β is calibrated on it; ±0.1 mm",
    });
    rows.push(ValidationRow {
        name: "power_arm_bodily_mm",
        tooth: 11,
        mf: None,
        value: power_arm_bodily_mm(&g11, &p11),
        unit: "mm",
        reference: Some([9.0, 14.0]),
        source: "power arm for bodily retraction of the upper incisors: 11.6 mm on 0.019×0.025\" in 0.022\" slots, 9.1 mm on 0.017×0.022\" in 0.018\" (Tominaga et al., AJODO 2014;146:166–74, finite elements); the arm along the long axis from the bracket, the wire free within its 14.9° torque play",
    });
    rows.extend(super::appliance_rows::rows(settings)?);
    Ok(Validation {
        model: "pdl",
        vertices: resolution.vertices,
        rows,
    })
}

/// Distal travel (mm) of the upper right canine's crown centre in `days` under 1 N distal on a
/// rectangular wire, with the first premolar extracted: case 1's arrangement (first premolars
/// extracted, jaws 3 mm apart) with its loads and constraints removed, every other tooth free.
///
/// # Errors
/// The case cannot be built or simulated.
pub fn canine_retraction(settings: &MovementSettings, days: f64) -> Result<f64, AnalysisError> {
    let mut d = bare_case1()?;
    let canine = tooth(13);
    let mut distal = Vec3::ZERO;
    for t in &mut d.teeth {
        if t.fdi == canine {
            distal = -t.anatomical_axes()[0];
            t.force = distal;
            t.wire = WireModel::Rectangular;
        }
    }
    let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None)?;
    let settings = MovementSettings {
        model: MovementModel::Pdl,
        ..*settings
    };
    let mut sim = Simulation::new(&d, shapes, Method::Continuous, settings)?;
    let i = sim
        .index_of(canine)
        .ok_or(MovementError::NotInCase(canine))?;
    let start = sim.teeth[i].crown_centre();
    while sim.elapsed_days < days - 1e-9 {
        if sim.step().at_rest && sim.elapsed_days > 0.0 {
            break;
        }
    }
    Ok((sim.teeth[i].crown_centre() - start).dot(distal) as f64)
}
