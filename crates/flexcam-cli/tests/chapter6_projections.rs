//! The chapter 6 projections of Brosz 2011 from the command line: the discontinuous
//! (`pieces`) examples raster like the ray caster, piece by piece; pieces that are the
//! halves of a perspective render that perspective's pixels; the NURBS example renders by
//! ray casting and the raster says why it cannot; bad pieces and bad NURBS surfaces are
//! refused with one line naming the file, the place and the pieces or keys at fault.

mod common;

use std::fs;

use common::{interior_agreement, raster_agrees, run, run_json, run_ok, scene_example};
use tempfile::TempDir;

/// `--method raster` against the ray caster on the piece examples (flat shading, interior
/// ids 99.99 %, relative RGB error below 0.002: `common::raster_agrees`): every piece is
/// drawn by its own inverse into its tile.
#[test]
fn piece_examples_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    for name in [
        "flexible-single-centre.toml",
        "flexible-collage.toml",
        "flexible-glc-mosaic.toml",
    ] {
        raster_agrees(&dir, &[&scene_example(name)]);
    }
}

const OBJECTS: &str = "\n[[object]]\nname = \"floor\"\nshape = \"plane\"\nsize = [8.0, 8.0]\n\
                       tessellation = 8\n\n[[object]]\nname = \"cube\"\nshape = \"box\"\n\
                       size = [2.0, 2.0, 2.0]\ntranslate = [0.0, 1.0, 0.0]\n\
                       rotate = [0.0, 30.0, 0.0]\n";

const FRAME: &str = "position = [1.0, 4.0, 6.0]\nlook_at = [0.0, 0.5, 0.0]\n";

/// A perspective of 70 degrees, and the same as two off-axis pieces, the halves of its
/// window (each 2 atan(tan 35 / 2) wide, shifted a half-width out), give the same ids at
/// every pixel by ray casting, and raster like it.
#[test]
fn off_axis_halves_render_the_perspective() {
    let dir = TempDir::new().unwrap();
    let image = "[image]\nwidth = 120\nheight = 90\n";
    fs::write(
        dir.path().join("whole.toml"),
        format!("{image}\n[projection]\ntype = \"perspective\"\n{FRAME}fov = 70.0\n{OBJECTS}"),
    )
    .unwrap();
    let half = 2.0 * (0.5 * 35f64.to_radians().tan()).atan().to_degrees();
    let piece = |rect: &str, shift: f64| {
        format!(
            "\n[[projection.pieces]]\nrect = {rect}\npreset = \"off_axis\"\n{FRAME}\
             fov = {half:?}\nshift = [{shift:?}, 0.0]\n"
        )
    };
    fs::write(
        dir.path().join("split.toml"),
        format!(
            "{image}\n[projection]\ntype = \"flexible\"\n{}{}{OBJECTS}",
            piece("[0.0, 0.0, 0.5, 1.0]", -1.0),
            piece("[0.5, 0.0, 1.0, 1.0]", 1.0)
        ),
    )
    .unwrap();
    for (scene, method) in [
        ("whole.toml", "raycast"),
        ("split.toml", "raycast"),
        ("split.toml", "raster"),
    ] {
        let ids = format!("{scene}-{method}-ids.png");
        run_ok(
            &dir,
            &[
                "render",
                scene,
                "--method",
                method,
                "--shading",
                "flat",
                "--ids",
                &ids,
                "-o",
                "out.png",
            ],
        );
    }
    let path = |name: &str| dir.path().join(name);
    let (w, h, whole) = common::ids(&path("whole.toml-raycast-ids.png"));
    let (_, _, split) = common::ids(&path("split.toml-raycast-ids.png"));
    let same = whole.iter().zip(&split).filter(|(a, b)| a == b).count();
    assert!(
        same as f64 >= 0.9995 * f64::from(w * h),
        "{same} of {} pixels",
        w * h
    );
    let (interior, pixels) = interior_agreement(
        &path("whole.toml-raycast-ids.png"),
        &path("split.toml-raster-ids.png"),
    );
    assert!(pixels > 5000, "{pixels}");
    assert!(
        interior >= 0.999,
        "raster of the pieces vs the perspective: {interior}"
    );
}

/// Runs `render scene.toml` with `text` as the scene and asserts exit status 1, exactly the
/// one line `expected` on stderr and no output.
fn refused(dir: &TempDir, text: &str, args: &[&str], expected: &str) {
    let stderr = common::refused_scene(dir, text, args);
    assert_eq!(stderr, format!("flexcam: {expected}\n"));
}

/// A flexible projection of `pieces` (the text after `type`), 40 x 30.
fn pieces_scene(pieces: &str) -> String {
    format!(
        "[image]\nwidth = 40\nheight = 30\n\n[projection]\ntype = \"flexible\"\n{pieces}{OBJECTS}"
    )
}

/// A perspective piece owning `rect`.
fn perspective_piece(rect: &str) -> String {
    format!("\n[[projection.pieces]]\nrect = {rect}\npreset = \"perspective\"\n{FRAME}fov = 50.0\n")
}

#[test]
fn bad_pieces_are_refused_at_their_place() {
    let dir = TempDir::new().unwrap();
    let two = |a: &str, b: &str| pieces_scene(&(perspective_piece(a) + &perspective_piece(b)));
    refused(
        &dir,
        &two("[0.0, 0.0, 0.6, 1.0]", "[0.5, 0.0, 1.0, 1.0]"),
        &[],
        "scene.toml:16:8: piece 2's rect [0.5, 0.0, 1.0, 1.0] overlaps piece 1's rect \
         [0.0, 0.0, 0.6, 1.0]: pieces may only touch",
    );
    refused(
        &dir,
        &two("[0.0, 0.0, 0.5, 1.0]", "[0.5, 0.0, 1.0, 1.2]"),
        &[],
        "scene.toml:16:8: piece 2: a piece's `rect` must be [u0, v0, u1, v1] with \
         0 <= u0 < u1 <= 1 and 0 <= v0 < v1 <= 1, got [0.5, 0.0, 1.0, 1.2]",
    );
    refused(
        &dir,
        &pieces_scene("pieces = []\n"),
        &[],
        "scene.toml:7:10: `pieces` must hold 1 to 64 pieces, got 0",
    );
    let many = format!(
        "pieces = [{}]\n",
        vec!["{ rect = [0.0, 0.0, 1.0, 1.0] }"; 65].join(", ")
    );
    refused(
        &dir,
        &pieces_scene(&many),
        &[],
        "scene.toml:7:10: `pieces` must hold 1 to 64 pieces, got 65",
    );
    refused(
        &dir,
        &pieces_scene("pieces = [{ preset = \"perspective\", fov = 50.0 }]\n"),
        &[],
        "scene.toml:7:11: piece 1 needs `rect = [u0, v0, u1, v1]`, the image rectangle it owns",
    );
    refused(
        &dir,
        &pieces_scene("pieces = [{ type = \"perspective\", rect = [0.0, 0.0, 1.0, 1.0] }]\n"),
        &[],
        "scene.toml:7:20: piece 1 is a flexible projection: leave out `type` or write \
         type = \"flexible\", not \"perspective\"",
    );
    refused(
        &dir,
        &pieces_scene(
            "pieces = [{ rect = [0.0, 0.0, 1.0, 1.0], pieces = [{ rect = [0.0, 0.0, 1.0, 1.0] }] }]\n",
        ),
        &[],
        "scene.toml:7:51: piece 1 holds `pieces` of its own: pieces do not nest",
    );
    refused(
        &dir,
        &pieces_scene(&format!(
            "reparam = \"polar\"\n{}",
            perspective_piece("[0.0, 0.0, 1.0, 1.0]")
        )),
        &[],
        "scene.toml:7:11: `reparam` is not a parameter of flexible projections made of \
         `pieces` (they take only `pieces`; each piece has its own keys)",
    );
    refused(
        &dir,
        &pieces_scene(
            &perspective_piece("[0.0, 0.0, 1.0, 1.0]")
                .replace("fov = 50.0", "fov = 50.0\nwidth = 2.0"),
        ),
        &[],
        "scene.toml:14:9: `width` is not a parameter of flexible preset \"perspective\" (it \
         takes: preset, position, look_at, up, clip, reparam, reparam_grid, fov)",
    );
    // `rect` belongs to pieces only.
    refused(
        &dir,
        &format!("[projection]\ntype = \"flexible\"\nrect = [0.0, 0.0, 1.0, 1.0]\npreset = \"perspective\"\n{FRAME}fov = 50.0\n"),
        &[],
        "scene.toml:3:8: `rect` is not a parameter of flexible projections (they take: preset, \
         position, look_at, up, converge, fov, width, h_fov, v_fov, clip, shear, \
         slit_distance, near, far, surfaces, blend, knots, segments, reparam, reparam_grid, \
         interpolate, max_latitude, shift, twist, azimuth, elevation, generators, projectors, corner_radius, outline, \
         outlines, profile, profiles, perspective_rect, transition, transitions, fovs, style, \
         pole, strength, path, directions, center, radius, magnification, deep, pieces, \
         z_near, z_far, map)",
    );
    // At build time: a sliver of no whole pixel, and the raster's refusal naming the piece.
    refused(
        &dir,
        &two("[0.0, 0.0, 0.5, 1.0]", "[0.5, 0.0, 0.51, 1.0]"),
        &[],
        "scene.toml:5:1: piece 2: rect [0.5, 0.0, 0.51, 1.0] covers no whole pixel of a 40x30 \
         image (its edges snap to the same pixel boundary)",
    );
    let curved = format!(
        "{}\n[[projection.pieces]]\nrect = [0.5, 0.0, 1.0, 1.0]\nblend = \"bezier\"\n\
         segments = 8\nsurfaces = [\n\
         {{ surface = \"rectangle\", center = [0.0, 2.0, 6.0], u_axis = [0.2, 0.0, 0.0], v_axis = [0.0, 0.15, 0.0] }},\n\
         {{ surface = \"rectangle\", center = [1.5, 2.5, 1.0], u_axis = [2.4, 0.0, 0.0], v_axis = [0.0, 1.8, 0.0] }},\n\
         {{ surface = \"rectangle\", center = [0.0, 0.0, -4.0], u_axis = [5.0, 0.0, 0.0], v_axis = [0.0, 3.75, 0.0] }},\n]\n",
        perspective_piece("[0.0, 0.0, 0.5, 1.0]")
    );
    // Ray casting draws it (quadratic projectors drawn as polylines: no inverse).
    fs::write(dir.path().join("scene.toml"), pieces_scene(&curved)).unwrap();
    run_ok(&dir, &["render", "scene.toml", "-o", "out.png"]);
    fs::remove_file(dir.path().join("out.png")).unwrap();
    refused(
        &dir,
        &pieces_scene(&curved),
        &["--method", "raster"],
        "scene.toml: method raster needs a projection with an analytic inverse; flexible has \
         none: piece 2 (rect [0.5, 0.0, 1.0, 1.0]) has no analytic inverse: its projectors \
         are Bezier curves of degree above 2 or drawn as polylines (`segments`), with no \
         closed-form inverse (quadratic projectors through three flat parallel surfaces have \
         one) (use --method raycast)",
    );
}

/// Polyline projectors through parallel planes raster like the ray caster: the
/// orthographic-near / perspective-far example and the depth-transition example made
/// piecewise (`common::raster_agrees`).
#[test]
fn piecewise_depth_volumes_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    raster_agrees(
        &dir,
        &[&scene_example("flexible-ortho-near-persp-far.toml")],
    );
    let depth = scene_example("flexible-depth-transition.toml");
    raster_agrees(&dir, &[&depth, "-D", "projection.style=piecewise"]);
    // The arc length along the polyline projector.
    let ortho = scene_example("flexible-ortho-near-persp-far.toml");
    project_meets_pick_and_depth(&dir, &ortho, [100, 120]);
}

/// `project` takes the point `pick` finds at the centre of pixel `pixel` of `scene` back to
/// that centre, with the depth `render --depth` writes there (the distance along the pixel's
/// projector, straight or curved).
fn project_meets_pick_and_depth(dir: &TempDir, scene: &str, pixel: [usize; 2]) {
    let centre = format!("{}.5,{}.5", pixel[0], pixel[1]);
    let picked = run_json(dir, &["pick", scene, &centre, "--json"]);
    let p = picked["point"].as_array().unwrap();
    let xyz = format!("{},{},{}", p[0], p[1], p[2]);
    let projected = run_json(dir, &["project", scene, &xyz, "--json"]);
    let image = &projected["images"][0];
    for (axis, at) in ["x", "y"].into_iter().zip(pixel) {
        assert!(
            (image[axis].as_f64().unwrap() - (at as f64 + 0.5)).abs() < 1e-6,
            "{projected}"
        );
    }
    run_ok(
        dir,
        &["render", scene, "--depth", "depth.pfm", "-o", "d.png"],
    );
    let pfm = fs::read(dir.path().join("depth.pfm")).unwrap();
    // "Pf\nW H\n-1.0\n", then rows bottom up, little-endian f32.
    let mut parts = pfm.splitn(4, |&b| b == b'\n');
    assert_eq!(parts.next(), Some(&b"Pf"[..]));
    let size: Vec<usize> = std::str::from_utf8(parts.next().unwrap())
        .unwrap()
        .split(' ')
        .map(|n| n.parse().unwrap())
        .collect();
    let samples = parts.nth(1).unwrap();
    let at = ((size[1] - 1 - pixel[1]) * size[0] + pixel[0]) * 4;
    let rendered = f32::from_le_bytes(samples[at..at + 4].try_into().unwrap());
    let along = image["depth"].as_f64().unwrap();
    assert!(
        (along - f64::from(rendered)).abs() < 1e-5 * along,
        "{scene}: {along} against {rendered}"
    );
}

/// Quadratic projectors through parallel planes raster like the ray caster
/// (`common::raster_agrees`): the bent example, the quadratic depth transition and the
/// orthographic-near / perspective-far example made quadratic.
#[test]
fn quadratic_depth_volumes_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    raster_agrees(&dir, &[&scene_example("flexible-quadratic.toml")]);
    raster_agrees(&dir, &[&scene_example("flexible-depth-transition.toml")]);
    let ortho = scene_example("flexible-ortho-near-persp-far.toml");
    raster_agrees(&dir, &[&ortho, "-D", "projection.style=quadratic"]);
    // The arc length along the quadratic projector (its curve parameter would be 0.997
    // where the render's depth is 10.5 at this pixel).
    let quadratic = scene_example("flexible-quadratic.toml");
    project_meets_pick_and_depth(&dir, &quadratic, [160, 120]);
}

/// The stderr of `render SCENE --method raster`, which must fail with exit status 1.
fn raster_refusal(dir: &TempDir, scene: &str) -> String {
    let out = run(
        dir,
        &["render", scene, "--method", "raster", "-o", "out.png"],
    );
    assert_eq!(out.status.code(), Some(1));
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `scenes/flexible-nurbs.toml` renders by ray casting; the raster refuses it with the
/// reason.
#[test]
fn the_nurbs_example_renders_and_the_raster_says_why_not() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("flexible-nurbs.toml");
    let stats = run_json(
        &dir,
        &[
            "render", &scene, "--width", "64", "--height", "48", "-o", "n.png", "--stats", "-",
        ],
    );
    assert!(stats.is_object());
    let stderr = raster_refusal(&dir, &scene);
    assert!(
        stderr.contains(
            "flexible has none: its near and far control surfaces are outside the scanline class"
        ),
        "{stderr}"
    );
}

/// A flexible projection from `near` (a NURBS table's keys after `surface = "nurbs"`) to a
/// rectangle.
fn nurbs_scene(near: &str) -> String {
    format!(
        "[image]\nwidth = 40\nheight = 30\n\n[projection]\ntype = \"flexible\"\n\
         near = {{ surface = \"nurbs\", {near} }}\n\
         far = {{ surface = \"rectangle\", center = [0.0, 0.0, -5.0], u_axis = [4.0, 0.0, 0.0], v_axis = [0.0, 3.0, 0.0] }}\n{OBJECTS}"
    )
}

const GRID: &str = "control = [[[-1.0, -1.0, 0.0], [0.0, -1.0, 0.0], [1.0, -1.0, 0.0]], \
                    [[-1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]], degree = [2, 1]";

#[test]
fn bad_nurbs_surfaces_are_refused_at_the_key() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("scene.toml"), nurbs_scene(GRID)).unwrap();
    run_ok(&dir, &["render", "scene.toml", "-o", "ok.png"]);
    let cases = [
        (
            format!("{GRID}, u_knots = [0.0, 0.0, 1.0, 0.5, 1.0, 1.0]"),
            "scene.toml:7:179: near nurbs surface u knots must not decrease: knot 4 (0.5) is \
             below knot 3 (1)",
        ),
        (
            format!("{GRID}, u_knots = [0.0, 0.0, 1.0, 1.0]"),
            "scene.toml:7:179: near nurbs surface needs 6 u knots (3 control points + degree \
             2 + 1), got 4",
        ),
        (
            format!("{GRID}, v_knots = [0.0, 0.0, 0.0, 0.0]"),
            "scene.toml:7:179: near nurbs surface v knots leave an empty parameter range: \
             knots 2 and 3 (degree + 1 from each end) are both 0",
        ),
        (
            format!("{GRID}, weights = [[1.0, -1.0, 1.0], [1.0, 1.0, 1.0]]"),
            "scene.toml:7:179: near nurbs surface weights must be positive and finite, got -1",
        ),
        (
            format!("{GRID}, weights = [[1.0, 1.0], [1.0, 1.0]]"),
            "scene.toml:7:179: near nurbs surface weights must have the control grid's shape \
             (2 rows of 3), got 2 rows of 2",
        ),
        (
            GRID.replace("[2, 1]", "[3, 1]"),
            "scene.toml:7:39: near nurbs surface of degree [3, 1] needs 4 to 64 control \
             points along u and 2 to 64 along v, got 2 rows of 3",
        ),
        (
            GRID.replace("[2, 1]", "[2, 9]"),
            "scene.toml:7:161: near nurbs surface degree along v must be in 1..=7, got 9",
        ),
        (
            GRID.replace("[2, 1]", "[2, -1]"),
            "scene.toml:7:161: near nurbs surface degree must be [u, v] in 1..=7, got [2, -1]",
        ),
    ];
    for (near, expected) in cases {
        refused(&dir, &nurbs_scene(&near), &[], expected);
    }
    let row = format!("[{}]", vec!["[0.0, 0.0, 0.0]"; 65].join(", "));
    refused(
        &dir,
        &nurbs_scene(&format!("control = [{row}, {row}]")),
        &[],
        "scene.toml:7:39: near nurbs surface takes at most 64 x 64 control points",
    );
}

/// `scenes/flexible-long-scene.toml` renders by ray casting and differs from the plain
/// pushbroom only around its deep areas, rasters like the ray caster; bad deep areas are
/// refused at `deep`.
#[test]
fn the_long_scene_example_renders_and_bad_deep_areas_are_refused() {
    let dir = TempDir::new().unwrap();
    let scene = scene_example("flexible-long-scene.toml");
    let text = fs::read_to_string(&scene).unwrap();
    let pushbroom = text
        .replace("preset = \"long_scene\"", "preset = \"pushbroom\"")
        .lines()
        .filter(|line| !line.starts_with("deep = "))
        .collect::<Vec<_>>()
        .join("\n");
    fs::write(dir.path().join("long.toml"), &text).unwrap();
    fs::write(dir.path().join("pushbroom.toml"), pushbroom).unwrap();
    for name in ["long", "pushbroom"] {
        run_ok(
            &dir,
            &[
                "render",
                &format!("{name}.toml"),
                "--width",
                "360",
                "--height",
                "90",
                "--ids",
                &format!("{name}-ids.png"),
                "-o",
                &format!("{name}.png"),
            ],
        );
    }
    let (w, h, long) = common::ids(&dir.path().join("long-ids.png"));
    let (_, _, pushbroom) = common::ids(&dir.path().join("pushbroom-ids.png"));
    // Columns by their difference: the image ends (no deep area near) agree; the columns
    // of the deep areas (u = 0.3 and 0.7, 0.08 wide) off their middles see the side
    // streets (the middle column itself is the pushbroom's).
    let differs =
        |x: u32| (0..h).any(|y| long[(y * w + x) as usize] != pushbroom[(y * w + x) as usize]);
    assert!((0..10).chain(w - 10..w).all(|x| !differs(x)));
    assert!(differs(3 * w / 10 + 10) && differs(7 * w / 10 - 10));
    // Its far surface is piecewise linear in u: raster draws it by the inverse of each
    // piece, as the ray caster sees it.
    raster_agrees(&dir, &["long.toml"]);

    let folded = text.replace("clip = [0.0, 25.0]", "clip = [0.0, 45.0]");
    let line = folded
        .lines()
        .position(|l| l.starts_with("deep = "))
        .unwrap()
        + 1;
    refused(
        &dir,
        &folded,
        &[],
        &format!(
            "scene.toml:{line}:8: flexible long_scene: deep area 1 and deep area 2 fold the far \
             surface (their fans cross before the far clip at 45): narrow the fov, the far clip \
             or the area"
        ),
    );
    let overlapping = text.replace("[0.7, 0.08, 50.0]", "[0.36, 0.08, 50.0]");
    refused(
        &dir,
        &overlapping,
        &[],
        &format!(
            "scene.toml:{line}:8: flexible long_scene deep areas 1 and 2 touch or overlap: \
             leave a gap of facade between them"
        ),
    );
}
