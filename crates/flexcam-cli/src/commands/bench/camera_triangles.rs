//! `flexcam bench camera-triangles`: Table 1 and Figures 6 and 7 of Hou, Wei, Shum and Guo
//! 2006 and the issue's targets, rerun with `--method camera-triangles`.
//!
//! - Table 1, reflection: a mirror sphere reflecting a cube and a checkered floor (about 108
//!   scene triangles) at 800 x 600, the sphere's visible triangles being the camera
//!   triangles, at three tessellations (about 26, 26 x 4 and 26 x 16 camera triangles):
//!   whole-frame time and frames per second, bounding and rendered fragments and overdraw,
//!   with the paper's bound and ours, beside the paper's figures; each row also with the
//!   cluster culling of section 2.4 switched off.
//! - Table 1, caustics: `camtri-caustics.toml` at the paper's 640 x 480 with a photon map of
//!   512 x 512, lit: the photon map's camera triangles (the mirror's reflection surface seen
//!   from the light), its bounding and rendered fragments and overdraw (`caustic_*` stats),
//!   and the whole frame's time.
//! - Table 1, visualisation: `camtri-visualisation.toml` (a walker of 6,864 triangles on a
//!   floor, seen through a trilinear projection of 400 camera triangles around it) at 800 x
//!   600, flat: the camera triangles, fragments and overdraw of the frame, rendered directly.
//! - A mirror sphere over a floor of about 5,000 scene triangles at 800 x 600: the whole
//!   frame by camera triangles, per camera mesh ([`MIRROR_SPHERE_MESHES`]), against
//!   `--method raycast` (true mirror), and the agreement of the reflector's pixels with the
//!   exact reflection (`measures`), over all of them and over those whose exact reflection
//!   does not show the mirror itself (`self_reflection`).
//! - `--figure 6` ([`figure6`]): reflection quality per camera mesh size; `--figure 7`
//!   ([`figure7`]): frames per second of a mirror teapot among moving balls, without and
//!   with acceleration. Both print a markdown table and write a CSV with `--csv FILE`
//!   (plotted by `tools/plot/csv_plot.py`).
//!
//! Flat shading (lit for the caustics), one warm-up render, then the median of `--repeat`
//! renders (`timing`).

mod figure6;
mod figure7;
mod measures;
mod self_reflection;

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::Projection;
use flexcam::render::{
    self, compare, CameraTriangleBound as Bound, CameraTriangleOptions, Method, Outputs,
    PreparedScene, RenderOptions, Rendered, Shading,
};
use flexcam::scene::{self, Scene};
use flexcam::Result;

use self::measures::{colour_agreement_inside, count, value};
use self::self_reflection::{marked, self_reflected_pixels};
use super::timing::{measure, Timing};

/// Arguments of `flexcam bench camera-triangles`.
#[derive(Args, Debug)]
pub struct CameraTrianglesArgs {
    /// Timed renders per row, after one warm-up render; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Measure a figure instead of Table 1: `6` (reflection quality per camera mesh size
    /// against the exact mirror) or `7` (frames per second of a mirror teapot among moving
    /// objects, without and with acceleration).
    #[arg(long, value_enum)]
    figure: Option<Figure>,
    /// Write the figure's measurements as CSV to FILE (with --figure).
    #[arg(long, value_name = "FILE", requires = "figure")]
    csv: Option<PathBuf>,
    /// Image width of every render (default: the paper's, 800, or 640 for caustics).
    #[arg(long, requires = "height", value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height of every render (default: the paper's, 600, or 480 for caustics).
    #[arg(long, requires = "width", value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// The folder of the example scenes (`camtri-*.toml`) that the caustics and visualisation
    /// rows and Figure 6 load.
    #[arg(long, value_name = "DIR", default_value = "scenes")]
    scenes: PathBuf,
}

/// A figure of the paper.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Figure {
    #[value(name = "6")]
    Six,
    #[value(name = "7")]
    Seven,
}

/// What every part of the bench runs with.
pub struct Settings {
    /// Timed renders per row.
    pub repeat: u32,
    /// `--width` and `--height`, if given.
    size: Option<(u32, u32)>,
    /// The example scenes' folder.
    pub scenes: PathBuf,
}

impl Settings {
    /// The image size: `--width` x `--height`, else `paper`.
    pub fn size(&self, paper: (u32, u32)) -> (u32, u32) {
        self.size.unwrap_or(paper)
    }
}

/// The paper's reflection rows: camera triangles, bounding and rendered fragments,
/// overdraw, frames per second (GeForce 7800 GT).
const PAPER: [(&str, u64, u64, f64, f64); 3] = [
    ("26", 2_002_513, 62_860, 32.0, 51.0),
    ("26x4", 920_156, 62_734, 15.0, 63.0),
    ("26x16", 783_566, 62_823, 12.0, 5.0),
];

/// Sphere tessellations whose visible triangles are about 26, 104 and 416 camera triangles.
const TESSELLATIONS: [u32; 3] = [5, 10, 20];

/// The reflection scene: a mirror sphere of `tessellation` with `reflector_keys` (lines of its
/// `[[object]]` table), a cube and a floor of `floor` x `floor` quads, at 800 x 600.
fn reflection_scene(tessellation: u32, floor: u32, reflector_keys: &str) -> Result<Scene> {
    let text = format!(
        r#"
[image]
width = 800
height = 600
background = [0.3, 0.4, 0.6]

[projection]
type = "perspective"
position = [0.4, 1.5, 3.0]
look_at = [0.0, 1.0, 0.0]
fov = 60.0

[[object]]
name = "sphere"
shape = "sphere"
size = 1.0
tessellation = {tessellation}
material = "mirror"
translate = [0.0, 1.0, 0.0]
trilinear_reflector = true
{reflector_keys}

[[object]]
name = "cube"
shape = "box"
size = [1.2, 1.2, 1.2]
face_colors = [[0.9, 0.15, 0.1], [0.1, 0.75, 0.8], [0.2, 0.8, 0.2], [0.8, 0.2, 0.8], [0.15, 0.3, 0.9], [0.95, 0.8, 0.1]]
translate = [-1.5, 0.6, 1.8]
rotate = [0.0, 30.0, 0.0]

[[object]]
name = "floor"
shape = "plane"
size = [12.0, 12.0]
tessellation = {floor}
color = [0.9, 0.9, 0.9]
checker = {{ color = [0.1, 0.1, 0.1], size = 0.5 }}
"#
    );
    scene::file::parse(&text, Path::new("bench:camera-triangles"))
}

pub fn run(args: &CameraTrianglesArgs) -> Result<()> {
    let settings = Settings {
        repeat: args.repeat,
        size: args.width.zip(args.height),
        scenes: args.scenes.clone(),
    };
    if let Some((width, height)) = settings.size {
        scene::file::validate_resolution(width, height)?;
    }
    let mut outputs = OutputSet::new();
    let csv_output = args
        .csv
        .as_deref()
        .map(|path| outputs.output("the CSV output", path, &["csv"]))
        .transpose()?;
    let csv = match args.figure {
        None => return table1(&settings),
        Some(Figure::Six) => figure6::csv(&figure6::run(&settings)?),
        Some(Figure::Seven) => figure7::csv(&figure7::run(&settings)?),
    };
    if let Some(id) = csv_output {
        outputs.stage(id, |tmp| image_io::write_bytes(tmp, csv.as_bytes()))?;
    }
    outputs.commit()
}

/// Table 1's reflection, caustics and visualisation rows, then the 5,000-triangle target.
fn table1(settings: &Settings) -> Result<()> {
    let (width, height) = settings.size((800, 600));
    println!(
        "Table 1, reflection (Hou et al. 2006): mirror sphere, cube and floor at {width} x \
         {height}, flat shading; whole frame (main view by method trilinear, reflection by \
         camera triangles); median of {} renders; cpu ms: mean CPU time of one render over \
         all threads.",
        settings.repeat
    );
    println!(
        "{:>7} {:>6} {:>6} | {:>6} {:>10} {:>9} {:>8} {:>7} {:>8} {:>7} | paper: {:>10} {:>8} {:>8} {:>5}",
        "camera",
        "scene",
        "bound",
        "cull",
        "bounding",
        "rendered",
        "overdraw",
        "ms",
        "fps",
        "cpu ms",
        "bounding",
        "rendered",
        "overdraw",
        "fps"
    );
    for (tessellation, paper) in TESSELLATIONS.iter().zip(PAPER) {
        let scene = reflection_scene(*tessellation, 7, "trilinear_refine_px = 0")?;
        let prepared = PreparedScene::new(&scene);
        let main = scene.projection.build(width, height)?;
        for bound in [Bound::Paper, Bound::Tight] {
            for cull in [false, true] {
                let options = RenderOptions {
                    method: Method::CameraTriangles,
                    shading: Shading::Flat,
                    camera_triangles: CameraTriangleOptions { bound, cull },
                    ..RenderOptions::default()
                };
                let (timing, rendered) =
                    timed_render(settings.repeat, &prepared, main.as_ref(), &options)?;
                let c = &rendered.counters;
                let ms = timing.median_ms();
                println!(
                    "{:>7} {:>6} {:>6} | {:>6} {:>10} {:>9} {:>8.2} {:>7.1} {:>8.1} {:>7} | {:>17} {:>8} {:>8} {:>5}",
                    count(c, "camera_triangles"),
                    prepared_triangles(&scene),
                    format!("{bound:?}").to_lowercase(),
                    if cull { "on" } else { "off" },
                    count(c, "bounding_fragments"),
                    count(c, "rendered_fragments"),
                    value(c, "overdraw"),
                    ms,
                    1e3 / ms,
                    timing.cpu_text(1e3, 1),
                    paper.1,
                    paper.2,
                    paper.3,
                    paper.4,
                );
            }
        }
    }
    application_row(settings, &CAUSTICS)?;
    application_row(settings, &VISUALISATION)?;
    five_thousand(settings.repeat, width, height)
}

/// A Table 1 row of an application scene from the `--scenes` folder: the paper's figures
/// are scene triangles, camera triangles, bounding and rendered fragments, overdraw and
/// frames per second (GeForce 7800 GT).
struct ApplicationRow {
    /// The row's name in the title line (`Table 1, NAME:`).
    name: &'static str,
    /// The scene file.
    file: &'static str,
    /// `-D` edits of the scene.
    defines: &'static [&'static str],
    /// The paper's image size.
    size: (u32, u32),
    shading: Shading,
    /// What the title line says is measured, after the scene and size.
    measured: &'static str,
    /// The prefix of the stats that hold the camera triangles and their fragments.
    stats: &'static str,
    paper: (u64, u64, u64, u64, f64, f64),
}

/// Table 1's caustics row (module doc).
const CAUSTICS: ApplicationRow = ApplicationRow {
    name: "caustics",
    file: "camtri-caustics.toml",
    defines: &["object.mirror.caustic_map=512"],
    size: (640, 480),
    shading: Shading::Lit,
    measured: "photon map 512 x 512, lit; camera triangles, fragments and overdraw of the \
               photon map's render through the mirror's camera triangles (caustic_* stats); \
               time of the whole frame (main view, the mirror's reflection, the photon map, \
               splatting)",
    stats: "caustic_",
    paper: (2, 400, 945_962, 475_852, 2.0, 35.0),
};

/// Table 1's visualisation row (module doc).
const VISUALISATION: ApplicationRow = ApplicationRow {
    name: "visualization",
    file: "camtri-visualisation.toml",
    defines: &[],
    size: (800, 600),
    shading: Shading::Flat,
    measured: "flat shading; the whole frame is the trilinear projection of 400 camera \
               triangles around the walker, rendered directly by camera triangles",
    stats: "",
    paper: (6_841, 400, 213_248, 213_248, 1.0, 46.0),
};

/// Renders `row`'s scene by camera triangles and prints its title, header and row beside
/// the paper's figures.
fn application_row(settings: &Settings, row: &ApplicationRow) -> Result<()> {
    let (width, height) = settings.size(row.size);
    let path = settings.scenes.join(row.file);
    let defines = row
        .defines
        .iter()
        .map(|d| d.parse())
        .collect::<Result<Vec<_>>>()?;
    let (scene, _) = scene::load_file(&path, &defines, &scene::ModelRequest::default())?;
    let prepared = PreparedScene::new(&scene);
    let main = scene.projection.build(width, height)?;
    let options = RenderOptions {
        method: Method::CameraTriangles,
        shading: row.shading,
        ..RenderOptions::default()
    };
    let (timing, rendered) = timed_render(settings.repeat, &prepared, main.as_ref(), &options)?;
    let c = &rendered.counters;
    let stat = |name: &str| format!("{}{name}", row.stats);
    let ms = timing.median_ms();
    let paper = row.paper;
    println!();
    println!(
        "Table 1, {}: {} at {width} x {height}, {}; median of {} renders.",
        row.name,
        path.display(),
        row.measured,
        settings.repeat
    );
    println!(
        "{:>7} {:>6} | {:>10} {:>9} {:>8} {:>7} {:>8} {:>7} | paper: {:>6} {:>6} {:>10} {:>8} {:>8} {:>5}",
        "camera", "scene", "bounding", "rendered", "overdraw", "ms", "fps", "cpu ms", "camera",
        "scene", "bounding", "rendered", "overdraw", "fps"
    );
    println!(
        "{:>7} {:>6} | {:>10} {:>9} {:>8.2} {:>7.1} {:>8.1} {:>7} | {:>13} {:>6} {:>10} {:>8} {:>8} {:>5}",
        count(c, &stat("camera_triangles")),
        prepared_triangles(&scene),
        count(c, &stat("bounding_fragments")),
        count(c, &stat("rendered_fragments")),
        value(c, &stat("overdraw")),
        ms,
        1e3 / ms,
        timing.cpu_text(1e3, 1),
        paper.1,
        paper.0,
        paper.2,
        paper.3,
        paper.4,
        paper.5,
    );
    Ok(())
}

/// The mirror sphere's camera meshes (`[[object]]` keys of the sphere) and their names:
/// the sphere's own 80 triangles unrefined; refined to `trilinear_refine_px = 8`, the
/// coarsest of 16, 12, 10, 8, 6 and 4 main-image pixels whose agreement reached 0.99 against
/// the ray caster before its rim rule, away from the rays it followed into the mirror
/// (docs/camera-triangles.md, "The mirror sphere"); the automatic camera mesh (refined to
/// the default 0.5 pixels).
const MIRROR_SPHERE_MESHES: [(&str, &str); 3] = [
    ("own mesh", "trilinear_refine_px = 0"),
    ("refined 8 px", "trilinear_refine_px = 8"),
    ("automatic", ""),
];

/// The 5,000-triangle mirror-sphere target (module doc): the ray caster's exact mirror,
/// then one row per camera mesh of [`MIRROR_SPHERE_MESHES`].
fn five_thousand(repeat: u32, width: u32, height: u32) -> Result<()> {
    let scene = reflection_scene(10, 50, MIRROR_SPHERE_MESHES[0].1)?;
    let main = scene.projection.build(width, height)?;
    let options = |method| RenderOptions {
        method,
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut exact_scene = scene.clone();
    exact_scene.trilinear_reflectors.clear();
    let exact = PreparedScene::new(&exact_scene);
    let (ray_time, reference) =
        timed_render(repeat, &exact, main.as_ref(), &options(Method::Raycast))?;
    let id = scene.trilinear_reflectors[0].id;
    let reflector = scene.objects.iter().position(|o| o.id == id);
    let surface_options = RenderOptions {
        outputs: Outputs {
            surface: true,
            ..Outputs::ALL
        },
        ..options(Method::Raycast)
    };
    let surfaces = render::render(&exact, main.as_ref(), &surface_options)?.frame;
    let self_reflected = match reflector {
        Some(index) => self_reflected_pixels(&exact, main.as_ref(), &surfaces, index, id),
        None => vec![false; surfaces.ids.len()],
    };
    println!();
    println!(
        "Mirror sphere ({} triangles) over {} scene triangles at {width} x {height}, flat: the \
         whole frame by camera triangles against --method raycast of the exact mirror, {:.1} ms \
         (cpu ms {:.1}); targets: time ratio <= 0.5, agreement >= 0.99. agreement: reflector \
         pixels away from colour edges with the exact colour, over all of them, then over \
         those whose exact reflected ray does not meet the mirror itself ({} of the \
         reflector's pixels do: a concave mirror reflects itself, camera triangles reflect \
         the scene without it); rgb: relative RGB error of the frame.",
        reflector.map_or(0, |index| scene.objects[index].mesh.triangles.len()),
        prepared_triangles(&scene),
        ray_time.median_ms(),
        ray_time.cpu_ms(),
        marked(&self_reflected),
    );
    println!(
        "{:>12} {:>7} {:>8} {:>8} {:>7} {:>6} {:>8} | {:>9} {:>7} {:>12} {:>8}",
        "camera mesh",
        "camera",
        "overdraw",
        "ms",
        "ratio",
        "cpu ms",
        "ratio",
        "agreement",
        "pixels",
        "no self-refl",
        "rgb",
    );
    for (name, keys) in MIRROR_SPHERE_MESHES {
        let scene = reflection_scene(10, 50, keys)?;
        let prepared = PreparedScene::new(&scene);
        let (ours_time, ours) = timed_render(
            repeat,
            &prepared,
            main.as_ref(),
            &options(Method::CameraTriangles),
        )?;
        let (same, pixels) = colour_agreement_inside(&ours.frame, &reference.frame, id, None);
        let (same_rest, rest) =
            colour_agreement_inside(&ours.frame, &reference.frame, id, Some(&self_reflected));
        let rgb = compare(&ours.frame, &reference.frame)?.relative_rgb_error;
        println!(
            "{:>12} {:>7} {:>8.2} {:>8.1} {:>7.2} {:>6.1} {:>8.2} | {:>9.4} {:>7} {:>5.4} of {:>6} {:>8.5}",
            name,
            count(&ours.counters, "camera_triangles"),
            value(&ours.counters, "overdraw"),
            ours_time.median_ms(),
            ours_time.median_ms() / ray_time.median_ms(),
            ours_time.cpu_ms(),
            ours_time.cpu_ms() / ray_time.cpu_ms(),
            same,
            pixels,
            same_rest,
            rest,
            rgb
        );
    }
    Ok(())
}

/// Renders `prepared` through `main` with `options`, timed by [`measure`]: the timing and
/// the median render.
fn timed_render(
    repeat: u32,
    prepared: &PreparedScene,
    main: &dyn Projection,
    options: &RenderOptions,
) -> Result<(Timing, Rendered)> {
    measure(repeat, || render::render(prepared, main, options))
}

/// Scene triangles other than the reflector's.
fn prepared_triangles(scene: &Scene) -> usize {
    let reflectors: Vec<u32> = scene.trilinear_reflectors.iter().map(|r| r.id).collect();
    scene
        .objects
        .iter()
        .filter(|o| !reflectors.contains(&o.id))
        .map(|o| o.mesh.triangles.len())
        .sum()
}
