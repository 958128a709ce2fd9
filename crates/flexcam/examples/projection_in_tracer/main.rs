//! A flexcam projection inside another ray tracer: the tracer (module `tracer`, spheres and
//! Lambert shading of its own) asks flexcam only for each pixel's projector.
//!
//!     cargo run --release -p flexcam --example projection_in_tracer \
//!         [SCENE [-D KEY=VALUE]...] [-o OUT.png]
//!
//! With SCENE (a scene file or `builtin:NAME`, its keys overridden by `-D` as in
//! `flexcam render`) the tracer uses that scene's projection at 400 x 300 (its own spheres,
//! not the scene's objects); without, a 200-degree fisheye built in code. OUT defaults to
//! `tracer.png`.

mod tracer;

use std::path::Path;

use flexcam::glam::DVec3;
use flexcam::projection::{CameraFrame, Projection, ProjectionSpec};
use flexcam::scene::file::Definition;
use flexcam::scene::{self, Overrides};
use flexcam::Error;

fn main() -> flexcam::Result<()> {
    let mut source = None;
    let mut out = "tracer.png".to_string();
    let mut definitions = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next()
                .ok_or_else(|| Error::new(format!("{arg} needs a value")))
        };
        match arg.as_str() {
            "-o" => out = value()?,
            "-D" => definitions.push(value()?.parse()?),
            _ => source = Some(arg),
        }
    }
    let projection = match source {
        Some(source) => projection_of_scene(&source, definitions)?,
        None => fisheye_in_code()?,
    };
    let hits = tracer::render_png(projection.as_ref(), Path::new(&out))?;
    let seen = hits.iter().flatten().count();
    println!(
        "wrote {out}: a {} projection, {seen} of {} pixels hit a sphere",
        projection.kind(),
        hits.len()
    );
    Ok(())
}

/// The projection a scene file (or built-in scene) names with `definitions` applied, built
/// at 400 x 300.
fn projection_of_scene(
    source: &str,
    definitions: Vec<Definition>,
) -> flexcam::Result<Box<dyn Projection>> {
    let overrides = Overrides {
        width: Some(400),
        height: Some(300),
        definitions,
        ..Overrides::default()
    };
    Ok(scene::load_with(source, &overrides)?.projection)
}

/// A 200-degree angular fisheye described and built in code, 400 x 300.
fn fisheye_in_code() -> flexcam::Result<Box<dyn Projection>> {
    let spec = ProjectionSpec::Fisheye {
        frame: CameraFrame {
            position: DVec3::new(0.0, 1.2, 3.5),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
        },
        fov: 200.0,
    };
    spec.build(400, 300)
}
