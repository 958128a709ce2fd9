//! The identity of a file, whatever spelling names it: two paths are the same file when
//! they resolve to the same canonical path (symlinks followed, `.`, `..` and repeated
//! separators removed) or, for files that exist, to the same device and inode (hard links).
//! A file that does not exist yet is identified by the canonical path of its nearest existing
//! ancestor folder joined with the rest of the path, normalised lexically.

use std::path::{Component, Path, PathBuf};

use crate::error::{Error, Result};

/// What identifies a file: its canonical path and, for an existing file on unix, its device
/// and inode.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileIdentity {
    /// The path with symlinks, `.` and `..` resolved (of the folder, for a file not yet written).
    pub canonical: PathBuf,
    /// Device and inode of an existing file on unix, which also catch hard links.
    pub inode: Option<(u64, u64)>,
}

impl FileIdentity {
    /// The identity of an existing file (an input); `None` when nothing is at `path` (a
    /// missing input cannot be overwritten: reading it fails on its own).
    pub fn of_existing(path: &Path) -> Option<FileIdentity> {
        let canonical = path.canonicalize().ok()?;
        let inode = inode(&canonical);
        Some(FileIdentity { canonical, inode })
    }

    /// Where a file about to be written at `path` goes: see [`Target`]. Errors: a path
    /// without a file name, or whose nearest existing ancestor is not a folder.
    pub fn of_target(path: &Path) -> Result<Target> {
        let Some(name) = path.file_name() else {
            return Err(Error::in_file(path, "an output needs a file name"));
        };
        if let Some(identity) = FileIdentity::of_existing(path) {
            return Ok(Target {
                identity,
                folders: Vec::new(),
                path: path.to_path_buf(),
            });
        }
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let (created_from, missing) = split_existing(folder);
        // `created_from` is empty when even the first folder of a relative path is missing.
        let existing = if created_from.as_os_str().is_empty() {
            Path::new(".")
        } else {
            created_from.as_path()
        };
        if !existing.is_dir() {
            return Err(Error::in_file(
                path,
                format!(
                    "cannot create the output folder: {} is not a folder",
                    existing.display()
                ),
            ));
        }
        let canonical_folder = existing
            .canonicalize()
            .map_err(|e| Error::in_file(path, format!("cannot resolve the output folder: {e}")))?;
        let mut canonical = canonical_folder;
        let mut to_create = Vec::new();
        let mut created = created_from.clone();
        for name in &missing {
            created.push(name);
            to_create.push(created.clone());
            canonical.push(name);
        }
        canonical.push(name);
        Ok(Target {
            identity: FileIdentity {
                canonical,
                inode: None,
            },
            path: created.join(name),
            folders: to_create,
        })
    }

    /// Whether `self` and `other` are the same file.
    pub fn same_file(&self, other: &FileIdentity) -> bool {
        self.canonical == other.canonical
            || matches!((self.inode, other.inode), (Some(a), Some(b)) if a == b)
    }
}

/// Where an output goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Target {
    /// The file the output is written to.
    pub identity: FileIdentity,
    /// The folders writing it creates, outermost first.
    pub folders: Vec<PathBuf>,
    /// The path to write: the path as given for a file that exists; for a new one, the path
    /// through its nearest existing folder with `.` and `..` applied to the rest
    /// (`new/x/../a.png` is written as `new/a.png`: the folder `new/x` is never made).
    pub path: PathBuf,
}

/// `folder` split into its longest existing prefix (as written, empty for none) and the names of the
/// folders below it that do not exist yet, with `.` and `..` applied lexically among them
/// (there are no symlinks to follow in what does not exist).
fn split_existing(folder: &Path) -> (PathBuf, Vec<PathBuf>) {
    let mut existing = PathBuf::new();
    let mut missing: Vec<PathBuf> = Vec::new();
    for component in folder.components() {
        let candidate = existing.join(component);
        if missing.is_empty() && candidate.symlink_metadata().is_ok() {
            existing = candidate;
            continue;
        }
        match component {
            Component::CurDir => {}
            Component::ParentDir if missing.is_empty() => existing = candidate,
            Component::ParentDir => {
                missing.pop();
            }
            other => missing.push(PathBuf::from(other.as_os_str())),
        }
    }
    (existing, missing)
}

#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

/// Without device and inode numbers, canonical paths alone identify files.
#[cfg(not(unix))]
fn inode(_path: &Path) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_file_are_the_same_file() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().canonicalize().unwrap();
        std::fs::create_dir(root.join("a")).unwrap();
        std::fs::write(root.join("a/x.png"), b"x").unwrap();
        let x = FileIdentity::of_existing(&root.join("a/x.png")).unwrap();
        for spelling in ["a/./x.png", "a/../a/x.png", "a//x.png", "a/./../a/x.png"] {
            let target = FileIdentity::of_target(&root.join(spelling)).unwrap();
            assert!(target.identity.same_file(&x), "{spelling}");
            assert!(target.folders.is_empty());
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(root.join("a/x.png"), root.join("link.png")).unwrap();
            std::fs::hard_link(root.join("a/x.png"), root.join("hard.png")).unwrap();
            for other in ["link.png", "hard.png"] {
                let target = FileIdentity::of_target(&root.join(other)).unwrap();
                assert!(target.identity.same_file(&x));
            }
        }
        let new = FileIdentity::of_target(&root.join("a/y.png")).unwrap();
        assert!(!new.identity.same_file(&x));
    }

    #[test]
    fn missing_folders_are_listed_and_normalised() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().canonicalize().unwrap();
        let deep = FileIdentity::of_target(&root.join("n/m/./x.png")).unwrap();
        assert_eq!(deep.folders, [root.join("n"), root.join("n/m")]);
        assert_eq!(deep.identity.canonical, root.join("n/m/x.png"));
        let back = FileIdentity::of_target(&root.join("n/k/../m/x.png")).unwrap();
        assert_eq!(back.folders, [root.join("n"), root.join("n/m")]);
        assert_eq!(back.path, root.join("n/m/x.png"));
        let up = FileIdentity::of_target(&root.join("n/../x.png")).unwrap();
        assert_eq!(up.identity.canonical, root.join("x.png"));
        assert!(up.folders.is_empty());
        assert_eq!(up.path, root.join("x.png"));
        std::fs::write(root.join("file"), b"").unwrap();
        let e = FileIdentity::of_target(&root.join("file/x.png")).unwrap_err();
        assert!(e.to_string().contains("is not a folder"), "{e}");
    }
}
