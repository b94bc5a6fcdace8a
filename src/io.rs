//! Files that orthosim writes: atomic writes (a reader never sees half a file), the rule that an
//! output never replaces a file the command reads, and sets of outputs written all or nothing.
//!
//! Every command that writes goes through here: `export-case`, `trees --out`, `report`, the tree
//! cache and the screenshot.

use std::{
    ffi::OsStr,
    path::{Path, PathBuf},
};

use thiserror::Error;

/// Longest file name (bytes) the common file systems accept.
pub const MAX_FILE_NAME_BYTES: usize = 255;
/// Longest path (bytes) accepted for an output.
pub const MAX_PATH_BYTES: usize = 4095;

/// An output that cannot or must not be written.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The output is one of the files the command reads.
    #[error("{}: refusing to overwrite a file this command reads", .path.display())]
    WouldOverwriteInput {
        /// The output.
        path: PathBuf,
    },
    /// The file's name, or a folder's on its path, is longer than file systems allow.
    #[error(
        "{}: a name on this path is {len} bytes long, more than the {MAX_FILE_NAME_BYTES} a file system allows",
        .path.display()
    )]
    NameTooLong {
        /// The output.
        path: PathBuf,
        /// Length of the longest name (bytes).
        len: usize,
    },
    /// The path is longer than the system allows.
    #[error("the output path is {len} bytes long, more than the {MAX_PATH_BYTES} allowed")]
    PathTooLong {
        /// Length of the path (bytes).
        len: usize,
    },
    /// The path has no file name (it ends in `..` or is a root).
    #[error("{}: not a file name", .path.display())]
    NoFileName {
        /// The output.
        path: PathBuf,
    },
    /// Two outputs of one set have the same path.
    #[error("{}: named twice among the files to write", .path.display())]
    Duplicate {
        /// The output.
        path: PathBuf,
    },
    /// A folder stands where the file would go.
    #[error("{}: is a folder", .path.display())]
    IsFolder {
        /// The output.
        path: PathBuf,
    },
    /// The folder could not be created.
    #[error("{}: cannot create folder: {source}", .path.display())]
    CreateFolder {
        /// The folder.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// Writing (or moving the finished file into place) failed.
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        /// The output.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
}

/// Writes `bytes` to `path` atomically: a temporary file beside it, then a rename, so a reader
/// never sees half a file.
///
/// # Errors
/// [`OutputError::Write`] when the temporary cannot be written or moved into place (the temporary
/// is removed).
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), OutputError> {
    let tmp = temporary_beside(path);
    let written = std::fs::write(&tmp, bytes.as_ref()).and_then(|()| std::fs::rename(&tmp, path));
    written.map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        OutputError::Write {
            path: path.to_owned(),
            source,
        }
    })
}

/// Refuses to write `output` over one of `inputs` (compared as canonical paths, so relative paths
/// and links count): outputs never replace the files a command reads.
///
/// # Errors
/// [`OutputError::WouldOverwriteInput`].
pub fn refuse_overwriting(output: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let Ok(out) = std::fs::canonicalize(output) else {
        return Ok(());
    };
    if inputs
        .iter()
        .any(|i| std::fs::canonicalize(i).is_ok_and(|i| i == out))
    {
        return Err(OutputError::WouldOverwriteInput {
            path: output.to_owned(),
        });
    }
    Ok(())
}

/// Checks one output before anything is written: its name and path lengths, that it is not a
/// folder and not one of `inputs`.
///
/// # Errors
/// The first problem found, naming the path.
pub fn check_output(path: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let len = path.as_os_str().len();
    if len > MAX_PATH_BYTES {
        return Err(OutputError::PathTooLong { len });
    }
    if path.file_name().is_none() {
        return Err(OutputError::NoFileName {
            path: path.to_owned(),
        });
    }
    // The file's name and every folder's on the way.
    if let Some(long) = path
        .components()
        .map(|c| c.as_os_str().len())
        .find(|&len| len > MAX_FILE_NAME_BYTES)
    {
        return Err(OutputError::NameTooLong {
            path: path.to_owned(),
            len: long,
        });
    }
    if path.is_dir() {
        return Err(OutputError::IsFolder {
            path: path.to_owned(),
        });
    }
    refuse_overwriting(path, inputs)
}

/// A set of files written all or nothing.
///
/// [`OutputSet::new`] checks every output ([`check_output`], and no path twice) before any byte is
/// written; [`OutputSet::write`] writes each to a temporary file beside its place;
/// [`OutputSet::commit`] moves them all into place. Dropped before the commit, or after a failed
/// write, the set removes its temporaries and the folders it created, so a failure leaves nothing
/// behind.
#[derive(Debug)]
pub struct OutputSet {
    /// Final paths, in the order given.
    paths: Vec<PathBuf>,
    /// Temporaries written so far: (temporary, index into `paths`).
    written: Vec<(PathBuf, usize)>,
    /// The folders this set created, outermost first (removed again when the set is abandoned).
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputSet {
    /// Checks `paths` (all in `folder`, which is created if missing) against `inputs`.
    ///
    /// # Errors
    /// The first output that cannot or must not be written; nothing is created then.
    pub fn new(folder: &Path, paths: Vec<PathBuf>, inputs: &[&Path]) -> Result<Self, OutputError> {
        let mut seen = std::collections::HashSet::new();
        for p in &paths {
            check_output(p, inputs)?;
            if !seen.insert(p.as_os_str()) {
                return Err(OutputError::Duplicate { path: p.clone() });
            }
        }
        if folder.exists() && !folder.is_dir() {
            return Err(OutputError::CreateFolder {
                path: folder.to_owned(),
                source: std::io::Error::other("a file of that name exists"),
            });
        }
        // The folders to create, outermost first.
        let created: Vec<PathBuf> = folder
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_owned)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        let set = Self {
            paths,
            written: Vec::new(),
            created,
            committed: false,
        };
        std::fs::create_dir_all(folder).map_err(|source| OutputError::CreateFolder {
            path: folder.to_owned(),
            source,
        })?;
        Ok(set)
    }

    /// Writes the output `path` (one of those the set was made with) to its temporary file.
    ///
    /// # Errors
    /// [`OutputError::Write`]; the set should then be dropped, which removes what it wrote.
    pub fn write(&mut self, path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), OutputError> {
        let Some(index) = self.paths.iter().position(|p| p == path) else {
            return Err(OutputError::Write {
                path: path.to_owned(),
                source: std::io::Error::other("not among the outputs checked beforehand"),
            });
        };
        let tmp = temporary_beside(path);
        std::fs::write(&tmp, bytes.as_ref()).map_err(|source| {
            let _ = std::fs::remove_file(&tmp);
            OutputError::Write {
                path: path.to_owned(),
                source,
            }
        })?;
        if !self.written.iter().any(|(_, k)| *k == index) {
            self.written.push((tmp, index));
        }
        Ok(())
    }

    /// Moves every written file into place.
    ///
    /// # Errors
    /// [`OutputError::Write`] when an output was never written or a move fails (the temporaries
    /// left are removed).
    pub fn commit(mut self) -> Result<Vec<PathBuf>, OutputError> {
        if let Some(missing) =
            (0..self.paths.len()).find(|i| !self.written.iter().any(|(_, k)| k == i))
        {
            return Err(OutputError::Write {
                path: self.paths[missing].clone(),
                source: std::io::Error::other("never written"),
            });
        }
        for k in 0..self.written.len() {
            let (tmp, index) = &self.written[k];
            let path = &self.paths[*index];
            if let Err(source) = std::fs::rename(tmp, path) {
                let path = path.clone();
                // The files already moved stay (they are complete); the rest are removed.
                self.written.drain(..k);
                self.committed = k > 0;
                return Err(OutputError::Write { path, source });
            }
        }
        self.written.clear();
        self.committed = true;
        Ok(std::mem::take(&mut self.paths))
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        for (tmp, _) in &self.written {
            let _ = std::fs::remove_file(tmp);
        }
        if !self.committed {
            // Only empty folders are removed: nothing of the user's is touched.
            for folder in self.created.iter().rev() {
                let _ = std::fs::remove_dir(folder);
            }
        }
    }
}

/// `.NAME.tmp-PID` beside `path`.
fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "out".into(), OsStr::to_string_lossy);
    // A long name keeps its temporary within the file-name limit.
    let short: String = name.chars().take(200).collect();
    path.with_file_name(format!(".{short}.tmp-{}", std::process::id()))
}

#[cfg(test)]
mod tests;
