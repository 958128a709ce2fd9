//! The stereo panoramas from the command line: the example scenes render alike by ray
//! casting and by rasterisation (each eye drawn by its own inverse), and what the raster or
//! the scene file cannot take is refused with one line naming the cause.

mod common;

use std::path::Path;

use common::run_json;
use tempfile::TempDir;

fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/cameras")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// `scenes/cameras/ods-teapot.toml` and `vr180-teapot.toml`, raster against the ray caster
/// (flat shading): object ids agree but for silhouette pixels, depth and colour match.
#[test]
fn stereo_example_scenes_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    for name in ["ods-teapot.toml", "vr180-teapot.toml"] {
        let scene = example(name);
        let report = run_json(
            &dir,
            &[
                "compare",
                &scene,
                "--method",
                "raster",
                "--shading",
                "flat",
                "--json",
            ],
        );
        let agreement = report["id_agreement"].as_f64().unwrap();
        let depth = report["depth_mean"].as_f64().unwrap();
        let rgb = report["relative_rgb_error"].as_f64().unwrap();
        assert!(agreement >= 0.999, "{name}: id agreement {agreement}");
        assert!(depth < 1e-4, "{name}: mean relative depth error {depth}");
        assert!(rgb < 0.002, "{name}: relative RGB error {rgb}");
    }
}

/// Runs `render scene.toml` with `text` as the scene and asserts the one-line refusal
/// containing `expected`, exit status 1, and no output.
fn refused(dir: &TempDir, text: &str, args: &[&str], expected: &str) {
    let stderr = common::refused_scene(dir, text, args);
    assert!(stderr.contains(expected), "{stderr}");
}

const FLOOR: &str = "\n[[object]]\nname = \"floor\"\nshape = \"plane\"\nsize = [4.0, 4.0]\n";

fn camera(kind: &str, keys: &str, size: [u32; 2]) -> String {
    format!(
        "[image]\nwidth = {}\nheight = {}\n\n[projection]\ntype = \"{kind}\"\n\
         position = [0, 1, 0]\nlook_at = [0, 1, -1]\n{keys}\n{FLOOR}",
        size[0], size[1]
    )
}

#[test]
fn refusals_are_one_line() {
    let dir = TempDir::new().unwrap();
    // Without pole merging the floor under the eye enters the eye cylinder.
    refused(
        &dir,
        &camera("ods", "", [32, 32]),
        &["--method", "raster"],
        "method raster cannot draw object \"floor\" through this ods projection: it touches \
         the vertical cylinder of radius ipd/2 around the eye (no pole merging)",
    );
    // A floor at the eye's height crosses the disc even with merging.
    refused(
        &dir,
        &camera("ods", "pole_merge_from = 60\npole_merge_to = 75", [32, 32])
            .replace("position = [0, 1, 0]", "position = [0, 0, 0]")
            .replace("look_at = [0, 1, -1]", "look_at = [0, 0, -1]"),
        &["--method", "raster"],
        "touches the disc of radius ipd/2 around the eye at its height",
    );
    refused(
        &dir,
        &camera("ods", "pole_merge_from = 60", [32, 32]),
        &[],
        "scene.toml:9:19: ods pole merging needs both `pole_merge_from` and `pole_merge_to`",
    );
    refused(
        &dir,
        &camera("ods", "pole_merge_from = 80\npole_merge_to = 75", [32, 32]),
        &[],
        "ods pole merging needs 0 <= pole_merge_from < pole_merge_to <= 90 degrees",
    );
    refused(
        &dir,
        &camera("ods", "", [32, 31]),
        &[],
        "ods needs an even image height (one half per eye), got 32x31",
    );
    refused(
        &dir,
        &camera("vr180", "ipd = -1", [32, 32]),
        &[],
        "vr180 ipd must be a positive length, got -1",
    );
    refused(
        &dir,
        &camera("vr180", "", [32, 32]),
        &["--width", "33", "--height", "32"],
        "vr180 needs an even image width (one half per eye), got 33x32",
    );
    refused(
        &dir,
        &camera("vr180", "pole_merge_from = 60", [32, 32]),
        &[],
        "pole_merge_from",
    );
}
