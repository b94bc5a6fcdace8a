//! Little's irregularity index (Little, AJO 1975;68:554–63): the sum of the five displacements
//! between the anatomic contact points of the six anterior teeth of an arch, canine to canine,
//! measured parallel to the occlusal plane (mm; 0 is perfect alignment, 4–6 moderate crowding,
//! over 7 severe).
//!
//! A tooth's anatomic contact points are fixed on the tooth, not where it happens to touch
//! ([`ContactPoints`]): where it touches its neighbours when the row is aligned. So a tooth turned
//! in its row moves its contact points off its neighbours' and the index grows by about the
//! crown's width times the sine of the turn, as it does on a cast. The displacement of a pair is
//! the distance between the two facing points in the world's x–z plane (the occlusal plane of
//! orthosim's frame); heights do not count.
//!
//! Guarantee: exact (to the closest-point query's float rounding) for teeth whose aligned place is
//! known: 0 on that aligned row. For scanned crowns the points come from the crown's outline
//! ([`shape_contact_points`]), which reads a well-aligned lower row of procedural teeth at about
//! 0.5 mm and an upper row, whose crowns meet at an angle at their labial corners, at about 3 mm;
//! an imported arch's index is an upper bound of that order.

use std::collections::BTreeMap;

use glam::{Vec2, Vec3};

use super::super::{
    fdi::{Arch, Fdi},
    tooth_shape::ToothGeometry,
};
use crate::geometry::{MeshRef, Pose, mesh_separation};

/// The part of the crown's height (from the cervical plane, as fractions of the crown's length)
/// where a tooth's proximal contacts lie.
pub const CONTACT_BAND: [f32; 2] = [0.45, 0.95];

/// A tooth's anatomic contact points from its shape alone, in its local frame (mesial, then
/// distal): the crown's farthest points along its mesiodistal axis within [`CONTACT_BAND`], put on
/// the mesiodistal line through the crown centre (the proximal crests' labiolingual place varies
/// with the crown's outline; on the line, a tooth's points are where its neighbours meet it in a
/// row).
pub fn shape_contact_points(fdi: Fdi, geometry: &ToothGeometry) -> [Vec3; 2] {
    let f = &geometry.frame;
    let mesial_x = Vec3::X * fdi.local_x_mesial_sign();
    let mesial = if f.mesiodistal.dot(mesial_x) >= 0.0 {
        f.mesiodistal
    } else {
        -f.mesiodistal
    };
    let height = |v: Vec3| (v - f.cervical_centre).dot(f.long_axis);
    let [lo, hi] = CONTACT_BAND.map(|b| b * f.crown_length);
    let c = f.crown_centre;
    let mut reach = [0.0f32; 2];
    for &v in &geometry.mesh.vertices {
        let h = height(v);
        if h < lo || h > hi {
            continue;
        }
        let along = (v - c).dot(mesial);
        reach[0] = reach[0].max(along);
        reach[1] = reach[1].max(-along);
    }
    [c + mesial * reach[0], c - mesial * reach[1]]
}

/// A posed tooth as the index reads it.
#[derive(Clone, Copy)]
pub struct Anterior<'a> {
    /// FDI number.
    pub fdi: Fdi,
    /// Shape.
    pub geometry: &'a ToothGeometry,
    /// Pose.
    pub pose: Pose,
}

/// The anatomic contact points of an arrangement's anterior teeth, each in its tooth's local
/// frame: mesial, then distal.
///
/// Where both teeth of a pair stand aligned (procedural teeth in the arrangement orthosim builds
/// them in, neighbours 0.05 mm apart), a pair's points are the midpoint of the exact closest points
/// between the two crowns there: where the teeth touch when aligned, which is what a clinician
/// marks on a cast. Then an aligned row reads 0 whatever the crowns' outlines. Elsewhere (a
/// scanned crown, whose aligned place is not known) the points come from the shape alone
/// ([`shape_contact_points`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactPoints(pub BTreeMap<Fdi, [Vec3; 2]>);

/// Which of a tooth's two points faces `other` (0 mesial, 1 distal): a tooth faces the midline with
/// its mesial side, so the centrals face each other mesially and elsewhere the tooth nearer the
/// midline shows its distal side.
fn facing(t: Fdi, other: Fdi) -> usize {
    usize::from(t.position() < other.position())
}

impl ContactPoints {
    /// The points of `teeth`, those pairs whose teeth both pass `aligned` taken from their poses
    /// (see the type's doc).
    pub fn new(teeth: &[Anterior], aligned: impl Fn(Fdi) -> bool) -> Self {
        fn mesh<'a>(t: &Anterior<'a>) -> MeshRef<'a> {
            MeshRef {
                mesh: &t.geometry.mesh,
                bvh: &t.geometry.bvh,
            }
        }
        // Each side from the aligned pair where there is one; the outline only for the rest.
        let mut found: BTreeMap<Fdi, [Option<Vec3>; 2]> = teeth
            .iter()
            .filter(|t| t.fdi.position() <= 3)
            .map(|t| (t.fdi, [None; 2]))
            .collect();
        let find = |fdi: Fdi| teeth.iter().find(|t| t.fdi == fdi);
        for arch in [Arch::Upper, Arch::Lower] {
            for (a, b) in anterior_pairs(arch) {
                let (Some(ta), Some(tb)) = (find(a), find(b)) else {
                    continue;
                };
                if !aligned(a) || !aligned(b) {
                    continue;
                }
                let s = mesh_separation(mesh(ta), &ta.pose, mesh(tb), &tb.pose);
                let mid = 0.5 * (s.point_a + s.point_b);
                if !mid.is_finite() {
                    continue;
                }
                for (t, other) in [(ta, b), (tb, a)] {
                    let local = t.pose.inverse().transform_point(mid);
                    if let Some(p) = found.get_mut(&t.fdi) {
                        p[facing(t.fdi, other)] = Some(local);
                    }
                }
            }
        }
        let points = found
            .into_iter()
            .filter_map(|(fdi, sides)| {
                let t = find(fdi)?;
                let shape = || shape_contact_points(fdi, t.geometry);
                let [m, d] = match sides {
                    [Some(m), Some(d)] => [m, d],
                    [m, d] => {
                        let s = shape();
                        [m.unwrap_or(s[0]), d.unwrap_or(s[1])]
                    }
                };
                Some((fdi, [m, d]))
            })
            .collect();
        Self(points)
    }
}

/// One of the five displacements of an arch's index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactDisplacement {
    /// The tooth nearer the patient's right.
    pub a: Fdi,
    /// The tooth nearer the patient's left.
    pub b: Fdi,
    /// Distance between their facing contact points in the occlusal plane (mm).
    pub mm: f32,
}

/// The five anterior teeth pairs of `arch`, from the right canine to the left one.
pub fn anterior_pairs(arch: Arch) -> [(Fdi, Fdi); 5] {
    let (right, left) = match arch {
        Arch::Upper => (1, 2),
        Arch::Lower => (4, 3),
    };
    let f = |q: u8, p: u8| Fdi::from_parts(q, p).expect("anterior FDI numbers are valid");
    [
        (f(right, 3), f(right, 2)),
        (f(right, 2), f(right, 1)),
        (f(right, 1), f(left, 1)),
        (f(left, 1), f(left, 2)),
        (f(left, 2), f(left, 3)),
    ]
}

/// The displacements of `arch`'s index for the posed teeth and their contact points, or None when
/// one of its six anterior teeth (or its points) is missing: the index is defined on all six.
pub fn displacements(
    teeth: &[Anterior],
    points: &ContactPoints,
    arch: Arch,
) -> Option<[ContactDisplacement; 5]> {
    let world = |fdi: Fdi, other: Fdi| -> Option<Vec2> {
        let t = teeth.iter().find(|t| t.fdi == fdi)?;
        let p = t
            .pose
            .transform_point(points.0.get(&fdi)?[facing(fdi, other)]);
        Some(Vec2::new(p.x, p.z))
    };
    let pairs = anterior_pairs(arch);
    let mut out = pairs.map(|(a, b)| ContactDisplacement { a, b, mm: 0.0 });
    for d in &mut out {
        d.mm = world(d.a, d.b)?.distance(world(d.b, d.a)?);
    }
    Some(out)
}

/// Little's irregularity index of `arch` (mm), or None when an anterior tooth is missing.
pub fn irregularity_mm(teeth: &[Anterior], points: &ContactPoints, arch: Arch) -> Option<f32> {
    displacements(teeth, points, arch).map(|d| d.iter().map(|p| p.mm).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{Case, Dentition};

    fn posed(d: &Dentition) -> Vec<Anterior<'_>> {
        d.visible()
            .map(|t| Anterior {
                fdi: t.fdi,
                geometry: &t.geometry,
                pose: t.pose,
            })
            .collect()
    }

    fn index(teeth: &[Anterior], d: &Dentition, arch: Arch) -> f32 {
        irregularity_mm(teeth, &d.contact_points, arch).unwrap()
    }

    /// Turns (about the long axis, through the crown centre) and moves (world) tooth `fdi`.
    fn displace(teeth: &mut [Anterior], fdi: u8, turn_deg: f32, shift: Vec3) {
        let t = teeth.iter_mut().find(|t| t.fdi.number() == fdi).unwrap();
        let centre = t.pose.transform_point(t.geometry.frame.crown_centre);
        let axis = t.pose.rotation * t.geometry.frame.long_axis;
        let turn = glam::Quat::from_axis_angle(axis, turn_deg.to_radians());
        t.pose = Pose::new(
            turn * t.pose.rotation,
            centre + turn * (t.pose.translation - centre) + shift,
        );
    }

    #[test]
    fn an_aligned_row_reads_zero_and_a_displaced_tooth_adds_its_displacement() {
        let d = Dentition::build(Case::resolve("normal").unwrap()).unwrap();
        let teeth = posed(&d);
        for arch in [Arch::Upper, Arch::Lower] {
            let i = index(&teeth, &d, arch);
            assert!(i < 0.01, "{arch:?}: {i}");
            // From the outlines alone, the floor the module doc states.
            let shape = ContactPoints::new(&teeth, |_| false);
            let floor = irregularity_mm(&teeth, &shape, arch).unwrap();
            assert!((0.2..4.0).contains(&floor), "{arch:?}: {floor}");
        }
        // 42 turned 20°: each contact point leaves its neighbour's by about half the crown's
        // width times sin 20°.
        let mut turned = teeth.clone();
        displace(&mut turned, 42, 20.0, Vec3::ZERO);
        let w = d
            .tooth(Fdi::new(42).unwrap())
            .unwrap()
            .geometry
            .anatomy
            .mesiodistal;
        let expected = w * 20f32.to_radians().sin();
        let got = index(&turned, &d, Arch::Lower);
        assert!(
            (got - expected).abs() < 0.3 * expected,
            "{got} vs {expected}"
        );
        assert!(index(&turned, &d, Arch::Upper) < 0.01);
        // 31 moved 1 mm lingually (−z at the front): both its contacts open by 1 mm.
        let mut moved = teeth.clone();
        displace(&mut moved, 31, 0.0, Vec3::new(0.0, 0.0, -1.0));
        let got = index(&moved, &d, Arch::Lower);
        assert!((got - 2.0).abs() < 0.2, "{got}");
        // Moved straight up, it reads as aligned: heights do not count.
        let mut raised = teeth.clone();
        displace(&mut raised, 31, 0.0, Vec3::Y * 2.0);
        assert!(index(&raised, &d, Arch::Lower) < 0.01);
        // A missing incisor leaves the index undefined.
        let mut missing = teeth.clone();
        missing.retain(|t| t.fdi.number() != 31);
        assert!(irregularity_mm(&missing, &d.contact_points, Arch::Lower).is_none());
        assert!(irregularity_mm(&missing, &d.contact_points, Arch::Upper).is_some());
    }

    #[test]
    fn the_crowded_case_starts_moderately_crowded() {
        let d = Dentition::build(Case::resolve("crowded").unwrap()).unwrap();
        let teeth = posed(&d);
        let lower = index(&teeth, &d, Arch::Lower);
        assert!((5.0..=6.0).contains(&lower), "{lower}");
        assert!(index(&teeth, &d, Arch::Upper) < 0.01);
    }
}
