//! Correspondences in a painting's pixel coordinates (`pixel` entries with `painting` or
//! `painting_size`) and `flexcam fit --overlay` (docs/fitting.md, "Fitting to a painting").

mod common;

use common::{run, run_ok};
use tempfile::TempDir;

/// The objects and lights of every case: a checker floor, a cube and a ball.
const OBJECTS: &str = common::FLOOR_CUBE_BALL;

/// The painting's size.
const W: u32 = 320;
const H: u32 = 240;

/// The painter: a pinhole camera whose clicks a 5 x 5 grid fits exactly.
fn painter() -> String {
    format!(
        "[image]\nwidth = {W}\nheight = {H}\n[projection]\ntype = \"perspective\"\nposition = \
         [2.0, 4.0, 8.0]\nlook_at = [0.0, 0.5, 0.0]\nfov = 55.0\n{OBJECTS}"
    )
}

/// Clicks at pixel centres over the painter's image with the scene points it sees there:
/// (x, y, point) for every position that sees an object.
fn clicks(dir: &TempDir) -> Vec<(f64, f64, [f64; 3])> {
    std::fs::write(dir.path().join("painter.toml"), painter()).unwrap();
    let mut positions = Vec::new();
    for j in 0..5 {
        for i in 0..6 {
            positions.push(format!("{}.5,{}.5", 20 + 55 * i, 20 + 50 * j));
        }
    }
    let mut args = vec!["pick", "painter.toml", "--json"];
    args.extend(positions.iter().map(String::as_str));
    let out = run_ok(dir, &args);
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| !v["object"].is_null())
        .map(|v| {
            let f = |a: &serde_json::Value, i: usize| a[i].as_f64().unwrap();
            let p = &v["point"];
            (
                f(&v["pixel"], 0),
                f(&v["pixel"], 1),
                [f(p, 0), f(p, 1), f(p, 2)],
            )
        })
        .collect()
}

/// A `fit` entry in pixels or in (u, v) (u = x / W, v = 1 - y / H, as the docs say).
fn entry((x, y, p): &(f64, f64, [f64; 3]), pixel: bool) -> String {
    let position = if pixel {
        format!("pixel = [{x:?}, {y:?}]")
    } else {
        let (u, v) = (x / f64::from(W), 1.0 - y / f64::from(H));
        format!("uv = [{u:?}, {v:?}]")
    };
    format!(
        "    {{ {position}, point = [{:?}, {:?}, {:?}] }},\n",
        p[0], p[1], p[2]
    )
}

/// The fitting scene: image `size`, a guessed 60-degree prior on a 5 x 5 grid, `keys` in
/// the projectors table and `entries` as its `fit`.
fn fitting_scene(size: (u32, u32), keys: &str, entries: &str) -> String {
    format!(
        "[image]\nwidth = {}\nheight = {}\n[projection]\ntype = \"flexible\"\npreset = \
         \"perspective\"\nposition = [0.0, 5.5, 7.0]\nlook_at = [0.0, 0.4, 0.0]\nfov = 60.0\n\
         clip = [0.5, 40.0]\n\n[projection.projectors]\nsize = [5, 5]\n{keys}fit = [\n{entries}]\n\
         {OBJECTS}",
        size.0, size.1
    )
}

/// A solid `W` x `H` PNG painting of colour `rgb`.
fn write_painting(dir: &TempDir, name: &str, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(W, H, image::Rgb(rgb))
        .save(dir.path().join(name))
        .unwrap();
}

/// The fitted node projectors of the file `fitted` (its `projector = [...]` list), the part
/// of the written scene that holds the fit.
fn fitted_nodes(dir: &TempDir, fitted: &str) -> String {
    let text = std::fs::read_to_string(dir.path().join(fitted)).unwrap();
    let start = text.find("projector = [").unwrap();
    text[start..].to_string()
}

#[test]
fn pixel_and_uv_forms_give_the_same_fit() {
    let dir = TempDir::new().unwrap();
    let clicks = clicks(&dir);
    assert!(clicks.len() >= 15, "{} clicks", clicks.len());
    write_painting(&dir, "painting.png", [200, 100, 50]);
    let all = |pixel: bool| clicks.iter().map(|c| entry(c, pixel)).collect::<String>();
    let mixed: String = (clicks.iter().enumerate())
        .map(|(k, c)| entry(c, k % 2 == 0))
        .collect();
    let cases = [
        ("uv.toml", String::new(), all(false)),
        (
            "size.toml",
            format!("painting_size = [{W}, {H}]\n"),
            all(true),
        ),
        (
            "image.toml",
            "painting = \"painting.png\"\n".into(),
            all(true),
        ),
        ("mixed.toml", "painting = \"painting.png\"\n".into(), mixed),
    ];
    let mut nodes = Vec::new();
    for (name, keys, entries) in &cases {
        std::fs::write(dir.path().join(name), fitting_scene((W, H), keys, entries)).unwrap();
        let out = format!("fitted-{name}");
        run_ok(&dir, &["fit", name, "-o", &out]);
        nodes.push(fitted_nodes(&dir, &out));
        // The written scene keeps neither the painting nor the clicks.
        let written = std::fs::read_to_string(dir.path().join(&out)).unwrap();
        assert!(
            !written.contains("painting") && !written.contains("pixel ="),
            "{written}"
        );
    }
    for (k, n) in nodes.iter().enumerate().skip(1) {
        assert_eq!(n, &nodes[0], "{} against uv.toml", cases[k].0);
    }
}

#[test]
fn the_overlay_marks_each_click_over_the_painting() {
    let dir = TempDir::new().unwrap();
    let clicks = clicks(&dir);
    write_painting(&dir, "painting.png", [255, 0, 255]);
    let entries: String = clicks.iter().map(|c| entry(c, true)).collect();
    // The scene's image is smaller than the painting: the overlay has the painting's size.
    let keys = "painting = \"painting.png\"\n";
    std::fs::write(
        dir.path().join("fit.toml"),
        fitting_scene((160, 120), keys, &entries),
    )
    .unwrap();
    let out = run_ok(
        &dir,
        &[
            "fit",
            "fit.toml",
            "-o",
            "fitted.toml",
            "--overlay",
            "overlay.png",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("over {} correspondences", clicks.len()))
            && stdout.contains("residual in the image max 0.00 px"),
        "{stdout}"
    );
    let overlay = image::open(dir.path().join("overlay.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(overlay.dimensions(), (W, H));
    // The data are exact: every mark is green, and the ring's rightmost pixel is 4 px right
    // of the click (whose projector meets the point there: no line, no other colour).
    for (x, y, _) in &clicks {
        let ring = overlay.get_pixel(*x as u32 + 4, *y as u32).0;
        assert!(
            ring[1] > 200 && ring[0] < 100 && ring[2] < 100,
            "{x},{y}: {ring:?}"
        );
        let fitted = overlay.get_pixel(*x as u32, *y as u32).0;
        assert_eq!(fitted, ring, "the fitted image's square at {x},{y}");
    }
    // Away from the marks (rings, and labels of up to two digits right of them), half the
    // painting: its red and blue at least sRGB(0.5) = 188.
    let far = |px: u32, py: u32| {
        clicks
            .iter()
            .all(|(x, y, _)| (f64::from(px) - x).abs() > 20.0 || (f64::from(py) - y).abs() > 14.0)
    };
    let mut checked = 0;
    for (px, py, p) in overlay.enumerate_pixels() {
        if far(px, py) {
            assert!(p.0[0] >= 187 && p.0[2] >= 187, "{px},{py}: {:?}", p.0);
            checked += 1;
        }
    }
    assert!(checked > 10_000, "{checked}");
}

#[test]
fn an_overlay_without_a_painting_is_the_render_at_the_painting_size() {
    let dir = TempDir::new().unwrap();
    let clicks = clicks(&dir);
    let entries: String = clicks.iter().map(|c| entry(c, true)).collect();
    let keys = format!("painting_size = [{W}, {H}]\n");
    std::fs::write(
        dir.path().join("fit.toml"),
        fitting_scene((160, 120), &keys, &entries),
    )
    .unwrap();
    run_ok(
        &dir,
        &["fit", "fit.toml", "-o", "fitted.toml", "--overlay", "o.png"],
    );
    let overlay = image::open(dir.path().join("o.png")).unwrap().to_rgb8();
    assert_eq!(overlay.dimensions(), (W, H));
    // uv entries and the scene's own size: the overlay has the scene's size.
    let uv: String = clicks.iter().map(|c| entry(c, false)).collect();
    std::fs::write(
        dir.path().join("uv.toml"),
        fitting_scene((160, 120), "", &uv),
    )
    .unwrap();
    run_ok(
        &dir,
        &[
            "fit",
            "uv.toml",
            "-o",
            "fitted-uv.toml",
            "--overlay",
            "uv.png",
        ],
    );
    let overlay = image::open(dir.path().join("uv.png")).unwrap().to_rgb8();
    assert_eq!(overlay.dimensions(), (160, 120));
}

#[test]
fn a_click_the_fit_misses_is_marked_with_its_residual() {
    let dir = TempDir::new().unwrap();
    let mut clicks = clicks(&dir);
    // One click 6 px off its point, fitted by one pinhole camera (which the other clicks
    // determine): the overlay shows that entry off and says which.
    clicks[7].0 += 6.0;
    let entries: String = clicks.iter().map(|c| entry(c, true)).collect();
    let keys = format!("painting_size = [{W}, {H}]\nstarts = \"pinhole\"\n");
    std::fs::write(
        dir.path().join("fit.toml"),
        fitting_scene((W, H), &keys, &entries),
    )
    .unwrap();
    let out = run_ok(
        &dir,
        &["fit", "fit.toml", "-o", "fitted.toml", "--overlay", "o.png"],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("(entry 8)"), "{stdout}");
    let overlay = image::open(dir.path().join("o.png")).unwrap().to_rgb8();
    let (x, y, _) = clicks[7];
    let ring = overlay.get_pixel(x as u32 + 4, y as u32).0;
    assert!(
        ring[0] > 200 && ring[1] < 100,
        "red ring at {x},{y}: {ring:?}"
    );
}

#[test]
fn bad_painting_input_is_one_line_naming_file_and_entry() {
    let dir = TempDir::new().unwrap();
    let good = "    { pixel = [100.5, 80.5], point = [0.0, 0.0, 0.0] },\n".repeat(6);
    write_painting(&dir, "painting.png", [0, 0, 0]);
    std::fs::write(dir.path().join("not-an-image.png"), "text").unwrap();
    let cases: [(&str, String, &str); 8] = [
        (
            "",
            good.clone(),
            "`fit` entry 1: `pixel` positions need the painting",
        ),
        (
            "painting = \"painting.png\"\n",
            format!("{good}    {{ pixel = [320.5, 10.0], point = [0.0, 0.0, 0.0] }},\n"),
            "`fit` entry 7: pixel [320.5, 10] is outside the 320 x 240 painting",
        ),
        (
            "painting_size = [320, 240]\n",
            format!("{good}    {{ pixel = [10.0, -1.0], point = [0.0, 0.0, 0.0] }},\n"),
            "`fit` entry 7: pixel [10, -1] is outside the 320 x 240 painting",
        ),
        (
            "painting = \"painting.png\"\n",
            format!(
                "{good}    {{ uv = [0.5, 0.5], pixel = [1.0, 1.0], point = [0.0, 0.0, 0.0] }},\n"
            ),
            "`fit` entry 7 gives both `uv` and `pixel`",
        ),
        (
            "painting = \"painting.png\"\n",
            format!("{good}    {{ point = [0.0, 0.0, 0.0] }},\n"),
            "`fit` entry 7 has no image position",
        ),
        (
            "painting = \"missing.png\"\n",
            good.clone(),
            "painting \"missing.png\" is not a file",
        ),
        (
            "painting = \"not-an-image.png\"\n",
            good.clone(),
            "painting \"not-an-image.png\" cannot be read",
        ),
        (
            "painting = \"painting.png\"\npainting_size = [320, 240]\n",
            good.clone(),
            "not both",
        ),
    ];
    for (keys, entries, message) in &cases {
        std::fs::write(
            dir.path().join("bad.toml"),
            fitting_scene((W, H), keys, entries),
        )
        .unwrap();
        let out = run(
            &dir,
            &["fit", "bad.toml", "-o", "out.toml", "--overlay", "out.png"],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{message}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("bad.toml:") && stderr.contains(message),
            "expected {message:?}: {stderr}"
        );
        assert!(!dir.path().join("out.toml").exists() && !dir.path().join("out.png").exists());
    }
    // The painting keys go with `fit`.
    let no_fit =
        fitting_scene((W, H), "painting_size = [320, 240]\n", "").replace("fit = [\n]\n", "");
    std::fs::write(dir.path().join("bad.toml"), no_fit).unwrap();
    let out = run(&dir, &["render", "bad.toml", "-o", "out.png"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert!(
        stderr.contains("bad.toml:") && stderr.contains("go with `fit`"),
        "{stderr}"
    );
    for size in ["[0, 240]", "[320, 70000]", "[-1, 5]"] {
        let keys = format!("painting_size = {size}\n");
        std::fs::write(
            dir.path().join("bad.toml"),
            fitting_scene((W, H), &keys, &good),
        )
        .unwrap();
        let out = run(&dir, &["fit", "bad.toml", "-o", "out.toml"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && stderr.lines().count() == 1,
            "{stderr}"
        );
        assert!(stderr.contains("`painting_size` must be"), "{stderr}");
    }
}

#[test]
fn pick_prints_fit_entries_that_load_as_they_are() {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("painter.toml"), painter()).unwrap();
    let positions = [
        "160.5,200.5",
        "100.5,150.5",
        "200.5,150.5",
        "160.5,120.5",
        "60.5,200.5",
        "260.5,200.5",
        "1,1",
    ];
    let mut args = vec!["pick", "painter.toml", "--fit"];
    args.extend(positions);
    let out = run_ok(&dir, &args);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[0].starts_with("{ pixel = [160.5, 200.5], point = ["),
        "{text}"
    );
    assert!(lines[0].ends_with("# floor"), "{text}");
    assert_eq!(lines[6], "# 1,1: nothing");
    // Pasted into a `fit` list they load and fit.
    let entries = format!("{}\n", lines[..6].join("\n"));
    let keys = format!("painting_size = [{W}, {H}]\n");
    std::fs::write(
        dir.path().join("fit.toml"),
        fitting_scene((W, H), &keys, &entries),
    )
    .unwrap();
    run_ok(&dir, &["fit", "fit.toml", "-o", "fitted.toml"]);
}
