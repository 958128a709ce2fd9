//! `flexcam bench view`: the viewer's frame rate at 1280 x 720 while a projection parameter
//! changes every frame (the render loop driven as the window drives it; see
//! `flexcam_view::bench`), on cube-floor through invertible cameras and on the
//! 123,554-triangle teapot-dense scene as an equirectangular panorama.

use clap::Args;
use flexcam::scene::builtin;
use flexcam::{Error, Result};
use flexcam_view::bench::{drag, scene_variant};
use toml_edit::Value;

/// Arguments of `flexcam bench view`.
#[derive(Args, Debug)]
pub struct ViewBenchArgs {
    /// Frames (edits) per case.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    frames: u32,
}

/// The viewer's image size in the frame-rate target.
const SIZE: (u32, u32) = (1280, 720);

/// A case: a built-in scene, its projection replaced by `keys` (or kept when empty), and
/// the key dragged from `from` to `to`.
struct Case {
    name: &'static str,
    builtin: &'static str,
    keys: Vec<(&'static str, Value)>,
    drag: (&'static str, f64, f64),
}

fn vector(v: [f64; 3]) -> Value {
    flexcam::scene::file::edit::float_array(&v)
}

fn cases() -> Vec<Case> {
    let fisheye = vec![
        ("type", Value::from("fisheye")),
        ("position", vector([0.0, 5.5, 7.0])),
        ("look_at", vector([0.0, 0.4, 0.0])),
        ("fov", Value::from(180.0)),
    ];
    let panorama = vec![
        ("type", Value::from("equirectangular")),
        ("position", vector([0.0, 2.2, 4.5])),
        ("look_at", vector([0.0, 0.6, 0.0])),
        ("h_fov", Value::from(360.0)),
        ("v_fov", Value::from(180.0)),
    ];
    vec![
        Case {
            name: "cube-floor, perspective",
            builtin: "cube-floor",
            keys: Vec::new(),
            drag: ("fov", 40.0, 80.0),
        },
        Case {
            name: "cube-floor, fisheye",
            builtin: "cube-floor",
            keys: fisheye,
            drag: ("fov", 150.0, 200.0),
        },
        Case {
            name: "teapot-dense, equirectangular",
            builtin: "teapot-dense",
            keys: panorama,
            drag: ("h_fov", 300.0, 360.0),
        },
    ]
}

/// Runs `flexcam bench view`: one line per case.
pub fn run(args: &ViewBenchArgs) -> Result<()> {
    let dir = std::env::temp_dir().join(format!("flexcam-bench-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .map_err(|e| Error::in_file(&dir, format!("cannot create the folder: {e}")))?;
    let result = run_cases(args, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn run_cases(args: &ViewBenchArgs, dir: &std::path::Path) -> Result<()> {
    println!(
        "viewer frame rate at {} x {}, one edit per frame ({} frames)",
        SIZE.0, SIZE.1, args.frames
    );
    for (i, case) in cases().into_iter().enumerate() {
        let replace = !case.keys.is_empty();
        let text = scene_variant(builtin::text(case.builtin)?, SIZE, &case.keys, replace)?;
        let path = dir.join(format!("case{i}.toml"));
        std::fs::write(&path, text)
            .map_err(|e| Error::in_file(&path, format!("cannot write: {e}")))?;
        let (key, from, to) = case.drag;
        let n = args.frames;
        let values: Vec<f64> = (0..n)
            .map(|k| from + (to - from) * f64::from(k) / f64::from(n - 1))
            .collect();
        let report = drag(&path, key, &values)?;
        println!(
            "{:32} {key:>6} {from}..{to}: {:7.1} frames/s ({:.2} ms/frame), shown by {}",
            case.name,
            report.fps(),
            report.total_ms / report.frames as f64,
            report.label
        );
    }
    Ok(())
}
