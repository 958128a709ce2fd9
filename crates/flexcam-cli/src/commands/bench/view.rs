//! `flexcam bench view`: the viewer's frame rate at 1280 x 720 while a projection parameter
//! changes every frame (the render loop driven as the window drives it; see
//! `flexcam_view::bench`), on cube-floor through invertible cameras and on the
//! 123,554-triangle teapot-dense scene as an equirectangular panorama; and while a handle
//! of a flexible volume on cube-floor is dragged (handles and volume sketch made again each
//! frame, as in the window). With `--presets`: cube-floor through every flexible preset
//! while the camera orbits (the line says which stage showed the frames: `raster` for the
//! presets with an analytic inverse).

use clap::Args;
use flexcam::scene::builtin;
use flexcam::{Error, Result};
use flexcam_view::bench::{drag, drag_handle, orbit, scene_variant};
use flexcam_view::Settings;
use toml_edit::Value;

/// Arguments of `flexcam bench view`.
#[derive(Args, Debug)]
pub struct ViewBenchArgs {
    /// Frames (edits) per case.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    frames: u32,
    /// Instead of the default cases: cube-floor through every flexible preset, the camera
    /// orbiting half a degree a frame.
    #[arg(long)]
    presets: bool,
    /// Only the cases whose name contains this text (e.g. `equirectangular`, `fisheye`);
    /// refused when none does.
    #[arg(long, value_name = "TEXT")]
    case: Option<String>,
    /// Every raster preview at the full 1280 x 720 (the size the frame-rate target is
    /// for), never halved when the last one missed a 60 Hz display frame as in the window.
    #[arg(long)]
    full_size: bool,
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
    /// The camera, by these degrees a frame (as `orbit` in a script).
    Orbit(f64, f64),
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

/// Cube-floor's camera frame and a clip range that holds the scene, then `keys`: the
/// projection of a preset case.
fn preset(name: &'static str, keys: Vec<(&'static str, Value)>) -> Case {
    let mut all = vec![
        ("type", Value::from("flexible")),
        ("preset", Value::from(name)),
        ("position", vector([0.0, 5.5, 7.0])),
        ("look_at", vector([0.0, 0.4, 0.0])),
    ];
    if name != "inverse_perspective" {
        all.push((
            "clip",
            flexcam::scene::file::edit::float_array(&[0.0, 30.0]),
        ));
    }
    all.extend(keys);
    Case {
        name,
        builtin: "cube-floor",
        keys: all,
        drag: Drag::Orbit(0.5, 0.0),
    }
}

/// Cube-floor through every flexible preset (keys as in the example scenes of
/// scenes/README.md).
fn preset_cases() -> Vec<Case> {
    let n = Value::from;
    let array = |v: &[f64]| flexcam::scene::file::edit::float_array(v);
    let rows = |rows: &[&[f64]]| Value::Array(rows.iter().map(|r| array(r)).collect());
    vec![
        preset("perspective", vec![("fov", n(50.0))]),
        preset(
            "inverse_perspective",
            vec![("fov", n(50.0)), ("converge", vector([0.0, -1.5, -3.0]))],
        ),
        preset("orthographic", vec![("width", n(8.0))]),
        preset(
            "oblique",
            vec![("width", n(8.0)), ("shear", array(&[0.2, 0.1]))],
        ),
        preset("pushbroom", vec![("width", n(8.0)), ("v_fov", n(50.0))]),
        preset(
            "crossed_slits",
            vec![("fov", n(60.0)), ("slit_distance", n(-3.0))],
        ),
        preset("cylindrical", vec![("h_fov", n(360.0)), ("v_fov", n(90.0))]),
        preset("equirectangular", Vec::new()),
        preset("cubic", Vec::new()),
        preset("rounded_cubic", vec![("corner_radius", n(0.5))]),
        preset("fisheye", vec![("fov", n(180.0))]),
        preset(
            "off_axis",
            vec![("fov", n(50.0)), ("shift", array(&[0.2, 0.1]))],
        ),
        preset("twist", vec![("fov", n(50.0)), ("twist", n(60.0))]),
        preset(
            "axonometric",
            vec![
                ("width", n(8.0)),
                ("azimuth", n(45.0)),
                ("elevation", n(35.264)),
            ],
        ),
        preset(
            "glc",
            vec![
                ("width", n(2.0)),
                (
                    "generators",
                    rows(&[
                        &[-0.5, -0.5, -1.0, -1.0],
                        &[0.5, -0.5, 1.0, -1.0],
                        &[-0.5, 0.5, -1.0, 1.0],
                    ]),
                ),
            ],
        ),
        preset(
            "ortho_near_persp_far",
            vec![("fov", n(50.0)), ("transition", n(8.0))],
        ),
        preset(
            "depth_transition",
            vec![
                ("fovs", array(&[60.0, 20.0])),
                ("transitions", array(&[8.0])),
            ],
        ),
        preset(
            "occlusion",
            vec![
                ("fov", n(60.0)),
                ("transition", n(6.0)),
                ("pole", array(&[0.5, 0.55])),
                ("strength", n(0.12)),
            ],
        ),
        preset(
            "mcop",
            vec![(
                "path",
                rows(&[&[-7.0, 3.0, 0.0], &[-4.95, 3.0, 4.95], &[0.0, 3.0, 7.0]]),
            )],
        ),
        preset("long_scene", vec![("width", n(8.0)), ("v_fov", n(50.0))]),
        preset(
            "magnifier",
            vec![
                ("fov", n(60.0)),
                ("center", array(&[0.5, 0.55])),
                ("radius", n(0.3)),
                ("magnification", n(3.0)),
            ],
        ),
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
    let cases = if args.presets {
        preset_cases()
    } else {
        cases()
    };
    let cases: Vec<Case> = match &args.case {
        None => cases,
        Some(text) => {
            let names: Vec<&str> = cases.iter().map(|c| c.name).collect();
            let chosen: Vec<Case> = cases
                .into_iter()
                .filter(|c| c.name.contains(text.as_str()))
                .collect();
            if chosen.is_empty() {
                return Err(Error::new(format!(
                    "--case {text:?} names no case; the cases are: {}",
                    names.join("; ")
                )));
            }
            chosen
        }
    };
    let settings = Settings {
        full_size_previews: args.full_size,
        ..Settings::DEFAULT
    };
    for (i, case) in cases.into_iter().enumerate() {
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
                (
                    drag(&path, settings, key, &values)?,
                    format!("{key} {from}..{to}"),
                )
            }
            Drag::Handle(name, dx, dy) => (
                drag_handle(&path, settings, name, (dx, dy), n as usize)?,
                format!("{name} by ({dx}, {dy}) px"),
            ),
            Drag::Orbit(yaw, pitch) => (
                orbit(&path, settings, (yaw, pitch), n as usize)?,
                format!("orbit ({yaw}, {pitch}) deg"),
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
