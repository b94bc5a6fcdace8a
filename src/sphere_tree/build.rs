//! Builder settings and the dispatch from settings to a builder.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::{medial::build_medial, octree::build_octree, tree::SphereTree};
use crate::geometry::{TriMesh, TriangleBvh};

/// Which builder makes the tree.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum TreeMethod {
    /// Recursive subdivision of the bounding cube (Hubbard 1993); branching 8 only.
    #[default]
    Octree,
    /// Spheres on the medial axis chosen by a weighted set cover (see [`super::medial`]).
    Medial,
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
    /// Checks the settings against the builder's limits.
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

    /// Builds the tree of `mesh` (with its triangle hierarchy) with these settings.
    pub fn build(&self, mesh: &TriMesh, bvh: &TriangleBvh) -> Result<SphereTree, TreeBuildError> {
        self.validate()?;
        Ok(match self.method {
            TreeMethod::Octree => build_octree(mesh, self.depth),
            TreeMethod::Medial => build_medial(mesh, bvh, self.branching, self.depth),
        })
    }
}
