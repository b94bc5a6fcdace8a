//! Builder settings and the dispatch from settings to a builder.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::{medial::build_medial, octree::build_octree, tree::SphereTree};
use crate::geometry::{TriMesh, TriangleBvh};

/// Which builder makes the tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TreeMethod {
    /// Recursive subdivision of the bounding cube (Hubbard 1993); branching 8 only.
    #[default]
    Octree,
    /// Spheres on the medial axis chosen by a weighted set cover (see [`super::medial`]).
    Medial,
}

impl TreeMethod {
    /// Every builder.
    pub const ALL: [TreeMethod; 2] = [TreeMethod::Octree, TreeMethod::Medial];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            TreeMethod::Octree => "octree",
            TreeMethod::Medial => "medial",
        }
    }
}

impl std::fmt::Display for TreeMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How sphere trees are built (RON-serialisable).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct TreeSettings {
    /// Builder.
    pub method: TreeMethod,
    /// Children per node.
    pub branching: u32,
    /// Levels including the root (the paper recommends 4).
    pub depth: u32,
}

impl Default for TreeSettings {
    fn default() -> Self {
        Self {
            method: TreeMethod::Octree,
            branching: 8,
            depth: 4,
        }
    }
}

/// Largest depth accepted (an octree of depth 8 has over two million slots).
pub const MAX_DEPTH: u32 = 7;

/// Settings a builder cannot honour.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum TreeBuildError {
    /// Depth outside 1..=MAX_DEPTH.
    #[error("tree depth must be 1–{MAX_DEPTH}, got {0}")]
    Depth(u32),
    /// The builder needs another branching factor.
    #[error("the {method:?} builder needs branching {needs}, got {got}")]
    Branching {
        /// Builder.
        method: TreeMethod,
        /// What it needs.
        needs: u32,
        /// What was asked.
        got: u32,
    },
}

impl TreeSettings {
    /// The builder `method` at the default depth and branching (4 and 8, the paper's
    /// recommendation and what the simulation commands use).
    pub fn with_method(method: TreeMethod) -> Self {
        Self {
            method,
            ..Self::default()
        }
    }

    /// Checks the settings against the builder's limits.
    ///
    /// # Errors
    /// [`TreeBuildError`] for a depth outside 1–[`MAX_DEPTH`] or a branching the builder cannot
    /// use.
    pub fn validate(&self) -> Result<(), TreeBuildError> {
        if !(1..=MAX_DEPTH).contains(&self.depth) {
            return Err(TreeBuildError::Depth(self.depth));
        }
        match self.method {
            TreeMethod::Octree if self.branching != 8 => Err(TreeBuildError::Branching {
                method: self.method,
                needs: 8,
                got: self.branching,
            }),
            _ => Ok(()),
        }
    }

    /// Builds the tree of `mesh` (with its triangle hierarchy) with these settings. The tree
    /// covers the mesh: every point of its surface lies in a leaf, and every inner sphere holds
    /// what its leaves are responsible for (see [`crate::sphere_tree`]).
    ///
    /// # Errors
    /// The settings are invalid ([`TreeSettings::validate`]).
    ///
    /// # Example
    /// ```
    /// use orthosim::{
    ///     geometry::TriangleBvh,
    ///     sphere_tree::{TreeMethod, TreeSettings, check_coverage, coverage::DEFAULT_SPLIT_DEPTH},
    ///     teeth::{Arch, ShapeSet, ToothKind, ToothResolution},
    /// };
    /// let molar = ShapeSet::shared(ToothResolution::PAPER).get(Arch::Lower, ToothKind::FirstMolar);
    /// let tree = TreeSettings::with_method(TreeMethod::Medial).build(&molar.mesh, &molar.bvh)?;
    /// assert!(tree.leaves().count() <= 512);
    /// assert!(check_coverage(&tree, &molar.mesh, DEFAULT_SPLIT_DEPTH).covered);
    /// # Ok::<(), orthosim::sphere_tree::TreeBuildError>(())
    /// ```
    pub fn build(&self, mesh: &TriMesh, bvh: &TriangleBvh) -> Result<SphereTree, TreeBuildError> {
        self.validate()?;
        Ok(match self.method {
            TreeMethod::Octree => build_octree(mesh, self.depth),
            TreeMethod::Medial => build_medial(mesh, bvh, self.branching, self.depth),
        })
    }
}
