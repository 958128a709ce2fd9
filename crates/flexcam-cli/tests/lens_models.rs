//! The calibrated lens models from the command line: the example scenes render alike by ray
//! casting and by rasterisation, a calibration is scaled only when `calibration_size` says
//! how, and `import-cameras` turns a COLMAP cameras.txt into projection tables a scene takes.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use common::{camera_example, raster_agrees, run, run_json, run_ok};
use tempfile::TempDir;

/// Each `scenes/cameras/opencv*.toml` by raycast and raster: every pixel away from object
/// edges has the same id, and the relative RGB error (flat shading) is small.
#[test]
fn opencv_example_scenes_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    let mut scenes: Vec<PathBuf> = fs::read_dir(Path::new(&camera_example("")))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("opencv"))
        })
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 2, "{scenes:?}");
    for scene in &scenes {
        raster_agrees(&dir, &[&scene.to_string_lossy()]);
    }
}

/// Without `calibration_size` the intrinsics are for the scene's own size: another size is
/// refused with one line naming the file and the key; with it they scale.
#[test]
fn other_sizes_need_calibration_size() {
    let dir = TempDir::new().unwrap();
    let scene = fs::read_to_string(camera_example("opencv-teapot.toml")).unwrap();
    let fixed = scene.replace("calibration_size = [400, 300]\n", "");
    assert_ne!(fixed, scene);
    fs::write(dir.path().join("fixed.toml"), &fixed).unwrap();
    run_ok(&dir, &["render", "fixed.toml", "-o", "same.png"]);
    let out = run(
        &dir,
        &[
            "render",
            "fixed.toml",
            "--width",
            "200",
            "--height",
            "300",
            "-o",
            "half.png",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("fixed.toml")
            && stderr.contains("are for the scene's 400x300 image, not 200x300")
            && stderr.contains("calibration_size = [400, 300]"),
        "{stderr}"
    );
    assert!(!dir.path().join("half.png").exists());
    let scaled = run_json(
        &dir,
        &[
            "render",
            &camera_example("opencv-teapot.toml"),
            "--width",
            "200",
            "--height",
            "150",
            "-o",
            "half.png",
            "--stats",
            "-",
        ],
    );
    assert_eq!(scaled["width"], 200);
}

const CAMERAS: &str = "# Camera list with one line of data per camera:
#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]
1 SIMPLE_RADIAL 160 120 150 80 60 -0.05
2 OPENCV 160 120 150 151 80 60 -0.1 0.01 0.001 -0.002
3 OPENCV_FISHEYE 160 160 50 50 80 80 0.02 -0.004 0.0005 -0.00002
";

/// `import-cameras`: one table per camera, each a projection a scene renders once renamed
/// `[projection]`; a bad line is refused with the file and line, and nothing is written.
#[test]
fn import_cameras_writes_tables_scenes_render() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("cameras.txt"), CAMERAS).unwrap();
    let out = run_ok(&dir, &["import-cameras", "cameras.txt"]);
    let printed = String::from_utf8(out.stdout).unwrap();
    run_ok(&dir, &["import-cameras", "cameras.txt", "-o", "cams.toml"]);
    let written = fs::read_to_string(dir.path().join("cams.toml")).unwrap();
    assert_eq!(printed, written);
    assert_eq!(written.matches("\n[camera_").count(), 3);
    for id in ["1", "2", "3"] {
        // The table's own text, renamed, as a scene's projection.
        let header = format!("[camera_{id}]\n");
        let start = written.find(&header).unwrap() + header.len();
        let body = written[start..].split("\n\n").next().unwrap();
        let scene = format!(
            "[image]\nwidth = 80\nheight = 60\n[projection]\n{body}\n\
             [[object]]\nshape = \"sphere\"\nsize = 1.0\ntranslate = [0.0, 0.0, -4.0]\n"
        );
        fs::write(dir.path().join("s.toml"), scene).unwrap();
        run_ok(&dir, &["render", "s.toml", "-o", "s.png"]);
    }
    fs::write(
        dir.path().join("bad.txt"),
        "1 PINHOLE 10 10 5 5 5 5\n2 FOV 10 10 5 5 5 5 0.1\n",
    )
    .unwrap();
    let out = run(&dir, &["import-cameras", "bad.txt", "-o", "bad.toml"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with("flexcam: bad.txt:2:1: camera model \"FOV\" is not supported"),
        "{stderr}"
    );
    assert!(!dir.path().join("bad.toml").exists());
}
