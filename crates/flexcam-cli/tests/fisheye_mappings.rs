//! The fisheye mappings, the sensor ellipse and the dome master from the command line: each
//! renders alike by ray casting and by rasterisation, the generic fisheye reproduces the
//! angular one byte for byte, and bad keys are refused in one line naming the file.

mod common;

use std::fs;

use common::{camera_example, ids, raster_agrees, run, run_ok};
use tempfile::TempDir;

/// [`raster_agrees`], and the top-left corner (outside the image circle in every case
/// here) has id 0 by both methods.
fn raster_agrees_outside_sees_nothing(dir: &TempDir, args: &[&str]) {
    raster_agrees(dir, args);
    for method in ["raycast", "raster"] {
        let (_, _, ids) = ids(&dir.path().join(format!("{method}-ids.png")));
        assert_eq!(ids[0], 0, "{args:?}: {method} sees at the corner");
    }
}

/// The four classic mappings at fov 180 (`-D projection.mapping=...` on the teapot
/// fisheye), the ellipse of `fit = "fill"` on a wide image, a lens on a sensor with
/// non-square pixels, the Cycles polynomial scene and the dome master scene.
#[test]
fn mappings_raster_like_the_ray_caster() {
    let dir = TempDir::new().unwrap();
    let fisheye = camera_example("teapot-fisheye.toml");
    for mapping in ["equidistant", "equisolid", "stereographic", "orthographic"] {
        let define = format!("projection.mapping={mapping}");
        raster_agrees_outside_sees_nothing(&dir, &[&fisheye, "-D", &define]);
    }
    raster_agrees_outside_sees_nothing(
        &dir,
        &[
            &fisheye,
            "-D",
            "projection.fit=fill",
            "--width",
            "400",
            "--height",
            "240",
        ],
    );
    raster_agrees_outside_sees_nothing(
        &dir,
        &[
            &fisheye,
            "-D",
            "projection.mapping=equisolid",
            "-D",
            "projection.lens=9",
            "-D",
            "projection.pixel_aspect=[1.0,1.5]",
        ],
    );
    raster_agrees_outside_sees_nothing(&dir, &[&camera_example("fisheye-polynomial-teapot.toml")]);
    raster_agrees_outside_sees_nothing(&dir, &[&camera_example("dome-master-teapot.toml")]);
}

/// `fit = "fill"` on a square image places the circle where the default does: the generic
/// path renders the angular fisheye's image byte for byte, by both methods.
#[test]
fn generic_path_reproduces_the_angular_fisheye() {
    let dir = TempDir::new().unwrap();
    let fisheye = camera_example("teapot-fisheye.toml");
    for method in ["raycast", "raster"] {
        for (name, define) in [
            ("plain", "projection.fit=inscribed"),
            ("fill", "projection.fit=fill"),
        ] {
            run_ok(
                &dir,
                &[
                    "render",
                    &fisheye,
                    "-D",
                    define,
                    "--method",
                    method,
                    "-o",
                    &format!("{name}.png"),
                ],
            );
        }
        let plain = fs::read(dir.path().join("plain.png")).unwrap();
        let fill = fs::read(dir.path().join("fill.png")).unwrap();
        assert!(plain == fill, "{method}: the images differ");
    }
}

/// Each bad key: exit status 1, one line naming the file and the key, no image written.
#[test]
fn bad_fisheye_keys_are_refused_in_one_line() {
    let dir = TempDir::new().unwrap();
    let fisheye = camera_example("teapot-fisheye.toml");
    let polynomial = camera_example("fisheye-polynomial-teapot.toml");
    let dome = camera_example("dome-master-teapot.toml");
    let cases: [(&str, &[&str], &str); 6] = [
        (
            &fisheye,
            &["-D", "projection.mapping=fishy"],
            "unknown fisheye mapping \"fishy\"; expected one of: equidistant, equisolid, stereographic, orthographic, polynomial",
        ),
        (
            &fisheye,
            &["-D", "projection.mapping=orthographic", "-D", "projection.fov=200"],
            "fisheye fov must be in (0, 180] degrees, got 200 (mapping \"orthographic\")",
        ),
        (
            &fisheye,
            &["-D", "projection.mapping=stereographic", "-D", "projection.fov=360"],
            "fisheye fov must be in (0, 360) degrees, got 360 (mapping \"stereographic\")",
        ),
        (
            &polynomial,
            &["-D", "projection.polynomial=[0.0,-0.12,0.006,0.0,0.0]"],
            "fisheye polynomial is not increasing over the image circle: d theta / dr = 0 at r = 10.000000 mm",
        ),
        (
            &polynomial,
            &["-D", "projection.polynomial=[0.0,-0.12]"],
            "`polynomial` needs 5 coefficients",
        ),
        (
            &dome,
            &["-D", "projection.tilt=120"],
            "dome_master tilt must be in [-90, 90] degrees, got 120",
        ),
    ];
    for (scene, defines, message) in cases {
        let mut args = vec!["render", scene];
        args.extend_from_slice(defines);
        args.extend_from_slice(&["-o", "out.png"]);
        let out = run(&dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{defines:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{defines:?}: {stderr}");
        let file = scene.rsplit('/').next().unwrap();
        assert!(
            stderr.contains(file) && stderr.contains(message),
            "{defines:?}: {stderr}"
        );
        assert!(!dir.path().join("out.png").exists());
    }
}
