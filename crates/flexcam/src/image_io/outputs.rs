//! All the files one command writes, committed together or not at all.
//!
//! A command declares its inputs and outputs first ([`OutputSet::input`],
//! [`OutputSet::output`]); an output that is the same file as an input or as another output
//! (by [`FileIdentity`], not by spelling) is refused then, before any work. Each output is
//! then written to a temporary file in its nearest existing folder ([`OutputSet::stage`]),
//! and [`OutputSet::commit`] moves them all into place: it creates the missing output
//! folders, keeps a backup of every file it replaces, and if any step fails it undoes the
//! steps already taken (restoring the backups, removing the new files and folders), so the
//! user sees either every new output or the files as they were. Temporaries of an
//! uncommitted set are removed when it is dropped.

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

use super::extension;
use super::identity::FileIdentity;
use crate::error::{Error, Result};

/// A declared output, for [`OutputSet::stage`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputId(usize);

/// What a file is to the command, for errors: `the ids output`, `the scene file`.
#[derive(Debug)]
struct Declared {
    role: String,
    path: PathBuf,
    is_output: bool,
}

/// An output: where it goes, the folders its commit creates, its temporary once staged.
#[derive(Debug)]
struct Output {
    /// The path as the user gave it, for messages.
    shown: PathBuf,
    /// The path written (see [`super::identity::Target::path`]).
    path: PathBuf,
    folders: Vec<PathBuf>,
    temporary: Option<PathBuf>,
}

/// The inputs and outputs of one command; see the module documentation.
#[derive(Debug, Default)]
pub struct OutputSet {
    declared: Vec<Declared>,
    by_path: HashMap<PathBuf, usize>,
    by_inode: HashMap<(u64, u64), usize>,
    outputs: Vec<Output>,
}

/// One step [`OutputSet::commit`] took, undone in reverse order when a later one fails.
enum Step {
    /// A folder it created.
    Folder(PathBuf),
    /// A file now at `target`; `backup` holds the file it replaced, if any.
    Placed {
        target: PathBuf,
        backup: Option<PathBuf>,
    },
}

impl OutputSet {
    /// An empty set: nothing staged yet.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Declares a file the command reads, `role` saying what it is (`the scene file`, `the
    /// texture`). Errors: a declared output is the same file. A file that does not exist is
    /// not recorded (reading it fails on its own).
    pub fn input(&mut self, role: &str, path: &Path) -> Result<()> {
        match FileIdentity::of_existing(path) {
            Some(identity) => self.declare(role, path, identity, false),
            None => Ok(()),
        }
    }

    /// Declares every file of `inputs` as [`OutputSet::input`] does.
    pub fn inputs<'a>(
        &mut self,
        inputs: impl IntoIterator<Item = (&'a str, &'a Path)>,
    ) -> Result<()> {
        inputs
            .into_iter()
            .try_for_each(|(role, path)| self.input(role, path))
    }

    /// Declares a file the command will write, `role` saying what it is (`the ids output`).
    /// Errors, each naming the file: an extension not in `extensions` (compared
    /// case-insensitively; "" allows none), a path whose folder cannot be created, a
    /// declared input or output that is the same file.
    pub fn output(&mut self, role: &str, path: &Path, extensions: &[&str]) -> Result<OutputId> {
        check_extension(path, extensions)?;
        let target = FileIdentity::of_target(path)?;
        self.declare(role, path, target.identity, true)?;
        self.outputs.push(Output {
            shown: path.to_path_buf(),
            path: target.path,
            folders: target.folders,
            temporary: None,
        });
        Ok(OutputId(self.outputs.len() - 1))
    }

    /// The declared outputs, as the user named them, in the order declared.
    pub fn output_paths(&self) -> impl Iterator<Item = &Path> {
        self.outputs.iter().map(|o| o.shown.as_path())
    }

    /// Records a file, refusing one already declared under another role.
    fn declare(
        &mut self,
        role: &str,
        path: &Path,
        identity: FileIdentity,
        is_output: bool,
    ) -> Result<()> {
        let earlier = self.by_path.get(&identity.canonical).copied().or_else(|| {
            identity
                .inode
                .and_then(|inode| self.by_inode.get(&inode).copied())
        });
        if let Some(earlier) = earlier {
            let other = &self.declared[earlier];
            if is_output || other.is_output {
                let (output, (other_role, other_path)) = if is_output {
                    ((role, path), (other.role.as_str(), other.path.as_path()))
                } else {
                    ((other.role.as_str(), other.path.as_path()), (role, path))
                };
                let verb = if is_output && other.is_output {
                    "is the same file as"
                } else {
                    "would overwrite"
                };
                return Err(Error::in_file(
                    output.1,
                    format!("{} {verb} {other_role} {}", output.0, other_path.display()),
                ));
            }
            // The same input read twice (a texture two objects share): nothing to record.
            return Ok(());
        }
        let index = self.declared.len();
        self.by_path.insert(identity.canonical, index);
        if let Some(inode) = identity.inode {
            self.by_inode.insert(inode, index);
        }
        self.declared.push(Declared {
            role: role.to_string(),
            path: path.to_path_buf(),
            is_output,
        });
        Ok(())
    }

    /// Writes output `id` by calling `write` with a temporary path in the output's nearest
    /// existing folder. Errors from `write` are reported naming the output's path.
    pub fn stage(&mut self, id: OutputId, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let output = &mut self.outputs[id.0];
        let name = output
            .path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy();
        // The nearest existing folder: the output's own, or the one its first missing folder
        // will be made in (same file system, so the final rename is atomic).
        let folder = match output.folders.first().and_then(|f| f.parent()) {
            Some(existing) => existing.to_path_buf(),
            None => output.path.parent().unwrap_or(Path::new("")).to_path_buf(),
        };
        let temporary = folder.join(format!(".{name}.{}-{}.partial", std::process::id(), id.0));
        output.temporary = Some(temporary.clone());
        write(&temporary).map_err(|e| Error::in_file(&output.shown, e.message))
    }

    /// Moves every staged output into place, or none: see the module documentation. Errors:
    /// an output never staged, a folder that cannot be created, a file that cannot be moved
    /// into place (each naming the path).
    pub fn commit(mut self) -> Result<()> {
        let mut steps = Vec::new();
        let result = self
            .outputs
            .iter_mut()
            .enumerate()
            .try_for_each(|(index, output)| place(index, output, &mut steps));
        match result {
            Ok(()) => {
                for step in steps {
                    if let Step::Placed {
                        backup: Some(backup),
                        ..
                    } = step
                    {
                        let _ = fs::remove_file(backup);
                    }
                }
                Ok(())
            }
            Err(e) => {
                undo(steps);
                Err(e)
            }
        }
    }
}

/// Errors: the extension of `path` (lower-cased; "" for none) is not one of `extensions`.
pub fn check_extension(path: &Path, extensions: &[&str]) -> Result<()> {
    let ext = extension(path);
    if extensions.contains(&ext.as_str()) {
        return Ok(());
    }
    let expected: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
    Err(Error::in_file(
        path,
        format!(
            "unsupported output extension \"{ext}\" (expected {})",
            expected.join(" or ")
        ),
    ))
}

/// Writes `bytes` (a stats report, a scene) at `path`.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    fs::write(path, bytes).map_err(|e| Error::new(format!("cannot write: {e}")))
}

/// Creates the missing folders of `output`, keeps a backup of the file it replaces and moves
/// its temporary into place, recording each step in `steps`.
fn place(index: usize, output: &mut Output, steps: &mut Vec<Step>) -> Result<()> {
    let target = &output.path;
    let shown = &output.shown;
    let temporary = output
        .temporary
        .clone()
        .ok_or_else(|| Error::in_file(shown, "the output was never written"))?;
    for folder in &output.folders {
        match fs::create_dir(folder) {
            Ok(()) => steps.push(Step::Folder(folder.clone())),
            // Created for an earlier output of the set.
            Err(_) if folder.is_dir() => {}
            Err(e) => {
                return Err(Error::in_file(
                    shown,
                    format!("cannot create the folder {}: {e}", folder.display()),
                ))
            }
        }
    }
    // A folder in the way is left alone: the rename below fails on it.
    let replaces_file = target.symlink_metadata().is_ok_and(|m| !m.is_dir());
    let backup = if replaces_file {
        let name = target.file_name().unwrap_or_default().to_string_lossy();
        let backup =
            target.with_file_name(format!(".{name}.{}-{index}.backup", std::process::id()));
        // A hard link keeps the old file in place until the rename replaces it atomically;
        // a copy where the file system has no hard links.
        fs::hard_link(target, &backup)
            .or_else(|_| fs::copy(target, &backup).map(|_| ()))
            .map_err(|e| Error::in_file(shown, format!("cannot keep a backup: {e}")))?;
        Some(backup)
    } else {
        None
    };
    if let Err(e) = fs::rename(&temporary, target) {
        if let Some(backup) = backup {
            let _ = fs::remove_file(backup);
        }
        return Err(Error::in_file(shown, format!("cannot write: {e}")));
    }
    output.temporary = None;
    steps.push(Step::Placed {
        target: target.clone(),
        backup,
    });
    Ok(())
}

/// Undoes `steps` in reverse: backups go back in place, new files and folders are removed.
fn undo(steps: Vec<Step>) {
    for step in steps.into_iter().rev() {
        let _ = match step {
            Step::Placed {
                target,
                backup: Some(backup),
            } => fs::rename(backup, target),
            Step::Placed {
                target,
                backup: None,
            } => fs::remove_file(target),
            Step::Folder(folder) => fs::remove_dir(folder),
        };
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        for output in &self.outputs {
            if let Some(temporary) = &output.temporary {
                let _ = fs::remove_file(temporary);
            }
        }
    }
}
