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
/// one id) whose ids agree, and how many such pixels there are.
pub fn interior_agreement(reference: &Path, other: &Path) -> (f64, usize) {
    let (w, h, a) = ids(reference);
    let (w2, h2, b) = ids(other);
    assert_eq!((w, h), (w2, h2));
    let at = |x: u32, y: u32| a[(y * w + x) as usize];
    let (mut interior, mut agree) = (0usize, 0usize);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let id = at(x, y);
            let uniform = (y - 1..=y + 1).all(|v| (x - 1..=x + 1).all(|u| at(u, v) == id));
            if uniform {
                interior += 1;
                agree += usize::from(b[(y * w + x) as usize] == id);
            }
        }
    }
    (agree as f64 / interior as f64, interior)
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
