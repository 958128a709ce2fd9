//! Rendering from a program: load a scene with overrides, prepare it once, render it by two
//! methods through the one entry point, and compare the two frames (module `two_methods`).
//!
//!     cargo run --release -p flexcam --example render_scene [SCENE]
//!
//! SCENE is a scene file or `builtin:NAME` (default `builtin:teapot-room`).

mod two_methods;

fn main() -> flexcam::Result<()> {
    let source = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "builtin:teapot-room".to_string());
    let made = two_methods::render_two_ways(&source, 320, 240)?;
    for warning in &made.warnings {
        eprintln!("warning: {source}: {warning}");
    }
    println!("raycast: {} x {}", made.raycast.width, made.raycast.height);
    match &made.raster {
        Ok((_, agreement)) => println!("raster against raycast: {agreement:?}"),
        Err(e) => println!("raster: {e}"),
    }
    println!("BVH builds: {}", made.bvh_builds);
    Ok(())
}
