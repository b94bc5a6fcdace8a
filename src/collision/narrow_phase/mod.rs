//! Narrow phases: whether, when and where two moving teeth touch during a step.
//!
//! | method | when tested | guarantee |
//! |---|---|---|
//! | [`circles`] | end pose | the paper's Eq. 1 on bounding circles in the x–z plane; coarse, no guarantee (ignores height, so upper and lower teeth always "collide") |
//! | [`spheres`] | end pose | conservative: if the meshes overlap or touch at the end pose, some pair of leaves overlaps (coverage invariant), so no false negatives at that pose |
//! | [`continuous`] | whole step | conservative: no false negatives for any contact during the step, and the reported time is never later than the first contact of the swept leaf spheres that hold the meshes' first contact point (hence of the meshes) |
//! | [`exact`] | whole step | the continuous stage, then conservative advancement on the candidate triangles: the time is never after the meshes' first contact and the gap left there is at most [`exact::GAP_TOLERANCE_MM`] |
//!
//! Results are [`PairContact`]s in world coordinates; `depth_mm` is a penetration depth when
//! positive and minus the gap when negative.

pub mod circles;
pub mod continuous;
pub mod exact;
pub(crate) mod lanes;
pub mod spheres;

use std::sync::Arc;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{
    motion::Motion,
    shape::{Circle, CollisionShape},
};
use crate::geometry::InsideSamples;
use crate::teeth::ToothGeometry;

/// The narrow-phase algorithm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Bounding circles in the x–z plane at the end pose (the paper's Eq. 1).
    Circles,
    /// Simultaneous descent of both sphere trees at the end pose.
    Spheres,
    /// Swept sphere trees over the step (interval bound, Eq. 2 at the leaves).
    #[default]
    Continuous,
    /// Continuous, then exact triangle contact and time of contact.
    Exact,
}

impl Method {
    /// Every method, in the paper's order then ours.
    pub const ALL: [Method; 4] = [
        Method::Circles,
        Method::Spheres,
        Method::Continuous,
        Method::Exact,
    ];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Circles => "circles",
            Method::Spheres => "spheres",
            Method::Continuous => "continuous",
            Method::Exact => "exact",
        }
    }

    /// True for the methods that test only the end pose of a step (circles, spheres); the others
    /// test the whole step.
    pub fn is_discrete(self) -> bool {
        matches!(self, Method::Circles | Method::Spheres)
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One tooth in a query: its shape, its bounding circle and its motion over the step.
#[derive(Clone, Copy, Debug)]
pub struct Body<'a> {
    /// Mesh and sphere tree.
    pub shape: &'a CollisionShape,
    /// Bounding circle (for [`Method::Circles`]).
    pub circle: Circle,
    /// Start and end pose.
    pub motion: Motion,
}

/// The contact of two teeth found by a narrow phase.
#[derive(Clone, Debug, PartialEq)]
pub struct PairContact {
    /// Time of contact in [0, 1] (1 for the discrete methods: at the end pose).
    pub time_of_contact: f32,
    /// Contact points (world): on the first tooth, then on the second.
    pub points: [Vec3; 2],
    /// Unit normal from the first tooth towards the second.
    pub normal: Vec3,
    /// Penetration depth (mm) when positive; minus the gap when negative.
    pub depth_mm: f32,
    /// Overlapping leaf pairs (compact-tree node indices) at the reported time.
    pub leaf_pairs: Vec<(u32, u32)>,
    /// For a contact at the start of the motion, the meshes' overlap at its end when the method
    /// found it on the way (exact, at scan resolution): what a response needs to tell whether the
    /// contact deepens ([`crate::collision::closing::deepens`]), which otherwise searches the
    /// whole meshes for it.
    pub end_overlap: Option<EndOverlap>,
}

/// The overlap of two teeth's meshes at the end of their motion, found by the exact query for a
/// contact at its start.
#[derive(Clone, Debug, PartialEq)]
pub struct EndOverlap {
    /// The end poses it was found at: first tooth, second. It holds for these poses only.
    pub poses: [crate::geometry::Pose; 2],
    /// The penetration depth there (mm, the estimate of
    /// [`crate::geometry::mesh_penetration_near`]); 0 or less when the meshes do not overlap.
    pub depth_mm: f32,
    /// The deepest point with the nearest point of the other surface (world): on the first
    /// tooth's side, then on the second's, as [`PairContact::points`] of an overlap.
    pub points: [Vec3; 2],
    /// The deepest sample point (a vertex or triangle centroid): the tooth it lies on (0 the
    /// first, 1 the second) and its place in that tooth's mesh frame. At the next placement its
    /// depth is one the overlap reaches, which lets the next search skip shallower samples
    /// ([`crate::geometry::mesh_penetration_near_from`]). None when nothing overlaps.
    pub deepest: Option<(usize, Vec3)>,
    /// The two teeth's geometries it was found for, and every sample of each mesh found inside
    /// the other with bounds of their depths: a query uses the overlap only for the same
    /// geometries, and at a nearby placement of them measures only the samples that can still
    /// be the deepest ([`crate::geometry::InsideSamples::rewalk`]) instead of walking.
    pub inside: KnownInside,
}

impl EndOverlap {
    /// The same overlap seen with the two teeth's roles swapped.
    pub fn swapped(mut self) -> Self {
        self.poses.swap(0, 1);
        self.points.swap(0, 1);
        self.deepest = self.deepest.map(|(side, local)| (1 - side, local));
        let [a, b] = self.inside.geometry;
        self.inside = KnownInside {
            geometry: [b, a],
            samples: (self.inside.samples).map(|s| Arc::new(s.swapped())),
        };
        self
    }

    /// Whether it was found for these two geometries (first tooth's, second's).
    pub fn is_for(&self, a: &Arc<ToothGeometry>, b: &Arc<ToothGeometry>) -> bool {
        let [ga, gb] = &self.inside.geometry;
        Arc::ptr_eq(ga, a) && Arc::ptr_eq(gb, b)
    }
}

/// What an overlap was found for ([`EndOverlap::inside`]): the two teeth's geometries (kept
/// alive, so a tooth given another mesh is never taken for the same one) and the samples found
/// inside, when the meshes overlap.
#[derive(Clone)]
pub struct KnownInside {
    /// The first tooth's geometry, then the second's.
    pub geometry: [Arc<ToothGeometry>; 2],
    /// The samples (shared: an overlap is copied along with its contact); `None` when nothing
    /// overlaps.
    pub samples: Option<Arc<InsideSamples>>,
}

impl PartialEq for KnownInside {
    /// Found for the same geometries. The samples' bounds are a search's working state, not
    /// part of the overlap: a search from known samples and a walk find the same overlap with
    /// different bounds.
    fn eq(&self, other: &Self) -> bool {
        (self.geometry.iter().zip(&other.geometry)).all(|(x, y)| Arc::ptr_eq(x, y))
    }
}

impl std::fmt::Debug for KnownInside {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KnownInside")
            .field("samples", &self.samples.as_ref().map(|s| s.len()))
            .finish()
    }
}

/// Runs `method` on a pair of teeth moving over one step: the first contact (or, for the discrete
/// methods, the contact at the end pose), or None. Each method's guarantee is in the module doc;
/// a body with an empty tree never touches anything.
///
/// # Example
/// Two lower central incisors, the left one pushed 0.5 mm towards its neighbour:
/// ```
/// use glam::Vec3;
/// use orthosim::{
///     collision::{Body, Circle, CollisionShape, Method, Motion, query},
///     geometry::Pose,
///     sphere_tree::{TreeMethod, TreeSettings},
///     teeth::{Case, Dentition, Fdi},
/// };
/// let d = Dentition::build(Case::resolve("normal")?)?;
/// let settings = TreeSettings::with_method(TreeMethod::Octree);
/// let body = |n: i64, shift: Vec3| -> Result<_, Box<dyn std::error::Error>> {
///     let t = d.tooth(Fdi::new(n)?).ok_or("no such tooth")?;
///     let tree = settings.build(&t.geometry.mesh, &t.geometry.bvh)?;
///     let end = Pose::new(t.pose.rotation, t.pose.translation + shift);
///     Ok((CollisionShape::new(t.geometry.clone(), &tree), Circle::of(&t.geometry, &t.pose), Motion { start: t.pose, end }))
/// };
/// let (a, b) = (body(31, Vec3::new(-0.5, 0.0, 0.0))?, body(41, Vec3::ZERO)?);
/// let (a, b) = (
///     Body { shape: &a.0, circle: a.1, motion: a.2 },
///     Body { shape: &b.0, circle: b.1, motion: b.2 },
/// );
/// let hit = query(Method::Exact, &a, &b).expect("they touch during the step");
/// assert!(hit.time_of_contact < 1.0);
/// assert!(hit.depth_mm.abs() <= orthosim::collision::narrow_phase::exact::GAP_TOLERANCE_MM);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn query(method: Method, a: &Body, b: &Body) -> Option<PairContact> {
    let empty = a.shape.tree.is_empty() || b.shape.tree.is_empty();
    match method {
        // Without the end overlap, which only a simulation's steps ask for.
        Method::Exact if !empty => exact::query(a, b),
        _ => query_knowing(method, a, b, None),
    }
}

/// [`query`] for a simulation's steps: exact contacts at the start of the step carry the
/// meshes' overlap at its end, and the overlap at the start poses may be `known` from the step
/// before (see [`exact::query_knowing`]; the other methods ignore both).
pub fn query_knowing(
    method: Method,
    a: &Body,
    b: &Body,
    known: Option<&EndOverlap>,
) -> Option<PairContact> {
    if a.shape.tree.is_empty() || b.shape.tree.is_empty() {
        return None;
    }
    match method {
        Method::Circles => circles::query(a, b),
        Method::Spheres => spheres::query(a, b),
        Method::Continuous => continuous::query(a, b, false).map(|c| c.contact),
        Method::Exact => exact::query_knowing(a, b, known),
    }
}
