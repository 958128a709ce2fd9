//! Figure 7 of Hou, Wei, Shum and Guo 2006: frames per second of a mirror teapot reflecting
//! many moving objects, without and with the acceleration of section 2.4, across scene and
//! camera triangle counts.
//!
//! The scene (`teapot_scene`; `scenes/camtri-teapot.toml` is its 10-ball layout with a
//! 256-triangle camera mesh, an `animate` scene): Newell's teapot (992 triangles) as a mirror, its
//! camera mesh simplified to the paper's 100, 256 or 512 triangles (`camera_triangles`),
//! balls of 80 triangles orbiting it at their own speeds (5 to 20 balls: the paper's 400 to
//! 1,600 scene triangles; each ball's `orbit` about the teapot's vertical axis) and a floor of
//! 2 triangles, at 800 x 600. Every timed render is the next frame (1/24 s later): the balls
//! are moved ([`Scene::at_time`]), the scene prepared anew and the whole
//! frame rendered (main view by the trilinear method, the teapot's reflection by camera
//! triangles, tight bound), so the time is that of a dynamic scene. "No acceleration" turns
//! off the culling of section 2.4 (clusters of scene triangles per camera triangle, and per
//! quarter of it); the camera mesh is given, as in the paper, not chosen automatically.
//! The teapot pixels the coarse camera mesh's surface does not cover are not ray cast
//! (`RenderOptions::cast_reflector_gaps` off, as in Figure 6) but counted: the time is that
//! of camera triangles, not of the exact ray casting that fills those gaps in a render.

use std::f32::consts::TAU;
use std::path::Path;

use flexcam::render::{
    self, CameraTriangleBound, CameraTriangleOptions, Method, PreparedScene, RenderOptions, Shading,
};
use flexcam::scene::{self, Scene};
use flexcam::Result;

use super::measures::{count, value};
use super::Settings;
use crate::commands::bench::timing::measure;

/// Triangles of one ball (a sphere of tessellation 10).
const BALL_TRIANGLES: u32 = 80;

/// The stats of the camera-triangle stages (milliseconds, summed over the surface).
const STAGES: [&str; 4] = [
    "owner_ms",
    "bound_ms",
    "surface_raster_ms",
    "surface_shade_ms",
];

/// Frames per second of the animation the timed renders step through.
const FPS: f64 = 24.0;

/// The paper's grid: scene triangles, camera triangles, frames per second without and with
/// acceleration (GeForce 7800 GT).
const PAPER: [(u32, usize, f64, f64); 8] = [
    (800, 100, 4.5, 20.1),
    (1200, 100, 3.6, 14.6),
    (1600, 100, 2.1, 9.2),
    (400, 256, 1.5, 6.0),
    (800, 256, 0.5, 2.1),
    (1200, 256, 0.35, 1.8),
    (400, 512, 0.8, 2.5),
    (800, 512, 0.3, 1.0),
];

/// Ball `k` of `balls`: its position at time 0, radius, colour and angular speed about the
/// teapot's vertical axis (radians per second; alternate balls turn the other way).
fn ball(k: u32, balls: u32) -> ([f32; 3], f32, [f32; 3], f32) {
    let ring = (k % 3) as f32;
    let angle = TAU * k as f32 / balls as f32;
    let distance = 2.4 + 0.8 * ring;
    let height = 0.35 + 0.5 * (k % 4) as f32;
    let hue = k as f32 / balls as f32;
    let channel = |offset: f32| 0.55 + 0.4 * (TAU * (hue + offset)).cos();
    let speed = (0.4 + 0.15 * (k % 5) as f32) * if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    (
        [distance * angle.sin(), height, distance * angle.cos()],
        0.3 + 0.05 * ring,
        [channel(0.0), channel(1.0 / 3.0), channel(2.0 / 3.0)],
        speed,
    )
}

/// The teapot scene with `balls` balls at time 0 and a camera mesh of `camera_triangles`.
pub fn teapot_scene(balls: u32, camera_triangles: usize, width: u32, height: u32) -> Result<Scene> {
    let mut text = format!(
        r#"
[image]
width = {width}
height = {height}
background = [0.3, 0.4, 0.6]

[projection]
type = "perspective"
position = [0.0, 3.8, 7.5]
look_at = [0.0, 1.0, 0.0]
fov = 55.0

[[object]]
name = "teapot"
shape = "teapot"
size = 1.0
tessellation = 16
material = "mirror"
trilinear_reflector = true
camera_triangles = {camera_triangles}

[[object]]
name = "floor"
shape = "plane"
size = [14.0, 14.0]
tessellation = 1
color = [0.9, 0.9, 0.9]
checker = {{ color = [0.1, 0.1, 0.1], size = 0.5 }}
"#
    );
    for k in 0..balls {
        let (position, radius, colour, speed) = ball(k, balls);
        let period = TAU / speed;
        text += &format!(
            "\n[[object]]\nname = \"ball{k}\"\nshape = \"sphere\"\nsize = {radius}\n\
             tessellation = 10\ncolor = {colour:?}\ntranslate = {position:?}\n\
             orbit = {{ center = [0.0, 0.0, 0.0], period = {period:?} }}\n"
        );
    }
    scene::file::parse(&text, Path::new("bench:camera-triangles-teapot"))
}

/// One cell of the figure, without and with acceleration.
pub struct Row {
    pub scene_triangles: u64,
    pub camera_mesh: usize,
    pub camera_triangles: u64,
    /// Median whole-frame milliseconds, without and with acceleration.
    pub ms: [f64; 2],
    /// (camera triangle, scene triangle) pairs bounded, without and with acceleration.
    pub pairs: [u64; 2],
    /// Milliseconds of the camera-triangle stages of the median frame (owners, bounds,
    /// the surface's raster and shading), without and with acceleration.
    pub stages_ms: [f64; 2],
    /// Teapot pixels no camera triangle covers (left uncast), and all teapot pixels.
    pub uncovered_pixels: u64,
    pub teapot_pixels: u64,
    /// The paper's frames per second, without and with acceleration.
    pub paper: [f64; 2],
}

/// Renders the figure, printing its table (markdown) as it goes; the rows for the CSV.
pub fn run(settings: &Settings) -> Result<Vec<Row>> {
    let (width, height) = settings.size((800, 600));
    println!(
        "Figure 7 (Hou et al. 2006): a mirror teapot (992 triangles) reflecting balls of 80 \
         triangles that orbit it, {width} x {height}, flat shading, tight bound; each timed \
         render the next frame (balls moved, scene prepared, whole frame), median of {} \
         frames; acceleration: section 2.4's culling; uncovered px: teapot pixels outside \
         the camera mesh's surface (left uncast) of teapot px.",
        settings.repeat
    );
    println!();
    println!(
        "| scene tris | camera mesh | camera tris | no acc ms | fps | pairs | stages ms | acc ms \
         | fps | pairs | stages ms | speed-up | uncovered px | teapot px | paper: no acc fps | \
         acc fps |"
    );
    println!(
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- \
         | --- |"
    );
    let mut rows = Vec::new();
    for (scene_triangles, camera_mesh, no_acc, acc) in PAPER {
        let balls = scene_triangles / BALL_TRIANGLES;
        let scene = teapot_scene(balls, camera_mesh, width, height)?;
        let main = scene.projection.build(width, height)?;
        let mut ms = [0.0; 2];
        let mut pairs = [0; 2];
        let mut stages_ms = [0.0; 2];
        let mut last = None;
        for (i, cull) in [false, true].into_iter().enumerate() {
            let options = RenderOptions {
                method: Method::CameraTriangles,
                shading: Shading::Flat,
                camera_triangles: CameraTriangleOptions {
                    bound: CameraTriangleBound::Tight,
                    cull,
                },
                cast_reflector_gaps: false,
                ..RenderOptions::default()
            };
            let mut frame = 0u32;
            let (timing, rendered) = measure(settings.repeat, || {
                let moved = scene.at_time(f64::from(frame) / FPS);
                frame += 1;
                render::render(&PreparedScene::new(&moved), main.as_ref(), &options)
            })?;
            ms[i] = timing.median_ms();
            pairs[i] = count(&rendered.counters, "surface_pairs");
            stages_ms[i] = STAGES
                .iter()
                .map(|name| value(&rendered.counters, name))
                .sum();
            last = Some(rendered.counters);
        }
        let counters = last.unwrap_or_default();
        let reflector = scene.trilinear_reflectors.first().map_or(0, |r| r.id);
        let row = Row {
            scene_triangles: scene
                .objects
                .iter()
                .filter(|o| o.id != reflector)
                .map(|o| o.mesh.triangles.len() as u64)
                .sum(),
            camera_mesh,
            camera_triangles: count(&counters, "camera_triangles"),
            ms,
            pairs,
            stages_ms,
            uncovered_pixels: count(&counters, "reflector_uncovered_pixels"),
            teapot_pixels: count(&counters, "reflector_pixels"),
            paper: [no_acc, acc],
        };
        println!(
            "| {} | {} | {} | {:.1} | {:.2} | {} | {:.1} | {:.1} | {:.2} | {} | {:.1} | {:.2} | {} \
             | {} | {} | {} |",
            row.scene_triangles,
            row.camera_mesh,
            row.camera_triangles,
            row.ms[0],
            1e3 / row.ms[0],
            row.pairs[0],
            row.stages_ms[0],
            row.ms[1],
            1e3 / row.ms[1],
            row.pairs[1],
            row.stages_ms[1],
            row.ms[0] / row.ms[1],
            row.uncovered_pixels,
            row.teapot_pixels,
            row.paper[0],
            row.paper[1]
        );
        rows.push(row);
    }
    Ok(rows)
}

/// The CSV, one line per cell and acceleration:
/// `scene_triangles,camera_mesh,camera_triangles,acceleration,ms,fps,pairs,stages_ms,paper_fps`.
pub fn csv(rows: &[Row]) -> String {
    let mut text = String::from(
        "scene_triangles,camera_mesh,camera_triangles,acceleration,ms,fps,pairs,stages_ms,paper_fps\n",
    );
    for row in rows {
        for (i, acceleration) in ["off", "on"].into_iter().enumerate() {
            text += &format!(
                "{},{},{},{acceleration},{:.3},{:.3},{},{:.3},{}\n",
                row.scene_triangles,
                row.camera_mesh,
                row.camera_triangles,
                row.ms[i],
                1e3 / row.ms[i],
                row.pairs[i],
                row.stages_ms[i],
                row.paper[i]
            );
        }
    }
    text
}
