//! `flexcam bench displaced`: Figure 8.1 of Ramsey 2005 (Ray Tracing Displaced Models in a
//! Level-of-Detail Hierarchy), time per frame of the displaced three-holed torus at
//! subdivision levels 0 and up, beside the same micro-triangles given to the ray caster as an
//! ordinary pre-tessellated mesh, in time and in peak memory; then Table 8.1's transition
//! row (`transition_rows`) and the whole of Table 8.1 (`displaced_methods`), chosen by
//! `--part`.
//!
//! The scene is `builtin:displaced-torus` (5,046 base triangles, procedural waves) with its
//! level replaced per row; every frame is `--method raycast` at the same size and shading.
//! The dissertation traced 180 x 180 pixels on ten R14000 processors testing every
//! micro-triangle of a base triangle per ray; flexcam descends a min/max hierarchy per base
//! triangle instead (`flexcam::displace`).
//!
//! Each cell runs in a process of its own (this binary again, with the hidden `--cell`
//! argument), so that its peak memory is its own: the peak resident set size (`VmHWM` of
//! `/proc/self/status`, Linux; "-" elsewhere) of a process that loads the scene, builds the
//! variant (a copy of the scene, or its tessellation), prepares it and renders it. Both
//! variants share the process's fixed cost (the binary, the base scene, the frame).

use std::sync::Arc;
use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::displace::{tessellate, Displacement};
use flexcam::glam::Vec3;
use flexcam::image_io::{encode_channel, ColorEncoding};
use flexcam::projection::{CameraFrame, ProjectionSpec};
use flexcam::render::{
    render, Counter, Frame, LodSelection, PreparedScene, RenderOptions, Shading, TransitionMethod,
    TransitionShading,
};
use flexcam::scene::{self, DisplacementSpec, Scene};
use flexcam::{Error, Result};

use super::timing::measure;

/// Figure 8.1: (level, micro-triangles per base triangle, seconds per frame).
const DISSERTATION: [(u32, u32, f64); 5] = [
    (1, 4, 0.41),
    (2, 16, 1.02),
    (3, 64, 3.43),
    (4, 256, 13.04),
    (5, 1024, 51.48),
];

/// Arguments of `flexcam bench displaced`.
#[derive(Args, Debug)]
pub struct DisplacedArgs {
    /// Timed renders per cell, after one warm-up render; the median is reported.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(16..=4096))]
    size: u32,
    /// Deepest subdivision level of the sweep.
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(0..=8))]
    max_level: u32,
    /// Deepest level also rendered pre-tessellated (its mesh grows 4x per level: level 5 is
    /// 5.2 million triangles, about 1 GB with its BVH).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=6))]
    max_tessellated: u32,
    /// Shading of every frame.
    #[arg(long, value_enum, default_value_t = BenchShading::Flat)]
    shading: BenchShading,
    /// Which tables to run: `figure-8-1` (the level sweep), `transitions` (the transition
    /// system against full displacement), `table-8-1` (every method of Table 8.1 at its
    /// three camera positions), or `all`.
    #[arg(long, value_enum, default_value_t = Part::All)]
    part: Part,
    /// Internal: measure one cell (`displaced:LEVEL` or `tessellated:LEVEL`) in this process
    /// and print it as one line.
    #[arg(long, hide = true)]
    cell: Option<String>,
}

/// `--shading` of the bench.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchShading {
    /// Primary rays only: the geometry's cost.
    Flat,
    /// Lights and shadow rays (micro-triangle normals).
    Lit,
}

/// `--part` of the bench.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Part {
    /// Every table.
    All,
    /// Figure 8.1: the subdivision-level sweep beside the pre-tessellated mesh.
    #[value(name = "figure-8-1")]
    Figure81,
    /// Table 8.1's transition row against full displacement, per `D` and LOD rule.
    Transitions,
    /// Table 8.1: every rendering method at the three camera positions.
    #[value(name = "table-8-1")]
    Table81,
}

/// One variant's measurements, in milliseconds and megabytes.
struct Cell {
    median_ms: f64,
    cpu_ms: f64,
    prepare_ms: f64,
    peak_mb: Option<f64>,
}

/// Runs the sweep and prints it beside Figure 8.1, or measures one cell (`--cell`).
pub fn run(args: &DisplacedArgs) -> Result<()> {
    if let Some(cell) = &args.cell {
        return measure_cell(args, cell);
    }
    let base = scene::load("builtin:displaced-torus")?;
    if matches!(args.part, Part::All | Part::Figure81) {
        level_sweep(args, &base)?;
    }
    if matches!(args.part, Part::All | Part::Transitions) {
        transition_rows(args, &base)?;
    }
    if matches!(args.part, Part::All | Part::Table81) {
        super::displaced_methods::table_8_1(args.size, args.repeat, &base)?;
    }
    Ok(())
}

/// Figure 8.1: the level sweep, each cell in a process of its own.
fn level_sweep(args: &DisplacedArgs, base: &Scene) -> Result<()> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "Figure 8.1 (Ramsey 2005): the displaced three-holed torus, {} base triangles, {s}x{s}, \
         {:?} shading, --method raycast, median of {} after one warm-up, {threads} threads",
        base.triangle_count(),
        args.shading,
        args.repeat,
        s = args.size,
    );
    println!(
        "dissertation: 180x180, ten 600 MHz R14000, every micro-triangle of a base triangle tested"
    );
    println!(
        "{:>5} {:>10} {:>8} | {:>12} {:>8} {:>8} | {:>12} {:>9} {:>8} | {:>6} {:>6}",
        "level",
        "micro/base",
        "diss. s",
        "displaced ms",
        "cpu ms",
        "peak MB",
        "tessel. ms",
        "build ms",
        "peak MB",
        "time x",
        "mem x"
    );
    for level in 0..=args.max_level {
        let displaced = spawn_cell(args, "displaced", level)?;
        let tessellated = if level <= args.max_tessellated {
            Some(spawn_cell(args, "tessellated", level)?)
        } else {
            None
        };
        let diss = DISSERTATION
            .iter()
            .find(|(l, _, _)| *l == level)
            .map_or("-".to_string(), |(_, _, s)| format!("{s:.2}"));
        let mb = |m: Option<f64>| m.map_or("-".to_string(), |m| format!("{m:.1}"));
        let (t_ms, t_build, t_mb, ratio, mem_ratio) = match &tessellated {
            Some(t) => (
                format!("{:.1}", t.median_ms),
                format!("{:.0}", t.prepare_ms),
                mb(t.peak_mb),
                format!("{:.2}", displaced.median_ms / t.median_ms),
                match (displaced.peak_mb, t.peak_mb) {
                    (Some(d), Some(t)) => format!("{:.3}", d / t),
                    _ => "-".to_string(),
                },
            ),
            None => Default::default(),
        };
        println!(
            "{level:>5} {:>10} {diss:>8} | {:>12.1} {:>8} {:>8} | {t_ms:>12} {t_build:>9} {t_mb:>8} | {ratio:>6} {mem_ratio:>6}",
            1u64 << (2 * level),
            displaced.median_ms,
            format!("{:.1}", displaced.cpu_ms),
            mb(displaced.peak_mb),
        );
    }
    println!(
        "time x: displaced / tessellated frame time; mem x: displaced / tessellated peak memory; \
         build ms: tessellation and BVH build of the tessellated mesh (the displaced set's own \
         build is under 100 ms)"
    );
    Ok(())
}

/// Camera distances of the transition rows, as fractions of the scene's own: the near view
/// (Table 8.1's e = (0, 0, 1) in spirit: the torus filling the frame) and the scene's view.
const TRANSITION_VIEWS: [(&str, f64); 2] = [("near", 0.45), ("scene", 1.0)];

/// Values of the transition function's `D` in the transition rows: the default and two
/// that favour the cheaper methods more.
const TRANSITION_DS: [f64; 3] = [TransitionShading::DEFAULT_D, 8.0, 32.0];

/// The transition system (`--shading transition-lit`) against full displacement (`--shading
/// lit`) at the near and the scene's view, level 5, in this process: Table 8.1's "transition
/// system" row beside "displaced detailed", for each `D` of [`TRANSITION_DS`], with the
/// displacing rays on the detailed mesh (`--lod finest`) and on the level of detail their
/// footprint allows (`--lod footprint`); and how far the `footprint` image is from full
/// displacement's under the same shader ([`image_error`], untimed renders at
/// [`ERROR_SPP`] samples per pixel).
fn transition_rows(args: &DisplacedArgs, base: &Scene) -> Result<()> {
    println!(
        "Table 8.1 (Ramsey 2005): transition system (transition-lit) against full displacement \
         (lit), level 5; the dissertation's was over 4x faster at the near view"
    );
    println!(
        "{:>6} {:>5} {:>13} {:>13} {:>8} {:>13} {:>8} | {:>6} {:>6} {:>6} | {:>7} | {:>6} {:>6}",
        "view",
        "D",
        "displaced ms",
        "finest ms",
        "speed-up",
        "footprint ms",
        "speed-up",
        "BRDF",
        "bump",
        "disp.",
        "coarser",
        "error",
        ">0.1"
    );
    let scene = with_level(base, 5);
    let prepared = PreparedScene::new(&scene);
    for (name, fraction) in TRANSITION_VIEWS {
        let projection = closer(&scene.projection, fraction)?.build(args.size, args.size)?;
        let time = |shading| {
            let options = RenderOptions {
                shading,
                ..RenderOptions::default()
            };
            measure(args.repeat, || {
                render(&prepared, projection.as_ref(), &options)
            })
        };
        let (full, _) = time(Shading::Lit)?;
        let image = |shading| {
            let options = RenderOptions {
                shading: Shading::Transitions(shading),
                spp: ERROR_SPP,
                ..RenderOptions::default()
            };
            render(&prepared, projection.as_ref(), &options).map(|r| r.frame)
        };
        let reference = image(
            TransitionShading::with_default_d(false)
                .with_method(TransitionMethod::Displacement)
                .with_lod(LodSelection::Finest),
        )?;
        for d in TRANSITION_DS {
            let shading = TransitionShading::new(false, d)?;
            let (finest, _) = time(Shading::Transitions(shading.with_lod(LodSelection::Finest)))?;
            let (footprint, rendered) = time(Shading::Transitions(
                shading.with_lod(LodSelection::Footprint),
            ))?;
            let counter = |key: &str| match rendered.counters.get(key) {
                Some(Counter::Value(v)) => *v,
                Some(Counter::Count(n)) => *n as f64,
                _ => 0.0,
            };
            let weights = [
                "transition_brdf_weight",
                "transition_bump_weight",
                "transition_displacement_weight",
            ]
            .map(counter);
            let total: f64 = weights.iter().sum::<f64>().max(1.0);
            let levels = LEVEL_KEYS.map(counter);
            let displacing: f64 = levels.iter().sum();
            let coarser = if displacing > 0.0 {
                format!("{:.0}%", 100.0 * (displacing - levels[0]) / displacing)
            } else {
                "-".to_string()
            };
            let (error, off) = image_error(
                &image(shading.with_lod(LodSelection::Footprint))?,
                &reference,
                scene.image.background,
            );
            println!(
                "{name:>6} {d:>5} {:>13.1} {:>13.1} {:>8.2} {:>13.1} {:>8.2} | {:>5.0}% {:>5.0}% {:>5.0}% | {coarser:>7} | {error:>6.3} {:>5.1}%",
                full.median_ms(),
                finest.median_ms(),
                full.median_ms() / finest.median_ms(),
                footprint.median_ms(),
                full.median_ms() / footprint.median_ms(),
                100.0 * weights[0] / total,
                100.0 * weights[1] / total,
                100.0 * weights[2] / total,
                100.0 * off,
            );
        }
    }
    println!(
        "finest: --lod finest (the detailed mesh); footprint: --lod footprint (the default); \
         BRDF, bump, disp.: share of the samples on the displaced object by method weight; \
         coarser: share of the displacing samples that traced a coarser level; the tables and \
         levels of detail are built once per prepared scene, in the first (warm-up) render; \
         error: the footprint image against full displacement's (transition-lit, \
         --transition-method displacement --lod finest), both at {ERROR_SPP} samples per \
         pixel, in sRGB codes / 255 over the pixels either shows the torus in: mean, and \
         share above 0.1"
    );
    Ok(())
}

/// Samples per pixel of the renders [`image_error`] compares: enough that pixels are
/// compared as averages, not as aliased samples of ridges a few pixels wide.
const ERROR_SPP: u32 = 4;

/// How far `image` is from `reference` (same size): per pixel the mean over the three
/// channels of the absolute difference of their 8-bit sRGB codes over 255, over the pixels
/// where either is not `background`; the mean, and the share of those pixels above 0.1.
/// (0, 0) where both are all background.
fn image_error(image: &Frame, reference: &Frame, background: Vec3) -> (f64, f64) {
    let code = |c: &Vec3| {
        c.to_array()
            .map(|v| f64::from(encode_channel(v, ColorEncoding::Srgb)))
    };
    let (mut sum, mut above, mut count) = (0.0, 0usize, 0usize);
    for (a, b) in image.color.iter().zip(&reference.color) {
        if *a == background && *b == background {
            continue;
        }
        let (ca, cb) = (code(a), code(b));
        let error = (0..3).map(|k| (ca[k] - cb[k]).abs()).sum::<f64>() / (3.0 * 255.0);
        sum += error;
        above += usize::from(error > 0.1);
        count += 1;
    }
    if count == 0 {
        return (0.0, 0.0);
    }
    (sum / count as f64, above as f64 / count as f64)
}

/// The statistics keys of the samples per level of detail (`--stats` of `transition-lit`).
const LEVEL_KEYS: [&str; 5] = [
    "lod_100_samples",
    "lod_80_samples",
    "lod_60_samples",
    "lod_40_samples",
    "lod_20_samples",
];

/// `projection` (a perspective camera) moved towards its target to `fraction` of its
/// distance.
fn closer(projection: &ProjectionSpec, fraction: f64) -> Result<ProjectionSpec> {
    match projection {
        ProjectionSpec::Perspective { frame, fov } => Ok(ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: frame.look_at + (frame.position - frame.look_at) * fraction,
                ..*frame
            },
            fov: *fov,
        }),
        _ => Err(Error::new(
            "the displaced torus bench needs a perspective camera",
        )),
    }
}

/// `scene` with every displacement at subdivision `level`.
pub(super) fn with_level(scene: &Scene, level: u32) -> Scene {
    let mut scene = scene.clone();
    for object in &mut scene.objects {
        if let Some(spec) = &object.displacement {
            object.displacement = Some(Arc::new(DisplacementSpec {
                level,
                ..DisplacementSpec::clone(spec)
            }));
        }
    }
    scene
}

/// `scene` with every displaced object replaced by its micro-triangles as a mesh.
fn tessellated(scene: &Scene) -> Scene {
    let mut scene = scene.clone();
    for object in &mut scene.objects {
        if let Some(spec) = object.displacement.take() {
            object.mesh = tessellate(&object.mesh, &Displacement::from_spec(&spec)).into();
        }
    }
    scene
}

/// Measures cell `variant:level` in a child process (module docs).
fn spawn_cell(args: &DisplacedArgs, variant: &str, level: u32) -> Result<Cell> {
    let exe = std::env::current_exe()
        .map_err(|e| Error::new(format!("cannot find this program to run a cell: {e}")))?;
    let shading = match args.shading {
        BenchShading::Flat => "flat",
        BenchShading::Lit => "lit",
    };
    let out = std::process::Command::new(exe)
        .args([
            "bench",
            "displaced",
            "--cell",
            &format!("{variant}:{level}"),
        ])
        .args(["--size", &args.size.to_string(), "--shading", shading])
        .args(["--repeat", &args.repeat.to_string()])
        .output()
        .map_err(|e| Error::new(format!("cannot run a bench cell: {e}")))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let fields: Vec<f64> = text
        .split_whitespace()
        .filter_map(|f| f.parse().ok())
        .collect();
    match (out.status.success(), fields.as_slice()) {
        (true, &[median_ms, cpu_ms, prepare_ms, peak_kb]) => Ok(Cell {
            median_ms,
            cpu_ms,
            prepare_ms,
            peak_mb: (peak_kb >= 0.0).then_some(peak_kb / 1024.0),
        }),
        _ => Err(Error::new(format!(
            "bench cell {variant}:{level} failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ))),
    }
}

/// Measures one cell in this process and prints `median_ms cpu_ms prepare_ms peak_kb`
/// (peak -1 where unknown).
fn measure_cell(args: &DisplacedArgs, cell: &str) -> Result<()> {
    let parsed = cell
        .split_once(':')
        .and_then(|(variant, level)| Some((variant, level.parse::<u32>().ok()?)));
    let (variant, level) = match parsed {
        Some((v @ ("displaced" | "tessellated"), l)) if l <= 8 => (v, l),
        _ => return Err(Error::new(format!("bad bench cell \"{cell}\""))),
    };
    let base = scene::load("builtin:displaced-torus")?;
    let projection = base.projection.build(args.size, args.size)?;
    let options = RenderOptions {
        shading: match args.shading {
            BenchShading::Flat => Shading::Flat,
            BenchShading::Lit => Shading::Lit,
        },
        ..RenderOptions::default()
    };
    let start = Instant::now();
    let scene = with_level(&base, level);
    let scene = match variant {
        "tessellated" => tessellated(&scene),
        _ => scene,
    };
    let prepared = PreparedScene::new(&scene);
    drop(scene);
    let prepare_ms = start.elapsed().as_secs_f64() * 1e3;
    let (timing, _) = measure(args.repeat, || {
        render(&prepared, projection.as_ref(), &options)
    })?;
    let peak_kb = memory_kb("VmHWM:").map_or(-1.0, |k| k as f64);
    println!(
        "{} {} {prepare_ms} {peak_kb}",
        timing.median_ms(),
        timing.cpu_ms()
    );
    Ok(())
}

/// A `kB` field of `/proc/self/status` (`VmRSS:`, `VmHWM:`), if readable.
fn memory_kb(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    line[field.len()..].split_whitespace().next()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Background pixels of both are left out; the others count by their channels' mean
    /// code difference; all background or identical frames give 0.
    #[test]
    fn image_error_over_the_object_only() {
        let background = Vec3::new(0.1, 0.2, 0.3);
        let mut a = Frame::new(4, 1, background);
        let mut b = Frame::new(4, 1, background);
        assert_eq!(image_error(&a, &b, background), (0.0, 0.0));
        a.color[0] = Vec3::ONE;
        b.color[0] = Vec3::ZERO;
        a.color[1] = Vec3::splat(0.5);
        b.color[1] = Vec3::splat(0.5);
        assert_eq!(image_error(&a, &a, background), (0.0, 0.0));
        let (mean, above) = image_error(&a, &b, background);
        assert!((mean - 0.5).abs() < 1e-12, "{mean}");
        assert!((above - 0.5).abs() < 1e-12, "{above}");
    }
}
