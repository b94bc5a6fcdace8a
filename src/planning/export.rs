//! What a plan writes: one binary STL per arch per stage (the teeth of the arch where they stand
//! at that stage, for aligner fabrication) and the names of the files.

use std::path::{Path, PathBuf};

use super::stager::Plan;
use crate::teeth::{Arch, Dentition};

/// The stage mesh file of `arch` at stage `k`: `upper_00.stl`, `lower_12.stl`, … (at least two
/// digits, more when the plan has 100 stages or more).
pub fn stage_file(dir: &Path, arch: Arch, k: u32, stages: u32) -> PathBuf {
    let width = stages.to_string().len().max(2);
    let name = if arch == Arch::Upper {
        "upper"
    } else {
        "lower"
    };
    dir.join(format!("{name}_{k:0width$}.stl"))
}

/// The teeth of `arch` at stage `k` as one binary STL (millimetres, the case's frame; each
/// tooth a closed shell of its own).
pub fn stage_stl(d: &Dentition, plan: &Plan, arch: Arch, k: u32) -> Vec<u8> {
    let posed: Vec<_> = plan
        .poses_at(k)
        .into_iter()
        .filter(|(f, _)| f.arch() == arch)
        .filter_map(|(f, p)| Some((d.tooth(f)?, p)))
        .collect();
    let count: usize = posed
        .iter()
        .map(|(t, _)| t.geometry.mesh.triangles.len())
        .sum();
    let mut out = Vec::with_capacity(84 + 50 * count);
    let mut header = [0u8; 80];
    let title = format!("orthosim plan {} stage {k}", plan.case);
    let n = title.len().min(80);
    header[..n].copy_from_slice(&title.as_bytes()[..n]);
    out.extend_from_slice(&header);
    out.extend_from_slice(&(count as u32).to_le_bytes());
    for (t, pose) in posed {
        let mesh = &t.geometry.mesh;
        for i in 0..mesh.triangles.len() {
            let v = mesh.triangle(i).map(|p| pose.transform_point(p));
            let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
            for p in [normal, v[0], v[1], v[2]] {
                for c in p.to_array() {
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
    }
    out
}
