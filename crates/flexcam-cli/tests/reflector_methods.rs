//! End-to-end tests of trilinear reflectors rendered by the fast methods (robustness audit 3,
//! docs/robustness.md): `--method trilinear` renders the whole frame of a reflector scene (the
//! perspective main view as two projection triangles, the reflection through the
//! reflector's surface), and `flexcam compare` measures that composite against the ray
//! caster's exact mirror.

use tempfile::TempDir;

mod common;
use common::{run_json, run_ok};

/// A plane mirror (4 x 4 quads, facing +z) reflecting a cube and a checker floor; not one
/// of the example scenes.
const PLANE_MIRROR: &str = r#"
[image]
width = 120
height = 90
background = [0.3, 0.4, 0.6]

[projection]
type = "perspective"
position = [0.5, 1.5, 4.0]
look_at = [0.0, 1.2, -1.0]
fov = 60.0

[[object]]
name = "mirror"
shape = "plane"
size = [3.0, 2.0]
tessellation = 4
material = "mirror"
rotate = [90.0, 0.0, 0.0]
translate = [0.0, 1.2, -1.0]
trilinear_reflector = true

[[object]]
name = "cube"
shape = "box"
size = [1.0, 1.0, 1.0]
face_colors = [[0.9, 0.15, 0.1], [0.1, 0.75, 0.8], [0.2, 0.8, 0.2], [0.8, 0.2, 0.8], [0.15, 0.3, 0.9], [0.95, 0.8, 0.1]]
translate = [0.7, 0.5, 1.2]
rotate = [0.0, 30.0, 0.0]

[[object]]
name = "floor"
shape = "plane"
size = [12.0, 12.0]
tessellation = 12
checker = { color = [0.1, 0.1, 0.1], size = 0.5 }
"#;

fn mirror_scene() -> TempDir {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("mirror.toml"), PLANE_MIRROR).unwrap();
    dir
}

/// Before audit 3, `flexcam render SCENE --method trilinear` on any scene with a trilinear
/// reflector failed ("the trilinear method renders only trilinear projections, not a
/// perspective projection"), so the reflection surfaces were never rendered by the fast
/// renderer they are made for. Now it renders, with the reflector's counters.
#[test]
fn trilinear_method_renders_reflector_scenes() {
    let dir = mirror_scene();
    let args = [
        "render",
        "mirror.toml",
        "--method",
        "trilinear",
        "--shading",
        "flat",
        "--stats",
        "-",
        "-o",
        "m.png",
    ];
    let stats = run_json(&dir, &args);
    assert_eq!(stats["method"], "trilinear");
    assert_eq!(stats["reflectors"], 1);
    assert!(
        stats["reflector_pixels"].as_u64().unwrap() > 1000,
        "{stats}"
    );
    assert_eq!(stats["reflector_exact_pixels"], 0, "{stats}");
    assert!(dir.path().join("m.png").is_file());
}

/// `flexcam compare` composites the method under test (as `render` does) and compares it
/// with the ray caster's exact mirror. A plane mirror's surface with
/// `trilinear_screen_map = "projective"` is the exact mirror up to rounding at colour edges,
/// for both methods; with the default affine map (the screen-space interpolation of Vallance 2005) the
/// interpolated rays move checker edges, still within the trilinear targets of docs/trilinear-raster.md, and the trilinear
/// composite is the ray-cast composite but for edge pixels.
#[test]
fn compare_measures_the_composite_against_the_exact_mirror() {
    let dir = mirror_scene();
    let projective = PLANE_MIRROR.replace(
        "trilinear_reflector = true",
        "trilinear_reflector = true\ntrilinear_screen_map = \"projective\"",
    );
    std::fs::write(dir.path().join("projective.toml"), projective).unwrap();
    for (scene, largest) in [("projective.toml", 1e-3), ("mirror.toml", 0.02)] {
        let mut measured = Vec::new();
        for method in ["trilinear", "raycast"] {
            let args = ["compare", scene, "--method", method, "--json"];
            let report = run_json(&dir, &args);
            let ids = report["id_agreement"].as_f64().unwrap();
            let rgb = report["relative_rgb_error"].as_f64().unwrap();
            assert!(ids >= 0.995 && rgb <= largest, "{scene} {method}: {report}");
            measured.push(rgb);
        }
        assert!((measured[0] - measured[1]).abs() < 0.002, "{measured:?}");
        if scene == "mirror.toml" {
            // Not the exact mirror: the interpolated rays move checker edges.
            assert!(measured[0] > 1e-4, "{measured:?}");
        }
    }
}

/// `--method camera-triangles` renders the reflector's surface by camera triangles (Hou et
/// al. 2006): both bounds give the same image, the fragment counters are reported and
/// `overdraw` is bounding over rendered fragments; `--bound` is refused with another method.
#[test]
fn camera_triangles_render_reflector_scenes_with_either_bound() {
    let dir = mirror_scene();
    let mut images = Vec::new();
    for bound in ["paper", "tight"] {
        let out = format!("{bound}.png");
        let args = [
            "render",
            "mirror.toml",
            "--method",
            "camera-triangles",
            "--bound",
            bound,
            "--shading",
            "flat",
            "--stats",
            "-",
            "-o",
            &out,
        ];
        let stats = run_json(&dir, &args);
        assert_eq!(stats["method"], "camera-triangles");
        let bounding = stats["bounding_fragments"].as_u64().unwrap();
        let rendered = stats["rendered_fragments"].as_u64().unwrap();
        assert!(rendered > 1000 && bounding >= rendered, "{stats}");
        let overdraw = stats["overdraw"].as_f64().unwrap();
        assert!((overdraw - bounding as f64 / rendered as f64).abs() < 1e-9);
        assert!(stats["camera_triangles"].as_u64().unwrap() > 0);
        images.push(std::fs::read(dir.path().join(&out)).unwrap());
    }
    assert_eq!(images[0], images[1]);
    let refused = common::run(
        &dir,
        &[
            "render",
            "mirror.toml",
            "--method",
            "raycast",
            "--bound",
            "paper",
            "-o",
            "r.png",
        ],
    );
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("--bound applies to --method camera-triangles, not raycast"),
        "{stderr}"
    );
    let report = run_json(
        &dir,
        &[
            "compare",
            "mirror.toml",
            "--method",
            "camera-triangles",
            "--json",
        ],
    );
    assert!(
        report["id_agreement"].as_f64().unwrap() >= 0.995,
        "{report}"
    );
}

/// The perspective camera `(position, look_at)` of the plane mirror scene as a key of a
/// flexible `animate` table.
fn animation_key(time: f64, position: &str) -> String {
    format!(
        "\n[[animation.key]]\ntime = {time}\n[animation.key.projection]\ntype = \"flexible\"\n\
         preset = \"perspective\"\nposition = {position}\nlook_at = [0.0, 1.2, -1.0]\n\
         fov = 60.0\n"
    )
}

/// Mean absolute difference of two 8-bit images' RGB, in [0, 1].
fn mean_rgb_difference(a: &std::path::Path, b: &std::path::Path) -> f64 {
    let (a, b) = (
        image::open(a).unwrap().to_rgb8(),
        image::open(b).unwrap().to_rgb8(),
    );
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: f64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(&x, &y)| f64::from(x.abs_diff(y)))
        .sum();
    sum / (255.0 * a.as_raw().len() as f64)
}

/// An animated reflector scene composites each frame through that frame's camera: frame 1
/// of `animate` (the second key, a camera moved to the left) matches `render` of the scene
/// with that camera, by every method that composites reflectors. Before, the composite took
/// its camera from the scene's `[projection]`, so the fast methods drew every frame from the
/// first camera.
#[test]
fn animated_reflector_frames_use_each_frames_camera() {
    let dir = TempDir::new().unwrap();
    let (first, moved) = ("[0.5, 1.5, 4.0]", "[-1.5, 2.0, 3.5]");
    let animated = format!(
        "{PLANE_MIRROR}\n[animation]\nframes = 2\nfps = 1.0\n{}{}",
        animation_key(0.0, first),
        animation_key(1.0, moved)
    );
    std::fs::write(dir.path().join("animated.toml"), animated).unwrap();
    let still = PLANE_MIRROR.replace(
        &format!("position = {first}"),
        &format!("position = {moved}"),
    );
    assert_ne!(still, PLANE_MIRROR);
    std::fs::write(dir.path().join("moved.toml"), still).unwrap();
    for method in ["raycast", "trilinear", "camera-triangles"] {
        let frames = format!("{method}-#.png");
        let moved_png = format!("{method}-moved.png");
        let flat = ["--method", method, "--shading", "flat"];
        let animate = [
            &["animate", "animated.toml", "-o", &frames, "--frames", "1"],
            &flat[..],
        ];
        run_ok(&dir, &animate.concat());
        let render = [&["render", "moved.toml", "-o", &moved_png], &flat[..]];
        run_ok(&dir, &render.concat());
        let path = |name: &str| dir.path().join(name);
        let difference = mean_rgb_difference(&path(&format!("{method}-1.png")), &path(&moved_png));
        assert!(
            difference < 0.002,
            "{method}: mean RGB difference {difference}"
        );
    }
}

/// Objects that move (`orbit`) are where each frame's time puts them, by every method that
/// composites reflectors: frame 1 of `animate` (a quarter turn of the cube about the vertical
/// line through the origin, so that the mirror shows it from another side) matches `render`
/// of a still scene with the cube placed there, and frame 0 is the file as written, byte for
/// byte.
#[test]
fn moving_objects_are_where_each_frames_time_puts_them() {
    let dir = mirror_scene();
    let cube = "translate = [0.7, 0.5, 1.2]\nrotate = [0.0, 30.0, 0.0]\n";
    assert!(PLANE_MIRROR.contains(cube));
    // A quarter turn about +y (period 4 s, frame 1 of 1 frame per second) takes (x, y, z) to
    // (z, y, -x) and adds 90 degrees to the cube's turn about y.
    let orbiting = PLANE_MIRROR.replace(
        cube,
        &format!("{cube}orbit = {{ center = [0.0, 0.0, 0.0], period = 4.0 }}\n"),
    );
    let animated = format!("{orbiting}\n[animation]\nframes = 2\nfps = 1.0\n");
    std::fs::write(dir.path().join("animated.toml"), animated).unwrap();
    let moved = PLANE_MIRROR.replace(
        cube,
        "translate = [1.2, 0.5, -0.7]\nrotate = [0.0, 120.0, 0.0]\n",
    );
    std::fs::write(dir.path().join("moved.toml"), moved).unwrap();
    let path = |name: &str| dir.path().join(name);
    for method in ["raycast", "trilinear", "camera-triangles"] {
        let frames = format!("{method}-#.png");
        let (moved_png, still_png) = (format!("{method}-moved.png"), format!("{method}-still.png"));
        let flat = ["--method", method, "--shading", "flat"];
        run_ok(
            &dir,
            &[&["animate", "animated.toml", "-o", &frames][..], &flat].concat(),
        );
        run_ok(
            &dir,
            &[&["render", "moved.toml", "-o", &moved_png][..], &flat].concat(),
        );
        run_ok(
            &dir,
            &[&["render", "mirror.toml", "-o", &still_png][..], &flat].concat(),
        );
        let difference = mean_rgb_difference(&path(&format!("{method}-1.png")), &path(&moved_png));
        assert!(
            difference < 0.002,
            "{method}: mean RGB difference {difference}"
        );
        // The cube did move: frame 1 is not the still scene.
        let unmoved = mean_rgb_difference(&path(&format!("{method}-1.png")), &path(&still_png));
        assert!(
            unmoved > 0.01,
            "{method}: frame 1 is the still scene ({unmoved})"
        );
    }
    run_ok(&dir, &["render", "mirror.toml", "-o", "time0.png"]);
    run_ok(
        &dir,
        &[
            "animate",
            "animated.toml",
            "-o",
            "lit-#.png",
            "--frames",
            "0",
        ],
    );
    assert_eq!(
        std::fs::read(path("time0.png")).unwrap(),
        std::fs::read(path("lit-0.png")).unwrap()
    );
}
