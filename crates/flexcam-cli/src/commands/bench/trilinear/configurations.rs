//! `flexcam bench trilinear --study configurations`: the seven shape configurations of
//! Vallance 2005, appendix C (`scenes/appendix-c/*.toml`: one scene triangle through one
//! projection triangle whose rays fold), each rendered by the ray caster and by the
//! trilinear rasteriser at the thesis's largest square image (640^2 = 409600 pixels): the
//! shapes drawn, the triangles left to the ray-cast fallback, the times beside Tables D.4 to
//! D.17, and the id agreement with the ray caster (Figures 8.1, 8.4 and 8.7 time the same
//! configurations over resolutions).

use std::path::Path;

use flexcam::render::{CurveOptions, PreparedScene};
use flexcam::scene::{self, Scene};
use flexcam::Result;

use super::study::{against, fixed, reference, Table};

/// The side of the square images: 640^2 = 409600 pixels, the thesis's largest.
pub const SIDE: u32 = 640;

/// The configurations (named by their shapes' vertex counts) in the thesis's order, with the
/// thesis's ray-traced (Tables D.4-D.10) and trilinear (D.11-D.17) ms at 409600 pixels.
/// The thesis's tables D.5 and D.12 name (2,7) "2,3".
pub const CONFIGURATIONS: [(&str, f64, f64); 7] = [
    ("2-2-2-3", 387.33, 0.02),
    ("2-7", 400.67, 0.07),
    ("3-3-3", 400.67, 0.02),
    ("4-2-3", 397.33, 0.02),
    ("4-5", 397.33, 0.04),
    ("6-3", 397.33, 0.03),
    ("9", 410.67, 0.25),
];

/// The scene of configuration `name` in folder `scenes`.
pub fn load(scenes: &Path, name: &str) -> Result<Scene> {
    let path = scenes.join("appendix-c").join(format!("{name}.toml"));
    scene::load(&path.to_string_lossy())
}

pub const COLUMNS: &[&str] = &[
    "configuration",
    "pixels",
    "shapes",
    "fallback_triangles",
    "fallback_rays",
    "raycast_ms",
    "trilinear_ms",
    "speedup",
    "ids_interior",
    "interior_pixels",
    "ids",
    "rgb_error",
    "thesis_ray_ms",
    "thesis_trilinear_ms",
];

/// Measures every configuration at `side x side` pixels (default [`SIDE`]).
pub fn run(scenes: &Path, side: Option<u32>, repeat: u32) -> Result<Table> {
    let side = side.unwrap_or(SIDE);
    let mut table = Table::new(COLUMNS);
    for (name, thesis_ray, thesis_ms) in CONFIGURATIONS {
        let scene = load(scenes, name)?;
        let projection = scene.projection.build(side, side)?;
        let prepared = PreparedScene::new(&scene);
        let (raycast, frame) = reference(&prepared, projection.as_ref(), repeat)?;
        let m = against(
            &frame,
            &prepared,
            projection.as_ref(),
            CurveOptions::default(),
            repeat,
        )?;
        table.push(vec![
            name.to_string(),
            (u64::from(side) * u64::from(side)).to_string(),
            m.count("shapes").to_string(),
            m.count("fallback_triangles").to_string(),
            m.count("fallback_rays").to_string(),
            fixed(raycast.median_ms(), 3),
            fixed(m.timing.median_ms(), 3),
            fixed(raycast.median / m.timing.median, 2),
            fixed(m.interior.0, 5),
            m.interior.1.to_string(),
            fixed(m.comparison.id_agreement, 5),
            fixed(m.comparison.relative_rgb_error, 6),
            fixed(thesis_ray, 2),
            fixed(thesis_ms, 2),
        ]);
    }
    Ok(table)
}
