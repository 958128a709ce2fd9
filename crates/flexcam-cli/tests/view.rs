//! `flexcam view --script`: frames byte for byte those of `flexcam render` of the saved
//! scene, the scene saved with its comments and layout, bad lines and invalid edits as one
//! error line naming the script, and a scripted window screenshot under a display.

mod common;

use std::path::Path;
use std::process::Command as Process;

use common::{run, run_ok};
use tempfile::TempDir;

const CUBE_FLOOR: &str = include_str!("../../../scenes/cube-floor.toml");

/// `flexcam view` on the scene and script of [`setup`].
const VIEW: [&str; 4] = ["view", "scene.toml", "--script", "view.txt"];

/// A folder holding `scene.toml` (cube-floor at a small size) and `view.txt` (`script`).
fn setup(script: &str) -> TempDir {
    let dir = TempDir::new().unwrap();
    let scene = CUBE_FLOOR.replace("width = 800\nheight = 800", "width = 96\nheight = 64");
    assert_ne!(scene, CUBE_FLOOR);
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    dir
}

fn read(dir: &TempDir, name: &str) -> Vec<u8> {
    std::fs::read(dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn frame_is_what_render_writes_for_the_saved_scene() {
    let dir = setup("set fov 70\norbit 20 10\nidle\nframe f.png\nsave s.toml\n");
    run_ok(&dir, &VIEW);
    run_ok(&dir, &["render", "s.toml", "-o", "r.png"]);
    assert_eq!(read(&dir, "f.png"), read(&dir, "r.png"));
    // The edit changed the image.
    run_ok(&dir, &["render", "scene.toml", "-o", "original.png"]);
    assert_ne!(read(&dir, "f.png"), read(&dir, "original.png"));
}

#[test]
fn frame_follows_method_and_shading() {
    let dir = setup("method raster\nset fov 65.5\nframe f.png\nsave s.toml\n");
    run_ok(&dir, &[&VIEW[..], &["--shading", "flat"]].concat());
    let args = ["render", "s.toml", "--method", "raster"];
    run_ok(
        &dir,
        &[&args[..], &["--shading", "flat", "-o", "r.png"]].concat(),
    );
    assert_eq!(read(&dir, "f.png"), read(&dir, "r.png"));
    run_ok(
        &dir,
        &[&args[..], &["--shading", "lit", "-o", "lit.png"]].concat(),
    );
    assert_ne!(read(&dir, "f.png"), read(&dir, "lit.png"));
}

#[test]
fn save_keeps_comments_and_layout() {
    let dir = setup("set fov 42.25\nsave s.toml\n");
    run_ok(&dir, &VIEW);
    let original = String::from_utf8(read(&dir, "scene.toml")).unwrap();
    let saved = String::from_utf8(read(&dir, "s.toml")).unwrap();
    assert_eq!(saved, original.replace("fov = 50.0", "fov = 42.25"));
}

#[test]
fn bad_lines_are_one_error_naming_script_line_and_column() {
    let cases = [
        (
            "idle\n  orbit 1 x\nframe f.png\n",
            "view.txt:2:11: expected a number, got `x`",
        ),
        (
            "frame f.png\nzoom 2\n",
            "view.txt:2:1: unknown command `zoom`",
        ),
        (
            "idle\nmethod warp\n",
            "view.txt:2:8: unknown method \"warp\"",
        ),
        // Errors found when a line runs name it too; the lines before it have run.
        ("set fov 500\nframe f.png\n", "view.txt:1:1: scene.toml:"),
        (
            "drag p3 1 2\n",
            "view.txt:1:1: no handle `p3` (this projection's handles: position, look_at)",
        ),
    ];
    for (script, expected) in cases {
        let dir = setup(script);
        let out = run(&dir, &VIEW);
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(!out.status.success(), "{script:?}");
        assert_eq!(stderr.lines().count(), 1, "{script:?}: {stderr}");
        assert!(
            stderr.starts_with(&format!("flexcam: {expected}")),
            "{script:?}: {stderr}"
        );
        assert!(!dir.path().join("f.png").exists(), "{script:?}");
    }
}

#[test]
fn invalid_edit_keeps_the_last_valid_projection_message() {
    let dir = setup("set fov 500\n");
    let out = run(&dir, &VIEW);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("perspective fov must be in (0, 180) degrees, got 500"),
        "{stderr}"
    );
}

/// Runs a scripted window session: under the display of `DISPLAY`, or a virtual one from
/// `xvfb-run` when there is none. Skipped, saying why, only when no display can be opened.
#[test]
fn window_screenshot_under_a_display() {
    // The drag runs through the window's script path too (the volume view drawn).
    let dir = setup("set fov 60\ndrag position 3 2\nidle\nwindow w.png\nframe f.png\n");
    let flexcam = assert_cmd::cargo::cargo_bin("flexcam");
    let args = [&VIEW[..], &["--shading", "flat", "--refine-spp", "1"]].concat();
    let has_display = std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty());
    let mut command = if has_display {
        Process::new(&flexcam)
    } else if which("xvfb-run") {
        let mut c = Process::new("xvfb-run");
        c.args(["-a", "-s", "-screen 0 1280x1024x24"]).arg(&flexcam);
        c
    } else {
        println!("skipped: no DISPLAY and no xvfb-run to open a virtual display");
        return;
    };
    let out = command
        .current_dir(dir.path())
        .args(args)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("cannot open the viewer's window") {
        println!("skipped: the display cannot be opened: {stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let shot = image::open(dir.path().join("w.png")).unwrap().to_rgb8();
    let frame = image::open(dir.path().join("f.png")).unwrap().to_rgb8();
    assert!(shot.width() > frame.width() && shot.height() > frame.height());
    // The frame is shown in the window: its centre pixel's colour (a flat face) is on
    // screen, within the texture filter's rounding.
    let centre = frame.get_pixel(frame.width() / 2, frame.height() / 2);
    let near = |p: &image::Rgb<u8>| p.0.iter().zip(centre.0).all(|(&a, b)| a.abs_diff(b) <= 2);
    assert!(shot.pixels().any(near), "{centre:?}");
}

fn which(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| Path::new(&dir).join(program).is_file())
    })
}

/// A folder holding `scene.toml` (scene file `text` with its image size `from` replaced by
/// `to`) and `view.txt` (`script`).
fn setup_scene(text: &str, from: &str, to: &str, script: &str) -> TempDir {
    let dir = TempDir::new().unwrap();
    let scene = text.replace(from, to);
    assert_ne!(scene, text);
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    dir
}

/// The numbers after `NAME KIND` on handle `name`'s line of `--list-handles`.
fn listed(dir: &TempDir, name: &str) -> Vec<f64> {
    let out = run_ok(dir, &["view", "scene.toml", "--list-handles"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name))
        .unwrap_or_else(|| panic!("no {name} in\n{text}"));
    line.split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// Runs the script, which saves `s.toml`: the only line of it that differs from
/// `scene.toml` (the rest kept as it was).
fn run_and_changed_line(dir: &TempDir) -> String {
    run_ok(dir, &VIEW);
    let original = String::from_utf8(read(dir, "scene.toml")).unwrap();
    let saved = String::from_utf8(read(dir, "s.toml")).unwrap();
    assert_eq!(original.lines().count(), saved.lines().count());
    let changed: Vec<_> = original
        .lines()
        .zip(saved.lines())
        .filter(|(a, b)| a != b)
        .map(|(_, b)| b.to_string())
        .collect();
    assert_eq!(changed.len(), 1, "{changed:?}");
    changed[0].clone()
}

/// The numbers of `text` (a line of a scene file), in order.
fn numbers_in(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter_map(|w| w.parse().ok())
        .collect()
}

#[test]
fn dragging_a_control_point_moves_its_key_in_the_view_plane() {
    let text = include_str!("../../../scenes/flexible-patches.toml");
    let script = "drag surface.1.1.2 12 -7\nidle\nframe f.png\nsave s.toml\n";
    let dir = setup_scene(
        text,
        "width = 320\nheight = 240",
        "width = 64\nheight = 48",
        script,
    );
    // Listed: the point, the world step of a pixel right, of a pixel down.
    let listed = listed(&dir, "surface.1.1.2");
    assert_eq!(&listed[..3], &[0.5, 1.2, 4.5]);
    let line = run_and_changed_line(&dir);
    // Row 1 of the Bezier patch: its third point moved, the others as written.
    let numbers = numbers_in(&line);
    assert_eq!(numbers.len(), 12, "{line}");
    assert_eq!(&numbers[..6], &[-1.5, 1.2, 3.5, -0.5, 1.2, 4.5]);
    assert_eq!(&numbers[9..], &[1.5, 1.2, 3.5]);
    for k in 0..3 {
        let expected = listed[k] + (listed[3 + k] * 12.0 + listed[6 + k] * -7.0);
        assert!(
            (numbers[6 + k] - expected).abs() < 1e-12,
            "{line}: {expected}"
        );
    }
    // The step is a real move: 12 and 7 pixels of a view of the whole scene.
    let moved =
        ((numbers[6] - 0.5).powi(2) + (numbers[7] - 1.2).powi(2) + (numbers[8] - 4.5).powi(2))
            .sqrt();
    assert!(moved > 0.05 && moved < 2.0, "{moved}");
    frame_renders_the_saved_scene(&dir, &[]);
    run_ok(&dir, &["render", "scene.toml", "-o", "original.png"]);
    assert_ne!(read(&dir, "f.png"), read(&dir, "original.png"));
}

/// The script's `f.png` is what `flexcam render s.toml` writes (with `args`), byte for byte.
fn frame_renders_the_saved_scene(dir: &TempDir, args: &[&str]) {
    run_ok(
        dir,
        &[&["render", "s.toml"][..], args, &["-o", "r.png"]].concat(),
    );
    assert_eq!(read(dir, "f.png"), read(dir, "r.png"));
}

#[test]
fn dragging_the_perspective_rectangle_over_the_image() {
    let text = include_str!("../../../scenes/flexible-panorama-edit.toml");
    let script = "drag rect.corner.2 8 4\nmethod raster\nframe f.png\nsave s.toml\n";
    let dir = setup_scene(
        text,
        "width = 320\nheight = 160",
        "width = 64\nheight = 32",
        script,
    );
    // Corner 2 is the top right one, (u1, v1) = (0.625, 0.8): x = 40, y = 32 * 0.2.
    let at = listed(&dir, "rect.corner.2");
    assert_eq!(at.len(), 2);
    assert!(
        (at[0] - 40.0).abs() < 1e-12 && (at[1] - 6.4).abs() < 1e-12,
        "{at:?}"
    );
    let line = run_and_changed_line(&dir);
    // 8 pixels right: u1 + 8 / 64; 4 pixels down: v1 - 4 / 32 (v up).
    assert_eq!(
        numbers_in(&line),
        [0.375, 0.15, 0.625 + 0.125, 0.8 - 0.125],
        "{line}"
    );
    frame_renders_the_saved_scene(&dir, &["--method", "raster"]);
}

#[test]
fn dragging_a_projector_grid_node_adds_its_entry() {
    let text = include_str!("../../../scenes/flexible-projector-tangents.toml");
    let script = "drag projector.4.0.end 5 5\nframe f.png\nsave s.toml\n";
    let dir = setup_scene(
        text,
        "width = 320\nheight = 240",
        "width = 48\nheight = 36",
        script,
    );
    let listed = listed(&dir, "projector.4.0.end");
    run_ok(&dir, &VIEW);
    let saved = String::from_utf8(read(&dir, "s.toml")).unwrap();
    let entry = saved
        .lines()
        .find(|l| l.contains("node = [4, 0]"))
        .unwrap_or_else(|| panic!("{saved}"));
    let numbers = numbers_in(entry);
    assert_eq!(&numbers[..2], &[4.0, 0.0], "{entry}");
    for k in 0..3 {
        let expected = listed[k] + (listed[3 + k] * 5.0 + listed[6 + k] * 5.0);
        assert!(
            (numbers[2 + k] - expected).abs() < 1e-12,
            "{entry}: {expected}"
        );
    }
    frame_renders_the_saved_scene(&dir, &[]);
}

#[test]
fn a_handle_moved_the_wrong_way_or_missing_is_one_error_line() {
    let text = include_str!("../../../scenes/flexible-panorama-edit.toml");
    for (script, expected) in [
        ("drag near.3.2 1 1\n", "view.txt:1:1: no handle `near.3.2` (this projection's handles: position, look_at, rect.corner.0"),
        // A corner dragged past the opposite one: the edit is refused, naming the scene.
        ("drag rect.corner.0 60 0\nframe f.png\n", "view.txt:1:1: scene.toml:"),
    ] {
        let dir = setup_scene(text, "width = 320\nheight = 160", "width = 64\nheight = 32", script);
        let out = run(&dir, &VIEW);
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(!out.status.success(), "{script:?}");
        assert_eq!(stderr.lines().count(), 1, "{script:?}: {stderr}");
        assert!(stderr.starts_with(&format!("flexcam: {expected}")), "{script:?}: {stderr}");
        assert!(!dir.path().join("f.png").exists());
    }
}
