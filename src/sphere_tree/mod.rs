//! Sphere trees: hierarchies of bounding spheres over a tooth mesh, for fast, conservative collision.
//!
//! Layout ([`SphereTree`]): a flat B-ary tree in Bradshaw's `.sph` index order (children of node n
//! at n·B+1 … n·B+B, empty slots marked), levels counted including the root ("depth 4" = levels
//! 0–3). Spheres are in the tooth's local frame. Each leaf lists the triangles it touches.
//!
//! **Invariant** ([`coverage::check_coverage`]): (1) every point of the tooth surface lies inside at
//! least one leaf sphere; (2) every inner sphere contains all the surface its leaves are responsible
//! for. It is checked exactly: each triangle is split recursively until every piece has its three
//! vertices inside one leaf sphere (then, spheres being convex, the whole piece is inside it); that
//! leaf is responsible for the piece, and every ancestor of it must contain the piece's vertices too.
//! A piece still uncovered past the depth limit fails the check. The invariant is what makes
//! sphere-tree collision conservative: two surfaces cannot touch unless some pair of leaves (and
//! every pair of their ancestors) overlaps, so a descent that prunes non-overlapping pairs has no
//! false negatives against the exact mesh.
//!
//! Builders: [`octree`] (Hubbard 1993) and [`medial`] (ours: medial-axis spheres chosen by a set
//! cover of the outside volume). Files: [`sph`] reads and writes Bradshaw's format; `cache` keeps
//! built trees on disk. Fit: [`metrics`]. ECS (feature `ecs`): `SphereTreePlugin` builds trees in
//! the background. Reports: `report` (the `orthosim trees` command).

mod build;
mod cache;
pub mod coverage;
pub mod medial;
pub mod metrics;
pub mod octree;
#[cfg(feature = "ecs")]
mod plugin;
mod report;
pub mod sph;
mod tree;

pub use build::{MAX_DEPTH, TreeBuildError, TreeMethod, TreeSettings};
pub use cache::{BUILDER_VERSION, TreeCache, TreeSource};
pub use coverage::{Coverage, check_coverage};
#[cfg(feature = "ecs")]
pub use plugin::{
    SphereTreeCache, SphereTreePlugin, SphereTreeProgress, SphereTreeSettings, SphereTreeSystems,
    ToothSphereTree,
};
pub use report::{ToothTreeReport, TreeSummary, TreesReport, trees_report};
pub use tree::SphereTree;
