//! `flexcam bench camera-triangles`: Table 1 of Hou, Wei, Shum and Guo 2006 (the reflection
//! rows) and the issue's targets, rerun with `--method camera-triangles`.
//!
//! - Table 1, reflection: a mirror sphere reflecting a cube and a checkered floor (about 108
//!   scene triangles) at 800 x 600, the sphere's visible triangles being the camera
//!   triangles, at three tessellations (about 26, 26 x 4 and 26 x 16 camera triangles):
//!   whole-frame time and frames per second, bounding and rendered fragments and overdraw,
//!   with the paper's bound and ours, beside the paper's figures; each row also with the
//!   cluster culling of section 2.4 switched off.
//! - A mirror sphere over a floor of about 5,000 scene triangles at 800 x 600: the whole
//!   frame by camera triangles against `--method raycast` (true mirror), and the agreement
//!   of the reflector's pixels with the exact reflection (flat colours: the fraction of
//!   reflector pixels away from colour edges whose colour is the exact one, and the relative
//!   RGB error).
//!
//! Flat shading, one warm-up render, then the median of `--repeat` renders (`timing`).

use std::path::Path;

use clap::Args;
use flexcam::render::{
    self, compare, CameraTriangleBound as Bound, CameraTriangleOptions, Counter, Frame, Method,
    PreparedScene, RenderOptions, Shading,
};
use flexcam::scene::{self, Scene};
use flexcam::Result;

use super::timing::measure;

/// Arguments of `flexcam bench camera-triangles`.
#[derive(Args, Debug)]
pub struct CameraTrianglesArgs {
    /// Timed renders per row, after one warm-up render; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
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

/// The reflection scene: a mirror sphere of `tessellation` whose visible triangles are the
/// camera triangles (`trilinear_refine_px = 0`), a cube and a floor of `floor` x `floor`
/// quads.
fn reflection_scene(tessellation: u32, floor: u32) -> Result<Scene> {
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
trilinear_refine_px = 0

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
    println!(
        "Table 1, reflection (Hou et al. 2006): mirror sphere, cube and floor at 800 x 600, flat \
         shading; whole frame (main view by method trilinear, reflection by camera triangles); \
         median of {} renders.",
        args.repeat
    );
    println!(
        "{:>7} {:>6} {:>6} | {:>6} {:>10} {:>9} {:>8} {:>7} {:>8} | paper: {:>10} {:>8} {:>8} {:>5}",
        "camera",
        "scene",
        "bound",
        "cull",
        "bounding",
        "rendered",
        "overdraw",
        "ms",
        "fps",
        "bounding",
        "rendered",
        "overdraw",
        "fps"
    );
    for (tessellation, paper) in TESSELLATIONS.iter().zip(PAPER) {
        let scene = reflection_scene(*tessellation, 7)?;
        let prepared = PreparedScene::new(&scene);
        let main = scene.projection.build(800, 600)?;
        for bound in [Bound::Paper, Bound::Tight] {
            for cull in [false, true] {
                let options = RenderOptions {
                    method: Method::CameraTriangles,
                    shading: Shading::Flat,
                    camera_triangles: CameraTriangleOptions { bound, cull },
                    ..RenderOptions::default()
                };
                let (timing, rendered) = measure(args.repeat, || {
                    render::render(&prepared, main.as_ref(), &options)
                })?;
                let c = &rendered.counters;
                let ms = timing.median_ms();
                println!(
                    "{:>7} {:>6} {:>6} | {:>6} {:>10} {:>9} {:>8.2} {:>7.1} {:>8.1} | {:>17} {:>8} {:>8} {:>5}",
                    count(c, "camera_triangles"),
                    prepared_triangles(&scene),
                    format!("{bound:?}").to_lowercase(),
                    if cull { "on" } else { "off" },
                    count(c, "bounding_fragments"),
                    count(c, "rendered_fragments"),
                    value(c, "overdraw"),
                    ms,
                    1e3 / ms,
                    paper.1,
                    paper.2,
                    paper.3,
                    paper.4,
                );
            }
        }
    }
    five_thousand(args.repeat)
}

/// The 5,000-triangle mirror-sphere target (module doc).
fn five_thousand(repeat: u32) -> Result<()> {
    let scene = reflection_scene(10, 50)?;
    let prepared = PreparedScene::new(&scene);
    let main = scene.projection.build(800, 600)?;
    let options = |method| RenderOptions {
        method,
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let ours_options = options(Method::CameraTriangles);
    let (ours_time, ours) = measure(repeat, || {
        render::render(&prepared, main.as_ref(), &ours_options)
    })?;
    let mut exact_scene = scene.clone();
    exact_scene.trilinear_reflectors.clear();
    let exact = PreparedScene::new(&exact_scene);
    let raycast_options = options(Method::Raycast);
    let (ray_time, reference) = measure(repeat, || {
        render::render(&exact, main.as_ref(), &raycast_options)
    })?;
    let id = scene.trilinear_reflectors[0].id;
    let (same, pixels) = colour_agreement_inside(&ours.frame, &reference.frame, id);
    let rgb = compare(&ours.frame, &reference.frame)?.relative_rgb_error;
    println!();
    println!(
        "Mirror sphere over {} scene triangles at 800 x 600, flat: camera triangles {:.1} ms \
         ({} camera triangles, overdraw {:.2}), raycast {:.1} ms: ratio {:.2} (target <= 0.5); \
         reflector pixels away from colour edges with the exact colour {:.4} of {pixels} \
         (target >= 0.99); relative RGB error of the frame {:.5}",
        prepared_triangles(&scene),
        ours_time.median_ms(),
        count(&ours.counters, "camera_triangles"),
        value(&ours.counters, "overdraw"),
        ray_time.median_ms(),
        ours_time.median_ms() / ray_time.median_ms(),
        same,
        rgb
    );
    Ok(())
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

/// The fraction of the reference's pixels of object `id` whose colour (over the pixel's
/// 3 x 3 neighbourhood in the reference) is uniform that `frame` gives exactly, and their
/// number.
fn colour_agreement_inside(frame: &Frame, reference: &Frame, id: u32) -> (f64, u64) {
    let (w, h) = (reference.width as usize, reference.height as usize);
    let (mut pixels, mut same) = (0u64, 0u64);
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let k = y * w + x;
            let colour = reference.color[k];
            let uniform = (y - 1..=y + 1).all(|yy| {
                (x - 1..=x + 1).all(|xx| {
                    let n = yy * w + xx;
                    reference.ids[n] == id
                        && (reference.color[n] - colour).abs().max_element() < 1e-6
                })
            });
            if uniform {
                pixels += 1;
                same += u64::from((frame.color[k] - colour).abs().max_element() < 1e-6);
            }
        }
    }
    (same as f64 / pixels.max(1) as f64, pixels)
}

fn count(stats: &render::Stats, name: &str) -> u64 {
    match stats.get(name) {
        Some(Counter::Count(n)) => *n,
        _ => 0,
    }
}

fn value(stats: &render::Stats, name: &str) -> f64 {
    match stats.get(name) {
        Some(Counter::Value(v)) => *v,
        Some(Counter::Count(n)) => *n as f64,
        None => f64::NAN,
    }
}
