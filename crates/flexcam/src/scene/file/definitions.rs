//! `-D KEY=VALUE`: a scene key set from the command line, as if the scene file said so.
//!
//! KEY is a dotted path through the file's tables (`projection.fov`, `image.width`); an
//! array of tables (`[[object]]`, `[[light]]`) is entered by a 0-based index or by the
//! `name` of one of its tables (`object.floor.color`). VALUE is a TOML value (`90`,
//! `[1, 0, 0]`, `"fisheye"`); anything that is not one is taken as a string, so
//! `projection.type=fisheye` needs no quotes. The definitions are written into the file's
//! text (missing tables created) and the result is parsed exactly as a file is, so a value
//! is type-checked as the file's own would be; an error that points into a definition's key
//! or value names the `-D` argument instead of a line of the edited text.

use std::ops::Range;
use std::path::Path;
use std::str::FromStr;

use toml_edit::{DocumentMut, ImDocument, Item, Table, TableLike, Value};

use crate::error::{Error, Location, Result};

/// One `-D KEY=VALUE`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Definition {
    /// The dotted path, split at its dots.
    path: Vec<String>,
    /// The value's text.
    value: String,
}

impl Definition {
    /// The argument as the user gave it, for errors.
    fn argument(&self) -> String {
        format!("-D {}={}", self.path.join("."), self.value)
    }
}

impl FromStr for Definition {
    type Err = Error;

    /// Errors: no `=`, an empty key or an empty part of the dotted path.
    fn from_str(s: &str) -> Result<Definition> {
        let refuse = |why: &str| Error::new(format!("-D {s}: {why}"));
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| refuse("needs KEY=VALUE, e.g. projection.fov=90"))?;
        let path: Vec<String> = key
            .trim()
            .split('.')
            .map(|p| p.trim().to_string())
            .collect();
        if path.iter().any(String::is_empty) {
            return Err(refuse(
                "the key has an empty part (KEY is a dotted path such as projection.fov)",
            ));
        }
        Ok(Definition {
            path,
            value: value.trim().to_string(),
        })
    }
}

/// `text` (a scene file named `path`) with `definitions` written into it, in order, and
/// the byte span of each definition's key and value in the result. Errors name the `-D`
/// argument: a path through a value that is not a table, an array of tables entered by an
/// index out of range or a name none of its tables has.
pub(super) fn apply(
    text: &str,
    path: &Path,
    definitions: &[Definition],
) -> Result<(String, Vec<Range<usize>>)> {
    let mut document: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| Error::in_file(path, e.message().to_string()))?;
    for definition in definitions {
        set(document.as_table_mut(), definition)
            .map_err(|why| Error::in_file(path, format!("{}: {why}", definition.argument())))?;
    }
    let edited = document.to_string();
    let parsed = ImDocument::parse(edited.as_str())
        .map_err(|e| Error::in_file(path, e.message().to_string()))?;
    let spans = definitions
        .iter()
        .map(|d| span(parsed.as_table(), &d.path).unwrap_or(0..0))
        .collect();
    Ok((edited, spans))
}

/// An error of parsing the edited text, at line and column `at` of it, moved onto the
/// definition whose key or value it points into, if any: `FILE: -D KEY=VALUE: message`.
pub(super) fn blame(
    error: Error,
    edited: &str,
    definitions: &[Definition],
    spans: &[Range<usize>],
) -> Error {
    let Some((line, column)) = error.location.as_ref().and_then(|l| l.line_column) else {
        return error;
    };
    let line_start: usize = edited
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    let offset = edited[line_start.min(edited.len())..]
        .char_indices()
        .nth(column - 1)
        .map_or(edited.len(), |(i, _)| line_start + i);
    match definitions
        .iter()
        .zip(spans)
        .rev()
        .find(|(_, span)| span.contains(&offset))
    {
        Some((definition, _)) => Error {
            location: error.location.map(|l| Location {
                line_column: None,
                ..l
            }),
            message: format!("{}: {}", definition.argument(), error.message),
        },
        None => error,
    }
}

/// Writes `definition` into `root`.
fn set(root: &mut Table, definition: &Definition) -> std::result::Result<(), String> {
    let path = &definition.path;
    let mut table: &mut dyn TableLike = root;
    let mut depth = 0;
    while depth + 1 < path.len() {
        let part = &path[depth];
        if table.get(part).is_none() {
            let mut new = Table::new();
            new.set_implicit(true);
            table.insert(part, Item::Table(new));
        }
        let item = table.get_mut(part).expect("just ensured");
        table = match item {
            Item::ArrayOfTables(array) => {
                // The next part picks the table; a key must follow it.
                depth += 1;
                let pick = &path[depth];
                if depth + 1 == path.len() {
                    return Err(format!(
                        "{} is a table of {part}, not a key",
                        path.join(".")
                    ));
                }
                let names: Vec<Option<String>> = array.iter().map(name_of).collect();
                let index = element(pick, &names).ok_or_else(|| {
                    format!(
                        "{part} has no table {pick} (give a 0-based index below {} or a name)",
                        names.len()
                    )
                })?;
                array.get_mut(index).expect("index in range")
            }
            other => other
                .as_table_like_mut()
                .ok_or_else(|| format!("{} is not a table", path[..=depth].join(".")))?,
        };
        depth += 1;
    }
    table.insert(&path[depth], Item::Value(value_of(&definition.value)));
    Ok(())
}

/// The `name` key of a table of an array of tables, if it is a string.
fn name_of(table: &Table) -> Option<String> {
    table.get("name")?.as_str().map(str::to_string)
}

/// The element `part` picks among tables named `names`: a 0-based index, or the first
/// table of that name.
fn element(part: &str, names: &[Option<String>]) -> Option<usize> {
    match part.parse::<usize>() {
        Ok(index) => (index < names.len()).then_some(index),
        Err(_) => names.iter().position(|n| n.as_deref() == Some(part)),
    }
}

/// `text` as a TOML value, or as a string when it is not one.
fn value_of(text: &str) -> Value {
    text.parse::<Value>().unwrap_or_else(|_| Value::from(text))
}

/// The span from the key to the end of the value at `path` in `table`.
fn span(table: &dyn TableLike, path: &[String]) -> Option<Range<usize>> {
    let (part, rest) = path.split_first()?;
    let item = table.get(part)?;
    if rest.is_empty() {
        let key = table.key(part)?.span()?;
        return Some(key.start..item.span()?.end);
    }
    match item {
        Item::ArrayOfTables(array) => {
            let names: Vec<Option<String>> = array.iter().map(name_of).collect();
            let (pick, rest) = rest.split_first()?;
            span(array.get(element(pick, &names)?)?, rest)
        }
        other => span(other.as_table_like()?, rest),
    }
}
