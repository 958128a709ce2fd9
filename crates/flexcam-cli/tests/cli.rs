//! End-to-end tests of the `flexcam` binary: real renders, and every kind of bad input of the
//! scene-and-CLI spec (one error line, non-zero exit, no output file).

use std::fs;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use tempfile::TempDir;

fn flexcam(dir: &Path) -> Command {
    let mut cmd = Command::cargo_bin("flexcam").expect("flexcam binary");
    cmd.current_dir(dir);
    cmd
}

/// A small valid scene: a red sphere on a checker floor, perspective camera.
const GOOD_SCENE: &str = r#"
[image]
width = 64
height = 48

[projection]
type = "perspective"
position = [0.0, 1.0, 5.0]
look_at = [0.0, 0.5, 0.0]
fov = 60.0

[[object]]
name = "floor"
shape = "plane"
size = [20.0, 20.0]
checker = { color = [0.1, 0.1, 0.1], size = 1.0 }

[[object]]
name = "ball"
shape = "sphere"
size = 1.0
color = [1.0, 0.0, 0.0]
translate = [0.0, 1.0, 0.0]
"#;

fn write(dir: &TempDir, name: &str, text: &str) -> PathBuf {
    let path = dir.path().join(name);
    fs::write(&path, text).unwrap();
    path
}

/// Runs a render expected to fail; returns its single stderr line and checks that no output
/// file was left behind.
fn expect_failure(dir: &TempDir, args: &[&str]) -> String {
    let out = flexcam(dir.path()).args(args).output().unwrap();
    assert!(!out.status.success(), "expected failure for {args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "expected exactly one error line, got: {stderr:?}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let leftovers: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml"))
        .collect();
    assert!(leftovers.is_empty(), "partial output left: {leftovers:?}");
    stderr.trim_end().to_string()
}

#[test]
fn default_render_writes_a_real_image() {
    let dir = TempDir::new().unwrap();
    flexcam(dir.path())
        .args(["render", "--width", "160", "--height", "80"])
        .assert()
        .success();
    let img = image::open(dir.path().join("flexcam.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(img.dimensions(), (160, 80));
    let distinct: std::collections::HashSet<_> = img.pixels().map(|p| p.0).collect();
    assert!(
        distinct.len() > 50,
        "image looks blank: {} colours",
        distinct.len()
    );
}

#[test]
fn scenes_lists_the_required_builtins() {
    let dir = TempDir::new().unwrap();
    let out = flexcam(dir.path()).arg("scenes").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    for required in ["default", "cube-floor", "teapot-room"] {
        assert!(names.contains(&required), "{required} missing from {text}");
    }
    assert!(
        text.lines().all(|l| l.split_whitespace().count() >= 2),
        "{text}"
    );
}

#[test]
fn flat_render_with_all_outputs_and_stats_on_stdout() {
    let dir = TempDir::new().unwrap();
    write(&dir, "s.toml", GOOD_SCENE);
    let out = flexcam(dir.path())
        .args([
            "render",
            "s.toml",
            "-o",
            "c.png",
            "--shading",
            "flat",
            "--depth",
            "d.exr",
            "--ids",
            "i.png",
            "--stats",
            "-",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON object");
    for key in [
        "method",
        "width",
        "height",
        "triangles",
        "render_ms",
        "rays_cast",
        "bvh_build_ms",
    ] {
        assert!(json.get(key).is_some(), "stats lack {key}: {json}");
    }
    assert_eq!(json["method"], "raycast");
    assert_eq!(json["width"], 64);
    assert!(json["rays_cast"].as_u64().unwrap() >= 64 * 48);

    // Flat colours round-trip: the sphere's centre pixel is exactly its base colour.
    let img = image::open(dir.path().join("c.png")).unwrap().to_rgb8();
    let ids = image::open(dir.path().join("i.png")).unwrap().to_luma16();
    let (cx, cy) = (32, 48 / 2);
    let (mut found_ball, mut found_floor) = (false, false);
    for (x, y, p) in ids.enumerate_pixels() {
        match p.0[0] {
            2 => {
                found_ball = true;
                assert_eq!(img.get_pixel(x, y).0, [255, 0, 0]);
            }
            1 => {
                found_floor = true;
                let c = img.get_pixel(x, y).0;
                assert!(
                    c == [204, 204, 204] || c == [26, 26, 26],
                    "floor colour {c:?}"
                );
            }
            _ => {}
        }
    }
    assert!(found_ball && found_floor);
    assert!(ids.get_pixel(cx, cy).0[0] == 2);
    assert!(dir.path().join("d.exr").exists());
}

#[test]
fn stats_and_depth_to_files() {
    let dir = TempDir::new().unwrap();
    write(&dir, "s.toml", GOOD_SCENE);
    flexcam(dir.path())
        .args([
            "render", "s.toml", "--depth", "d.pfm", "--stats", "st.json", "--spp", "4",
        ])
        .assert()
        .success()
        .stdout("");
    let json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.path().join("st.json")).unwrap()).unwrap();
    assert_eq!(json["spp"], 4);
    let pfm = fs::read(dir.path().join("d.pfm")).unwrap();
    assert!(pfm.starts_with(b"Pf\n64 48\n"));
}

#[test]
fn missing_scene_file() {
    let dir = TempDir::new().unwrap();
    let e = expect_failure(&dir, &["render", "nope.toml"]);
    assert!(e.contains("nope.toml"), "{e}");
}

#[test]
fn unknown_builtin_scene() {
    let dir = TempDir::new().unwrap();
    let e = expect_failure(&dir, &["render", "builtin:no-such-scene"]);
    assert!(
        e.contains("no-such-scene") && e.contains("cube-floor"),
        "{e}"
    );
}

#[test]
fn toml_syntax_error_has_line_and_column() {
    let dir = TempDir::new().unwrap();
    write(&dir, "bad.toml", "[image]\nwidth = 64\nheight = = 3\n");
    let e = expect_failure(&dir, &["render", "bad.toml"]);
    assert!(e.contains("bad.toml:3:"), "{e}");
}

#[test]
fn unknown_projection_type_is_located() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("type = \"perspective\"", "type = \"perspektive\"");
    write(&dir, "bad.toml", &text);
    let e = expect_failure(&dir, &["render", "bad.toml"]);
    let line = text
        .lines()
        .position(|l| l.contains("perspektive"))
        .unwrap()
        + 1;
    assert!(e.contains(&format!("bad.toml:{line}:")), "{e}");
    assert!(e.contains("perspektive"), "{e}");
}

#[test]
fn nan_value_is_located() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("fov = 60.0", "fov = nan");
    write(&dir, "bad.toml", &text);
    let e = expect_failure(&dir, &["render", "bad.toml"]);
    let line = text.lines().position(|l| l.contains("nan")).unwrap() + 1;
    assert!(e.contains(&format!("bad.toml:{line}:")), "{e}");
}

#[test]
fn degenerate_projection() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("look_at = [0.0, 0.5, 0.0]", "look_at = [0.0, 1.0, 5.0]");
    write(&dir, "bad.toml", &text);
    let e = expect_failure(&dir, &["render", "bad.toml"]);
    assert!(e.contains("bad.toml"), "{e}");
}

#[test]
fn unknown_shape_and_key() {
    let dir = TempDir::new().unwrap();
    write(
        &dir,
        "a.toml",
        &GOOD_SCENE.replace("shape = \"sphere\"", "shape = \"spere\""),
    );
    let e = expect_failure(&dir, &["render", "a.toml"]);
    assert!(e.contains("a.toml:") && e.contains("spere"), "{e}");
    write(
        &dir,
        "b.toml",
        &GOOD_SCENE.replace("translate =", "translat ="),
    );
    let e = expect_failure(&dir, &["render", "b.toml"]);
    assert!(e.contains("b.toml:") && e.contains("translat"), "{e}");
}

#[test]
fn missing_model_file_names_it() {
    let dir = TempDir::new().unwrap();
    let text =
        format!("{GOOD_SCENE}\n[[object]]\nshape = \"mesh\"\nfile = \"models/missing.obj\"\n");
    write(&dir, "m.toml", &text);
    let e = expect_failure(&dir, &["render", "m.toml"]);
    assert!(e.contains("missing.obj"), "{e}");
}

#[test]
fn absurd_resolution() {
    let dir = TempDir::new().unwrap();
    write(&dir, "s.toml", GOOD_SCENE);
    for args in [
        ["render", "s.toml", "--width", "0"],
        ["render", "s.toml", "--width", "1000000"],
    ] {
        expect_failure(&dir, &args);
    }
    write(
        &dir,
        "big.toml",
        &GOOD_SCENE.replace("width = 64", "width = 0"),
    );
    let e = expect_failure(&dir, &["render", "big.toml"]);
    assert!(e.contains("big.toml:3:"), "{e}");
}

#[test]
fn bad_flags() {
    let dir = TempDir::new().unwrap();
    write(&dir, "s.toml", GOOD_SCENE);
    let e = expect_failure(&dir, &["render", "s.toml", "--method", "magic"]);
    assert!(e.contains("magic") && e.contains("raycast"), "{e}");
    expect_failure(&dir, &["render", "s.toml", "--spp", "0"]);
    expect_failure(&dir, &["render", "s.toml", "--shading", "glossy"]);
    let e = expect_failure(&dir, &["render", "s.toml", "-o", "out.jpg"]);
    assert!(e.contains("out.jpg"), "{e}");
    let e = expect_failure(&dir, &["render", "s.toml", "--depth", "d.png"]);
    assert!(e.contains("d.png"), "{e}");
    let e = expect_failure(&dir, &["render", "s.toml", "-o", "no/such/dir/x.png"]);
    assert!(e.contains("x.png"), "{e}");
}

/// Every example scene in scenes/ renders (flat, small), so the examples stay true.
#[test]
fn every_example_scene_renders() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut rendered = 0;
    for entry in fs::read_dir(&scenes).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let dir = TempDir::new().unwrap();
            let out = flexcam(dir.path())
                .arg("render")
                .arg(&path)
                .args(["--width", "48", "--height", "32", "--shading", "flat"])
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}: {}",
                path.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            rendered += 1;
        }
    }
    assert!(rendered >= 5, "only {rendered} example scenes found");
}

#[test]
fn trilinear_method_renders_a_trilinear_scene_and_refuses_others() {
    let fan = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/trilinear-fan.toml");
    let dir = TempDir::new().unwrap();
    for curves in ["tessellate", "slice", "adaptive"] {
        let out = flexcam(dir.path())
            .arg("render")
            .arg(&fan)
            .args(["--width", "60", "--height", "40", "--shading", "flat"])
            .args([
                "--method",
                "trilinear",
                "--curves",
                curves,
                "--curve-steps",
                "4",
            ])
            .args(["--stats", "-"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{curves}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["method"], "trilinear");
        assert_eq!(json["curve_steps"], 4);
        assert!(json["shapes"].as_u64().unwrap() > 0, "{json}");
        assert!(json["raster_covered"].as_u64().unwrap() > 0, "{json}");
    }
    // A fresh folder: the renders above left flexcam.png, and failures must leave nothing.
    let dir = TempDir::new().unwrap();
    write(&dir, "s.toml", GOOD_SCENE);
    let e = expect_failure(&dir, &["render", "s.toml", "--method", "trilinear"]);
    assert!(e.contains("only trilinear projections"), "{e}");
    let e = expect_failure(
        &dir,
        &[
            "render",
            "s.toml",
            "--method",
            "trilinear",
            "--curves",
            "bezier",
        ],
    );
    assert!(e.contains("bezier"), "{e}");
    let e = expect_failure(
        &dir,
        &[
            "render",
            "s.toml",
            "--method",
            "trilinear",
            "--curve-steps",
            "0",
        ],
    );
    assert!(e.contains("curve steps"), "{e}");
}
