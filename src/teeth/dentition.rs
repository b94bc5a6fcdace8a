//! `Dentition`: a patient case turned into placed teeth (engine-free), ready for spawning,
//! inspection and analysis.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::{
    arch::{
        ArchCurve, ArchLayout, Arrangement, BetaArch, OcclusionMeasures, Spaces,
        irregularity::{Anterior, ContactPoints},
    },
    case::{Case, CaseError, CaseOffset, CaseVector, LoadedCase, WireModel},
    fdi::{Arch, Fdi},
    import::Repairs,
    patient::{OrientationReport, patient_teeth},
    tooth_shape::{ShapeSet, ToothGeometry},
};
use crate::geometry::{Pose, TriMesh};

/// One tooth of a case, placed in the world frame.
#[derive(Clone, Debug)]
pub struct PlacedTooth {
    /// FDI number.
    pub fdi: Fdi,
    /// Shared geometry.
    pub geometry: Arc<ToothGeometry>,
    /// Pose of the local frame.
    pub pose: Pose,
    /// True for an extracted tooth (kept in the data, hidden and skipped by the simulation).
    pub extracted: bool,
    /// Net force on the tooth from the case's individual loads (N, world frame).
    pub force: Vec3,
    /// Net torque from the case's individual loads (N·mm, world frame).
    pub torque: Vec3,
    /// Index into [`Dentition::groups`] when the tooth is loaded as part of a group.
    pub group: Option<usize>,
    /// Wire model.
    pub wire: WireModel,
    /// Moment-to-force ratio at the bracket from the case's loads (mm), if one is given.
    pub mf: Option<f32>,
}

impl PlacedTooth {
    /// Unit mesial, buccal and occlusal directions in the world frame.
    pub fn anatomical_axes(&self) -> [Vec3; 3] {
        self.anatomical_axes_at(&self.pose)
    }

    /// [`PlacedTooth::anatomical_axes`] with the tooth at `pose` instead of where it stands.
    pub fn anatomical_axes_at(&self, pose: &Pose) -> [Vec3; 3] {
        let r = pose.rotation;
        [
            r * (Vec3::X * self.fdi.local_x_mesial_sign()),
            r * Vec3::Z,
            r * Vec3::Y,
        ]
    }

    /// A case vector in the world frame.
    pub fn world_vector(&self, v: &CaseVector) -> Vec3 {
        match *v {
            CaseVector::World(x, y, z) => Vec3::new(x.0, y.0, z.0),
            CaseVector::Anatomical {
                mesial,
                buccal,
                occlusal,
            } => {
                let [m, b, o] = self.anatomical_axes();
                m * mesial.0 + b * buccal.0 + o * occlusal.0
            }
        }
    }

    /// The pose after moving the tooth by `offset`: turned about its crown centre (mesial axis,
    /// then buccal, then occlusal), then shifted along its anatomical axes, all taken at the
    /// present pose.
    pub fn offset_pose(&self, offset: &CaseOffset) -> Pose {
        let [m, b, o] = self.anatomical_axes();
        let (t, r) = (offset.translation, offset.rotation_deg);
        let rotation = Quat::from_axis_angle(m, r.0.0.to_radians())
            * Quat::from_axis_angle(b, r.1.0.to_radians())
            * Quat::from_axis_angle(o, r.2.0.to_radians());
        let pivot = self.crown_centre();
        let about_pivot = Pose::from_translation(pivot)
            .mul(&Pose::new(rotation, Vec3::ZERO))
            .mul(&Pose::from_translation(-pivot));
        let shift = Pose::from_translation(m * t.0.0 + b * t.1.0 + o * t.2.0);
        shift.mul(&about_pivot).mul(&self.pose)
    }

    /// The offset that [`PlacedTooth::offset_pose`] turns into `target`: the inverse of that
    /// map (exact up to rounding; rotations within ±90° about the buccal axis, beyond which the
    /// three angles are not unique).
    pub fn offset_between(&self, target: &Pose) -> CaseOffset {
        let axes = self.anatomical_axes();
        let basis = glam::Mat3::from_cols(axes[0], axes[1], axes[2]);
        let rotation = (target.rotation * self.pose.rotation.inverse()).normalize();
        // The rotation in the axes' basis; a left-handed basis (mesial along +x) turns the
        // other way in it.
        let local = Quat::from_mat3(&(basis.transpose() * glam::Mat3::from_quat(rotation) * basis));
        let hand = basis.determinant().signum();
        let (a, b, c) = local.to_euler(glam::EulerRot::XYZ);
        let pivot = self.crown_centre();
        let shift = target.translation - pivot - rotation * (self.pose.translation - pivot);
        let f = |v: f32| crate::teeth::case::Finite(v);
        CaseOffset {
            translation: (
                f(shift.dot(axes[0])),
                f(shift.dot(axes[1])),
                f(shift.dot(axes[2])),
            ),
            rotation_deg: (
                f(hand * a.to_degrees()),
                f(hand * b.to_degrees()),
                f(hand * c.to_degrees()),
            ),
        }
    }

    /// The crown centre in the world frame.
    pub fn crown_centre(&self) -> Vec3 {
        self.pose.transform_point(self.geometry.frame.crown_centre)
    }
}

/// A load applied to a group of teeth moving as one block.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupLoad {
    /// Members.
    pub teeth: Vec<Fdi>,
    /// Force (N, world frame), resolved in the first member's frame when anatomical.
    pub force: Vec3,
    /// Torque (N·mm, world frame).
    pub torque: Vec3,
}

/// The teeth of a case placed in the world frame.
#[derive(Clone, Debug)]
pub struct Dentition {
    /// The case it was built from.
    pub case: Arc<LoadedCase>,
    /// Present teeth in FDI order (extracted ones included, flagged).
    pub teeth: Vec<PlacedTooth>,
    /// Group loads.
    pub groups: Vec<GroupLoad>,
    /// Occlusion measures of the underlying arrangement (before offsets).
    pub arrangement: OcclusionMeasures,
    /// The arch forms of the teeth as they stand: upper, then lower. They are the arrangement's
    /// (whose curves run through the teeth's cervical centres) unless a tooth was imported or
    /// offset; then each is the arrangement's form fitted to the cervical centres of its arch's
    /// present teeth ([`BetaArch::fit`]), which slides teeth and gives imported teeth their
    /// buccal axis. The bite opening raises the teeth, not the curve in x–z.
    pub arch_forms: [BetaArch; 2],
    /// The anterior teeth's anatomic contact points for Little's irregularity index.
    pub contact_points: ContactPoints,
    /// Where each procedural tooth stands aligned: its place in the arrangement (the bite
    /// opening included), before the case's offsets. Imported teeth have none (their aligned
    /// place is not known).
    pub setup: std::collections::BTreeMap<Fdi, Pose>,
    /// What was repaired in each imported tooth mesh (teeth with a mesh file only).
    pub imported: std::collections::BTreeMap<Fdi, Repairs>,
    /// Where the case's mesh and scan files were placed.
    pub orientation: Vec<OrientationReport>,
    /// The case's bone meshes (upper, lower) where it names them, in place (the maxilla raised
    /// with the upper teeth by the bite's opening).
    pub bone: [Option<Arc<TriMesh>>; 2],
    /// What the import of each labelled scan changed in its labels or left out.
    pub scans: Vec<super::patient::ScanReport>,
}

impl Dentition {
    /// Places the teeth of a validated case.
    pub fn build(loaded: LoadedCase) -> Result<Self, CaseError> {
        let case = &loaded.case;
        let shapes = ShapeSet::shared(case.tooth_resolution());
        let spaces: Spaces = case.spaces.0.iter().map(|(f, s)| (*f, s.0)).collect();
        let arrangement = Arrangement::shared(&shapes, &spaces);
        let patient = if case.meshes.0.is_empty() && case.scans.is_empty() {
            None
        } else {
            Some(patient_teeth(&loaded, &arrangement)?)
        };
        let labelled = patient.as_ref().map_or(&[][..], |p| &p.labelled[..]);
        let mut teeth: Vec<PlacedTooth> = case
            .present_with(labelled)
            .into_iter()
            .map(|fdi| PlacedTooth {
                fdi,
                geometry: shapes.get(fdi.arch(), fdi.kind()),
                pose: arrangement.pose(fdi),
                extracted: case.is_extracted(fdi),
                force: Vec3::ZERO,
                torque: Vec3::ZERO,
                group: None,
                wire: case.wire_of(fdi),
                mf: None,
            })
            .collect();
        let mut arch_forms = [arrangement.upper, ArchLayout::default().lower];
        let mut imported_repairs = std::collections::BTreeMap::new();
        let mut orientation = Vec::new();
        let mut scans = Vec::new();
        let patient_teeth_of: Vec<Fdi> = patient
            .as_ref()
            .map_or_else(Vec::new, |p| p.teeth.iter().map(|(f, _)| *f).collect());
        if let Some(patient) = patient {
            // Each imported tooth's buccal axis comes from the arch as it is: the arrangement's
            // forms fitted to the cervical centres of the teeth present. An imported tooth's
            // cervical centre (its frame's origin) does not depend on the curve, so any curve
            // places it for the fit.
            let provisional = arch_forms.map(|f| ArchCurve::new(&f));
            fn curve_of(curves: &[ArchCurve; 2], f: Fdi) -> &ArchCurve {
                &curves[usize::from(f.arch() == Arch::Lower)]
            }
            for (f, prepared) in &patient.teeth {
                if let Some(placed) = teeth.iter_mut().find(|t| t.fdi == *f) {
                    placed.pose = prepared.pose(*f, curve_of(&provisional, *f));
                }
            }
            arch_forms = fitted_forms(&teeth, arch_forms);
            let fitted = arch_forms.map(|f| ArchCurve::new(&f));
            for (f, prepared) in &patient.teeth {
                let tooth = prepared.frame(*f, curve_of(&fitted, *f));
                if let Some(t) = teeth.iter_mut().find(|t| t.fdi == *f) {
                    t.geometry = Arc::new(tooth.geometry);
                    t.pose = tooth.pose;
                }
                imported_repairs.insert(*f, tooth.repairs);
            }
            orientation = patient.orientation;
            scans = patient.scans;
        }
        // The anatomic contact points while the arrangement's teeth stand aligned (before the
        // case's offsets); imported crowns take theirs from their shape.
        let contact_points = {
            let anteriors: Vec<Anterior> = teeth
                .iter()
                .filter(|t| !t.extracted)
                .map(|t| Anterior {
                    fdi: t.fdi,
                    geometry: &t.geometry,
                    pose: t.pose,
                })
                .collect();
            let imported = |f: Fdi| patient_teeth_of.contains(&f);
            ContactPoints::new(&anteriors, |f| !imported(f))
        };
        let lift = Vec3::Y * case.bite_opening_mm.0;
        for tooth in teeth.iter_mut().filter(|t| t.fdi.arch() == Arch::Upper) {
            tooth.pose.translation += lift;
        }
        let setup = teeth
            .iter()
            .filter(|t| !patient_teeth_of.contains(&t.fdi))
            .map(|t| (t.fdi, t.pose))
            .collect();
        for tooth in &mut teeth {
            if let Some(offset) = case.offsets.0.get(&tooth.fdi) {
                tooth.pose = tooth.offset_pose(offset);
            }
        }
        if !case.offsets.0.is_empty() {
            arch_forms = fitted_forms(&teeth, arch_forms);
        }
        let mut groups = Vec::new();
        for load in &case.loads {
            if load.as_group {
                let first = teeth
                    .iter()
                    .find(|t| t.fdi == load.teeth.0[0])
                    .expect("validated: loaded teeth are present");
                groups.push(GroupLoad {
                    teeth: load.teeth.0.clone(),
                    force: first.world_vector(&load.force),
                    torque: first.world_vector(&load.torque),
                });
                for t in teeth.iter_mut().filter(|t| load.teeth.0.contains(&t.fdi)) {
                    t.group = Some(groups.len() - 1);
                }
            } else {
                for t in teeth.iter_mut().filter(|t| load.teeth.0.contains(&t.fdi)) {
                    t.force += t.world_vector(&load.force);
                    t.torque += t.world_vector(&load.torque);
                    if let Some(mf) = load.mf {
                        t.mf = Some(mf.0);
                    }
                }
            }
        }
        let bone = read_bones(&loaded, &orientation, lift)?;
        Ok(Self {
            case: Arc::new(loaded),
            teeth,
            groups,
            arrangement: arrangement.measures,
            arch_forms,
            contact_points,
            setup,
            imported: imported_repairs,
            bone,
            orientation,
            scans,
        })
    }

    /// A tooth by number.
    pub fn tooth(&self, fdi: Fdi) -> Option<&PlacedTooth> {
        self.teeth.iter().find(|t| t.fdi == fdi)
    }

    /// Teeth that are present and not extracted.
    pub fn visible(&self) -> impl Iterator<Item = &PlacedTooth> {
        self.teeth.iter().filter(|t| !t.extracted)
    }

    /// Adjacent visible teeth along each arch, from the patient's right to left; extracted or
    /// absent teeth are skipped, so their neighbours pair up across the space.
    pub fn neighbour_pairs(&self) -> Vec<(Fdi, Fdi)> {
        let mut pairs = Vec::new();
        for arch in [Arch::Upper, Arch::Lower] {
            let mut row: Vec<&PlacedTooth> =
                self.visible().filter(|t| t.fdi.arch() == arch).collect();
            row.sort_by_key(|t| t.fdi.arch_index());
            pairs.extend(row.windows(2).map(|w| (w[0].fdi, w[1].fdi)));
        }
        pairs
    }
}

/// The arch forms fitted to the cervical centres (local origins) of each arch's present teeth,
/// less the arrangement's buccal offsets, starting from `start` (upper, lower).
fn fitted_forms(teeth: &[PlacedTooth], start: [BetaArch; 2]) -> [BetaArch; 2] {
    // A tooth the arrangement sets out from its curve (the upper canines' prominence) counts
    // where its curve runs: its centre less that offset along the curve's outward normal.
    let layout = ArchLayout::default();
    let fit = |arch: Arch, form: BetaArch| {
        let curve = ArchCurve::new(&form);
        let row = usize::from(arch == Arch::Lower);
        let points: Vec<glam::Vec2> = teeth
            .iter()
            .filter(|t| t.fdi.arch() == arch && !t.extracted)
            .map(|t| {
                let p = glam::Vec2::new(t.pose.translation.x, t.pose.translation.z);
                let offset = layout.buccal_offset[row][t.fdi.position() as usize - 1];
                if offset == 0.0 || !p.is_finite() {
                    return p;
                }
                let (_, tangent) = curve.at(curve.project(p));
                p - glam::Vec2::new(-tangent.y, tangent.x) * offset
            })
            .collect();
        form.fit(&points)
    };
    [fit(Arch::Upper, start[0]), fit(Arch::Lower, start[1])]
}

/// The case's bone meshes, read and placed: `Auto` as the case's automatically placed files
/// (the file's own frame without any), the maxilla raised by the bite's opening `lift`.
fn read_bones(
    loaded: &LoadedCase,
    orientation: &[OrientationReport],
    lift: Vec3,
) -> Result<[Option<Arc<TriMesh>>; 2], CaseError> {
    let bone = &loaded.case.bone;
    let auto = orientation
        .iter()
        .find(|r| r.auto)
        .map_or(Pose::IDENTITY, |r| r.pose);
    let read = |spec: &Option<crate::teeth::import::ToothMeshFile>,
                raise: Vec3|
     -> Result<Option<Arc<TriMesh>>, CaseError> {
        let Some(spec) = spec else {
            return Ok(None);
        };
        let path = Case::mesh_path(&loaded.origin, &spec.file);
        let mesh =
            crate::teeth::import::read_bone(&path, spec.units).map_err(|e| CaseError::Scan {
                path: path.display().to_string(),
                case: loaded.origin.clone(),
                message: e.to_string(),
            })?;
        let pose = spec.transform.pose().unwrap_or(auto);
        Ok(Some(Arc::new(
            mesh.map_vertices(|v| pose.transform_point(v) + raise),
        )))
    };
    Ok([read(&bone.upper, lift)?, read(&bone.lower, Vec3::ZERO)?])
}
