//! Rasterising straight into a [`Frame`], band by band: each band of rows is drawn into a
//! small band-local target (a G-buffer that stays in a core's cache) and finished into the
//! frame's rows at once by a caller's pass (deferred shading), instead of drawing a
//! frame-sized [`super::Target`] and walking it again. No frame-sized buffer other than the
//! frame itself is allocated, and every pixel's memory is touched by one pass.
//!
//! Determinism: a band draws the shapes reaching it in input order, exactly as
//! [`super::rasterize_parallel_resolved`] does, so the drawn values are bit for bit those of
//! [`super::rasterize`] whatever the band size or thread count; the finish pass must be a
//! pure function of the drawn rows for the frame to be too.

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::polygon::PolygonBatch;
use super::scan::{FillRule, Scratch};
use super::stats::{FragmentCounts, RasterStats};
use super::target::{Fragment, Target, NO_PRIMITIVE};
use super::{bins, count_shapes, draw};
use crate::render::Frame;

/// Pixels per band of [`rasterize_into_frame`] (see [`band_rows_for`]): a band-local target
/// (32 bytes a pixel) of about 256 KiB, half a core's L2 cache on the machines we measure.
const BAND_PIXELS: u32 = 8192;

/// The rows per band for an image `width` pixels wide: about [`BAND_PIXELS`] pixels, at
/// least one row and at most 64.
pub fn band_rows_for(width: u32) -> u32 {
    (BAND_PIXELS / width.max(1)).clamp(1, 64)
}

/// Rows `[rows.0, rows.1)` of the image as drawn: row-major, `width` pixels a row, the first
/// element at row `rows.0`.
#[derive(Debug)]
pub struct DrawnRows<'a> {
    pub width: u32,
    pub rows: (u32, u32),
    /// The shader's colour of each winner; the target's background where nothing was drawn.
    pub color: &'a [Vec3],
    /// The winner's depth; `f64::INFINITY` where nothing was drawn.
    pub depth: &'a [f64],
    /// The winner's object id; 0 where nothing was drawn.
    pub ids: &'a [u32],
    /// The winner's primitive key; [`NO_PRIMITIVE`] where nothing was drawn.
    pub primitives: &'a [u64],
}

/// The same rows of the output frame, to be written by the finish pass.
#[derive(Debug)]
pub struct FrameRows<'a> {
    pub width: u32,
    pub rows: (u32, u32),
    pub color: &'a mut [Vec3],
    pub depth: &'a mut [f32],
    pub ids: &'a mut [u32],
}

/// Where the time of [`rasterize_into_frame`] went, summed over bands (so over threads: CPU
/// seconds, not wall time).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BandTimes {
    /// Drawing shapes (coverage, resolve step, z-test).
    pub draw_s: f64,
    /// The finish pass.
    pub finish_s: f64,
}

/// Draws `polygons` as [`super::rasterize_parallel_resolved`] would into a target with
/// `background` colour, `band_rows` rows at a time (in parallel, rayon), and hands each band,
/// once drawn, to `finish` with the same rows of `frame` (which must be as large as the
/// image) to write; `finish`'s results are summed. Returns the raster counts (`covered` over
/// the whole image), the sum of `finish`'s results and where the time went.
#[allow(clippy::too_many_arguments)]
pub fn rasterize_into_frame<const N: usize, C>(
    frame: &mut Frame,
    polygons: &PolygonBatch<N>,
    rule: FillRule,
    band_rows: u32,
    background: Vec3,
    resolve: &(impl Fn(&mut Fragment<N>) -> bool + Sync),
    shader: &(impl Fn(&Fragment<N>) -> Vec3 + Sync),
    finish: &(impl Fn(&DrawnRows<'_>, FrameRows<'_>) -> C + Sync),
) -> (RasterStats, C, BandTimes)
where
    C: Default + Send + std::ops::Add<Output = C>,
{
    let (width, height) = (frame.width, frame.height);
    let band_rows = band_rows.max(1);
    let bins = bins(polygons, height, band_rows);
    let n = (band_rows as usize * width as usize).max(1);
    let zero = || {
        (
            FragmentCounts::default(),
            0u64,
            C::default(),
            BandTimes::default(),
        )
    };
    let (counts, covered, out, times) = frame
        .color
        .par_chunks_mut(n)
        .zip(frame.depth.par_chunks_mut(n))
        .zip(frame.ids.par_chunks_mut(n))
        .zip(bins)
        .enumerate()
        .map_init(
            || {
                (
                    Target::new(width, band_rows, background),
                    Scratch::default(),
                )
            },
            |(buffer, scratch), (i, (((color, depth), ids), bin))| {
                let start = Instant::now();
                let first = i as u32 * band_rows;
                let rows = (first, first + (color.len() / width as usize) as u32);
                let mut band = buffer.band_at(rows, background);
                let counts = bin.iter().fold(FragmentCounts::default(), |sum, &k| {
                    sum + draw(&mut band, &polygons.get(k), rule, scratch, resolve, shader)
                });
                let drawn = band.into_drawn();
                let covered = drawn
                    .primitives
                    .iter()
                    .filter(|&&p| p != NO_PRIMITIVE)
                    .count() as u64;
                let finishing = Instant::now();
                let out = finish(
                    &drawn,
                    FrameRows {
                        width,
                        rows,
                        color,
                        depth,
                        ids,
                    },
                );
                let times = BandTimes {
                    draw_s: (finishing - start).as_secs_f64(),
                    finish_s: finishing.elapsed().as_secs_f64(),
                };
                (counts, covered, out, times)
            },
        )
        .reduce(zero, |a, b| {
            (
                a.0 + b.0,
                a.1 + b.1,
                a.2 + b.2,
                BandTimes {
                    draw_s: a.3.draw_s + b.3.draw_s,
                    finish_s: a.3.finish_s + b.3.finish_s,
                },
            )
        });
    let mut stats = count_shapes(polygons);
    stats.add_fragments(counts);
    stats.covered = covered;
    (stats, out, times)
}
