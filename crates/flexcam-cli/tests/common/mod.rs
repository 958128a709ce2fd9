//! Helpers shared by the CLI test files: run the `flexcam` binary in a folder and read its
//! JSON output.
//!
//! Every test file that includes this module compiles its own copy and uses part of it, so
//! the parts one file leaves unused are not dead code.
#![allow(dead_code)]

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
