//! The software polygon rasteriser shared by the fast renderers: shapes in continuous pixel
//! coordinates (polygons of any shape, or two-vertex lines) with a depth and `N` attributes
//! per vertex, scan-converted at pixel centres by an explicit [`FillRule`] with a top-left tie
//! rule into spans ([`spans`]) that each renderer z-tests and shades its own way.
//!
//! - [`polygon`]: the input ([`Vertex`], [`Polygon`], [`PolygonBatch`]);
//! - [`fill`]: polygon coverage, the fill and tie rules, and attribute interpolation;
//! - [`line`](mod@line): one-pixel-wide lines for two-vertex shapes;
//! - `reference` and `target` (tests only): the reference rasteriser, one fragment at a time
//!   into a z-buffered target, that the renderers' scan conversion is checked against;
//! - [`fused`]: the image cut into bands drawn in parallel into small band-local buffers,
//!   each shaded into the output [`crate::render::Frame`] at once (deferred shading without
//!   frame-sized buffers);
//! - [`stats`]: counters for `--stats`.
//!
//! A renderer may rewrite each fragment before its z-test (an exact per-pixel depth instead
//! of the interpolated one) or discard it.
//!
//! Determinism: a pixel keeps the fragment with the smallest `(depth, primitive)` pair, and
//! every fragment's position and values depend only on its own shape, so the image does not
//! depend on the band size or the number of threads, and with distinct primitive keys not on
//! the order of the shapes either. Shaders must be pure functions of the fragment.

pub mod fill;
pub mod fused;
pub mod interpolate;
pub mod line;
pub mod polygon;
#[cfg(test)]
mod reference;
pub mod stats;
#[cfg(test)]
pub mod target;
#[cfg(test)]
mod tests;

pub use fill::{FillRule, Scratch, Span};
pub use fused::{band_rows_for, for_each_band, FrameRows};
pub use polygon::{Polygon, PolygonBatch, Vertex, LIMIT, NO_PRIMITIVE};
#[cfg(test)]
pub use reference::{rasterize, rasterize_parallel, rasterize_parallel_resolved, BAND_ROWS};
pub use stats::RasterStats;
#[cfg(test)]
pub use target::{id_of, Fragment, Target};

use rayon::prelude::*;

use polygon::Kind;

/// The shapes reaching each band of `band_rows` rows (at least 1) of an image `height` rows
/// tall, in input order: their row ranges in parallel, then a serial pass over the ranges.
fn bins<const N: usize>(
    polygons: &PolygonBatch<N>,
    height: u32,
    band_rows: u32,
) -> Vec<Vec<usize>> {
    let ranges: Vec<(u32, u32)> = (0..polygons.len())
        .into_par_iter()
        .map(|i| polygons.get(i).rows(height))
        .collect();
    let mut bins = vec![Vec::new(); height.div_ceil(band_rows) as usize];
    for (i, &(first, end)) in ranges.iter().enumerate() {
        if first < end {
            for bin in &mut bins[(first / band_rows) as usize..=((end - 1) / band_rows) as usize] {
                bin.push(i);
            }
        }
    }
    bins
}

/// Calls `emit` with the runs of pixel centres that `polygon` covers in rows
/// `rows.0..rows.1` and columns `0..width`, row by row, left to right, each pixel in at most
/// one span: a polygon's by `rule` (`scan`), a line's pixels one by one ([`line`](mod@line)),
/// none for a shape that is not drawn. For renderers that run their own stage and z-test
/// along a span (see [`Span::start_and_step`]) instead of one fragment at a time.
pub fn spans<const N: usize>(
    polygon: &Polygon<'_, N>,
    rule: FillRule,
    rows: (u32, u32),
    width: u32,
    scratch: &mut Scratch<N>,
    mut emit: impl FnMut(&Span<'_, N>),
) {
    match polygon.kind() {
        Kind::Fill => fill::fill_spans(polygon, rule, rows, width, scratch, emit),
        Kind::Line => line::line(
            &polygon.vertices[0],
            &polygon.vertices[1],
            rows,
            width,
            |x, y, values| emit(&Span::pixel(x, y, &values)),
        ),
        Kind::Skip => {}
    }
}
