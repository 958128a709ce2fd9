//! `--method raycast`, the reference ray caster: every pixel's projector traced through the
//! prepared scene's BVH ([`PreparedScene`]), tiles rendered in parallel. [`render`] renders
//! a projection into a new frame, [`render_into`] into a frame the caller keeps.
//! See docs/raycast.md for the design and the measurements.

mod curve;
mod hull_cull;
mod pick;
pub(in crate::render) mod pieces;
pub(crate) mod sampling;
mod shade;
mod tiles;
// Bench scenes, for `flexcam bench` and the criterion benches only (`bench_support`).
#[cfg(any(test, feature = "workloads"))]
pub mod workloads;

use glam::DVec3;

pub(in crate::render) use self::pick::{first_hit, ProjectorHit};
pub use self::pick::{pick, Picked};
pub(crate) use self::sampling::SamplePattern;

use self::pieces::polyline_segment;
use crate::error::Result;
use crate::geometry::Ray;
use crate::projection::Projection;
use crate::render::prepared::{Hit32, PreparedScene};
use crate::render::{Frame, PixelWindow, RenderOptions, Stats};

impl PreparedScene {
    /// The first hits of four polyline projectors (`None`: no projector) and the segments
    /// they lie on: for each, the first segment with a hit wins, and on it the nearest hit,
    /// exactly as searching the segments one by one with [`PreparedScene::intersect_f32`] finds
    /// it. Segment k of the four is searched by one shared BVH traversal
    /// ([`Bvh::closest4`]), leaving out the polylines that have hit something already or have
    /// fewer segments, and the segments that `live` rules out. Degenerate cases: a
    /// zero-length segment sees nothing (and the next segment is searched); a hit exactly at
    /// a joint, the end of segment k and the start of segment k + 1, is segment k's (both
    /// ends of a segment's interval are closed); a joint on a triangle is such a hit.
    fn intersect4_polylines(
        &self,
        polylines: [Option<&[DVec3]>; 4],
        live: hull_cull::LiveParts,
    ) -> [Option<(usize, Hit32)>; 4] {
        let segments = polylines
            .iter()
            .flatten()
            .map(|p| p.len().saturating_sub(1))
            .max()
            .unwrap_or(0);
        let mut found: [Option<(usize, Hit32)>; 4] = [None; 4];
        for k in (0..segments).filter(|&k| live.may_hit(k)) {
            let rays: [Option<Ray>; 4] = std::array::from_fn(|i| match polylines[i] {
                Some(p) if found[i].is_none() && k + 1 < p.len() => Some(polyline_segment(p, k)),
                _ => None,
            });
            let hits = self.intersect4_f32(rays.each_ref().map(Option::as_ref));
            for (slot, hit) in found.iter_mut().zip(hits) {
                if let Some(hit) = hit {
                    *slot = Some((k, hit));
                }
            }
        }
        found
    }
}

/// Renders `projection` (colour, depth and object ids) with `options` into a new frame
/// (see [`render_into`]). The frame starts as zeroed memory
/// (`Frame::zeroed`), not cleared to the background: every pixel is written. Fails only
/// when the frame's memory cannot be had.
pub fn render(
    scene: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<(Frame, Stats)> {
    let window = window_of(projection, options);
    let mut frame = Frame::zeroed(window.width(), window.height(), options.outputs)?;
    let stats = render_into(scene, &mut frame, projection, options)?;
    Ok((frame, stats))
}

/// Renders `projection` (colour, depth and object ids) with `options` into `frame`, every
/// pixel of it overwritten, in parallel over tiles; the image does not depend on the
/// number of threads, nor on what `frame` held. A caller drawing frame after frame keeps
/// one frame and pays neither its allocation nor the first touch of its pages again; a
/// frame of another size than the projection's resolution (or whose buffers do not match
/// its size) is replaced by one of the right size. `options.spp = 0` counts as one
/// sample. See `shade` for what the depth and id of a pixel are. With `options.crop` the
/// frame is the window's (a window that fits in the image: `render::render` checks it).
/// Fails only when a new frame's memory cannot be had (`frame` is then left as it was).
pub fn render_into(
    scene: &PreparedScene,
    frame: &mut Frame,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<Stats> {
    let window = window_of(projection, options);
    frame.fit(window.width(), window.height(), options.outputs)?;
    let mut stats = tiles::render(scene, projection, options, window, frame);
    stats.insert(
        "bvh_build_ms",
        crate::render::Counter::Value(scene.build_ms),
    );
    stats.insert(
        "bvh_nodes",
        crate::render::Counter::Count(scene.bvh.node_count() as u64),
    );
    stats.insert(
        "triangles",
        crate::render::Counter::Count(scene.triangle_count as u64),
    );
    if let Some(displaced) = &scene.displaced {
        stats.insert(
            "displaced_triangles",
            crate::render::Counter::Count(displaced.len() as u64),
        );
    }
    Ok(stats)
}

/// The pixels `options` asks for: its crop window, or the whole image.
fn window_of(projection: &dyn Projection, options: &RenderOptions) -> PixelWindow {
    let (width, height) = projection.resolution();
    options
        .crop
        .unwrap_or_else(|| PixelWindow::whole(width, height))
}

#[cfg(test)]
mod projector_tests;
#[cfg(test)]
mod tests;
