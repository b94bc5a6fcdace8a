//! Clinical measures of placed teeth: distances between adjacent teeth, occlusal contacts between
//! the arches, IPR limits, Bolton ratios and arch-length discrepancy.
//!
//! - **Distances**: the paper's horizontal distance between adjacent crown centres (x–z plane) and
//!   the exact minimal surface gap; gaps above [`GAP_FLAG_MM`] (1 mm, the clinical threshold) are
//!   flagged.
//! - **Occlusal contacts**: the surface of a tooth within [`OCCLUSAL_CONTACT_MM`] (0.05 mm) of the
//!   opposing arch, or inside it. Each triangle near an antagonist is split (the four-way split of
//!   the coverage check) into pieces with edges under [`PIECE_MM`]; a piece counts when its
//!   centroid's exact distance to the antagonist's mesh is within the tolerance, or the centroid
//!   lies inside it. Area error: at most the area of the pieces along the patch border, i.e. about
//!   the patch perimeter × 0.2 mm. Teeth apart (exact gap above zero) are not split where a
//!   piece's centroid lies farther from the antagonist than the tolerance plus the piece's radius
//!   (no point of the piece can then count), which gives the same area for far less work; a
//!   tooth's least gap is the exact mesh distance.
//! - **IPR**: per contact, flagged above [`IPR_CONTACT_LIMIT_MM`] (0.5 mm) per contact and above
//!   [`IPR_SURFACE_LIMIT_MM`] (0.25 mm) per surface (half the contact's overlap on each tooth).
//! - **Bolton** (Bolton 1958): anterior ratio = Σ mandibular / Σ maxillary mesiodistal widths of
//!   the six anterior teeth (norm 77.2 %), overall ratio of the twelve teeth from first molar to
//!   first molar (norm 91.3 %), and the mandibular excess in mm against each norm.
//! - **Arch-length discrepancy** per arch: space available (the path through the crown centres of
//!   the present teeth from first molar to first molar in the x–z plane, less half of each first
//!   molar's mesiodistal width) minus space required (Σ mesiodistal widths of the teeth present
//!   between the first molars, extracted ones left out). Negative means crowding, positive
//!   spacing; teeth in contact give about the sum of their contact gaps.

use serde::Serialize;

use crate::{
    geometry::{
        MeshRef, Pose, closest_point_on_mesh, closest_point_on_mesh_within, mesh_separation,
        point_inside_mesh,
    },
    sphere_tree::coverage::split4,
    teeth::{Arch, Fdi, ToothGeometry},
};

/// Gaps above this are flagged (mm).
pub const GAP_FLAG_MM: f32 = 1.0;
/// Surface within this of the opposing arch is in occlusal contact (mm).
pub const OCCLUSAL_CONTACT_MM: f32 = 0.05;
/// Largest piece edge for the occlusal contact area (mm).
pub const PIECE_MM: f32 = 0.2;
/// IPR limit per contact (mm).
pub const IPR_CONTACT_LIMIT_MM: f32 = 0.5;
/// IPR limit per surface (mm).
pub const IPR_SURFACE_LIMIT_MM: f32 = 0.25;
/// Bolton's anterior norm (%).
pub const BOLTON_ANTERIOR_NORM: f32 = 77.2;
/// Bolton's overall norm (%).
pub const BOLTON_OVERALL_NORM: f32 = 91.3;

/// A posed tooth for measuring.
#[derive(Clone, Copy)]
pub struct Posed<'a> {
    /// FDI number.
    pub fdi: Fdi,
    /// Shape.
    pub geometry: &'a ToothGeometry,
    /// Pose.
    pub pose: Pose,
}

impl<'a> Posed<'a> {
    /// The teeth of a simulation where they stand now.
    pub fn of_simulation(sim: &'a crate::movement::Simulation) -> Vec<Self> {
        sim.teeth
            .iter()
            .map(|t| Posed {
                fdi: t.fdi,
                geometry: &t.shape.geometry,
                pose: t.pose,
            })
            .collect()
    }

    /// The visible teeth of a dentition as placed.
    pub fn of_dentition(d: &'a crate::teeth::Dentition) -> Vec<Self> {
        d.visible()
            .map(|t| Posed {
                fdi: t.fdi,
                geometry: &t.geometry,
                pose: t.pose,
            })
            .collect()
    }
}

/// Occlusal contact of one tooth with the opposing arch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OcclusalContact {
    /// The tooth.
    pub fdi: Fdi,
    /// Surface area in contact (mm²).
    pub area_mm2: f32,
    /// Least exact distance to the opposing arch (mm; 0 when overlapping); None when no antagonist
    /// comes within the tolerance of its box.
    pub min_gap_mm: Option<f32>,
    /// Opposing teeth it touches.
    pub antagonists: Vec<Fdi>,
    /// Centroid of its contact surface (world), when there is one.
    pub centre: Option<[f32; 3]>,
}

fn world_box(t: &Posed) -> crate::geometry::Aabb {
    t.geometry
        .mesh
        .aabb()
        .transformed(&glam::Mat3::from_quat(t.pose.rotation), t.pose.translation)
}

fn near(a: &crate::geometry::Aabb, b: &crate::geometry::Aabb, margin: f32) -> bool {
    (a.min - glam::Vec3::splat(margin)).cmple(b.max).all()
        && (b.min - glam::Vec3::splat(margin)).cmple(a.max).all()
}

/// Occlusal contacts of every tooth with the opposing arch (see the module doc).
pub fn occlusal_contacts(teeth: &[Posed], tolerance: f32) -> Vec<OcclusalContact> {
    let boxes: Vec<_> = teeth.iter().map(world_box).collect();
    let one = |i: usize| {
        let t = &teeth[i];
        let mut area = 0.0f32;
        let mut weighted = glam::Vec3::ZERO;
        let mut min_gap = f32::INFINITY;
        let mut antagonists = Vec::new();
        for (j, o) in teeth.iter().enumerate() {
            if o.fdi.arch() == t.fdi.arch() || !near(&boxes[i], &boxes[j], tolerance) {
                continue;
            }
            let to_local = o.pose.inverse();
            let m = MeshRef {
                mesh: &o.geometry.mesh,
                bvh: &o.geometry.bvh,
            };
            // The pair's exact gap: beyond the tolerance nothing of it is in contact; apart, no
            // point of one tooth lies inside the other, so a piece whose centroid lies farther
            // from the antagonist than the tolerance plus the piece's radius is wholly out of
            // contact and is not split further.
            let pair_gap = mesh_separation(t.geometry.mesh_ref(), &t.pose, m, &o.pose).signed_gap();
            min_gap = min_gap.min(pair_gap.max(0.0));
            if pair_gap > tolerance {
                continue;
            }
            let apart = pair_gap > 0.0;
            let mut touched = false;
            for k in 0..t.geometry.mesh.triangles.len() {
                let tri = t
                    .geometry
                    .mesh
                    .triangle(k)
                    .map(|p| t.pose.transform_point(p));
                let tri_box = crate::geometry::Aabb::from_points(tri.iter().copied());
                if !near(&tri_box, &boxes[j], tolerance) {
                    continue;
                }
                let mut stack = vec![tri];
                while let Some(p) = stack.pop() {
                    let c = (p[0] + p[1] + p[2]) / 3.0;
                    let local = to_local.transform_point(c);
                    let radius = p.iter().map(|v| v.distance(c)).fold(0.0f32, f32::max);
                    let edge = p[0]
                        .distance(p[1])
                        .max(p[1].distance(p[2]))
                        .max(p[2].distance(p[0]));
                    if apart {
                        let Some((_, d)) =
                            closest_point_on_mesh_within(m, local, tolerance + radius)
                        else {
                            continue;
                        };
                        if edge > PIECE_MM {
                            stack.extend(split4(p));
                        } else if d <= tolerance {
                            let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                            area += a;
                            weighted += c * a;
                            touched = true;
                        }
                        continue;
                    }
                    if edge > PIECE_MM {
                        stack.extend(split4(p));
                        continue;
                    }
                    let Some((_, d)) = closest_point_on_mesh(m, local) else {
                        continue;
                    };
                    let inside = d <= 1.0 && point_inside_mesh(m, local);
                    let gap = if inside { 0.0 } else { d };
                    if gap <= tolerance {
                        let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                        area += a;
                        weighted += c * a;
                        touched = true;
                    }
                }
            }
            if touched {
                antagonists.push(o.fdi);
            }
        }
        OcclusalContact {
            fdi: t.fdi,
            area_mm2: area,
            min_gap_mm: min_gap.is_finite().then_some(min_gap),
            antagonists,
            centre: (area > 0.0).then(|| (weighted / area).to_array()),
        }
    };
    let indices: Vec<usize> = (0..teeth.len()).collect();
    let mut contacts = crate::parallel::parallel_map(&indices, |&i| one(i));
    // Contact is mutual: at a pair's closest points each surface lies within the tolerance of the
    // other, though near the tolerance only one side's sampled pieces may show it.
    for i in 0..contacts.len() {
        for a in contacts[i].antagonists.clone() {
            let fdi = contacts[i].fdi;
            if let Some(o) = contacts.iter_mut().find(|o| o.fdi == a)
                && !o.antagonists.contains(&fdi)
            {
                o.antagonists.push(fdi);
            }
        }
    }
    contacts
}

/// One contact's interproximal reduction and its limits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IprEntry {
    /// First tooth.
    pub a: Fdi,
    /// Second tooth.
    pub b: Fdi,
    /// Overlap to strip at the contact (mm).
    pub ipr_mm: f32,
    /// More than 0.5 mm at the contact.
    pub over_contact_limit: bool,
    /// More than 0.25 mm per surface, the contact's overlap shared equally by its two surfaces
    /// (with an equal share this agrees with the contact limit; it differs once a plan assigns
    /// the reduction unequally).
    pub over_surface_limit: bool,
}

/// IPR entries with their limits flagged.
pub fn ipr_entries(ipr: impl IntoIterator<Item = (Fdi, Fdi, f32)>) -> Vec<IprEntry> {
    ipr.into_iter()
        .map(|(a, b, mm)| IprEntry {
            a,
            b,
            ipr_mm: mm,
            over_contact_limit: mm > IPR_CONTACT_LIMIT_MM,
            over_surface_limit: 0.5 * mm > IPR_SURFACE_LIMIT_MM,
        })
        .collect()
}

/// Bolton analysis and arch-length discrepancy.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bolton {
    /// Anterior ratio (%).
    pub anterior_ratio_pct: f32,
    /// Its norm (%).
    pub anterior_norm_pct: f32,
    /// Mandibular anterior excess over the norm (mm; negative: maxillary excess).
    pub anterior_excess_mm: f32,
    /// Overall ratio (%).
    pub overall_ratio_pct: f32,
    /// Its norm (%).
    pub overall_norm_pct: f32,
    /// Mandibular excess over the overall norm (mm).
    pub overall_excess_mm: f32,
    /// Space available minus space required, upper arch (mm).
    pub arch_length_discrepancy_upper_mm: f32,
    /// The same, lower arch (mm).
    pub arch_length_discrepancy_lower_mm: f32,
}

/// Bolton ratios from the mesiodistal widths of `width(fdi)` (every tooth assumed present), and the
/// arch-length discrepancy of each arch from the placed teeth (`present` with their arc length on
/// the arch curve and mesiodistal width).
pub fn bolton(width: impl Fn(Fdi) -> f32, arches: [&[(Fdi, glam::Vec2, f32)]; 2]) -> Bolton {
    let sum = |quadrants: [u8; 2], positions: std::ops::RangeInclusive<u8>| -> f32 {
        quadrants
            .iter()
            .flat_map(|&q| positions.clone().map(move |p| (q, p)))
            .map(|(q, p)| width(Fdi::from_parts(q, p).expect("valid FDI")))
            .sum()
    };
    let (upper6, lower6) = (sum([1, 2], 1..=3), sum([3, 4], 1..=3));
    let (upper12, lower12) = (sum([1, 2], 1..=6), sum([3, 4], 1..=6));
    let discrepancy = |teeth: &[(Fdi, glam::Vec2, f32)]| -> f32 {
        // From first molar to first molar along the arch.
        let mut row: Vec<&(Fdi, glam::Vec2, f32)> =
            teeth.iter().filter(|t| t.0.position() <= 6).collect();
        row.sort_by_key(|t| t.0.arch_index());
        let (Some(first), Some(last)) = (row.first(), row.last()) else {
            return f32::NAN;
        };
        if first.0.position() != 6 || last.0.position() != 6 {
            return f32::NAN;
        }
        let span: f32 = row.windows(2).map(|w| w[0].1.distance(w[1].1)).sum();
        let available = span - 0.5 * (first.2 + last.2);
        let required: f32 = row
            .iter()
            .filter(|t| t.0.position() <= 5)
            .map(|t| t.2)
            .sum();
        available - required
    };
    Bolton {
        anterior_ratio_pct: 100.0 * lower6 / upper6,
        anterior_norm_pct: BOLTON_ANTERIOR_NORM,
        anterior_excess_mm: lower6 - upper6 * BOLTON_ANTERIOR_NORM / 100.0,
        overall_ratio_pct: 100.0 * lower12 / upper12,
        overall_norm_pct: BOLTON_OVERALL_NORM,
        overall_excess_mm: lower12 - upper12 * BOLTON_OVERALL_NORM / 100.0,
        arch_length_discrepancy_upper_mm: discrepancy(arches[0]),
        arch_length_discrepancy_lower_mm: discrepancy(arches[1]),
    }
}

/// Each posed tooth's crown centre in the x–z plane with its mesiodistal width, per arch (upper,
/// lower): the input of [`bolton`]'s discrepancy.
pub fn arch_positions(teeth: &[Posed]) -> [Vec<(Fdi, glam::Vec2, f32)>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for t in teeth {
        let k = match t.fdi.arch() {
            Arch::Upper => 0,
            Arch::Lower => 1,
        };
        let c = t.pose.transform_point(t.geometry.frame.crown_centre);
        out[k].push((
            t.fdi,
            glam::Vec2::new(c.x, c.z),
            t.geometry.anatomy.mesiodistal,
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{Case, Dentition};

    #[test]
    fn bolton_of_equal_widths_and_spacing_of_an_extraction() {
        let b = bolton(|_| 7.0, [&[], &[]]);
        assert!((b.anterior_ratio_pct - 100.0).abs() < 1e-4);
        assert!((b.anterior_excess_mm - (42.0 - 42.0 * 0.772)).abs() < 1e-3);
        assert!(b.arch_length_discrepancy_upper_mm.is_nan());
        // Normal arch: teeth in contact, so the discrepancy is small; an extraction frees about its
        // width.
        let measure = |case: &str| {
            let d = Dentition::build(Case::resolve(case).unwrap()).unwrap();
            let teeth = Posed::of_dentition(&d);
            let arches = arch_positions(&teeth);
            let w = |f: Fdi| d.tooth(f).unwrap().geometry.anatomy.mesiodistal;
            bolton(w, [&arches[0], &arches[1]])
        };
        let normal = measure("normal");
        assert!(
            normal.arch_length_discrepancy_upper_mm.abs() < 3.0,
            "{normal:?}"
        );
        let case1 = measure("case1");
        let freed =
            case1.arch_length_discrepancy_upper_mm - normal.arch_length_discrepancy_upper_mm;
        assert!(
            (freed - 2.0 * 7.0).abs() < 1.5,
            "two premolars' width: {freed}"
        );
    }

    #[test]
    fn arches_in_occlusion_touch_and_apart_they_do_not() {
        let d = Dentition::build(Case::resolve("normal").unwrap()).unwrap();
        let posed = |lift: f32| -> Vec<Posed> {
            d.visible()
                .map(|t| Posed {
                    fdi: t.fdi,
                    geometry: &t.geometry,
                    pose: if t.fdi.arch() == Arch::Upper {
                        Pose::new(t.pose.rotation, t.pose.translation + glam::Vec3::Y * lift)
                    } else {
                        t.pose
                    },
                })
                .collect()
        };
        let closed = occlusal_contacts(&posed(0.0), OCCLUSAL_CONTACT_MM);
        let touching: Vec<_> = closed.iter().filter(|c| c.area_mm2 > 0.0).collect();
        assert!(!touching.is_empty(), "{closed:?}");
        for c in &touching {
            assert!(c.min_gap_mm.unwrap() <= OCCLUSAL_CONTACT_MM && !c.antagonists.is_empty());
            assert!(c.antagonists.iter().all(|a| a.arch() != c.fdi.arch()));
            // Contacts are seen from both sides.
            for a in &c.antagonists {
                let other = closed.iter().find(|o| o.fdi == *a).unwrap();
                assert!(other.antagonists.contains(&c.fdi), "{c:?} {other:?}");
            }
        }
        let total = |list: &[OcclusalContact]| list.iter().map(|c| c.area_mm2).sum::<f32>();
        // Pressed 0.3 mm further together, the arches meet over more surface.
        let pressed = occlusal_contacts(&posed(-0.3), OCCLUSAL_CONTACT_MM);
        assert!(total(&pressed) > total(&closed) + 1.0);
        assert!(pressed.iter().filter(|c| c.area_mm2 > 0.0).count() > touching.len());
        let open = occlusal_contacts(&posed(2.0), OCCLUSAL_CONTACT_MM);
        assert!(
            open.iter()
                .all(|c| c.area_mm2 == 0.0 && c.antagonists.is_empty())
        );
    }

    #[test]
    fn ipr_limits_are_flagged() {
        let f = |n| Fdi::new(n).unwrap();
        let e = ipr_entries([(f(11), f(21), 0.3), (f(12), f(11), 0.6)]);
        assert!(!e[0].over_contact_limit && !e[0].over_surface_limit);
        assert!(e[1].over_contact_limit && e[1].over_surface_limit);
    }
}
