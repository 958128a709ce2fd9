//! `flexcam animate`: render every frame of a scene's `[animation]` (a keyframed flexible
//! camera, objects that move along their `orbit`, or both) to a numbered PNG sequence and/or
//! an animated GIF. Nothing is written unless every frame renders.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use flexcam::image_io::{self, ColorEncoding, ColorFormat, GifFrames, OutputSet, PngBits};
use flexcam::projection::ProjectionSpec;
use flexcam::render::{self, Counter, Method, Outputs, PreparedScene, RenderOptions, Stats};
use flexcam::scene;
use flexcam::{Error, Result};

use super::frame_list;
use super::scene_args::{
    method_names, print_lines, warning_lines, DefineArgs, MemoryArgs, ShadingArg, ThreadsArg,
};
use crate::progress::RenderProgress;
use crate::stats_json::{self, RunFacts};
use crate::OutputTarget;

/// Arguments of `flexcam animate`.
#[derive(Args, Debug)]
pub struct AnimateArgs {
    /// A scene file (.toml) with an `[animation]` table: camera keys, objects with an
    /// `orbit`, or both.
    scene: PathBuf,
    /// Numbered frames: the run of `#` in the file name becomes the zero-padded frame
    /// number, from 0 (e.g. `frames/out_####.png`); 8-bit PNG, or linear float `.exr` or
    /// `.pfm` as `render -o` writes them.
    #[arg(short, long, value_name = "PATTERN")]
    output: Option<PathBuf>,
    /// An animated GIF of all frames.
    #[arg(long, value_name = "FILE")]
    gif: Option<PathBuf>,
    /// Image width in pixels (overrides the scene file; alone, it keeps the scene's aspect
    /// ratio).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene file; alone, it keeps the scene's aspect
    /// ratio).
    #[arg(long)]
    height: Option<u32>,
    /// Rendering method of every frame: `raycast` (the reference, every camera), `raster`
    /// (rasterisation by the analytic inverse, cameras that have one), `trilinear` or
    /// `camera-triangles` (a scene's trilinear reflectors, each frame's pinhole view and its
    /// reflections rendered by that method; a camera either method cannot render is
    /// refused with the reason).
    #[arg(long, default_value = "raycast", value_parser = method_names())]
    method: String,
    /// Shading: `flat` (base colours, exact) or `lit` (lights, shadows, reflections).
    #[arg(long, value_enum, default_value_t = ShadingArg::Lit)]
    shading: ShadingArg,
    /// Samples per pixel (overrides the scene's `[image] spp`, whose default is 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: Option<u32>,
    /// Render only these frames (numbered from 0): comma-separated frame numbers `N`,
    /// ranges `A-B` and ranges with a step `A-B:S`, e.g. `3,5-10,20-40:5`. A GIF then holds
    /// these frames alone.
    #[arg(long, value_name = "LIST")]
    frames: Option<String>,
    /// Leave out the frames whose file (-o PATTERN) exists already, so that a farm task that
    /// was cut off can be rerun; not with --gif, which needs every frame.
    #[arg(long, requires = "output", conflicts_with = "gif")]
    skip_existing: bool,
    /// Write statistics of the whole animation as one JSON object to FILE, or to standard
    /// output with `-` (as `flexcam render --stats`; `frames`, `bvh_builds`).
    #[arg(long, value_name = "FILE|-")]
    stats: Option<OutputTarget>,
    #[command(flatten)]
    define: DefineArgs,
    #[command(flatten)]
    memory: MemoryArgs,
    #[command(flatten)]
    threads: ThreadsArg,
}

/// Estimated bytes a GIF holds per frame pixel until it is written.
const GIF_BYTES_PER_PIXEL: u64 = 4;

/// A file name with one run of `#` to be replaced by the frame number.
struct FramePattern {
    folder: PathBuf,
    before: String,
    digits: usize,
    after: String,
}

impl FramePattern {
    /// Errors: no `#` in the file name, two separate runs of them, an extension other than
    /// .png, .exr or .pfm, or fewer `#` than the last frame number has digits.
    fn new(path: &Path, frames: u32) -> Result<Self> {
        image_io::check_extension(path, &ColorFormat::EXTENSIONS)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let start = name.find('#').ok_or_else(|| {
            Error::in_file(
                path,
                "the frame pattern needs a run of `#` for the frame number",
            )
        })?;
        let digits = name[start..].chars().take_while(|&c| c == '#').count();
        let after = name[start + digits..].to_string();
        if after.contains('#') {
            return Err(Error::in_file(
                path,
                "the frame pattern must hold one run of `#`, not several",
            ));
        }
        let needed = (frames - 1).to_string().len();
        if digits < needed {
            return Err(Error::in_file(
                path,
                format!(
                    "{frames} frames need {needed} `#` for their numbers, the pattern has {digits}"
                ),
            ));
        }
        Ok(FramePattern {
            folder: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            before: name[..start].to_string(),
            digits,
            after,
        })
    }

    /// The path of frame `frame`.
    fn path(&self, frame: u32) -> PathBuf {
        let name = format!(
            "{}{frame:0width$}{}",
            self.before,
            self.after,
            width = self.digits
        );
        self.folder.join(name)
    }
}

/// Runs `flexcam animate`. Every frame and the GIF are written only once all frames have
/// rendered, all together, and never over an input.
pub fn run(args: &AnimateArgs) -> Result<()> {
    let start = Instant::now();
    let method: Method = args.method.parse()?;
    if args.output.is_none() && args.gif.is_none() {
        return Err(Error::new(
            "nothing to write: give -o PATTERN (numbered PNG frames), --gif FILE, or both",
        ));
    }
    let mut outputs = OutputSet::new();
    outputs.input("the scene file", &args.scene)?;
    let gif_output = args
        .gif
        .as_deref()
        .map(|gif| outputs.output("the GIF output", gif, &["gif"]))
        .transpose()?;
    let stats_output = match &args.stats {
        Some(OutputTarget::File(path)) => {
            Some(outputs.output("the stats output", path, &["json", "txt", ""])?)
        }
        _ => None,
    };
    args.memory.apply();
    args.threads.apply()?;
    let load_start = Instant::now();
    let request = scene::ModelRequest {
        width: args.width,
        height: args.height,
        camera: None,
    };
    let (scene, animation) = scene::load_file(&args.scene, &args.define.definitions, &request)?;
    super::declare_scene_inputs(&mut outputs, &scene.inputs)?;
    let animation = animation.ok_or_else(|| {
        Error::in_file(&args.scene, "the scene has no [animation] table to animate")
    })?;
    let frames = animation.frames();
    let pattern = args
        .output
        .as_deref()
        .map(|p| FramePattern::new(p, frames))
        .transpose()?;
    let mut chosen = match &args.frames {
        Some(list) => frame_list::parse(list, frames)?,
        None => (0..frames).collect(),
    };
    if let (true, Some(pattern)) = (args.skip_existing, &pattern) {
        chosen.retain(|&n| !pattern.path(n).exists());
    }
    let frame_format = match &pattern {
        Some(pattern) => ColorFormat::of(&pattern.path(0), PngBits::Eight)?,
        None => ColorFormat::Png(PngBits::Eight),
    };
    // The output of each chosen frame, in the order of `chosen`.
    let frame_outputs = match &pattern {
        Some(pattern) => chosen
            .iter()
            .map(|&n| {
                outputs.output(
                    &format!("frame {n} of the output"),
                    &pattern.path(n),
                    &ColorFormat::EXTENSIONS,
                )
            })
            .collect::<Result<Vec<_>>>()?,
        None => Vec::new(),
    };
    let rendered_frames = chosen.len() as u32;
    let (width, height) = scene.image.size_with(args.width, args.height);
    scene::file::validate_resolution(width, height)?;
    let gif_bytes = match &args.gif {
        Some(_) => {
            u64::from(rendered_frames) * u64::from(width) * u64::from(height) * GIF_BYTES_PER_PIXEL
        }
        None => 0,
    };
    scene::check_budget(&scene, width, height, gif_bytes).map_err(|e| e.or_in_file(&args.scene))?;

    let encoding = ColorEncoding::of_shading(args.shading.shading());
    // A still scene is prepared once (one BVH) for every frame; one whose objects move is
    // prepared anew at each frame's time.
    let still = scene.motions.is_empty().then(|| PreparedScene::new(&scene));
    // Without camera keys every frame is seen through the scene's own projection.
    let (fixed_projection, _) = flexcam::calibrate::build(&scene.projection, width, height)
        .map_err(|e| e.or_in_file(&args.scene))?;
    let (mut bvh_builds, mut bvh_build_ms) = (0, 0.0);
    let load_ms = load_start.elapsed().as_secs_f64() * 1e3;
    let render_start = Instant::now();
    let progress = RenderProgress::new();
    let mut gif = args.gif.as_ref().map(|_| GifFrames::default());
    let mut warnings = Vec::new();
    let spp = args.spp.unwrap_or(scene.image.spp);
    for (index, &frame_number) in chosen.iter().enumerate() {
        let keyed = match animation.projection(frame_number) {
            Some(spec) => Some(
                flexcam::calibrate::build(&ProjectionSpec::Flexible(Box::new(spec)), width, height)
                    .map_err(|e| e.or_in_file(&args.scene))?
                    .0,
            ),
            None => None,
        };
        let projection = keyed.as_ref().unwrap_or(&fixed_projection);
        let moved;
        let prepared = match &still {
            Some(prepared) => prepared,
            None => {
                moved = PreparedScene::new(&scene.at_time(animation.time(frame_number)));
                &moved
            }
        };
        let done_before = index as u64;
        let report = |done: u64, total: u64| {
            progress.update(
                done_before * total + done,
                u64::from(rendered_frames) * total,
            )
        };
        let options = RenderOptions {
            method,
            shading: args.shading.shading(),
            spp,
            progress: Some(&report),
            outputs: Outputs::COLOR,
            ..RenderOptions::default()
        };
        let rendered = render::render(prepared, projection.as_ref(), &options)
            .map_err(|e| e.or_in_file(&args.scene))?;
        warnings.extend(rendered.warnings);
        if still.is_none() {
            bvh_builds += prepared.bvh_builds();
            bvh_build_ms += prepared.bvh_build_ms();
        }
        let frame = rendered.frame;
        if let Some(&id) = frame_outputs.get(index) {
            outputs.stage(id, |tmp| {
                image_io::write_color(&frame, tmp, frame_format, encoding)
            })?;
        }
        if let Some(gif) = &mut gif {
            gif.push(&frame, encoding)?;
        }
    }
    progress.finish();
    let render_ms = render_start.elapsed().as_secs_f64() * 1e3;
    let warnings = warning_lines(&warnings);
    print_lines(&args.scene.to_string_lossy(), &warnings);
    if let (Some(gif), Some(id)) = (gif, gif_output) {
        outputs.stage(id, |tmp| gif.write(tmp, animation.fps()))?;
    }
    let mut counters = Stats::new();
    counters.insert("frames", Counter::Count(u64::from(rendered_frames)));
    if let Some(still) = &still {
        bvh_builds += still.bvh_builds();
        bvh_build_ms += still.bvh_build_ms();
    }
    counters.insert("bvh_builds", Counter::Count(bvh_builds));
    counters.insert("bvh_build_ms", Counter::Value(bvh_build_ms));
    let facts = RunFacts {
        method: method.name(),
        scene: &args.scene.to_string_lossy(),
        projection: match animation.keys() {
            [] => scene.projection.kind(),
            _ => "flexible",
        },
        shading: args.shading.name(),
        width,
        height,
        spp,
        triangles: scene.triangle_count(),
        load_ms,
        render_ms,
        warnings: &warnings,
        wall_ms: start.elapsed().as_secs_f64() * 1e3,
        outputs: stats_json::shown(&outputs),
    };
    let json = format!("{}\n", stats_json::to_json(&facts, &counters));
    if let Some(id) = stats_output {
        outputs.stage(id, |tmp| image_io::write_bytes(tmp, json.as_bytes()))?;
    }
    outputs.commit()?;
    if let Some(OutputTarget::Stdout) = &args.stats {
        super::print_stdout(&json)?;
    }
    Ok(())
}
