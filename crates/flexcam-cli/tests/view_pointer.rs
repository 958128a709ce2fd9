//! `flexcam view --script` with `pointer` and `scroll` lines: raw input events that go
//! through egui's hit testing and the window's own input handlers (under a display, as the
//! window test of view.rs), checked against the lines that make the same moves without a
//! window (`drag`, `orbit`, `pan`, `dolly`) and against `flexcam pick`.
//!
//! The pointer's positions are whole window pixels, exact in egui's f32 points, so a move's
//! delta reaches the handlers exactly; the tolerances below come from the f32 arithmetic
//! the window does with it.

mod common;

use common::{numbers_in, run_ok, run_with_display, setup_scene};
use tempfile::TempDir;

const VIEW: [&str; 4] = ["view", "scene.toml", "--script", "view.txt"];

/// What a `layout` line writes: the image's and the volume view's rectangles (x0, y0, x1,
/// y1) and each handle's position, in window pixels.
#[derive(Debug, PartialEq)]
struct Layout {
    image: [f64; 4],
    volume: [f64; 4],
    handles: Vec<(String, [f64; 2])>,
}

fn parse_layout(text: &str) -> Layout {
    let mut layout = Layout {
        image: [f64::NAN; 4],
        volume: [f64::NAN; 4],
        handles: Vec::new(),
    };
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let number = |k: usize| -> f64 { words[k].parse().unwrap() };
        match words[0] {
            "image" => layout.image = std::array::from_fn(|k| number(k + 1)),
            "volume" => layout.volume = std::array::from_fn(|k| number(k + 1)),
            "handle" => layout
                .handles
                .push((words[1].to_string(), [number(2), number(3)])),
            other => panic!("unknown layout line {other}: {text}"),
        }
    }
    assert!(layout.image.iter().all(|v| v.is_finite()), "{text}");
    assert!(layout.volume.iter().all(|v| v.is_finite()), "{text}");
    layout
}

fn read(dir: &TempDir, name: &str) -> String {
    std::fs::read_to_string(dir.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Runs `script` in the window on the folder's `scene.toml`; its standard output, or `None`
/// when no display can be opened (skipped).
fn window_script(dir: &TempDir, script: &str) -> Option<String> {
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    let out = run_with_display(dir, &VIEW)?;
    assert!(
        out.status.success(),
        "{script}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(out.stdout).unwrap())
}

/// Runs `script` without a window (it has no window lines).
fn headless_script(dir: &TempDir, script: &str) {
    std::fs::write(dir.path().join("view.txt"), script).unwrap();
    run_ok(dir, &VIEW);
}

/// The window's layout on the folder's scene once it is refined.
fn layout_of(dir: &TempDir) -> Option<Layout> {
    window_script(dir, "idle\nlayout l.txt\n")?;
    Some(parse_layout(&read(dir, "l.txt")))
}

/// The lines of a pointer drag with `button` from `from` to `to` (window pixels): the
/// pointer moved to `from`, pressed, moved to `to`, released.
fn drag_lines(from: [f64; 2], to: [f64; 2], button: &str) -> String {
    format!(
        "pointer move {} {}\npointer press {} {} {button}\npointer move {} {}\n\
         pointer release {} {} {button}\n",
        from[0], from[1], from[0], from[1], to[0], to[1], to[0], to[1]
    )
}

/// Checks that saved scenes `a` and `b` have the same lines with the same numbers within
/// `tolerance`; returns the lines of `a` that differ from `scene.toml`.
fn same_scene(dir: &TempDir, a: &str, b: &str, tolerance: f64) -> Vec<String> {
    let (original, a, b) = (read(dir, "scene.toml"), read(dir, a), read(dir, b));
    assert_eq!(a.lines().count(), b.lines().count());
    assert_eq!(a.lines().count(), original.lines().count());
    for (x, y) in a.lines().zip(b.lines()) {
        let (nx, ny) = (numbers_in(x), numbers_in(y));
        assert_eq!(nx.len(), ny.len(), "{x}\n{y}");
        assert!(
            nx.iter().zip(&ny).all(|(p, q)| (p - q).abs() <= tolerance),
            "not within {tolerance}:\n{x}\n{y}"
        );
    }
    a.lines()
        .zip(original.lines())
        .filter(|(x, o)| x != o)
        .map(|(x, _)| x.to_string())
        .collect()
}

/// Checks that the script's `f.png` is what `flexcam render p.toml ARGS` writes.
fn frame_renders_p(dir: &TempDir, args: &[&str]) {
    run_ok(
        dir,
        &[&["render", "p.toml"][..], args, &["-o", "r.png"]].concat(),
    );
    assert_eq!(
        std::fs::read(dir.path().join("f.png")).unwrap(),
        std::fs::read(dir.path().join("r.png")).unwrap()
    );
}

/// A folder holding scene file `text` with its image size `from` made `to`, and the
/// window's layout on it; `None` when no display can be opened (skipped).
fn open((text, from, to): (&str, &str, &str)) -> Option<(TempDir, Layout)> {
    let dir = setup_scene(text, from, to, "");
    let layout = layout_of(&dir)?;
    Some((dir, layout))
}

/// The position nearest `at` in whole pixels.
fn whole(at: [f64; 2]) -> [f64; 2] {
    [at[0].round(), at[1].round()]
}

#[test]
fn a_pointer_drag_of_a_volume_handle_is_the_drag_line() {
    let text = include_str!("../../../scenes/flexible-patches.toml");
    let (from, to) = ("width = 320\nheight = 240", "width = 64\nheight = 48");
    let Some((dir, layout)) = open((text, from, to)) else {
        return;
    };
    // The handle farthest from every other, with room about it for the move (so that the
    // press, within half a pixel of it, picks it and no other).
    let [x0, y0, x1, y1] = layout.volume;
    let clearance = |at: [f64; 2]| {
        layout
            .handles
            .iter()
            .map(|(_, p)| (p[0] - at[0]).hypot(p[1] - at[1]))
            .filter(|&d| d > 0.0)
            .fold(f64::INFINITY, f64::min)
    };
    let (name, at) = layout
        .handles
        .iter()
        .filter(|(_, p)| {
            p[0] > x0 + 40.0 && p[0] < x1 - 40.0 && p[1] > y0 + 40.0 && p[1] < y1 - 40.0
        })
        .max_by(|a, b| clearance(a.1).total_cmp(&clearance(b.1)))
        .expect("a handle inside the volume view");
    assert!(clearance(*at) > 3.0, "{name}: {layout:?}");
    let from = whole(*at);
    let to = [from[0] + 30.0, from[1] - 20.0];
    let script = format!(
        "idle\nlayout l2.txt\n{}idle\nframe f.png\nsave p.toml\n",
        drag_lines(from, to, "left")
    );
    if window_script(&dir, &script).is_none() {
        return;
    }
    assert_eq!(parse_layout(&read(&dir, "l2.txt")), layout);
    // A drag line's pixels are those of a view 480 high: the pointer's, scaled.
    let k = 480.0 / (y1 - y0);
    headless_script(
        &dir,
        &format!("drag {name} {:?} {:?}\nsave d.toml\n", 30.0 * k, -20.0 * k),
    );
    // Whole-pixel moves and an f32 view height of whole pixels: the same f64 arithmetic in
    // another order, equal to rounding.
    let changed = same_scene(&dir, "p.toml", "d.toml", 1e-9);
    assert_eq!(changed.len(), 1, "{name}: {changed:?}");
    frame_renders_p(&dir, &[]);
}

/// Drags image handle `handle` of scene `text` (its size `from` made `to`, `width` pixels
/// wide) with the pointer by (10, 6) window pixels, and checks the saved scene against the
/// `drag` line of the same move: only the line starting with `key` changed.
fn pointer_drag_of_image_handle(
    text: &str,
    (from, to): (&str, &str),
    width: f64,
    handle: &str,
    key: &str,
) {
    let Some((dir, layout)) = open((text, from, to)) else {
        return;
    };
    let (_, at) = layout
        .handles
        .iter()
        .find(|(name, _)| name == handle)
        .unwrap_or_else(|| panic!("{handle}: {layout:?}"));
    // Window pixels per image pixel.
    let scale = (layout.image[2] - layout.image[0]) / width;
    let from = whole(*at);
    let to = [from[0] + 10.0, from[1] + 6.0];
    let script = format!(
        "idle\nlayout l2.txt\n{}method raster\nframe f.png\nsave p.toml\n",
        drag_lines(from, to, "left")
    );
    if window_script(&dir, &script).is_none() {
        return;
    }
    assert_eq!(parse_layout(&read(&dir, "l2.txt")), layout);
    headless_script(
        &dir,
        &format!(
            "drag {handle} {:?} {:?}\nsave d.toml\n",
            10.0 / scale,
            6.0 / scale
        ),
    );
    // The window's scale is the f32 it drew with, the test's the drawn width over the
    // image width: equal to f32 rounding (2^-24), so image fractions (the move about 0.1)
    // agree within 1e-6. Only the handle's key moved (the drag did not orbit).
    let changed = same_scene(&dir, "p.toml", "d.toml", 1e-6);
    assert_eq!(changed.len(), 1, "{changed:?}");
    assert!(changed[0].starts_with(key), "{changed:?}");
    frame_renders_p(&dir, &["--method", "raster"]);
}

#[test]
fn a_pointer_drag_of_an_image_handle_is_the_drag_line() {
    let text = include_str!("../../../scenes/flexible-panorama-edit.toml");
    let size = ("width = 320\nheight = 160", "width = 192\nheight = 96");
    pointer_drag_of_image_handle(text, size, 192.0, "rect.corner.2", "perspective_rect =");
}

#[test]
fn a_pointer_drag_of_a_deep_area_is_the_drag_line() {
    let text = include_str!("../../../scenes/flexible-long-scene.toml");
    let size = ("width = 800\nheight = 200", "width = 192\nheight = 48");
    pointer_drag_of_image_handle(text, size, 192.0, "deep.1.width", "deep =");
}

#[test]
fn a_click_picks_and_pointer_orbit_pan_and_wheel_are_the_script_moves() {
    let text = include_str!("../../../scenes/cube-floor.toml");
    let (from, to) = ("width = 800\nheight = 800", "width = 96\nheight = 64");
    let Some((dir, layout)) = open((text, from, to)) else {
        return;
    };
    let [x0, y0, x1, y1] = layout.image;
    let (w, h) = (x1 - x0, y1 - y0);
    let centre = whole([(x0 + x1) / 2.0, (y0 + y1) / 2.0]);
    let [cx, cy] = centre;
    let script = format!(
        "idle\nlayout l2.txt\npointer move {cx} {cy}\npointer press {cx} {cy}\n\
         pointer release {cx} {cy}\n{}{}scroll 120\nidle\nframe f.png\nsave p.toml\n",
        drag_lines(centre, [cx + 20.0, cy + 10.0], "left"),
        drag_lines(centre, [cx + 12.0, cy - 8.0], "right"),
    );
    let Some(stdout) = window_script(&dir, &script) else {
        return;
    };
    assert_eq!(parse_layout(&read(&dir, "l2.txt")), layout);
    // The click printed what its pixel sees: what `flexcam pick` finds there (its point
    // printed to 4 decimals; the pixel, window pixels over the drawn scale, differs from
    // the window's f32 one by about 1e-5 pixels).
    let line = stdout.lines().next().expect("the click's pick line");
    let pixel = [(cx - x0) * 96.0 / w, (cy - y0) * 64.0 / h];
    let at = format!("{},{}", pixel[0], pixel[1]);
    let out = run_ok(&dir, &["pick", "scene.toml", &at]);
    let picked = String::from_utf8(out.stdout).unwrap();
    assert!(
        picked.contains("cube (id 2) at"),
        "the image's centre sees the cube: {picked}"
    );
    assert!(line.contains("object 2 \"cube\" at"), "{line}");
    let shown = numbers_in(line.split(" at ").nth(1).unwrap());
    let expected = numbers_in(picked.split(" at ").nth(1).unwrap());
    assert_eq!(shown.len(), 3, "{line}");
    assert!(
        shown
            .iter()
            .zip(&expected)
            .all(|(a, b)| (a - b).abs() < 1e-4),
        "{line}\n{picked}"
    );
    // The same moves by script lines: 0.3 degrees of orbit a pixel, a pan by the eye's
    // distance per image width (height), the wheel's dolly exp(-0.002) a point.
    headless_script(
        &dir,
        &format!(
            "orbit {:?} {:?}\npan {:?} {:?}\ndolly {:?}\nsave d.toml\n",
            -20.0 * 0.3,
            10.0 * 0.3,
            -12.0 / w,
            -8.0 / h,
            (-0.002f64 * 120.0).exp()
        ),
    );
    // egui divides the pan by the image's size and spreads the wheel's turn over frames in
    // f32 (relative 1e-7 of each), so in a scene about 10 m across the camera's points
    // agree within 1e-5.
    let changed = same_scene(&dir, "p.toml", "d.toml", 1e-5);
    assert_eq!(changed.len(), 2, "{changed:?}");
    assert!(changed[0].starts_with("position =") && changed[1].starts_with("look_at ="));
    frame_renders_p(&dir, &[]);
}
