//! The flags a render farm drives flexcam with: `--crop` tiles stitched back into the whole
//! frame byte for byte, `--threads`, `animate --frames` and `--skip-existing`, the `[image]
//! spp` scene key, the documented exit statuses and the `--stats` facts of a run.

use std::fs;
use std::path::{Path, PathBuf};

use exr::prelude::FlatSamples;
use tempfile::TempDir;

mod common;
use common::{run, run_json, run_ok};

/// The repository's scenes folder.
fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Width and height of the frames the crop tests split: odd, and not multiples of the ray
/// caster's tile, so tiles cut across its tiles and quads.
const SIZE: (u32, u32) = (101, 77);

/// Four windows covering the `SIZE` image, meeting at an odd pixel.
const TILES: [[u32; 4]; 4] = [
    [0, 0, 37, 41],
    [37, 0, 101, 41],
    [0, 41, 37, 77],
    [37, 41, 101, 77],
];

/// A frame's channels as raw bytes per pixel, row-major: (width, height, bytes per pixel,
/// bytes).
struct Raster {
    width: usize,
    height: usize,
    pixel: usize,
    bytes: Vec<u8>,
}

impl Raster {
    fn png(path: &Path) -> Raster {
        let image = image::open(path).unwrap();
        let (width, height) = (image.width() as usize, image.height() as usize);
        let bytes = image.as_bytes().to_vec();
        Raster {
            width,
            height,
            pixel: bytes.len() / (width * height),
            bytes,
        }
    }

    /// Every channel of every layer of the EXR at `path`, interleaved per pixel, as the
    /// bits of its samples.
    fn exr(path: &Path) -> Raster {
        let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
        let layer = &image.layer_data[0];
        let (width, height) = (layer.size.0, layer.size.1);
        let channels: Vec<Vec<[u8; 4]>> = layer
            .channel_data
            .list
            .iter()
            .map(|c| match &c.sample_data {
                FlatSamples::F32(v) => v.iter().map(|x| x.to_bits().to_le_bytes()).collect(),
                FlatSamples::U32(v) => v.iter().map(|x| x.to_le_bytes()).collect(),
                FlatSamples::F16(v) => v
                    .iter()
                    .map(|x| u32::from(x.to_bits()).to_le_bytes())
                    .collect(),
            })
            .collect();
        let bytes = (0..width * height)
            .flat_map(|i| channels.iter().flat_map(move |c| c[i]))
            .collect();
        Raster {
            width,
            height,
            pixel: 4 * channels.len(),
            bytes,
        }
    }

    /// `tiles` (each with its window) put back into one image of `SIZE`.
    fn stitch(tiles: &[([u32; 4], Raster)]) -> Raster {
        let pixel = tiles[0].1.pixel;
        let (width, height) = (SIZE.0 as usize, SIZE.1 as usize);
        let mut bytes = vec![0; width * height * pixel];
        for ([x0, y0, x1, y1], tile) in tiles {
            assert_eq!(
                (tile.width, tile.height),
                ((x1 - x0) as usize, (y1 - y0) as usize)
            );
            for row in 0..tile.height {
                let from = row * tile.width * pixel;
                let to = ((*y0 as usize + row) * width + *x0 as usize) * pixel;
                let len = tile.width * pixel;
                bytes[to..to + len].copy_from_slice(&tile.bytes[from..from + len]);
            }
        }
        Raster {
            width,
            height,
            pixel,
            bytes,
        }
    }
}

/// Renders `scene` whole and as the four `TILES` with `flags`, to `extension` outputs,
/// and asserts that the stitched tiles are the whole frame, byte for byte; `aovs` adds
/// the AOV EXR (colour, depth, ids) and compares it too.
fn assert_tiles_stitch(scene: &str, flags: &[&str], extension: &str) {
    let dir = TempDir::new().unwrap();
    let (w, h) = (SIZE.0.to_string(), SIZE.1.to_string());
    let base = [&["render", scene, "--width", &w, "--height", &h][..], flags].concat();
    let render = |name: &str, crop: Option<String>| {
        let colour = format!("{name}.{extension}");
        let aovs = format!("{name}-aovs.exr");
        let mut args = base.clone();
        args.extend(["-o", &colour, "--aovs", &aovs]);
        if let Some(crop) = &crop {
            args.extend(["--crop", crop]);
        }
        run_ok(&dir, &args);
        let colour = dir.path().join(colour);
        let colour = match extension {
            "exr" => Raster::exr(&colour),
            _ => Raster::png(&colour),
        };
        (colour, Raster::exr(&dir.path().join(aovs)))
    };
    let (whole, whole_aovs) = render("whole", None);
    let (tiles, tile_aovs): (Vec<_>, Vec<_>) = TILES
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let crop = t.map(|v| v.to_string()).join(",");
            let (colour, aovs) = render(&format!("tile{i}"), Some(crop));
            ((*t, colour), (*t, aovs))
        })
        .unzip();
    for (what, stitched, whole) in [
        ("colour", Raster::stitch(&tiles), whole),
        ("aovs", Raster::stitch(&tile_aovs), whole_aovs),
    ] {
        assert_eq!(
            (stitched.width, stitched.height, stitched.pixel),
            (whole.width, whole.height, whole.pixel)
        );
        let differ = (0..whole.width * whole.height)
            .filter(|i| {
                let px = i * whole.pixel..(i + 1) * whole.pixel;
                stitched.bytes[px.clone()] != whole.bytes[px]
            })
            .count();
        assert_eq!(
            differ, 0,
            "{scene} {flags:?} {extension}: {what} pixels differ"
        );
    }
}

#[test]
fn raycast_tiles_stitch_into_the_whole_frame() {
    assert_tiles_stitch("builtin:cube-floor", &["--method", "raycast"], "png");
    assert_tiles_stitch(
        "builtin:cube-floor",
        &["--method", "raycast", "--spp", "4"],
        "exr",
    );
    let flexible = scenes().join("flexible-bent.toml");
    assert_tiles_stitch(flexible.to_str().unwrap(), &["--shading", "flat"], "png");
}

#[test]
fn raster_tiles_stitch_into_the_whole_frame() {
    assert_tiles_stitch("builtin:cube-floor", &["--method", "raster"], "png");
    assert_tiles_stitch("builtin:cube-floor", &["--method", "raster"], "exr");
}

#[test]
fn crop_windows_outside_the_image_are_refused() {
    let dir = TempDir::new().unwrap();
    for (crop, message) in [
        (
            "0,0,65,10",
            "flexcam: --crop: crop window 0,0,65,10 does not fit in the 64 x 48 image",
        ),
        (
            "5,5,5,9",
            "flexcam: --crop: crop window 5,5,5,9 is empty (it needs X0 < X1 and Y0 < Y1)",
        ),
        (
            "1,2,3",
            "flexcam: --crop: needs 4 pixel bounds X0,Y0,X1,Y1, got 3",
        ),
    ] {
        let args = ["render", "--width", "64", "--height", "48", "--crop", crop];
        let out = run(&dir, &args);
        assert_eq!(out.status.code(), Some(1), "{crop}");
        assert_eq!(String::from_utf8_lossy(&out.stderr).trim(), message);
        assert!(!dir.path().join("flexcam.png").exists());
    }
}

/// The image does not depend on the number of threads.
#[test]
fn threads_change_no_pixel() {
    let dir = TempDir::new().unwrap();
    let small = [
        "render",
        "builtin:cube-floor",
        "--width",
        "48",
        "--height",
        "32",
    ];
    for threads in ["1", "3"] {
        let out = format!("{threads}.png");
        let args = ["--threads", threads, "-o", &out, "--stats", "-"];
        let v = run_json(&dir, &[&small[..], &args].concat());
        assert_eq!(v["threads"].to_string(), threads);
    }
    assert_eq!(
        fs::read(dir.path().join("1.png")).unwrap(),
        fs::read(dir.path().join("3.png")).unwrap()
    );
}

#[test]
fn stats_report_version_threads_wall_time_and_outputs() {
    let dir = TempDir::new().unwrap();
    let v = run_json(
        &dir,
        &[
            "render", "--width", "16", "--height", "12", "-o", "c.png", "--depth", "d.exr",
            "--stats", "-",
        ],
    );
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    assert!(v["threads"].as_u64().unwrap() >= 1);
    let (wall, render) = (
        v["wall_ms"].as_f64().unwrap(),
        v["render_ms"].as_f64().unwrap(),
    );
    assert!(wall >= render, "{wall} < {render}");
    assert_eq!(v["outputs"], serde_json::json!(["c.png", "d.exr"]));
}

/// `[image] spp` is what `--spp` gives when the flag is not there.
#[test]
fn the_scene_key_spp_is_the_default_of_the_flag() {
    let dir = TempDir::new().unwrap();
    let text = fs::read_to_string(scenes().join("cube-floor.toml")).unwrap();
    let with_spp = text.replacen("[image]", "[image]\nspp = 4", 1);
    assert_ne!(with_spp, text, "the scene has an [image] table");
    fs::write(dir.path().join("s.toml"), with_spp).unwrap();
    fs::write(dir.path().join("plain.toml"), &text).unwrap();
    let small = ["--width", "40", "--height", "30"];
    let key = run_json(
        &dir,
        &[
            &["render", "s.toml", "-o", "key.png", "--stats", "-"][..],
            &small,
        ]
        .concat(),
    );
    assert_eq!(key["spp"], 4);
    run_ok(
        &dir,
        &[
            &["render", "plain.toml", "-o", "flag.png", "--spp", "4"][..],
            &small,
        ]
        .concat(),
    );
    run_ok(
        &dir,
        &[
            &["render", "s.toml", "-o", "one.png", "--spp", "1"][..],
            &small,
        ]
        .concat(),
    );
    run_ok(
        &dir,
        &[&["render", "plain.toml", "-o", "plain.png"][..], &small].concat(),
    );
    let read = |name: &str| fs::read(dir.path().join(name)).unwrap();
    assert_eq!(read("key.png"), read("flag.png"));
    assert_eq!(read("one.png"), read("plain.png"));
    assert_ne!(read("key.png"), read("one.png"));

    let bad = text.replacen("[image]", "[image]\nspp = 0", 1);
    fs::write(dir.path().join("bad.toml"), bad).unwrap();
    let out = run(&dir, &["render", "bad.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).starts_with("flexcam: bad.toml:"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `animate --frames` renders the listed frames, byte for byte as the whole animation
/// renders them; `--skip-existing` leaves out the frames already written.
#[test]
fn animate_renders_the_listed_frames_and_skips_existing_ones() {
    let dir = TempDir::new().unwrap();
    let scene = scenes().join("flexible-animation.toml");
    let scene = scene.to_str().unwrap();
    let small = ["--width", "24", "--height", "16", "--shading", "flat"];
    run_ok(
        &dir,
        &[&["animate", scene, "-o", "all/f_#.png"][..], &small].concat(),
    );
    let stats = run_json(
        &dir,
        &[
            &[
                "animate",
                scene,
                "-o",
                "some/f_#.png",
                "--frames",
                "1,4-8:3",
                "--stats",
                "-",
            ][..],
            &small,
        ]
        .concat(),
    );
    assert_eq!(stats["frames"], 3);
    let names = |folder: &str| {
        let mut names: Vec<String> = fs::read_dir(dir.path().join(folder))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    assert_eq!(names("some"), ["f_1.png", "f_4.png", "f_7.png"]);
    for name in names("some") {
        assert_eq!(
            fs::read(dir.path().join("some").join(&name)).unwrap(),
            fs::read(dir.path().join("all").join(&name)).unwrap(),
            "{name}"
        );
    }
    // A rerun of the whole range renders only the frames still missing.
    fs::write(dir.path().join("some/f_4.png"), b"kept").unwrap();
    let stats = run_json(
        &dir,
        &[
            &[
                "animate",
                scene,
                "-o",
                "some/f_#.png",
                "--frames",
                "0-8",
                "--skip-existing",
                "--stats",
                "-",
            ][..],
            &small,
        ]
        .concat(),
    );
    assert_eq!(stats["frames"], 6);
    assert_eq!(names("some").len(), 9);
    assert_eq!(fs::read(dir.path().join("some/f_4.png")).unwrap(), b"kept");

    let out = run(
        &dir,
        &[
            &["animate", scene, "--gif", "a.gif", "--frames", "2-9"][..],
            &small,
        ]
        .concat(),
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "flexcam: --frames 2-9: \"2-9\" is past the last frame, 8 (frames count from 0)"
    );
    assert!(!dir.path().join("a.gif").exists());
    let out = run(
        &dir,
        &["animate", scene, "--gif", "a.gif", "--skip-existing"],
    );
    assert_eq!(out.status.code(), Some(2));
}

/// Exit statuses: 0 done, 1 a render or input error, 2 a usage error, 3 a comparison that
/// missed its threshold.
#[test]
fn exit_statuses_tell_the_kinds_of_failure_apart() {
    let dir = TempDir::new().unwrap();
    let small = ["--width", "32", "--height", "24"];
    let code = |args: &[&str]| run(&dir, &[args, &small].concat()).status.code();
    assert_eq!(code(&["render"]), Some(0));
    assert_eq!(code(&["render", "missing.toml"]), Some(1));
    assert_eq!(code(&["render", "--method", "trilinear"]), Some(1));
    assert_eq!(code(&["render", "--no-such-flag"]), Some(2));
    assert_eq!(code(&["render", "--spp", "x"]), Some(2));
    let compare = ["compare", "builtin:cube-floor", "--method", "raster"];
    assert_eq!(
        code(&[&compare[..], &["--min-id-agreement", "0"]].concat()),
        Some(0)
    );
    let missed = run(
        &dir,
        &[&compare[..], &["--min-id-agreement", "100.5"], &small].concat(),
    );
    assert_eq!(missed.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&missed.stderr).contains("is below the required 100.5 %"));
    assert_eq!(
        code(&[&compare[..], &["--min-id-agreement", "nan"]].concat()),
        Some(1)
    );
    let help = String::from_utf8(run(&dir, &["--help"]).stdout).unwrap();
    assert!(
        help.contains("Exit status: 0 done; 1 a render or input error"),
        "{help}"
    );
}

/// `-D KEY=VALUE` renders what the edited file renders; by table name and index in arrays
/// of tables, on built-in scenes too.
#[test]
fn definitions_render_as_the_edited_file() {
    let dir = TempDir::new().unwrap();
    let text = fs::read_to_string(scenes().join("cube-floor.toml")).unwrap();
    let edited = text.replacen("fov = 50.0", "fov = 70.0", 1).replacen(
        "color = [0.9, 0.9, 0.9]",
        "color = [1.0, 0.0, 0.0]",
        1,
    );
    assert_ne!(edited, text);
    fs::write(dir.path().join("s.toml"), &text).unwrap();
    fs::write(dir.path().join("edited.toml"), &edited).unwrap();
    let small = ["--width", "40", "--height", "30"];
    run_ok(
        &dir,
        &[&["render", "edited.toml", "-o", "edited.png"][..], &small].concat(),
    );
    for (name, floor) in [
        ("by_name.png", "object.floor.color"),
        ("by_index.png", "object.0.color"),
    ] {
        let floor = format!("{floor}=[1.0, 0.0, 0.0]");
        let args = [
            "render",
            "s.toml",
            "-o",
            name,
            "-D",
            "projection.fov=70",
            "-D",
            &floor,
        ];
        run_ok(&dir, &[&args[..], &small].concat());
        assert_eq!(
            fs::read(dir.path().join(name)).unwrap(),
            fs::read(dir.path().join("edited.png")).unwrap(),
            "{name}"
        );
    }
    let v = run_json(
        &dir,
        &[
            "render",
            "builtin:cube-floor",
            "-D",
            "image.width=24",
            "-D",
            "image.height=20",
            "--stats",
            "-",
        ],
    );
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(24), Some(20))
    );
}

#[test]
fn bad_definitions_name_the_argument() {
    let dir = TempDir::new().unwrap();
    fs::copy(scenes().join("cube-floor.toml"), dir.path().join("s.toml")).unwrap();
    for (definition, status, message) in [
        (
            "projection.fov=wide",
            1,
            "flexcam: s.toml: -D projection.fov=wide: invalid type: string \"wide\", expected f64",
        ),
        (
            "projection.fvo=90",
            1,
            "flexcam: s.toml: -D projection.fvo=90: unknown key `fvo`; did you mean `fov`?",
        ),
        (
            "object.table.color=[1,0,0]",
            1,
            "flexcam: s.toml: -D object.table.color=[1,0,0]: object has no table table (give a 0-based index below 2 or a name)",
        ),
        (
            "projection.fov.x=1",
            1,
            "flexcam: s.toml: -D projection.fov.x=1: projection.fov is not a table",
        ),
        (
            "projection.fov",
            2,
            "flexcam: invalid value 'projection.fov' for '--define <KEY=VALUE>': -D projection.fov: needs KEY=VALUE, e.g. projection.fov=90",
        ),
    ] {
        let out = run(&dir, &["render", "s.toml", "-D", definition, "--width", "8", "--height", "8"]);
        assert_eq!(out.status.code(), Some(status), "{definition}");
        assert_eq!(String::from_utf8_lossy(&out.stderr).trim(), message);
        assert!(!dir.path().join("flexcam.png").exists());
    }
}

/// `--width` or `--height` alone keeps the scene's aspect ratio (cube-floor is 800 x 800,
/// the default scene 800 x 600 unless its file says otherwise).
#[test]
fn one_side_keeps_the_aspect_ratio() {
    let dir = TempDir::new().unwrap();
    let size = |args: &[&str]| {
        let v = run_json(&dir, &[&["render", "--stats", "-"][..], args].concat());
        (v["width"].as_u64().unwrap(), v["height"].as_u64().unwrap())
    };
    assert_eq!(size(&["builtin:cube-floor", "--width", "33"]), (33, 33));
    let scene = scenes().join("cube-floor.toml");
    let wide = fs::read_to_string(&scene)
        .unwrap()
        .replacen("height = 800", "height = 450", 1);
    fs::write(dir.path().join("wide.toml"), wide).unwrap();
    assert_eq!(size(&["wide.toml", "--width", "64"]), (64, 36));
    assert_eq!(size(&["wide.toml", "--height", "45"]), (80, 45));
    assert_eq!(size(&["wide.toml", "--width", "3"]), (3, 2));
    assert_eq!(size(&["wide.toml", "--width", "1"]), (1, 1));
    assert_eq!(
        size(&["wide.toml", "--width", "50", "--height", "50"]),
        (50, 50)
    );
}
