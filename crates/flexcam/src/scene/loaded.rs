//! Loading a scene with the caller's overrides (image size, the perspective edit of a
//! panorama, ...) and building its projection: what a command needs before rendering, with
//! the projection build's report (counters, warnings) for the caller to print or ignore.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::projection::flexible::panorama::edit_source;
use crate::projection::flexible::{FlexibleSpec, Preset, PresetSpec, VolumeSource};
use crate::projection::{BuildReport, CameraFrame, Projection, ProjectionSpec};
use crate::scene::file::Definition;
use crate::scene::{self, budget, Scene};

/// What a caller changes in a scene file's settings. `None` keeps the file's value.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// Image width in pixels (alone, the height follows the scene's aspect ratio:
    /// [`scene::ImageSettings::size_with`]).
    pub width: Option<u32>,
    /// Image height in pixels (alone, the width follows the scene's aspect ratio).
    pub height: Option<u32>,
    /// The local perspective edit of a shape-defined panorama (the scene key
    /// `perspective_rect`: `[u0, v0, u1, v1]` of the image domain), applied after the scene
    /// file's own rectangle, if any.
    pub perspective_rect: Option<[f64; 4]>,
    /// Scene keys set as if the file said so (`-D KEY=VALUE`), applied in order before the
    /// file is parsed.
    pub definitions: Vec<Definition>,
    /// The glTF camera of a model given as the scene to view it through (an index in the
    /// file's `cameras`, a camera's or its node's name; [`scene::ModelRequest`]).
    pub camera: Option<String>,
}

/// A scene loaded with overrides and its projection built at the image size.
pub struct LoadedScene {
    /// The scene as named by the caller (`builtin:NAME` for built-ins).
    pub source: String,
    /// The scene with the overrides applied.
    pub scene: Scene,
    /// The scene's projection, built at `width` x `height`.
    pub projection: Box<dyn Projection>,
    /// Image width in pixels: the override, or the scene's.
    pub width: u32,
    /// Image height in pixels: the override, or the scene's.
    pub height: u32,
    /// What building the projection reported: counters for `--stats` (a fitted grid's
    /// residual, ...) and warnings (a fitted grid's doubtful nodes).
    pub build_report: BuildReport,
    /// Time spent loading and building, in milliseconds.
    pub load_ms: f64,
}

/// Loads `source` (a scene file or `builtin:NAME`), applies `overrides` and builds the
/// projection. Errors name the scene file; an override that does not apply names the
/// command-line flag that sets it (`--perspective-rect`), the spelling users see.
///
/// ```
/// use flexcam::scene::{self, Overrides};
///
/// // A built-in scene at a size of our own; a scene file's path works the same way.
/// let overrides = Overrides { width: Some(64), ..Overrides::default() };
/// let loaded = scene::load_with("builtin:cube-floor", &overrides)?;
/// // The height follows the scene's aspect ratio (square), and the projection is built at
/// // that size.
/// assert_eq!((loaded.width, loaded.height), (64, 64));
/// assert_eq!(loaded.projection.resolution(), (64, 64));
/// assert_eq!(loaded.projection.kind(), "perspective");
/// # Ok::<(), flexcam::Error>(())
/// ```
pub fn load_with(source: &str, overrides: &Overrides) -> Result<LoadedScene> {
    let start = Instant::now();
    let request = scene::ModelRequest {
        width: overrides.width,
        height: overrides.height,
        camera: overrides.camera.as_deref(),
    };
    let mut scene = scene::load_requested(source, &overrides.definitions, &request)?;
    if let Some(rect) = overrides.perspective_rect {
        scene.projection = perspective_rect(&scene.projection, rect)?;
    }
    let (width, height) = scene.image.size_with(overrides.width, overrides.height);
    scene::validate_resolution(width, height)?;
    check_budget(&scene, width, height, 0).map_err(|e| e.or_in_file(source))?;
    let (projection, build_report) = crate::calibrate::build(&scene.projection, width, height)
        .map_err(|e: Error| e.or_in_file(source))?;
    Ok(LoadedScene {
        source: source.to_string(),
        scene,
        projection,
        width,
        height,
        build_report,
        load_ms: start.elapsed().as_secs_f64() * 1e3,
    })
}

/// Fails when the scene's triangles and a `width` x `height` image need more memory than
/// the budget ([`budget::check`]), before any frame is allocated. `extra_bytes` counts what
/// the command holds besides (the frames of a GIF).
pub fn check_budget(scene: &Scene, width: u32, height: u32, extra_bytes: u64) -> Result<()> {
    let triangles = scene.triangle_count() as u64;
    let pixels = u64::from(width) * u64::from(height);
    let estimate = (triangles.saturating_mul(budget::BYTES_PER_TRIANGLE))
        .saturating_add(pixels.saturating_mul(budget::BYTES_PER_PIXEL))
        .saturating_add(extra_bytes);
    budget::check(
        estimate,
        &format!("{triangles} triangles, a {width} x {height} image"),
    )
}

/// `projection` with the perspective edit `rect`: a flexible projection's volume edited
/// ([`edit_source`]), or a `cylindrical` or `equirectangular` camera as the flexible preset of
/// the same name (the same rays, out to the preset's default far clip) edited. Errors: any
/// other projection, and those of [`edit_source`].
fn perspective_rect(projection: &ProjectionSpec, rect: [f64; 4]) -> Result<ProjectionSpec> {
    let refuse = |why: String| Error::new(format!("--perspective-rect: {why}"));
    let as_preset = |preset: Preset, frame: &CameraFrame| {
        VolumeSource::Preset(PresetSpec {
            preset,
            frame: *frame,
            clip: None,
        })
    };
    let (source, reparam) = match projection {
        ProjectionSpec::Flexible(spec) => (spec.source.clone(), spec.reparam.clone()),
        ProjectionSpec::Cylindrical {
            frame,
            h_fov,
            v_fov,
        } => (
            as_preset(
                Preset::Cylindrical {
                    h_fov: *h_fov,
                    v_fov: *v_fov,
                },
                frame,
            ),
            None,
        ),
        ProjectionSpec::Equirectangular {
            frame,
            h_fov,
            v_fov,
        } => (
            as_preset(
                Preset::Equirectangular {
                    h_fov: *h_fov,
                    v_fov: *v_fov,
                },
                frame,
            ),
            None,
        ),
        other => {
            return Err(refuse(format!(
                "needs a flexible shape-defined panorama or a cylindrical or equirectangular \
                 camera, the scene's projection is {}",
                other.kind()
            )))
        }
    };
    let source = edit_source(&source, rect).map_err(|e| refuse(e.message))?;
    Ok(ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source,
        reparam,
    })))
}
