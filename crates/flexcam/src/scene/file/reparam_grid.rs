//! `reparam = "grid"` of a flexible projection: `reparam_grid = { size = [M, N], uv = [[u, v],
//! ...] }` or `{ size = [M, N], file = "map.txt" }`, with `interpolation = "bilinear"` (the
//! default) or `"bicubic"`. The samples run along each row from left to right, rows from the
//! bottom of the image up. A file holds the same numbers as text, separated by spaces, tabs,
//! commas or line breaks, `#` starting a comment to the end of its line. Every problem is
//! reported at the value (or the file's line and column) it concerns; a folding cell at its
//! first (bottom-left) sample.

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use glam::DVec2;
use toml::Spanned;

use super::raw::RawReparamGrid;
use super::source::Source;
use crate::error::Result;
use crate::file_read::{read_regular_text, MAX_SCENE_FILE_BYTES};
use crate::projection::flexible::reparam::grid::{
    GridProblem, SampleInterpolation, MAX_GRID_SIDE, SAMPLE_INTERPOLATION_NAMES,
};
use crate::projection::flexible::reparam::UvGrid;
use crate::projection::flexible::Reparam;

/// The grid map of `table`.
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawReparamGrid>,
    base_dir: &Path,
) -> Result<Reparam> {
    let raw = table.get_ref();
    let [columns, rows] = *raw.size.get_ref();
    for n in [columns, rows] {
        if !(2..=MAX_GRID_SIDE as u32).contains(&n) {
            return Err(src.error(
                &raw.size.span(),
                format!("`size` = [columns, rows] must each be 2 to {MAX_GRID_SIDE}, got {n}"),
            ));
        }
    }
    let (columns, rows) = (columns as usize, rows as usize);
    let interpolation = match &raw.interpolation {
        None => SampleInterpolation::Bilinear,
        Some(name) => match name.get_ref().as_str() {
            "bilinear" => SampleInterpolation::Bilinear,
            "bicubic" => SampleInterpolation::Bicubic,
            other => {
                return Err(src.unknown(
                    &name.span(),
                    "uv grid interpolation",
                    other,
                    &SAMPLE_INTERPOLATION_NAMES,
                ))
            }
        },
    };
    let build = |samples| UvGrid::new(columns, rows, samples, interpolation);
    let grid = match (&raw.uv, &raw.file) {
        (Some(uv), None) => {
            let list = uv.get_ref();
            for sample in list {
                src.all_finite(sample.get_ref(), sample, "uv")?;
            }
            if list.len() != columns * rows {
                return Err(src.error(
                    &uv.span(),
                    format!(
                        "`uv` of a {columns} x {rows} grid needs {} samples [u, v], got {}",
                        columns * rows,
                        list.len()
                    ),
                ));
            }
            let samples = list
                .iter()
                .map(|p| DVec2::from_array(*p.get_ref()))
                .collect();
            build(samples).map_err(|problem| {
                let at = problem.sample.map_or(uv.span(), |k| list[k].span());
                src.error(&at, problem.message)
            })?
        }
        (None, Some(name)) => {
            let path = src.existing_file(name, base_dir, "uv grid")?;
            let text = read_regular_text(&path, "uv grid", MAX_SCENE_FILE_BYTES)?;
            let file = Source::new(&text, &path);
            let (samples, starts) = file_samples(&file, columns * rows)?;
            build(samples).map_err(|problem| match problem {
                GridProblem {
                    sample: Some(k),
                    message,
                } => file.error(&(starts[k]..starts[k]), message),
                GridProblem { message, .. } => file.file_error(message),
            })?
        }
        (Some(uv), Some(_)) => {
            return Err(src.error(
                &uv.span(),
                "`reparam_grid` takes either `uv` or `file`, not both",
            ))
        }
        (None, None) => {
            return Err(src.error(
                &table.span(),
                "`reparam_grid` needs its samples: `uv = [[u, v], ...]` or `file = \"...\"`",
            ))
        }
    };
    Ok(Reparam::Grid(Arc::new(grid)))
}

/// The `count` samples of the grid file `file` and the byte offset of each one's u. Errors:
/// a token that is not a finite number, a number beyond the `count` samples, fewer numbers
/// than 2 `count`.
fn file_samples(file: &Source, count: usize) -> Result<(Vec<DVec2>, Vec<usize>)> {
    let mut numbers = Vec::with_capacity(2 * count);
    let mut starts = Vec::with_capacity(count);
    for token in tokens(file.text) {
        let word = &file.text[token.clone()];
        let x: f64 = word
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .ok_or_else(|| {
                file.error(
                    &token,
                    format!("uv grid value `{word}` is not a finite number"),
                )
            })?;
        if numbers.len() == 2 * count {
            return Err(file.error(
                &token,
                format!("more numbers than the {count} samples [u, v] of the grid's `size`"),
            ));
        }
        if numbers.len() % 2 == 0 {
            starts.push(token.start);
        }
        numbers.push(x);
    }
    if numbers.len() != 2 * count {
        return Err(file.file_error(format!(
            "uv grid holds {} numbers; its `size` needs {count} samples, {} numbers",
            numbers.len(),
            2 * count
        )));
    }
    let samples = numbers
        .chunks_exact(2)
        .map(|p| DVec2::new(p[0], p[1]))
        .collect();
    Ok((samples, starts))
}

/// The byte ranges of the words of `text`: separated by whitespace and commas, with `#`
/// comments to the end of the line left out.
fn tokens(text: &str) -> impl Iterator<Item = Range<usize>> + '_ {
    let mut offset = 0;
    text.split_inclusive('\n').flat_map(move |line| {
        let start = offset;
        offset += line.len();
        let code = line.split('#').next().unwrap_or("");
        let mut words = Vec::new();
        let mut word: Option<usize> = None;
        for (i, c) in code.char_indices() {
            let separator = c.is_whitespace() || c == ',';
            match (separator, word) {
                (true, Some(w)) => {
                    words.push(start + w..start + i);
                    word = None;
                }
                (false, None) => word = Some(i),
                _ => {}
            }
        }
        if let Some(w) = word {
            words.push(start + w..start + code.len());
        }
        words
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_skip_separators_and_comments() {
        let text = "0 0, 1 0 # the bottom row\n\n0,1\t1 1";
        let words: Vec<&str> = tokens(text).map(|r| &text[r]).collect();
        assert_eq!(words, ["0", "0", "1", "0", "0", "1", "1", "1"]);
    }

    #[test]
    fn file_errors_name_the_line_and_column() {
        let path = Path::new("g.txt");
        let samples = |text: &str| file_samples(&Source::new(text, path), 4);
        let e = samples("0 0 1 0\n0 1 x 1\n").unwrap_err().to_string();
        assert_eq!(e, "g.txt:2:5: uv grid value `x` is not a finite number");
        let e = samples("0 0 1 0\n0 1 1 1 # done\n  5\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("g.txt:3:3: more numbers"), "{e}");
        assert!(samples("0 0 1 0 0 1 1 inf").is_err());
        let e = samples("0 0 1 0 0 1").unwrap_err().to_string();
        assert_eq!(
            e,
            "g.txt: uv grid holds 6 numbers; its `size` needs 4 samples, 8 numbers"
        );
        let (grid, starts) = samples("0 0 1 0\n 0 1 1 1").unwrap();
        assert_eq!(grid[3], DVec2::ONE);
        assert_eq!(starts, [0, 4, 9, 13]);
    }
}
