//! A case's patient teeth: every tooth of `meshes` and every labelled tooth of `scans`, read in
//! millimetres, placed in orthosim's frame (by its file's transform, or automatically with the
//! other files of the case's shared frame), then repaired and closed ([`crate::teeth::import`]).

use std::collections::BTreeMap;

use serde::Serialize;

use super::{
    arch::Arrangement,
    case::{Case, CaseError, LoadedCase},
    fdi::Fdi,
    import::{
        CrownAxis, ImportError, LabelFix, Placement, Prepared, RepairLimits, RootGuide,
        apart::keep_roots_apart,
        check_raw, check_scan,
        orient::{Arranged, REFERENCE_RESOLUTION, as_euler_deg, orient},
        prepare_or_rebuild, read_in_mm, read_labelled, split, tidy_labels, trim_bleed,
    },
    tooth_shape::ShapeSet,
};
use crate::geometry::{Pose, TriMesh};

/// Where the files of a case were placed: one entry for all the files placed automatically (they
/// share a frame), one per file with its own transform.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OrientationReport {
    /// The files, as the case names them.
    pub files: Vec<String>,
    /// Rotation (degrees about x, then y, then z) into orthosim's frame, as a case's `transform`
    /// writes it.
    pub rotation_deg: [f32; 3],
    /// Translation (mm) after the rotation.
    pub translation: [f32; 3],
    /// True when orthosim found it from the labelled teeth.
    pub auto: bool,
    /// For an automatic placement: root-mean-square distance (mm) of the teeth's occlusal caps
    /// from the arrangement's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_mm: Option<f32>,
    /// The placement itself, from the files' frame (mm) to orthosim's.
    #[serde(skip)]
    pub pose: Pose,
}

/// What the import of a labelled scan changed in its labels, and the labels it left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScanReport {
    /// The scan, as the case names it.
    pub file: String,
    /// Second pieces moved, islands dropped, margins trimmed.
    pub fixes: Vec<LabelFix>,
    /// Labels that cannot be a tooth, left out of the case with the reason.
    pub left_out: Vec<LeftOut>,
}

/// A label left out of a scan's import.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LeftOut {
    /// FDI number.
    pub fdi: u8,
    /// Why, on one line.
    pub reason: String,
}

/// A labelled tooth with fewer triangles than this is no tooth: left out of its scan's import.
pub const MIN_TOOTH_TRIANGLES: usize = 40;

/// One imported tooth's raw mesh, before placement.
struct Source {
    fdi: Fdi,
    /// The file as the case names it, and its resolved path.
    file: String,
    path: String,
    /// Millimetres, the file's frame.
    mesh: TriMesh,
    placement: Placement,
    /// From a labelled scan.
    scanned: bool,
}

/// The patient's teeth of a case, placed and prepared.
pub(super) struct PatientTeeth {
    /// Prepared teeth.
    pub teeth: Vec<(Fdi, Prepared)>,
    /// The teeth the scans label.
    pub labelled: Vec<Fdi>,
    /// Where the files went.
    pub orientation: Vec<OrientationReport>,
    /// What each labelled scan's import changed or left out.
    pub scans: Vec<ScanReport>,
}

/// Reads, places and prepares the case's `meshes` and `scans`.
pub(super) fn patient_teeth(
    loaded: &LoadedCase,
    arrangement: &Arrangement,
) -> Result<PatientTeeth, CaseError> {
    let case = &loaded.case;
    let (sources, mut scans) = read_sources(loaded)?;
    let labelled: Vec<Fdi> = sources
        .iter()
        .filter(|s| s.scanned)
        .map(|s| s.fdi)
        .collect();
    if case.presence_from_scans() {
        loaded.check_present(&case.present_with(&labelled))?;
    }
    let present = case.present_with(&labelled);
    if let Some(s) = sources.iter().find(|s| !present.contains(&s.fdi)) {
        return Err(scan_error(
            loaded,
            &s.path,
            format!(
                "the scan labels tooth {}, which the case's `teeth` leaves out",
                s.fdi
            ),
        ));
    }
    // Placement.
    let mut orientation = Vec::new();
    let mut poses: Vec<Pose> = vec![Pose::IDENTITY; sources.len()];
    let auto: Vec<usize> = (0..sources.len())
        .filter(|&i| sources[i].placement == Placement::Auto)
        .collect();
    if !auto.is_empty() {
        let teeth: Vec<(Fdi, &TriMesh)> = auto
            .iter()
            .map(|&i| (sources[i].fdi, &sources[i].mesh))
            .collect();
        let mut files: Vec<String> = Vec::new();
        for &i in &auto {
            if !files.contains(&sources[i].file) {
                files.push(sources[i].file.clone());
            }
        }
        let reference = ShapeSet::shared(REFERENCE_RESOLUTION);
        let geometries: BTreeMap<Fdi, _> = teeth
            .iter()
            .map(|(f, _)| (*f, reference.get(f.arch(), f.kind())))
            .collect();
        let found = orient(&teeth, |fdi| Arranged {
            mesh: &geometries[&fdi].mesh,
            pose: arrangement.pose(fdi),
        })
        .map_err(|e| scan_error(loaded, &files.join(", "), e.to_string()))?;
        for &i in &auto {
            poses[i] = found.pose;
        }
        let (rotation_deg, translation) = as_euler_deg(&found.pose);
        orientation.push(OrientationReport {
            files,
            rotation_deg,
            translation,
            auto: true,
            rms_mm: Some(found.rms_mm),
            pose: found.pose,
        });
    }
    for (i, s) in sources.iter().enumerate() {
        let Some(pose) = s.placement.pose() else {
            continue;
        };
        poses[i] = pose;
        if orientation
            .iter()
            .any(|r| !r.auto && r.files.first() == Some(&s.file))
        {
            continue;
        }
        let (rotation_deg, translation) = as_euler_deg(&pose);
        orientation.push(OrientationReport {
            files: vec![s.file.clone()],
            rotation_deg,
            translation,
            auto: false,
            rms_mm: None,
            pose,
        });
    }
    // The label fixes' places, from the scans' frames (mm) to orthosim's.
    for report in &mut scans {
        if let Some(i) = sources
            .iter()
            .position(|s| s.scanned && s.file == report.file)
        {
            for fix in &mut report.fixes {
                fix.at = poses[i]
                    .transform_point(glam::Vec3::from_array(fix.at))
                    .to_array();
            }
        }
    }
    // Labels past the crown trimmed (where the arrangement says which way is occlusal), then
    // repaired and closed or rebuilt, on all cores.
    let jobs: Vec<usize> = (0..sources.len()).collect();
    let limits = RepairLimits::default();
    let mut guides: Vec<RootGuide> = sources
        .iter()
        .map(|s| RootGuide {
            guess: Some(arrangement.pose(s.fdi)),
            ..RootGuide::default()
        })
        .collect();
    let worlds: Vec<TriMesh> = sources
        .iter()
        .zip(&poses)
        .map(|(s, pose)| s.mesh.map_vertices(|v| pose.transform_point(v)))
        .collect();
    let occlusal = |fdi: Fdi| arrangement.pose(fdi).rotation * glam::Vec3::Y;
    // Each scanned crown's axis, for its neighbours' trims (`None` for CBCT teeth, which are whole).
    let axes: Vec<Option<CrownAxis>> = sources
        .iter()
        .zip(&worlds)
        .map(|(s, world)| {
            let an = super::anatomy::anatomy(s.fdi.arch(), s.fdi.kind());
            s.scanned
                .then(|| CrownAxis::of(world, &an, occlusal(s.fdi)))
                .flatten()
        })
        .collect();
    let first = crate::parallel::parallel_map(&jobs, |&i| {
        let s = &sources[i];
        let world = worlds[i].clone();
        let (input, fix) = if s.scanned {
            let an = super::anatomy::anatomy(s.fdi.arch(), s.fdi.kind());
            // The nearest tooth present on each side along the arch.
            let place = |j: usize| sources[j].fdi.arch_index();
            let same = |j: usize| j != i && sources[j].fdi.arch() == s.fdi.arch();
            let before = (0..sources.len())
                .filter(|&j| same(j) && place(j) < place(i))
                .max_by_key(|&j| place(j));
            let after = (0..sources.len())
                .filter(|&j| same(j) && place(j) > place(i))
                .min_by_key(|&j| place(j));
            let neighbours: Vec<CrownAxis> = [before, after]
                .into_iter()
                .flatten()
                .filter_map(|j| axes[j])
                .collect();
            trim_bleed(&world, s.fdi, &an, occlusal(s.fdi), &neighbours)
        } else {
            (world, None)
        };
        let p = prepare_or_rebuild(&input, s.fdi, &limits, guides[i]);
        (fix, input, p)
    });
    let mut trims = Vec::with_capacity(first.len());
    let mut inputs = Vec::with_capacity(first.len());
    let mut results = Vec::with_capacity(first.len());
    for (fix, input, p) in first {
        trims.push(fix);
        inputs.push(input);
        results.push(p);
    }
    // Generated roots of neighbouring crowns turned apart where they reach into each other.
    let fdis: Vec<Fdi> = sources.iter().map(|s| s.fdi).collect();
    keep_roots_apart(&fdis, &inputs, &mut results, &mut guides, &limits);
    let prepared = trims.into_iter().zip(results);
    let mut teeth = Vec::with_capacity(sources.len());
    let mut kept = Vec::with_capacity(labelled.len());
    for (s, (trim, p)) in sources.iter().zip(prepared) {
        let report = scans.iter_mut().find(|r| r.file == s.file && s.scanned);
        if let (Some(r), Some(fix)) = (report, trim) {
            r.fixes.push(fix);
        }
        match p {
            Ok(p) => {
                if s.scanned {
                    kept.push(s.fdi);
                }
                teeth.push((s.fdi, p));
            }
            // A labelled tooth that is no tooth is left out; its arch imports without it.
            Err(message) if s.scanned => {
                if let Some(r) = scans.iter_mut().find(|r| r.file == s.file) {
                    r.left_out.push(LeftOut {
                        fdi: s.fdi.number(),
                        reason: message.to_string(),
                    });
                }
            }
            Err(message) => {
                return Err(CaseError::Mesh {
                    path: s.path.clone(),
                    fdi: s.fdi,
                    case: loaded.origin.clone(),
                    message,
                });
            }
        }
    }
    if kept.len() < labelled.len() && case.presence_from_scans() {
        loaded.check_present(&case.present_with(&kept))?;
    }
    Ok(PatientTeeth {
        teeth,
        labelled: kept,
        orientation,
        scans,
    })
}

fn scan_error(loaded: &LoadedCase, path: &str, message: String) -> CaseError {
    CaseError::Scan {
        path: path.to_owned(),
        case: loaded.origin.clone(),
        message,
    }
}

/// Every imported tooth's raw mesh, in millimetres in its file's frame: one per `meshes` entry,
/// one per labelled tooth of each scan. A tooth given twice is refused.
fn read_sources(loaded: &LoadedCase) -> Result<(Vec<Source>, Vec<ScanReport>), CaseError> {
    let case = &loaded.case;
    let mesh_error = |path: &str, fdi: Fdi, message: ImportError| CaseError::Mesh {
        path: path.to_owned(),
        fdi,
        case: loaded.origin.clone(),
        message,
    };
    let files: Vec<_> = case.meshes.0.iter().collect();
    let read = crate::parallel::parallel_map(&files, |(fdi, spec)| {
        let path = Case::mesh_path(&loaded.origin, &spec.file);
        let shown = path.display().to_string();
        read_in_mm(&path, spec.units)
            .and_then(|mesh| check_raw(&mesh).map(|()| mesh))
            .map(|mesh| Source {
                fdi: **fdi,
                file: spec.file.clone(),
                path: shown.clone(),
                mesh,
                placement: spec.transform,
                scanned: false,
            })
            .map_err(|e| mesh_error(&shown, **fdi, e))
    });
    let mut sources = read.into_iter().collect::<Result<Vec<_>, _>>()?;
    let scans = crate::parallel::parallel_map(&case.scans, |scan| {
        let path = Case::mesh_path(&loaded.origin, &scan.file);
        let shown = path.display().to_string();
        let labels_file = match &scan.labels {
            super::import::Labels::Json(f) => Some(Case::mesh_path(&loaded.origin, f)),
            _ => None,
        };
        let mut labelled = read_labelled(&path, &scan.labels, labels_file.as_deref())
            .and_then(|m| check_scan(&m).map(|()| m))
            .map_err(|e| scan_error(loaded, &shown, e.to_string()))?;
        let scale = scan.units.mm();
        let mut fixes = tidy_labels(&mut labelled);
        for fix in &mut fixes {
            fix.at = fix.at.map(|x| x * scale);
        }
        let mut report = ScanReport {
            file: scan.file.clone(),
            fixes,
            left_out: Vec::new(),
        };
        let mut teeth = Vec::new();
        for (fdi, mesh) in split(&labelled) {
            if mesh.triangles.len() < MIN_TOOTH_TRIANGLES {
                report.left_out.push(LeftOut {
                    fdi: fdi.number(),
                    reason: format!(
                        "{} labelled triangles, fewer than a tooth's {MIN_TOOTH_TRIANGLES}",
                        mesh.triangles.len()
                    ),
                });
                continue;
            }
            teeth.push(Source {
                fdi,
                file: scan.file.clone(),
                path: shown.clone(),
                mesh: mesh.map_vertices(|v| v * scale),
                placement: scan.transform,
                scanned: true,
            });
        }
        Ok::<_, CaseError>((teeth, report))
    });
    let mut seen: BTreeMap<Fdi, String> = sources.iter().map(|s| (s.fdi, s.path.clone())).collect();
    let mut reports = Vec::new();
    for scan in scans {
        let (teeth, report) = scan?;
        reports.push(report);
        for s in teeth {
            if let Some(other) = seen.get(&s.fdi) {
                let what = if case.meshes.0.contains_key(&s.fdi) {
                    format!("also named in `meshes` ({other})")
                } else {
                    format!("also labelled in {other}")
                };
                return Err(scan_error(
                    loaded,
                    &s.path,
                    format!(
                        "tooth {} is labelled here and {what}: give each tooth once",
                        s.fdi
                    ),
                ));
            }
            seen.insert(s.fdi, s.path.clone());
            sources.push(s);
        }
    }
    Ok((sources, reports))
}
