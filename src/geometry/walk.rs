//! The penetration estimate found from the contact ([`mesh_penetration_near`]): a walk over the
//! part of each surface that lies inside the other, from the triangles at the contact.

use glam::Vec3;

pub use rewalk::InsideSamples;

use super::{
    aabb::Aabb,
    mesh_distance::{Deepest, MeshRef},
    pose::Pose,
    ray::SegmentTargets,
    stars::VertexStars,
};

/// One side of [`mesh_penetration_near`]: a mesh, its vertex stars, and triangles of it that
/// include every triangle meeting the other mesh's surface.
#[derive(Clone, Copy)]
pub struct NearContact<'a> {
    /// The mesh with its hierarchy.
    pub mesh: MeshRef<'a>,
    /// Its vertex stars ([`VertexStars::of`] the same mesh).
    pub stars: &'a VertexStars,
    /// Triangle indices: every triangle that meets the other surface must be among them (more
    /// are allowed).
    pub near: &'a [u32],
}

/// [`super::mesh_penetration`] found from the contact: the same estimate (the deepest vertex or
/// triangle centroid of either mesh inside the other), sampling only the part of each surface
/// that lies inside the other.
///
/// Why that finds every sample point inside the other mesh: a vertex inside with a neighbour
/// outside ends an edge that crosses the other surface, so the triangles on that edge meet the
/// other surface and are among `near`; the vertices inside connect to such a vertex through
/// vertices inside, unless their whole piece of the mesh is inside (each piece's first vertex is
/// therefore tested too). A triangle with its centroid inside has a corner inside, reached by the
/// walk, or crosses the other surface and is among `near`. The walk starts at the corners and
/// centroids of `near` and spreads from each vertex found inside to the triangles around it.
///
/// Two savings, neither changing the result:
/// - **Inside or out, carried along edges.** A segment of one surface (an edge, or a corner to
///   its triangle's centroid) crosses the other surface only at triangles meeting this surface,
///   which are among the other side's `near`. So when that list is short (at most
///   [`CARRY_LIMIT`] triangles) a sample's side is its neighbour's, flipped by the parity of the
///   segment's crossings with them; a segment that passes within 10⁻⁶ (barycentric) of one of
///   their edges or ends within 10⁻⁴ of its length from one of their planes is not trusted, and
///   the sample is tested by rays through the whole mesh instead, as every sample is when the
///   list is long. The list is kept in runs of nearby triangles under one box each
///   (`SegmentTargets`), so a short segment is tested against few of them.
/// - **Depths bounded by the neighbour's.** The distance to a surface changes by at most the
///   distance moved, and a segment that enters the other mesh crosses its surface; so a sample's
///   depth is at most its inside neighbour's (or bound) plus the segment's length, or the length
///   alone from an outside neighbour. A sample whose bound does not exceed the deepest so far
///   cannot be the deepest and is not measured; one that can is measured only among the surface
///   points within its bound. The distance to the other surface's triangle nearest the last
///   sample measured bounds the depth as well, and the walk keeps that triangle near: often it
///   is the sample's own nearest, so the bound is the depth itself.
pub fn mesh_penetration_near(
    a: NearContact,
    pose_a: &Pose,
    b: NearContact,
    pose_b: &Pose,
) -> (f32, Vec3, Vec3) {
    let p = mesh_penetration_near_from(a, pose_a, b, pose_b, 0.0);
    (p.depth, p.points[0], p.points[1])
}

/// [`mesh_penetration_near`] told a depth that some sample point of either mesh reaches inside
/// the other (`floor`, mm; for instance [`sample_depth`] of the deepest sample of an earlier
/// placement), so that shallower samples are not measured. The result is the same for every
/// floor up to the true estimate: each walk is exact when its own deepest sample reaches the
/// floor, and when it does not, the other walk's does and wins the comparison. Also returns
/// which mesh the deepest sample lies on (`false`: the first, whose point comes first).
///
/// The result also keeps every sample found inside with an upper bound of its depth
/// ([`Penetration::inside`]), from which a later placement of the same meshes may be searched
/// without walking ([`InsideSamples::rewalk`]).
pub fn mesh_penetration_near_from(
    a: NearContact,
    pose_a: &Pose,
    b: NearContact,
    pose_b: &Pose,
    floor: f32,
) -> Penetration {
    let (deepest_a, found_a) = Walk::new(&a, pose_a, &b, pose_b, floor).deepest();
    let (deepest_b, found_b) = Walk::new(&b, pose_b, &a, pose_a, floor).deepest();
    let inside = InsideSamples::walked([a.mesh, b.mesh], [pose_a, pose_b], [found_a, found_b]);
    Penetration::of(deepest_a, deepest_b, inside)
}

/// What [`mesh_penetration_near_from`] and [`InsideSamples::rewalk`] find.
#[derive(Clone, Debug)]
pub struct Penetration {
    /// The depth of the deepest sample (mm; 0 when no sample lies inside the other mesh).
    pub depth: f32,
    /// The deepest point and the nearest point of the other surface (world), the first mesh's
    /// point first (as [`mesh_penetration_near`]).
    pub points: [Vec3; 2],
    /// Whether the deepest sample lies on the second mesh.
    pub on_b: bool,
    /// The samples found inside, for a later search of the same meshes.
    pub inside: InsideSamples,
}

impl Penetration {
    /// The deeper of the two walks' results (the first's on a tie), each (depth, sample point,
    /// nearest point of the other surface).
    fn of(a: (f32, Vec3, Vec3), b: (f32, Vec3, Vec3), inside: InsideSamples) -> Self {
        let ((da, pa, qa), (db, pb, qb)) = (a, b);
        let (depth, points, on_b) = if da >= db {
            (da, [pa, qa], false)
        } else {
            (db, [qb, pb], true)
        };
        Self {
            depth,
            points,
            on_b,
            inside,
        }
    }
}

/// The depth inside `other` (posed by `pose_other`) of a point `local` of a mesh posed by
/// `pose`, or None when the point is outside: for a sample point of that mesh (a vertex or a
/// triangle's centroid), a floor that [`mesh_penetration_near_from`] may be told, less the
/// rounding of mapping a point found elsewhere back to `local`.
pub fn sample_depth(local: Vec3, pose: &Pose, other: MeshRef, pose_other: &Pose) -> Option<f32> {
    let mut deepest = Deepest::new(pose, other, pose_other);
    let p = deepest.place(local);
    deepest.inside(p).then(|| deepest.depth(p, f32::INFINITY))
}

/// Most near triangles of the other side against which the walk carries inside or out along
/// segments; beyond it every sample is tested by rays.
pub const CARRY_LIMIT: usize = 256;

/// What the walk knows of a vertex.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Unknown,
    Outside,
    /// Inside, with an upper bound of its depth (its depth when measured).
    Inside(f32),
}

/// The walk of [`mesh_penetration_near`] over one mesh's part inside the other.
struct Walk<'a> {
    a: NearContact<'a>,
    /// The other side's near triangles (its frame) with their boxes, when few enough to carry
    /// sides along segments.
    others: Option<SegmentTargets>,
    side: Vec<Side>,
    seen_triangle: Vec<bool>,
    inside: Vec<u32>,
    /// Every sample found inside (see [`InsideSamples`] for the numbering) with an upper bound
    /// of its depth.
    found: Vec<(u32, f32)>,
    deepest: Deepest<'a>,
}

impl<'a> Walk<'a> {
    fn new(
        a: &NearContact<'a>,
        pose_a: &Pose,
        b: &NearContact<'a>,
        pose_b: &Pose,
        floor: f32,
    ) -> Self {
        let others = (b.near.len() <= CARRY_LIMIT).then(|| {
            SegmentTargets::new(
                b.near
                    .iter()
                    .map(|&t| {
                        let v = b.mesh.mesh.triangle(t as usize);
                        (v, Aabb::from_points(v))
                    })
                    .collect(),
            )
        });
        Self {
            a: *a,
            others,
            side: vec![Side::Unknown; a.mesh.mesh.vertices.len()],
            seen_triangle: vec![false; a.mesh.mesh.triangles.len()],
            inside: Vec::new(),
            found: Vec::new(),
            deepest: Deepest::new(pose_a, b.mesh, pose_b).with_floor(floor),
        }
    }

    /// Depth, point (world) and nearest point of b's surface (world), as
    /// [`super::mesh_penetration`], and the samples found inside with bounds of their depths.
    fn deepest(mut self) -> ((f32, Vec3, Vec3), Vec<(u32, f32)>) {
        for &t in self.a.near {
            self.triangle(t);
        }
        for &v in self.a.stars.pieces() {
            let p = self.deepest.place(self.a.mesh.mesh.vertices[v as usize]);
            self.alone(v, p);
        }
        while let Some(v) = self.inside.pop() {
            for &t in self.a.stars.around(v as usize) {
                self.triangle(t);
            }
        }
        (self.deepest.result(), self.found)
    }

    fn triangle(&mut self, t: u32) {
        if std::mem::replace(&mut self.seen_triangle[t as usize], true) {
            return;
        }
        let corners = self.a.mesh.mesh.triangles[t as usize];
        let local = self.a.mesh.mesh.triangle(t as usize);
        let placed = local.map(|v| self.deepest.place(v));
        // Carried from a corner whose side is known (one is tested alone when none is).
        let k = corners
            .iter()
            .position(|&c| self.side[c as usize] != Side::Unknown)
            .unwrap_or(0);
        let (base, start) = (corners[k], placed[k]);
        self.alone(base, start);
        // The centroid taken in the mesh's frame, as the whole-mesh search takes it.
        let centroid = self.deepest.place((local[0] + local[1] + local[2]) / 3.0);
        if let Side::Inside(bound) = self.sample(base, start, centroid) {
            let vertices = self.a.mesh.mesh.vertices.len() as u32;
            self.found.push((vertices + t, bound));
        }
        for (c, p) in corners.into_iter().zip(placed) {
            if self.side[c as usize] == Side::Unknown {
                self.side[c as usize] = self.sample(base, start, p);
                if let Side::Inside(bound) = self.side[c as usize] {
                    self.inside.push(c);
                    self.found.push((c, bound));
                }
            }
        }
    }

    /// Settles vertex `v`, at `p` (b's frame), by testing it alone (rays), if its side is
    /// unknown.
    fn alone(&mut self, v: u32, p: Vec3) {
        if self.side[v as usize] != Side::Unknown {
            return;
        }
        self.side[v as usize] = if self.deepest.inside(p) {
            self.inside.push(v);
            let bound = self.deepest.depth(p, f32::INFINITY);
            self.found.push((v, bound));
            Side::Inside(bound)
        } else {
            Side::Outside
        };
    }

    /// The side of the point `p` (b's frame) reached from vertex `from` (side known, at `start`)
    /// along the segment between them, measuring its depth when inside.
    fn sample(&mut self, from: u32, start: Vec3, p: Vec3) -> Side {
        let carried = self.others.as_ref().and_then(|o| o.parity(start, p));
        let length = start.distance(p) * (1.0 + 1e-5) + 1e-6;
        let bound = match (carried, self.side[from as usize]) {
            (Some(false), Side::Outside) => return Side::Outside,
            (Some(true), Side::Inside(_)) => return Side::Outside,
            (Some(false), Side::Inside(d)) => (d + length) * (1.0 + 1e-6),
            (Some(true), _) => length,
            _ => {
                if !self.deepest.inside(p) {
                    return Side::Outside;
                }
                f32::INFINITY
            }
        };
        Side::Inside(self.deepest.depth(p, bound))
    }
}
mod rewalk;

/// The penetration walk checked on real teeth (kept here, with the test-only use of the teeth
/// above this layer, so that the layer check's test-block rule covers it).
#[cfg(test)]
mod tooth_tests {
    use super::*;
    use crate::geometry::mesh_distance::tests::refs;
    use crate::geometry::trimesh::tests::cuboid;
    use crate::geometry::{TriMesh, mesh_penetration};
    use glam::Quat;

    /// Triangles of `a` (posed) that meet `b`'s surface, by testing every pair.
    fn meeting(a: &TriMesh, pose_a: &Pose, b: &TriMesh, pose_b: &Pose) -> Vec<u32> {
        let world =
            |m: &TriMesh, pose: &Pose, i: usize| m.triangle(i).map(|v| pose.transform_point(v));
        let boxes = |m: &TriMesh, pose: &Pose| -> Vec<Aabb> {
            (0..m.triangles.len())
                .map(|i| Aabb::from_points(world(m, pose, i)))
                .collect()
        };
        let (boxes_a, boxes_b) = (boxes(a, pose_a), boxes(b, pose_b));
        (0..a.triangles.len() as u32)
            .filter(|&i| {
                let ta = world(a, pose_a, i as usize);
                (0..b.triangles.len()).any(|j| {
                    boxes_a[i as usize].distance_squared(&boxes_b[j]) <= 0.0
                        && crate::geometry::triangles_intersect(&ta, &world(b, pose_b, j))
                })
            })
            .collect()
    }

    /// The walk from the contact finds the same deepest sample as the whole-mesh search, for two
    /// real teeth overlapping by up to most of their size, and for a box wholly inside another
    /// (no triangle meets the other surface there: the walk starts from each piece's vertex).
    #[test]
    fn penetration_from_the_contact_matches_the_whole_mesh_search() {
        use crate::teeth::{Arch, ToothGeometry, ToothKind, ToothResolution};
        let a =
            ToothGeometry::procedural(Arch::Lower, ToothKind::FirstMolar, ToothResolution::PAPER);
        let b = ToothGeometry::procedural(
            Arch::Upper,
            ToothKind::SecondPremolar,
            ToothResolution::PAPER,
        );
        let mut n = crate::geometry::test_numbers(41);
        let mut deep = 0;
        for case in 0..60 {
            let pose_a = Pose::new(
                Quat::from_euler(glam::EulerRot::XYZ, n() * 6.0, n() * 6.0, n() * 6.0),
                Vec3::new(n(), n(), n()) * 20.0,
            );
            let offset = Vec3::new(n(), n() + 0.5, n()) * 2.0 * (2.0 + 8.0 * (case as f32 / 60.0));
            let pose_b = Pose::new(
                Quat::from_euler(glam::EulerRot::XYZ, n() * 6.0, n() * 6.0, n() * 6.0),
                pose_a.transform_point(offset),
            );
            let (near_a, near_b) = (
                meeting(&a.mesh, &pose_a, &b.mesh, &pose_b),
                meeting(&b.mesh, &pose_b, &a.mesh, &pose_a),
            );
            let whole = mesh_penetration(a.mesh_ref(), &pose_a, b.mesh_ref(), &pose_b);
            let walk_from = |near_a: &[u32], near_b: &[u32], floor: f32| {
                let p = mesh_penetration_near_from(
                    NearContact {
                        mesh: a.mesh_ref(),
                        stars: &a.stars,
                        near: near_a,
                    },
                    &pose_a,
                    NearContact {
                        mesh: b.mesh_ref(),
                        stars: &b.stars,
                        near: near_b,
                    },
                    &pose_b,
                    floor,
                );
                (p.depth, p.points[0], p.points[1], p.on_b)
            };
            let walk = |near_a: &[u32], near_b: &[u32]| {
                let (d, p, q, _) = walk_from(near_a, near_b, 0.0);
                (d, p, q)
            };
            // Told a floor up to the true depth, the walk finds the same; the deepest sample's
            // depth, found again from its place, is such a floor.
            let (d, p, q, on_b) = walk_from(&near_a, &near_b, 0.0);
            if d > 0.0 {
                let (other, pose_own, pose_other) = if on_b {
                    (&a, &pose_b, &pose_a)
                } else {
                    (&b, &pose_a, &pose_b)
                };
                let sample = if on_b { q } else { p };
                let local = pose_own.inverse().transform_point(sample);
                let again = sample_depth(local, pose_own, other.mesh_ref(), pose_other).unwrap();
                assert!((again - d).abs() < 1e-4, "case {case}: {again} against {d}");
                for floor in [d, 0.5 * d, again - 1e-4] {
                    let (df, pf, qf, side) = walk_from(&near_a, &near_b, floor);
                    assert_eq!(
                        (df, pf, qf, side),
                        (d, p, q, on_b),
                        "case {case}, floor {floor}"
                    );
                }
            }
            // From the meeting triangles, and from every triangle (more than are needed, as the
            // exact stage's candidates are): sides carried against all of the other's.
            let every = |n: usize| (0..n as u32).collect::<Vec<_>>();
            let (all_a, all_b) = (every(a.mesh.triangles.len()), every(b.mesh.triangles.len()));
            assert!(all_a.len() <= CARRY_LIMIT && all_b.len() <= CARRY_LIMIT);
            for walked in [walk(&near_a, &near_b), walk(&all_a, &all_b)] {
                assert_eq!(walked.0, whole.0, "case {case}");
                if whole.0 > 0.0 {
                    assert_eq!((walked.1, walked.2), (whole.1, whole.2), "case {case}");
                }
            }
            // The hierarchy search lists every meeting triangle (and only near ones).
            let (cross_a, cross_b) = crate::geometry::crossing_triangles(
                a.mesh_ref(),
                &pose_a,
                b.mesh_ref(),
                &pose_b,
                1e-4,
            );
            assert!(near_a.iter().all(|t| cross_a.contains(t)), "case {case}");
            assert!(near_b.iter().all(|t| cross_b.contains(t)), "case {case}");
            for &t in cross_a.iter().take(12) {
                let ta = a
                    .mesh
                    .triangle(t as usize)
                    .map(|v| pose_a.transform_point(v));
                let nearest = (0..b.mesh.triangles.len())
                    .map(|j| {
                        let tb = b.mesh.triangle(j).map(|v| pose_b.transform_point(v));
                        crate::geometry::closest_points_triangle_triangle(&ta, &tb).distance
                    })
                    .fold(f32::INFINITY, f32::min);
                assert!(
                    nearest <= 2e-4,
                    "case {case}: triangle {t} is {nearest} mm away"
                );
            }
            deep += (whole.0 > 0.5) as usize;
        }
        assert!(deep > 20, "{deep} deep overlaps");

        let (big, big_bvh) = refs(&cuboid(Vec3::splat(-5.0), Vec3::splat(5.0)));
        let (small, small_bvh) = refs(&cuboid(Vec3::ZERO, Vec3::ONE));
        let (big_stars, small_stars) = (VertexStars::of(&big), VertexStars::of(&small));
        let big_ref = MeshRef {
            mesh: &big,
            bvh: &big_bvh,
        };
        let small_ref = MeshRef {
            mesh: &small,
            bvh: &small_bvh,
        };
        let side = |mesh, stars| NearContact {
            mesh,
            stars,
            near: &[],
        };
        let pose = Pose::new(Quat::from_rotation_y(0.3), Vec3::ZERO);
        let walked = mesh_penetration_near(
            side(big_ref, &big_stars),
            &Pose::IDENTITY,
            side(small_ref, &small_stars),
            &pose,
        );
        let whole = mesh_penetration(big_ref, &Pose::IDENTITY, small_ref, &pose);
        assert!(walked.0 > 3.5, "{walked:?}");
        assert_eq!(walked, whole);
    }
    /// The pruned depths (bounds from neighbours, from the last nearest triangle, and limited
    /// searches) find the deepest sample that measuring every sample finds: teeth of 1,500
    /// vertices overlapping by up to a few tenths of a millimetre, as scans' neighbours do.
    #[test]
    fn pruned_depths_find_the_deepest_sample() {
        use crate::geometry::{closest_point_on_mesh, point_inside_mesh};
        use crate::teeth::{Arch, ToothGeometry, ToothKind, ToothResolution};
        let res = ToothResolution { vertices: 1500 };
        let a = ToothGeometry::procedural(Arch::Lower, ToothKind::FirstMolar, res);
        let b = ToothGeometry::procedural(Arch::Lower, ToothKind::SecondPremolar, res);
        // The deepest sample of `a` inside `b`, every sample measured.
        let every = |a: &ToothGeometry, pose_a: &Pose, b: &ToothGeometry, pose_b: &Pose| {
            let a_in_b = pose_b.inverse().mul(pose_a);
            let centroids = (0..a.mesh.triangles.len()).map(|i| {
                let [p, q, r] = a.mesh.triangle(i);
                (p + q + r) / 3.0
            });
            (a.mesh.vertices.iter().copied().chain(centroids))
                .map(|v| a_in_b.transform_point(v))
                .filter(|&p| point_inside_mesh(b.mesh_ref(), p))
                .map(|p| closest_point_on_mesh(b.mesh_ref(), p).unwrap().1)
                .fold(0.0f32, f32::max)
        };
        let mut n = crate::geometry::test_numbers(7);
        let mut deep = 0;
        for case in 0..12 {
            let pose_a = Pose::new(
                Quat::from_euler(glam::EulerRot::XYZ, n(), n(), n()),
                Vec3::new(n(), n(), n()),
            );
            // Side by side along x, pushed together by up to 0.6 mm.
            let reach =
                |g: &ToothGeometry| (g.mesh.vertices.iter()).fold(0.0f32, |m, v| m.max(v.x));
            let gap = reach(&a) - (b.mesh.vertices.iter()).fold(0.0f32, |m, v| m.min(v.x));
            let push = 0.05 * case as f32;
            let offset = Vec3::new(gap - push, n() * 0.5, n() * 0.5);
            let pose_b = Pose::new(
                Quat::from_euler(glam::EulerRot::XYZ, n() * 0.1, n() * 0.1, n() * 0.1),
                pose_a.transform_point(offset),
            );
            let whole = mesh_penetration(a.mesh_ref(), &pose_a, b.mesh_ref(), &pose_b);
            let measured = every(&a, &pose_a, &b, &pose_b).max(every(&b, &pose_b, &a, &pose_a));
            assert_eq!(whole.0, measured, "case {case}");
            deep += (measured > 0.05) as usize;
        }
        assert!(deep >= 4, "{deep} overlaps deeper than 0.05 mm");
    }
}
