//! The text of a scene file and its name, for turning byte spans into `FILE:LINE:COLUMN`
//! errors.

use std::cell::{Cell, RefCell};
use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::Spanned;

use crate::error::{Error, Result};
use crate::scene::loaders::Model;
use crate::scene::{budget, InputFile};

/// A scene file being parsed: its text, the path the user gave for it, and the files its
/// values named so far.
pub(super) struct Source<'a> {
    pub text: &'a str,
    pub path: &'a Path,
    inputs: RefCell<Vec<InputFile>>,
    /// Triangles of the objects converted so far, for the memory budget.
    triangles: Cell<u64>,
    /// A model already read, for the object that names its file ([`Source::take_model`]).
    model: RefCell<Option<Model>>,
}

impl<'a> Source<'a> {
    pub fn new(text: &'a str, path: &'a Path) -> Source<'a> {
        Source {
            text,
            path,
            inputs: RefCell::new(Vec::new()),
            triangles: Cell::new(0),
            model: RefCell::new(None),
        }
    }

    /// The source with `model` read already: the object whose file is the model's takes it
    /// instead of reading the file again.
    pub fn with_model(self, model: Option<Model>) -> Source<'a> {
        Source {
            model: RefCell::new(model),
            ..self
        }
    }

    /// Records files read on behalf of the scene (a model's material libraries, say).
    pub fn read_files(&self, files: impl IntoIterator<Item = InputFile>) {
        self.inputs.borrow_mut().extend(files);
    }

    /// Adds `count` triangles to the scene's, failing at `span` before they are built when
    /// the scene's triangles would exceed the memory budget ([`budget::check`]).
    pub fn reserve_triangles(&self, count: u64, span: &Range<usize>) -> Result<()> {
        let total = self.triangles.get().saturating_add(count);
        let bytes = total.saturating_mul(budget::BYTES_PER_TRIANGLE);
        budget::check(bytes, &format!("{total} triangles"))
            .map_err(|e| self.error(span, e.message))?;
        self.triangles.set(total);
        Ok(())
    }

    /// Fails at `span` before the model file `path` is parsed when its size suggests more
    /// memory than the budget leaves (its triangles are reserved once it is loaded).
    pub fn check_model_size(&self, path: &Path, span: &Range<usize>) -> Result<()> {
        let reserved = self.triangles.get() * budget::BYTES_PER_TRIANGLE;
        budget::check_model_file(path, reserved).map_err(|e| self.error(span, e.message))
    }

    /// The model read from `path` before the text was parsed, if it is the one handed to
    /// [`Source::with_model`] (once: the model is moved out).
    pub fn take_model(&self, path: &Path) -> Option<Model> {
        let mut slot = self.model.borrow_mut();
        let matches = slot
            .as_ref()
            .is_some_and(|m| m.files.first().is_some_and(|f| f.path == path));
        matches.then(|| slot.take()).flatten()
    }

    /// The files recorded so far, in the order they were read.
    pub fn into_inputs(self) -> Vec<InputFile> {
        self.inputs.into_inner()
    }

    /// An error at the start of the byte span `span` of the text.
    pub fn error(&self, span: &Range<usize>, message: impl Into<String>) -> Error {
        let (line, column) = self.line_column(span.start);
        Error::at(self.path, line, column, message)
    }

    /// The file a scene value names (a model, texture or surface), resolved against
    /// `base_dir`. Fails at the value when no regular file is there (an empty name, a
    /// folder, a missing file), so that the error points into the scene rather than at a
    /// path the user never wrote; the loader's own errors (a file it cannot parse) name the
    /// file itself. The file is recorded as an input of the scene.
    pub fn existing_file(
        &self,
        name: &Spanned<String>,
        base_dir: &Path,
        what: &'static str,
    ) -> Result<PathBuf> {
        let path = base_dir.join(name.get_ref());
        if path.is_file() {
            self.read_files([InputFile {
                what,
                path: path.clone(),
            }]);
            return Ok(path);
        }
        Err(self.error(
            &name.span(),
            format!(
                "{what} \"{}\" is not a file (looked for {})",
                name.get_ref(),
                path.display()
            ),
        ))
    }

    /// The error for a value that names none of the choices a key takes: `unknown WHAT
    /// "NAME"; expected one of: A, B, ...`, the one form every such key of a scene file uses.
    pub fn unknown<S: AsRef<str>>(
        &self,
        span: &Range<usize>,
        what: &str,
        name: &str,
        expected: &[S],
    ) -> Error {
        let expected: Vec<&str> = expected.iter().map(AsRef::as_ref).collect();
        self.error(
            span,
            format!(
                "unknown {what} \"{name}\"; expected one of: {}",
                expected.join(", ")
            ),
        )
    }

    /// Fails at the first key of `present` (name, span) that is not in `allowed`, naming
    /// `what` takes instead (e.g. "fisheye projections"), so a key of another type is caught.
    pub fn reject_foreign_key(
        &self,
        present: Vec<(&'static str, Range<usize>)>,
        allowed: &[&str],
        what: &str,
    ) -> Result<()> {
        match present.into_iter().find(|(key, _)| !allowed.contains(key)) {
            Some((key, span)) => Err(self.error(
                &span,
                format!(
                    "`{key}` is not a parameter of {what} (they take: {})",
                    allowed.join(", ")
                ),
            )),
            None => Ok(()),
        }
    }

    /// An error about the file as a whole.
    pub fn file_error(&self, message: impl Into<String>) -> Error {
        Error::in_file(self.path, message)
    }

    /// Converts a TOML syntax or type error into a positioned one-line error.
    pub fn toml_error(&self, error: &toml::de::Error) -> Error {
        let message =
            super::suggest::unknown_key(error.message()).unwrap_or_else(|| error.message().into());
        match error.span() {
            Some(span) => self.error(&span, message),
            None => self.file_error(message),
        }
    }

    /// The 1-based line and column (in characters) of byte offset `offset`, clamped to the
    /// text.
    pub fn line_column(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line = before.matches('\n').count() + 1;
        let column = before[line_start..].chars().count() + 1;
        (line, column)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_column_counts_characters_from_one() {
        let src = Source::new("ab\nc\u{e9}d\n", Path::new("s.toml"));
        assert_eq!(src.line_column(0), (1, 1));
        assert_eq!(src.line_column(1), (1, 2));
        assert_eq!(src.line_column(3), (2, 1));
        // 'é' is two bytes but one column.
        assert_eq!(src.line_column(6), (2, 3));
        assert_eq!(src.line_column(100), (3, 1));
        assert_eq!(src.error(&(4..5), "x").to_string(), "s.toml:2:2: x");
    }
}
