//! Figure 6 of Hou, Wei, Shum and Guo 2006: the quality of a curved reflection per camera
//! tessellation level. Each reflector scene is rendered by camera triangles with its
//! reflector's camera mesh simplified to 8, 16, 32, ... triangles and at the reflector's own
//! mesh (object key `camera_triangles = N`, used unrefined), and with the automatic size
//! (no key); each frame is compared with the exact mirror (the reflector a plain mirror,
//! `--method raycast`) over the pixels where that mirror is seen: the agreement of the
//! reflected content (`measures`) and the relative RGB error, with the whole frame's time.
//! The reflector pixels that the camera mesh's surface does not cover (a coarse mesh lies
//! inside a convex reflector, so its outline shrinks) are not ray cast here
//! (`RenderOptions::cast_reflector_gaps` off): they count as errors, so the figure measures
//! the camera triangles alone, as the paper's does.
//!
//! Scenes: Table 1's reflection scene with a finer sphere (960 triangles, so that the series
//! reaches the paper's 26, 104 and 416 camera triangles and beyond), `camtri-convex.toml`
//! and `camtri-mixed.toml` (a torus: convex outside, saddle-shaped inside).

use flexcam::render::{Method, PreparedScene, RenderOptions, Shading};
use flexcam::scene::{self, file::Definition, ModelRequest, Scene};
use flexcam::Result;

use super::measures::{colour_agreement_inside, count, relative_rgb_inside};
use super::{reflection_scene, timed_render, Settings};

/// Sphere tessellation of the figure's reflection scene (960 triangles).
const SPHERE_TESSELLATION: u32 = 32;

/// The smallest camera mesh of the series.
const SMALLEST: usize = 8;

/// A reflector scene of the figure.
enum Subject {
    /// Table 1's reflection scene, its sphere of [`SPHERE_TESSELLATION`].
    Reflection,
    /// A scene file in the bench's scene folder and its reflector object's name.
    File(&'static str, &'static str),
}

const SUBJECTS: [Subject; 3] = [
    Subject::Reflection,
    Subject::File("camtri-convex.toml", "sphere"),
    Subject::File("camtri-mixed.toml", "torus"),
];

impl Subject {
    fn name(&self) -> &'static str {
        match self {
            Subject::Reflection => "reflection",
            Subject::File(file, _) => file.trim_end_matches(".toml"),
        }
    }

    /// The scene with the reflector's camera mesh of `size` triangles (`None`: automatic).
    fn load(&self, settings: &Settings, size: Option<usize>) -> Result<Scene> {
        match self {
            Subject::Reflection => {
                let key = size.map_or(String::new(), |n| format!("camera_triangles = {n}"));
                reflection_scene(SPHERE_TESSELLATION, 7, &key)
            }
            Subject::File(file, object) => {
                let definitions = match size {
                    Some(n) => vec![format!("object.{object}.camera_triangles={n}").parse()?],
                    None => Vec::<Definition>::new(),
                };
                let path = settings.scenes.join(file);
                let request = ModelRequest::default();
                Ok(scene::load_file(&path, &definitions, &request)?.0)
            }
        }
    }
}

/// One render of the figure.
pub struct Row {
    /// The scene's name.
    pub scene: &'static str,
    /// The camera mesh's size (`None`: automatic).
    pub mesh: Option<usize>,
    /// The camera triangles rendered (the stats' `camera_triangles`: the mesh's triangles
    /// facing the eye, refined where the size is automatic).
    pub camera_triangles: u64,
    /// Agreement of the reflected content with the exact mirror, and its pixels.
    pub agreement: f64,
    pub agreement_pixels: u64,
    /// Relative RGB error over the exact mirror's pixels.
    pub rgb: f64,
    /// Reflector pixels no camera triangle covers (left uncast: errors).
    pub uncovered_pixels: u64,
    /// Median whole-frame milliseconds.
    pub ms: f64,
}

/// Renders the figure, printing its table (markdown) as it goes; the rows for the CSV.
pub fn run(settings: &Settings) -> Result<Vec<Row>> {
    let (width, height) = settings.size((800, 600));
    println!(
        "Figure 6 (Hou et al. 2006): reflection quality per camera mesh size, against the \
         exact mirror (--method raycast), {width} x {height}, flat shading, tight bound, \
         median of {} renders. agreement: reflector pixels away from colour edges with the \
         exact colour (the id agreement of what the mirror shows); rgb: relative RGB error \
         over the reflector's pixels; uncovered px: reflector pixels no camera triangle \
         covers (not ray cast: errors).",
        settings.repeat
    );
    println!();
    println!(
        "| scene | camera mesh | camera tris | agreement | pixels | rgb | uncovered px | ms |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let mut rows = Vec::new();
    for subject in &SUBJECTS {
        let automatic = subject.load(settings, None)?;
        let main = automatic.projection.build(width, height)?;
        let reflector = automatic.trilinear_reflectors.first().ok_or_else(|| {
            flexcam::Error::new(format!("{}: the scene has no reflector", subject.name()))
        })?;
        let id = reflector.id;
        let own = automatic
            .objects
            .iter()
            .filter(|o| o.id == id)
            .map(|o| o.mesh.triangles.len())
            .sum::<usize>();
        let mut exact_scene = automatic.clone();
        exact_scene.trilinear_reflectors.clear();
        let raycast = RenderOptions {
            method: Method::Raycast,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        let exact = PreparedScene::new(&exact_scene);
        let (ray_time, reference) = timed_render(settings.repeat, &exact, main.as_ref(), &raycast)?;
        let sizes = std::iter::successors(Some(SMALLEST), |n| Some(n * 2))
            .take_while(|&n| n < own)
            .map(Some)
            .chain([Some(own), None]);
        for size in sizes {
            let scene = subject.load(settings, size)?;
            let prepared = PreparedScene::new(&scene);
            let options = RenderOptions {
                method: Method::CameraTriangles,
                shading: Shading::Flat,
                cast_reflector_gaps: false,
                ..RenderOptions::default()
            };
            let (timing, ours) = timed_render(settings.repeat, &prepared, main.as_ref(), &options)?;
            let (agreement, agreement_pixels) =
                colour_agreement_inside(&ours.frame, &reference.frame, id, None);
            let row = Row {
                scene: subject.name(),
                mesh: size,
                camera_triangles: count(&ours.counters, "camera_triangles"),
                agreement,
                agreement_pixels,
                rgb: relative_rgb_inside(&ours.frame, &reference.frame, id),
                uncovered_pixels: count(&ours.counters, "reflector_uncovered_pixels"),
                ms: timing.median_ms(),
            };
            println!(
                "| {} | {} | {} | {:.4} | {} | {:.4} | {} | {:.1} |",
                row.scene,
                row.mesh.map_or("auto".to_string(), |n| n.to_string()),
                row.camera_triangles,
                row.agreement,
                row.agreement_pixels,
                row.rgb,
                row.uncovered_pixels,
                row.ms
            );
            rows.push(row);
        }
        println!(
            "| {} | exact mirror (raycast, {own} triangles) | | 1 | | 0 | | {:.1} |",
            subject.name(),
            ray_time.median_ms()
        );
    }
    Ok(rows)
}

/// The CSV of the rows of given size (the automatic one has no place on the size axis):
/// `scene,camera_mesh,camera_triangles,agreement,rgb_error,uncovered_pixels,ms`.
pub fn csv(rows: &[Row]) -> String {
    let mut text = String::from(
        "scene,camera_mesh,camera_triangles,agreement,rgb_error,uncovered_pixels,ms\n",
    );
    for row in rows {
        if let Some(mesh) = row.mesh {
            text += &format!(
                "{},{mesh},{},{:.6},{:.6},{},{:.3}\n",
                row.scene,
                row.camera_triangles,
                row.agreement,
                row.rgb,
                row.uncovered_pixels,
                row.ms
            );
        }
    }
    text
}
