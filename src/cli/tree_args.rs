//! The sphere trees of the simulation commands (`simulate`, `report`, `bench`): the builder, at the
//! library's default depth and branching, from the user's tree cache unless `--no-cache`.

use clap::Args;
use orthosim::sphere_tree::{TreeCache, TreeMethod, TreeSettings};

use super::choice;

/// `--tree` and `--no-cache`.
#[derive(Args, Debug, Clone, Copy)]
pub struct TreeArgs {
    /// Sphere-tree builder (depth 4, branching 8).
    #[arg(long, value_parser = choice::tree_method(), default_value_t = TreeMethod::Medial)]
    pub tree: TreeMethod,
    /// Build every tree afresh instead of using the user's tree cache.
    #[arg(long)]
    pub no_cache: bool,
}

impl TreeArgs {
    /// The tree settings: the chosen builder at the default depth and branching.
    pub fn settings(&self) -> TreeSettings {
        TreeSettings::with_method(self.tree)
    }

    /// The user's tree cache, unless `--no-cache`.
    pub fn cache(&self) -> Option<TreeCache> {
        if self.no_cache {
            None
        } else {
            TreeCache::user_default()
        }
    }
}
