//! `flexcam reproject --input-projection`: photos taken by cylindrical, fisheye and
//! equirectangular cameras, reprojected to a perspective view from the same eye, match the
//! perspective camera's own render; a photo read with the wrong projection does not; flags
//! of another kind of photo are refused.

mod common;

use std::fs;

use common::{run, run_ok};
use tempfile::TempDir;

/// A scene seen from [0, 2, 6] towards [0, 1, 0]; `{projection}` is the camera's type and
/// angles, `{size}` the image size.
const SCENE: &str = r#"
[image]
{size}
background = [0.2, 0.3, 0.5]

[projection]
position = [0.0, 2.0, 6.0]
look_at = [0.0, 1.0, 0.0]
{projection}

[[object]]
name = "floor"
shape = "plane"
size = [40.0, 40.0]
color = [0.9, 0.85, 0.8]
checker = { color = [0.15, 0.2, 0.1], size = 2.0 }

[[object]]
name = "box"
shape = "box"
size = [2.0, 2.0, 2.0]
color = [0.9, 0.2, 0.1]
translate = [-1.2, 1.0, 0.0]
rotate = [0.0, 30.0, 0.0]

[[object]]
name = "ball"
shape = "sphere"
size = 1.0
color = [0.2, 0.6, 0.95]
translate = [1.5, 1.0, 1.0]
"#;

/// The photo's look direction and up, as `--input-direction` / `--input-up` take them: the
/// scene camera's (look_at - position).
const DIRECTION: &str = "0,-1,-6";

fn scene(dir: &TempDir, name: &str, projection: &str, (w, h): (u32, u32)) {
    let text = SCENE
        .replace("{projection}", projection)
        .replace("{size}", &format!("width = {w}\nheight = {h}"));
    fs::write(dir.path().join(name), text).unwrap();
}

/// The share of pixels whose colours differ by at most 8 / 255 in every channel.
fn agreement(dir: &TempDir, a: &str, b: &str) -> f64 {
    let a = image::open(dir.path().join(a)).unwrap().to_rgb8();
    let b = image::open(dir.path().join(b)).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions());
    let close = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).all(|c| p[c].abs_diff(q[c]) <= 8))
        .count();
    close as f64 / f64::from(a.width() * a.height())
}

/// Renders the photo of `projection` at `size` (lit, sRGB: the encoding `reproject` reads
/// and writes; 4 samples a pixel), reprojects it with `flags` and 16 samples a pixel
/// through the perspective scene and returns the agreement with the perspective render
/// (percent). The photos have 3.8 (fisheye 4.7) times the perspective's pixels per degree,
/// and both sides are antialiased, so that edges agree as well as flat areas.
fn reprojected(
    dir: &TempDir,
    name: &str,
    projection: &str,
    size: (u32, u32),
    flags: &[&str],
) -> f64 {
    let photo_scene = format!("{name}.toml");
    scene(dir, &photo_scene, projection, size);
    let photo = format!("{name}.png");
    run_ok(dir, &["render", &photo_scene, "--spp", "4", "-o", &photo]);
    let out = format!("{name}-persp.png");
    let mut args = vec![
        "reproject",
        "--input",
        &photo,
        "persp.toml",
        "-o",
        &out,
        "--spp",
        "16",
    ];
    args.extend_from_slice(flags);
    run_ok(dir, &args);
    100.0 * agreement(dir, &out, "direct.png")
}

#[test]
fn photos_of_each_projection_reproject_to_the_direct_view() {
    let dir = TempDir::new().unwrap();
    scene(
        &dir,
        "persp.toml",
        "type = \"perspective\"\nfov = 60.0",
        (64, 48),
    );
    let args = ["render", "persp.toml", "--spp", "16", "-o", "direct.png"];
    run_ok(&dir, &args);
    let frame = ["--input-direction", DIRECTION, "--input-up", "0,1,0"];
    let cylindrical = reprojected(
        &dir,
        "cyl",
        "type = \"cylindrical\"\nh_fov = 360.0\nv_fov = 120.0",
        (1440, 800),
        &[
            &["--input-projection", "cylindrical", "--input-v-fov", "120"],
            &frame[..],
        ]
        .concat(),
    );
    let fisheye = reprojected(
        &dir,
        "fish",
        "type = \"fisheye\"\nfov = 180.0",
        (900, 900),
        &[&["--input-projection", "fisheye"], &frame[..]].concat(),
    );
    let equirectangular = reprojected(
        &dir,
        "equi",
        "type = \"equirectangular\"",
        (1440, 720),
        &frame,
    );
    // The cylindrical photo read as if it were an equirectangular one of the same angles:
    // the rows are wrong.
    let out = [
        "reproject",
        "--input",
        "cyl.png",
        "persp.toml",
        "-o",
        "wrong.png",
        "--spp",
        "16",
    ];
    let out = [&out[..], &["--input-v-fov", "120"]].concat();
    run_ok(&dir, &[&out[..], &frame[..]].concat());
    let wrong = 100.0 * agreement(&dir, "wrong.png", "direct.png");
    println!(
        "within 8/255 of the direct render: cylindrical {cylindrical:.2} %, fisheye \
         {fisheye:.2} %, equirectangular {equirectangular:.2} %; the cylindrical photo read \
         as equirectangular {wrong:.2} %"
    );
    for (kind, share) in [
        ("cylindrical", cylindrical),
        ("fisheye", fisheye),
        ("equirectangular", equirectangular),
    ] {
        assert!(share >= 98.5, "{kind}: {share:.2} %");
    }
    assert!(wrong < 80.0, "{wrong:.2} %");
}

#[test]
fn flags_of_another_kind_of_photo_are_refused() {
    let dir = TempDir::new().unwrap();
    scene(
        &dir,
        "persp.toml",
        "type = \"perspective\"\nfov = 60.0",
        (32, 24),
    );
    run_ok(&dir, &["render", "persp.toml", "-o", "photo.png"]);
    for (flags, needle) in [
        (
            &["--input-projection", "cylindrical", "--input-fov", "90"][..],
            "--input-fov applies to --input-projection fisheye, not cylindrical",
        ),
        (
            &["--input-projection", "fisheye", "--input-h-fov", "90"],
            "--input-h-fov applies to --input-projection equirectangular or cylindrical",
        ),
        (&["--input-mapping", "equisolid"], "--input-mapping applies"),
        (
            &["--input-direction", "1,2"],
            "--input-direction: needs 3 numbers",
        ),
        (
            &["--input-direction", "0,1,0"],
            "photo.png: read as a photo of type equirectangular",
        ),
        (
            &["--input-projection", "fisheye", "--input-fov", "400"],
            "fov",
        ),
    ] {
        let mut args = vec![
            "reproject",
            "--input",
            "photo.png",
            "persp.toml",
            "-o",
            "o.png",
        ];
        args.extend_from_slice(flags);
        let out = run(&dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flags:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(needle), "{flags:?}: {stderr}");
        assert!(!dir.path().join("o.png").exists());
    }
    let args = [
        "reproject",
        "--input",
        "photo.png",
        "persp.toml",
        "-o",
        "o.png",
    ];
    let out = run(
        &dir,
        &[&args[..], &["--input-projection", "cubic"]].concat(),
    );
    assert_eq!(out.status.code(), Some(2));
}
