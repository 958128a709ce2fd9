//! What `render` and `compare` share: the scene argument, the size overrides, shading and the
//! methods' tuning options, and loading a scene and building its projection from them.

use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::projection::flexible::panorama::edit_source;
use flexcam::projection::flexible::FlexibleSpec;
use flexcam::projection::{BuildReport, Projection, ProjectionSpec};
use flexcam::render::raster::Subdivision;
use flexcam::render::trilinear::CurveOptions;
use flexcam::render::{Method, Shading};
use flexcam::scene::{self, Scene};
use flexcam::{Error, Result};

/// The scene to render and its image size.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// A scene file (.toml) or `builtin:NAME`; the default built-in scene when omitted.
    pub scene: Option<String>,
    /// Image width in pixels (overrides the scene file).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene file).
    #[arg(long)]
    pub height: Option<u32>,
    /// The local perspective edit of a shape-defined panorama (or the cubic, rounded_cubic,
    /// cylindrical and equirectangular presets), as the scene key
    /// `perspective_rect`: the rectangle of the
    /// image domain (u right, v up, in [0, 1]; U0 > U1 across the seam) becomes a perspective
    /// view. Applied after the scene file's own rectangle, if any.
    #[arg(
        long,
        value_name = "U0,V0,U1,V1",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub perspective_rect: Option<Vec<f64>>,
}

/// A loaded scene with its projection bound to the image size.
pub struct LoadedScene {
    /// The scene as named on the command line (`builtin:NAME` for built-ins).
    pub source: String,
    pub scene: Scene,
    pub projection: Box<dyn Projection>,
    /// What building the projection reported (a fitted grid's residual and warnings).
    pub build_report: BuildReport,
    pub width: u32,
    pub height: u32,
    /// Time spent loading and building, in milliseconds.
    pub load_ms: f64,
}

impl SceneArgs {
    /// Loads the scene, applies the size overrides and builds the projection. Errors name the
    /// scene file.
    pub fn load(&self) -> Result<LoadedScene> {
        let source = self
            .scene
            .clone()
            .unwrap_or_else(|| format!("builtin:{}", scene::builtin::DEFAULT));
        let start = Instant::now();
        let mut scene = scene::load(&source)?;
        if let Some(rect) = &self.perspective_rect {
            scene.projection = perspective_rect(&scene.projection, rect)?;
        }
        let width = self.width.unwrap_or(scene.image.width);
        let height = self.height.unwrap_or(scene.image.height);
        scene::file::validate_resolution(width, height)?;
        let (projection, build_report) =
            flexcam::calibrate::build(&scene.projection, width, height)
                .map_err(|e: Error| e.or_in_file(&source))?;
        Ok(LoadedScene {
            source,
            scene,
            projection,
            build_report,
            width,
            height,
            load_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }
}

/// `projection` with the perspective edit of `--perspective-rect` (clap gives four numbers).
fn perspective_rect(projection: &ProjectionSpec, rect: &[f64]) -> Result<ProjectionSpec> {
    let refuse = |why: String| Error::new(format!("--perspective-rect: {why}"));
    let rect: [f64; 4] = rect
        .try_into()
        .map_err(|_| refuse(format!("needs 4 numbers, got {}", rect.len())))?;
    let ProjectionSpec::Flexible(spec) = projection else {
        return Err(refuse(format!(
            "needs a flexible shape-defined panorama, the scene's projection is {}",
            projection.kind()
        )));
    };
    let source = edit_source(&spec.source, rect).map_err(|e| refuse(e.message))?;
    Ok(ProjectionSpec::Flexible(Box::new(FlexibleSpec {
        source,
        reparam: spec.reparam,
    })))
}

/// `--shading` on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ShadingArg {
    Flat,
    Lit,
}

impl ShadingArg {
    pub fn shading(self) -> Shading {
        match self {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Lit => Shading::Lit,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ShadingArg::Flat => "flat",
            ShadingArg::Lit => "lit",
        }
    }
}

/// The options that tune one rendering method (each refused with any other method).
#[derive(Args, Debug)]
pub struct MethodTuning {
    /// Method raster: cut every triangle into N x N pieces (uniform subdivision; without
    /// --raster-tolerance there is then no adaptive step).
    #[arg(long, value_name = "N")]
    subdiv: Option<u32>,
    /// Method raster: halve edges whose projected midpoint is more than PX pixels off the
    /// straight line (adaptive subdivision, the default, with 0.5; at least 0.001).
    #[arg(long, value_name = "PX")]
    raster_tolerance: Option<f64>,
    /// Method trilinear: how curved edges are followed, `tessellate`, `slice` or `adaptive`
    /// (the default).
    #[arg(long, value_name = "MODE")]
    curves: Option<String>,
    /// Method trilinear: steps of the curve mode: segments per scene edge (tessellate),
    /// slices per shape (slice) or most segments per edge piece (adaptive); defaults 8, 10
    /// and 256.
    #[arg(long, value_name = "N")]
    curve_steps: Option<u32>,
}

impl MethodTuning {
    /// The subdivision of method raster from `--subdiv` and `--raster-tolerance`; an error
    /// when either is given to another method.
    pub fn subdivision(&self, method: Method) -> Result<Subdivision> {
        if method != Method::Raster && (self.subdiv.is_some() || self.raster_tolerance.is_some()) {
            return Err(Error::new(format!(
                "--subdiv and --raster-tolerance apply to --method raster, not {method}"
            )));
        }
        let subdivision = match (self.subdiv, self.raster_tolerance) {
            (None, None) => Subdivision::default(),
            (Some(n), None) => Subdivision::uniform(n),
            (None, Some(tolerance)) => Subdivision::adaptive(tolerance),
            (Some(n), Some(tolerance)) => Subdivision {
                uniform: n,
                tolerance: Some(tolerance),
            },
        };
        subdivision.validate()?;
        Ok(subdivision)
    }

    /// The curve handling of method trilinear from `--curves` and `--curve-steps`; an error
    /// when either is given to another method.
    pub fn curves(&self, method: Method) -> Result<CurveOptions> {
        if method != Method::Trilinear && (self.curves.is_some() || self.curve_steps.is_some()) {
            return Err(Error::new(format!(
                "--curves and --curve-steps apply to --method trilinear, not {method}"
            )));
        }
        let mode = match &self.curves {
            Some(name) => name.parse()?,
            None => CurveOptions::ADAPTIVE.mode,
        };
        CurveOptions::new(mode, self.curve_steps)
    }
}
