//! The TOML scene format of the scene-and-CLI spec (`scenes/README.md` documents every key).
//!
//! Parsing happens in two stages: serde reads the text into flat, span-carrying structs
//! (module `raw`), then each table is checked and converted by hand, so that every error, from a
//! TOML syntax error to a degenerate projection, is one line `FILE:LINE:COLUMN: message`.

mod animation;
mod calibrated_projection;
mod control_surface;
mod definitions;
mod displacement;
pub mod edit;
mod fisheye_projection;
mod fitted_grid;
mod flexible;
#[cfg(test)]
mod flexible_map_tests;
mod interpolate;
mod light;
mod motion;
mod object;
mod panorama;
mod pieces;
mod projection;
mod projection_table;
mod projector_grid;
mod raw;
mod reparam_grid;
mod shape;
mod source;
mod strict;
mod suggest;
mod trilinear_grid;
mod values;

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;
use toml::Spanned;

use self::raw::{RawImage, RawProjection, RawScene};
use self::source::Source;
use super::loaders::Model;
use super::{ImageSettings, InputFile, Light, Scene};
use crate::error::{Error, Result};
use crate::file_read::{read_regular_text, MAX_SCENE_FILE_BYTES};
use crate::projection::flexible::Animation;
use crate::projection::ProjectionSpec;

pub use self::animation::DEFAULT_FPS;
pub use self::definitions::Definition;
pub use self::fitted_grid::{fit_scene, FittedScene};

/// The largest accepted image side, in pixels. It keeps an image at or below 2^28 pixels, so
/// that frame buffers (several values per pixel) fit in memory.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The most samples per pixel a scene (`[image] spp`) or `--spp` may ask for.
pub const MAX_SPP: u32 = 4096;

/// Checks an image resolution: both sides in 1..=[`MAX_IMAGE_SIDE`]. The CLI reuses it for
/// its `--width` / `--height` overrides.
pub fn validate_resolution(width: u32, height: u32) -> Result<()> {
    for (name, value) in [("width", width), ("height", height)] {
        if !(1..=MAX_IMAGE_SIDE).contains(&value) {
            return Err(Error::new(format!(
                "image {name} {value} is out of range: it must be in 1..={MAX_IMAGE_SIDE}"
            )));
        }
    }
    Ok(())
}

/// Reads and parses the scene file at `path`. Errors name `path` as given.
pub fn load(path: &Path) -> Result<Scene> {
    load_animated(path).map(|(scene, _)| scene)
}

/// Parses scene-file text. `path` names the file in errors, and its folder is the base for
/// the relative paths in the file (models, textures, projection surfaces). An `[animation]`
/// table is checked but left out: see [`parse_animated`].
pub fn parse(text: &str, path: &Path) -> Result<Scene> {
    parse_animated(text, path).map(|(scene, _)| scene)
}

/// Reads and parses the scene file at `path` with its `[animation]` table, if any. The
/// scene file is the first of the scene's [`Scene::inputs`].
pub fn load_animated(path: &Path) -> Result<(Scene, Option<Animation>)> {
    load_animated_defined(path, &[])
}

/// [`load_animated`] with `definitions` (`-D KEY=VALUE`) written into the file's text
/// ([`parse_defined`]).
pub fn load_animated_defined(
    path: &Path,
    definitions: &[Definition],
) -> Result<(Scene, Option<Animation>)> {
    let text = read_regular_text(path, "scene file", MAX_SCENE_FILE_BYTES)?;
    let (mut scene, animation) = parse_defined(&text, path, definitions)?;
    scene.inputs.insert(
        0,
        InputFile {
            what: "scene file",
            path: path.to_path_buf(),
        },
    );
    Ok((scene, animation))
}

/// [`parse_animated`] of `text` with `definitions` (`-D KEY=VALUE`) written into it; an
/// error in a definition's key or value names the definition (module `definitions`).
pub fn parse_defined(
    text: &str,
    path: &Path,
    definitions: &[Definition],
) -> Result<(Scene, Option<Animation>)> {
    parse_defined_with_model(text, path, definitions, None)
}

/// [`parse_defined`] with `model` already read: the object whose `file` is the model's
/// file takes it instead of reading the file again (a model given as the scene is read
/// once to frame it, [`crate::scene::model_scene`]).
pub fn parse_defined_with_model(
    text: &str,
    path: &Path,
    definitions: &[Definition],
    model: Option<Model>,
) -> Result<(Scene, Option<Animation>)> {
    if definitions.is_empty() {
        return parse_source(Source::new(text, path).with_model(model));
    }
    let (edited, spans) = definitions::apply(text, path, definitions)?;
    parse_source(Source::new(&edited, path).with_model(model))
        .map_err(|e| definitions::blame(e, &edited, definitions, &spans))
}

/// The `[image]` settings of scene-file text with `definitions` (`-D KEY=VALUE`) written
/// into it, the file's other tables read but not converted: the image size a scene's
/// camera is made for before the scene is parsed ([`crate::scene::model_scene`]).
pub fn image_defined(text: &str, path: &Path, definitions: &[Definition]) -> Result<ImageSettings> {
    let (edited, spans) = definitions::apply(text, path, definitions)?;
    let src = Source::new(&edited, path);
    read_raw(&src)
        .and_then(|raw| image_settings(&src, raw.image.as_ref()))
        .map_err(|e| definitions::blame(e, &edited, definitions, &spans))
}

/// As [`parse`], also giving the keyframed camera of the `[animation]` table, if any. The
/// scene's [`Scene::inputs`] are the files its values name (and the files those name).
pub fn parse_animated(text: &str, path: &Path) -> Result<(Scene, Option<Animation>)> {
    parse_source(Source::new(text, path))
}

/// [`parse_animated`] of the text of `src`.
fn parse_source(src: Source) -> Result<(Scene, Option<Animation>)> {
    let path = src.path;
    let raw = read_raw(&src)?;
    let base_dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let (image, projection_table, projection) = image_and_projection(&src, &raw, &base_dir)?;
    check_unique_names(&src, &raw.object)?;
    let mut objects = Vec::new();
    let mut trilinear_reflectors = Vec::new();
    let mut caustics = Vec::new();
    let mut motions = Vec::new();
    for (index, table) in raw.object.iter().enumerate() {
        let id =
            u32::try_from(index + 1).map_err(|_| src.error(&table.span(), "too many objects"))?;
        let parts = object::convert(&src, table, id, &base_dir)?;
        if let Some(reflector) = object::trilinear_reflector(&src, table, id, &parts, &projection)?
        {
            trilinear_reflectors.push(reflector);
        }
        if let Some(caustic) = object::caustic_reflector(&src, table, id, &parts, &projection)? {
            caustics.push(caustic);
        }
        if let Some(orbit) = &table.get_ref().orbit {
            motions.push(motion::convert(&src, orbit, id)?);
        }
        objects.extend(parts);
    }
    let lights = raw
        .light
        .iter()
        .map(|table| light::convert(&src, table))
        .collect::<Result<Vec<_>>>()?;
    if let Some((_, span)) = caustics.first() {
        if !lights.iter().any(|l| matches!(l, Light::Point { .. })) {
            return Err(src.error(
                span,
                "`caustics` needs a point light ([[light]] type = \"point\") to focus",
            ));
        }
    }
    // Building the projection is what detects degenerate parameters.
    crate::calibrate::build(&projection, image.width, image.height).map_err(|e| {
        match e.location {
            Some(_) => e,
            None => src.error(&projection_table.span(), e.message),
        }
    })?;
    let animation = raw
        .animation
        .as_ref()
        .map(|table| animation::convert(&src, table, &base_dir, &image, !motions.is_empty()))
        .transpose()?;
    let scene = Scene {
        objects,
        lights,
        image,
        projection,
        base_dir: Some(base_dir),
        trilinear_reflectors,
        caustics: caustics.into_iter().map(|(c, _)| c).collect(),
        motions,
        inputs: src.into_inputs(),
    };
    Ok((scene, animation))
}

/// The image settings and the projection of scene-file text (read from `path`), checked and
/// converted as [`parse`] does but neither built nor followed by the objects: what a program
/// that edits the projection alone (the viewer) reads again after each edit, without
/// loading the scene's models again. The projection is not built (see
/// [`crate::calibrate::build`]), so a degenerate one is found only then.
pub fn parse_projection(text: &str, path: &Path) -> Result<(ImageSettings, ProjectionSpec)> {
    let src = Source::new(text, path);
    let raw = read_raw(&src)?;
    let base_dir = path.parent().unwrap_or(Path::new(""));
    let (image, _, projection) = image_and_projection(&src, &raw, base_dir)?;
    Ok((image, projection))
}

/// The raw tables of scene-file text, after refusing a projection type that is recognised
/// but not supported.
fn read_raw(src: &Source) -> Result<RawScene> {
    projection::reject_unsupported(src)?;
    toml::from_str(src.text).map_err(|e| src.toml_error(&e))
}

/// `[image]` and `[projection]` converted, with the projection's raw table (for the span
/// of errors found when it is built).
fn image_and_projection<'r>(
    src: &Source,
    raw: &'r RawScene,
    base_dir: &Path,
) -> Result<(ImageSettings, &'r Spanned<RawProjection>, ProjectionSpec)> {
    let image = image_settings(src, raw.image.as_ref())?;
    let projection_table = raw
        .projection
        .as_ref()
        .ok_or_else(|| src.file_error("missing [projection] table: a scene needs exactly one"))?;
    let projection =
        projection::convert(src, projection_table, base_dir, [image.width, image.height])?;
    Ok((image, projection_table, projection))
}

/// `[image]`, with [`ImageSettings::default`] for absent keys.
fn image_settings(src: &Source, table: Option<&Spanned<RawImage>>) -> Result<ImageSettings> {
    let defaults = ImageSettings::default();
    let Some(table) = table else {
        return Ok(defaults);
    };
    let raw = table.get_ref();
    let side = |value: &Option<Spanned<u32>>, default: u32| {
        value.as_ref().map_or(default, |v| *v.get_ref())
    };
    let (width, height) = (
        side(&raw.width, defaults.width),
        side(&raw.height, defaults.height),
    );
    validate_resolution(width, height).map_err(|e| {
        let at = [&raw.width, &raw.height]
            .into_iter()
            .flatten()
            .find(|v| !(1..=MAX_IMAGE_SIDE).contains(v.get_ref()))
            .map_or(table.span(), Spanned::span);
        src.error(&at, e.message)
    })?;
    let background = raw
        .background
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |b| src.color(b, "background"))?;
    let spp = match &raw.spp {
        Some(spp) if !(1..=MAX_SPP).contains(spp.get_ref()) => {
            return Err(src.error(
                &spp.span(),
                format!("spp must be 1 to {MAX_SPP}, got {}", spp.get_ref()),
            ))
        }
        Some(spp) => *spp.get_ref(),
        None => defaults.spp,
    };
    Ok(ImageSettings {
        width,
        height,
        background,
        spp,
    })
}

/// Object names are optional but must be unique.
fn check_unique_names(src: &Source, objects: &[Spanned<raw::RawObject>]) -> Result<()> {
    let mut seen = HashMap::new();
    for name in objects.iter().filter_map(|o| o.get_ref().name.as_ref()) {
        if let Some(first) = seen.insert(name.get_ref().as_str(), name.span()) {
            let (line, _) = src.line_column(first.start);
            return Err(src.error(
                &name.span(),
                format!(
                    "duplicate object name \"{}\" (first used on line {line})",
                    name.get_ref()
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod depth_preset_tests;
#[cfg(test)]
mod tests;
