//! Rasterising straight into a [`Frame`], band by band: the image is cut into bands of rows,
//! and each band's shapes are drawn into a small band-local buffer (a G-buffer that stays in
//! a core's cache) by the caller, who shades it at once into the frame's rows (deferred
//! shading), instead of drawing a frame-sized [`super::Target`] and walking it again. No
//! frame-sized buffer other than the frame itself is allocated, and every pixel's memory is
//! touched by one pass. `--method trilinear` draws with [`super::spans`] into its own
//! G-buffer (`render::trilinear::gbuffer`).
//!
//! Determinism: each band gets the shapes reaching it in input order, whatever the band size
//! or thread count; a caller whose drawing and shading are pure functions of the shapes gets
//! the same frame whatever the thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::bins;
use super::polygon::PolygonBatch;
use crate::error::Result;
use crate::render::Frame;

/// Pixels per band (see [`band_rows_for`]): a band-local buffer of 24 to 32 bytes a pixel
/// is then about 200 to 256 KiB, well inside a core's L2 cache on the machines we measure.
const BAND_PIXELS: u32 = 8192;

/// The rows per band for an image `width` pixels wide: about `BAND_PIXELS` pixels, at
/// least one row and at most 64.
pub fn band_rows_for(width: u32) -> u32 {
    (BAND_PIXELS / width.max(1)).clamp(1, 64)
}

/// Rows `[rows.0, rows.1)` of the output frame (row-major, `width` pixels a row, the first
/// element at row `rows.0`), to be written by a band's shading.
#[derive(Debug)]
pub struct FrameRows<'a> {
    pub width: u32,
    pub rows: (u32, u32),
    pub color: &'a mut [Vec3],
    pub depth: &'a mut [f32],
    pub ids: &'a mut [u32],
}

/// Cuts `frame` (whose buffers must match its size) into bands of `band_rows` rows, at
/// least one, and calls `band(state, shapes, rows)` for each, in parallel (rayon), with the
/// indices of the shapes of `polygons` reaching the band in input order and the band's rows
/// of the frame; `state` is per-thread scratch made by `init` (band-local buffers reused
/// from band to band). Returns the sum of the results. Renderers draw each band's shapes
/// into their own band buffer (see [`super::spans`]) and shade it into the rows. Fails when
/// `init` fails (its buffers' memory cannot be had); the frame's rows are then partly drawn.
pub fn for_each_band<const N: usize, S, C>(
    frame: &mut Frame,
    polygons: &PolygonBatch<N>,
    band_rows: u32,
    init: impl Fn() -> Result<S> + Sync + Send,
    band: impl Fn(&mut S, &[usize], FrameRows<'_>) -> C + Sync + Send,
) -> Result<C>
where
    C: Default + Send + std::ops::Add<Output = C>,
{
    let (width, height) = (frame.width, frame.height);
    let band_rows = band_rows.max(1);
    let bins = bins(polygons, height, band_rows);
    let n = (band_rows as usize * width as usize).max(1);
    frame
        .color
        .par_chunks_mut(n)
        .zip(frame.depth.par_chunks_mut(n))
        .zip(frame.ids.par_chunks_mut(n))
        .zip(bins)
        .enumerate()
        .map_init(init, |state, (i, (((color, depth), ids), bin))| {
            let state = state.as_mut().map_err(|e| e.clone())?;
            let first = i as u32 * band_rows;
            let rows = (first, first + (color.len() / width as usize) as u32);
            let out = FrameRows {
                width,
                rows,
                color,
                depth,
                ids,
            };
            Ok(band(state, &bin, out))
        })
        .try_reduce(C::default, |a, b| Ok(a + b))
}
