//! `flexcam bench view`: the viewer's frame rate at 1280 x 720 while a projection parameter
//! changes every frame (the render loop driven as the window drives it; see
//! `flexcam_view::bench`), on cube-floor through invertible cameras and on the
//! 123,554-triangle teapot-dense scene as an equirectangular panorama; and while a handle
//! of a flexible volume on cube-floor is dragged (handles and volume sketch made again each
//! frame, as in the window).

use clap::Args;
use flexcam::scene::builtin;
use flexcam::{Error, Result};
use flexcam_view::bench::{drag, drag_handle, scene_variant};
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
/// what is dragged.
struct Case {
    name: &'static str,
    builtin: &'static str,
    keys: Vec<(&'static str, Value)>,
    drag: Drag,
}

/// What a case drags every frame.
enum Drag {
    /// A key, from a value to another over the frames (a slider).
    Key(&'static str, f64, f64),
    /// A handle, by these pixels a frame (as `drag` in a script).
    Handle(&'static str, f64, f64),
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
    let rectangle = |center: [f64; 3], half: f64| {
        let mut table = toml_edit::InlineTable::new();
        table.insert("surface", Value::from("rectangle"));
        table.insert("center", vector(center));
        table.insert("u_axis", vector([half, 0.0, 0.0]));
        table.insert("v_axis", vector([0.0, half * 9.0 / 16.0, 0.0]));
        Value::InlineTable(table)
    };
    let volume = vec![
        ("type", Value::from("flexible")),
        ("near", rectangle([0.0, 2.0, 6.0], 0.4)),
        ("far", rectangle([0.0, 0.0, -4.0], 5.0)),
    ];
    vec![
        Case {
            name: "cube-floor, perspective",
            builtin: "cube-floor",
            keys: Vec::new(),
            drag: Drag::Key("fov", 40.0, 80.0),
        },
        Case {
            name: "cube-floor, fisheye",
            builtin: "cube-floor",
            keys: fisheye,
            drag: Drag::Key("fov", 150.0, 200.0),
        },
        Case {
            name: "teapot-dense, equirectangular",
            builtin: "teapot-dense",
            keys: panorama,
            drag: Drag::Key("h_fov", 300.0, 360.0),
        },
        Case {
            name: "cube-floor, flexible near/far",
            builtin: "cube-floor",
            keys: volume,
            drag: Drag::Handle("far.center", 1.0, -0.5),
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
        let n = args.frames;
        let (report, what) = match case.drag {
            Drag::Key(key, from, to) => {
                let values: Vec<f64> = (0..n)
                    .map(|k| from + (to - from) * f64::from(k) / f64::from(n - 1))
                    .collect();
                (drag(&path, key, &values)?, format!("{key} {from}..{to}"))
            }
            Drag::Handle(name, dx, dy) => (
                drag_handle(&path, name, (dx, dy), n as usize)?,
                format!("{name} by ({dx}, {dy}) px"),
            ),
        };
        println!(
            "{:32} {what:>18}: {:7.1} frames/s ({:.2} ms/frame), shown by {}",
            case.name,
            report.fps(),
            report.total_ms / report.frames as f64,
            report.label
        );
    }
    Ok(())
}
