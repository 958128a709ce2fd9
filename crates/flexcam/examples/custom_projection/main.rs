//! A projection of your own: a stereographic "little planet" implementing flexcam's
//! `Projection` trait, rendered by flexcam's ray caster and rasteriser.
//!
//!     cargo run --release -p flexcam --example custom_projection [SCENE [OUT.png]]
//!
//! SCENE is a scene file or `builtin:NAME` (default `builtin:default`), seen from
//! (0, 1, 0) looking down; OUT defaults to `little-planet.png`.

mod little_planet;

use flexcam::glam::DVec3;

fn main() -> flexcam::Result<()> {
    let mut args = std::env::args().skip(1);
    let source = args.next().unwrap_or_else(|| "builtin:default".to_string());
    let out = args
        .next()
        .unwrap_or_else(|| "little-planet.png".to_string());
    let report = little_planet::render_little_planet(
        &source,
        DVec3::new(0.0, 1.0, 0.0),
        400,
        400,
        std::path::Path::new(&out),
    )?;
    println!("wrote {out} (ray cast)");
    println!(
        "raster against raycast: {:?}",
        report.raster_against_raycast
    );
    Ok(())
}
