//! `flexcam render`: load a scene, render it through its projection, write the outputs.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::image_io::{self, ColorEncoding, ColorFormat, DepthFormat, OutputSet, PngBits};
use flexcam::render::{
    self, Counter, LodSelection, Method, Outputs, PixelWindow, PreparedScene, RenderOptions,
    Shading, TransitionMethod, TransitionShading,
};
use flexcam::Result;

use super::atlas_outputs::AtlasOutputs;
use super::scene_args::{
    method_names, print_lines, print_warnings, warning_lines, MethodTuning, SceneArgs, ShadingArg,
};
use crate::progress::RenderProgress;
use crate::stats_json::{self, RunFacts};
use crate::OutputTarget;

/// Arguments of `flexcam render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten, next_help_heading = "Scene")]
    scene: SceneArgs,
    /// The colour image to write, in the format its extension names: `.png` (8-bit, or
    /// 16-bit with `--png-bits 16`; sRGB-encoded, or linear with `--shading flat`), `.exr`
    /// (OpenEXR) or `.pfm`, both linear 32-bit float RGB as rendered (no curve, no clamping).
    #[arg(help_heading = "Outputs", short, long, default_value = "flexcam.png")]
    output: PathBuf,
    /// Bits per channel of a PNG colour output: 8 or 16.
    #[arg(help_heading = "Outputs", long, value_enum, default_value_t = PngBitsArg::Eight)]
    png_bits: PngBitsArg,
    /// Rendering method: `raycast` (the reference, every projection), `raster`
    /// (rasterisation by the analytic inverse, projections that have one), `trilinear`
    /// (rasterisation of trilinear projections) or `camera-triangles` (trilinear projections
    /// and trilinear reflectors, by camera triangles).
    #[arg(help_heading = "Rendering", long, default_value = "raycast", value_parser = method_names())]
    method: String,
    #[command(flatten, next_help_heading = "Method tuning")]
    tuning: MethodTuning,
    /// Shading: `flat` (base colours, exact), `lit` (lights, shadows, reflections),
    /// `transition-lit` (lit, with displaced objects shaded per ray by full displacement,
    /// redistributed bump mapping or their BRDF, as the transition function chooses from the
    /// ray's footprint) or `transitions` (each pixel coloured by the method chosen: green
    /// displacement, blue bump, red BRDF, mixed in the blends).
    #[arg(help_heading = "Rendering", long, value_enum, default_value_t = ShadingArg::Lit)]
    shading: ShadingArg,
    /// The transition function's constant D for `--shading transitions` and
    /// `transition-lit` (default 2): relief of D + 1 pixel footprints or more seen head on is
    /// displaced; below D - 1 footprints of relief, bumps wider than 2.7 footprints are bump
    /// mapped and bumps of 2 footprints or less (the Nyquist limit) get the BRDF; larger D
    /// favours the cheaper methods.
    #[arg(help_heading = "Rendering", long, value_name = "D")]
    transition_d: Option<f64>,
    /// Render only the pixels of columns X0..X1 and rows Y0..Y1 (pixel (0, 0) the top-left;
    /// X1 and Y1 excluded): every output is that rectangle of the whole frame, byte for byte,
    /// so a large frame split into tiles on several machines can be stitched back exactly.
    #[arg(
        help_heading = "Outputs",
        long,
        value_name = "X0,Y0,X1,Y1",
        value_delimiter = ',',
        num_args = 1
    )]
    crop: Option<Vec<u32>>,
    /// Samples per pixel (overrides the scene's `[image] spp`, whose default is 1).
    #[arg(help_heading = "Rendering", long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: Option<u32>,
    /// How rays of `--shading transitions` and `transition-lit` that displace pick the level
    /// of detail of a displaced object (its progressive mesh at 100, 80, 60, 40 or 20 % of
    /// its faces): `footprint` (default: the coarsest whose texture deviation is at most half
    /// the ray's footprint), `distance` (the dissertation's rule by the distance from the
    /// ray's origin), `finest` (always the detailed mesh), or one level for every ray:
    /// `m100`, `m80`, `m60`, `m40`, `m20` (the dissertation's names; `m100` is `finest`).
    #[arg(help_heading = "Rendering", long, value_enum, value_name = "RULE")]
    lod: Option<LodArg>,
    /// The method of `--shading transitions` and `transition-lit` on displaced objects:
    /// `auto` (default: the transition function's choice per ray) or one method for every
    /// ray, `displacement`, `redistributed-bump`, `bump` (the height field's normals, not
    /// redistributed) or `brdf`: the rows of the dissertation's Table 8.1.
    #[arg(help_heading = "Rendering", long, value_enum, value_name = "METHOD")]
    transition_method: Option<TransitionMethodArg>,
    /// Write the depth along each pixel's ray (.exr or .pfm; +inf where nothing is hit).
    #[arg(help_heading = "Outputs", long, value_name = "FILE")]
    depth: Option<PathBuf>,
    /// Write object ids as a 16-bit grayscale PNG (0 = background).
    #[arg(help_heading = "Outputs", long, value_name = "FILE")]
    ids: Option<PathBuf>,
    /// Write object ids as an 8-bit false-colour PNG: a fixed colour per id, black background.
    #[arg(help_heading = "Outputs", long, value_name = "FILE")]
    ids_preview: Option<PathBuf>,
    /// Write every AOV as one multi-channel OpenEXR (.exr): linear colour `R`, `G`, `B`,
    /// depth `Z` (+inf where nothing is hit), object id `id` (uint, 0 = background), and the
    /// surface drawn, world space: shading normal `N.X/Y/Z`, face normal `Ng.X/Y/Z`,
    /// position `P.X/Y/Z`, texture coordinates `uv.U/V` (normals 0, position and uv NaN on
    /// the background).
    #[arg(help_heading = "Outputs", long, value_name = "FILE")]
    aovs: Option<PathBuf>,
    /// Write the joint texture atlas of every trilinear reflector with `reflection =
    /// "atlas"` (.png, .exr or .pfm), one image each beside FILE: `STEM-NAME-reflection.EXT`
    /// for a mirror, `STEM-NAME-refraction.EXT` for glass (and in lit shading its Fresnel
    /// reflection's `STEM-NAME-reflection.EXT`), NAME the reflector's object name.
    #[arg(help_heading = "Outputs", long, value_name = "FILE")]
    atlas: Option<PathBuf>,
    /// Write statistics as one JSON object to FILE, or to standard output with `-`.
    #[arg(help_heading = "Outputs", long, value_name = "FILE|-")]
    stats: Option<OutputTarget>,
}

/// The window of `--crop X0,Y0,X1,Y1` in a `size` image; errors name the flag.
fn crop_window(bounds: &[u32], size: (u32, u32)) -> Result<PixelWindow> {
    let refuse = |why: String| flexcam::Error::new(format!("--crop: {why}"));
    let &[x0, y0, x1, y1] = bounds else {
        return Err(refuse(format!(
            "needs 4 pixel bounds X0,Y0,X1,Y1, got {}",
            bounds.len()
        )));
    };
    let window = PixelWindow { x0, y0, x1, y1 };
    window.check(size).map_err(|e| refuse(e.message))?;
    Ok(window)
}

/// The values of `--png-bits`.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum PngBitsArg {
    #[value(name = "8")]
    Eight,
    #[value(name = "16")]
    Sixteen,
}

/// Runs `flexcam render`. Outputs are written only once everything has succeeded, all
/// together, and never over an input.
pub fn run(args: &RenderArgs) -> Result<()> {
    let start = Instant::now();
    let method: Method = args.method.parse()?;
    let mut outputs = OutputSet::new();
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let color = outputs.output("the output", &args.output, &ColorFormat::EXTENSIONS)?;
    let png_bits = match args.png_bits {
        PngBitsArg::Eight => PngBits::Eight,
        PngBitsArg::Sixteen => PngBits::Sixteen,
    };
    let color_format = ColorFormat::of(&args.output, png_bits)?;
    if png_bits == PngBits::Sixteen && !matches!(color_format, ColorFormat::Png(_)) {
        return Err(flexcam::Error::in_file(
            &args.output,
            "--png-bits 16 applies to a .png output only (.exr and .pfm are float)",
        ));
    }
    let depth = match &args.depth {
        Some(path) => Some((
            outputs.output("the depth output", path, &DepthFormat::EXTENSIONS)?,
            DepthFormat::of(path)?,
        )),
        None => None,
    };
    let ids = args
        .ids
        .as_deref()
        .map(|path| outputs.output("the ids output", path, &["png"]))
        .transpose()?;
    let ids_preview = args
        .ids_preview
        .as_deref()
        .map(|path| outputs.output("the ids preview", path, &["png"]))
        .transpose()?;
    let aovs = args
        .aovs
        .as_deref()
        .map(|path| outputs.output("the AOV output", path, &["exr"]))
        .transpose()?;
    let stats = match &args.stats {
        Some(OutputTarget::File(path)) => {
            Some(outputs.output("the stats output", path, &["json", "txt", ""])?)
        }
        _ => None,
    };

    let loaded = args.scene.load()?;
    super::declare_scene_inputs(&mut outputs, &loaded.scene.inputs)?;

    let progress = RenderProgress::new();
    let report = |done: u64, total: u64| progress.update(done, total);
    let shading = match args.shading.shading() {
        Shading::Transitions(t) => Shading::Transitions(
            TransitionShading::new(t.methods, args.transition_d.unwrap_or(t.d()))?
                .with_lod(args.lod.map_or(t.lod, LodArg::selection))
                .with_method(
                    args.transition_method
                        .map_or(t.method, TransitionMethodArg::method),
                ),
        ),
        shading => {
            let given = [
                ("--transition-d", args.transition_d.is_some()),
                ("--lod", args.lod.is_some()),
                ("--transition-method", args.transition_method.is_some()),
            ];
            if let Some((flag, _)) = given.iter().find(|(_, given)| *given) {
                return Err(flexcam::Error::new(format!(
                    "{flag} applies to --shading transitions and transition-lit only"
                )));
            }
            shading
        }
    };
    let atlases = args
        .atlas
        .as_deref()
        .map(|base| AtlasOutputs::declare(&mut outputs, base, &loaded.scene, shading))
        .transpose()?;
    let spp = args.spp.unwrap_or(loaded.scene.image.spp);
    let crop = args
        .crop
        .as_deref()
        .map(|bounds| crop_window(bounds, (loaded.width, loaded.height)))
        .transpose()?;
    let options = RenderOptions {
        method,
        shading,
        spp,
        subdivision: args.tuning.subdivision(method)?,
        curves: args.tuning.curves(method)?,
        camera_triangles: args.tuning.camera_triangles(method)?,
        progress: Some(&report),
        crop,
        outputs: Outputs {
            depth: depth.is_some() || aovs.is_some(),
            ids: ids.is_some() || ids_preview.is_some() || aovs.is_some(),
            surface: aovs.is_some(),
            atlases: atlases.is_some(),
        },
        ..RenderOptions::default()
    };
    let render_start = Instant::now();
    let prepared = PreparedScene::new(&loaded.scene);
    // Trilinear reflectors (if the scene has any) are composited into the main view, each
    // rendered by the same method (the options' default).
    let rendered = render::render(&prepared, loaded.projection.as_ref(), &options);
    let render_ms = render_start.elapsed().as_secs_f64() * 1e3;
    progress.finish();
    let render::Rendered {
        frame,
        mut counters,
        warnings,
        atlases: atlas_images,
    } = rendered.map_err(|e| e.or_in_file(&loaded.source))?;
    let warnings = warning_lines(&warnings);
    for &(name, value) in &loaded.build_report.counters {
        counters.insert(name, Counter::Value(value));
    }
    counters.insert("bvh_builds", Counter::Count(prepared.bvh_builds()));

    let encoding = ColorEncoding::of_shading(options.shading);
    outputs.stage(color, |tmp| {
        image_io::write_color(&frame, tmp, color_format, encoding)
    })?;
    if let Some((id, format)) = depth {
        outputs.stage(id, |tmp| image_io::write_depth(&frame, tmp, format))?;
    }
    if let Some(id) = ids {
        outputs.stage(id, |tmp| image_io::write_ids_png(&frame, tmp))?;
    }
    if let Some(id) = ids_preview {
        outputs.stage(id, |tmp| image_io::write_ids_preview_png(&frame, tmp))?;
    }
    if let Some(id) = aovs {
        outputs.stage(id, |tmp| image_io::write_aovs_exr(&frame, tmp))?;
    }
    if let Some(atlases) = atlases {
        atlases.stage(&mut outputs, &atlas_images, encoding)?;
    }
    let facts = RunFacts {
        method: method.name(),
        scene: &loaded.source,
        projection: loaded.projection.kind(),
        shading: args.shading.name(),
        width: loaded.width,
        height: loaded.height,
        spp,
        triangles: loaded.scene.triangle_count(),
        load_ms: loaded.load_ms,
        render_ms,
        warnings: &[&loaded.build_report.warnings[..], &warnings].concat(),
        wall_ms: start.elapsed().as_secs_f64() * 1e3,
        outputs: stats_json::shown(&outputs),
    };
    let json = stats_json::to_json(&facts, &counters).to_string();
    super::commit_with_stats(outputs, stats, args.stats.as_ref(), &json)?;
    // Warnings only once the command has succeeded: a failing command prints one line.
    print_warnings(&loaded);
    print_lines(&loaded.source, &warnings);
    Ok(())
}

/// `--lod` on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum LodArg {
    Footprint,
    Distance,
    Finest,
    M100,
    M80,
    M60,
    M40,
    M20,
}

impl LodArg {
    fn selection(self) -> LodSelection {
        match self {
            LodArg::Footprint => LodSelection::Footprint,
            LodArg::Distance => LodSelection::Distance,
            LodArg::Finest => LodSelection::Finest,
            LodArg::M100 => LodSelection::Level(0),
            LodArg::M80 => LodSelection::Level(1),
            LodArg::M60 => LodSelection::Level(2),
            LodArg::M40 => LodSelection::Level(3),
            LodArg::M20 => LodSelection::Level(4),
        }
    }
}

/// `--transition-method` on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum TransitionMethodArg {
    Auto,
    Displacement,
    RedistributedBump,
    Bump,
    Brdf,
}

impl TransitionMethodArg {
    fn method(self) -> TransitionMethod {
        match self {
            TransitionMethodArg::Auto => TransitionMethod::Auto,
            TransitionMethodArg::Displacement => TransitionMethod::Displacement,
            TransitionMethodArg::RedistributedBump => TransitionMethod::RedistributedBump,
            TransitionMethodArg::Bump => TransitionMethod::Bump,
            TransitionMethodArg::Brdf => TransitionMethod::Brdf,
        }
    }
}
