//! Editing scene-file text in place (toml_edit), keeping its comments and layout: how
//! `flexcam fit` writes the fitted projectors and the viewer writes an edited projection
//! back into a scene file.
//!
//! Floats are written in Rust's shortest round-trip form, so a value read back from the
//! written text is the written value bit for bit.

use std::path::Path;

use toml_edit::{DocumentMut, Item, Value};

use crate::error::{Error, Result};

/// Parses scene-file text `text` (read from `path`, named in errors) into an editable
/// document.
pub fn parse_document(text: &str, path: &Path) -> Result<DocumentMut> {
    text.parse()
        .map_err(|e: toml_edit::TomlError| Error::in_file(path, e.message().to_string()))
}

/// A TOML array of floats.
pub fn float_array(values: &[f64]) -> Value {
    Value::Array(values.iter().copied().collect())
}

/// The value of key `key` of the `[projection]` table of `document`: a key of the table, or
/// a dotted path into its tables (`projectors.rows`); `None` when absent or not a value.
pub fn projection_value<'d>(document: &'d DocumentMut, key: &str) -> Option<&'d Value> {
    let mut item = document.get("projection")?;
    for part in key.split('.') {
        item = item.get(part)?;
    }
    item.as_value()
}

/// Sets key `key` (as [`projection_value`] reads it) of the `[projection]` table of
/// `document` to `value`. A replaced value keeps its decoration (the spaces and the comment
/// around it), and a float stays a float when given an integer (`fov = 70.0` for 70); a new
/// key is appended to its table. The tables on the way must exist; the
/// value itself is not checked here (parse the edited text for that). Errors name `path`.
pub fn set_projection_value(
    document: &mut DocumentMut,
    key: &str,
    mut value: Value,
    path: &Path,
) -> Result<()> {
    let missing = |what: &str| Error::in_file(path, format!("no {what} to set `{key}` in"));
    let (tables, last) = match key.rsplit_once('.') {
        Some((tables, last)) => (Some(tables), last),
        None => (None, key),
    };
    if last.is_empty() || tables.is_some_and(|t| t.split('.').any(str::is_empty)) {
        return Err(Error::new(format!("`{key}` is not a key")));
    }
    // Looked up through the tables themselves: `Item::get_mut` would insert a missing key.
    let mut table = document
        .as_table_mut()
        .get_mut("projection")
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| missing("[projection] table"))?;
    for part in tables.into_iter().flat_map(|t| t.split('.')) {
        table = table
            .get_mut(part)
            .and_then(Item::as_table_like_mut)
            .ok_or_else(|| missing(&format!("table `{part}`")))?;
    }
    match table.get_mut(last) {
        Some(Item::Value(old)) if !old.is_inline_table() => {
            if let (Value::Float(_), Some(i)) = (&*old, value.as_integer()) {
                value = Value::from(i as f64);
            }
            *value.decor_mut() = old.decor().clone();
            *old = value;
        }
        Some(_) => {
            return Err(Error::in_file(
                path,
                format!("`{key}` is a table, not a value: set its keys one by one"),
            ))
        }
        None => {
            table.insert(last, Item::Value(value));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# a scene\n[projection]\ntype = \"perspective\"\nfov = 60.0 # degrees\n\
                        projectors = { rows = 2 }\n\n[[object]]\nshape = \"box\"\n";

    fn document() -> DocumentMut {
        parse_document(TEXT, Path::new("s.toml")).unwrap()
    }

    #[test]
    fn replacing_a_value_keeps_comments_and_layout() {
        let mut doc = document();
        set_projection_value(&mut doc, "fov", Value::from(100.5), Path::new("s.toml")).unwrap();
        assert_eq!(
            doc.to_string(),
            TEXT.replace("fov = 60.0 # degrees", "fov = 100.5 # degrees")
        );
        set_projection_value(&mut doc, "fov", Value::from(70), Path::new("s.toml")).unwrap();
        assert_eq!(
            projection_value(&doc, "fov").unwrap().as_float(),
            Some(70.0)
        );
        assert_eq!(
            doc.to_string(),
            TEXT.replace("fov = 60.0 # degrees", "fov = 70.0 # degrees")
        );
    }

    #[test]
    fn dotted_keys_reach_inline_tables_and_new_keys_are_added() {
        let mut doc = document();
        let path = Path::new("s.toml");
        set_projection_value(&mut doc, "projectors.rows", Value::from(3), path).unwrap();
        set_projection_value(&mut doc, "position", float_array(&[0.0, 1.0, 0.1]), path).unwrap();
        assert_eq!(
            projection_value(&doc, "projectors.rows")
                .unwrap()
                .as_integer(),
            Some(3)
        );
        let text = doc.to_string();
        assert!(text.contains("position = [0.0, 1.0, 0.1]"), "{text}");
        assert!(text.starts_with("# a scene\n"));
    }

    #[test]
    fn missing_tables_and_tables_as_values_are_errors() {
        let mut doc = document();
        let path = Path::new("s.toml");
        let err = set_projection_value(&mut doc, "grid.rows", Value::from(3), path).unwrap_err();
        assert_eq!(
            err.to_string(),
            "s.toml: no table `grid` to set `grid.rows` in"
        );
        let err = set_projection_value(&mut doc, "projectors", Value::from(3), path).unwrap_err();
        assert!(err.to_string().contains("is a table, not a value"), "{err}");
        assert!(set_projection_value(&mut doc, "a..b", Value::from(3), path).is_err());
        assert!(projection_value(&doc, "nothing").is_none());
    }
}
