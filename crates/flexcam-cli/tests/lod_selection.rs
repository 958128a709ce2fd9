//! `flexcam render --lod footprint|distance|finest|m100..m20` on the displaced torus: which
//! level of detail the displacing rays trace (the `lod_*_samples` counters), and what that
//! does to the image against the detailed mesh's; the transition flags refused without a
//! transition shading.

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

/// A fixed level (`m60`, `m20`) puts every displacing sample on that level.
#[test]
fn fixed_levels_trace_only_their_level() {
    let dir = TempDir::new().unwrap();
    for (lod, k) in [("m60", 2), ("m20", 4)] {
        let stats = render(&dir, lod);
        let levels = counts(&stats);
        let total: u64 = levels.iter().sum();
        assert!(total > 1000, "{lod}: the torus displaces: {levels:?}");
        assert_eq!(levels[k], total, "{lod}: {levels:?}");
    }
}

/// `--lod`, `--transition-method` and `--transition-d` without a transition shading are
/// refused in one line naming the flag, writing nothing.
#[test]
fn transition_flags_without_transition_shading_are_refused() {
    let dir = TempDir::new().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/displaced-torus.toml");
    for (flag, value) in [
        ("--lod", "finest"),
        ("--transition-method", "bump"),
        ("--transition-d", "3"),
    ] {
        let out = run(
            &dir,
            &[
                "render",
                scene.to_str().unwrap(),
                flag,
                value,
                "-o",
                "x.png",
            ],
        );
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        let expected = format!("{flag} applies to --shading transitions and transition-lit only");
        assert!(stderr.contains(&expected), "{stderr}");
        assert!(!dir.path().join("x.png").exists());
    }
}
