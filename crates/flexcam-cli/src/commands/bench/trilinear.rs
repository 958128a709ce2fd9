//! `flexcam bench trilinear`: the timing study of Vallance 2005 (Trilinear Projection,
//! chapter 8 and appendix D) with flexcam's two renderers of the same trilinear projection:
//! the BVH ray caster (`--method raycast`) and the rasteriser (`--method trilinear`, adaptive
//! curves), with and without scene-space clipping.
//!
//! - Tables D.1 to D.3: random scenes of 1 to 640 disconnected vertex-coloured triangles
//!   through random regular screen meshes of 2 to 50 projection triangles, square images of
//!   1 to 640^2 pixels (`render::bench_support::workloads::trilinear`).
//! - Table 8.1, figure 7.4: the cube-floor scene (686 triangles) through 2, 8, 18, 32 and 50
//!   projection triangles (the fan grid of the accuracy tests) at 800 x 800, with the
//!   accuracy against the ray caster (id agreement and relative RGB error) and the trilinear stage times.
//!
//! Flat shading, as in the thesis ("no lighting or texture mapping"). Each cell is one
//! warm-up render, then the median of `--repeat` timed renders; renderers (BVH, scene
//! geometry) are built once per scene, outside the timing. The cube table also gives the
//! mean CPU time (all threads, user + system) per render of the ray caster and of the
//! clipped trilinear renderer, which load from other processes distorts far less than wall
//! time (Linux only, in 10 ms ticks: use a `--repeat` of 10 or more).
//!
//! Every render above returns a new frame, the ray caster's and trilinear's alike
//! (`render::render`, `TrilinearRenderer::render`): its 12.8 MB at 800 x 800 are allocated
//! and their pages first touched in each timed render. A second cube table times the later
//! frames of a program that draws frame after frame into one frame it keeps, both renderers
//! alike (`bench_support::raycast_into`, `TrilinearRenderer::render_into` without and with
//! clipping), and compares them like for like.
//!
//! `--study` runs one of the chapter 8 studies instead (modules [`examples`],
//! [`configurations`], [`tessellation`]), and `--sweep` the Figure 7.4 sweep of a view through
//! a mirror or glass ball against N (module [`sweep`]): a markdown table on stdout, and as
//! CSV with `--csv FILE` (plotted by `tools/plot/trilinear-studies.sh`).

mod configurations;
mod examples;
mod study;
mod sweep;
mod tessellation;

use std::path::PathBuf;

use clap::{ArgGroup, Args, ValueEnum};
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::{Trilinear, TrilinearMesh};
use flexcam::render::bench_support::workloads::trilinear::{
    fan_grid, random_grid, random_triangles,
};
use flexcam::render::bench_support::{raycast_into, TrilinearRenderer};
use flexcam::render::{
    self, compare, Counter, CurveOptions, Frame, PreparedScene, RenderOptions, Shading,
};
use flexcam::scene;
use flexcam::Result;

use super::timing::measure;

/// Arguments of `flexcam bench trilinear`.
#[derive(Args, Debug)]
#[command(group(ArgGroup::new("table").args(["study", "sweep"])))]
pub struct TrilinearArgs {
    /// Timed renders per cell, after one warm-up render; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// A fast subset: random scenes of 1 and 640 triangles through 2, 18 and 50 projections
    /// at 1 and 256^2 pixels, and the cube-floor scene through 2, 18 and 50 projections;
    /// with `--study tessellation`, the factors 1, 10 and 100 alone; with `--sweep`, the
    /// grids N = 1, 4 and 16 alone.
    #[arg(long)]
    quick: bool,
    /// Run a study of chapter 8 instead: `examples` (Table 8.1, every row), `configurations`
    /// (the appendix C shape configurations, Tables D.4-D.17) or `tessellation` (curve
    /// following per tessellation factor, Figures 8.9-8.12, Tables D.18-D.31).
    #[arg(long, value_enum)]
    study: Option<Study>,
    /// Run the Figure 7.4 sweep instead: the view through a mirror ball (`reflection`) or a
    /// glass ball (`refraction`) as an N x N trilinear grid, N = 1 to 32, against the exact
    /// ball ray cast (object-id agreement away from id edges, relative RGB error).
    #[arg(long, value_enum)]
    sweep: Option<sweep::Sweep>,
    /// Write the study's or sweep's table as CSV to FILE.
    #[arg(long, value_name = "FILE", requires = "table")]
    csv: Option<PathBuf>,
    /// Image width of every render of the study or sweep (default: the thesis's, or for a
    /// sweep the scene's 320; the height keeps that aspect ratio).
    #[arg(long, requires = "table", value_parser = clap::value_parser!(u32).range(3..=4096))]
    size: Option<u32>,
    /// The folder of the example scenes the studies and sweeps load (`trilinear-*.toml`,
    /// `reflect-*.toml`, `refract-lens.toml`, `appendix-c/`).
    #[arg(long, value_name = "DIR", default_value = "scenes")]
    scenes: PathBuf,
}

/// A study of chapter 8 (`--study`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Study {
    Examples,
    Configurations,
    Tessellation,
}

/// What `--study` or `--sweep` runs.
#[derive(Clone, Copy)]
enum Tabled {
    Study(Study),
    Sweep(sweep::Sweep),
}

/// Runs a study or sweep: prints its table and writes it as CSV where asked (nothing is
/// written when a render fails).
fn run_study(tabled: Tabled, args: &TrilinearArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    let csv_output = args
        .csv
        .as_deref()
        .map(|path| outputs.output("the CSV output", path, &["csv"]))
        .transpose()?;
    let (scenes, size, repeat) = (args.scenes.as_path(), args.size, args.repeat);
    let (title, table) = match tabled {
        Tabled::Sweep(which) => (
            which.title(),
            sweep::run(which, scenes, size, repeat, args.quick)?,
        ),
        Tabled::Study(study) => match study {
            Study::Examples => (
                "Table 8.1 (Vallance 2005): every example, ray caster (raycast) and trilinear \
             rasteriser of the same frame",
                examples::run(scenes, size, repeat)?,
            ),
            Study::Configurations => (
                "Appendix C configurations (Tables D.4-D.17): one scene triangle through one \
             folding projection triangle",
                configurations::run(scenes, size, repeat)?,
            ),
            Study::Tessellation => (
                "Tessellation factor (Figures 8.9-8.12, Tables D.18-D.31): --curves tessellate \
             and slice against the ray caster",
                tessellation::run(scenes, size, repeat, args.quick)?,
            ),
        },
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "{title}; flat shading, {threads} threads, median of {repeat} after one warm-up; ms = \
         median wall, cpu_ms = mean CPU of all threads; ids_interior = id agreement away \
         from id edges\n"
    );
    print!("{}", table.markdown());
    if let Some(id) = csv_output {
        outputs.stage(id, |tmp| image_io::write_bytes(tmp, table.csv().as_bytes()))?;
    }
    outputs.commit()
}

/// Side lengths of the square images of appendix D (1 to 640^2 pixels).
const SIDES: [u32; 6] = [1, 128, 256, 384, 512, 640];
/// Scene triangle counts of appendix D.
const SCENE_TRIANGLES: [u32; 6] = [1, 128, 256, 384, 512, 640];
/// Screen cells per side of the projection meshes: 2, 8, 18, 32, 50 projection triangles.
const CELLS: [u32; 5] = [1, 2, 3, 4, 5];
/// The image side of Table 8.1's cube scene.
const CUBE_SIDE: u32 = 800;
/// Seed of the random data (fixed: every run times the same scenes).
const SEED: u64 = 2005;

/// The thesis's times (ms) at 640 triangles and 640^2 pixels through 2 to 50 projections:
/// ray tracing (D.1), trilinear (D.2), with scene-space clipping (D.3).
const THESIS_D: [[f64; 5]; 3] = [
    [57913.0, 71352.0, 69250.0, 55970.0, 64122.0],
    [62.56, 81.62, 242.40, 414.00, 696.00],
    [90.92, 127.63, 501.00, 906.50, 1572.00],
];
/// Table 8.1, figure 7.4: the cube through 2 to 50 projections at 800 x 800 (ms); ray traced
/// once (177926 ms).
const THESIS_CUBE: [f64; 5] = [24.4, 70.1, 150.1, 230.2, 360.7];
const THESIS_CUBE_RAY: f64 = 177926.0;

/// One cell's medians (ms), the trilinear stage times of its median render, and the mean
/// CPU times (ms) per render.
struct Timing {
    raycast: f64,
    trilinear: f64,
    clipped: f64,
    stages: [f64; 3],
    /// The ray caster, trilinear and clipped trilinear, each returning a new frame.
    cpu: [f64; 3],
    /// The ray caster and trilinear without and with clipping, each into a frame it keeps
    /// (`None`: not timed).
    kept: Option<Kept>,
    /// Id agreement and relative RGB error against the ray caster of trilinear without
    /// and with clipping.
    accuracy: [(f64, f64); 2],
}

/// Medians (ms) and mean CPU times (ms) of rendering into a kept frame: the ray caster,
/// trilinear, clipped trilinear.
struct Kept {
    raycast: f64,
    trilinear: f64,
    clipped: f64,
    cpu: [f64; 3],
}

/// Runs the benchmark and prints both tables.
pub fn run(args: &TrilinearArgs) -> Result<()> {
    if let Some(study) = args.study {
        return run_study(Tabled::Study(study), args);
    }
    if let Some(which) = args.sweep {
        return run_study(Tabled::Sweep(which), args);
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let (sides, counts, cells): (&[u32], &[u32], &[u32]) = if args.quick {
        (&[1, 256], &[1, 640], &[1, 3, 5])
    } else {
        (&SIDES, &SCENE_TRIANGLES, &CELLS)
    };
    println!(
        "Vallance 2005 chapter 8 / appendix D: flat shading, {threads} threads, median of {} after \
         one warm-up; raycast = BVH ray caster, trilinear = adaptive curves without / with \
         scene-space clipping (clip); times in ms",
        args.repeat
    );
    println!(
        "\nTables D.1-D.3: random scenes through random regular screen meshes; new frames (each \
         render, ray cast and trilinear alike, returns a new frame)"
    );
    println!(
        "{:>10}{:>7}{:>6}{:>11}{:>11}{:>9}{:>11}{:>9}",
        "pixels", "tris", "proj", "raycast", "trilinear", "speedup", "clip", "speedup"
    );
    for &count in counts {
        let scene = random_triangles(count, SEED + u64::from(count));
        let prepared = PreparedScene::new(&scene);
        let renderers = Renderers::new(&prepared);
        for &side in sides {
            for &n in cells {
                let mesh = random_grid(n, SEED + u64::from(n))?;
                let timing = renderers.time(&mesh, side, args.repeat, false)?;
                println!(
                    "{:>10}{count:>7}{:>6}{:>11.2}{:>11.2}{:>8.1}x{:>11.2}{:>8.1}x",
                    side * side,
                    mesh.triangles.len(),
                    timing.raycast,
                    timing.trilinear,
                    timing.raycast / timing.trilinear,
                    timing.clipped,
                    timing.raycast / timing.clipped,
                );
            }
        }
    }
    println!("thesis at 640 triangles, 640^2 pixels (800 MHz Athlon, no acceleration structure):");
    for (k, n) in CELLS.iter().enumerate() {
        println!(
            "{:>10}{:>7}{:>6}{:>11.2}{:>11.2}{:>8.1}x{:>11.2}{:>8.1}x",
            640 * 640,
            640,
            2 * n * n,
            THESIS_D[0][k],
            THESIS_D[1][k],
            THESIS_D[0][k] / THESIS_D[1][k],
            THESIS_D[2][k],
            THESIS_D[0][k] / THESIS_D[2][k],
        );
    }

    println!(
        "\nTable 8.1 (figure 7.4): cube-floor, 686 triangles, {CUBE_SIDE} x {CUBE_SIDE}, fan \
         projection; NEW FRAMES: every render, ray cast and trilinear alike, returns a new \
         frame (its allocation and first touch timed); accuracy of trilinear with clipping \
         against raycast; cpu = mean CPU ms per render, all threads"
    );
    println!(
        "{:>5}{:>10}{:>11}{:>9}{:>10}{:>9}{:>9}{:>9}{:>9}{:>9}{:>11}{:>9}{:>9}{:>9}{:>9}{:>10}{:>9}",
        "proj",
        "rc new",
        "tri new",
        "speedup",
        "clip new",
        "speedup",
        "project",
        "raster",
        "shade",
        "ids",
        "rgb error",
        "thesis",
        "rc cpu",
        "tri cpu",
        "cpu x",
        "clip cpu",
        "cpu x"
    );
    let cube = scene::load("builtin:cube-floor")?;
    let prepared = PreparedScene::new(&cube);
    let renderers = Renderers::new(&prepared);
    let mut later = Vec::new();
    for &n in cells {
        let mesh = fan_grid(n)?;
        let timing = renderers.time(&mesh, CUBE_SIDE, args.repeat, true)?;
        let [_, accuracy] = timing.accuracy;
        let [project, raster, shade] = timing.stages;
        let [raycast_cpu, trilinear_cpu, clipped_cpu] = timing.cpu;
        let thesis = CELLS
            .iter()
            .position(|&c| c == n)
            .map_or(f64::NAN, |k| THESIS_CUBE[k]);
        println!(
            "{:>5}{:>10.2}{:>11.2}{:>8.1}x{:>10.2}{:>8.1}x{project:>9.2}{raster:>9.2}{shade:>9.2}\
             {:>9.5}{:>11.6}{thesis:>9.1}{raycast_cpu:>9.1}{trilinear_cpu:>9.1}{:>8.1}x\
             {clipped_cpu:>10.1}{:>8.1}x",
            mesh.triangles.len(),
            timing.raycast,
            timing.trilinear,
            timing.raycast / timing.trilinear,
            timing.clipped,
            timing.raycast / timing.clipped,
            accuracy.0,
            accuracy.1,
            raycast_cpu / trilinear_cpu,
            raycast_cpu / clipped_cpu,
        );
        later.push((mesh.triangles.len(), timing));
    }
    println!(
        "thesis: ray traced {THESIS_CUBE_RAY} ms; stage times are those of the median clipped \
         render"
    );
    print_kept(&later);
    Ok(())
}

/// The cube table of later frames, like for like: the ray caster and trilinear without and
/// with clipping, each drawing into a frame it keeps (median ms, speed-up over the ray
/// caster's kept frame, mean CPU ms per render and CPU ratios); the accuracy of trilinear
/// without clipping against the ray caster (the clipped render's is in Table 8.1).
fn print_kept(cells: &[(usize, Timing)]) {
    println!(
        "\ncube-floor, later frames, KEPT FRAMES: the ray caster (raycast_into) and \
         trilinear without / with clipping (TrilinearRenderer::render_into) each draw into a \
         frame kept from render to render; accuracy of trilinear without clipping against \
         raycast; cpu = mean CPU ms per render, all threads"
    );
    println!(
        "{:>5}{:>10}{:>10}{:>9}{:>9}{:>11}{:>11}{:>9}{:>9}{:>9}{:>9}{:>11}{:>9}",
        "proj",
        "rc kept",
        "tri kept",
        "speedup",
        "ids",
        "rgb error",
        "clip kept",
        "speedup",
        "rc cpu",
        "tri cpu",
        "cpu x",
        "clip cpu",
        "cpu x"
    );
    for (projections, timing) in cells {
        let Some(kept) = &timing.kept else { continue };
        let [raycast_cpu, trilinear_cpu, clipped_cpu] = kept.cpu;
        let [(ids, rgb_error), _] = timing.accuracy;
        println!(
            "{projections:>5}{:>10.2}{:>10.2}{:>8.1}x{ids:>9.5}{rgb_error:>11.6}{:>11.2}{:>8.1}x\
             {raycast_cpu:>9.1}{trilinear_cpu:>9.1}{:>8.1}x{clipped_cpu:>11.1}{:>8.1}x",
            kept.raycast,
            kept.trilinear,
            kept.raycast / kept.trilinear,
            kept.clipped,
            kept.raycast / kept.clipped,
            raycast_cpu / trilinear_cpu,
            raycast_cpu / clipped_cpu,
        );
    }
}

/// Both renderers of one prepared scene.
struct Renderers<'a> {
    caster: &'a PreparedScene,
    trilinear: TrilinearRenderer<'a>,
}

impl<'a> Renderers<'a> {
    fn new(prepared: &'a PreparedScene) -> Renderers<'a> {
        Renderers {
            caster: prepared,
            trilinear: TrilinearRenderer::new(prepared),
        }
    }

    /// Times the three renders of `mesh` at `side x side` pixels into new frames (and with
    /// `kept` the same three into kept frames), and the id agreement and relative RGB error
    /// of the two trilinear renders against the ray caster.
    fn time(&self, mesh: &TrilinearMesh, side: u32, repeat: u32, kept: bool) -> Result<Timing> {
        let projection = Trilinear::new(mesh, side, side)?;
        let options = RenderOptions {
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        let (raycast, reference) = measure(repeat, || {
            Ok(render::render(self.caster, &projection, &options)?.frame)
        })?;
        let trilinear = |curves: CurveOptions| {
            measure(repeat, || {
                self.trilinear.render(&projection, &options, curves)
            })
        };
        let unclipped = CurveOptions {
            scene_clipping: false,
            ..CurveOptions::ADAPTIVE
        };
        let (plain, (plain_frame, _)) = trilinear(unclipped)?;
        let (clipped, (frame, stats)) = trilinear(CurveOptions::ADAPTIVE)?;
        // Each kept frame starts at the wrong size, so its first (warm-up) render allocates
        // it, as a program's first frame would.
        let into_kept = |curves: CurveOptions| {
            let mut kept = Frame::new(1, 1, glam::Vec3::ZERO);
            measure(repeat, || {
                self.trilinear
                    .render_into(&mut kept, &projection, &options, curves)
            })
        };
        let kept = if kept {
            let mut frame = Frame::new(1, 1, glam::Vec3::ZERO);
            let (raycast, _) = measure(repeat, || {
                raycast_into(self.caster, &mut frame, &projection, &options)
            })?;
            let (trilinear, _) = into_kept(unclipped)?;
            let (clipped, _) = into_kept(CurveOptions::ADAPTIVE)?;
            Some(Kept {
                raycast: raycast.median_ms(),
                trilinear: trilinear.median_ms(),
                clipped: clipped.median_ms(),
                cpu: [raycast, trilinear, clipped].map(|t| t.cpu_ms()),
            })
        } else {
            None
        };
        let accuracy = [&plain_frame, &frame].map(|frame| {
            compare(frame, &reference).map(|c| (c.id_agreement, c.relative_rgb_error))
        });
        let [plain_accuracy, clipped_accuracy] = accuracy;
        let stage = |name| match stats.get(name) {
            Some(Counter::Value(ms)) => *ms,
            _ => f64::NAN,
        };
        let timing = Timing {
            raycast: raycast.median_ms(),
            trilinear: plain.median_ms(),
            clipped: clipped.median_ms(),
            stages: ["project_ms", "raster_ms", "shade_ms"].map(stage),
            cpu: [raycast, plain, clipped].map(|t| t.cpu_ms()),
            kept,
            accuracy: [plain_accuracy?, clipped_accuracy?],
        };
        Ok(timing)
    }
}
