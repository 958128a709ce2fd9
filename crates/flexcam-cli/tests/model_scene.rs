//! A model file given where a scene is expected: the framing camera, the model's glTF
//! cameras (and `import-cameras` of them), the overrides, and the refusals.

mod common;

use std::path::Path;

use common::{run, run_ok};
use tempfile::TempDir;

/// The object ids of a `--ids` PNG: width, height and ids row by row.
fn ids(path: &Path) -> (u32, u32, Vec<u16>) {
    let image = image::open(path).unwrap().to_luma16();
    let (w, h) = image.dimensions();
    (w, h, image.into_raw())
}

/// The pixel bounding box (x0, y0, x1, y1, inclusive) of the non-zero ids, and their count.
fn covered(path: &Path) -> ([u32; 4], usize) {
    let (w, h, ids) = ids(path);
    let mut bounds = [u32::MAX, u32::MAX, 0, 0];
    let mut count = 0;
    for y in 0..h {
        for x in 0..w {
            if ids[(y * w + x) as usize] != 0 {
                bounds = [
                    bounds[0].min(x),
                    bounds[1].min(y),
                    bounds[2].max(x),
                    bounds[3].max(y),
                ];
                count += 1;
            }
        }
    }
    (bounds, count)
}

/// Renders `args` (a scene and its flags) with flat shading to `OUT.png`, ids to
/// `OUT-ids.png`.
fn render_flat(dir: &TempDir, args: &[&str], out: &str) {
    let (png, ids) = (format!("{out}.png"), format!("{out}-ids.png"));
    let mut all = vec!["render", "--shading", "flat", "-o", &png, "--ids", &ids];
    all.extend_from_slice(args);
    run_ok(dir, &all);
}

/// Fails unless files `a` and `b` of `dir` hold the same bytes.
fn assert_same_files(dir: &TempDir, a: &str, b: &str) {
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert!(read(a) == read(b), "{a} and {b} differ");
}

/// An octahedron of half-diagonal `s` round `c`, as OBJ text.
fn octahedron(c: [f64; 3], s: f64) -> String {
    let mut text = String::new();
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            let mut p = c;
            p[axis] += sign * s;
            text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
    }
    // Vertices: 1 +x, 2 -x, 3 +y, 4 -y, 5 +z, 6 -z.
    for (a, b, c) in [
        (1, 3, 5),
        (5, 3, 2),
        (2, 3, 6),
        (6, 3, 1),
        (5, 4, 1),
        (2, 4, 5),
        (6, 4, 2),
        (1, 4, 6),
    ] {
        text += &format!("f {a} {b} {c}\n");
    }
    text
}

/// The framing rule written out independently: a 50-degree horizontal pinhole looking at
/// the bounding box's centre from azimuth 45, elevation 30 degrees, at 1.1 times the
/// distance where the bounding sphere touches the narrower side. Returns the pixel position
/// (x right, y down) of `p` in a `w` x `h` image.
fn framed_pixel(lo: [f64; 3], hi: [f64; 3], w: f64, h: f64, p: [f64; 3]) -> (f64, f64) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let centre = [0, 1, 2].map(|i| (lo[i] + hi[i]) / 2.0);
    let radius = dot(sub(hi, lo), sub(hi, lo)).sqrt() / 2.0;
    let half_w = 25f64.to_radians();
    let half_h = (half_w.tan() * h / w).atan();
    let distance = 1.1 * radius / half_w.min(half_h).sin();
    let (az, el) = (45f64.to_radians(), 30f64.to_radians());
    let back = [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()];
    // Camera axes: right = world up x back, normalised; up = back x right.
    let right = [back[2], 0.0, -back[0]].map(|v| v / (back[0].powi(2) + back[2].powi(2)).sqrt());
    let up = [
        back[1] * right[2] - back[2] * right[1],
        back[2] * right[0] - back[0] * right[2],
        back[0] * right[1] - back[1] * right[0],
    ];
    let eye = [0, 1, 2].map(|i| centre[i] + distance * back[i]);
    let d = sub(p, eye);
    let depth = -dot(d, back);
    let focal = (w / 2.0) / half_w.tan();
    (
        w / 2.0 + focal * dot(d, right) / depth,
        h / 2.0 - focal * dot(d, up) / depth,
    )
}

/// An OBJ given as the scene is framed by the stated rule: its pixels' bounding box is the
/// box of its vertices' images (to a pixel), centred, and it covers a fair part of the
/// image, at the default size and at another aspect ratio.
#[test]
fn an_obj_renders_framed_and_centred() {
    let dir = TempDir::new().unwrap();
    let (c, s) = ([1.0, 2.0, -3.0], 0.5);
    std::fs::write(dir.path().join("octa.obj"), octahedron(c, s)).unwrap();
    for (size, w, h) in [
        (&[][..], 800.0, 600.0),
        (&["--width", "300", "--height", "400"][..], 300.0, 400.0),
    ] {
        let mut args = vec!["render", "octa.obj", "-o", "o.png", "--ids", "ids.png"];
        args.extend_from_slice(size);
        run_ok(&dir, &args);
        let (bounds, count) = covered(&dir.path().join("ids.png"));
        let (lo, hi) = (c.map(|v| v - s), c.map(|v| v + s));
        let vertices = (0..6).map(|k| {
            let mut p = c;
            p[k / 2] += if k % 2 == 0 { s } else { -s };
            framed_pixel(lo, hi, w, h, p)
        });
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for (x, y) in vertices {
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        let expected = [x0, y0, x1 - 1.0, y1 - 1.0];
        for (got, want) in bounds.iter().zip(expected) {
            assert!(
                (f64::from(*got) - want).abs() <= 1.0,
                "{bounds:?} vs {expected:?}"
            );
        }
        let centre_x = f64::from(bounds[0] + bounds[2] + 1) / 2.0;
        let centre_y = f64::from(bounds[1] + bounds[3] + 1) / 2.0;
        assert!((centre_x - w / 2.0).abs() <= 1.0, "{centre_x}");
        assert!((centre_y - h / 2.0).abs() <= 0.03 * h, "{centre_y}");
        let fraction = count as f64 / (w * h);
        assert!(fraction > 0.05, "{fraction}");
    }
}

/// A glTF model: a 2 x 1 quad in the plane z = 0 round the origin, and three cameras:
/// 0 "Front", perspective at (0, 0, 5) with tan(yfov / 2) = 1/5 and aspectRatio 2 (so the
/// view at z = 0 is 4 x 2); 1 "Ortho", orthographic xmag 2, ymag 1, at (0, 0, 3); 2, with
/// no aspectRatio, behind the quad at (0.5, 1, -4) turned 180 degrees about y, placed by
/// node "Back" under a parent that moves it by (0, 0, 0) and 1 along x back again.
fn quad_with_cameras(dir: &TempDir, name: &str, yfov: f64) {
    let positions: [[f32; 3]; 6] = [
        [-1.0, -0.5, 0.0],
        [1.0, -0.5, 0.0],
        [1.0, 0.5, 0.0],
        [-1.0, -0.5, 0.0],
        [1.0, 0.5, 0.0],
        [-1.0, 0.5, 0.0],
    ];
    let bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.path().join("quad.bin"), &bytes).unwrap();
    let gltf = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2, 3]}}],
  "nodes": [
    {{"mesh": 0}},
    {{"camera": 0, "name": "FrontNode", "translation": [0, 0, 5]}},
    {{"camera": 1, "translation": [0, 0, 3]}},
    {{"translation": [1, 0, 0], "children": [4]}},
    {{"camera": 2, "name": "Back", "translation": [-0.5, 1, -4], "rotation": [0, 1, 0, 0]}}
  ],
  "cameras": [
    {{"name": "Front", "type": "perspective",
      "perspective": {{"yfov": {yfov}, "aspectRatio": 2.0, "znear": 0.1}}}},
    {{"name": "Ortho", "type": "orthographic",
      "orthographic": {{"xmag": 2.0, "ymag": 1.0, "znear": 0.1, "zfar": 100}}}},
    {{"type": "perspective", "perspective": {{"yfov": 0.7, "znear": 0.01}}}}
  ],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "buffers": [{{"byteLength": 72, "uri": "quad.bin"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 72}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3",
                  "min": [-1, -0.5, 0], "max": [1, 0.5, 0]}}]
}}"#
    );
    std::fs::write(dir.path().join(name), gltf).unwrap();
}

/// tan(yfov / 2) = 1/5: the view at the quad's distance is 2 high.
fn front_yfov() -> f64 {
    2.0 * (0.2f64).atan()
}

/// yfov is the full vertical angle and aspectRatio widens it, xmag and ymag are half the
/// view: both cameras see the quad over exactly the middle half of each side.
#[test]
fn gltf_camera_conventions() {
    let dir = TempDir::new().unwrap();
    quad_with_cameras(&dir, "quad.gltf", front_yfov());
    // The first camera is the default; its aspect ratio gives the height.
    for camera in [
        &[][..],
        &["--camera", "Ortho"][..],
        &["--camera", "FrontNode"][..],
    ] {
        let mut args = vec!["render", "quad.gltf", "--width", "200", "-o", "o.png"];
        args.extend_from_slice(&["--ids", "ids.png"]);
        args.extend_from_slice(camera);
        run_ok(&dir, &args);
        let (w, h, _) = ids(&dir.path().join("ids.png"));
        assert_eq!((w, h), (200, 100), "{camera:?}");
        let (bounds, count) = covered(&dir.path().join("ids.png"));
        assert_eq!(bounds, [50, 25, 149, 74], "{camera:?}");
        assert_eq!(count, 100 * 50, "{camera:?}");
    }
}

/// The glTF camera's render is, byte for byte, the render of a scene file written by hand
/// with that camera (yfov 0.7 as written, not its f32 rounding): a camera without
/// aspectRatio keeps its yfov at the image's aspect ratio, placed by its node's transform composed with its parent's (looking down -Z
/// turned 180 degrees about y: along +z).
#[test]
fn a_gltf_camera_renders_as_the_equivalent_scene_file() {
    let dir = TempDir::new().unwrap();
    quad_with_cameras(&dir, "quad.gltf", front_yfov());
    let yfov = 0.7f64;
    let (w, h) = (320.0, 200.0);
    let fov = (2.0 * ((w / h) * (yfov / 2.0).tan()).atan()).to_degrees();
    let scene = format!(
        "[image]\nwidth = 320\nheight = 200\n\n[projection]\ntype = \"perspective\"\n\
         position = [0.5, 1.0, -4.0]\nlook_at = [0.5, 1.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         fov = {fov:?}\n\n[[object]]\nshape = \"mesh\"\nfile = \"quad.gltf\"\n"
    );
    std::fs::write(dir.path().join("by-hand.toml"), scene).unwrap();
    render_flat(&dir, &["by-hand.toml"], "a");
    let size = ["--width", "320", "--height", "200"];
    render_flat(
        &dir,
        &[&["quad.gltf", "--camera", "Back"][..], &size].concat(),
        "b",
    );
    assert_same_files(&dir, "a.png", "b.png");
    assert_same_files(&dir, "a-ids.png", "b-ids.png");
    let (_, count) = covered(&dir.path().join("b-ids.png"));
    assert!(count > 1000, "{count}");
}

/// `import-cameras` writes one table per glTF camera; a scene made of one of them and the
/// model renders what `--camera` renders.
#[test]
fn imported_gltf_cameras_render_as_the_model_does() {
    let dir = TempDir::new().unwrap();
    quad_with_cameras(&dir, "quad.gltf", front_yfov());
    let tables = String::from_utf8(run_ok(&dir, &["import-cameras", "quad.gltf"]).stdout).unwrap();
    for table in ["[camera_0]", "[camera_1]", "[camera_2]"] {
        assert!(tables.contains(table), "{tables}");
    }
    assert!(tables.contains("type = \"orthographic\"") && tables.contains("width = 4.0"));
    assert!(tables.contains("800 x 400 image"), "{tables}");
    let scene = format!(
        "[image]\nwidth = 800\nheight = 400\n\n{}\n[[object]]\nshape = \"mesh\"\nfile = \"quad.gltf\"\n",
        tables.replace("[camera_1]", "[projection]").replace("[camera_0]", "[unused_0]").replace("[camera_2]", "[unused_2]")
    );
    // The unused tables are not scene keys: keep only the projection.
    let projection: String = scene
        .split("\n[")
        .filter(|part| !part.starts_with("unused"))
        .collect::<Vec<_>>()
        .join("\n[");
    std::fs::write(dir.path().join("imported.toml"), projection).unwrap();
    render_flat(&dir, &["imported.toml"], "a");
    render_flat(&dir, &["quad.gltf", "--camera", "1"], "b");
    assert_same_files(&dir, "a-ids.png", "b-ids.png");
    assert_same_files(&dir, "a.png", "b.png");
}

/// Overrides still apply: `--width` alone keeps the aspect ratio, `-D` edits the default
/// scene (here the field of view and the projection type), and the object is `model`.
#[test]
fn overrides_apply_to_a_model() {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("octa.obj"), octahedron([0.0; 3], 1.0)).unwrap();
    let stats = |extra: &[&str]| {
        let mut args = vec![
            "render", "octa.obj", "-o", "o.png", "--ids", "ids.png", "--stats", "-",
        ];
        args.extend_from_slice(extra);
        let json: serde_json::Value = serde_json::from_slice(&run_ok(&dir, &args).stdout).unwrap();
        (json, covered(&dir.path().join("ids.png")).1)
    };
    let (json, base) = stats(&["--width", "200"]);
    assert_eq!(
        (json["width"].as_u64(), json["height"].as_u64()),
        (Some(200), Some(150))
    );
    let (_, narrower) = stats(&["--width", "200", "-D", "projection.fov=25"]);
    assert!(narrower > 2 * base, "{narrower} vs {base}");
    let (_, fisheye) = stats(&[
        "--width",
        "200",
        "-D",
        "projection.type=fisheye",
        "-D",
        "projection.fov=180",
    ]);
    assert!(fisheye > 0 && fisheye < base, "{fisheye} vs {base}");
    run_ok(
        &dir,
        &[
            "render",
            "octa.obj",
            "--width",
            "40",
            "-D",
            "object.model.color=[1,0,0]",
            "--shading",
            "flat",
            "-o",
            "red.png",
        ],
    );
    let red = image::open(dir.path().join("red.png")).unwrap().to_rgb8();
    assert_eq!(red.get_pixel(20, 15).0, [255, 0, 0]);
}

/// Runs a command that must fail with one line naming `names` and containing `says`, and
/// write nothing.
fn refused(dir: &TempDir, args: &[&str], names: &str, says: &str) {
    let out = run(dir, args);
    assert!(!out.status.success(), "{args:?} succeeded");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    assert!(
        stderr.contains(names) && stderr.contains(says),
        "{args:?}: {stderr}"
    );
    assert!(
        !dir.path().join("out.png").exists(),
        "{args:?} wrote its output"
    );
}

#[test]
fn refusals_are_one_line() {
    let dir = TempDir::new().unwrap();
    quad_with_cameras(&dir, "quad.gltf", front_yfov());
    std::fs::write(dir.path().join("octa.obj"), octahedron([0.0; 3], 1.0)).unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        dir.path().join("dot.obj"),
        "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n",
    )
    .unwrap();
    fn render<'a>(rest: &[&'a str]) -> Vec<&'a str> {
        [&["render"][..], rest, &["-o", "out.png"]].concat()
    }
    // The camera fixes 2:1; a square image would stretch it.
    refused(
        &dir,
        &render(&["quad.gltf", "--width", "400", "--height", "400"]),
        "quad.gltf",
        "camera 0 \"Front\" has aspectRatio 2, the image 400 x 400",
    );
    refused(
        &dir,
        &render(&["quad.gltf", "-D", "image.height=800"]),
        "quad.gltf",
        "aspectRatio 2",
    );
    refused(
        &dir,
        &render(&[
            "quad.gltf",
            "--camera",
            "Ortho",
            "--height",
            "10",
            "--width",
            "10",
        ]),
        "quad.gltf",
        "xmag / ymag 2",
    );
    refused(&dir, &render(&["quad.gltf", "--camera", "Side"]), "quad.gltf", "--camera Side: no camera of that index or name; the model's: camera 0 \"Front\", camera 1 \"Ortho\", camera 2 \"Back\"");
    refused(
        &dir,
        &render(&["octa.obj", "--camera", "0"]),
        "octa.obj",
        "places no camera",
    );
    std::fs::write(dir.path().join("s.toml"), "[projection]\ntype = \"perspective\"\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\nfov = 60.0\n").unwrap();
    refused(
        &dir,
        &render(&["s.toml", "--camera", "0"]),
        "s.toml",
        "is not a model file",
    );
    refused(&dir, &render(&["bad.obj"]), "bad.obj", "");
    refused(&dir, &render(&["dot.obj"]), "dot.obj", "nothing to frame");
    refused(
        &dir,
        &render(&["octa.obj", "-D", "projection.type=opencv"]),
        "octa.obj: default scene:",
        "",
    );
    refused(
        &dir,
        &render(&["octa.obj", "-D", "projection.fov=x"]),
        "octa.obj",
        "-D projection.fov=x",
    );
    quad_with_cameras(&dir, "flat.gltf", 0.0);
    refused(
        &dir,
        &render(&["flat.gltf"]),
        "flat.gltf",
        "camera 0 \"Front\": yfov 0 is not in (0, pi)",
    );
    let out = run(&dir, &["import-cameras", "octa.obj"]);
    assert!(!out.status.success());
    let out = run(&dir, &["import-cameras", "flat.gltf"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("flat.gltf") && stderr.contains("yfov 0"),
        "{stderr}"
    );
}

/// Animation needs an `[animation]` table, which a model's scene has not: said plainly.
#[test]
fn animating_a_model_says_it_has_no_animation() {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("octa.obj"), octahedron([0.0; 3], 1.0)).unwrap();
    refused(
        &dir,
        &["animate", "octa.obj", "--gif", "out.gif"],
        "octa.obj",
        "no [animation] table",
    );
}
