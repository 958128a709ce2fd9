//! `flexcam render`: load a scene, render it through its projection, write the outputs.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::image_io::{self, ColorEncoding, StagedFile};
use flexcam::render::trilinear::CurveOptions;
use flexcam::render::{Method, RenderOptions, Shading};
use flexcam::scene::{self, Scene};
use flexcam::{Error, Result};

use crate::progress::RenderProgress;
use crate::stats_json::{self, RunFacts};
use crate::OutputTarget;

/// Arguments of `flexcam render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A scene file (.toml) or `builtin:NAME`; the default built-in scene when omitted.
    scene: Option<String>,
    /// The colour image to write (PNG).
    #[arg(short, long, default_value = "flexcam.png")]
    output: PathBuf,
    /// Image width in pixels (overrides the scene file).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene file).
    #[arg(long)]
    height: Option<u32>,
    /// Rendering method: `raycast` (the reference, every projection) or `trilinear`
    /// (rasterisation of trilinear projections).
    #[arg(long, default_value = "raycast")]
    method: String,
    /// How `--method trilinear` follows curved edges: `tessellate`, `slice` or `adaptive`.
    #[arg(long, default_value = "adaptive")]
    curves: String,
    /// Steps of the curve mode: segments per scene edge (tessellate), slices per shape
    /// (slice) or most segments per edge piece (adaptive); defaults 8, 10 and 256.
    #[arg(long, value_name = "N")]
    curve_steps: Option<u32>,
    /// Shading: `flat` (base colours, exact) or `lit` (lights, shadows, reflections).
    #[arg(long, value_enum, default_value_t = ShadingArg::Lit)]
    shading: ShadingArg,
    /// Samples per pixel.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: u32,
    /// Write the depth along each pixel's ray (.exr or .pfm; +inf where nothing is hit).
    #[arg(long, value_name = "FILE")]
    depth: Option<PathBuf>,
    /// Write object ids as a 16-bit grayscale PNG (0 = background).
    #[arg(long, value_name = "FILE")]
    ids: Option<PathBuf>,
    /// Write statistics as one JSON object to FILE, or to standard output with `-`.
    #[arg(long, value_name = "FILE|-")]
    stats: Option<OutputTarget>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum ShadingArg {
    Flat,
    Lit,
}

impl ShadingArg {
    fn shading(self) -> Shading {
        match self {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Lit => Shading::Lit,
        }
    }
    fn name(self) -> &'static str {
        match self {
            ShadingArg::Flat => "flat",
            ShadingArg::Lit => "lit",
        }
    }
}

/// Runs `flexcam render`. Outputs are written only once everything has succeeded.
pub fn run(args: &RenderArgs) -> Result<()> {
    let method = match args.method.parse()? {
        Method::Trilinear(_) => {
            Method::Trilinear(CurveOptions::new(args.curves.parse()?, args.curve_steps)?)
        }
        other => other,
    };
    check_outputs(args)?;

    let source = args
        .scene
        .clone()
        .unwrap_or_else(|| format!("builtin:{}", scene::builtin::DEFAULT));
    let load_start = Instant::now();
    let scene = scene::load(&source)?;
    let load_ms = load_start.elapsed().as_secs_f64() * 1e3;

    let (width, height) = resolution(args, &scene)?;
    let projection = scene
        .projection
        .build(width, height)
        .map_err(|e| with_scene_file(e, &source))?;

    let progress = RenderProgress::new();
    let report = |done: u64, total: u64| progress.update(done, total);
    let options = RenderOptions {
        shading: args.shading.shading(),
        spp: args.spp,
        progress: Some(&report),
        ..RenderOptions::default()
    };
    let render_start = Instant::now();
    let rendered = method.render(&scene, projection.as_ref(), &options);
    let render_ms = render_start.elapsed().as_secs_f64() * 1e3;
    progress.finish();
    let (frame, counters) = rendered?;

    let encoding = match options.shading {
        Shading::Flat => ColorEncoding::Linear,
        Shading::Lit => ColorEncoding::Srgb,
    };
    let mut staged: Vec<StagedFile> =
        vec![image_io::write_color_png(&frame, &args.output, encoding)?];
    if let Some(path) = &args.depth {
        staged.push(image_io::write_depth(&frame, path)?);
    }
    if let Some(path) = &args.ids {
        staged.push(image_io::write_ids_png(&frame, path)?);
    }
    let facts = RunFacts {
        method: method.name(),
        scene: &source,
        projection: projection.kind(),
        shading: args.shading.name(),
        width,
        height,
        spp: args.spp,
        triangles: scene.triangle_count(),
        load_ms,
        render_ms,
    };
    let json = stats_json::to_json(&facts, &counters).to_string();
    if let Some(OutputTarget::File(path)) = &args.stats {
        staged.push(image_io::write_bytes(path, format!("{json}\n").as_bytes())?);
    }
    for file in staged {
        file.commit()?;
    }
    if let Some(OutputTarget::Stdout) = &args.stats {
        println!("{json}");
    }
    Ok(())
}

/// The image size: the scene's, overridden by the flags, validated.
fn resolution(args: &RenderArgs, scene: &Scene) -> Result<(u32, u32)> {
    let width = args.width.unwrap_or(scene.image.width);
    let height = args.height.unwrap_or(scene.image.height);
    scene::file::validate_resolution(width, height)?;
    Ok((width, height))
}

/// Fails before rendering on output paths that could not be written afterwards.
fn check_outputs(args: &RenderArgs) -> Result<()> {
    image_io::check_output_path(&args.output, &["png"])?;
    if let Some(path) = &args.depth {
        image_io::check_output_path(path, &["exr", "pfm"])?;
    }
    if let Some(path) = &args.ids {
        image_io::check_output_path(path, &["png"])?;
    }
    if let Some(OutputTarget::File(path)) = &args.stats {
        image_io::check_output_path(path, &["json", "txt", ""])?;
    }
    let mut paths: Vec<&Path> = vec![&args.output];
    paths.extend(args.depth.as_deref());
    paths.extend(args.ids.as_deref());
    if let Some(OutputTarget::File(path)) = &args.stats {
        paths.push(path);
    }
    for (i, a) in paths.iter().enumerate() {
        if paths[..i].contains(a) {
            return Err(Error::in_file(a, "the same file is given for two outputs"));
        }
    }
    Ok(())
}

/// Names the scene file in an error that has no location yet (built-ins are named as given).
fn with_scene_file(e: Error, source: &str) -> Error {
    e.or_in_file(source)
}
