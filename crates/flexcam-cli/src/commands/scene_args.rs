//! What `render`, `compare` and `reproject` share: the scene argument and its overrides,
//! shading and the methods' tuning options, turned into the library's load and render
//! options, and the warnings printed on stderr.

use clap::builder::PossibleValuesParser;
use clap::{Args, ValueEnum};
use flexcam::render::{
    CameraTriangleBound, CameraTriangleOptions, CurveMode, CurveOptions, Method, RenderWarning,
    Shading, Subdivision, TransitionShading,
};
use flexcam::scene::file::Definition;
use flexcam::scene::{self, LoadedScene, Overrides};
use flexcam::{Error, Result};

/// The scene to render and its image size.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// A scene file (.toml), `builtin:NAME`, or a model file (.obj, .gltf, .glb, .ply) seen
    /// by its default scene (its first glTF camera, or a camera that frames it, and one
    /// light); the default built-in scene when omitted.
    pub scene: Option<String>,
    /// The glTF camera to view a glTF / GLB model given as SCENE through: its index in the
    /// file's `cameras` (from 0), or the camera's or its node's name. Default: the model's
    /// camera of lowest index, or a camera that frames the model when it has none.
    #[arg(long, value_name = "N|NAME")]
    pub camera: Option<String>,
    /// Image width in pixels (overrides the scene file; alone, it keeps the scene's aspect
    /// ratio).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene file; alone, it keeps the scene's aspect
    /// ratio).
    #[arg(long)]
    pub height: Option<u32>,
    /// The local perspective edit of a shape-defined panorama (or the cubic, rounded_cubic,
    /// cylindrical and equirectangular presets, and the cylindrical and equirectangular
    /// cameras, as those presets), as the scene key `perspective_rect`: the rectangle of the
    /// image domain (u right, v up, in [0, 1]; U0 > U1 across the seam) becomes a perspective
    /// view. Applied after the scene file's own rectangle, if any.
    #[arg(
        long,
        value_name = "U0,V0,U1,V1",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub perspective_rect: Option<Vec<f64>>,
    #[command(flatten)]
    pub define: DefineArgs,
    #[command(flatten, next_help_heading = "Resources")]
    pub memory: MemoryArgs,
    #[command(flatten, next_help_heading = "Resources")]
    pub threads: ThreadsArg,
}

/// The names `--method` accepts, listed in `--help` (clap refuses any other).
pub fn method_names() -> PossibleValuesParser {
    PossibleValuesParser::new(Method::ALL.map(|(name, _)| name))
}

/// Scene keys set on the command line.
#[derive(Args, Debug)]
pub struct DefineArgs {
    /// Set a scene key as if the scene file said so (repeatable, applied in order): KEY is a
    /// dotted path (`projection.fov`, `image.width`; `object.NAME.KEY` or `object.N.KEY`, N
    /// from 0, for a table of `[[object]]`), VALUE a TOML value (a bare word is a string),
    /// checked as the file's own would be. E.g. `-D projection.fov=90 -D
    /// object.floor.color=[1,0,0]`.
    #[arg(short = 'D', long = "define", value_name = "KEY=VALUE")]
    pub definitions: Vec<Definition>,
}

/// The number of threads a rendering command renders with.
#[derive(Args, Debug)]
pub struct ThreadsArg {
    /// Render with N threads (a pool of N workers; the default is one per core). Images do
    /// not depend on it.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
}

impl ThreadsArg {
    /// Makes the process's rayon pool N threads if `--threads` was given. Call it before
    /// anything runs on the pool (it is built once).
    pub fn apply(&self) -> Result<()> {
        match self.threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(usize::from(n))
                .build_global()
                .map_err(|e| Error::new(format!("--threads {n}: {e}"))),
            None => Ok(()),
        }
    }
}

/// The memory budget of a rendering command.
#[derive(Args, Debug)]
pub struct MemoryArgs {
    /// The memory budget (e.g. 8G, 512MiB, 1.5GB): a scene whose estimated memory
    /// (triangles, image) exceeds it is refused before it is built, with the estimate. The
    /// default is three quarters of the memory this process may use.
    #[arg(long, value_name = "SIZE", value_parser = scene::budget::parse_size)]
    pub max_memory: Option<u64>,
}

impl MemoryArgs {
    /// Sets the process's memory budget if `--max-memory` was given.
    pub fn apply(&self) {
        if let Some(bytes) = self.max_memory {
            scene::budget::set_max_memory(bytes);
        }
    }
}

impl SceneArgs {
    /// Loads the scene with the size and perspective-rect overrides and builds the
    /// projection ([`scene::load_with`]). Errors name the scene file.
    pub fn load(&self) -> Result<LoadedScene> {
        let source = self
            .scene
            .clone()
            .unwrap_or_else(|| format!("builtin:{}", scene::builtin::DEFAULT));
        let perspective_rect = match &self.perspective_rect {
            Some(rect) => Some(<[f64; 4]>::try_from(rect.as_slice()).map_err(|_| {
                Error::new(format!(
                    "--perspective-rect: needs 4 numbers, got {}",
                    rect.len()
                ))
            })?),
            None => None,
        };
        self.memory.apply();
        self.threads.apply()?;
        let overrides = Overrides {
            width: self.width,
            height: self.height,
            perspective_rect,
            definitions: self.define.definitions.clone(),
            camera: self.camera.clone(),
        };
        scene::load_with(&source, &overrides)
    }
}

/// Prints the warnings of a scene's load on stderr (the command goes on).
pub fn print_warnings(loaded: &LoadedScene) {
    print_lines(&loaded.source, &loaded.build_report.warnings);
}

/// Prints warnings about scene `source` on stderr, one line each (the command goes on).
pub fn print_lines(source: &str, warnings: &[String]) {
    for warning in warnings {
        eprintln!("flexcam: warning: {source}: {warning}");
    }
}

/// The lines of render warnings `warnings`, each once, in the order first reported.
pub fn warning_lines<'a>(warnings: impl IntoIterator<Item = &'a RenderWarning>) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for line in warnings.into_iter().map(RenderWarning::to_string) {
        if !lines.contains(&line) {
            lines.push(line);
        }
    }
    lines
}

/// `--shading` on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ShadingArg {
    Flat,
    Lit,
    /// Displaced objects coloured by the transition system's method per pixel.
    Transitions,
    /// Displaced objects shaded by the transition system (BRDF, bump, displacement).
    TransitionLit,
}

impl ShadingArg {
    pub fn shading(self) -> Shading {
        match self {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Lit => Shading::Lit,
            ShadingArg::Transitions => {
                Shading::Transitions(TransitionShading::with_default_d(true))
            }
            ShadingArg::TransitionLit => {
                Shading::Transitions(TransitionShading::with_default_d(false))
            }
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ShadingArg::Flat => "flat",
            ShadingArg::Lit => "lit",
            ShadingArg::Transitions => "transitions",
            ShadingArg::TransitionLit => "transition-lit",
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
    #[arg(long, value_name = "MODE", value_parser = PossibleValuesParser::new(CurveMode::ALL.map(|(name, _)| name)))]
    curves: Option<String>,
    /// Method trilinear: steps of the curve mode: segments per scene edge (tessellate),
    /// slices per shape (slice) or most segments per edge piece (adaptive); defaults 8, 10
    /// and 256.
    #[arg(long, value_name = "N")]
    curve_steps: Option<u32>,
    /// Method camera-triangles: the bounding region of each scene triangle in each camera
    /// triangle, `paper` (the bounding triangle of Hou et al. 2006) or `tight` (the default).
    #[arg(long, value_name = "BOUND")]
    bound: Option<String>,
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

    /// The options of method camera-triangles from `--bound`; an error when it is given to
    /// another method.
    pub fn camera_triangles(&self, method: Method) -> Result<CameraTriangleOptions> {
        if method != Method::CameraTriangles && self.bound.is_some() {
            return Err(Error::new(format!(
                "--bound applies to --method camera-triangles, not {method}"
            )));
        }
        Ok(CameraTriangleOptions {
            bound: match &self.bound {
                Some(name) => name.parse()?,
                None => CameraTriangleBound::default(),
            },
            ..CameraTriangleOptions::default()
        })
    }
}
