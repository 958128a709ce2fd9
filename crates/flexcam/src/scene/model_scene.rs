//! A model file (OBJ, glTF / GLB, PLY) given where a scene is expected: the scene flexcam
//! makes for it, and the scene-file tables of a model's glTF cameras.
//!
//! The scene is scene-file text, written here and parsed as any scene file is, so that
//! `-D KEY=VALUE` edits it as it edits a file and the same checks apply:
//!
//! ```toml
//! [image]
//! width = 800               # 800 x 600, or the glTF camera's aspect ratio 800 wide
//! height = 600
//! [projection]              # the model's first glTF camera, or the framing camera
//! type = "perspective"      # (module model_view)
//! position = [...]
//! look_at = [...]
//! up = [...]
//! fov = 50.0
//! [[object]]
//! name = "model"
//! shape = "mesh"
//! file = "MODEL"            # the model, with its own materials
//! [[light]]
//! type = "directional"      # module model_view's key light
//! direction = [...]
//! ```
//!
//! The camera is made for the final image size (the `[image]` size with the definitions and
//! the command's `--width` / `--height`), so the framing and a glTF camera's vertical field
//! hold at any size. The model is read once: the parse takes the model already read.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use glam::DVec3;
use toml_edit::{value, ArrayOfTables, DocumentMut, Item, Table};

use super::file::{self, edit::float_array, Definition};
use super::loaders::{load_model, Model, ModelCamera, MODEL_EXTENSIONS};
use super::model_view::{camera_view, framing, key_light, triangle_bounds, Lens, View};
use super::{budget, Scene};
use crate::error::{Error, Result};
use crate::projection::flexible::Animation;

/// The width of a model's default scene, pixels; its height is 600, or follows the aspect
/// ratio of the glTF camera that fixes one (800 the longer side then).
pub const DEFAULT_SIDE: u32 = 800;

/// The name of the model's object in its default scene (`-D object.model.color=...`).
pub const OBJECT_NAME: &str = "model";

/// What a command asks of a model's default scene besides the `-D` definitions: the
/// image size (`--width`, `--height`; `None` keeps the scene's) and the glTF camera to
/// view it through (`--camera`: an index in the file's `cameras`, a camera's or a camera
/// node's name).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ModelRequest<'a> {
    /// `--width`.
    pub width: Option<u32>,
    /// `--height`.
    pub height: Option<u32>,
    /// `--camera`.
    pub camera: Option<&'a str>,
}

impl ModelRequest<'_> {
    /// Fails when the request names a camera of `source`, which is not a model file.
    pub fn refuse_camera(&self, source: &str) -> Result<()> {
        match self.camera {
            Some(key) => Err(Error::new(format!(
                "--camera {key}: selects a camera of a glTF / GLB model given as the scene; \
                 {source} is not a model file"
            ))),
            None => Ok(()),
        }
    }
}

/// Whether `path` names a model file (by its extension: [`MODEL_EXTENSIONS`], any case).
pub fn is_model_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| MODEL_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The default scene of the model file at `path`, with `definitions` written into it and
/// the `request`'s size and camera. Errors name `path`; an error in the scene's text (a
/// definition that makes it invalid) says `default scene:`. A model without triangles has
/// nothing to frame: an error.
pub fn load(
    path: &Path,
    definitions: &[Definition],
    request: &ModelRequest,
) -> Result<(Scene, Option<Animation>)> {
    load_with_text(path, definitions, request).map(|(_, scene, animation)| (scene, animation))
}

/// [`load`], also giving the default scene's text (before `definitions`): what `flexcam
/// view` edits and saves as a new scene file. The text names the model by its file name,
/// relative to [`text_path`].
pub fn load_with_text(
    path: &Path,
    definitions: &[Definition],
    request: &ModelRequest,
) -> Result<(String, Scene, Option<Animation>)> {
    let in_model = |e: Error| Error::in_file(path, e.message);
    budget::check_model_file(path, 0).map_err(in_model)?;
    let model = load_model(path)?;
    let camera = chosen_camera(&model, request.camera).map_err(in_model)?;
    let bounds = triangle_bounds(model.parts.iter().map(|p| &p.mesh))
        .ok_or_else(|| Error::in_file(path, "the model has no triangles to frame"))?;
    let centre = (bounds[0] + bounds[1]) / 2.0;
    let view_for = |width: u32, height: u32| match camera {
        Some(camera) => camera_view(camera, width, height, centre),
        None => framing(bounds, f64::from(width) / f64::from(height)),
    };
    let text_path = text_path(path);
    let in_text = |e: Error| {
        if e.location.as_ref().is_some_and(|at| at.file == text_path) {
            Error::in_file(path, format!("default scene: {}", e.message))
        } else {
            e
        }
    };
    let own = own_size(camera);
    let own_text = scene_text(path, own, &view_for(own.0, own.1).map_err(in_model)?);
    let image = file::image_defined(&own_text, &text_path, definitions).map_err(in_text)?;
    let (width, height) = image.size_with(request.width, request.height);
    file::validate_resolution(width, height).map_err(in_model)?;
    let text = scene_text(path, own, &view_for(width, height).map_err(in_model)?);
    let (scene, animation) =
        file::parse_defined_with_model(&text, &text_path, definitions, Some(model))
            .map_err(in_text)?;
    Ok((text, scene, animation))
}

/// The camera a model is viewed through: the one `key` names, or by default the model's
/// camera of the lowest index (placed by its first node), or none (framing).
fn chosen_camera<'m>(model: &'m Model, key: Option<&str>) -> Result<Option<&'m ModelCamera>> {
    let Some(key) = key else {
        return Ok(model.cameras.iter().min_by_key(|c| c.index));
    };
    if model.cameras.is_empty() {
        return Err(Error::new(format!(
            "--camera {key}: the model places no camera (glTF and GLB files can)"
        )));
    }
    model
        .cameras
        .iter()
        .find(|c| c.is_named(key))
        .map(Some)
        .ok_or_else(|| {
            let known: Vec<String> = model.cameras.iter().map(ModelCamera::label).collect();
            Error::new(format!(
                "--camera {key}: no camera of that index or name; the model's: {}",
                known.join(", ")
            ))
        })
}

/// The image size of a model's scene: [`DEFAULT_SIDE`] x 600, or the aspect ratio `camera`
/// fixes with [`DEFAULT_SIDE`] its longer side (the other at least 1 pixel).
fn own_size(camera: Option<&ModelCamera>) -> (u32, u32) {
    let side = f64::from(DEFAULT_SIDE);
    let other = |x: f64| x.round().max(1.0) as u32;
    match camera.and_then(ModelCamera::fixed_aspect) {
        Some(a) if a >= 1.0 => (DEFAULT_SIDE, other(side / a)),
        Some(a) => (other(side * a), DEFAULT_SIDE),
        None => (DEFAULT_SIDE, 600),
    }
}

/// The name the scene text is parsed under: beside the model, so that its relative `file`
/// resolves to the model, and apart from it, so that an error in the text is told from an
/// error in the model file.
pub fn text_path(model: &Path) -> PathBuf {
    let name = model
        .file_name()
        .map_or_else(|| "model".into(), |n| n.to_string_lossy().into_owned());
    model.with_file_name(format!("{name} (default scene)"))
}

/// The scene text of the model at `path` seen by `view` in a `width` x `height` image.
fn scene_text(path: &Path, (width, height): (u32, u32), view: &View) -> String {
    let mut document = DocumentMut::new();
    let mut image = Table::new();
    image.insert("width", value(i64::from(width)));
    image.insert("height", value(i64::from(height)));
    document.insert("image", Item::Table(image));
    document.insert("projection", Item::Table(projection_table(view)));
    let file = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let mut object = Table::new();
    object.insert("name", value(OBJECT_NAME));
    object.insert("shape", value("mesh"));
    object.insert("file", value(file));
    let mut light = Table::new();
    light.insert("type", value("directional"));
    light.insert(
        "direction",
        value(float_array(&key_light(&view.frame).to_array())),
    );
    for (key, table) in [("object", object), ("light", light)] {
        let mut array = ArrayOfTables::new();
        array.push(table);
        document.insert(key, Item::ArrayOfTables(array));
    }
    document.to_string()
}

/// The `[projection]` table of `view`.
fn projection_table(view: &View) -> Table {
    let mut table = Table::new();
    let (kind, key, size) = match view.lens {
        Lens::Perspective { fov } => ("perspective", "fov", fov),
        Lens::Orthographic { width } => ("orthographic", "width", width),
    };
    table.insert("type", value(kind));
    let frame = &view.frame;
    for (name, v) in [
        ("position", frame.position),
        ("look_at", frame.look_at),
        ("up", frame.up),
    ] {
        table.insert(name, value(float_array(&v.to_array())));
    }
    table.insert(key, value(size));
    table
}

/// The scene-file tables `[camera_N]` of the glTF cameras of `model` (N the camera's index,
/// tables in the model's order; a camera placed by several nodes has one table per node,
/// `[camera_N_node_M]`), each
/// viewing an image of the size [`load`] would make (the camera's aspect ratio, or 800 x
/// 600), `look_at` ahead at the model's centre's distance. `source` names the model in the
/// comments. Errors: a model without cameras, a camera whose lens makes no image.
pub fn camera_tables(model: &Model, source: &str) -> Result<String> {
    if model.cameras.is_empty() {
        return Err(Error::new(
            "the model places no camera (a glTF camera placed by a node of its scene)",
        ));
    }
    let centre = triangle_bounds(model.parts.iter().map(|p| &p.mesh))
        .map_or(DVec3::ZERO, |[lo, hi]| (lo + hi) / 2.0);
    let mut out = format!(
        "# Cameras of {source}, one table per camera: rename a table to [projection] in a\n\
         # scene whose [image] has the size given above it.\n"
    );
    for camera in &model.cameras {
        let (width, height) = own_size(Some(camera));
        let view = camera_view(camera, width, height, centre)?;
        let placements = model.cameras.iter().filter(|c| c.index == camera.index);
        let name = match placements.count() {
            1 => format!("camera_{}", camera.index),
            _ => format!("camera_{}_node_{}", camera.index, camera.node),
        };
        let mut document = DocumentMut::new();
        document.insert(&name, {
            let mut table = projection_table(&view);
            table.decor_mut().set_prefix(format!(
                "\n# glTF {} (node {}): for a {width} x {height} image\n",
                camera.label(),
                camera.node
            ));
            Item::Table(table)
        });
        let _ = write!(out, "{document}");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_files_are_told_by_extension() {
        for name in ["a.obj", "dir/b.GLB", "c.gltf", "d.Ply"] {
            assert!(is_model_file(Path::new(name)), "{name}");
        }
        for name in ["a.toml", "obj", "a.stl", "builtin:cube-floor"] {
            assert!(!is_model_file(Path::new(name)), "{name}");
        }
    }

    #[test]
    fn the_text_is_parsed_beside_the_model() {
        assert_eq!(
            text_path(Path::new("dir/m.obj")),
            Path::new("dir/m.obj (default scene)")
        );
        assert_eq!(
            text_path(Path::new("dir/m.obj")).parent(),
            Some(Path::new("dir"))
        );
    }

    /// The own size follows a camera's fixed aspect ratio, 800 its longer side; degenerate
    /// ratios keep the other side at 1 pixel.
    #[test]
    fn own_sizes() {
        use crate::scene::loaders::CameraLens;
        let with = |lens| ModelCamera {
            index: 0,
            name: None,
            node: 0,
            node_name: None,
            lens,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let perspective = |aspect_ratio| {
            with(CameraLens::Perspective {
                yfov: 1.0,
                aspect_ratio,
            })
        };
        assert_eq!(own_size(None), (800, 600));
        assert_eq!(own_size(Some(&perspective(None))), (800, 600));
        assert_eq!(own_size(Some(&perspective(Some(1.5)))), (800, 533));
        assert_eq!(own_size(Some(&perspective(Some(0.5)))), (400, 800));
        assert_eq!(own_size(Some(&perspective(Some(1e-9)))), (1, 800));
        let ortho = with(CameraLens::Orthographic {
            xmag: 4.0,
            ymag: 1.0,
        });
        assert_eq!(own_size(Some(&ortho)), (800, 200));
    }
}
