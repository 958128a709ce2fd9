//! Rendering a scene from a program: load it with overrides, prepare it once, render it by two
//! methods through the one entry point, and compare the two frames.

use flexcam::render::{self, compare, Comparison, Frame, Method, PreparedScene};
use flexcam::render::{RenderOptions, Shading};
use flexcam::scene::{self, Overrides};

/// What [`render_two_ways`] made.
#[derive(Debug)]
pub struct TwoWays {
    /// Warnings of the projection's build (a fitted grid's doubtful nodes), to show the user.
    pub warnings: Vec<String>,
    /// The ray-cast reference frame.
    pub raycast: Frame,
    /// The raster frame and its agreement with the reference, or why the scene's projection
    /// cannot be rasterised (it has no analytic inverse).
    pub raster: Result<(Frame, Comparison), flexcam::Error>,
    /// BVH builds: one for the scene, whatever is rendered of it.
    pub bvh_builds: u64,
}

/// Renders `source` (a scene file or `builtin:NAME`) at `width` x `height` with flat shading
/// by the ray caster and by rasterisation, and compares the two.
pub fn render_two_ways(source: &str, width: u32, height: u32) -> flexcam::Result<TwoWays> {
    // 1. Load the scene with overrides and build its projection.
    let overrides = Overrides {
        width: Some(width),
        height: Some(height),
        ..Overrides::default()
    };
    let loaded = scene::load_with(source, &overrides)?;
    // 2. Prepare it once: every renderer reads it, nothing mutates it.
    let prepared = PreparedScene::new(&loaded.scene);
    // 3. Render it by the reference and by rasterisation, where the projection allows.
    let render = |method| {
        let options = RenderOptions {
            method,
            shading: Shading::Flat,
            ..RenderOptions::default()
        };
        render::render(&prepared, loaded.projection.as_ref(), &options).map(|r| r.frame)
    };
    let raycast = render(Method::Raycast)?;
    let raster = render(Method::Raster).and_then(|frame| {
        let agreement = compare(&frame, &raycast)?;
        Ok((frame, agreement))
    });
    Ok(TwoWays {
        warnings: loaded.build_report.warnings.clone(),
        raycast,
        raster,
        bvh_builds: prepared.bvh_builds(),
    })
}
