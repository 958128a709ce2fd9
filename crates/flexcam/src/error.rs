//! The one error type of the library: a message, and where in which input it arose.
//!
//! Every error a user can cause is reported as a single line, `FILE:LINE:COLUMN: message`
//! (or `FILE: message` when no position is known), so that the CLI can print it unchanged.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where an error arose: a file and, when known, a 1-based line and column in it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The input file, as the user named it.
    pub file: PathBuf,
    /// 1-based line and column in `file`, where the input format has them (scene files, OBJ).
    pub line_column: Option<(usize, usize)>,
}

/// An error with a human-readable message and an optional input location.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    /// The input the error is in, printed before the message; `None` when it concerns no file.
    pub location: Option<Location>,
    /// What went wrong, one line for the user.
    pub message: String,
}

/// Result alias used throughout the library.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An error that is not tied to an input file (a bad flag value, say).
    pub fn new(message: impl Into<String>) -> Self {
        Error {
            location: None,
            message: message.into(),
        }
    }

    /// An error about a whole file (missing, unreadable, wrong format).
    pub fn in_file(file: impl AsRef<Path>, message: impl Into<String>) -> Self {
        Error {
            location: Some(Location {
                file: file.as_ref().to_path_buf(),
                line_column: None,
            }),
            message: message.into(),
        }
    }

    /// An error at a 1-based line and column of a file.
    pub fn at(
        file: impl AsRef<Path>,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        Error {
            location: Some(Location {
                file: file.as_ref().to_path_buf(),
                line_column: Some((line, column)),
            }),
            message: message.into(),
        }
    }

    /// Attaches `file` as the location if the error has none yet; keeps a more precise one.
    pub fn or_in_file(mut self, file: impl AsRef<Path>) -> Self {
        if self.location.is_none() {
            self.location = Some(Location {
                file: file.as_ref().to_path_buf(),
                line_column: None,
            });
        }
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Messages are kept to one line: a multi-line message from a dependency is folded.
        let message = self
            .message
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        match &self.location {
            None => write!(f, "{message}"),
            Some(Location {
                file,
                line_column: None,
            }) => write!(f, "{}: {message}", file.display()),
            Some(Location {
                file,
                line_column: Some((line, column)),
            }) => write!(f, "{}:{line}:{column}: {message}", file.display()),
        }
    }
}

impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_is_one_line_with_position() {
        let e = Error::at(
            "scene.toml",
            3,
            7,
            "unknown projection type \"fisheyes\"\n  expected one of ...",
        );
        assert_eq!(
            e.to_string(),
            "scene.toml:3:7: unknown projection type \"fisheyes\" expected one of ..."
        );
        assert_eq!(
            Error::in_file("a.obj", "not found").to_string(),
            "a.obj: not found"
        );
        assert_eq!(Error::new("bad").to_string(), "bad");
    }

    #[test]
    fn or_in_file_keeps_precise_location() {
        let e = Error::at("a.toml", 1, 2, "x").or_in_file("b.toml");
        assert_eq!(e.to_string(), "a.toml:1:2: x");
        let e = Error::new("x").or_in_file("b.toml");
        assert_eq!(e.to_string(), "b.toml: x");
    }
}
