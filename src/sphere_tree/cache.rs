//! On-disk cache of built trees, so that a tooth shape's tree is built once per machine.
//!
//! A tree is stored as Bradshaw `.sph` text (f32 values written in their shortest exact form, so
//! they read back bit for bit) under a name that is a 64-bit FNV-1a hash of everything the tree
//! depends on: the mesh's vertex bits and triangle indices, the settings, and [`BUILDER_VERSION`]
//! (raised whenever a builder changes its output). A cached tree is used only if it reads back
//! with the expected shape and passes the exact coverage check against the mesh; anything else
//! (missing, truncated, stale, hand-edited) is rebuilt and rewritten. Writes are atomic (temporary
//! file, then rename), so concurrent builders and interrupted runs never leave half a file.

use std::path::{Path, PathBuf};

use super::{
    build::{TreeBuildError, TreeSettings},
    coverage::{DEFAULT_SPLIT_DEPTH, check_coverage},
    tree::SphereTree,
};
use crate::{
    geometry::{TriMesh, TriangleBvh},
    io::{OutputError, write_atomic},
};

/// Changes whenever a builder's output changes for the same mesh and settings.
pub const BUILDER_VERSION: u32 = 14;

/// A directory of cached trees.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TreeCache {
    dir: PathBuf,
}

/// Where a tree came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TreeSource {
    /// Built now (and stored, if the cache directory is writable).
    Built,
    /// Read from the cache.
    Cached,
}

struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
}

impl TreeCache {
    /// A cache in `dir` (created on first store).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The user's cache directory for trees: `$XDG_CACHE_HOME/orthosim/trees`, else
    /// `$HOME/.cache/orthosim/trees`; None when neither variable is set.
    pub fn user_default() -> Option<Self> {
        let base = std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("HOME")
                    .filter(|v| !v.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache"))
            })?;
        Some(Self::new(base.join("orthosim").join("trees")))
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The key of a mesh built with `settings`.
    pub fn key(mesh: &TriMesh, settings: &TreeSettings) -> u64 {
        let mut h = Fnv::new();
        h.u32(BUILDER_VERSION);
        h.bytes(format!("{:?}", settings.method).as_bytes());
        h.u32(settings.branching);
        h.u32(settings.depth);
        h.u32(mesh.vertices.len() as u32);
        for v in &mesh.vertices {
            for c in v.to_array() {
                h.u32(c.to_bits());
            }
        }
        h.u32(mesh.triangles.len() as u32);
        for t in &mesh.triangles {
            for &i in t {
                h.u32(i);
            }
        }
        h.0
    }

    /// The file a mesh's tree is cached in.
    pub fn path(&self, mesh: &TriMesh, settings: &TreeSettings) -> PathBuf {
        self.dir
            .join(format!("{:016x}.sph", Self::key(mesh, settings)))
    }

    /// The cached tree of `mesh`, if there is a valid one.
    pub fn load(&self, mesh: &TriMesh, settings: &TreeSettings) -> Option<SphereTree> {
        let text = std::fs::read_to_string(self.path(mesh, settings)).ok()?;
        let mut tree = SphereTree::from_sph(&text).ok()?;
        if tree.levels != settings.depth || tree.branching != settings.branching {
            return None;
        }
        tree.assign_triangles(mesh);
        check_coverage(&tree, mesh, DEFAULT_SPLIT_DEPTH)
            .covered
            .then_some(tree)
    }

    /// Stores a tree (atomically).
    ///
    /// # Errors
    /// The cache folder cannot be created or the file written.
    pub fn store(
        &self,
        mesh: &TriMesh,
        settings: &TreeSettings,
        tree: &SphereTree,
    ) -> Result<(), OutputError> {
        std::fs::create_dir_all(&self.dir).map_err(|source| OutputError::CreateFolder {
            path: self.dir.clone(),
            source,
        })?;
        write_atomic(&self.path(mesh, settings), tree.to_sph())
    }

    /// The cached tree, or a new one (stored for next time; a failure to store is a warning in the
    /// log (`tracing`, which Bevy's log shows), not an error, since the tree itself is fine).
    ///
    /// # Errors
    /// The settings are invalid ([`TreeSettings::validate`]).
    pub fn load_or_build(
        &self,
        settings: &TreeSettings,
        mesh: &TriMesh,
        bvh: &TriangleBvh,
    ) -> Result<(SphereTree, TreeSource), TreeBuildError> {
        settings.validate()?;
        if let Some(tree) = self.load(mesh, settings) {
            return Ok((tree, TreeSource::Cached));
        }
        let tree = settings.build(mesh, bvh)?;
        if let Err(e) = self.store(mesh, settings, &tree) {
            tracing::warn!("could not store a sphere tree in the cache: {e}");
        }
        Ok((tree, TreeSource::Built))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::{geometry::trimesh::tests::cuboid, sphere_tree::TreeMethod};

    fn scratch_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("orthosim-cache-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_stored_tree_reads_back_identically_and_bad_files_are_rebuilt() {
        let dir = scratch_dir("roundtrip");
        let cache = TreeCache::new(&dir);
        let mesh = cuboid(Vec3::ZERO, Vec3::new(3.0, 2.0, 1.0));
        let bvh = TriangleBvh::build(&mesh);
        let settings = TreeSettings {
            method: TreeMethod::Medial,
            branching: 4,
            depth: 3,
        };
        let (built, source) = cache.load_or_build(&settings, &mesh, &bvh).unwrap();
        assert_eq!(source, TreeSource::Built);
        let (cached, source) = cache.load_or_build(&settings, &mesh, &bvh).unwrap();
        assert_eq!(source, TreeSource::Cached);
        assert_eq!(cached.nodes, built.nodes);
        assert_eq!(cached.triangles, built.triangles);
        // Other settings or another mesh: another key.
        let octree = TreeSettings {
            method: TreeMethod::Octree,
            branching: 8,
            depth: 3,
        };
        assert_ne!(
            TreeCache::key(&mesh, &settings),
            TreeCache::key(&mesh, &octree)
        );
        let moved = mesh.map_vertices(|v| v + Vec3::X * 1e-3);
        assert_ne!(
            TreeCache::key(&mesh, &settings),
            TreeCache::key(&moved, &settings)
        );
        // A truncated file and a shrunken sphere are both refused and rebuilt.
        let path = cache.path(&mesh, &settings);
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, &text[..text.len() / 2]).unwrap();
        assert!(cache.load(&mesh, &settings).is_none());
        let mut shrunk = built.clone();
        let leaf = shrunk.leaves().next().unwrap();
        shrunk.nodes[leaf].as_mut().unwrap().radius *= 0.5;
        std::fs::write(&path, shrunk.to_sph()).unwrap();
        assert!(cache.load(&mesh, &settings).is_none());
        let (_, source) = cache.load_or_build(&settings, &mesh, &bvh).unwrap();
        assert_eq!(source, TreeSource::Built);
        assert!(cache.load(&mesh, &settings).is_some());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
