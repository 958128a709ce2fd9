//! The depth-discontinuity occlusion camera (`preset = "ddoc"`) from the command line:
//! `flexcam ddoc-map` writes the map of the example scene and the DDOC then shows the balls
//! its pillar hides in the perspective view; a zero map renders the perspective's pixels;
//! bad maps are refused with one line naming the file; `--method raster` renders it like the
//! ray caster and refuses a map steep enough to fold, saying why.

mod common;

use std::fs;

use common::{raster_agrees, run, run_ok, scene_example};
use tempfile::TempDir;

/// The example scene's text with its `map` line replaced by `map_line` (empty: no map).
fn example_with(map_line: &str) -> String {
    let text = fs::read_to_string(scene_example("flexible-ddoc.toml")).unwrap();
    let line = "map = \"flexible-ddoc-map.pfm\"\n";
    assert!(text.contains(line));
    text.replace(line, map_line)
}

/// Renders `scene` by ray casting, flat, and returns its ids.
fn ids(dir: &TempDir, scene: &str, name: &str) -> Vec<u16> {
    common::render_flat(dir, scene, name);
    common::ids(&dir.path().join(format!("{name}-ids.png"))).2
}

/// The two balls (ids 4 and 5) are hidden behind the pillar in the perspective, and the
/// DDOC with the map `ddoc-map` writes shows both, beside the pillar (id 3), which keeps
/// its own pixels.
#[test]
fn ddoc_map_reveals_what_the_pillar_hides() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("reference.toml"), example_with("")).unwrap();
    run_ok(
        &dir,
        &[
            "ddoc-map",
            "reference.toml",
            "--width",
            "80",
            "--height",
            "60",
            "--strength",
            "0.06",
            "-o",
            "map.pfm",
        ],
    );
    fs::write(
        dir.path().join("ddoc.toml"),
        example_with("map = \"map.pfm\"\n"),
    )
    .unwrap();
    let perspective = ids(&dir, "reference.toml", "perspective");
    let ddoc = ids(&dir, "ddoc.toml", "ddoc");
    let count = |ids: &[u16], id: u16| ids.iter().filter(|&&i| i == id).count();
    assert_eq!(count(&perspective, 4) + count(&perspective, 5), 0);
    for ball in [4, 5] {
        assert!(
            count(&ddoc, ball) > 200,
            "ball {ball}: {}",
            count(&ddoc, ball)
        );
    }
    // The pillar is nearer than z_near: its pixels are the perspective's.
    let pillar = |ids: &[u16]| -> Vec<bool> { ids.iter().map(|&i| i == 3).collect() };
    assert_eq!(pillar(&perspective), pillar(&ddoc));
    // The shipped map is the one the documented command writes.
    let shipped = fs::read(scene_example("flexible-ddoc-map.pfm")).unwrap();
    assert_eq!(fs::read(dir.path().join("map.pfm")).unwrap(), shipped);
    // The example renders with it.
    let example = ids(&dir, &scene_example("flexible-ddoc.toml"), "example");
    assert_eq!(example, ddoc);
}

/// `--method raster` renders the example as the ray caster does (interior ids, relative RGB
/// error: `common::raster_agrees`), balls revealed beside the pillar included.
#[test]
fn the_ddoc_rasters_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    raster_agrees(&dir, &[&scene_example("flexible-ddoc.toml")]);
    let raster = common::ids(&dir.path().join("raster-ids.png")).2;
    for ball in [4, 5] {
        let n = raster.iter().filter(|&&i| i == ball).count();
        assert!(n > 200, "ball {ball}: {n} pixels");
    }
}

/// A colour PFM of `w` x `h` samples `value` (little-endian).
fn pfm(w: u32, h: u32, value: f32) -> Vec<u8> {
    let mut bytes = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    for _ in 0..w * h * 3 {
        bytes.extend_from_slice(&value.to_le_bytes());
    }
    bytes
}

/// A zero map renders the perspective preset's ids and colours at every pixel.
#[test]
fn a_zero_map_renders_the_perspective() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("zero.pfm"), pfm(3, 2, 0.0)).unwrap();
    fs::write(
        dir.path().join("ddoc.toml"),
        example_with("map = \"zero.pfm\"\n"),
    )
    .unwrap();
    let perspective = example_with("")
        .replace("preset = \"ddoc\"", "preset = \"perspective\"")
        .replace("z_near = 3.5", "")
        .replace("z_far = 6.0", "");
    fs::write(dir.path().join("perspective.toml"), perspective).unwrap();
    assert_eq!(
        ids(&dir, "ddoc.toml", "ddoc"),
        ids(&dir, "perspective.toml", "perspective")
    );
    let rgb = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (a, b) = (rgb("ddoc.png"), rgb("perspective.png"));
    let worst = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap();
    assert!(worst <= 1, "{worst}");
}

/// Runs `args` and returns its one stderr line, asserting exit status 1.
fn refused(dir: &TempDir, args: &[&str]) -> String {
    let out = run(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    stderr
}

#[test]
fn bad_maps_and_bad_uses_are_refused_naming_the_file() {
    let dir = TempDir::new().unwrap();
    let good = pfm(4, 3, 0.01);
    let mut nan = good.clone();
    let header = "PF\n4 3\n-1.0\n".len();
    nan[header + 16..header + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "short.pfm",
            good[..good.len() - 4].to_vec(),
            "flexcam: short.pfm: a 4 x 3 colour PFM holds 144 bytes of samples, the file has 140",
        ),
        (
            "nan.pfm",
            nan,
            "flexcam: nan.pfm: ddoc map sample at pixel (1, 2) (from the top left) must be finite",
        ),
        (
            "gray.pfm",
            b"Pf\n4 3\n-1.0\n".to_vec(),
            "flexcam: gray.pfm: a ddoc map is a colour PFM",
        ),
    ];
    for (name, bytes, expected) in cases {
        fs::write(dir.path().join(name), bytes).unwrap();
        let scene = format!("{name}.toml");
        fs::write(
            dir.path().join(&scene),
            example_with(&format!("map = \"{name}\"\n")),
        )
        .unwrap();
        let line = refused(&dir, &["render", &scene, "-o", "out.png"]);
        assert!(line.starts_with(expected), "{line}");
        assert!(!dir.path().join("out.png").exists());
    }
    fs::write(
        dir.path().join("missing.toml"),
        example_with("map = \"missing.pfm\"\n"),
    )
    .unwrap();
    let line = refused(&dir, &["render", "missing.toml", "-o", "out.png"]);
    assert!(
        line.starts_with("flexcam: missing.toml:")
            && line.contains("ddoc map \"missing.pfm\" is not a file"),
        "{line}"
    );
    // Raster refuses a map steep enough to fold, with the reason and the method that works:
    // two samples 0.5 apart across a two-pixel map, slope 2 x 0.5.
    let mut steep = b"PF\n2 1\n-1.0\n".to_vec();
    for v in [0.0f32, 0.0, 0.0, 0.5, 0.0, 0.0] {
        steep.extend_from_slice(&v.to_le_bytes());
    }
    fs::write(dir.path().join("steep.pfm"), steep).unwrap();
    fs::write(
        dir.path().join("steep.toml"),
        example_with("map = \"steep.pfm\"\n"),
    )
    .unwrap();
    let line = refused(
        &dir,
        &[
            "render",
            "steep.toml",
            "--method",
            "raster",
            "-o",
            "out.png",
        ],
    );
    assert!(
        line.contains("its displacement map's slope reaches 1.000 (at map pixel (0, 0)")
            && line.ends_with("(use --method raycast)\n"),
        "{line}"
    );
    fs::write(dir.path().join("ok.pfm"), pfm(2, 2, 0.0)).unwrap();
    fs::write(
        dir.path().join("ok.toml"),
        example_with("map = \"ok.pfm\"\n"),
    )
    .unwrap();
    // ddoc-map needs a ddoc and a strength in range.
    let line = refused(
        &dir,
        &[
            "ddoc-map",
            &scene_example("flexible-occlusion.toml"),
            "-o",
            "m.pfm",
        ],
    );
    assert!(
        line.contains("needs a flexible projection with preset = \"ddoc\""),
        "{line}"
    );
    let line = refused(
        &dir,
        &["ddoc-map", "ok.toml", "--strength", "0.5", "-o", "m.pfm"],
    );
    assert!(line.contains("--strength must be in (0, 0.1]"), "{line}");
    assert!(!dir.path().join("m.pfm").exists());
}
