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
