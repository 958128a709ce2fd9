//! Every renderer returns an error, not an abort, when a frame's memory cannot be had: the
//! failure is injected by the test hook of `flexcam::try_alloc` (its environment variable,
//! set here before the first allocation of this test process: every buffer above
//! [`LIMIT`] bytes then fails as the allocator's refusal would).

use std::path::Path;
use std::sync::Once;

use flexcam::projection::ray_map::ray_map;
use flexcam::render::{self, LinearImage, Method, Photo, PreparedScene, RenderOptions};
use flexcam::render::{Shading, StPoints, TransitionShading};
use flexcam::scene::{load_with, LoadedScene, Overrides};
use flexcam::try_alloc;

/// Above every buffer of loading and preparing the scenes below at 200 x 150, below a 200 x
/// 150 frame's colour buffer (360 kB).
const LIMIT: &str = "100000";

/// Sets the hook once, before any test of this process allocates through `try_alloc`.
fn hook() {
    static SET: Once = Once::new();
    SET.call_once(|| std::env::set_var(try_alloc::TEST_LIMIT_VARIABLE, LIMIT));
}

/// The example scene `name` at 200 x 150.
fn scene(name: &str) -> LoadedScene {
    hook();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let overrides = Overrides {
        width: Some(200),
        height: Some(150),
        ..Overrides::default()
    };
    load_with(&path.to_string_lossy(), &overrides).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The error of rendering `name` by `options`, which must be an out-of-memory one.
fn render_error(name: &str, options: &RenderOptions) -> String {
    let loaded = scene(name);
    let prepared = PreparedScene::new(&loaded.scene);
    let e = render::render(&prepared, loaded.projection.as_ref(), options)
        .err()
        .unwrap_or_else(|| panic!("{name} by {:?} rendered", options.method));
    assert!(try_alloc::is_out_of_memory(&e), "{name}: {e}");
    e.to_string()
}

const FRAME: &str = "out of memory: cannot allocate 360.0 kB for the 200 x 150 frame";

#[test]
fn every_method_returns_the_error() {
    for (scene, method) in [
        ("cube-floor.toml", Method::Raycast),
        ("cube-floor.toml", Method::Raster),
        ("trilinear-fan.toml", Method::Trilinear),
    ] {
        let options = RenderOptions {
            method,
            ..RenderOptions::default()
        };
        assert_eq!(render_error(scene, &options), FRAME, "{method}");
    }
    // Camera triangles allocate the owner of each pixel (4 bytes) before the frame.
    let options = RenderOptions {
        method: Method::CameraTriangles,
        ..RenderOptions::default()
    };
    assert_eq!(
        render_error("trilinear-fan.toml", &options),
        "out of memory: cannot allocate 120.0 kB for the camera triangle of each pixel of the \
         200 x 150 frame"
    );
}

#[test]
fn compositing_caustics_transitions_and_outputs_return_the_error() {
    // Reflector compositing and caustics: their main views and maps fail alike.
    for method in [Method::Trilinear, Method::Raycast] {
        let options = RenderOptions {
            method,
            ..RenderOptions::default()
        };
        assert_eq!(render_error("camtri-caustics.toml", &options), FRAME);
    }
    let transitions = RenderOptions {
        shading: Shading::Transitions(TransitionShading::with_default_d(false)),
        ..RenderOptions::default()
    };
    assert_eq!(render_error("displaced-torus.toml", &transitions), FRAME);
    let loaded = scene("cube-floor.toml");
    let projection = loaded.projection.as_ref();
    let e = ray_map(projection).unwrap_err().to_string();
    assert_eq!(
        e,
        "out of memory: cannot allocate 3.1 MB for the ray map of the 200 x 150 image"
    );
    let e = render::st_map(projection, projection, StPoints::Distance(10.0))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "out of memory: cannot allocate 720.0 kB for the STMap of the 200 x 150 frame"
    );
    let photo = Photo::equirectangular(LinearImage {
        width: 4,
        height: 2,
        pixels: vec![glam::Vec3::ONE; 8],
    })
    .unwrap();
    let e = render::reproject(&photo, projection, 1, glam::Vec3::ZERO).unwrap_err();
    assert_eq!(e.to_string(), FRAME);
}
