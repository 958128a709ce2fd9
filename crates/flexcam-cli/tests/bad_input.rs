//! The bad-input catalogue (docs/bad-input.md) through the binary: one case of each class,
//! each asserting the exact outcome: the exit status, the one line on stderr (naming the
//! file, and where in it), and that no output was written. Never a panic, an abort, a hang
//! or a silent acceptance.

use std::fs;
use std::path::Path;

use tempfile::TempDir;

mod common;

use common::run;

/// A camera table and nothing else.
const CAMERA: &str = "[image]\nwidth = 8\nheight = 6\n\n[projection]\ntype = \"perspective\"\n\
                      position = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov = 60\n";

/// Runs `flexcam ARGS` in `dir` and asserts that it fails with `status` and exactly the
/// line `expected` on stderr, and writes no `out.png`.
fn refused(dir: &TempDir, args: &[&str], status: i32, expected: &str) {
    let out = run(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(status), "{args:?}: {stderr}");
    assert_eq!(stderr, format!("{expected}\n"), "{args:?}");
    assert!(
        !dir.path().join("out.png").exists(),
        "{args:?} wrote out.png"
    );
}

/// Writes `text` to `name` in `dir`.
fn write(dir: &TempDir, name: &str, text: impl AsRef<[u8]>) {
    fs::write(dir.path().join(name), text).unwrap();
}

/// `scene.toml` with `body` after the camera; renders it expecting `expected`.
fn scene_refused(dir: &TempDir, body: &str, expected: &str) {
    write(dir, "scene.toml", format!("{CAMERA}{body}"));
    refused(dir, &["render", "scene.toml", "-o", "out.png"], 1, expected);
}

/// A one-triangle glTF (`m.gltf`, buffer `m.bin`: positions, normals, texture coordinates,
/// u16 indices) with `edit` applied to its JSON, and a scene showing it.
fn gltf_scene(dir: &TempDir, edit: impl Fn(&str) -> String) {
    let floats: Vec<f32> = [
        [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].as_slice(),
        &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
    ]
    .concat();
    let mut bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    write(dir, "m.bin", &bin);
    let json = r#"{"asset": {"version": "2.0"},
        "buffers": [{"uri": "m.bin", "byteLength": 104}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 72, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 8}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1,
                                                   "TEXCOORD_0": 2}, "indices": 3}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]}"#;
    let edited = edit(json);
    write(dir, "m.gltf", edited);
    write(
        dir,
        "scene.toml",
        format!("{CAMERA}[[object]]\nshape = \"mesh\"\nfile = \"m.gltf\"\n"),
    );
}

fn gltf_refused(dir: &TempDir, edit: impl Fn(&str) -> String, expected: &str) {
    gltf_scene(dir, edit);
    let line = format!("flexcam: m.gltf: {expected}");
    refused(dir, &["render", "scene.toml", "-o", "out.png"], 1, &line);
}

#[test]
fn the_test_gltf_itself_renders() {
    let dir = TempDir::new().unwrap();
    gltf_scene(&dir, str::to_string);
    let out = run(&dir, &["render", "scene.toml", "-o", "out.png"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Class 1: accessor types the gltf crate meets with `unreachable!()`.
#[test]
fn gltf_accessors_of_the_wrong_type_are_errors_not_panics() {
    let dir = TempDir::new().unwrap();
    let indices = "\"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\"";
    let uvs = "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC2\"";
    for (from, to, expected) in [
        (
            indices,
            "\"componentType\": 5126, \"count\": 3, \"type\": \"SCALAR\"",
            "accessor 3 (indices) is F32 Scalar; glTF 2.0 allows u8, u16 or u32 SCALAR",
        ),
        (
            indices,
            "\"componentType\": 5122, \"count\": 3, \"type\": \"SCALAR\"",
            "accessor 3 (indices) is I16 Scalar; glTF 2.0 allows u8, u16 or u32 SCALAR",
        ),
        (
            uvs,
            "\"componentType\": 5120, \"count\": 3, \"type\": \"VEC2\"",
            "accessor 2 (TEXCOORD_0) is I8 Vec2; glTF 2.0 allows VEC2 of f32, or of normalized \
             u8 or u16",
        ),
        (
            "\"TEXCOORD_0\": 2",
            "\"COLOR_0\": 2",
            "accessor 2 (COLOR_0) is F32 Vec2; glTF 2.0 allows VEC3 or VEC4 of f32, or of \
             normalized u8 or u16",
        ),
    ] {
        gltf_refused(
            &dir,
            |j| j.replacen(from, to, 1),
            &format!("mesh 0 primitive 0: {expected}"),
        );
    }
}

/// Class 1, found by fuzzing: a short MTL colour (tobj unwraps three values) and a glTF
/// image in a buffer view without a MIME type (the gltf crate unwraps it).
#[test]
fn fuzzed_panics_are_errors() {
    let dir = TempDir::new().unwrap();
    write(
        &dir,
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    );
    write(&dir, "m.mtl", "newmtl a\nKd 0.8 0.1\n");
    scene_refused(
        &dir,
        "[[object]]\nshape = \"mesh\"\nfile = \"m.obj\"\n",
        "flexcam: m.mtl:2:1: `Kd` needs three values (r g b), not 2",
    );
    gltf_refused(
        &dir,
        |j| {
            j.replacen(
                "\"nodes\":",
                "\"images\": [{\"bufferView\": 0}],\n\"nodes\":",
                1,
            )
        },
        "image 0 has a bufferView but no mimeType",
    );
}

/// Class 2: counts from a file are bounded, and so is the memory a scene may take.
#[test]
fn unbounded_counts_and_memory_are_refused_before_allocating() {
    let dir = TempDir::new().unwrap();
    let surfaces = (0..3)
        .map(|k| {
            format!(
                "{{ surface = \"rectangle\", center = [0, 0, {}], u_axis = [{}, 0, 0], \
                 v_axis = [0, {}, 0] }}",
                [-1, -3, -2][k],
                k + 1,
                k + 1
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let bezier = format!(
        "[image]\nwidth = 8\nheight = 6\n[projection]\ntype = \"flexible\"\n\
         surfaces = [{surfaces}]\nblend = \"bezier\"\n"
    );
    write(
        &dir,
        "bezier.toml",
        format!("{bezier}segments = 4294967295\n"),
    );
    refused(
        &dir,
        &["render", "bezier.toml", "-o", "out.png"],
        1,
        "flexcam: bezier.toml:8:12: `segments` must be at most 4096, not 4294967295",
    );
    // Without `segments` it renders, but not by the raster method: its middle plane lies
    // beyond the far one (class 5: the message names the scene file).
    write(&dir, "bezier.toml", bezier);
    refused(
        &dir,
        &[
            "render",
            "bezier.toml",
            "--method",
            "raster",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: bezier.toml: method raster needs a projection with an analytic inverse; \
         flexible has none: its quadratic (Bezier) projectors run through control surfaces \
         whose middle plane does not lie strictly between the near and far planes, outside \
         the scanline class of curved projectors (three flat surfaces in parallel planes, the \
         middle one strictly between the others) (use --method raycast)",
    );

    // A 20-byte GLB whose header claims 4 GiB; one whose header claims fewer bytes than the
    // header (found by fuzzing: the gltf crate's length arithmetic underflowed).
    for (file, claimed, message) in [
        (
            "huge.glb",
            u32::MAX,
            "its header claims 4294967295 bytes, the file holds 20",
        ),
        (
            "short.glb",
            0,
            "its header claims 0 bytes, less than the header's own 12",
        ),
    ] {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(claimed.to_le_bytes());
        glb.extend([0u8; 8]);
        write(&dir, file, &glb);
        scene_refused(
            &dir,
            &format!("[[object]]\nshape = \"mesh\"\nfile = \"{file}\"\n"),
            &format!("flexcam: {file}: malformed GLB: {message}"),
        );
    }

    // Ten teapots at the largest tessellation, against a budget of 1 GB.
    let teapots = "[[object]]\nshape = \"teapot\"\ntessellation = 1024\n".repeat(10);
    write(&dir, "teapots.toml", format!("{CAMERA}{teapots}"));
    refused(
        &dir,
        &[
            "render",
            "teapots.toml",
            "--max-memory",
            "1G",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: teapots.toml:15:16: needs about 1.8 GB of memory (8388608 triangles), more \
         than the memory budget of 1.0 GB (--max-memory changes it)",
    );
    // Textures and photos count from their headers, before they are decoded.
    image::RgbImage::new(64, 64)
        .save(dir.path().join("photo.png"))
        .unwrap();
    refused(
        &dir,
        &[
            "reproject",
            "--input",
            "photo.png",
            "--max-memory",
            "100k",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: photo.png: needs about 131.1 kB of memory (a 64 x 64 image), more than the \
         memory budget of 100.0 kB (--max-memory changes it)",
    );
    let textured = "[[object]]\nshape = \"sphere\"\ntexture = \"photo.png\"\n";
    write(&dir, "textured.toml", format!("{CAMERA}{textured}"));
    refused(
        &dir,
        &[
            "render",
            "textured.toml",
            "--max-memory",
            "100k",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: photo.png: needs about 131.1 kB of memory (a 64 x 64 image), more than the \
         memory budget of 100.0 kB (--max-memory changes it)",
    );
    // The image counts too.
    refused(
        &dir,
        &[
            "render",
            "builtin:cube-floor",
            "--max-memory",
            "100M",
            "--width",
            "4000",
            "--height",
            "4000",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: builtin:cube-floor: needs about 1.0 GB of memory (686 triangles, a 4000 x \
         4000 image), more than the memory budget of 100.0 MB (--max-memory changes it)",
    );
}

/// Class 3: files that never end or block on opening.
#[test]
fn fifos_devices_and_folders_are_refused_without_reading() {
    let dir = TempDir::new().unwrap();
    refused(
        &dir,
        &["render", "/dev/zero", "-o", "out.png"],
        1,
        "flexcam: /dev/zero: scene file is not a regular file (a FIFO, socket or device)",
    );
    fs::create_dir(dir.path().join("folder.toml")).unwrap();
    refused(
        &dir,
        &["render", "folder.toml", "-o", "out.png"],
        1,
        "flexcam: folder.toml: scene file is a folder",
    );
    let fifo = dir.path().join("fifo.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    refused(
        &dir,
        &["render", "fifo.toml", "-o", "out.png"],
        1,
        "flexcam: fifo.toml: scene file is not a regular file (a FIFO, socket or device)",
    );
    std::process::Command::new("mkfifo")
        .arg(dir.path().join("photo.png"))
        .status()
        .unwrap();
    refused(
        &dir,
        &["reproject", "--input", "photo.png", "-o", "out.png"],
        1,
        "flexcam: photo.png: image is not a regular file (a FIFO, socket or device)",
    );
}

/// Class 4: values that used to be read as something else.
#[test]
fn nonsense_is_refused_at_its_place_not_accepted() {
    let dir = TempDir::new().unwrap();
    write(
        &dir,
        "scene.toml",
        CAMERA.replace("[0, 0, 3]", "[0, 0, 3, \"x\"]"),
    );
    refused(
        &dir,
        &["render", "scene.toml", "-o", "out.png"],
        1,
        "flexcam: scene.toml:7:12: invalid length 4, expected an array of length 3",
    );
    scene_refused(
        &dir,
        "[[object]]\nshape = \"sphere\"\ncolor = [0.8, 0.8, 0.8, 7]\n",
        "flexcam: scene.toml:12:9: invalid length 4, expected an array of length 3",
    );
    let huge = format!(
        "[image]\nbackground = [{}]\n",
        vec!["0"; 1_000_000].join(",")
    );
    write(&dir, "huge.toml", huge);
    refused(
        &dir,
        &["render", "huge.toml", "-o", "out.png"],
        1,
        "flexcam: huge.toml:2:14: invalid length 1000000, expected an array of length 3",
    );

    // Models: a face naming texture coordinates the file lacks, a NaN colour, PLY 2.0.
    write(
        &dir,
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n",
    );
    write(&dir, "m.mtl", "newmtl a\nKd 0.5 0.5 0.5\n");
    scene_refused(
        &dir,
        "[[object]]\nshape = \"mesh\"\nfile = \"m.obj\"\n",
        "flexcam: m.obj:5:1: face vertex `1/1` refers to texture coordinate 1, but the file \
         has 0 `vt` line(s)",
    );
    write(
        &dir,
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    );
    write(&dir, "m.mtl", "newmtl a\nKd 0.5 nan 0.5\n");
    scene_refused(
        &dir,
        "[[object]]\nshape = \"mesh\"\nfile = \"m.obj\"\n",
        "flexcam: m.mtl:2:1: `Kd` value nan is not a finite number",
    );
    write(
        &dir,
        "m.ply",
        "ply\nformat ascii 2.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
         end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    scene_refused(
        &dir,
        "[[object]]\nshape = \"mesh\"\nfile = \"m.ply\"\n",
        "flexcam: m.ply:2:14: PLY version \"2.0\" is not supported (only 1.0)",
    );

    // glTF: attribute shapes, node transforms and the version.
    let positions = "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\",\n";
    let u16_positions = positions.replace("5126", "5123");
    let vec2_positions = positions.replace("VEC3", "VEC2");
    for (from, to, expected) in [
        (
            positions,
            u16_positions.as_str(),
            "mesh 0 primitive 0: accessor 0 (POSITION) is U16 Vec3; glTF 2.0 allows f32 VEC3",
        ),
        (
            positions,
            &vec2_positions,
            "mesh 0 primitive 0: accessor 0 (POSITION) is F32 Vec2; glTF 2.0 allows f32 VEC3",
        ),
        (
            "\"NORMAL\": 1",
            "\"NORMAL\": 2",
            "mesh 0 primitive 0: accessor 2 (NORMAL) is F32 Vec2; glTF 2.0 allows f32 VEC3",
        ),
        (
            "{\"mesh\": 0}",
            "{\"mesh\": 0, \"scale\": [1e39, 1, 1]}",
            "node 0: transform has a value that is not finite in single precision",
        ),
        (
            "{\"mesh\": 0}",
            "{\"mesh\": 0, \"scale\": [1, 0, 1]}",
            "node 0: transform is singular (it flattens its meshes)",
        ),
        (
            "\"2.0\"",
            "\"1.0\"",
            "asset.version \"1.0\" is not supported (glTF 2.x only)",
        ),
    ] {
        gltf_refused(&dir, |j| j.replacen(from, to, 1), expected);
    }
}

/// Class 5: messages that did not say which argument or file.
#[test]
fn messages_name_the_argument_and_the_file() {
    let dir = TempDir::new().unwrap();
    refused(
        &dir,
        &["reproject", "-o", "out.png"],
        2,
        "flexcam: the following required arguments were not provided: --input <PHOTO>",
    );
    refused(
        &dir,
        &["render", "--width", "-1", "-o", "out.png"],
        2,
        "flexcam: invalid value '-1' for '--width <WIDTH>': -1 is not in 0..=4294967295",
    );
    gltf_refused(
        &dir,
        |j| j.replacen("\"uri\": \"m.bin\"", "\"uri\": \"gone.bin\"", 1),
        "buffer 0: \"gone.bin\" is not a file (looked for gone.bin)",
    );
    // A NaN ray in a trilinear surface: at the OBJ's line, not the scene's table.
    write(
        &dir,
        "s.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 nan 1\n\
         f 1/1/1 2/2/1 3/3/2\n",
    );
    write(
        &dir,
        "trilinear.toml",
        "[projection]\ntype = \"trilinear\"\nsurface = \"s.obj\"\n",
    );
    refused(
        &dir,
        &["render", "trilinear.toml", "-o", "out.png"],
        1,
        "flexcam: s.obj:8:1: `vn` value nan is not a finite number",
    );
}

/// The scenes of this file reach the renderer only through files: no stray file is left.
#[test]
fn refusals_leave_no_output() {
    let dir = TempDir::new().unwrap();
    scene_refused(
        &dir,
        "[[object]]\nshape = \"mesh\"\nfile = \"m.gltf\"\n",
        "flexcam: scene.toml:12:8: model file \"m.gltf\" is not a file (looked for m.gltf)",
    );
    let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only scene.toml: {left:?}");
    assert!(Path::new(&dir.path().join("scene.toml")).exists());
}

/// A correspondence behind the eye (`scenes/flexible-projector-fit.toml` with the point of
/// its (0.5, 0.6) correspondence mirrored through the camera's position added at the same
/// image position): kept starts cannot reach it and refuse it by number; the central models
/// (eye, pinhole, and auto, which takes one of them) move the eye until the point is in
/// front (pinhole by the general camera matrix: no square-pixel camera keeps every point in
/// front), so the data are not fitted exactly: the fit says so by a residual of degrees
/// (`--stats`) and a warning; free starts, which may lie anywhere, fit it exactly by a node
/// starting behind the camera, and warn that the node left the prior by far. Never silently.
#[test]
fn a_correspondence_behind_the_eye_is_refused_or_shown_in_the_residual() {
    let dir = TempDir::new().unwrap();
    let example = fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/flexible-projector-fit.toml"),
    )
    .unwrap();
    let cube_centre = "    { uv = [0.5, 0.6], point = [0.0, 1.0, 0.0] },";
    assert!(example.contains(cube_centre));
    // The camera is at [0, 5.5, 7]: the cube's centre mirrored through it.
    let behind = format!("{cube_centre}\n    {{ uv = [0.5, 0.6], point = [0.0, 10.0, 14.0] }},");
    // The error names the `[projection]` table's line (the fit is that table's).
    let projection_line = 1 + example.lines().position(|l| l == "[projection]").unwrap();
    for starts in ["kept", "eye", "pinhole", "free", "auto"] {
        let scene = example.replace(cube_centre, &behind).replace(
            "interpolation = \"bilinear\"",
            &format!("interpolation = \"bilinear\"\nstarts = \"{starts}\""),
        );
        write(&dir, "scene.toml", &scene);
        let args = ["render", "scene.toml", "-o", "out.png", "--stats", "s.json"];
        if starts == "kept" {
            refused(
                &dir,
                &args,
                1,
                &format!(
                    "flexcam: scene.toml:{projection_line}:1: correspondence 6: no projector of \
                     the grid can reach [0, 10, 14] at [0.5, 0.6] (the fitted projector points \
                     away from it; the correspondences contradict each other)"
                ),
            );
            continue;
        }
        let out = run(&dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{starts}: {stderr}");
        assert!(
            stderr.contains("left the prior by far"),
            "{starts}: {stderr}"
        );
        if starts == "free" {
            fs::remove_file(dir.path().join("out.png")).unwrap();
            continue;
        }
        let stats = fs::read_to_string(dir.path().join("s.json")).unwrap();
        if starts == "pinhole" {
            // No square-pixel camera sees the point behind the eye in front: the general
            // camera matrix is fitted instead, and both the warning and the counter say so.
            assert!(stderr.contains("general camera matrix"), "{stderr}");
            assert!(stats.contains("\"fit_general_camera\":1"), "{stats}");
        }
        let max_angle: f64 = stats
            .split("\"fit_max_angle_deg\":")
            .nth(1)
            .and_then(|rest| rest.split([',', '}']).next())
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("{starts}: no fit_max_angle_deg in {stats}"));
        assert!(max_angle > 5.0, "{starts}: fitted to {max_angle} degrees");
        fs::remove_file(dir.path().join("out.png")).unwrap();
    }
}

#[test]
fn trilinear_surface_normals_are_refused_at_the_obj_line() {
    let dir = TempDir::new().unwrap();
    let obj = |normal: &str| {
        format!(
            "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nvn 0 0 -1\n{normal}\n\
             vn 0 0 -1\nf 1/1/1 2/2/2 3/3/3\n"
        )
    };
    let scene = "[image]\nwidth = 8\nheight = 6\n\n[projection]\ntype = \"trilinear\"\n\
                 surface = \"s.obj\"\n";
    write(&dir, "scene.toml", scene);
    for (normal, expected) in [
        (
            "vn nan 0 -1",
            "flexcam: s.obj:8:1: `vn` value nan is not a finite number",
        ),
        (
            "vn 0 0 0",
            "flexcam: s.obj:8:1: `vn` has zero length: every vertex of a trilinear surface \
             needs a ray direction",
        ),
    ] {
        write(&dir, "s.obj", obj(normal));
        refused(
            &dir,
            &["render", "scene.toml", "-o", "out.png"],
            1,
            expected,
        );
    }
}

/// The 1-based line and column of the first `needle` in `text`.
fn line_column(text: &str, needle: &str) -> (usize, usize) {
    let offset = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in {text}"));
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (before.matches('\n').count() + 1, offset - line_start + 1)
}

#[test]
fn flexible_maps_and_blends_are_refused_at_their_place() {
    let dir = TempDir::new().unwrap();
    let head = "[image]\nwidth = 8\nheight = 6\n\n[projection]\ntype = \"flexible\"\n";
    let perspective = "preset = \"perspective\"\nposition = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
                       fov = 60\n";
    let render = ["render", "scene.toml", "-o", "out.png"];
    // A grid map in a file: a folding cell at its first sample, a bad value at itself.
    write(
        &dir,
        "scene.toml",
        format!(
            "{head}{perspective}reparam = \"grid\"\n\
             reparam_grid = {{ size = [3, 2], file = \"g.txt\" }}\n"
        ),
    );
    write(&dir, "g.txt", "# u v\n0 0  0.4 0  1 0\n0 1  1.6 1  1 1\n");
    refused(
        &dir,
        &render,
        1,
        "flexcam: g.txt:2:6: uv grid cell (1, 0) (column, row from the bottom left) folds: \
         its map is not one-to-one there",
    );
    write(&dir, "g.txt", "# u v\n0 0  0.4 0  1 0\n0 1  x 1  1 1\n");
    refused(
        &dir,
        &render,
        1,
        "flexcam: g.txt:3:6: uv grid value `x` is not a finite number",
    );
    // The same fold inline: at the sample in the scene.
    let scene = format!(
        "{head}{perspective}reparam = \"grid\"\nreparam_grid = {{ size = [3, 2], \
         uv = [[0, 0], [0.4, 0], [1, 0], [0, 1], [1.6, 1], [1, 1]] }}\n"
    );
    write(&dir, "scene.toml", &scene);
    let (line, column) = line_column(&scene, "[0.4, 0]");
    refused(
        &dir,
        &render,
        1,
        &format!(
            "flexcam: scene.toml:{line}:{column}: uv grid cell (1, 0) (column, row from the \
             bottom left) folds: its map is not one-to-one there"
        ),
    );
    // A polar map on flat surfaces names both.
    let scene = format!(
        "{head}near = {{ surface = \"point\", point = [0, 0, 3] }}\n\
         far = {{ surface = \"rectangle\", center = [0, 0, -3], u_axis = [2, 0, 0], \
         v_axis = [0, 1.5, 0] }}\nreparam = \"polar\"\n"
    );
    write(&dir, "scene.toml", &scene);
    let (line, column) = line_column(&scene, "\"polar\"");
    refused(
        &dir,
        &render,
        1,
        &format!(
            "flexcam: scene.toml:{line}:{column}: reparam \"polar\" does not go with flat \
             control surfaces (point, rectangle): it reads v as the angle off a fisheye's axis \
             and u as the azimuth, which needs a sphere or hemisphere among them (use reparam \
             = \"linear\" or \"grid\")"
        ),
    );
    // A static blend: a weight that is not a number, a part that is not flexible.
    let blend = |weight: &str, second_type: &str| {
        format!(
            "{head}[projection.interpolate]\nweight = {weight}\n\
             [projection.interpolate.first]\ntype = \"flexible\"\n{perspective}\
             [projection.interpolate.second]\ntype = \"{second_type}\"\n\
             position = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov = 180\n{}",
            if second_type == "flexible" {
                "preset = \"fisheye\"\n"
            } else {
                ""
            }
        )
    };
    let scene = blend("nan", "flexible");
    write(&dir, "scene.toml", &scene);
    let (line, column) = line_column(&scene, "nan");
    refused(
        &dir,
        &render,
        1,
        &format!("flexcam: scene.toml:{line}:{column}: `weight` must be a finite number, not NaN"),
    );
    let scene = blend("0.5", "fisheye");
    write(&dir, "scene.toml", &scene);
    let (line, column) = line_column(&scene, "\"fisheye\"");
    refused(
        &dir,
        &render,
        1,
        &format!(
            "flexcam: scene.toml:{line}:{column}: `interpolate`'s `first` and `second` need \
             type = \"flexible\" (only flexible volumes can be interpolated), not \"fisheye\""
        ),
    );
    // The blend itself renders, by raycast; raster names the reason it cannot.
    write(&dir, "scene.toml", blend("0.5", "flexible"));
    refused(
        &dir,
        &[
            "render",
            "scene.toml",
            "--method",
            "raster",
            "-o",
            "out.png",
        ],
        1,
        "flexcam: scene.toml: method raster needs a projection with an analytic inverse; \
         flexible has none: it interpolates volumes on different re-parameterisations, with no \
         closed-form inverse (use --method raycast)",
    );
    let out = run(&dir, &render);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
