//! Helpers shared by the CLI test files: run the `flexcam` binary in a folder and read its
//! JSON output.
//!
//! Every test file that includes this module compiles its own copy and uses part of it, so
//! the parts one file leaves unused are not dead code.
#![allow(dead_code)]

use std::path::Path;
use std::process::Output;

use assert_cmd::Command;
use tempfile::TempDir;

/// Runs `flexcam ARGS` in `dir`.
pub fn run(dir: &TempDir, args: &[&str]) -> Output {
    Command::cargo_bin("flexcam")
        .expect("flexcam binary")
        .current_dir(dir.path())
        .args(args)
        .output()
        .expect("flexcam runs")
}

/// Runs `flexcam ARGS` in `dir`; fails the test, showing the command's stderr, unless it
/// exited successfully.
pub fn run_ok(dir: &TempDir, args: &[&str]) -> Output {
    let out = run(dir, args);
    assert!(
        out.status.success(),
        "flexcam {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// [`run_ok`], returning the JSON object its standard output must be.
pub fn run_json(dir: &TempDir, args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&run_ok(dir, args).stdout).expect("stdout is one JSON object")
}

/// Writes `text` as `scene.toml` in `dir` and renders it to `out.png` with `args` added;
/// fails the test unless flexcam refused it with exit code 1, one line on stderr and no
/// image written. Returns that line (with its newline).
pub fn refused_scene(dir: &TempDir, text: &str, args: &[&str]) -> String {
    std::fs::write(dir.path().join("scene.toml"), text).expect("scene written");
    let all = [&["render", "scene.toml", "-o", "out.png"][..], args].concat();
    let out = run(dir, &all);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!dir.path().join("out.png").exists());
    stderr
}

/// Deterministic uniform numbers in [0, 1) from `seed` (SplitMix64).
pub fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / u64::MAX as f64
    }
}

/// The 16-bit object ids of an `--ids` PNG.
pub fn ids(path: &Path) -> (u32, u32, Vec<u16>) {
    let image = image::open(path).unwrap().to_luma16();
    let (w, h) = image.dimensions();
    (w, h, image.into_raw())
}

/// The fraction of pixels away from object edges (the reference's 3 x 3 neighbourhood has
/// one id) whose ids agree, and how many such pixels there are
/// (`flexcam::render::interior_id_agreement` of the two `--ids` PNGs).
pub fn interior_agreement(reference: &Path, other: &Path) -> (f64, usize) {
    let (w, h, a) = ids(reference);
    let (w2, h2, b) = ids(other);
    assert_eq!((w, h), (w2, h2));
    let (agreement, interior) = flexcam::render::interior_id_agreement(w, h, &b, &a).unwrap();
    (agreement, interior as usize)
}

/// Renders `scene` flat into `NAME.png` and its ids into `NAME-ids.png` in `dir`.
pub fn render_flat(dir: &TempDir, scene: &str, name: &str) {
    let (color, ids) = (format!("{name}.png"), format!("{name}-ids.png"));
    run_ok(
        dir,
        &[
            "render",
            scene,
            "--shading",
            "flat",
            "-o",
            &color,
            "--ids",
            &ids,
        ],
    );
}

/// The path of `scenes/NAME`.
pub fn scene_example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// The path of `scenes/cameras/NAME`.
pub fn camera_example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/cameras")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// Renders `scene_args` (a scene and its options) by raycast and raster, flat shaded, into
/// `raycast.png` / `raster.png` and their `--ids` PNGs in `dir`, and checks that at least
/// 99.99 % of the (more than 10,000) pixels away from object edges have the same id and
/// that `compare` reports a relative RGB error below 0.002.
pub fn raster_agrees(dir: &TempDir, scene_args: &[&str]) {
    for method in ["raycast", "raster"] {
        let color = format!("{method}.png");
        let ids = format!("{method}-ids.png");
        let mut args = vec!["render"];
        args.extend_from_slice(scene_args);
        args.extend_from_slice(&["--method", method, "--shading", "flat", "-o", &color]);
        args.extend_from_slice(&["--ids", &ids]);
        run_ok(dir, &args);
    }
    let (agreement, interior) = interior_agreement(
        &dir.path().join("raycast-ids.png"),
        &dir.path().join("raster-ids.png"),
    );
    assert!(
        interior > 10_000,
        "{scene_args:?}: {interior} interior pixels"
    );
    assert!(
        agreement >= 0.9999,
        "{scene_args:?}: interior id agreement {agreement}"
    );
    let mut args = vec!["compare"];
    args.extend_from_slice(scene_args);
    args.extend_from_slice(&["--method", "raster", "--shading", "flat", "--json"]);
    let rgb = run_json(dir, &args)["relative_rgb_error"].as_f64().unwrap();
    assert!(rgb < 0.002, "{scene_args:?}: relative RGB error {rgb}");
}

/// A scene of a floor plane (id 1: 20 x 20 at y = 0, light grey with a dark checker of
/// 0.5) and a red sphere of radius 1 standing on it (id 2, centre (0, 1, 0)), black
/// background, `width` x `height`, seen through `projection` (the `[projection]` table's
/// keys, one a line).
pub fn plane_and_sphere(width: u32, height: u32, projection: &str) -> String {
    format!(
        r#"[image]
width = {width}
height = {height}
background = [0.0, 0.0, 0.0]

[projection]
{projection}

[[object]]
name = "floor"
shape = "plane"
size = [20.0, 20.0]
color = [0.8, 0.8, 0.8]
checker = {{ color = [0.1, 0.1, 0.1], size = 0.5 }}

[[object]]
name = "ball"
shape = "sphere"
size = 1.0
tessellation = 96
color = [0.9, 0.2, 0.1]
translate = [0.0, 1.0, 0.0]
"#
    )
}

/// The channels of the one-layer OpenEXR file at `path`, by name.
pub struct Layers(pub Vec<(String, exr::prelude::FlatSamples)>);

impl Layers {
    /// Reads the file at `path`, asserting it is one layer of `size` pixels.
    pub fn read(path: &std::path::Path, size: (usize, usize)) -> Layers {
        let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
        assert_eq!(image.layer_data.len(), 1);
        let layer = &image.layer_data[0];
        assert_eq!((layer.size.0, layer.size.1), size);
        Layers(
            (layer.channel_data.list.iter())
                .map(|c| (c.name.to_string(), c.sample_data.clone()))
                .collect(),
        )
    }

    /// The channel names, sorted as the file stores them.
    pub fn names(&self) -> Vec<&str> {
        self.0.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// The samples of float channel `name`.
    pub fn floats(&self, name: &str) -> Vec<f32> {
        match &self.0.iter().find(|(n, _)| n == name).unwrap().1 {
            exr::prelude::FlatSamples::F32(v) => v.clone(),
            other => panic!("{name} is not f32: {other:?}"),
        }
    }

    /// The samples of the unsigned channel `id`.
    pub fn ids(&self) -> Vec<u32> {
        match &self.0.iter().find(|(n, _)| n == "id").unwrap().1 {
            exr::prelude::FlatSamples::U32(v) => v.clone(),
            other => panic!("id is not u32: {other:?}"),
        }
    }

    /// The vector of layer `layer` (`N`, `P`, ...) at every pixel.
    pub fn vectors(&self, layer: &str) -> Vec<glam::Vec3> {
        let [x, y, z] = ["X", "Y", "Z"].map(|c| self.floats(&format!("{layer}.{c}")));
        (0..x.len())
            .map(|i| glam::Vec3::new(x[i], y[i], z[i]))
            .collect()
    }
}

/// The objects and light of the painting tests (`fit_painting`, `fit_overlay`): a checker
/// floor (id 1, 10 x 10 at y = 0), a cube (id 2, side 2, on the floor at x = -1.3, turned 30
/// degrees) and a ball (id 3, radius 1, centre (1.6, 1, 1)), lit from above.
pub const FLOOR_CUBE_BALL: &str = r#"
[[object]]
name = "floor"
shape = "plane"
size = [10.0, 10.0]
tessellation = 21
color = [0.9, 0.9, 0.9]
checker = { color = [0.1, 0.1, 0.1], size = 1.0 }

[[object]]
name = "cube"
shape = "box"
size = [2.0, 2.0, 2.0]
tessellation = 3
color = [0.8, 0.3, 0.2]
translate = [-1.3, 1.0, 0.0]
rotate = [0.0, 30.0, 0.0]

[[object]]
name = "ball"
shape = "sphere"
size = 1.0
tessellation = 32
color = [0.2, 0.4, 0.9]
translate = [1.6, 1.0, 1.0]

[[light]]
type = "directional"
direction = [-0.3, -1.0, -0.5]
intensity = 1.0
"#;

/// Runs `flexcam ARGS` in `dir` where the viewer's window can open: under the display of
/// `DISPLAY`, or a virtual one from `xvfb-run` when there is none (Mesa's software OpenGL
/// either way). `None`, having printed a line starting `skipped:` (which .ci/run refuses),
/// only when no display can be opened. One at a time in a test binary: `xvfb-run -a`
/// started in parallel can pick the same display number and fail.
pub fn run_with_display(dir: &TempDir, args: &[&str]) -> Option<Output> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let flexcam = assert_cmd::cargo::cargo_bin("flexcam");
    let has_display = std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty());
    let mut command = if has_display {
        std::process::Command::new(&flexcam)
    } else if on_path("xvfb-run") {
        let mut c = std::process::Command::new("xvfb-run");
        c.args(["-a", "-s", "-screen 0 1280x1024x24"]).arg(&flexcam);
        c
    } else {
        println!("skipped: no DISPLAY and no xvfb-run to open a virtual display");
        return None;
    };
    let out = command
        .current_dir(dir.path())
        .args(args)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .output()
        .expect("flexcam runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("cannot open the viewer's window") {
        println!("skipped: the display cannot be opened: {stderr}");
        return None;
    }
    Some(out)
}

/// Whether `program` is a file in a folder of `PATH`.
fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| Path::new(&dir).join(program).is_file())
    })
}

/// A folder holding `scene.toml` (scene file `text` with its image size `from` replaced by
/// `to`) and `view.txt` (`script`).
pub fn setup_scene(text: &str, from: &str, to: &str, script: &str) -> TempDir {
    let dir = TempDir::new().unwrap();
    let scene = text.replace(from, to);
    assert_ne!(scene, text);
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    dir
}

/// The numbers of `text` (a line of a scene file), in order.
pub fn numbers_in(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter_map(|w| w.parse().ok())
        .collect()
}
