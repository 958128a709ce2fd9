//! End-to-end tests of caustics (object key `caustics = true`, docs/camera-triangles.md):
//! `flexcam render` adds the caustic of the example scenes (mirror and glass) by camera
//! triangles and by the ray caster's exact photon map, `flexcam compare` measures one against
//! the other, and bad caustic keys fail with one line naming the file and key.

use tempfile::TempDir;

mod common;
use common::{run, run_json, run_ok};

/// The example scene `name`, by absolute path (its model is relative to it).
fn scene_path(name: &str) -> String {
    format!("{}/../../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// The mirror example.
fn example() -> String {
    scene_path("camtri-caustics")
}

/// Both photon maps light the floor: the stats count photons, caustic triangles and lit
/// pixels, and the lit image is brighter than the same render without caustics.
#[test]
fn render_adds_the_caustic_by_camera_triangles_and_ray_casting() {
    let dir = TempDir::new().unwrap();
    let scene = example();
    for method in ["camera-triangles", "raycast"] {
        let stats = run_json(
            &dir,
            &[
                "render", &scene, "--method", method, "--width", "120", "--stats", "-", "-o",
                "c.png",
            ],
        );
        for key in ["caustic_photons", "caustic_triangles", "caustic_pixels"] {
            assert!(
                stats[key].as_u64().unwrap() > 200,
                "{method} {key}: {stats}"
            );
        }
        assert!(stats["caustic_ms"].as_f64().is_some(), "{stats}");
    }
    // Flat shading has no light, so no caustics.
    let flat = run_json(
        &dir,
        &[
            "render",
            &scene,
            "--shading",
            "flat",
            "--width",
            "60",
            "--stats",
            "-",
            "-o",
            "f.png",
        ],
    );
    assert!(flat.get("caustic_triangles").is_none(), "{flat}");
}

/// `flexcam compare --shading lit` measures the camera-triangle frame, caustic included,
/// against the ray caster's exact mirror and exact caustic.
#[test]
fn compare_measures_the_caustic_against_the_exact_one() {
    let dir = TempDir::new().unwrap();
    assert_lit_frame_close(&dir, &example(), &["--width", "120"]);
}

/// `flexcam compare SCENE --method camera-triangles --shading lit` (with `extra`) finds the
/// frame, caustic included, within 5 % relative RGB error of the ray caster's.
fn assert_lit_frame_close(dir: &TempDir, scene: &str, extra: &[&str]) {
    let mut args = vec![
        "compare",
        scene,
        "--method",
        "camera-triangles",
        "--shading",
        "lit",
        "--json",
    ];
    args.extend_from_slice(extra);
    let report = run_json(dir, &args);
    let rgb = report["relative_rgb_error"].as_f64().unwrap();
    assert!(rgb < 0.05, "{report}");
}

/// The glass example at its own size: both photon maps light the floor; the main view's
/// refraction surface counts the edges across the cap's silhouette (where the exact image
/// jumps) apart, and the warning names only the edges over the tolerance; the lit frame,
/// caustic included, is close to the ray caster's.
#[test]
fn the_glass_caustic_renders_by_camera_triangles_and_ray_casting() {
    let dir = TempDir::new().unwrap();
    let scene = scene_path("camtri-caustic-glass");
    for method in ["camera-triangles", "raycast"] {
        let args = [
            "render", &scene, "--method", method, "--stats", "-", "-o", "g.png",
        ];
        let out = run_ok(&dir, &args);
        let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(stats["caustic_pixels"].as_u64().unwrap() > 1000, "{stats}");
        if method == "camera-triangles" {
            let stderr = String::from_utf8_lossy(&out.stderr);
            let unsplit = stats["reflector_unsplit_edges"].as_u64().unwrap();
            assert!(
                stats["reflector_silhouette_edges"].as_u64().unwrap() > 0,
                "{stats}"
            );
            assert!(
                unsplit == 0 || stderr.contains(&format!("{unsplit} edges")),
                "{stderr}"
            );
        }
    }
    assert_lit_frame_close(&dir, &scene, &[]);
}

const FLAT_MIRROR: &str = r#"
[projection]
type = "perspective"
position = [0.0, 1.0, 6.0]
look_at = [0.0, 0.0, 0.0]
fov = 60.0

[[object]]
name = "mirror"
shape = "plane"
size = [1.0, 1.0]
material = "mirror"
rotate = [180.0, 0.0, 0.0]
translate = [0.0, 2.0, 0.0]
caustics = true

[[object]]
name = "floor"
shape = "plane"
size = [20.0, 20.0]

[[light]]
type = "point"
position = [0.2, 1.0, 0.1]
"#;

/// Bad caustic keys: one line on stderr naming the file, line and key; no image.
#[test]
fn bad_caustic_keys_are_refused() {
    let dir = TempDir::new().unwrap();
    let cases = [
        (
            FLAT_MIRROR.replace("caustics = true", "caustics = true\ncaustic_map = 3"),
            "`caustic_map` must be between 8 and 2048 texels, not 3",
        ),
        (
            FLAT_MIRROR.replace("caustics = true", "caustic_map = 64"),
            "`caustic_map` needs `caustics = true`",
        ),
        (
            FLAT_MIRROR.replace("material = \"mirror\"", "material = \"diffuse\""),
            "`caustics` needs material \"mirror\" or \"glass\", but \"mirror\" is diffuse",
        ),
        (
            FLAT_MIRROR
                .replace(
                    "type = \"point\"",
                    "type = \"directional\"\ndirection = [0.0, 1.0, 0.0]",
                )
                .replace("position = [0.2, 1.0, 0.1]\n", ""),
            "`caustics` needs a point light",
        ),
        (
            FLAT_MIRROR.replace("position = [0.2, 1.0, 0.1]", "position = [0.0, 2.1, 0.0]"),
            "inside the reflector's bounding sphere",
        ),
    ];
    for (text, message) in cases {
        std::fs::write(dir.path().join("bad.toml"), text).unwrap();
        let out = run(&dir, &["render", "bad.toml", "-o", "bad.png"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{message}");
        assert!(
            stderr.contains("bad.toml") && stderr.contains(message),
            "{stderr}"
        );
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!dir.path().join("bad.png").exists());
    }
    // The raster method has no photon map.
    std::fs::write(dir.path().join("ok.toml"), FLAT_MIRROR).unwrap();
    let out = run(
        &dir,
        &["render", "ok.toml", "--method", "raster", "-o", "r.png"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("not raster"),
        "{stderr}"
    );
}
