//! `flexcam volume`: a scene projection's viewing volume written as OBJ + MTL, for a
//! flexible volume and a pinhole; the outputs never overwrite an input; the tube form
//! renders beside the scene with flexcam itself.

mod common;

use std::fs;
use std::path::Path;

use common::{run, run_ok, scene_example};
use tempfile::TempDir;

/// A pinhole at [0, 2, 6] over a box of size 2 at the origin.
const PINHOLE: &str = r#"
[image]
width = 64
height = 48

[projection]
type = "perspective"
position = [0.0, 2.0, 6.0]
look_at = [0.0, 0.0, 0.0]
fov = 60.0

[[object]]
name = "box"
shape = "box"
size = [2.0, 2.0, 2.0]
color = [0.8, 0.8, 0.8]
"#;

/// The OBJ's objects: name, vertices (the file's, numbered from 1 across objects) and the
/// `l` segments of that object as vertex pairs.
struct Obj {
    vertices: Vec<[f64; 3]>,
    objects: Vec<(String, Vec<[usize; 2]>, usize)>,
}

fn read_obj(path: &Path) -> Obj {
    let text = fs::read_to_string(path).unwrap();
    let mut obj = Obj {
        vertices: Vec::new(),
        objects: Vec::new(),
    };
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"o") => obj.objects.push((words[1].to_string(), Vec::new(), 0)),
            Some(&"v") => obj
                .vertices
                .push([1, 2, 3].map(|k| words[k].parse::<f64>().unwrap())),
            Some(&"l") => {
                let pair = [1, 2].map(|k| words[k].parse::<usize>().unwrap());
                obj.objects.last_mut().unwrap().1.push(pair);
            }
            Some(&"f") => obj.objects.last_mut().unwrap().2 += 1,
            _ => {}
        }
    }
    obj
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// A flexible preset whose near surface is the eye (the twist, clip from 0): the far surface
/// as a mesh, the near one reported as a point and left out, 7 x 7 projectors and the image
/// grid as `l` lines, each part with its material in the MTL written beside the OBJ.
#[test]
fn a_flexible_volume_is_written_with_its_materials() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("flexible-twist.toml");
    let out = run_ok(&dir, &["volume", &scene, "-o", "twist.obj"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("near_surface: no area (a point or a line), not written"),
        "{stdout}"
    );
    assert!(
        stdout.contains("far_surface: 289 vertices, 512 triangles, 0 lines"),
        "{stdout}"
    );
    assert!(
        stdout.contains("projectors: 98 vertices, 0 triangles, 49 lines"),
        "{stdout}"
    );
    let obj = read_obj(&dir.path().join("twist.obj"));
    let names: Vec<&str> = obj.objects.iter().map(|o| o.0.as_str()).collect();
    assert_eq!(names, ["far_surface", "projectors", "image_grid"]);
    // The projectors start at the eye [0, 5.5, 7] (the twist's near clip is 0).
    for &[a, _] in &obj.objects[1].1 {
        assert!(distance(obj.vertices[a - 1], [0.0, 5.5, 7.0]) < 1e-9);
    }
    let text = fs::read_to_string(dir.path().join("twist.obj")).unwrap();
    assert!(text.contains("mtllib twist.mtl\n"), "{text:.200}");
    let mtl = fs::read_to_string(dir.path().join("twist.mtl")).unwrap();
    for name in names {
        assert!(mtl.contains(&format!("newmtl {name}\nKd ")), "{mtl}");
    }
}

/// A pinhole has no control surfaces: its projectors run from its eye to the farthest corner
/// of the box around the scene's objects (or --reach), and the image grid lies on the sphere
/// at 1/5 of that.
#[test]
fn a_pinhole_is_drawn_as_rays_from_its_eye() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("pinhole.toml"), PINHOLE).unwrap();
    run_ok(
        &dir,
        &["volume", "pinhole.toml", "-o", "v.obj", "--projectors", "3"],
    );
    let obj = read_obj(&dir.path().join("v.obj"));
    let names: Vec<&str> = obj.objects.iter().map(|o| o.0.as_str()).collect();
    assert_eq!(names, ["projectors", "image_grid"]);
    let eye = [0.0, 2.0, 6.0];
    // The box's farthest corner from the eye: (+-1, -1, -1), sqrt(59) away.
    let reach = 59f64.sqrt();
    assert_eq!(obj.objects[0].1.len(), 9);
    for &[a, b] in &obj.objects[0].1 {
        assert!(distance(obj.vertices[a - 1], eye) < 1e-9);
        assert!((distance(obj.vertices[b - 1], eye) - reach).abs() < 1e-9);
    }
    for &[a, _] in &obj.objects[1].1 {
        assert!((distance(obj.vertices[a - 1], eye) - reach / 5.0).abs() < 1e-9);
    }
    let args = ["volume", "pinhole.toml", "-o", "r.obj", "--reach", "2.5"];
    run_ok(&dir, &args);
    let obj = read_obj(&dir.path().join("r.obj"));
    for &[a, b] in &obj.objects[0].1 {
        assert!((distance(obj.vertices[b - 1], obj.vertices[a - 1]) - 2.5).abs() < 1e-9);
    }
}

/// Neither the OBJ nor the MTL beside it may be a file the scene was read from (the scene,
/// a model, its material library); bad options are one line; nothing is written.
#[test]
fn inputs_are_never_overwritten_and_bad_options_refused() {
    let dir = TempDir::new().unwrap();
    let model = "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
    fs::write(dir.path().join("m.obj"), model).unwrap();
    fs::write(dir.path().join("x.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let scene =
        format!("{PINHOLE}\n[[object]]\nname = \"model\"\nshape = \"mesh\"\nfile = \"m.obj\"\n");
    fs::write(dir.path().join("s.toml"), scene).unwrap();
    run_ok(&dir, &["render", "s.toml", "-o", "check.png"]);
    let before: Vec<Vec<u8>> = ["m.obj", "x.mtl", "s.toml"]
        .iter()
        .map(|f| fs::read(dir.path().join(f)).unwrap())
        .collect();
    for (output, needle) in [
        ("m.obj", "model file"),
        ("x.obj", "material library"),
        ("v.png", "extension"),
    ] {
        let out = run(&dir, &["volume", "s.toml", "-o", output]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{output}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(needle), "{output}: {stderr}");
    }
    let after: Vec<Vec<u8>> = ["m.obj", "x.mtl", "s.toml"]
        .iter()
        .map(|f| fs::read(dir.path().join(f)).unwrap())
        .collect();
    assert_eq!(before, after);
    for args in [
        &["--grid-at", "1.5"][..],
        &["--reach", "0"],
        &["--tube-radius", "-1"],
    ] {
        let out = run(
            &dir,
            &[&["volume", "s.toml", "-o", "bad.obj"], args].concat(),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!dir.path().join("bad.obj").exists());
        assert!(!dir.path().join("bad.mtl").exists());
    }
    let out = run(
        &dir,
        &["volume", "s.toml", "-o", "bad.obj", "--projectors", "0"],
    );
    assert_eq!(out.status.code(), Some(2));
}

/// With --tube-radius the lines are triangles: the OBJ loads as a model beside the scene's
/// objects and renders, its projectors red and unlit (the MTL's `Ke`).
#[test]
fn the_tube_form_renders_beside_the_scene() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("pinhole.toml"), PINHOLE).unwrap();
    let args = [
        "volume",
        "pinhole.toml",
        "-o",
        "v.obj",
        "--tube-radius",
        "0.08",
    ];
    run_ok(&dir, &args);
    let obj = read_obj(&dir.path().join("v.obj"));
    assert!(obj.objects.iter().all(|o| o.1.is_empty() && o.2 > 0));
    let side = PINHOLE
        .replace("position = [0.0, 2.0, 6.0]", "position = [12.0, 4.0, 3.0]")
        .replace("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 1.0, 3.0]")
        + "\n[[object]]\nname = \"volume\"\nshape = \"mesh\"\nfile = \"v.obj\"\n";
    fs::write(dir.path().join("side.toml"), side).unwrap();
    run_ok(
        &dir,
        &["render", "side.toml", "-o", "side.png", "--width", "160"],
    );
    let image = image::open(dir.path().join("side.png")).unwrap().to_rgb8();
    let red = image
        .pixels()
        .filter(|p| p[0] > 180 && p[1] < 110 && p[2] < 110)
        .count();
    assert!(red > 40, "{red} red pixels");
}
