//! End-to-end tests of `flexcam render --atlas FILE` (docs/camera-triangles.md, "The joint
//! texture atlas"): one image per atlas reflector, named after it and its light path, of the
//! size `--stats` reports, holding the reflected scene in its right triangles; refused, with
//! one line naming the file, where the scene has no atlas reflector.

use std::path::Path;

use tempfile::TempDir;

mod common;
use common::{run, run_json, scene_example};

/// The atlas image's size and its texels that are not the background (the colour of texel
/// (0, 0), in the margin of the first cell that no triangle covers).
fn atlas_texels(path: &Path) -> ((u32, u32), usize) {
    let image = image::open(path).unwrap().to_rgb8();
    let background = image.get_pixel(0, 0).0;
    let covered = image.pixels().filter(|p| p.0 != background).count();
    (image.dimensions(), covered)
}

/// A mirror's atlas: `STEM-NAME-reflection.png`, as large as `atlas_width` x
/// `atlas_height`, a quarter or more of its texels reflecting objects (flat shading: their
/// base colours) rather than the background.
#[test]
fn a_mirrors_atlas_is_written_beside_the_image() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("camtri-convex.toml");
    let stats = run_json(
        &dir,
        &[
            "render",
            &scene,
            "--method",
            "camera-triangles",
            "--shading",
            "flat",
            "--width",
            "160",
            "-D",
            "object.sphere.reflection=\"atlas\"",
            "--atlas",
            "out/atlas.png",
            "--stats",
            "-",
            "-o",
            "out/main.png",
        ],
    );
    let path = dir.path().join("out/atlas-sphere-reflection.png");
    let (size, covered) = atlas_texels(&path);
    let want = (
        stats["atlas_width"].as_u64().unwrap() as u32,
        stats["atlas_height"].as_u64().unwrap() as u32,
    );
    assert_eq!(size, want, "{stats}");
    let texels = (size.0 * size.1) as usize;
    assert!(covered * 4 > texels, "{covered} of {texels} texels");
    let outputs = stats["outputs"].to_string();
    assert!(outputs.contains("atlas-sphere-reflection.png"), "{outputs}");
}

/// Lit glass makes two atlases, its refraction and its Fresnel reflection; flat glass one.
#[test]
fn glass_writes_its_refraction_and_lit_its_reflection_atlas() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("camtri-refract.toml");
    let base = [
        "render",
        &scene,
        "--method",
        "camera-triangles",
        "--width",
        "120",
        "-D",
        "object.lens.reflection=\"atlas\"",
        "--atlas",
        "a.png",
        "-o",
        "main.png",
        "--shading",
    ];
    let lit = run(&dir, &[&base[..], &["lit"]].concat());
    assert!(lit.status.success(), "{lit:?}");
    for file in ["a-lens-refraction.png", "a-lens-reflection.png"] {
        assert!(dir.path().join(file).is_file(), "{file}");
    }
    let flat_dir = TempDir::new().unwrap();
    let flat = run(&flat_dir, &[&base[..], &["flat"]].concat());
    assert!(flat.status.success(), "{flat:?}");
    assert!(flat_dir.path().join("a-lens-refraction.png").is_file());
    assert!(!flat_dir.path().join("a-lens-reflection.png").exists());
}

/// No atlas reflector, or an extension that is not a colour image's: one line naming the
/// file, a non-zero exit, nothing written.
#[test]
fn atlas_outputs_are_refused_with_the_reason() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("camtri-convex.toml");
    let plain = run(
        &dir,
        &["render", &scene, "--atlas", "a.png", "-o", "main.png"],
    );
    assert!(!plain.status.success());
    let stderr = String::from_utf8_lossy(&plain.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("a.png") && stderr.contains("reflection = \"atlas\""),
        "{stderr}"
    );
    let tiff = run(
        &dir,
        &[
            "render",
            &scene,
            "-D",
            "object.sphere.reflection=\"atlas\"",
            "--atlas",
            "a.tif",
            "-o",
            "main.png",
        ],
    );
    assert!(!tiff.status.success());
    let stderr = String::from_utf8_lossy(&tiff.stderr);
    assert!(
        stderr.contains("a.tif") && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert!(!dir.path().join("main.png").exists());
}
