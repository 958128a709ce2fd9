//! Which camera triangle each pixel belongs to: the one whose screen triangle covers the pixel
//! centre, the lowest-numbered where several do (as [`Trilinear::ray`] picks it, so that
//! overlapping screen triangles, e.g. a reflector hiding part of itself, give the ray
//! caster's rays). A fragment of any other camera triangle at that pixel is killed.
//!
//! A centre counts as covered within [`EDGE_TOLERANCE`] of the screen triangle in
//! barycentrics, so that a centre on an edge two triangles share is never lost to rounding
//! (the lower-numbered takes it; on a continuous mesh both give the same ray there).
//!
//! [`Trilinear::ray`]: crate::projection::Trilinear

use glam::DVec2;
use rayon::prelude::*;

use super::camera::Camera;
use crate::error::Result;
use crate::render::frame_name;
use crate::try_alloc;

/// No camera triangle covers the pixel.
pub const NONE: u32 = u32::MAX;

/// How far outside a screen triangle (in its barycentrics) a pixel centre still counts.
const EDGE_TOLERANCE: f64 = 1e-9;

/// The owner of every pixel of a `width` x `height` image, row-major. Fails when the
/// memory cannot be had.
pub fn owners(cameras: &[Camera], width: u32, height: u32) -> Result<Vec<u32>> {
    let n = width as usize * height as usize;
    let mut out = try_alloc::filled(n, NONE, || {
        format!(
            "the camera triangle of each pixel of {}",
            frame_name(width, height)
        )
    })?;
    if width == 0 {
        return Ok(out);
    }
    let boxes: Vec<((u32, u32), (u32, u32))> = cameras
        .iter()
        .map(|c| {
            let (lo, hi) = c.pixel_box;
            let range = |lo: f64, hi: f64, max: u32| {
                let first = (lo - 0.5).floor().clamp(0.0, f64::from(max)) as u32;
                let end = (hi + 0.5).ceil().clamp(0.0, f64::from(max)) as u32;
                (first, end)
            };
            (range(lo.x, hi.x, width), range(lo.y, hi.y, height))
        })
        .collect();
    out.par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            for (index, (camera, &(xs, ys))) in cameras.iter().zip(&boxes).enumerate() {
                if y < ys.0 || y >= ys.1 {
                    continue;
                }
                for x in xs.0..xs.1 {
                    let cell = &mut row[x as usize];
                    if *cell != NONE {
                        continue;
                    }
                    let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let b = camera.map.barycentrics(centre);
                    let inside = b.x >= -EDGE_TOLERANCE
                        && b.y >= -EDGE_TOLERANCE
                        && b.x + b.y <= 1.0 + EDGE_TOLERANCE;
                    if inside {
                        *cell = index as u32;
                    }
                }
            }
        });
    Ok(out)
}
