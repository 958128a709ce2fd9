//! `flexcam raymap`: the ray map of straight and curved projectors and the STMap against a
//! reference camera, read back with the exr crate and compared with closed forms; an STMap
//! applied to a perspective render (bilinear, as a compositor warps a plate) reproduces the
//! fisheye render of the same scene.

use std::fs;

use glam::{DVec2, DVec3, Vec3};
use tempfile::TempDir;

mod common;
use common::{plane_and_sphere, run, run_ok, Layers};

const EYE: DVec3 = DVec3::new(0.0, 1.5, 5.0);
const LOOK_AT: DVec3 = DVec3::new(0.0, 0.8, 0.0);

/// The `[projection]` keys of a camera of type `kind` and field `fov` at [`EYE`].
fn camera(kind: &str, fov: f64) -> String {
    format!(
        "type = \"{kind}\"\nposition = [{}, {}, {}]\nlook_at = [{}, {}, {}]\nfov = {fov}",
        EYE.x, EYE.y, EYE.z, LOOK_AT.x, LOOK_AT.y, LOOK_AT.z
    )
}

/// The camera frame at [`EYE`]: forward, right, up (unit, y up).
fn frame() -> [DVec3; 3] {
    let forward = (LOOK_AT - EYE).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    [forward, right, right.cross(forward)]
}

/// Writes `files` (name, text) into a new folder.
fn folder(files: &[(&str, String)]) -> TempDir {
    let dir = TempDir::new().unwrap();
    for (name, text) in files {
        fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

fn vec3(layers: &Layers, layer: &str) -> Vec<DVec3> {
    layers.vectors(layer).iter().map(|v| v.as_dvec3()).collect()
}

#[test]
fn a_perspective_ray_map_is_the_eye_and_the_closed_form_directions() {
    let (w, h) = (40, 30);
    let dir = folder(&[(
        "p.toml",
        plane_and_sphere(w, h, &camera("perspective", 70.0)),
    )]);
    run_ok(&dir, &["raymap", "p.toml", "-o", "rays.exr"]);
    let layers = Layers::read(&dir.path().join("rays.exr"), (40, 30));
    assert_eq!(
        layers.names(),
        [
            "A",
            "direction.X",
            "direction.Y",
            "direction.Z",
            "origin.X",
            "origin.Y",
            "origin.Z"
        ]
    );
    let [forward, right, up] = frame();
    let half = 35f64.to_radians().tan();
    let (origin, direction) = (vec3(&layers, "origin"), vec3(&layers, "direction"));
    assert!(layers.floats("A").iter().all(|&a| a == 1.0));
    for i in 0..(w * h) as usize {
        let (x, y) = ((i % 40) as f64 + 0.5, (i / 40) as f64 + 0.5);
        let sx = (2.0 * x / 40.0 - 1.0) * half;
        let sy = (1.0 - 2.0 * y / 30.0) * half * 30.0 / 40.0;
        let expected = (forward + sx * right + sy * up).normalize();
        assert!(origin[i].distance(EYE) < 1e-6, "pixel {i}");
        assert!(direction[i].distance(expected) < 1e-6, "pixel {i}");
    }
}

#[test]
fn a_fisheye_ray_map_marks_the_pixels_outside_its_circle() {
    let dir = folder(&[(
        "f.toml",
        plane_and_sphere(32, 24, &camera("fisheye", 180.0)),
    )]);
    run_ok(
        &dir,
        &[
            "raymap", "f.toml", "-o", "rays.exr", "--width", "48", "--height", "24",
        ],
    );
    let layers = Layers::read(&dir.path().join("rays.exr"), (48, 24));
    let (alpha, direction) = (layers.floats("A"), vec3(&layers, "direction"));
    for (i, a) in alpha.iter().enumerate() {
        let centred = DVec2::new((i % 48) as f64 + 0.5 - 24.0, (i / 48) as f64 + 0.5 - 12.0);
        let inside = centred.length() <= 12.0;
        assert_eq!(*a, if inside { 1.0 } else { 0.0 }, "pixel {i}");
        if !inside {
            assert_eq!(direction[i], DVec3::ZERO);
        }
    }
}

/// Curved projectors: each starts on the near square and ends on the far one of
/// scenes/flexible-quadratic.toml, and its start and end tangents meet on the middle
/// square's plane (they are the legs of its Bezier control polygon).
#[test]
fn curved_projectors_have_their_exit_ray() {
    let dir = TempDir::new().unwrap();
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/flexible-quadratic.toml"
    );
    run_ok(
        &dir,
        &[
            "raymap", scene, "-o", "rays.exr", "--width", "32", "--height", "24",
        ],
    );
    let layers = Layers::read(&dir.path().join("rays.exr"), (32, 24));
    assert!(layers.names().contains(&"exit_direction.X"));
    let (origin, direction) = (vec3(&layers, "origin"), vec3(&layers, "direction"));
    let (end, leaving) = (
        vec3(&layers, "exit_origin"),
        vec3(&layers, "exit_direction"),
    );
    assert!(layers.floats("A").iter().all(|&a| a == 1.0));
    for i in 0..32 * 24 {
        assert!((origin[i].z - 6.0).abs() < 1e-6 && (end[i].z + 4.0).abs() < 1e-6);
        assert!(origin[i].x.abs() <= 0.2 + 1e-9 && (origin[i].y - 2.0).abs() <= 0.15 + 1e-9);
        assert!((direction[i].length() - 1.0).abs() < 1e-6);
        assert!((leaving[i].length() - 1.0).abs() < 1e-6);
        let from_start = origin[i] + direction[i] * ((1.0 - origin[i].z) / direction[i].z);
        let from_end = end[i] + leaving[i] * ((1.0 - end[i].z) / leaving[i].z);
        assert!(from_start.distance(from_end) < 1e-4, "pixel {i}");
        assert!((from_start.x - 1.5).abs() <= 2.4 + 1e-4 && (from_start.y - 2.5).abs() <= 1.8);
    }
}

/// The STMap of a camera against itself is the identity: s = (x + 0.5) / w,
/// t = 1 - (y + 0.5) / h at every pixel, surfaces and background alike; the 16-bit PNG
/// holds round(65535 s), round(65535 t) of the EXR's values.
#[test]
fn an_stmap_against_the_same_camera_is_the_identity() {
    let dir = folder(&[(
        "p.toml",
        plane_and_sphere(40, 30, &camera("perspective", 70.0)),
    )]);
    for out in ["st.exr", "st.png"] {
        run_ok(
            &dir,
            &["raymap", "p.toml", "--stmap", out, "--reference", "p.toml"],
        );
    }
    let png = image::open(dir.path().join("st.png")).unwrap().to_rgba16();
    let layers = Layers::read(&dir.path().join("st.exr"), (40, 30));
    assert_eq!(layers.names(), ["A", "B", "G", "R"]);
    let (s, t, a) = (layers.floats("R"), layers.floats("G"), layers.floats("A"));
    for i in 0..40 * 30 {
        let (x, y) = ((i % 40) as f64 + 0.5, (i / 40) as f64 + 0.5);
        assert_eq!(a[i], 1.0, "pixel {i}");
        assert!((s[i] as f64 - x / 40.0).abs() < 1e-6, "pixel {i}");
        assert!((t[i] as f64 - (1.0 - y / 30.0)).abs() < 1e-6, "pixel {i}");
        let code = |v: f32| (v as f64 * 65535.0).round() as u16;
        let expected = [code(s[i]), code(t[i]), 0, u16::MAX];
        assert_eq!(png.get_pixel((i % 40) as u32, (i / 40) as u32).0, expected);
    }
}

/// Where a 180-degree fisheye pixel lies in a 90-degree perspective image from the same
/// eye, by the two projections' definitions: `None` outside the perspective image.
fn fisheye_to_perspective(i: usize, fisheye: u32, (w, h): (u32, u32)) -> Option<DVec2> {
    let n = fisheye as f64;
    let centred = DVec2::new(
        (i as u32 % fisheye) as f64 + 0.5,
        (i as u32 / fisheye) as f64 + 0.5,
    ) - DVec2::splat(n / 2.0);
    let theta = centred.length() / (n / 2.0) * 90f64.to_radians();
    let azimuth = centred.normalize();
    let [forward, right, up] = frame();
    let d = forward * theta.cos() + (right * azimuth.x - up * azimuth.y) * theta.sin();
    if d.dot(forward) <= 0.0 {
        return None;
    }
    let pixel = f64::from(w) / 2.0; // focal length in pixels: tan(45 degrees) = 1
    let x = f64::from(w) / 2.0 + pixel * d.dot(right) / d.dot(forward);
    let y = f64::from(h) / 2.0 - pixel * d.dot(up) / d.dot(forward);
    ((0.0..f64::from(w)).contains(&x) && (0.0..f64::from(h)).contains(&y))
        .then(|| DVec2::new(x / f64::from(w), 1.0 - y / f64::from(h)))
}

/// A folder with `f.toml` (the plane and sphere through a 64 x 64, 180-degree fisheye),
/// `p.toml` (the same through a 90-degree perspective of `size`) and `st.exr`, the fisheye's
/// STMap against that perspective (`flexcam raymap f.toml --stmap st.exr --reference p.toml`).
fn fisheye_stmap((w, h): (u32, u32)) -> TempDir {
    let dir = folder(&[
        (
            "f.toml",
            plane_and_sphere(64, 64, &camera("fisheye", 180.0)),
        ),
        (
            "p.toml",
            plane_and_sphere(w, h, &camera("perspective", 90.0)),
        ),
    ]);
    run_ok(
        &dir,
        &[
            "raymap",
            "f.toml",
            "--stmap",
            "st.exr",
            "--reference",
            "p.toml",
        ],
    );
    dir
}

#[test]
fn a_fisheye_stmap_against_a_perspective_is_the_closed_form() {
    let dir = fisheye_stmap((80, 60));
    let layers = Layers::read(&dir.path().join("st.exr"), (64, 64));
    let (s, t, a) = (layers.floats("R"), layers.floats("G"), layers.floats("A"));
    let (mut inside, mut hidden) = (0, 0);
    for i in 0..64 * 64 {
        let centred = DVec2::new((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5) - 32.0;
        match fisheye_to_perspective(i, 64, (80, 60)) {
            _ if centred.length() > 32.0 => assert_eq!(a[i], 0.0, "pixel {i}: no ray"),
            None => assert_eq!(a[i], 0.0, "pixel {i}: outside the perspective"),
            // A surface point seen from the same eye is hidden only by rounding, at an
            // object's silhouette.
            Some(_) if a[i] == 0.0 => hidden += 1,
            Some(st) => {
                inside += 1;
                assert!(
                    (s[i] as f64 - st.x).abs() < 1e-6,
                    "pixel {i}: s {} {}",
                    s[i],
                    st.x
                );
                assert!(
                    (t[i] as f64 - st.y).abs() < 1e-6,
                    "pixel {i}: t {} {}",
                    t[i],
                    st.y
                );
            }
        }
    }
    assert!(inside > 500 && hidden < 10, "{inside} {hidden}");
}

/// Bilinear sample of the `w` x `h` image `rgb` (rows from the top) at STMap (s, t).
fn sample(rgb: &[Vec3], (w, h): (usize, usize), (s, t): (f32, f32)) -> Vec3 {
    let x = (s * w as f32 - 0.5).clamp(0.0, w as f32 - 1.0);
    let y = ((1.0 - t) * h as f32 - 0.5).clamp(0.0, h as f32 - 1.0);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |x: usize, y: usize| rgb[y * w + x];
    (at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx) * (1.0 - fy)
        + (at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx) * fy
}

#[test]
fn an_stmap_warps_a_perspective_render_into_the_fisheye_render() {
    let dir = fisheye_stmap((320, 240));
    for scene in ["f", "p"] {
        let args = ["render", &format!("{scene}.toml"), "--shading", "flat"];
        run_ok(
            &dir,
            &[&args[..], &["-o", &format!("{scene}.exr")]].concat(),
        );
    }
    let colour = |name: &str, size| {
        let layers = Layers::read(&dir.path().join(name), size);
        let [r, g, b] = ["R", "G", "B"].map(|c| layers.floats(c));
        (0..r.len())
            .map(|i| Vec3::new(r[i], g[i], b[i]))
            .collect::<Vec<_>>()
    };
    let (fisheye, plate) = (colour("f.exr", (64, 64)), colour("p.exr", (320, 240)));
    let st = Layers::read(&dir.path().join("st.exr"), (64, 64));
    let (s, t, a) = (st.floats("R"), st.floats("G"), st.floats("A"));
    // Away from edges: the fisheye pixel and its 8 neighbours show one colour.
    let uniform = |i: usize| {
        let (x, y) = (i % 64, i / 64);
        (1..63).contains(&x)
            && (1..63).contains(&y)
            && (0..9).all(|k| fisheye[(y + k / 3 - 1) * 64 + x + k % 3 - 1] == fisheye[i])
    };
    let mut compared = 0;
    for i in (0..64 * 64).filter(|&i| a[i] == 1.0 && uniform(i)) {
        let warped = sample(&plate, (320, 240), (s[i], t[i]));
        assert!(
            warped.distance(fisheye[i]) < 1e-3,
            "pixel {i}: {warped} {}",
            fisheye[i]
        );
        compared += 1;
    }
    assert!(compared > 250, "{compared}");
}

#[test]
fn bad_raymap_requests_are_one_line_and_write_nothing() {
    let dir = folder(&[
        (
            "p.toml",
            plane_and_sphere(16, 12, &camera("perspective", 70.0)),
        ),
        (
            "q.toml",
            fs::read_to_string(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../scenes/flexible-occlusion.toml"
            ))
            .unwrap(),
        ),
    ]);
    let fails = |args: &[&str], status: i32, expected: &str| {
        let out = run(&dir, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(status), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    };
    fails(&["raymap", "p.toml"], 1, "nothing to write");
    fails(
        &["raymap", "p.toml", "-o", "rays.png"],
        1,
        "rays.png: unsupported output",
    );
    fails(
        &[
            "raymap",
            "p.toml",
            "--stmap",
            "st.tif",
            "--reference",
            "p.toml",
        ],
        1,
        "st.tif: unsupported output extension",
    );
    fails(
        &[
            "raymap",
            "p.toml",
            "-o",
            "a.exr",
            "--stmap",
            "a.exr",
            "--reference",
            "p.toml",
        ],
        1,
        "a.exr: the STMap is the same file as the ray map",
    );
    fails(&["raymap", "p.toml", "--stmap", "st.exr"], 2, "--reference");
    fails(
        &[
            "raymap",
            "p.toml",
            "--stmap",
            "st.exr",
            "--reference",
            "q.toml",
        ],
        1,
        "q.toml: the reference camera needs a projection with an inverse; flexible has none",
    );
    fails(
        &[
            "raymap",
            "p.toml",
            "--stmap",
            "st.exr",
            "--reference",
            "p.toml",
            "--distance",
            "-1",
        ],
        1,
        "--distance must be a positive number",
    );
    let left: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "{left:?}");
}
