//! `flexcam compare`: render a scene with a method and with a reference method (the ray
//! caster by default) at the same projection and size, and report how closely they agree
//! (object-id agreement, depth error, the thesis's relative RGB error; see
//! `flexcam::render::compare`). Optional thresholds turn it into a check with an exit status.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::Args;
use flexcam::image_io::{self, ColorEncoding, OutputSet};
use flexcam::render::{self, compare, Comparison, Frame, Method, PreparedScene, RenderOptions};
use flexcam::{Error, Result};
use glam::Vec3;
use serde_json::json;

use super::scene_args::{method_names, MethodTuning, SceneArgs, ShadingArg};

/// Arguments of `flexcam compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The method under test.
    #[arg(long, value_parser = method_names())]
    method: String,
    /// The reference method.
    #[arg(long, default_value = "raycast", value_parser = method_names())]
    reference: String,
    /// Tuning of the method under test (the reference runs with its defaults).
    #[command(flatten)]
    tuning: MethodTuning,
    /// Shading of both renders; `flat` compares base colours, which is what the accuracy
    /// targets are stated for.
    #[arg(long, value_enum, default_value_t = ShadingArg::Flat)]
    shading: ShadingArg,
    /// Samples per pixel of both renders (the same pattern in every method that supports
    /// supersampling): colours averaged, depth and id of the sample nearest the centre.
    /// Overrides the scene's `[image] spp`, whose default is 1.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: Option<u32>,
    /// Write a difference image (PNG): id mismatches red, colour differences amplified 4x.
    #[arg(long, value_name = "FILE")]
    diff: Option<PathBuf>,
    /// Print the report as one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Fail (exit 3) when the id agreement, in percent, is below this.
    #[arg(long, value_name = "PERCENT")]
    min_id_agreement: Option<f64>,
    /// Fail (exit 3) when the relative RGB error is above this.
    #[arg(long, value_name = "ERROR")]
    max_rgb_error: Option<f64>,
}

/// The exit status of a comparison that ran but missed a threshold (`--min-id-agreement`,
/// `--max-rgb-error`), told apart from 1, a comparison that could not run.
pub const THRESHOLD_MISSED: u8 = 3;

/// Runs `flexcam compare`: exit status 0 when the renders compared within the thresholds,
/// [`THRESHOLD_MISSED`] (with the missed threshold on stderr) when they did not, 1 when they
/// could not be compared.
pub fn run(args: &CompareArgs) -> ExitCode {
    match compare_renders(args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(THRESHOLD_MISSED),
        Err(e) => super::fail(&e),
    }
}

/// Renders and compares, writes the report and the outputs; `false` when a threshold was
/// missed (reported on stderr).
fn compare_renders(args: &CompareArgs) -> Result<bool> {
    let method: Method = args.method.parse()?;
    let reference: Method = args.reference.parse()?;
    validate_thresholds(args)?;
    let mut outputs = OutputSet::new();
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let diff = args
        .diff
        .as_deref()
        .map(|path| outputs.output("the diff output", path, &["png"]))
        .transpose()?;
    let loaded = args.scene.load()?;
    super::declare_scene_inputs(&mut outputs, &loaded.scene.inputs)?;
    let prepared = PreparedScene::new(&loaded.scene);
    let spp = args.spp.unwrap_or(loaded.scene.image.spp);
    // The method under test renders as `flexcam render` does (trilinear reflectors
    // composited through their surfaces); the reference renders the scene as it is (a
    // reflector is then the ray caster's exact mirror or glass).
    let reference_options = RenderOptions {
        method: reference,
        composite_reflectors: false,
        shading: args.shading.shading(),
        spp,
        ..RenderOptions::default()
    };
    let options = RenderOptions {
        method,
        composite_reflectors: true,
        subdivision: args.tuning.subdivision(method)?,
        curves: args.tuning.curves(method)?,
        camera_triangles: args.tuning.camera_triangles(method)?,
        ..reference_options
    };
    let mut warnings = Vec::new();
    let mut timed_render = |options: &RenderOptions| {
        let start = Instant::now();
        let rendered = render::render(&prepared, loaded.projection.as_ref(), options)
            .map_err(|e| e.or_in_file(&loaded.source))?;
        warnings.extend(super::scene_args::warning_lines(&rendered.warnings));
        Ok::<_, Error>((rendered.frame, start.elapsed().as_secs_f64() * 1e3))
    };
    let (frame, method_ms) = timed_render(&options)?;
    let (reference_frame, reference_ms) = timed_render(&reference_options)?;
    let result = compare(&frame, &reference_frame)?;

    if let Some(id) = diff {
        let image =
            difference_image(&frame, &reference_frame).map_err(|e| e.or_in_file(&loaded.source))?;
        outputs.stage(id, |tmp| {
            image_io::write_color_png(&image, tmp, ColorEncoding::Linear)
        })?;
    }
    outputs.commit()?;
    let header = Header {
        source: &loaded.source,
        projection: loaded.projection.kind(),
        method,
        reference,
        size: (loaded.width, loaded.height),
        shading: args.shading.name(),
        spp,
        times_ms: (method_ms, reference_ms),
        bvh_builds: prepared.bvh_builds(),
    };
    if args.json {
        super::print_stdout(&format!("{}\n", report_json(&header, &result)))?;
    } else {
        super::print_stdout(&report_text(&header, &result))?;
    }
    if let Err(missed) = check_thresholds(args, &result) {
        eprintln!("flexcam: {missed}");
        return Ok(false);
    }
    // Warnings only once the command has succeeded: a failing command prints one line.
    super::scene_args::print_lines(&loaded.source, &warnings);
    Ok(true)
}

/// What was compared, for the report.
struct Header<'a> {
    source: &'a str,
    projection: &'a str,
    method: Method,
    reference: Method,
    size: (u32, u32),
    shading: &'a str,
    spp: u32,
    /// Render times of the method and the reference, in milliseconds.
    times_ms: (f64, f64),
    /// BVH builds of the scene prepared once for both renders.
    bvh_builds: u64,
}

fn report_text(h: &Header, c: &Comparison) -> String {
    format!(
        "{} ({}), {} vs {}, {}x{}, {} shading, {} spp\n\
         id agreement        {:.3} %\n\
         relative RGB error  {:.5}\n\
         depth error         max {:.3e}, mean {:.3e} (relative, over {} pixels on the same object)\n\
         render time         {:.1} ms vs {:.1} ms\n",
        h.source,
        h.projection,
        h.method,
        h.reference,
        h.size.0,
        h.size.1,
        h.shading,
        h.spp,
        100.0 * c.id_agreement,
        c.relative_rgb_error,
        c.depth_max,
        c.depth_mean,
        c.depth_pixels,
        h.times_ms.0,
        h.times_ms.1,
    )
}

fn report_json(h: &Header, c: &Comparison) -> serde_json::Value {
    // Non-finite errors (a black reference) are not JSON numbers: they become null.
    let number = |v: f64| serde_json::Number::from_f64(v).map_or(json!(null), |n| json!(n));
    json!({
        "scene": h.source,
        "projection": h.projection,
        "method": h.method.name(),
        "reference": h.reference.name(),
        "width": h.size.0,
        "height": h.size.1,
        "shading": h.shading,
        "spp": h.spp,
        "pixels": c.pixels,
        "id_agreement": number(c.id_agreement),
        "relative_rgb_error": number(c.relative_rgb_error),
        "depth_pixels": c.depth_pixels,
        "depth_max": number(c.depth_max),
        "depth_mean": number(c.depth_mean),
        "method_ms": number(h.times_ms.0),
        "reference_ms": number(h.times_ms.1),
        "bvh_builds": h.bvh_builds,
    })
}

/// Errors: a `--min-id-agreement` or `--max-rgb-error` that is not a finite number.
/// Checked before rendering: a NaN threshold would otherwise pass every comparison (every
/// test against NaN is false), a check that cannot fail. Finite thresholds out of reach
/// (above 100 %, a negative error) are kept: they fail with the measured value.
fn validate_thresholds(args: &CompareArgs) -> Result<()> {
    for (flag, value) in [
        ("--min-id-agreement", args.min_id_agreement),
        ("--max-rgb-error", args.max_rgb_error),
    ] {
        if let Some(v) = value.filter(|v| !v.is_finite()) {
            return Err(Error::new(format!(
                "{flag} must be a finite number, got {v}"
            )));
        }
    }
    Ok(())
}

/// The thresholds given on the command line, as one error line naming the first one missed.
fn check_thresholds(args: &CompareArgs, c: &Comparison) -> Result<()> {
    if let Some(min) = args.min_id_agreement {
        let got = 100.0 * c.id_agreement;
        if got < min {
            return Err(Error::new(format!(
                "id agreement {got:.3} % is below the required {min} %"
            )));
        }
    }
    if let Some(max) = args.max_rgb_error {
        // A NaN error fails too.
        if c.relative_rgb_error.is_nan() || c.relative_rgb_error > max {
            return Err(Error::new(format!(
                "relative RGB error {:.5} is above the allowed {max}",
                c.relative_rgb_error
            )));
        }
    }
    Ok(())
}

/// Red where the object ids differ; elsewhere the colour difference amplified 4x. Fails when
/// its memory cannot be had.
fn difference_image(frame: &Frame, reference: &Frame) -> Result<Frame> {
    let mut diff = Frame::try_new(frame.width, frame.height, Vec3::ZERO)?;
    for (i, out) in diff.color.iter_mut().enumerate() {
        *out = if frame.ids[i] != reference.ids[i] {
            Vec3::new(1.0, 0.0, 0.0)
        } else {
            ((frame.color[i] - reference.color[i]).abs() * 4.0).min(Vec3::ONE)
        };
    }
    Ok(diff)
}
