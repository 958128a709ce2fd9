//! End-to-end tests of the `flexcam` binary: real renders, and every kind of bad input of the
//! scene-and-CLI spec (one error line, non-zero exit, no output file).

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use tempfile::TempDir;

mod common;
use common::{run, run_json, run_ok};

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

/// The single stderr line of a failed run; fails the test unless the run failed with
/// exactly one line and no panic.
fn error_line(out: Output, args: &[&str]) -> String {
    assert!(!out.status.success(), "expected failure for {args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "expected exactly one error line, got: {stderr:?}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr.trim_end().to_string()
}

fn write(dir: &TempDir, name: &str, text: &str) -> PathBuf {
    let path = dir.path().join(name);
    fs::write(&path, text).unwrap();
    path
}

/// A fresh folder holding [`GOOD_SCENE`] as the file `name`.
fn good_scene_in(name: &str) -> TempDir {
    let dir = TempDir::new().unwrap();
    write(&dir, name, GOOD_SCENE);
    dir
}

/// The folder of the example scenes.
fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The path of example scene `name` in [`scenes_dir`].
fn example_scene(name: &str) -> String {
    let path = scenes_dir().join(name);
    path.to_str().expect("a UTF-8 path").to_string()
}

/// The 1-based number of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("the needle is in the text")
        + 1
}

/// Runs a command expected to fail; returns its single stderr line and checks that no
/// output file was left behind.
fn expect_failure(dir: &TempDir, args: &[&str]) -> String {
    let line = error_line(run(dir, args), args);
    let leftovers: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml"))
        .collect();
    assert!(leftovers.is_empty(), "partial output left: {leftovers:?}");
    line
}

/// Writes the scene file `name` with `text` and returns the single error line of rendering
/// it (see [`expect_failure`]).
fn render_fails(dir: &TempDir, name: &str, text: &str) -> String {
    write(dir, name, text);
    expect_failure(dir, &["render", name])
}

#[test]
fn default_render_writes_a_real_image() {
    let dir = TempDir::new().unwrap();
    run_ok(&dir, &["render", "--width", "160", "--height", "80"]);
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
    let text = String::from_utf8(run_ok(&dir, &["scenes"]).stdout).unwrap();
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
    let dir = good_scene_in("s.toml");
    let json = run_json(
        &dir,
        &[
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
        ],
    );
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
    let dir = good_scene_in("s.toml");
    let out = run_ok(
        &dir,
        &[
            "render", "s.toml", "--depth", "d.pfm", "--stats", "st.json", "--spp", "4",
        ],
    );
    assert!(out.stdout.is_empty(), "{out:?}");
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
    let e = render_fails(&dir, "bad.toml", "[image]\nwidth = 64\nheight = = 3\n");
    assert!(e.contains("bad.toml:3:"), "{e}");
}

#[test]
fn unknown_projection_type_is_located() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("type = \"perspective\"", "type = \"perspektive\"");
    let e = render_fails(&dir, "bad.toml", &text);
    let line = line_of(&text, "perspektive");
    assert!(e.contains(&format!("bad.toml:{line}:")), "{e}");
    assert!(e.contains("perspektive"), "{e}");
}

#[test]
fn nan_value_is_located() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("fov = 60.0", "fov = nan");
    let e = render_fails(&dir, "bad.toml", &text);
    let line = line_of(&text, "nan");
    assert!(e.contains(&format!("bad.toml:{line}:")), "{e}");
}

#[test]
fn degenerate_projection() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("look_at = [0.0, 0.5, 0.0]", "look_at = [0.0, 1.0, 5.0]");
    let e = render_fails(&dir, "bad.toml", &text);
    assert!(e.contains("bad.toml"), "{e}");
}

#[test]
fn unknown_shape_and_key() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace("shape = \"sphere\"", "shape = \"spere\"");
    let e = render_fails(&dir, "a.toml", &text);
    assert!(e.contains("a.toml:") && e.contains("spere"), "{e}");
    let text = GOOD_SCENE.replace("translate =", "translat =");
    let e = render_fails(&dir, "b.toml", &text);
    assert!(e.contains("b.toml:") && e.contains("translat"), "{e}");
}

#[test]
fn missing_model_file_names_it() {
    let dir = TempDir::new().unwrap();
    let text =
        format!("{GOOD_SCENE}\n[[object]]\nshape = \"mesh\"\nfile = \"models/missing.obj\"\n");
    let e = render_fails(&dir, "m.toml", &text);
    assert!(e.contains("missing.obj"), "{e}");
}

#[test]
fn absurd_resolution() {
    let dir = good_scene_in("s.toml");
    for args in [
        ["render", "s.toml", "--width", "0"],
        ["render", "s.toml", "--width", "1000000"],
    ] {
        expect_failure(&dir, &args);
    }
    let e = render_fails(
        &dir,
        "big.toml",
        &GOOD_SCENE.replace("width = 64", "width = 0"),
    );
    assert!(e.contains("big.toml:3:"), "{e}");
}

#[test]
fn bad_flags() {
    let dir = good_scene_in("s.toml");
    let e = expect_failure(&dir, &["render", "s.toml", "--method", "magic"]);
    assert!(e.contains("magic") && e.contains("raycast"), "{e}");
    expect_failure(&dir, &["render", "s.toml", "--spp", "0"]);
    expect_failure(&dir, &["render", "s.toml", "--shading", "glossy"]);
    let e = expect_failure(&dir, &["render", "s.toml", "-o", "out.jpg"]);
    assert!(e.contains("out.jpg"), "{e}");
    let e = expect_failure(&dir, &["render", "s.toml", "--depth", "d.png"]);
    assert!(e.contains("d.png"), "{e}");
    // A missing output folder is created, but not below a file.
    let e = expect_failure(&dir, &["render", "s.toml", "-o", "s.toml/dir/x.png"]);
    assert!(e.contains("x.png") && e.contains("is not a folder"), "{e}");
}

/// Every example scene in scenes/ renders (flat, small), so the examples stay true.
#[test]
fn every_example_scene_renders() {
    let mut rendered = 0;
    for entry in fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let dir = TempDir::new().unwrap();
            let path = path.to_str().expect("a UTF-8 path");
            let size = ["--width", "48", "--height", "32", "--shading", "flat"];
            run_ok(&dir, &[&["render", path][..], &size].concat());
            rendered += 1;
        }
    }
    assert!(rendered >= 5, "only {rendered} example scenes found");
}

#[test]
fn compare_reports_agreement_and_enforces_thresholds() {
    let dir = good_scene_in("s.toml");
    let report = run_json(
        &dir,
        &[
            "compare",
            "s.toml",
            "--method",
            "raycast",
            "--json",
            "--min-id-agreement",
            "99.5",
            "--max-rgb-error",
            "0.02",
            "--diff",
            "diff.png",
        ],
    );
    assert_eq!(report["id_agreement"], 1.0);
    assert_eq!(report["relative_rgb_error"], 0.0);
    assert_eq!(report["pixels"], 64 * 48);
    assert!(report["depth_pixels"].as_u64().unwrap() > 0);
    let diff = image::open(dir.path().join("diff.png")).unwrap().to_rgb8();
    assert!(
        diff.pixels().all(|p| p.0 == [0, 0, 0]),
        "identical renders differ"
    );

    // An unreachable threshold fails (status 3) with one line naming the measure; the diff image of a
    // failed check is kept on purpose (it is what one looks at next).
    let args = [
        "compare",
        "s.toml",
        "--method",
        "raycast",
        "--min-id-agreement",
        "100.5",
    ];
    let out = run(&dir, &args);
    assert_eq!(out.status.code(), Some(3), "a missed threshold exits 3");
    let e = error_line(out, &args);
    assert!(e.contains("id agreement 100.000 % is below"), "{e}");

    let clean = good_scene_in("s.toml");
    let e = expect_failure(
        &clean,
        &[
            "compare",
            "s.toml",
            "--method",
            "raycast",
            "--reference",
            "x",
        ],
    );
    assert!(
        e.contains("invalid value 'x' for '--reference <REFERENCE>'")
            && e.contains("[possible values: raycast, raster, trilinear, camera-triangles]"),
        "{e}"
    );
}

/// `compare --spp 4` supersamples both renders with the same pattern: trilinear against the
/// ray caster on the fan example at a small size meets the accuracy targets, and the report
/// names the sample count.
#[test]
fn compare_supersamples_trilinear_and_the_reference() {
    let dir = TempDir::new().unwrap();
    let fan = example_scene("trilinear-fan.toml");
    let report = run_json(
        &dir,
        &[
            "compare",
            &fan,
            "--method",
            "trilinear",
            "--width",
            "180",
            "--height",
            "120",
            "--spp",
            "4",
            "--json",
            "--min-id-agreement",
            "99.5",
            "--max-rgb-error",
            "0.02",
        ],
    );
    assert_eq!(report["spp"], 4);
    assert_eq!(report["method"], "trilinear");
    expect_failure(
        &dir,
        &["compare", "s.toml", "--method", "raycast", "--spp", "0"],
    );
}

/// `--method raster` renders from the command line, with both subdivision flags, and
/// reports its counters.
#[test]
fn raster_method_renders_and_reports() {
    let dir = good_scene_in("s.toml");
    for flags in [
        vec![],
        vec!["--subdiv", "4"],
        vec!["--raster-tolerance", "0.25"],
    ] {
        let render = ["render", "s.toml", "--method", "raster", "--stats", "-"];
        let out = run_ok(&dir, &[&render[..], &flags[..]].concat());
        let stats = String::from_utf8(out.stdout).unwrap();
        assert!(stats.contains("\"method\":\"raster\""), "{stats}");
        assert!(stats.contains("\"raster_pieces\""), "{stats}");
        assert!(dir.path().join("flexcam.png").exists());
    }
}

#[test]
fn raster_bad_input_is_one_line() {
    let dir = good_scene_in("s.toml");
    let raster = ["render", "s.toml", "--method", "raster"];
    let e = expect_failure(&dir, &[&raster[..], &["--subdiv", "0"]].concat());
    assert!(e.contains("subdivision must be between 1 and 64"), "{e}");
    let e = expect_failure(&dir, &[&raster[..], &["--raster-tolerance=-1"]].concat());
    assert!(e.contains("raster tolerance"), "{e}");
    let e = expect_failure(&dir, &[&raster[..], &["--spp", "4"]].concat());
    assert!(e.contains("one sample per pixel"), "{e}");
    let e = expect_failure(&dir, &["render", "s.toml", "--subdiv", "2"]);
    assert!(e.contains("apply to --method raster"), "{e}");
    let fan = example_scene("trilinear-fan.toml");
    let e = expect_failure(&dir, &["render", &fan, "--method", "raster"]);
    assert!(e.contains("method raster needs a projection"), "{e}");
}

/// A trilinear reflector is composited by `flexcam render`, and says so in the stats.
#[test]
fn trilinear_reflector_renders_with_its_counters() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace(
        "color = [1.0, 0.0, 0.0]",
        "material = \"mirror\"\ntrilinear_reflector = true",
    );
    write(&dir, "r.toml", &text);
    let stats = run_json(
        &dir,
        &["render", "r.toml", "--shading", "flat", "--stats", "-"],
    );
    assert_eq!(stats["reflectors"], 1);
    assert!(
        stats["reflector_triangles"].as_u64().unwrap() > 100,
        "{stats}"
    );
    assert!(stats["reflector_pixels"].as_u64().unwrap() > 50, "{stats}");
    assert!(dir.path().join("flexcam.png").exists());
}

/// `trilinear_reflector` on a diffuse object, or under a non-perspective camera, is one
/// positioned error line.
#[test]
fn trilinear_reflector_errors_are_positioned() {
    let dir = TempDir::new().unwrap();
    let text = GOOD_SCENE.replace(
        "color = [1.0, 0.0, 0.0]",
        "color = [1.0, 0.0, 0.0]\ntrilinear_reflector = true",
    );
    let e = render_fails(&dir, "d.toml", &text);
    assert!(
        e.contains("d.toml:23:23:") && e.contains("needs material"),
        "{e}"
    );
    let text = GOOD_SCENE
        .replace(
            "color = [1.0, 0.0, 0.0]",
            "material = \"mirror\"\ntrilinear_reflector = true",
        )
        .replace("type = \"perspective\"", "type = \"fisheye\"");
    let e = render_fails(&dir, "f.toml", &text);
    assert!(
        e.contains("f.toml:23:23:") && e.contains("perspective"),
        "{e}"
    );
}

/// A small animated scene: three keys (perspective, pushbroom, perspective) over 5 frames.
fn animated_scene(second_key_time: &str) -> String {
    let key = |time: &str, body: &str| {
        format!(
            "\n[[animation.key]]\ntime = {time}\n[animation.key.projection]\ntype = \"flexible\"\n\
             position = [0.0, 1.0, 5.0]\nlook_at = [0.0, 0.5, 0.0]\nclip = [0.0, 30.0]\n{body}"
        )
    };
    let perspective = "preset = \"perspective\"\nfov = 60.0\n";
    format!(
        "{GOOD_SCENE}\n[animation]\nframes = 5\nfps = 2.0\n{}{}{}",
        key("0.0", perspective),
        key(
            second_key_time,
            "preset = \"pushbroom\"\nwidth = 4.0\nv_fov = 45.0\n"
        ),
        key("2.0", "preset = \"perspective\"\nfov = 40.0\n"),
    )
}

/// `animate --help` describes every method `animate` accepts: all of `render`'s.
#[test]
fn animate_help_describes_every_method() {
    let dir = TempDir::new().unwrap();
    let out = run_ok(&dir, &["animate", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    let method = &help[help.find("--method").expect("a --method option")..];
    let method = &method[..method.find("--shading").expect("--shading after it")];
    for (name, _) in flexcam::render::Method::ALL {
        assert!(method.contains(&format!("`{name}`")), "{name}: {method}");
    }
}

#[test]
fn animate_writes_numbered_frames_and_a_gif() {
    let dir = TempDir::new().unwrap();
    write(&dir, "a.toml", &animated_scene("1.0"));
    fs::create_dir(dir.path().join("frames")).unwrap();
    run_ok(
        &dir,
        &[
            "animate",
            "a.toml",
            "-o",
            "frames/out_###.png",
            "--gif",
            "a.gif",
            "--shading",
            "flat",
        ],
    );
    let mut names: Vec<String> = fs::read_dir(dir.path().join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let want: Vec<String> = (0..5).map(|i| format!("out_{i:03}.png")).collect();
    assert_eq!(names, want);
    let frame = |i: usize| image::open(dir.path().join("frames").join(&want[i])).unwrap();
    assert_eq!((frame(0).width(), frame(0).height()), (64, 48));
    // Frame 0 is the first key; frame 1 (t = 0.5 s) is half way to the pushbroom key.
    assert_ne!(frame(0).to_rgb8(), frame(1).to_rgb8());
    let gif = fs::File::open(dir.path().join("a.gif")).unwrap();
    let decoded = {
        use image::AnimationDecoder;
        image::codecs::gif::GifDecoder::new(std::io::BufReader::new(gif))
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap()
    };
    assert_eq!(decoded.len(), 5);
    assert_eq!(decoded[0].delay().numer_denom_ms(), (500, 1));
    // Frame 0 renders the same as the first key alone through `flexcam render`.
    let single = GOOD_SCENE.replace(
        "type = \"perspective\"",
        "type = \"flexible\"\npreset = \"perspective\"\nclip = [0.0, 30.0]",
    );
    write(&dir, "k.toml", &single);
    run_ok(
        &dir,
        &["render", "k.toml", "-o", "k.png", "--shading", "flat"],
    );
    assert_eq!(
        image::open(dir.path().join("k.png")).unwrap().to_rgb8(),
        frame(0).to_rgb8()
    );
}

/// An animation of a static scene prepares it once: `animate --stats` reports one BVH build
/// for its 5 frames (to a file, and on standard output with `-`), and the frame count.
#[test]
fn animate_stats_report_one_bvh_build_for_all_frames() {
    let dir = TempDir::new().unwrap();
    write(&dir, "a.toml", &animated_scene("1.0"));
    let args = [
        "animate",
        "a.toml",
        "--gif",
        "a.gif",
        "--shading",
        "flat",
        "--width",
        "16",
        "--height",
        "12",
    ];
    let mut with_file = args.to_vec();
    with_file.extend(["--stats", "stats.json"]);
    run_ok(&dir, &with_file);
    let text = fs::read_to_string(dir.path().join("stats.json")).unwrap();
    let stats: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(stats["frames"], 5);
    assert_eq!(stats["bvh_builds"], 1);
    assert_eq!(stats["method"], "raycast");
    assert_eq!(stats["width"], 16);
    let mut to_stdout = args.to_vec();
    to_stdout.extend(["--stats", "-"]);
    let stats = run_json(&dir, &to_stdout);
    assert_eq!(
        (stats["frames"].clone(), stats["bvh_builds"].clone()),
        (5.into(), 1.into())
    );
}

/// A render warning (a reflector's refinement left edges over its tolerance) is one stderr
/// line naming the scene, and listed in `--stats`; without it the list is empty.
#[test]
fn render_warnings_go_to_stderr_and_stats() {
    let dir = TempDir::new().unwrap();
    let text = fs::read_to_string(scenes_dir().join("reflect-sphere-cube.toml")).unwrap();
    let tight = text.replace(
        "trilinear_reflector = true",
        "trilinear_reflector = true\ntrilinear_refine_px = 0.0001",
    );
    assert_ne!(tight, text);
    write(&dir, "tight.toml", &tight);
    write(&dir, "plain.toml", &text);
    let args = |scene| {
        [
            "render", scene, "--width", "40", "--height", "30", "--stats", "-",
        ]
    };
    let out = run_ok(&dir, &args("tight.toml"));
    let stderr = String::from_utf8(out.stderr).unwrap();
    let lines: Vec<&str> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].starts_with("flexcam: warning: tight.toml: trilinear reflector 1: "),
        "{stderr}"
    );
    let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let listed = stats["warnings"].as_array().unwrap();
    assert_eq!(listed.len(), 1);
    assert!(lines[0].ends_with(listed[0].as_str().unwrap()));
    let out = run_ok(&dir, &args("plain.toml"));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(stats["warnings"], serde_json::json!([]));
}

/// `compare` renders both methods from one prepared scene (one BVH build), and `render
/// --stats` reports the build too; compositing a lit glass reflector (the scene without it,
/// the reflector alone for the Fresnel split) builds no other.
#[test]
fn compare_and_render_build_the_bvh_once() {
    let dir = good_scene_in("s.toml");
    let report = run_json(&dir, &["compare", "s.toml", "--method", "raster", "--json"]);
    assert_eq!(report["bvh_builds"], 1);
    let stats = run_json(&dir, &["render", "s.toml", "-o", "a.png", "--stats", "-"]);
    assert_eq!(stats["bvh_builds"], 1);
    let lens = example_scene("refract-lens.toml");
    let small = ["--width", "48", "--height", "36", "--stats", "-"];
    let stats = run_json(
        &dir,
        &[&["render", &lens, "-o", "b.png"][..], &small].concat(),
    );
    assert_eq!(stats["reflectors"], 1);
    assert!(stats["reflector_fresnel_rays"].as_u64().unwrap() > 0);
    assert_eq!(stats["bvh_builds"], 1);
}

#[test]
fn animate_errors_are_one_line_and_write_nothing() {
    let dir = TempDir::new().unwrap();
    // Key 1 at 2.5 s comes after key 2 at 2 s: wrong order, reported at the next key's time.
    write(&dir, "bad.toml", &animated_scene("2.5"));
    let e = expect_failure(
        &dir,
        &["animate", "bad.toml", "-o", "f_#.png", "--gif", "a.gif"],
    );
    assert!(
        e.contains("bad.toml:") && e.contains("must be later than the key before it"),
        "{e}"
    );
    let line = line_of(&animated_scene("2.5"), "time = 2.0");
    assert!(e.contains(&format!("bad.toml:{line}:8:")), "{e}");
    write(&dir, "nan.toml", &animated_scene("nan"));
    let e = expect_failure(&dir, &["animate", "nan.toml", "--gif", "a.gif"]);
    assert!(e.contains("nan.toml:") && e.contains("time"), "{e}");
    write(&dir, "a.toml", &animated_scene("1.0"));
    let e = expect_failure(&dir, &["animate", "a.toml"]);
    assert!(e.contains("nothing to write"), "{e}");
    let e = expect_failure(&dir, &["animate", "a.toml", "-o", "frames.png"]);
    assert!(e.contains("run of `#`"), "{e}");
    let e = expect_failure(&dir, &["animate", "a.toml", "-o", "f_#_#.png"]);
    assert!(e.contains("not several"), "{e}");
    let e = expect_failure(&dir, &["animate", "a.toml", "--gif", "a.png"]);
    assert!(e.contains("a.png"), "{e}");
    write(&dir, "still.toml", GOOD_SCENE);
    let e = expect_failure(&dir, &["animate", "still.toml", "--gif", "a.gif"]);
    assert!(e.contains("no [animation] table"), "{e}");
}

#[test]
fn trilinear_method_renders_a_trilinear_scene_and_refuses_others() {
    let fan = example_scene("trilinear-fan.toml");
    let dir = TempDir::new().unwrap();
    for curves in ["tessellate", "slice", "adaptive"] {
        let json = run_json(
            &dir,
            &[
                "render",
                &fan,
                "--width",
                "60",
                "--height",
                "40",
                "--shading",
                "flat",
                "--method",
                "trilinear",
                "--curves",
                curves,
                "--curve-steps",
                "4",
                "--stats",
                "-",
            ],
        );
        assert_eq!(json["method"], "trilinear");
        assert_eq!(json["curve_steps"], 4);
        assert!(json["shapes"].as_u64().unwrap() > 0, "{json}");
        assert!(json["raster_covered"].as_u64().unwrap() > 0, "{json}");
    }
    // A fresh folder: the renders above left flexcam.png, and failures must leave nothing.
    let dir = good_scene_in("s.toml");
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

/// A 16 x 8 equirectangular PNG photo: colour encodes the column and row.
fn write_photo(dir: &TempDir, name: &str) -> PathBuf {
    let path = dir.path().join(name);
    let photo =
        image::RgbImage::from_fn(16, 8, |x, y| image::Rgb([x as u8 * 16, y as u8 * 32, 128]));
    photo.save(&path).unwrap();
    path
}

#[test]
fn reproject_through_an_equirectangular_camera_returns_the_photo() {
    let dir = TempDir::new().unwrap();
    write_photo(&dir, "photo.png");
    write(
        &dir,
        "pano.toml",
        "[image]\nwidth = 16\nheight = 8\n[projection]\ntype = \"equirectangular\"\n\
         position = [0, 0, 0]\nlook_at = [0, 0, -1]\n",
    );
    run_ok(
        &dir,
        &[
            "reproject",
            "--input",
            "photo.png",
            "pano.toml",
            "-o",
            "out.png",
        ],
    );
    let got = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let want = image::open(dir.path().join("photo.png")).unwrap().to_rgb8();
    assert_eq!(got.dimensions(), (16, 8));
    for (a, b) in got.pixels().zip(want.pixels()) {
        for c in 0..3 {
            assert!(
                (i32::from(a[c]) - i32::from(b[c])).abs() <= 1,
                "{a:?} {b:?}"
            );
        }
    }
}

#[test]
fn reproject_errors_are_one_line() {
    let dir = good_scene_in("scene.toml");
    let reproject = |input: &str, output: &str| {
        expect_failure(
            &dir,
            &["reproject", "--input", input, "scene.toml", "-o", output],
        )
    };
    let missing = reproject("none.png", "o.png");
    assert!(
        missing.starts_with("flexcam: none.png: cannot read image"),
        "{missing}"
    );
    let format = reproject("photo.tif", "o.png");
    assert!(
        format.contains("photo.tif: unsupported input format \"tif\""),
        "{format}"
    );
    // A zero image size fails in one line and writes nothing.
    let photo_dir = good_scene_in("scene.toml");
    write_photo(&photo_dir, "p.png");
    let args = [
        "reproject",
        "--input",
        "p.png",
        "scene.toml",
        "-o",
        "o.png",
        "--width",
        "0",
    ];
    let e = error_line(run(&photo_dir, &args), &args);
    assert!(e.contains("width"), "{e}");
    assert!(!photo_dir.path().join("o.png").exists());
    let output = reproject("none.png", "o.jpg");
    assert!(output.contains("unsupported output extension"), "{output}");
}

/// `bench trilinear --quick` with one timed render per cell prints both of Vallance 2005's tables
/// and the cube's kept-frame table with a row per cell of the quick subset; an out-of-range
/// `--repeat` is one error line.
#[test]
fn bench_trilinear_quick_prints_both_tables() {
    let dir = TempDir::new().unwrap();
    let out = run_ok(&dir, &["bench", "trilinear", "--quick", "--repeat", "1"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let (random, cube) = text.split_once("Table 8.1").expect("Table 8.1 is printed");
    assert!(random.contains("Tables D.1-D.3"), "{text}");
    // A row starts with a number: its first cell.
    let rows = |table: &str| -> Vec<String> {
        table
            .lines()
            .filter_map(|l| l.split_whitespace().next())
            .filter(|cell| cell.parse::<f64>().is_ok())
            .map(String::from)
            .collect()
    };
    // 2 image sizes x 2 scene sizes x 3 projection meshes, then the thesis's 5 rows.
    assert_eq!(rows(random).len(), 12 + 5, "{text}");
    // Then the cube's later frames into a kept frame, the same cells.
    let (cube, kept) = cube.split_once("later frames").expect("kept-frame table");
    assert_eq!(rows(cube), ["2", "18", "50"], "{text}");
    assert_eq!(rows(kept), ["2", "18", "50"], "{text}");
    let e = expect_failure(&dir, &["bench", "trilinear", "--quick", "--repeat", "0"]);
    assert!(e.contains("--repeat"), "{e}");
}

/// `bench displaced --part table-8-1` prints Table 8.1's eleven rows, each with a time per
/// camera position and the dissertation's three, and the transition system's speed-up over
/// full displacement at both levels; nothing of the other parts.
#[test]
fn bench_displaced_table_8_1_prints_every_method() {
    let dir = TempDir::new().unwrap();
    let args = [
        "bench",
        "displaced",
        "--part",
        "table-8-1",
        "--size",
        "24",
        "--repeat",
        "1",
    ];
    let text = String::from_utf8(run_ok(&dir, &args).stdout).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.contains(" | ") && !l.starts_with("method"))
        .collect();
    assert_eq!(rows.len(), 11, "{text}");
    for row in &rows {
        let numbers = row
            .split_whitespace()
            .filter(|w| w.parse::<f64>().is_ok_and(|v| v > 0.0))
            .count();
        // Three times and the dissertation's three figures.
        assert_eq!(numbers, 6, "{row}");
    }
    assert!(rows[0].starts_with("fully detailed LOD"), "{text}");
    assert!(rows[10].starts_with("transition system (3)"), "{text}");
    assert_eq!(
        text.matches("transition system against full displacement")
            .count(),
        2
    );
    assert!(!text.contains("Figure 8.1"), "{text}");
}

/// `bench flexible --part table --rows 1` prints Table 7.1's four tables with the one row
/// asked for, times named as medians, and with `--hash` one frame hash per column.
#[test]
fn bench_flexible_table_prints_median_times_and_hashes() {
    let dir = TempDir::new().unwrap();
    let args = [
        "bench", "flexible", "--part", "table", "--rows", "1", "--repeat", "1", "--hash",
    ];
    let text = String::from_utf8(run_ok(&dir, &args).stdout).unwrap();
    assert!(text.contains("median of 1 after one warm-up"), "{text}");
    assert!(text.contains("flexcam (median seconds)"), "{text}");
    let kia_rows: Vec<&str> = text.lines().filter(|l| l.starts_with("Kia ")).collect();
    // Thesis, flexcam, speed-up, CPU, hashes: each a model, then six columns.
    assert_eq!(kia_rows.len(), 5, "{text}");
    let hashes: Vec<&str> = kia_rows[4].split_whitespace().skip(1).collect();
    assert_eq!(hashes.len(), 6, "{text}");
    assert!(hashes.iter().all(|h| u64::from_str_radix(h, 16).is_ok()));
    assert!(!text.contains("panorama"), "{text}");
}

/// `--perspective-rect` applies the local perspective edit to a shape-defined panorama (here
/// the rounded cubic preset of an example scene) before rendering: the image changes inside
/// the rectangle's column band, both methods render it and agree; other projections and bad
/// rectangles are refused in one line.
#[test]
fn perspective_rect_option_edits_the_panorama() {
    let dir = TempDir::new().unwrap();
    let scene = example_scene("flexible-panorama-cubic.toml");
    let scene = scene.as_str();
    let ids = |name: &str, extra: &[&str]| {
        let mut args = vec!["render", scene, "--shading", "flat", "-o", "c.png"];
        args.extend_from_slice(&["--ids", name]);
        args.extend_from_slice(extra);
        run_ok(&dir, &args);
        image::open(dir.path().join(name)).unwrap().to_luma16()
    };
    let rect = ["--perspective-rect", "0.5,0.2,0.75,0.8"];
    let plain = ids("plain.png", &[]);
    let edited = ids("edited.png", &rect);
    let raster = ids("raster.png", &[&rect[..], &["--method", "raster"]].concat());
    let width = plain.width();
    let (mut inside, mut outside) = (0, 0);
    for (x, y, p) in plain.enumerate_pixels() {
        if p != edited.get_pixel(x, y) {
            // Only the columns of u in [0.5, 0.75] change: the rows would too, but the
            // vertical segment profile's chord is the segment itself.
            let u = (f64::from(x) + 0.5) / f64::from(width);
            if (0.5..=0.75).contains(&u) {
                inside += 1;
            } else {
                outside += 1;
            }
        }
    }
    assert!(inside > 100, "{inside} pixels changed in the column band");
    assert!(
        outside * 20 <= inside,
        "{outside} changed outside the column band"
    );
    let agree = edited
        .pixels()
        .zip(raster.pixels())
        .filter(|(a, b)| a == b)
        .count();
    let share = agree as f64 / f64::from(width * plain.height());
    assert!(share >= 0.995, "raster vs raycast ids agree on {share}");

    let good = write(&dir, "s.toml", GOOD_SCENE);
    let good = good.to_str().unwrap();
    for f in ["c.png", "plain.png", "edited.png", "raster.png"] {
        fs::remove_file(dir.path().join(f)).unwrap();
    }
    let e = expect_failure(
        &dir,
        &["render", good, "--perspective-rect", "0.4,0.3,0.6,0.7"],
    );
    assert!(
        e.contains("--perspective-rect: needs a flexible shape-defined panorama")
            && e.contains("perspective"),
        "{e}"
    );
    let e = expect_failure(
        &dir,
        &["render", scene, "--perspective-rect", "0.4,0.7,0.6,0.3"],
    );
    assert!(e.contains("needs u0, u1, v0, v1 in [0, 1]"), "{e}");
    let e = expect_failure(
        &dir,
        &["render", scene, "--perspective-rect", "0.1,0.3,0.9,0.7"],
    );
    assert!(e.contains("degrees around the eye"), "{e}");
    expect_failure(
        &dir,
        &["render", scene, "--perspective-rect", "0.4,0.3,0.6"],
    );
}

/// `--perspective-rect` takes `type = "cylindrical"` and `"equirectangular"` cameras as the
/// flexible presets of the same names: the edited camera renders the same object ids as the
/// edited preset, and differently from the unedited camera inside the rectangle's columns.
#[test]
fn perspective_rect_takes_cylindrical_and_equirectangular_cameras() {
    let dir = TempDir::new().unwrap();
    let rect = ["--perspective-rect", "0.3,0.2,0.7,0.8"];
    for (kind, v_fov) in [("cylindrical", "100.0"), ("equirectangular", "120.0")] {
        let projection = format!(
            "position = [0.0, 1.5, 2.0]\nlook_at = [0.0, 1.0, 0.0]\nh_fov = 360.0\n\
             v_fov = {v_fov}\n"
        );
        let scene = |head: &str| {
            GOOD_SCENE.replace(
            "type = \"perspective\"\nposition = [0.0, 1.0, 5.0]\nlook_at = [0.0, 0.5, 0.0]\nfov = 60.0\n",
            &format!("{head}{projection}"),
        )
        };
        let camera = scene(&format!("type = \"{kind}\"\n"));
        let preset = scene(&format!("type = \"flexible\"\npreset = \"{kind}\"\n"));
        assert_ne!(camera, GOOD_SCENE);
        write(&dir, "camera.toml", &camera);
        write(&dir, "preset.toml", &preset);
        let ids = |scene: &str, extra: &[&str]| {
            let mut args = vec!["render", scene, "--shading", "flat", "-o", "c.png"];
            args.extend_from_slice(&["--ids", "ids.png", "--width", "128", "--height", "64"]);
            args.extend_from_slice(extra);
            run_ok(&dir, &args);
            image::open(dir.path().join("ids.png")).unwrap().to_luma16()
        };
        let edited = ids("camera.toml", &rect);
        let edited_preset = ids("preset.toml", &rect);
        let plain = ids("camera.toml", &[]);
        let same = edited
            .pixels()
            .zip(edited_preset.pixels())
            .filter(|(a, b)| a == b)
            .count();
        assert!(
            same * 1000 >= 999 * 128 * 64,
            "{kind}: {same} of {}",
            128 * 64
        );
        let changed = edited
            .pixels()
            .zip(plain.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed > 20, "{kind}: the edit changed {changed} pixels");
    }
}

/// Renders `scene` flat at its own size; returns the colour and id PNG files' bytes.
fn flat_render_bytes(dir: &TempDir, scene: &str, name: &str) -> (Vec<u8>, Vec<u8>) {
    common::render_flat(dir, scene, name);
    (
        fs::read(dir.path().join(format!("{name}.png"))).unwrap(),
        fs::read(dir.path().join(format!("{name}-ids.png"))).unwrap(),
    )
}

/// Copies example scene `name` into `dir` as fitting.toml and runs `flexcam fit` on it into
/// fitted.toml; checks the summary line starts with `summary` and that the written 3 x 3
/// grid has its 9 nodes as explicit projectors and no correspondences left. Returns the
/// written text.
fn fit_example(dir: &TempDir, name: &str, summary: &str) -> String {
    write(
        dir,
        "fitting.toml",
        &fs::read_to_string(example_scene(name)).unwrap(),
    );
    let out = run_ok(dir, &["fit", "fitting.toml", "-o", "fitted.toml"]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.starts_with(summary), "{stdout}");
    let fitted = fs::read_to_string(dir.path().join("fitted.toml")).unwrap();
    assert!(!fitted.contains("fit = ["), "{fitted}");
    assert_eq!(fitted.matches("{ node = [").count(), 9, "{fitted}");
    fitted
}

/// The scene `flexcam fit` wrote (fitted.toml) renders bit for bit like the scene it was
/// fitted from (fitting.toml): colours and ids, flat.
fn assert_fitted_renders_like_fitting(dir: &TempDir) {
    let original = flat_render_bytes(dir, "fitting.toml", "original");
    let written = flat_render_bytes(dir, "fitted.toml", "written");
    assert!(original.1.len() > 100);
    assert!(original.0 == written.0, "colour images differ");
    assert!(original.1 == written.1, "id images differ");
}

/// `flexcam fit` writes the fitted grid as explicit node projectors, keeping the file's
/// comments, and the written scene renders bit for bit like the fitting scene.
#[test]
fn fit_writes_a_scene_that_renders_like_the_fitting_scene() {
    let dir = TempDir::new().unwrap();
    let fitted = fit_example(
        &dir,
        "flexible-projector-fit.toml",
        "fitted 5 correspondences (3 nodes unconstrained): residual max ",
    );
    // The artist's comments survive.
    assert!(
        fitted.contains("# Extension: one colour per face"),
        "{fitted}"
    );
    assert_fitted_renders_like_fitting(&dir);
}

/// `flexcam fit` on a grid with tangents fits curved projectors and writes every node with
/// its fitted tangent; the written scene renders bit for bit like the fitting scene, and the
/// fitted nodes are the known curved grid the example's correspondences come from.
#[test]
fn curved_fit_writes_tangents_and_renders_like_the_fitting_scene() {
    let dir = TempDir::new().unwrap();
    let fitted = fit_example(
        &dir,
        "flexible-projector-fit-curved.toml",
        "fitted 25 correspondences (0 nodes unconstrained): residual max ",
    );
    // The top row and the centre of the known grid are curved: their tangents are written
    // and point like the known ones (normalised).
    let tangent = |c: u32, r: u32| -> Vec<f64> {
        let line = fitted
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{{ node = [{c}, {r}]")))
            .unwrap();
        let (_, after) = line.split_once("tangent = [").expect(line);
        let (list, _) = after.split_once(']').unwrap();
        list.split(',').map(|x| x.trim().parse().unwrap()).collect()
    };
    let close = |a: Vec<f64>, b: [f64; 3]| {
        let n = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        a.iter().zip(b).all(|(x, y)| (x - y / n).abs() < 1e-4)
    };
    let known = [
        ((0, 2), [-0.47, -0.35, -0.86]),
        ((1, 2), [0.0, -0.37, -0.98]),
        ((2, 2), [0.47, -0.35, -0.86]),
        ((1, 1), [0.15, -0.59, -0.81]),
    ];
    for ((c, r), t) in known {
        assert!(close(tangent(c, r), t), "{:?}", tangent(c, r));
    }
    assert_fitted_renders_like_fitting(&dir);
}

/// Node projectors given the thesis's way (`point`, a tangent at the point, `length`) render
/// from the CLI, their tangents bend the image (the same scene with the nodes straight through
/// the same points differs), and bad entries are one error line naming the file, the line
/// or the node, with nothing written.
#[test]
fn projectors_through_scene_points_render_and_bad_ones_are_one_line() {
    let dir = TempDir::new().unwrap();
    let scene = fs::read_to_string(example_scene("flexible-projector-through.toml")).unwrap();
    write(&dir, "through.toml", &scene);
    let straight = scene
        .replace(", tangent = [0.35, -0.42, -0.84]", "")
        .replace(", tangent = [0.0, -1.0, -1.0]", "");
    assert_eq!(straight.matches("tangent = [").count(), 0, "{straight}");
    write(&dir, "straight.toml", &straight);
    let bent = flat_render_bytes(&dir, "through.toml", "bent");
    let plain = flat_render_bytes(&dir, "straight.toml", "plain");
    assert!(bent.1.len() > 100 && plain.1.len() > 100);
    assert!(
        bent.1 != plain.1,
        "the tangents at the points change nothing"
    );

    let bad = TempDir::new().unwrap();
    let both = scene.replace(
        "point = [0.0, 2.0, 0.0]",
        "end = [0.0, 0.0, -9.0], point = [0.0, 2.0, 0.0]",
    );
    let e = render_fails(&bad, "both.toml", &both);
    let line = line_of(&both, "end = [0.0, 0.0, -9.0]");
    assert!(e.starts_with(&format!("flexcam: both.toml:{line}:")), "{e}");
    assert!(e.contains("`end` or `point`"), "{e}");
    let length = scene.replace(
        "{ node = [1, 4], point = [-2.0, 0.0, -3.0]",
        "{ node = [1, 4], length = 5.0, end = [-2.0, 0.0, -3.0]",
    );
    let e = render_fails(&bad, "length.toml", &length);
    assert!(e.starts_with("flexcam: length.toml:"), "{e}");
    assert!(e.contains("`length` goes with `point`"), "{e}");
    let bent_far = scene.replace(
        "tangent = [0.35, -0.42, -0.84]",
        "tangent = [1.0, -0.2, 0.0]",
    );
    let e = render_fails(&bad, "far.toml", &bent_far);
    assert!(e.starts_with("flexcam: far.toml:"), "{e}");
    assert!(
        e.contains("node (2, 2)") && e.contains("bends at most"),
        "{e}"
    );
    let short = scene.replace("length = 30.0", "length = 3.0");
    let e = render_fails(&bad, "short.toml", &short);
    assert!(
        e.contains("node (2, 2)") && e.contains("does not reach past"),
        "{e}"
    );
    let negative = scene.replace("length = 30.0", "length = -3.0");
    let e = render_fails(&bad, "negative.toml", &negative);
    let line = line_of(&negative, "length = -3.0");
    assert!(
        e.starts_with(&format!("flexcam: negative.toml:{line}:")),
        "{e}"
    );
}

/// `flexcam fit` errors: nothing to fit, a missing file, writing over the input, a bad
/// extension and a scene that does not load are one line each, and nothing is written.
#[test]
fn fit_errors_are_one_line_and_write_nothing() {
    let dir = TempDir::new().unwrap();
    write(&dir, "plain.toml", GOOD_SCENE);
    let nothing = expect_failure(&dir, &["fit", "plain.toml", "-o", "out.toml"]);
    assert!(
        nothing.starts_with("flexcam: plain.toml: nothing to fit"),
        "{nothing}"
    );
    let missing = expect_failure(&dir, &["fit", "none.toml", "-o", "out.toml"]);
    assert!(
        missing.starts_with("flexcam: none.toml: cannot read scene file"),
        "{missing}"
    );
    let over = expect_failure(&dir, &["fit", "plain.toml", "-o", "plain.toml"]);
    assert!(over.contains("would overwrite the fitting scene"), "{over}");
    let extension = expect_failure(&dir, &["fit", "plain.toml", "-o", "out.txt"]);
    assert!(
        extension.contains("unsupported output extension"),
        "{extension}"
    );
    // A correspondence at its own projector's start: the scene does not load, with the
    // file named.
    let bad = GOOD_SCENE.replace(
        "type = \"perspective\"",
        "type = \"flexible\"\npreset = \"perspective\"\nclip = [1.0, 40.0]\n\
         projectors = { size = [3, 3], fit = [{ uv = [0.5, 0.5], point = [0.0, 1.0, 5.0] }] }",
    );
    write(&dir, "bad.toml", &bad);
    let e = expect_failure(&dir, &["fit", "bad.toml", "-o", "out.toml"]);
    assert!(e.starts_with("flexcam: bad.toml:"), "{e}");
    assert!(!dir.path().join("out.toml").exists());
}

// Robustness: scene-file inputs outside the example scenes on which a renderer was wrong,
// crashed or disagreed with the ray caster (docs/robustness.md). Each renders through
// `compare` with the acceptance targets as thresholds.

/// Runs `flexcam compare SCENE --method METHOD` with the targets of issues 3 and 4 (ids at
/// least 99.5 %, and for `--method trilinear` a relative RGB error of at most 0.02).
fn meets_targets(dir: &TempDir, scene: &str, method: &str) -> serde_json::Value {
    let mut args = vec![
        "compare",
        scene,
        "--method",
        method,
        "--json",
        "--min-id-agreement",
        "99.5",
    ];
    if method == "trilinear" {
        args.extend(["--max-rgb-error", "0.02"]);
    }
    run_json(dir, &args)
}

/// An object pierced by the axis behind a fisheye: near that pole a piece's image spans a
/// wide arc, and the straight polygons of the pieces next to the pole used to paint a ring
/// inside the image circle (ids 89 % at 220 degrees, 87 % for the 270-degree lens-like
/// preset, 77 % at 300). The fisheye type and the flexible preset (also its equisolid map,
/// added later), with a floor and a
/// cylinder behind the eye. (At 360 degrees the pole lies within a pixel of the outermost
/// pixel centres, where the adaptive rule's bend bound does not hold: 99.3 % here,
/// docs/robustness.md.)
#[test]
fn raster_fisheye_with_an_object_on_the_axis_behind() {
    let dir = TempDir::new().unwrap();
    for (name, projection) in [
        ("type220.toml", "type = \"fisheye\"\nfov = 220.0"),
        ("type180.toml", "type = \"fisheye\"\nfov = 180.0"),
        (
            "lens270.toml",
            "type = \"flexible\"\npreset = \"fisheye\"\nfov = 270.0\nreparam = \"lens\"",
        ),
        (
            "preset300.toml",
            "type = \"flexible\"\npreset = \"fisheye\"\nfov = 300.0",
        ),
        (
            "equisolid300.toml",
            "type = \"flexible\"\npreset = \"fisheye\"\nfov = 300.0\nreparam = \"equisolid\"",
        ),
    ] {
        let scene = format!(
            "[image]\nwidth = 80\nheight = 60\n[projection]\n{projection}\n\
             position = [0.0, 1.5, 0.0]\nlook_at = [0.0, 1.2, -5.0]\n\
             [[object]]\nshape = \"plane\"\nsize = [30.0, 30.0]\ntessellation = 10\n\
             checker = {{ color = [0.1, 0.1, 0.1], size = 1.0 }}\n\
             [[object]]\nshape = \"cylinder\"\nsize = [0.4, 3.0]\n\
             color = [0.5, 0.5, 0.9]\ntranslate = [0.0, 1.5, 4.0]\n"
        );
        write(&dir, name, &scene);
        meets_targets(&dir, name, "raster");
    }
}

/// The inward-looking sphere grid: projection triangles whose rays sweep a surface, not a
/// volume, project no scene point; they are ray cast (were background). The pole rows (two
/// vertices with one base point and one ray: ids 96 %, RGB error 0.034 on the example
/// scene), a one-cell grid whose first and last columns coincide (0 %), and a 2 x 2 grid
/// whose cells span longitudes 0 to 180, so that each triangle's rays to the centre lie in
/// one plane (12.5 %).
#[test]
fn trilinear_grid_with_projection_triangles_sweeping_no_volume() {
    let dir = TempDir::new().unwrap();
    let scene = fs::read_to_string(scenes_dir().join("trilinear-inward-sphere.toml"))
        .unwrap()
        .replace("width = 320", "width = 96")
        .replace("height = 160", "height = 48");
    for cells in [24, 1, 2] {
        let name = format!("grid{cells}.toml");
        write(
            &dir,
            &name,
            &scene.replace("grid = 24", &format!("grid = {cells}")),
        );
        meets_targets(&dir, &name, "trilinear");
    }
}

/// A scene translated 1e4 from the origin: the checker floor at object y = 0 lies on a
/// cell boundary, and the ray caster's checker, read from the interpolated world point
/// whose rounding there exceeds the checker's nudge, flickered (RGB error 0.062 against
/// the trilinear renderer, which interpolates object-space corners; 0.094 in this scene).
#[test]
fn trilinear_scene_far_from_the_origin() {
    let dir = TempDir::new().unwrap();
    let scene = "[image]\nwidth = 96\nheight = 72\n[projection]\ntype = \"trilinear\"\n\
        points = [[9999.0, -2999.75, 20004.0], [10001.0, -2999.75, 20004.0], \
        [10001.0, -2998.25, 20004.0], [9999.0, -2998.25, 20004.0]]\n\
        normals = [[-1.0, -0.75, -1.0], [1.0, -0.75, -1.0], [1.0, 0.75, -1.0], [-1.0, 0.75, -1.0]]\n\
        screen = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]\n\
        triangles = [[0, 1, 2], [0, 2, 3]]\n\
        [[object]]\nshape = \"plane\"\nsize = [8.0, 8.0]\ntessellation = 8\n\
        checker = { color = [0.1, 0.1, 0.1], size = 1.0 }\n\
        translate = [10000.0, -3000.0, 20000.0]\n";
    write(&dir, "far.toml", scene);
    meets_targets(&dir, "far.toml", "trilinear");
}

/// Mercator at the patch's own latitudes (`max_latitude` = `v_fov` / 2, the documented
/// example) and equal area over the full sphere: the poles map to exactly +-90 degrees,
/// which `--method raster` refused; they are singular and dropped anyway.
#[test]
fn raster_mercator_and_equal_area_maps() {
    let dir = TempDir::new().unwrap();
    for (name, keys) in [
        ("mercator.toml", "v_fov = 170.0\nreparam = \"mercator\""),
        ("equal.toml", "reparam = \"equal_area\""),
    ] {
        let scene = GOOD_SCENE.replace(
            "type = \"perspective\"",
            &format!("type = \"flexible\"\npreset = \"equirectangular\"\n{keys}"),
        );
        write(&dir, name, &scene.replace("fov = 60.0\n", ""));
        meets_targets(&dir, name, "raster");
    }
}

/// An equi-angular cubemap face (`reparam = "equiangular"` on the perspective preset): the
/// raster keeps the perspective volume's inverse, and its adaptive subdivision follows the
/// edges that the map bends.
#[test]
fn raster_equiangular_cubemap_face() {
    let dir = TempDir::new().unwrap();
    let scene = GOOD_SCENE.replace(
        "type = \"perspective\"",
        "type = \"flexible\"\npreset = \"perspective\"\nreparam = \"equiangular\"",
    );
    write(&dir, "eac.toml", &scene.replace("fov = 60.0", "fov = 90.0"));
    meets_targets(&dir, "eac.toml", "raster");
}

/// A glTF primitive whose POSITION accessor does not exist: gltf-json's validation panicked
/// on it; now one error line naming the file.
#[test]
fn gltf_with_a_missing_position_accessor_is_one_error_line() {
    let dir = TempDir::new().unwrap();
    write(
        &dir,
        "bad.gltf",
        r#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}]}"#,
    );
    let scene = format!("{GOOD_SCENE}\n[[object]]\nshape = \"mesh\"\nfile = \"bad.gltf\"\n");
    write(&dir, "s.toml", &scene);
    let args = ["render", "s.toml", "-o", "out.png"];
    let e = error_line(run(&dir, &args), &args);
    assert!(e.contains("bad.gltf") && e.contains("POSITION"), "{e}");
    assert!(!dir.path().join("out.png").exists());
}

/// Standard output closed before anything is written to it (`flexcam render --stats - | head
/// -c 0`, `flexcam scenes | head -c 0`): `println!` panicked on the broken pipe. Now the
/// program ends as other command-line tools do, by SIGPIPE (Unix; exit status 141 in a
/// shell), or with one error line; never a panic.
#[test]
fn closed_standard_output_is_no_panic() {
    let dir = good_scene_in("s.toml");
    for args in [
        &["render", "s.toml", "-o", "out.png", "--stats", "-"][..],
        &["scenes"][..],
    ] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("flexcam"))
            .current_dir(dir.path())
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("flexcam runs");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("flexcam ends");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(stderr.trim_end().lines().count() <= 1, "{args:?}: {stderr}");
        #[cfg(unix)]
        let by_sigpipe = std::os::unix::process::ExitStatusExt::signal(&out.status) == Some(13);
        #[cfg(not(unix))]
        let by_sigpipe = false;
        if !out.status.success() && !by_sigpipe {
            assert!(
                stderr.contains("cannot write to standard output"),
                "{args:?}: {:?} {stderr}",
                out.status
            );
        }
    }
}

/// A raster tolerance far below a pixel split every edge, straight ones too (their midpoints
/// are off the chord by rounding), to the deepest level: a 20 x 20 render of the test scene
/// with `--raster-tolerance 1e-30` had not ended after 7 CPU minutes. It is refused now.
#[test]
fn raster_tolerance_below_a_thousandth_of_a_pixel_is_refused() {
    let dir = good_scene_in("s.toml");
    for tolerance in ["1e-30", "0.0009"] {
        let args = [
            "render",
            "s.toml",
            "--method",
            "raster",
            "--raster-tolerance",
            tolerance,
        ];
        let e = expect_failure(&dir, &args);
        assert!(
            e.contains("raster tolerance must be a number of pixels of at least 0.001"),
            "{e}"
        );
    }
    run_ok(
        &dir,
        &[
            "render",
            "s.toml",
            "--method",
            "raster",
            "--raster-tolerance",
            "0.001",
            "--width",
            "16",
            "--height",
            "12",
        ],
    );
}

/// `compare` thresholds that no comparison can miss passed silently (`--min-id-agreement
/// nan` and `--max-rgb-error nan` exited 0 whatever the result); non-finite thresholds are
/// one error line before anything is rendered or written.
#[test]
fn compare_thresholds_that_cannot_be_checked_are_refused() {
    let dir = good_scene_in("s.toml");
    let compare = ["compare", "s.toml", "--method", "raster", "--diff", "d.png"];
    for bad in [
        "--min-id-agreement=nan",
        "--min-id-agreement=-inf",
        "--max-rgb-error=nan",
        "--max-rgb-error=inf",
    ] {
        let e = expect_failure(&dir, &[&compare[..], &[bad]].concat());
        let flag = bad.split('=').next().unwrap_or(bad);
        assert!(e.contains(&format!("{flag} must be")), "{bad}: {e}");
    }
    let ok = [
        "--min-id-agreement=0",
        "--max-rgb-error=0.5",
        "--width=16",
        "--height=12",
    ];
    run_ok(&dir, &[&compare[..], &ok[..]].concat());
}

/// A projection triangle from an OBJ surface whose rays cross inside the cube, where its
/// parametric triangle (horizontal at every depth) degenerates to a segment: the outlines
/// of its projected shapes ran through infinity there and drew the cube's hidden faces over
/// its top (relative RGB error 0.064 with adaptive curves, 0.062 with slicing). The pairs
/// whose shapes reach across that depth are split at the band around it, nothing is ray
/// cast, and `--stats` counts them.
#[test]
fn trilinear_projection_triangle_folding_inside_the_scene() {
    let dir = TempDir::new().unwrap();
    write(
        &dir,
        "c2.obj",
        "v -3 4 7\nv 3 4 7\nv 3 6 7\nv -3 6 7\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         vn 0.5 -0.6 -1\nvn -0.5 -0.6 -1\nvn -0.4 -0.3 -1\nvn 0.4 -0.3 -1\n\
         f 1/1/1 3/3/3 4/4/4\n",
    );
    let cube = fs::read_to_string(scenes_dir().join("cube-floor.toml")).unwrap();
    let objects = &cube[cube.find("[[object]]\nname = \"cube\"").unwrap()..];
    let scene = format!(
        "[image]\nwidth = 120\nheight = 90\n[projection]\ntype = \"trilinear\"\n\
         surface = \"c2.obj\"\n\n{objects}"
    );
    write(&dir, "fold.toml", &scene);
    for curves in ["adaptive", "slice"] {
        let (report, stats) = trilinear_compare_and_stats(&dir, "fold.toml", curves);
        let rgb = report["relative_rgb_error"].as_f64().unwrap();
        assert!(rgb <= 1e-4, "{curves}: {report}");
        assert_eq!(stats["fallback_triangles"], 0, "{stats}");
        assert!(stats["split_pairs"].as_u64().unwrap() > 0, "{stats}");
    }
}

/// `flexcam compare --method trilinear --json` and `flexcam render --method trilinear --stats
/// -` of `scene` in `dir` with `--curves curves`, flat shading: the report and the stats.
fn trilinear_compare_and_stats(
    dir: &TempDir,
    scene: &str,
    curves: &str,
) -> (serde_json::Value, serde_json::Value) {
    let method = [
        "--method",
        "trilinear",
        "--shading",
        "flat",
        "--curves",
        curves,
    ];
    let report = run_json(
        dir,
        &[&["compare", scene][..], &method, &["--json"]].concat(),
    );
    let stats = run_json(
        dir,
        &[&["render", scene][..], &method, &["--stats", "-"]].concat(),
    );
    (report, stats)
}

/// Rays that all meet in one point in front of the scene (F = (0, 1.8, 3.8), at t = 1; audit
/// 4 of docs/robustness.md, found against POV-Ray's mesh_camera): the floor reaches across
/// the plane through F, whose image is at infinity, and `--method trilinear` drew none of
/// its 1,930 pixels in every curve mode (ids 92.95 %). Both projection triangles collapse at
/// a depth the floor reaches; their rays meet in one point (to the 8 decimals written), so
/// they are drawn as central projections (`render::trilinear::central`): no cubic, no
/// fallback, every pixel the ray caster's.
#[test]
fn trilinear_rays_meeting_in_front_of_the_scene() {
    let dir = TempDir::new().unwrap();
    let scene = "[image]\nwidth = 232\nheight = 118\n[projection]\ntype = \"trilinear\"\n\
        points = [[-1.45764322, 0.477759585, 5.5424479], [1.54085543, 0.51293406, 6.46326127], \
                  [-1.51028013, 2.4670385, 5.55334929], [1.50218028, 2.47545296, 6.43633547]]\n\
        normals = [[1.45764322, 1.32224042, -1.7424479], [-1.54085543, 1.28706594, -2.66326127], \
                   [1.51028013, -0.667038497, -1.75334929], [-1.50218028, -0.675452959, -2.63633547]]\n\
        screen = [[0, 0], [1, 0], [0, 1], [1, 1]]\ntriangles = [[0, 1, 2], [1, 3, 2]]\n\
        [[object]]\nshape = \"plane\"\nsize = [8.0, 8.0]\n";
    write(&dir, "converge.toml", scene);
    for curves in ["adaptive", "slice", "tessellate"] {
        let (report, stats) = trilinear_compare_and_stats(&dir, "converge.toml", curves);
        assert_eq!(
            report["id_agreement"].as_f64().unwrap(),
            1.0,
            "{curves}: {report}"
        );
        assert!(
            report["relative_rgb_error"].as_f64().unwrap() < 1e-6,
            "{report}"
        );
        assert_eq!(stats["central_triangles"], 2, "{stats}");
        assert_eq!(stats["fallback_triangles"], 0, "{stats}");
        assert_eq!(stats["vertices_projected"], 0, "{stats}");
        assert_eq!(stats["raster_covered"], 1930, "{stats}");
    }
}

/// The inward-looking sphere (Vallance 2005, Figure 6.9): every ray passes through the centre,
/// inside the cube, so every projection triangle but the 48 of the pole rows is a central
/// projection, drawn exactly; the pole rows' triangles have two equal vertices, sweep no
/// volume and are drawn as fans of rays (`render::trilinear::ray_fan`): every pixel the ray
/// caster's id; the colour differs at 7 pixels of one image row whose shared ray passes
/// exactly through a vertex of the cube's tessellated top or bottom, which the ray caster
/// misses there and sees the far face (relative RGB error 0.00017; with those pixels ray
/// cast it was 1.5e-8).
#[test]
fn trilinear_inward_sphere_is_drawn_as_central_projections() {
    let dir = TempDir::new().unwrap();
    let scene = fs::read_to_string(scenes_dir().join("trilinear-inward-sphere.toml")).unwrap();
    write(&dir, "inward.toml", &scene);
    let (report, stats) = trilinear_compare_and_stats(&dir, "inward.toml", "adaptive");
    assert_eq!(report["id_agreement"].as_f64().unwrap(), 1.0, "{report}");
    assert!(
        report["relative_rgb_error"].as_f64().unwrap() < 2e-4,
        "{report}"
    );
    assert_eq!(stats["central_triangles"], 1104, "{stats}");
    assert_eq!(stats["fallback_triangles"], 0, "{stats}");
    assert!(stats["shapes"].as_u64().unwrap() > 1104, "{stats}");
}

/// `--method raycast` through the binary sees exactly the displaced micro-geometry: every
/// pixel's id and depth equal those of a brute-force search of every micro-triangle (the
/// library's `MicroGrid`) along the same pixel-centre ray, through a perspective camera and
/// a fisheye.
#[test]
fn displaced_renders_hit_the_micro_triangles_brute_force_finds() {
    use flexcam::displace::{base_corners, Displacement, MicroGrid};

    let dir = TempDir::new().unwrap();
    let (width, height) = (40u32, 32u32);
    for projection in [
        "type = \"perspective\"\nposition = [0.0, 2.2, 2.6]\nlook_at = [0.0, 0.0, 0.0]\nfov = 50.0",
        "type = \"fisheye\"\nposition = [0.0, 1.1, 1.2]\nlook_at = [0.0, 0.0, 0.0]\nfov = 170.0",
    ] {
        let text = format!(
            "[image]\nwidth = {width}\nheight = {height}\n[projection]\n{projection}\n\
             [[object]]\nshape = \"torus\"\nsize = [1.0, 0.35]\ntessellation = 8\n\
             displacement = {{ procedural = \"waves\", waves = [[1.0, 6, 0, 0.0], [0.6, 1, 4, 0.5]], scale = 0.2, level = 3 }}\n\
             [[object]]\nshape = \"sphere\"\nsize = 0.5\ntessellation = 6\n\
             displacement = {{ procedural = \"bumps\", cells = [5, 3], radius = 0.4, scale = 0.3, level = 2, fraction = 0.5 }}\n"
        );
        fs::write(dir.path().join("d.toml"), &text).unwrap();
        run_ok(
            &dir,
            &[
                "render",
                "d.toml",
                "--shading",
                "flat",
                "--depth",
                "d.pfm",
                "--ids",
                "ids.png",
            ],
        );
        let ids = image::open(dir.path().join("ids.png"))
            .unwrap()
            .into_luma16();
        let pfm = fs::read(dir.path().join("d.pfm")).unwrap();
        let header = format!("Pf\n{width} {height}\n-1.0\n");
        assert!(pfm.starts_with(header.as_bytes()));
        let depth: Vec<f32> = pfm[header.len()..]
            .chunks(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();

        let scene = flexcam::scene::file::parse(&text, &dir.path().join("d.toml")).unwrap();
        let camera = scene.projection.build(width, height).unwrap();
        let grids: Vec<(u32, MicroGrid)> = scene
            .objects
            .iter()
            .flat_map(|o| {
                let d = Displacement::from_spec(o.displacement.as_deref().unwrap());
                (0..o.mesh.triangles.len())
                    .map(move |k| (o.id, MicroGrid::new(&base_corners(&o.mesh, k), &d)))
            })
            .collect();
        let (mut hits, mut mismatches) = (0, Vec::new());
        for y in 0..height {
            for x in 0..width {
                let pixel = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let want = camera.ray(pixel).and_then(|ray| {
                    grids
                        .iter()
                        .filter_map(|(id, g)| Some((g.intersect(&ray)?.t, *id)))
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .map(|(t, id)| (id, (t * ray.direction.length()) as f32))
                });
                let got_id = ids.get_pixel(x, y).0[0] as u32;
                let got_depth = depth[((height - 1 - y) * width + x) as usize];
                let agree = match want {
                    None => got_id == 0 && got_depth == f32::INFINITY,
                    Some((id, d)) => {
                        hits += 1;
                        got_id == id && (got_depth - d).abs() <= 1e-5 * d
                    }
                };
                if !agree {
                    mismatches.push((x, y, want, got_id, got_depth));
                }
            }
        }
        assert!(mismatches.is_empty(), "{projection}: {mismatches:?}");
        assert!(hits > 60, "{projection}: {hits} hits");
    }
}
