//! Making a simulation of a case, and editing it while it runs: loads, wires, extraction and
//! restoration.

use std::collections::{BTreeMap, BTreeSet};

use glam::Vec3;

use super::{SimGroup, SimTooth, Simulation, StepOutcome, row};
use crate::{
    collision::{Circle, CollisionShape, Method, Motion},
    geometry::mesh_separation,
    movement::{
        MovementError,
        arch_path::arc_of,
        model::ToothConstraint,
        settings::{MovementModel, MovementSettings},
    },
    teeth::{Dentition, Fdi, Load, WireModel, arch::ArchCurve, case::Freedoms},
};

impl Simulation {
    /// A simulation of the visible teeth of `d`, with a collision shape for each (`shapes` in any
    /// order, one per visible tooth).
    ///
    /// # Errors
    /// [`MovementError::Setting`] for settings out of range, [`MovementError::NoShape`] for a
    /// visible tooth without a shape.
    ///
    /// # Example
    /// The paper's case 1 run to rest: the first molars close the extraction spaces.
    /// ```
    /// use orthosim::{
    ///     collision::{Method, collision_shapes},
    ///     movement::{MovementSettings, Simulation},
    ///     sphere_tree::{TreeMethod, TreeSettings},
    ///     teeth::{Case, Dentition, Fdi},
    /// };
    /// let d = Dentition::build(Case::resolve("case1")?)?;
    /// let shapes = collision_shapes(&d, TreeSettings::with_method(TreeMethod::Octree), None)?;
    /// let mut sim = Simulation::new(&d, shapes, Method::Continuous, MovementSettings::default())?;
    /// while !sim.step().at_rest && sim.steps < 10_000 {}
    /// let molar = &sim.teeth[sim.index_of(Fdi::new(16)?).ok_or("16 is in case 1")?];
    /// assert!(molar.displacement_mm() > 1.0);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(
        d: &Dentition,
        shapes: Vec<(Fdi, CollisionShape)>,
        method: Method,
        settings: MovementSettings,
    ) -> Result<Self, MovementError> {
        let mut sim = Self::with_ligaments(d, shapes, method, settings, &[])?;
        if settings.model == MovementModel::Pdl {
            sim.bond_case(&d.case.case.appliance)?;
        }
        Ok(sim)
    }

    /// [`Simulation::new`], taking the ligaments of `known` teeth (same settings) instead of
    /// computing them again for their shapes.
    fn with_ligaments(
        d: &Dentition,
        shapes: Vec<(Fdi, CollisionShape)>,
        method: Method,
        settings: MovementSettings,
        known: &[SimTooth],
    ) -> Result<Self, MovementError> {
        settings.validate()?;
        let curves = [
            ArchCurve::new(&d.arch_forms[0]),
            ArchCurve::new(&d.arch_forms[1]),
        ];
        let case = &d.case.case;
        let mut teeth = Vec::new();
        for t in d.visible() {
            let shape = shapes
                .iter()
                .find(|(f, _)| *f == t.fdi)
                .map(|(_, s)| s.clone())
                .ok_or(MovementError::NoShape(t.fdi))?;
            let mut constraint = ToothConstraint::default();
            for c in case
                .constraints
                .iter()
                .filter(|c| c.teeth.0.contains(&t.fdi))
            {
                let and = |a: Freedoms, b: Freedoms| Freedoms {
                    mesial: a.mesial && b.mesial,
                    buccal: a.buccal && b.buccal,
                    occlusal: a.occlusal && b.occlusal,
                };
                constraint.translate = and(constraint.translate, c.translate);
                constraint.rotate = and(constraint.rotate, c.rotate);
                let min = |a: Option<f32>, b: Option<f32>| match (a, b) {
                    (Some(x), Some(y)) => Some(x.min(y)),
                    (x, None) => x,
                    (None, y) => y,
                };
                constraint.max_translation_mm = min(
                    constraint.max_translation_mm,
                    c.max_translation_mm.map(|v| v.0),
                );
                constraint.max_rotation_rad = min(
                    constraint.max_rotation_rad,
                    c.max_rotation_deg.map(|v| v.0.to_radians()),
                );
            }
            let curve = &curves[row(t.fdi.arch())];
            teeth.push(SimTooth {
                fdi: t.fdi,
                circle: Circle::of(&t.geometry, &t.pose),
                shape,
                wire: t.wire,
                load: Load {
                    force: t.force,
                    torque: t.torque,
                },
                group: t.group,
                constraint,
                initial: t.pose,
                pose: t.pose,
                arc: arc_of(curve, &t.pose),
                mf: t.mf,
                pdl: None,
            });
        }
        let groups = d
            .groups
            .iter()
            .map(|g| SimGroup {
                members: teeth
                    .iter()
                    .enumerate()
                    .filter(|(_, t)| g.teeth.contains(&t.fdi))
                    .map(|(i, _)| i)
                    .collect(),
                load: Load {
                    force: g.force,
                    torque: g.torque,
                },
            })
            .collect();
        let n = teeth.len();
        let mut sim = Self {
            motions: teeth.iter().map(|t| Motion::still(t.pose)).collect(),
            teeth,
            groups,
            curves,
            settings,
            method,
            passed: vec![Vec3::ZERO; n],
            next_passed: vec![Vec3::ZERO; n],
            effective: vec![Vec3::ZERO; n],
            steps: 0,
            last: StepOutcome::default(),
            ipr: BTreeMap::new(),
            ipr_over: BTreeSet::new(),
            still_steps: 0,
            total_impacts: 0,
            total_energy_lost_uj: 0.0,
            pdl: super::PdlState::default(),
            elapsed_days: 0.0,
            known: BTreeMap::new(),
            wires: Vec::new(),
            elastics: Vec::new(),
            contact_points: d.contact_points.clone(),
            setup: d.setup.clone(),
            bone: None,
            bone_files: d.bone.clone(),
            bone_meshes: None,
            cortical: Vec::new(),
        };
        if settings.model == MovementModel::Pdl {
            for t in &mut sim.teeth {
                t.pdl = known
                    .iter()
                    .find(|k| std::sync::Arc::ptr_eq(&k.shape.geometry, &t.shape.geometry))
                    .and_then(|k| k.pdl.clone());
            }
            sim.prepare_pdl()?;
            // The bone as the case stands, extraction sites included: their sockets are bone
            // the neighbours may move into.
            let extracted: Vec<(crate::teeth::Fdi, crate::geometry::Pose, Vec<Vec3>)> = d
                .teeth
                .iter()
                .filter(|t| t.extracted)
                .map(|t| {
                    let crest = settings.pdl.crest_mm.of(t.geometry.kind);
                    (
                        t.fdi,
                        t.pose,
                        crate::movement::pdl::root_samples(&t.geometry, crest),
                    )
                })
                .collect();
            sim.make_bone(&extracted);
        }
        Ok(sim)
    }

    /// Replaces the movement settings (for the UI), computing the teeth's ligaments when the PDL
    /// model or its parameters change; refuses, keeping the old settings, settings out of range
    /// or a tooth that cannot carry a ligament.
    ///
    /// # Errors
    /// [`MovementError::Setting`] or [`MovementError::Pdl`].
    pub fn set_settings(&mut self, settings: MovementSettings) -> Result<(), MovementError> {
        settings.validate()?;
        let old = self.settings;
        if settings.pdl != old.pdl {
            for t in &mut self.teeth {
                t.pdl = None;
            }
        }
        self.settings = settings;
        self.pdl.cache.clear();
        if settings.model == MovementModel::Pdl
            && let Err(e) = self.prepare_pdl()
        {
            self.settings = old;
            for t in &mut self.teeth {
                t.pdl = None;
            }
            if old.model == MovementModel::Pdl {
                self.prepare_pdl()?;
            }
            return Err(e);
        }
        Ok(())
    }

    /// Moves teeth to new poses outside the simulation's own steps (the viewer's bite and
    /// excursions): their motions are reset and the contacts between steps forgotten.
    pub fn place_teeth(&mut self, poses: &[(usize, crate::geometry::Pose)]) {
        for &(i, pose) in poses {
            if i < self.teeth.len() && pose.is_finite() {
                self.teeth[i].pose = pose;
                self.teeth[i].arc = arc_of(&self.curves[row(self.teeth[i].fdi.arch())], &pose);
                self.motions[i] = Motion::still(pose);
            }
        }
        self.pdl.touching.clear();
        self.pdl.forces.clear();
        self.pdl.cache.clear();
    }

    /// Sets a tooth's moment-to-force ratio at the bracket (mm; None: the wire decides).
    ///
    /// # Errors
    /// [`MovementError::Setting`] for a ratio that is not finite or beyond ±30 mm.
    pub fn set_mf(&mut self, i: usize, mf: Option<f32>) -> Result<(), MovementError> {
        let max = crate::teeth::case::MAX_MF_MM;
        if let Some(v) = mf
            && !(v.is_finite() && v.abs() <= max)
        {
            return Err(MovementError::Setting {
                field: "mf",
                value: v,
                min: -max,
                max,
            });
        }
        self.teeth[i].mf = mf;
        Ok(())
    }

    /// Replaces a tooth's own load (for the UI and messages); refuses, keeping the old one, a load
    /// that [`Load::check`] refuses.
    pub fn set_load(&mut self, i: usize, load: Load) -> Result<(), MovementError> {
        load.check()?;
        self.teeth[i].load = load;
        Ok(())
    }

    /// Replaces a tooth's archwire model.
    pub fn set_wire(&mut self, i: usize, wire: WireModel) {
        self.teeth[i].wire = wire;
    }

    /// The same simulation with tooth `fdi` extracted (`extract`) or restored, for extracting and
    /// restoring teeth while a case runs. `d` is the case the simulation was made from; `shape` is
    /// the restored tooth's collision shape (unused when extracting).
    ///
    /// The other teeth keep their current poses, loads, wire models and displacements, and the step
    /// count, IPR record and impact totals carry over; forces passed between neighbours start
    /// afresh (the neighbours changed). A restored tooth comes back at its place in the case with
    /// its case load; it is refused, with the reason, when a tooth has moved into that place (the
    /// meshes would overlap) or when it is not a tooth of the case.
    pub fn with_extraction(
        &self,
        d: &Dentition,
        fdi: Fdi,
        extract: bool,
        shape: Option<CollisionShape>,
    ) -> Result<Self, MovementError> {
        let Some(placed) = d.tooth(fdi) else {
            return Err(MovementError::NotInCase(fdi));
        };
        let present = self.index_of(fdi).is_some();
        if extract && !present {
            return Err(MovementError::AlreadyExtracted(fdi));
        }
        if !extract && present {
            return Err(MovementError::AlreadyInPlace(fdi));
        }
        let mut shapes: Vec<(Fdi, CollisionShape)> = self
            .teeth
            .iter()
            .filter(|t| t.fdi != fdi)
            .map(|t| (t.fdi, t.shape.clone()))
            .collect();
        if !extract {
            let shape = shape.ok_or(MovementError::NotReady(fdi))?;
            let radius = shape
                .tree
                .spheres
                .first()
                .map_or(f32::INFINITY, |s| s.radius);
            let centre = shape
                .tree
                .spheres
                .first()
                .map_or(Vec3::ZERO, |s| placed.pose.transform_point(s.centre));
            for t in &self.teeth {
                let Some(root) = t.shape.tree.spheres.first() else {
                    continue;
                };
                let far =
                    t.pose.transform_point(root.centre).distance(centre) > radius + root.radius;
                if far {
                    continue;
                }
                let sep = mesh_separation(
                    shape.geometry.mesh_ref(),
                    &placed.pose,
                    t.shape.geometry.mesh_ref(),
                    &t.pose,
                );
                if sep.overlapping() {
                    return Err(MovementError::Occupied {
                        fdi,
                        by: t.fdi,
                        overlap_mm: sep.penetration,
                    });
                }
            }
            shapes.push((fdi, shape));
        }
        let mut edited = d.clone();
        for t in &mut edited.teeth {
            if t.fdi == fdi {
                t.extracted = extract;
            } else if let Some(i) = self.index_of(t.fdi) {
                t.extracted = false;
                t.pose = self.teeth[i].pose;
            } else {
                t.extracted = true;
            }
        }
        let mut next =
            Self::with_ligaments(&edited, shapes, self.method, self.settings, &self.teeth)?;
        // (A restored tooth starts from the case: its initial pose, load and wire.)
        for t in &mut next.teeth {
            if let Some(i) = self.index_of(t.fdi) {
                let old = &self.teeth[i];
                t.initial = old.initial;
                t.load = old.load;
                t.wire = old.wire;
                t.mf = old.mf;
            }
        }
        for (g, old) in next.groups.iter_mut().zip(&self.groups) {
            g.load = old.load;
        }
        next.steps = self.steps;
        next.ipr = self.ipr.clone();
        next.total_impacts = self.total_impacts;
        next.total_energy_lost_uj = self.total_energy_lost_uj;
        next.elapsed_days = self.elapsed_days;
        next.bone = self.bone.clone();
        next.bone_meshes = self.bone_meshes.clone();
        next.cortical = self.cortical.clone();
        // The wires are laid again through the brackets left (as a wire is engaged afresh
        // after an extraction).
        for w in &self.wires {
            let teeth: Vec<Fdi> = w
                .brackets
                .iter()
                .map(|b| b.fdi)
                .filter(|f| next.index_of(*f).is_some())
                .collect();
            if teeth.len() >= 3 {
                next.bond(w.arch, w.choice, &teeth)?;
            }
        }
        next.elastics = self
            .elastics
            .iter()
            .filter(|e| next.slot_of(e.from).is_some() && next.slot_of(e.to).is_some())
            .cloned()
            .collect();
        Ok(next)
    }
}
