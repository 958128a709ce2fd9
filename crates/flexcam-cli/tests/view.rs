//! `flexcam view --script`: frames byte for byte those of `flexcam render` of the saved
//! scene, the scene saved with its comments and layout, bad lines and invalid edits as one
//! error line naming the script, and a scripted window screenshot under a display.

mod common;

use common::{numbers_in, run, run_ok, run_with_display, setup_scene};
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
    let args = [&VIEW[..], &["--shading", "flat", "--refine-spp", "1"]].concat();
    let Some(out) = run_with_display(&dir, &args) else {
        return;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
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
        ("drag near.3.2 1 1\n", "view.txt:1:1: no handle `near.3.2` (this projection's handles: position, look_at, clip.near, clip.far, rect.corner.0"),
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

/// Drags `handle` by (`dx`, `dy`) pixels in a copy of scene file `text` whose image size
/// `from` is replaced by `to` (the ray caster's frame): checks that the script's frame is
/// `flexcam render` of the saved scene and differs from the unedited render, and returns
/// the handle's numbers of `--list-handles` and the one line the drag changed.
fn drag_one(
    text: &str,
    (from, to): (&str, &str),
    handle: &str,
    dx: f64,
    dy: f64,
) -> (Vec<f64>, String) {
    let script = format!("drag {handle} {dx} {dy}\nframe f.png\nsave s.toml\n");
    let dir = setup_scene(text, from, to, &script);
    let listed = listed(&dir, handle);
    let line = run_and_changed_line(&dir);
    frame_renders_the_saved_scene(&dir, &[]);
    run_ok(&dir, &["render", "scene.toml", "-o", "original.png"]);
    assert_ne!(read(&dir, "f.png"), read(&dir, "original.png"), "{handle}");
    (listed, line)
}

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Where a script's drag by (`dx`, `dy`) puts a world handle listed as `listed` (point,
/// step of a pixel right, step of a pixel down).
fn dragged(listed: &[f64], dx: f64, dy: f64) -> V3 {
    std::array::from_fn(|k| listed[k] + listed[3 + k] * dx + listed[6 + k] * dy)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

/// The eye, view direction and image right of the preset scenes (eye (0, 5.5, 7) looking
/// at (0, 0.4, 0), up +y).
fn preset_frame() -> (V3, V3, V3) {
    let eye = [0.0, 5.5, 7.0];
    let forward = unit(sub([0.0, 0.4, 0.0], eye));
    (eye, forward, unit(cross(forward, [0.0, 1.0, 0.0])))
}

const SMALL_PRESET: (&str, &str) = ("width = 240\nheight = 180", "width = 48\nheight = 36");

#[test]
fn dragging_image_keys_of_presets() {
    let magnifier = include_str!("../../../scenes/flexible-magnifier.toml");
    let occlusion = include_str!("../../../scenes/flexible-occlusion.toml");
    // 48 x 36: x moves u by dx / 48, y moves v by -dy / 36; the magnifier's radius is a
    // fraction of the shorter side, 36.
    for (text, handle, dx, dy, key, expected) in [
        (magnifier, "center", 6.0, -9.0, "center =", vec![0.625, 0.8]),
        (
            magnifier,
            "radius",
            3.0,
            0.0,
            "radius =",
            vec![0.3 + 3.0 / 36.0],
        ),
        (occlusion, "pole", -12.0, 4.5, "pole =", vec![0.25, 0.425]),
    ] {
        let (_, line) = drag_one(text, SMALL_PRESET, handle, dx, dy);
        assert!(line.starts_with(key), "{handle}: {line}");
        let numbers = numbers_in(line.split('#').next().unwrap());
        assert_eq!(numbers.len(), expected.len(), "{line}");
        assert!(
            numbers.iter().zip(&expected).all(|(a, b)| close(*a, *b)),
            "{line}"
        );
    }
}

#[test]
fn dragging_distances_and_angles_of_presets() {
    let occlusion = include_str!("../../../scenes/flexible-occlusion.toml");
    let depth = include_str!("../../../scenes/flexible-depth-transition.toml");
    let ortho_persp = include_str!("../../../scenes/flexible-ortho-near-persp-far.toml");
    let slits = include_str!("../../../scenes/flexible-crossed-slits.toml");
    let orthographic = ortho_persp
        .replace(
            "preset = \"ortho_near_persp_far\"",
            "preset = \"orthographic\"",
        )
        .replace("fov = 50.0", "width = 8.0")
        .replace("transition = 8.0 ", "# transition = 8.0 ")
        .replace("style = \"piecewise\"", "");
    let (eye, forward, right) = preset_frame();
    let up = cross(right, forward);
    let slits_size = ("width = 800\nheight = 600", "width = 48\nheight = 36");
    // (scene, size, handle, drag, the changed line's start, its number at `index`, from the
    // dragged point p, the eye, the view direction, right and up).
    type Value = fn(V3, V3, V3, V3, V3) -> f64;
    type Case<'a> = (
        &'a str,
        (&'a str, &'a str),
        &'a str,
        f64,
        f64,
        &'a str,
        usize,
        Value,
    );
    let along: Value = |p, eye, forward, _, _| dot(sub(p, eye), forward);
    let cases: [Case; 6] = [
        (
            occlusion,
            SMALL_PRESET,
            "transition",
            0.0,
            -5.0,
            "transition =",
            0,
            along,
        ),
        (
            occlusion,
            SMALL_PRESET,
            "clip.far",
            2.0,
            8.0,
            "clip =",
            1,
            along,
        ),
        (
            depth,
            SMALL_PRESET,
            "transitions.0",
            0.0,
            6.0,
            "transitions =",
            0,
            along,
        ),
        (
            ortho_persp,
            SMALL_PRESET,
            "fov",
            10.0,
            0.0,
            "fov =",
            0,
            |p, eye, forward, right, _| {
                let v = sub(p, eye);
                2.0 * dot(v, right).atan2(dot(v, forward)).to_degrees()
            },
        ),
        (
            slits,
            slits_size,
            "v_fov",
            0.0,
            -6.0,
            "v_fov =",
            0,
            |p, eye, forward, _, up| {
                let v = sub(p, eye);
                2.0 * dot(v, up).atan2(dot(v, forward)).to_degrees()
            },
        ),
        (
            orthographic.as_str(),
            SMALL_PRESET,
            "width",
            7.0,
            0.0,
            "width =",
            0,
            |p, eye, _, right, _| 2.0 * dot(sub(p, eye), right),
        ),
    ];
    for (text, size, handle, dx, dy, key, index, value) in cases {
        let (listed, line) = drag_one(text, size, handle, dx, dy);
        assert!(line.starts_with(key), "{handle}: {line}");
        let numbers = numbers_in(line.split('#').next().unwrap());
        let p = dragged(&listed, dx, dy);
        let expected = value(p, eye, forward, right, up);
        assert!(
            close(numbers[index], expected),
            "{handle}: {line}, expected {expected}"
        );
    }
}

#[test]
fn dragging_a_point_of_the_mcop_path() {
    let text = include_str!("../../../scenes/flexible-mcop.toml");
    let (listed, line) = drag_one(text, SMALL_PRESET, "path.1", 5.0, 5.0);
    assert!(line.starts_with("path ="), "{line}");
    let numbers = numbers_in(&line);
    assert_eq!(numbers.len(), 9, "{line}");
    assert_eq!(&numbers[..3], &[-7.0, 3.0, 0.0]);
    assert_eq!(&numbers[6..], &[0.0, 3.0, 7.0]);
    let p = dragged(&listed, 5.0, 5.0);
    assert!((0..3).all(|k| close(numbers[3 + k], p[k])), "{line}: {p:?}");
}

/// The point at arc-length fraction `s` of the polyline through `points` (closed: back to
/// the first), as the panorama's curves are parameterised.
fn polyline_at(points: &[[f64; 2]], closed: bool, s: f64) -> [f64; 2] {
    let mut pieces: Vec<_> = points.windows(2).map(|w| (w[0], w[1])).collect();
    if closed {
        pieces.push((points[points.len() - 1], points[0]));
    }
    let length = |(a, b): ([f64; 2], [f64; 2])| (b[0] - a[0]).hypot(b[1] - a[1]);
    let total: f64 = pieces.iter().map(|&p| length(p)).sum();
    let mut walked = 0.0;
    for &(a, b) in &pieces {
        let l = length((a, b));
        if walked + l >= s * total {
            let t = (s * total - walked) / l;
            return [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
        }
        walked += l;
    }
    unreachable!("s = {s} past the end")
}

#[test]
fn dragging_outline_and_profile_points_over_the_image() {
    let text = include_str!("../../../scenes/flexible-panorama-custom.toml").replace(
        "{ at = 0.5, shape = \"segment\", elevation = [-50.0, 50.0] }",
        "{ at = 0.5, points = [[1.0, -1.2], [1.0, 1.2]] }",
    );
    let size = ("width = 320\nheight = 160", "width = 64\nheight = 32");
    let outline = [
        [0.0, -1.0],
        [-0.7, -0.7],
        [-1.0, 0.0],
        [-0.6, 0.8],
        [0.6, 0.8],
        [1.0, 0.0],
        [0.7, -0.7],
    ];
    // Outline vertex 3 sits on the middle row at the column of its arc-length fraction;
    // 4 pixels right, it turns to the direction of the outline's point there (length 1).
    let (listed, line) = drag_one(&text, size, "outline.3", 4.0, 0.0);
    assert_eq!(listed.len(), 2);
    assert!(close(listed[1], 16.0), "{listed:?}");
    let s3 = listed[0] / 64.0;
    let at = polyline_at(&outline, true, s3);
    assert!(close(at[0], -0.6) && close(at[1], 0.8), "{at:?}");
    let toward = polyline_at(&outline, true, (listed[0] + 4.0) / 64.0);
    let length = toward[0].hypot(toward[1]);
    let numbers = numbers_in(&line);
    assert!(line.starts_with("outline ="), "{line}");
    assert_eq!(numbers.len(), 14, "{line}");
    assert!(
        close(numbers[6], toward[0] / length) && close(numbers[7], toward[1] / length),
        "{line}: {toward:?}"
    );
    // Profile vertex 1 of the front profile: the top of column 1/2; 6 pixels down it turns
    // to the profile's point at v = 1 - 6 / 32, keeping its length.
    let (listed, line) = drag_one(&text, size, "profile.1.1", 0.0, 6.0);
    assert!(
        close(listed[0], 32.0) && close(listed[1], 0.0),
        "{listed:?}"
    );
    let numbers = numbers_in(line.split('#').next().unwrap());
    let toward = polyline_at(&[[1.0, -1.2], [1.0, 1.2]], false, 1.0 - 6.0 / 32.0);
    let scale = 1.2f64.hypot(1.0) / toward[0].hypot(toward[1]);
    assert_eq!(numbers.len(), 5, "{line}");
    assert!(
        close(numbers[3], toward[0] * scale) && close(numbers[4], toward[1] * scale),
        "{line}: {toward:?}"
    );
}

/// `text` with each `(from, to)` replaced (each must be there).
fn edited(text: &str, replacements: &[(&str, &str)]) -> String {
    replacements
        .iter()
        .fold(text.to_string(), |text, (from, to)| {
            assert!(text.contains(from), "{from}");
            text.replace(from, to)
        })
}

/// The numbers of a changed scene line before its comment.
fn line_numbers(line: &str) -> Vec<f64> {
    numbers_in(line.split('#').next().unwrap())
}

fn scale(a: V3, k: f64) -> V3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[test]
fn dragging_the_shift_shear_twist_convergence_and_slit_of_presets() {
    let ortho_persp = include_str!("../../../scenes/flexible-ortho-near-persp-far.toml");
    let off_axis = edited(
        ortho_persp,
        &[
            ("preset = \"ortho_near_persp_far\"", "preset = \"off_axis\""),
            ("transition = 8.0 ", "shift = [0.2, -0.1] "),
            ("style = \"piecewise\"", ""),
        ],
    );
    let twist = include_str!("../../../scenes/flexible-twist.toml");
    let slits = include_str!("../../../scenes/flexible-crossed-slits.toml");
    let (eye, forward, right) = preset_frame();
    let up = cross(right, forward);
    // off_axis: the window's centre seen from the eye, in half-widths (tan 25 degrees at
    // unit distance) and half-heights (times 36 / 48).
    let (listed, line) = drag_one(&off_axis, SMALL_PRESET, "shift", 6.0, 4.0);
    assert!(line.starts_with("shift ="), "{line}");
    let v = sub(dragged(&listed, 6.0, 4.0), eye);
    let t = 25f64.to_radians().tan();
    let expected = [
        dot(v, right) / dot(v, forward) / t,
        dot(v, up) / dot(v, forward) / (t * 0.75),
    ];
    let numbers = line_numbers(&line);
    assert!(
        close(numbers[0], expected[0]) && close(numbers[1], expected[1]),
        "{line}: {expected:?}"
    );
    // The listed point is the old window's centre at the look-at distance.
    let distance = dot(sub([0.0, 0.4, 0.0], eye), forward);
    let centre = add(
        add(eye, scale(forward, distance)),
        add(
            scale(right, distance * 0.2 * t),
            scale(up, -distance * 0.1 * t * 0.75),
        ),
    );
    assert!(
        (0..3).all(|k| (listed[k] - centre[k]).abs() < 1e-12),
        "{listed:?}"
    );
    // oblique: the image centre's projector, minus the direction from the eye (right, up
    // over forward).
    let oblique = edited(
        &off_axis,
        &[
            ("preset = \"off_axis\"", "preset = \"oblique\""),
            ("fov = 50.0", "width = 8.0"),
            ("shift = [0.2, -0.1]", "shear = [0.2, -0.1]"),
        ],
    );
    let (listed, line) = drag_one(&oblique, SMALL_PRESET, "shear", -5.0, 3.0);
    assert!(line.starts_with("shear ="), "{line}");
    let v = sub(dragged(&listed, -5.0, 3.0), eye);
    let expected = [
        -dot(v, right) / dot(v, forward),
        -dot(v, up) / dot(v, forward),
    ];
    let numbers = line_numbers(&line);
    assert!(
        close(numbers[0], expected[0]) && close(numbers[1], expected[1]),
        "{line}: {expected:?}"
    );
    // twist: the far rectangle's right edge turned about the axis (far clip 20 m); the
    // dragged point's angle about it, counter-clockwise from the right seen from the eye.
    let size = ("width = 320\nheight = 240", "width = 48\nheight = 36");
    let (listed, line) = drag_one(twist, size, "twist", -5.0, -8.0);
    assert!(line.starts_with("twist ="), "{line}");
    let v = sub(dragged(&listed, -5.0, -8.0), add(eye, scale(forward, 20.0)));
    let expected = dot(v, up).atan2(dot(v, right)).to_degrees();
    assert!(expected > 60.0, "up and left turns it further: {expected}");
    assert!(
        close(line_numbers(&line)[0], expected),
        "{line}: {expected}"
    );
    // inverse_perspective: the point the projectors meet at (the far clip defaults to
    // its depth).
    let inverse = edited(
        ortho_persp,
        &[
            (
                "preset = \"ortho_near_persp_far\"",
                "preset = \"inverse_perspective\"",
            ),
            ("transition = 8.0 ", "converge = [0.0, -1.5, -3.0] "),
            ("clip = [0.0, 30.0]", ""),
            ("style = \"piecewise\"", ""),
        ],
    );
    let (listed, line) = drag_one(&inverse, SMALL_PRESET, "converge", 7.0, -4.0);
    assert!(line.starts_with("converge ="), "{line}");
    assert_eq!(&listed[..3], &[0.0, -1.5, -3.0]);
    let p = dragged(&listed, 7.0, -4.0);
    let numbers = line_numbers(&line);
    assert!((0..3).all(|k| close(numbers[k], p[k])), "{line}: {p:?}");
    // crossed_slits: the horizontal slit's distance along the axis.
    let size = ("width = 800\nheight = 600", "width = 48\nheight = 36");
    let (listed, line) = drag_one(slits, size, "slit_distance", 0.0, 5.0);
    assert!(line.starts_with("slit_distance ="), "{line}");
    let expected = dot(sub(dragged(&listed, 0.0, 5.0), eye), forward);
    assert!(
        close(line_numbers(&line)[0], expected),
        "{line}: {expected}"
    );
}

#[test]
fn dragging_view_angles_generators_and_directions_of_presets() {
    let depth = include_str!("../../../scenes/flexible-depth-transition.toml");
    let ortho_persp = include_str!("../../../scenes/flexible-ortho-near-persp-far.toml");
    let mcop = include_str!("../../../scenes/flexible-mcop.toml");
    let (eye, forward, right) = preset_frame();
    let up = cross(right, forward);
    // depth_transition: view 1 runs from the transition at 8 m (half-width 8 tan 30, where
    // view 0 ends) to the far clip at 30 m; its edge passes the dragged point there.
    let (listed, line) = drag_one(depth, SMALL_PRESET, "fovs.1", 9.0, 0.0);
    assert!(line.starts_with("fovs ="), "{line}");
    let p = dragged(&listed, 9.0, 0.0);
    let start = 8.0 * 30f64.to_radians().tan();
    let expected = 2.0
        * ((dot(sub(p, eye), right) - start) / (30.0 - 8.0))
            .atan()
            .to_degrees();
    let numbers = line_numbers(&line);
    assert_eq!(numbers[0], 60.0, "{line}");
    assert!(close(numbers[1], expected), "{line}: {expected}");
    // glc: generator 1's end, at local depth 1, moved across the axis.
    let glc = edited(
        ortho_persp,
        &[
            ("preset = \"ortho_near_persp_far\"", "preset = \"glc\""),
            ("fov = 50.0", "width = 2.0"),
            (
                "transition = 8.0 ",
                "generators = [[-0.5, -0.5, -1.0, -1.0], [0.5, -0.5, 1.0, -1.0], [-0.5, 0.5, -1.0, 1.0]] ",
            ),
            ("style = \"piecewise\"", ""),
        ],
    );
    let (listed, line) = drag_one(&glc, SMALL_PRESET, "generators.1.end", 5.0, -3.0);
    assert!(line.starts_with("generators ="), "{line}");
    let local = sub(dragged(&listed, 5.0, -3.0), add(eye, forward));
    let numbers = line_numbers(&line);
    assert_eq!(numbers.len(), 12, "{line}");
    assert_eq!(&numbers[..6], &[-0.5, -0.5, -1.0, -1.0, 0.5, -0.5]);
    assert_eq!(&numbers[8..], &[-0.5, 0.5, -1.0, 1.0]);
    assert!(
        close(numbers[6], dot(local, right)) && close(numbers[7], dot(local, up)),
        "{line}: {local:?}"
    );
    // mcop: direction 1 is twice the dragged point less path point 1.
    let (listed, line) = drag_one(mcop, SMALL_PRESET, "directions.1", 4.0, -3.0);
    assert!(line.starts_with("directions ="), "{line}");
    let direction = scale(sub(dragged(&listed, 4.0, -3.0), [-4.95, 3.0, 4.95]), 2.0);
    let numbers = line_numbers(&line);
    assert_eq!(numbers.len(), 9, "{line}");
    assert_eq!(&numbers[..3], &[7.0, -2.0, 0.0]);
    assert_eq!(&numbers[6..], &[0.0, -2.0, -7.0]);
    assert!(
        (0..3).all(|k| close(numbers[3 + k], direction[k])),
        "{line}: {direction:?}"
    );
}

#[test]
fn dragging_the_strength_and_magnification_over_the_image() {
    let occlusion = include_str!("../../../scenes/flexible-occlusion.toml");
    let magnifier = include_str!("../../../scenes/flexible-magnifier.toml");
    // 48 x 36: the strength's point sits strength image widths right of the pole.
    let (listed, line) = drag_one(occlusion, SMALL_PRESET, "strength", 6.0, 2.0);
    assert!(close(listed[0], 0.5 * 48.0 + 0.12 * 48.0), "{listed:?}");
    assert!(line.starts_with("strength ="), "{line}");
    assert!(close(line_numbers(&line)[0], 0.12 + 6.0 / 48.0), "{line}");
    // The magnification's point: the radius (0.3 of 36 pixels) over the magnification (3)
    // above the centre; 3 pixels further up, the radius over that height.
    let (listed, line) = drag_one(magnifier, SMALL_PRESET, "magnification", 1.0, -3.0);
    let centre_y = (1.0 - 0.55) * 36.0;
    assert!(close(listed[1], centre_y - 10.8 / 3.0), "{listed:?}");
    assert!(line.starts_with("magnification ="), "{line}");
    let expected = 10.8 / (centre_y - (listed[1] - 3.0));
    assert!(
        close(line_numbers(&line)[0], expected),
        "{line}: {expected}"
    );
}

/// The numbers of a changed scene line, before its comment.
fn line_values(line: &str) -> Vec<f64> {
    numbers_in(line.split('#').next().unwrap())
}

#[test]
fn dragging_the_clamped_keys_of_presets() {
    let isometric = include_str!("../../../scenes/flexible-isometric.toml");
    let iso_size = ("width = 320\nheight = 240", "width = 48\nheight = 36");
    let look_at = [0.0, 0.5, 0.0];
    // azimuth: the dragged point's angle about +y through look_at, from +z towards +x.
    let (listed, line) = drag_one(isometric, iso_size, "azimuth", 6.0, 0.0);
    let v = sub(dragged(&listed, 6.0, 0.0), look_at);
    assert!(line.starts_with("azimuth ="), "{line}");
    assert!(
        close(line_values(&line)[0], v[0].atan2(v[2]).to_degrees()),
        "{line}"
    );
    // elevation: its angle above the level plane through look_at.
    let (listed, line) = drag_one(isometric, iso_size, "elevation", 0.0, -5.0);
    let v = sub(dragged(&listed, 0.0, -5.0), look_at);
    let expected = v[1].atan2(v[0].hypot(v[2])).to_degrees();
    assert!(line.starts_with("elevation ="), "{line}");
    assert!(close(line_values(&line)[0], expected), "{line}: {expected}");
    // corner_radius: the eye at (0, 1.5, 0) looks along -z, the far clip at 60; the
    // corner's middle is 60 (sqrt 2 - r (sqrt 2 - 1)) along the front-right diagonal.
    let cubic = include_str!("../../../scenes/flexible-panorama-cubic.toml");
    let cubic_size = ("width = 320\nheight = 120", "width = 48\nheight = 18");
    let (listed, line) = drag_one(cubic, cubic_size, "corner_radius", -4.0, 0.0);
    let p = sub(dragged(&listed, -4.0, 0.0), [0.0, 1.5, 0.0]);
    let s = (p[0] - p[2]) / 2f64.sqrt() / 60.0;
    let expected = (2f64.sqrt() - s) / (2f64.sqrt() - 1.0);
    assert!(line.starts_with("corner_radius ="), "{line}");
    assert!(close(line_values(&line)[0], expected), "{line}: {expected}");
    assert!(expected > 0.3 && expected < 1.0, "{expected}");
    // Dragged past the circle (r above 1): kept at 1.
    let (_, line) = drag_one(cubic, cubic_size, "corner_radius", -400.0, 0.0);
    assert_eq!(line_values(&line)[0], 1.0, "{line}");
    // The mcop's v_fov: the middle column (path point 1, its two segments equally long)
    // looks along directions[1]; twice the angle above it, up being +y made perpendicular.
    let mcop = include_str!("../../../scenes/flexible-mcop.toml");
    let (listed, line) = drag_one(mcop, SMALL_PRESET, "v_fov", 0.0, 4.0);
    let v = sub(dragged(&listed, 0.0, 4.0), [-4.95, 3.0, 4.95]);
    let forward = unit([4.95, -2.0, -4.95]);
    let up = unit(sub([0.0, 1.0, 0.0], scale(forward, forward[1])));
    let expected = 2.0 * dot(v, up).atan2(dot(v, forward)).to_degrees();
    assert!(line.starts_with("v_fov ="), "{line}");
    assert!(close(line_values(&line)[0], expected), "{line}: {expected}");
    // The long scene's first deep area [0.3, 0.08, 50.0] at 48 pixels wide: its centre and
    // width over the image, its fov from its edge on the slit (0.04 * 100 right of u =
    // 0.3, that is -16) to the dragged point at the far clip (25 from the slit).
    let long = include_str!("../../../scenes/flexible-long-scene.toml");
    let long_size = ("width = 800\nheight = 200", "width = 48\nheight = 12");
    for (handle, dx, dy, index) in [
        ("deep.0.center", 3.0, 1.0, 0),
        ("deep.0.width", 2.0, 0.0, 1),
        ("deep.0.fov", 4.0, 0.0, 2),
    ] {
        let (listed, line) = drag_one(long, long_size, handle, dx, dy);
        assert!(line.starts_with("deep ="), "{line}");
        let expected = match index {
            0 => 0.3 + dx / 48.0,
            1 => 0.08 + 2.0 * dx / 48.0,
            _ => {
                2.0 * ((dragged(&listed, dx, dy)[0] + 16.0) / 25.0)
                    .atan()
                    .to_degrees()
            }
        };
        let numbers = line_values(&line);
        assert!(close(numbers[index], expected), "{line}: {expected}");
        assert_eq!(numbers[3..], [0.7, 0.08, 50.0], "{line}");
    }
}

/// A drag of the world handle listed as `listed` (see [`dragged`]) that takes it right of
/// the view axis and behind the eye (its angle from the axis past 90 degrees, twice that
/// past 180): the first such direction of the drag plane, a million pixels long.
fn behind_and_right(listed: &[f64], eye: V3, forward: V3, right: V3) -> (f64, f64) {
    (0..360)
        .map(|k| {
            let (sin, cos) = f64::from(k).to_radians().sin_cos();
            (1e6 * cos, 1e6 * sin)
        })
        .find(|&(dx, dy)| {
            let v = sub(dragged(listed, dx, dy), eye);
            dot(v, right) > 0.0 && dot(v, forward) < 0.0
        })
        .expect("the drag plane reaches behind the eye")
}

#[test]
fn angle_drags_past_their_range_stop_at_its_end() {
    let ortho_persp = include_str!("../../../scenes/flexible-ortho-near-persp-far.toml");
    let depth = include_str!("../../../scenes/flexible-depth-transition.toml");
    let slits = include_str!("../../../scenes/flexible-crossed-slits.toml");
    let slits_size = ("width = 800\nheight = 600", "width = 48\nheight = 36");
    // Past 180 degrees, which the loader refuses: the fov handle behind the eye.
    let (eye, forward, right) = preset_frame();
    let dir = setup_scene(ortho_persp, SMALL_PRESET.0, SMALL_PRESET.1, "");
    let (dx, dy) = behind_and_right(&listed(&dir, "fov"), eye, forward, right);
    // (scene, size, handle, drag, the changed line's start, the number at `index`): across
    // the view axis (a negative angle) the smallest angle, 0.1; past 180 (or a `fovs` edge
    // far out, nearly 180) the largest below the loader's 180, 179.9. Each saved scene
    // renders as the script's frame (`drag_one`).
    let cases = [
        (
            ortho_persp,
            SMALL_PRESET,
            "fov",
            -300.0,
            0.0,
            "fov =",
            0,
            0.1,
        ),
        (ortho_persp, SMALL_PRESET, "fov", dx, dy, "fov =", 0, 179.9),
        (slits, slits_size, "v_fov", 0.0, 300.0, "v_fov =", 0, 0.1),
        (depth, SMALL_PRESET, "fovs.1", 1e9, 0.0, "fovs =", 1, 179.9),
        (depth, SMALL_PRESET, "fovs.0", -300.0, 0.0, "fovs =", 0, 0.1),
    ];
    for (text, size, handle, dx, dy, key, index, expected) in cases {
        let (_, line) = drag_one(text, size, handle, dx, dy);
        assert!(line.starts_with(key), "{handle}: {line}");
        assert_eq!(line_values(&line)[index], expected, "{handle}: {line}");
    }
}

#[test]
fn axonometric_and_glc_views_have_a_width_handle() {
    let isometric = include_str!("../../../scenes/flexible-isometric.toml");
    let iso_size = ("width = 320\nheight = 240", "width = 48\nheight = 36");
    // A general linear camera as wide as a 53-degree perspective, at the isometric view's
    // eye (30 m in front of the scene).
    let glc = isometric
        .replace("preset = \"axonometric\"", "preset = \"glc\"")
        .replace("width = 12.0", "width = 1.0")
        .replace(
            "azimuth = 45.0\nelevation = 35.264\n",
            "generators = [[-0.5, -0.5, -1.0, -1.0], [0.5, -0.5, 1.0, -1.0], [-0.5, 0.5, -1.0, 1.0]]\n",
        );
    // The handle lies half the width right of the view's axis point (the axonometric
    // look-at point, the glc's eye): its offset from there is the axis's right direction.
    for (text, axis_point, width) in [
        (isometric, [0.0, 0.5, 0.0], 12.0),
        (&glc, [0.0, 0.0, 30.0], 1.0),
    ] {
        let (listed, line) = drag_one(text, iso_size, "width", 5.0, 2.0);
        let offset = sub([listed[0], listed[1], listed[2]], axis_point);
        assert!(close(dot(offset, offset).sqrt(), width / 2.0), "{listed:?}");
        let right = unit(offset);
        let expected = 2.0 * dot(sub(dragged(&listed, 5.0, 2.0), axis_point), right);
        assert!(line.starts_with("width ="), "{line}");
        assert!(close(line_values(&line)[0], expected), "{line}: {expected}");
    }
}
