//! `flexcam render --lod footprint|distance|finest` on the displaced torus: which level of
//! detail the displacing rays trace (the `lod_*_samples` counters), and what that does to
//! the image against the detailed mesh's.

mod common;

use std::path::Path;

use common::{run, run_json};
use tempfile::TempDir;

const LEVELS: [&str; 5] = [
    "lod_100_samples",
    "lod_80_samples",
    "lod_60_samples",
    "lod_40_samples",
    "lod_20_samples",
];

/// The torus example at 64 x 64 with a transition constant small enough that every sample
/// on the torus displaces, so every one of them traces a level.
fn render(dir: &TempDir, lod: &str) -> serde_json::Value {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/displaced-torus.toml");
    let out = format!("{lod}.png");
    run_json(
        dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "64",
            "--shading",
            "transition-lit",
            "--transition-d",
            "0.05",
            "--lod",
            lod,
            "-o",
            &out,
            "--stats",
            "-",
        ],
    )
}

fn counts(stats: &serde_json::Value) -> [u64; 5] {
    LEVELS.map(|k| {
        stats[k]
            .as_u64()
            .unwrap_or_else(|| panic!("{k} in {stats}"))
    })
}

/// Mean absolute difference of the RGB channels of two PNGs of one size, in [0, 1].
fn mean_difference(a: &Path, b: &Path) -> f64 {
    let (a, b) = (
        image::open(a).unwrap().into_rgb8(),
        image::open(b).unwrap().into_rgb8(),
    );
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(&x, &y)| u64::from(x.abs_diff(y)))
        .sum();
    sum as f64 / (a.as_raw().len() as f64 * 255.0)
}

/// `finest` traces the detailed mesh only; `footprint` and `distance` trace the same
/// samples on coarser levels (none fails), and their images stay close to the detailed
/// one's.
#[test]
fn each_rule_traces_its_levels_and_keeps_the_image() {
    let dir = TempDir::new().unwrap();
    let finest = counts(&render(&dir, "finest"));
    let total: u64 = finest.iter().sum();
    assert!(total > 1000, "the torus displaces: {finest:?}");
    assert_eq!(
        finest[0], total,
        "finest traces the detailed mesh only: {finest:?}"
    );
    for lod in ["footprint", "distance"] {
        let stats = render(&dir, lod);
        let levels = counts(&stats);
        assert_eq!(stats["lod_failures"], 0, "{lod}: {stats}");
        assert_eq!(levels.iter().sum::<u64>(), total, "{lod}: {levels:?}");
        assert!(levels[0] < total, "{lod} uses coarser levels: {levels:?}");
        let difference = mean_difference(
            &dir.path().join("finest.png"),
            &dir.path().join(format!("{lod}.png")),
        );
        println!("{lod}: {levels:?}, mean RGB difference from finest {difference:.5}");
        assert!(difference > 0.0 && difference < 0.01, "{lod}: {difference}");
    }
}

/// `--lod` without a transition shading is refused in one line, writing nothing.
#[test]
fn lod_without_transition_shading_is_refused() {
    let dir = TempDir::new().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/displaced-torus.toml");
    let out = run(
        &dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--lod",
            "finest",
            "-o",
            "x.png",
        ],
    );
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("--lod applies to --shading transitions and transition-lit only"),
        "{stderr}"
    );
    assert!(!dir.path().join("x.png").exists());
}
