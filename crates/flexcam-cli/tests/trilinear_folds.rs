//! `--method trilinear` on projection triangles whose rays fold or collapse, against the ray
//! caster through the binary (the appendix C configurations, the visualisation surfaces, the
//! views through a mirror and a glass ball); and `flexcam project`, which lists every image
//! of a point.

use std::path::{Path, PathBuf};

use tempfile::TempDir;

mod common;
use common::{interior_agreement, run, run_json, run_ok};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn scene(name: &str) -> String {
    scenes_dir().join(name).to_str().expect("UTF-8").to_string()
}

/// Renders `scene` flat with `--method trilinear` (its stats) and with the ray caster, and
/// returns the stats and the object-id agreement over the pixels away from id edges: those
/// whose 3 x 3 neighbourhood in the reference holds one id (the pixels at an edge depend
/// on which side of a curved silhouette a pixel centre falls, a sub-pixel matter).
fn trilinear_against_raycast(scene: &str) -> (serde_json::Value, f64) {
    let dir = TempDir::new().unwrap();
    let flat = ["--shading", "flat", "-o", "x.png"];
    let stats = run_json(
        &dir,
        &[
            &["render", scene, "--method", "trilinear", "--ids", "t.png"][..],
            &flat,
            &["--stats", "-"],
        ]
        .concat(),
    );
    run_ok(
        &dir,
        &[&["render", scene, "--ids", "r.png"][..], &flat].concat(),
    );
    let (agreement, interior) =
        interior_agreement(&dir.path().join("r.png"), &dir.path().join("t.png"));
    assert!(interior > 0, "{scene}: no interior pixel");
    (stats, agreement)
}

/// One configuration of Vallance 2005, appendix C (`scenes/appendix-c/NAME.toml`: the view
/// triangle of Table C.2 and the scene triangle of Table C.1): its rays fold, and the
/// triangle is drawn by its shapes (`shapes` of them before clipping), no pixel ray cast,
/// agreeing with the ray caster on at least 99.5 % of the pixels away from id edges.
fn appendix_c_configuration(name: &str, shapes: u64) {
    let (stats, agreement) = trilinear_against_raycast(&scene(&format!("appendix-c/{name}.toml")));
    assert_eq!(stats["fallback_triangles"], 0, "{name}: {stats}");
    assert_eq!(stats["fallback_rays"], 0, "{name}: {stats}");
    assert_eq!(stats["shapes"], shapes, "{name}: {stats}");
    assert!(
        stats["raster_covered"].as_u64().unwrap() > 0,
        "{name}: {stats}"
    );
    assert!(agreement >= 0.995, "{name}: {agreement}");
}

#[test]
fn appendix_c_2_2_2_3() {
    appendix_c_configuration("2-2-2-3", 4);
}

#[test]
fn appendix_c_3_3_3() {
    appendix_c_configuration("3-3-3", 3);
}

#[test]
fn appendix_c_4_2_3() {
    appendix_c_configuration("4-2-3", 3);
}

#[test]
fn appendix_c_4_5() {
    appendix_c_configuration("4-5", 2);
}

#[test]
fn appendix_c_6_3() {
    appendix_c_configuration("6-3", 3);
}

#[test]
fn appendix_c_2_7() {
    appendix_c_configuration("2-7", 2);
}

#[test]
fn appendix_c_9() {
    appendix_c_configuration("9", 2);
}

/// The two-views band (Vallance 2005, 6.2): its rays blend a perspective view into an
/// orthographic one and fold; its triangles are drawn by their shapes, except the pairs
/// whose shapes reach across a depth where four of its parametric triangles degenerate
/// (`ProjectionTriangleCache::degenerate_depths`), which are ray cast.
#[test]
fn two_views_band_is_drawn_by_its_shapes() {
    let (stats, agreement) = trilinear_against_raycast(&scene("trilinear-two-views.toml"));
    assert!(stats["shapes"].as_u64().unwrap() > 10_000, "{stats}");
    assert!(
        stats["fallback_triangles"].as_u64().unwrap() <= 4,
        "{stats}"
    );
    assert!(agreement >= 0.995, "{agreement}");
}

/// The inward-looking sphere (Vallance 2005, 6.3): the pole rows, whose triangles have two
/// equal vertices and sweep no volume, are drawn as fans of rays; the rest as central
/// projections. Nothing is ray cast.
#[test]
fn inward_sphere_pole_rows_are_drawn_as_fans() {
    let (stats, agreement) = trilinear_against_raycast(&scene("trilinear-inward-sphere.toml"));
    assert_eq!(stats["fallback_triangles"], 0, "{stats}");
    assert_eq!(stats["central_triangles"], 1104, "{stats}");
    assert!(agreement >= 0.995, "{agreement}");
}

/// The mirror ball of Figure 7.4 (`view = "sphere_mirror"`): its reflected rays diverge and
/// never cross, so every projection triangle is drawn by its shapes.
#[test]
fn sphere_mirror_is_drawn_by_its_shapes() {
    let (stats, agreement) = trilinear_against_raycast(&scene("trilinear-sphere-mirror.toml"));
    assert_eq!(stats["projection_triangles"], 512, "{stats}");
    assert_eq!(stats["fallback_triangles"], 0, "{stats}");
    assert!(stats["shapes"].as_u64().unwrap() > 0, "{stats}");
    assert!(agreement >= 0.995, "{agreement}");
}

/// The example scene `name` with its text `from` replaced by `to`, written into `dir`.
fn variant(dir: &TempDir, name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(scene(name)).unwrap();
    assert!(text.contains(from), "{name}: {from}");
    let path = dir.path().join(name);
    std::fs::write(&path, text.replace(from, to)).unwrap();
    path.to_str().expect("UTF-8").to_string()
}

/// The glass ball (`view = "sphere_glass"`, 7.3.3) focuses its rays: where the rays of a
/// projection triangle cross, its parametric triangle degenerates at that depth, and the
/// pairs with scene triangles reaching across it are split at the band around it
/// (`split_pairs`): drawn by their shapes before and beyond it and pixel tested inside it.
/// Nothing is ray cast, at the example's 16 x 16 grid and at 32 x 32.
#[test]
fn sphere_glass_splits_the_pairs_whose_rays_cross() {
    for grid in ["grid = 16", "grid = 32"] {
        let dir = TempDir::new().unwrap();
        let path = variant(&dir, "trilinear-sphere-glass.toml", "grid = 16", grid);
        let (stats, agreement) = trilinear_against_raycast(&path);
        assert_eq!(stats["fallback_triangles"], 0, "{grid}: {stats}");
        assert_eq!(stats["fallback_rays"], 0, "{grid}: {stats}");
        assert_eq!(stats["unprojectable"], 0, "{grid}: {stats}");
        assert!(
            stats["split_pairs"].as_u64().unwrap() > 0,
            "{grid}: {stats}"
        );
        assert!(stats["shapes"].as_u64().unwrap() > 0, "{grid}: {stats}");
        assert!(agreement >= 0.995, "{grid}: {agreement}");
    }
}

/// Detail in context with the base plane inside the scene (`magnification = 1.5`: the plane
/// 6.7 from the eye, the floor reaching through it), either focus (the inverse focus's
/// converging rays degenerate inside the scene, and its pairs there are split): floor
/// vertices lying on the base plane get
/// cubics whose roots lost to infinity differ in number from their neighbours' by rounding
/// (rays parallel in the focus, a smoothstep weight of nearly 0 at its edge: `a` and `b`
/// vanish or nearly), so their pairs are unprojectable (`OpenAtInfinity`) and those
/// projection triangles are ray cast, exactly.
#[test]
fn detail_in_context_with_the_base_plane_inside_the_scene() {
    for (name, from) in [
        ("trilinear-detail-in-context.toml", "magnification = 2.5"),
        (
            "trilinear-detail-inverse-perspective.toml",
            "magnification = 2.0",
        ),
    ] {
        let dir = TempDir::new().unwrap();
        let path = variant(&dir, name, from, "magnification = 1.5");
        let (stats, agreement) = trilinear_against_raycast(&path);
        assert!(
            stats["unprojectable"].as_u64().unwrap() > 0,
            "{name}: {stats}"
        );
        assert!(
            stats["fallback_triangles"].as_u64().unwrap() <= 32,
            "{name}: {stats}"
        );
        assert!(stats["shapes"].as_u64().unwrap() > 1000, "{name}: {stats}");
        assert!(agreement >= 0.995, "{name}: {agreement}");
    }
}

/// Detail in context with an inverse-perspective focus (6.1): the focus rays converge
/// beyond the cube, and across the band they turn into the diverging context rays; every
/// projection triangle is drawn by its shapes.
#[test]
fn detail_in_context_inverse_perspective_focus() {
    let (stats, agreement) =
        trilinear_against_raycast(&scene("trilinear-detail-inverse-perspective.toml"));
    assert!(stats["shapes"].as_u64().unwrap() > 1000, "{stats}");
    assert_eq!(stats["fallback_triangles"], 0, "{stats}");
    assert!(agreement >= 0.995, "{agreement}");
}

/// Multi-hit reflection (7.2.3): the mirror ball with a second mirror ball (`second_sphere`)
/// behind the camera; the rays that meet it are reflected again. Drawn by the trilinear
/// rasteriser, agreeing with the ray caster of the same grid.
#[test]
fn sphere_mirror_twice_agrees_with_the_ray_caster() {
    let (stats, agreement) =
        trilinear_against_raycast(&scene("trilinear-sphere-mirror-twice.toml"));
    assert!(stats["shapes"].as_u64().unwrap() > 1000, "{stats}");
    assert!(agreement >= 0.995, "{agreement}");
}

/// `exact = true` renders the exact ball by ray casting, which the grid approaches: at the
/// scenes' 16 x 16 grids the ids agree away from id edges on nearly every pixel; the exact
/// view has no triangles to rasterise, so `--method trilinear` refuses it with one line.
#[test]
fn exact_balls_are_what_the_grids_approach() {
    let dir = TempDir::new().unwrap();
    for name in [
        "trilinear-sphere-mirror.toml",
        "trilinear-sphere-glass.toml",
    ] {
        let path = scene(name);
        let flat = ["--shading", "flat", "-o", "x.png"];
        run_ok(
            &dir,
            &[&["render", &path, "--ids", "grid.png"][..], &flat].concat(),
        );
        run_ok(
            &dir,
            &[
                &["render", &path, "-D", "projection.exact=true"][..],
                &["--ids", "exact.png"],
                &flat,
            ]
            .concat(),
        );
        let (agreement, interior) =
            interior_agreement(&dir.path().join("exact.png"), &dir.path().join("grid.png"));
        assert!(interior > 10_000, "{name}: {interior}");
        assert!(agreement >= 0.99, "{name}: {agreement}");
        let args = [
            "render",
            &path,
            "-D",
            "projection.exact=true",
            "--method",
            "trilinear",
        ];
        let out = run(&dir, &args);
        assert_eq!(out.status.code(), Some(1), "{name}");
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(stderr.trim().lines().count(), 1, "{name}: {stderr}");
    }
}

/// The lines of `flexcam project SCENE X,Y,Z` in `dir`: `x y depth` each.
fn project_lines(dir: &TempDir, scene: &str, point: &str) -> Vec<[f64; 3]> {
    let out = run_ok(dir, &["project", scene, point]);
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|line| {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// One projection triangle whose rays all pass through (0.3, 0.3, 1) at t = 1: a point on
/// its vertical ray beyond that focus is imaged once, at depth 2 (the cubic's double root
/// at the focus is no image); the JSON lists the same; a point behind the base has none
/// (no line, exit 0).
#[test]
fn project_lists_the_image_of_a_point_and_none_behind() {
    let dir = TempDir::new().unwrap();
    let scene = "[image]\nwidth = 100\nheight = 100\n[projection]\ntype = \"trilinear\"\n\
        points = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n\
        normals = [[0.3, 0.3, 1], [-0.7, 0.3, 1], [0.3, -0.7, 1]]\n\
        screen = [[0, 0], [1, 0], [0, 1]]\ntriangles = [[0, 1, 2]]\n";
    std::fs::write(dir.path().join("focus.toml"), scene).unwrap();
    let images = project_lines(&dir, "focus.toml", "0.3,0.3,2");
    assert_eq!(images.len(), 1, "{images:?}");
    let [x, y, depth] = images[0];
    assert!((depth - 2.0).abs() < 1e-9, "{depth}");
    // Screen (0.3, 0.3) from the bottom left of a 100 x 100 image.
    assert!(
        (x - 30.0).abs() < 1e-6 && (y - 70.0).abs() < 1e-6,
        "{x} {y}"
    );
    let json = run_json(&dir, &["project", "focus.toml", "0.3,0.3,2", "--json"]);
    assert_eq!(json["images"].as_array().unwrap().len(), 1, "{json}");
    assert_eq!(json["point"], serde_json::json!([0.3, 0.3, 2.0]));
    assert!((json["images"][0]["depth"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    assert!(project_lines(&dir, "focus.toml", "0.3,0.3,-1").is_empty());
    let json = run_json(&dir, &["project", "focus.toml", "0.3,0.3,-1", "--json"]);
    assert_eq!(json["images"], serde_json::json!([]));
}

/// A scene point seen three times through a folding triangle: the first scene vertex of
/// appendix C's configuration (3,3,3) (Vallance 2005), whose cubic has three roots, at
/// depths about 0.096, 0.367 and 1.273, all inside the projection triangle; listed nearest
/// first, each inside the image.
#[test]
fn project_finds_the_three_images_of_a_point_beyond_a_fold() {
    let dir = TempDir::new().unwrap();
    let images = project_lines(
        &dir,
        &scene("appendix-c/3-3-3.toml"),
        "0.0962,-0.0457,-0.011",
    );
    assert_eq!(images.len(), 3, "{images:?}");
    assert!(
        images.windows(2).all(|w| w[0][2] < w[1][2]),
        "nearest first"
    );
    for [x, y, _] in &images {
        assert!(
            (0.0..=200.0).contains(x) && (0.0..=200.0).contains(y),
            "{images:?}"
        );
    }
    // A point whose first coordinate is negative: (2,7)'s third vertex, three images too.
    let images = project_lines(&dir, &scene("appendix-c/2-7.toml"), "-0.117,-0.388,0.265");
    assert_eq!(images.len(), 3, "{images:?}");
}

/// Projections without an analytic inverse, and points that are not three finite numbers,
/// are one error line.
#[test]
fn project_refuses_what_it_cannot_project() {
    let dir = TempDir::new().unwrap();
    for point in ["1,2", "1,2,nan", "1,2,3,4"] {
        let out = run(&dir, &["project", "builtin:cube-floor", point]);
        assert!(!out.status.success(), "{point}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("X,Y,Z"), "{err}");
    }
    let out = run(&dir, &["project", &scene("flexible-bent.toml"), "0,0,0"]);
    let err = String::from_utf8(out.stderr).unwrap();
    if !out.status.success() {
        assert!(err.contains("no analytic inverse"), "{err}");
    }
}

/// The inward-looking sphere's pole rows: projection triangles whose two pole vertices
/// coincide, so their rays form a fan and a point on it is seen along a whole segment of
/// pixels. For pixels of the bottom and top rows, the point `pick` finds there is listed by
/// `project` with an image through that pixel: a point image on it or a segment (a line of
/// five numbers, the JSON's `x_end`, `y_end`) passing through it, at one depth.
#[test]
fn project_lists_the_segment_along_which_a_fan_triangle_sees_a_point() {
    let dir = TempDir::new().unwrap();
    let sphere = scene("trilinear-inward-sphere.toml");
    let mut segments = 0;
    for pixel in [
        "10.5,158.5",
        "60.5,158.5",
        "100.5,158.5",
        "230.5,158.5",
        "40.5,1.5",
    ] {
        let picked = run_json(&dir, &["pick", &sphere, pixel, "--json"]);
        let point: Vec<String> = picked["point"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| format!("{:?}", c.as_f64().unwrap()))
            .collect();
        let point = point.join(",");
        let (x, y) = pixel.split_once(',').unwrap();
        let at = [x.parse::<f64>().unwrap(), y.parse::<f64>().unwrap()];
        let json = run_json(&dir, &["project", &sphere, &point, "--json"]);
        let through = json["images"].as_array().unwrap().iter().any(|image| {
            let p = |k: &str| image[k].as_f64();
            let a = [p("x").unwrap(), p("y").unwrap()];
            let b = match (p("x_end"), p("y_end")) {
                (Some(x), Some(y)) => {
                    segments += 1;
                    [x, y]
                }
                _ => a,
            };
            // The distance from the pixel to the segment a b (a point where a == b).
            let d = [b[0] - a[0], b[1] - a[1]];
            let length2 = d[0] * d[0] + d[1] * d[1];
            let s = if length2 == 0.0 {
                0.0
            } else {
                (((at[0] - a[0]) * d[0] + (at[1] - a[1]) * d[1]) / length2).clamp(0.0, 1.0)
            };
            (a[0] + s * d[0] - at[0]).hypot(a[1] + s * d[1] - at[1]) < 1e-6
        });
        assert!(through, "{pixel}: {json}");
        let text = String::from_utf8(run_ok(&dir, &["project", &sphere, &point]).stdout).unwrap();
        assert_eq!(
            text.lines().count(),
            json["images"].as_array().unwrap().len(),
            "{text}"
        );
    }
    assert!(segments >= 4, "{segments} segments");
}
