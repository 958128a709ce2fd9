//! Rendering from a program: load a scene with overrides, prepare it once, render it by two
//! methods through the one entry point, and compare the two frames.
//!
//!     cargo run --release -p flexcam --example render_scene [SCENE]
//!
//! SCENE is a scene file or `builtin:NAME` (default `builtin:teapot-room`).

use flexcam::render::{self, compare, Method, PreparedScene, RenderOptions, Shading};
use flexcam::scene::{self, Overrides};

fn main() -> flexcam::Result<()> {
    let source = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "builtin:teapot-room".to_string());
    // 1. Load the scene with overrides and build its projection.
    let overrides = Overrides {
        width: Some(320),
        height: Some(240),
        ..Overrides::default()
    };
    let loaded = scene::load_with(&source, &overrides)?;
    for warning in &loaded.build_report.warnings {
        eprintln!("warning: {source}: {warning}");
    }
    // 2. Prepare it once: every renderer reads it, nothing mutates it.
    let prepared = PreparedScene::new(&loaded.scene);
    // 3. Render it by the reference and by rasterisation, where the projection allows.
    let mut frames = Vec::new();
    for method in [Method::Raycast, Method::Raster] {
        let options = RenderOptions {
            method,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        match render::render(&prepared, loaded.projection.as_ref(), &options) {
            Ok(rendered) => {
                println!("{method}: {} counters", rendered.counters.len());
                frames.push(rendered.frame);
            }
            Err(e) => println!("{method}: {e}"),
        }
    }
    if let [reference, raster] = frames.as_slice() {
        let agreement = compare(raster, reference)?;
        println!("raster against raycast: {agreement:?}");
    }
    println!("BVH builds: {}", prepared.bvh_builds());
    Ok(())
}
