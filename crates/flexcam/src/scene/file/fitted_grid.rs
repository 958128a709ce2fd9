//! `flexcam fit`: runs the projector-grid fit of a scene file and writes the scene back with
//! the fitted node projectors explicit, so that an artist can go on editing them.
//!
//! The written file is the original text edited in place (comments and layout kept): in the
//! projection's `projectors` table the `fit`, `aim`, `projector`, `starts`, `painting` and
//! `painting_size` keys are replaced by one
//! `projector` entry per node with its fitted `start` and `end`, and its `tangent` when it is
//! curved (a grid with tangents is fitted with curved projectors). Floats are written in Rust's
//! shortest round-trip form, so the written grid is the fitted one bit for bit, and rendering
//! the written file gives the image of the fitting scene. The result is parsed back before
//! it is returned (as if it were at its output path, whose folder then resolves its relative
//! model paths) and its grid compared with the fitted one: a written scene that would not
//! load, or load differently, is an error instead of a file.

use std::path::{Path, PathBuf};

use toml_edit::{Array, InlineTable, Item, TableLike, Value};

use super::edit::{float_array, parse_document};

use crate::calibrate::{self, FitReport};
use crate::error::{Error, Result};
use crate::projection::flexible::{
    Correspondence, Flexible, FlexibleSpec, ProjectorGrid, Volume, VolumeSource,
};
use crate::projection::ProjectionSpec;
use crate::scene::InputFile;

/// A fitted scene: the text to write, the fit's residual, the files the fitting scene's
/// values named (models, textures, surfaces, the painting; see
/// [`crate::scene::Scene::inputs`]), and the correspondences and painting the fit was made
/// from (for an overlay of the fit on the painting).
#[derive(Debug, Clone, PartialEq)]
pub struct FittedScene {
    /// The scene file's text with the fitted node projectors written in.
    pub text: String,
    /// The fit's residual and what it chose.
    pub report: FitReport,
    /// The files the fitting scene read.
    pub inputs: Vec<InputFile>,
    /// The correspondences fitted, their image positions in (u, v) (`pixel` entries
    /// converted).
    pub correspondences: Vec<Correspondence>,
    /// The painting image (`painting`, resolved from the fitting scene's folder).
    pub painting: Option<PathBuf>,
    /// The painting's size given by `painting_size`, in pixels.
    pub painting_size: Option<[u32; 2]>,
}

/// Fits the projector grid of the scene file `text` (read from `path`) to its `fit`
/// correspondences and returns the scene text with the fitted projectors explicit, checked
/// to load back from `output` to the same grid. Errors (naming `path`): a scene that does
/// not load, a projection that is not a flexible projector grid with `fit` correspondences,
/// and a written scene that does not load back from `output` identically.
pub fn fit_scene(text: &str, path: &Path, output: &Path) -> Result<FittedScene> {
    let scene = super::parse(text, path)?;
    let (width, height) = (scene.image.width, scene.image.height);
    let (grid, report) = fitted_grid(&scene.projection, width, height)
        .map_err(|e| e.or_in_file(path))?
        .ok_or_else(|| {
            Error::in_file(
                path,
                "nothing to fit: the projection is not a flexible projection with a \
                 `projectors` table holding `fit` correspondences",
            )
        })?;
    let mut document = parse_document(text, path)?;
    let projectors = document
        .get_mut("projection")
        .and_then(|p| p.get_mut("projectors"))
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| Error::in_file(path, "the [projection] table has no `projectors`"))?;
    // Both were checked by the parse above.
    let base_dir = path.parent().unwrap_or(Path::new(""));
    let painting = projectors
        .get("painting")
        .and_then(Item::as_str)
        .map(|name| base_dir.join(name));
    let painting_size = projectors
        .get("painting_size")
        .and_then(Item::as_array)
        .and_then(|a| {
            let side = |i| a.get(i)?.as_integer().and_then(|n| u32::try_from(n).ok());
            Some([side(0)?, side(1)?])
        });
    replace_nodes(projectors, &grid);
    let warning = report
        .warning()
        .map_or_else(String::new, |w| format!("# Warning: {w}.\n"));
    let header = format!(
        "# Written by `flexcam fit` from {}: {} correspondences, residual max {:e} and rms \
         {:e} degrees, {}.\n{warning}",
        path.display(),
        report.correspondences,
        report.max_angle_deg,
        report.rms_angle_deg,
        report.model()
    );
    let written = format!("{header}{document}");
    check_round_trip(&written, output, &grid, width, height)?;
    Ok(FittedScene {
        text: written,
        report,
        inputs: scene.inputs,
        correspondences: correspondences(&scene.projection),
        painting,
        painting_size,
    })
}

/// The fitted grid and its residual when `projection` is a projector grid with
/// correspondences; `None` otherwise.
fn fitted_grid(
    projection: &ProjectionSpec,
    width: u32,
    height: u32,
) -> Result<Option<(ProjectorGrid, FitReport)>> {
    let ProjectionSpec::Flexible(spec) = projection else {
        return Ok(None);
    };
    if !has_fit(spec) {
        return Ok(None);
    }
    // The top-level grid is fitted last (after any grids of its base).
    let (flexible, mut reports) = calibrate::build_flexible(spec, width, height)?;
    Ok(match (flexible.volume(), reports.pop()) {
        (Volume::Grid(grid), Some(report)) => Some((grid.grid.clone(), report)),
        _ => None,
    })
}

fn has_fit(spec: &FlexibleSpec) -> bool {
    matches!(&spec.source, VolumeSource::ProjectorGrid { grid, .. } if !grid.correspondences.is_empty())
}

/// The correspondences of the top-level projector grid of `projection` (none for any other
/// projection).
fn correspondences(projection: &ProjectionSpec) -> Vec<Correspondence> {
    match projection {
        ProjectionSpec::Flexible(spec) => match &spec.source {
            VolumeSource::ProjectorGrid { grid, .. } => grid.correspondences.clone(),
            _ => Vec::new(),
        },
        _ => Vec::new(),
    }
}

/// Replaces `fit`, `aim`, `projector` and `starts`, `painting` and `painting_size` (which go
/// with `fit` only) in `table` by one `projector` entry per node of
/// `grid` (bottom row first), one per line, with the tangents of curved nodes (unit vectors
/// that normalising leaves unchanged, so they load back bit for bit).
fn replace_nodes(table: &mut dyn TableLike, grid: &ProjectorGrid) {
    for key in [
        "fit",
        "aim",
        "projector",
        "starts",
        "painting",
        "painting_size",
    ] {
        table.remove(key);
    }
    let cols = grid.size().0;
    let mut nodes = Array::new();
    let nodes_of = grid.starts().iter().zip(grid.ends()).zip(grid.tangents());
    for (j, ((start, end), tangent)) in nodes_of.enumerate() {
        let mut node = InlineTable::new();
        node.insert("node", pair([j % cols, j / cols]));
        node.insert("start", float_array(&start.to_array()));
        node.insert("end", float_array(&end.to_array()));
        if let Some(tangent) = tangent {
            node.insert("tangent", float_array(&tangent.to_array()));
        }
        let mut value = Value::InlineTable(node);
        value.decor_mut().set_prefix("\n    ");
        nodes.push_formatted(value);
    }
    nodes.set_trailing_comma(true);
    nodes.set_trailing("\n");
    table.insert("projector", Item::Value(Value::Array(nodes)));
}

fn pair(values: [usize; 2]) -> Value {
    // Node indices are below 10 (the grid's largest side is 9).
    Value::Array(values.iter().map(|&i| i as i64).collect())
}

/// Parses `written` as if it were at `output` and checks that it holds exactly `grid`.
fn check_round_trip(
    written: &str,
    output: &Path,
    grid: &ProjectorGrid,
    width: u32,
    height: u32,
) -> Result<()> {
    let reloaded = super::parse(written, output).map_err(|e| {
        Error::in_file(
            output,
            format!(
                "the fitted scene would not load from here ({e}); write it next to the \
                 original so its relative paths still resolve"
            ),
        )
    })?;
    let ProjectionSpec::Flexible(spec) = &reloaded.projection else {
        return Err(Error::in_file(
            output,
            "the fitted scene lost its projection",
        ));
    };
    let same = match Flexible::new(spec, width, height)?.volume() {
        Volume::Grid(g) => g.grid == *grid,
        _ => false,
    };
    if same {
        Ok(())
    } else {
        Err(Error::in_file(
            output,
            "the fitted scene does not load back to the fitted grid",
        ))
    }
}
