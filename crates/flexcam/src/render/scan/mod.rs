//! The software polygon rasteriser shared by the fast renderers: shapes in continuous pixel
//! coordinates (polygons of any shape, or two-vertex lines) with a depth and `N` attributes
//! per vertex, scan-converted at pixel centres by an explicit [`FillRule`] with a top-left tie
//! rule, z-tested and shaded into a [`Target`].
//!
//! - [`polygon`]: the input ([`Vertex`], [`Polygon`], [`PolygonBatch`]);
//! - [`fill`]: polygon coverage, the fill and tie rules, and attribute interpolation;
//! - [`line`](mod@line): one-pixel-wide lines for two-vertex shapes;
//! - [`target`]: the z-buffered target and [`Fragment`]s;
//! - [`fused`]: the image cut into bands drawn in parallel into small band-local buffers,
//!   each shaded into the output [`crate::render::Frame`] at once (deferred shading without
//!   frame-sized buffers);
//! - [`stats`]: counters for `--stats`.
//!
//! A *stage* (see `rasterize_parallel_staged`) may rewrite each fragment before its z-test
//! (an exact per-pixel depth instead of the interpolated one) or discard it.
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
pub mod stats;
pub mod target;
#[cfg(test)]
mod tests;

use glam::Vec3;
use rayon::prelude::*;

pub use fill::{FillRule, Scratch, Span};
pub use fused::{band_rows_for, for_each_band, FrameRows};
pub use interpolate::Varying;
pub use polygon::{Polygon, PolygonBatch, Vertex, LIMIT};
pub use stats::RasterStats;

use stats::FragmentCounts;
pub use target::{Fragment, Layers, Target, NO_PRIMITIVE};

use polygon::Kind;
use target::Band;

/// Rows per band in [`rasterize_parallel`]: enough for little per-band overhead on small
/// shapes, few enough for many tasks on typical images.
pub const BAND_ROWS: u32 = 16;

/// Draws `polygons` into `target` in order on the calling thread, shading each fragment that
/// passes the z-test with `shader`. Returns what was done (`covered` counts the whole
/// target after the pass).
pub fn rasterize<const N: usize>(
    target: &mut Target,
    polygons: &PolygonBatch<N>,
    rule: FillRule,
    shader: &impl Fn(&Fragment<N>) -> Vec3,
) -> RasterStats {
    let mut stats = RasterStats::of_shapes(polygons);
    let mut scratch = Scratch::default();
    let mut band = target.band();
    for polygon in polygons.iter() {
        let counts = draw(&mut band, &polygon, rule, &mut scratch, &keep, shader);
        stats.add_fragments(counts);
    }
    stats.covered = target.covered();
    stats
}

/// Like [`rasterize`], with the target cut into bands of `band_rows` rows drawn in parallel
/// (rayon), each band by one task drawing the shapes that reach it in input order. The result
/// is bit for bit that of [`rasterize`], whatever the thread count or band size.
pub fn rasterize_parallel<const N: usize>(
    target: &mut Target,
    polygons: &PolygonBatch<N>,
    rule: FillRule,
    band_rows: u32,
    shader: &(impl Fn(&Fragment<N>) -> Vec3 + Sync),
) -> RasterStats {
    rasterize_parallel_resolved(target, polygons, rule, band_rows, &keep, shader)
}

/// Keeps every fragment as interpolated (the resolve step of plain rasterisation).
fn keep<const N: usize>(_: &mut Fragment<N>) -> bool {
    true
}

/// [`rasterize_parallel`] with a resolve step run on every covered fragment before its
/// z-test: `resolve` may replace the interpolated depth and attributes (a renderer that
/// computes exact per-pixel values from the fragment's primitive) or discard the fragment by
/// returning `false` (counted in [`RasterStats::discarded`]). It must be a pure function of
/// the fragment, like the shader, for the result to stay deterministic.
pub fn rasterize_parallel_resolved<const N: usize>(
    target: &mut Target,
    polygons: &PolygonBatch<N>,
    rule: FillRule,
    band_rows: u32,
    resolve: &(impl Fn(&mut Fragment<N>) -> bool + Sync),
    shader: &(impl Fn(&Fragment<N>) -> Vec3 + Sync),
) -> RasterStats {
    let band_rows = band_rows.max(1);
    let bins = bins(polygons, target.height(), band_rows);
    let counts = target
        .bands(band_rows)
        .into_par_iter()
        .zip(bins)
        .map(|(mut band, bin)| {
            let mut scratch = Scratch::default();
            bin.iter().fold(FragmentCounts::default(), |sum, &i| {
                let polygon = polygons.get(i);
                sum + draw(&mut band, &polygon, rule, &mut scratch, resolve, shader)
            })
        })
        .reduce(FragmentCounts::default, |a, b| a + b);
    let mut stats = RasterStats::of_shapes(polygons);
    stats.add_fragments(counts);
    stats.covered = target.covered();
    stats
}

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

/// Draws one shape into the rows of `band`, resolving each fragment before its z-test.
fn draw<const N: usize>(
    band: &mut Band<'_>,
    polygon: &Polygon<'_, N>,
    rule: FillRule,
    scratch: &mut Scratch<N>,
    resolve: &impl Fn(&mut Fragment<N>) -> bool,
    shader: &impl Fn(&Fragment<N>) -> Vec3,
) -> FragmentCounts {
    let mut counts = FragmentCounts::default();
    let (rows, width) = (band.rows, band.width);
    spans(polygon, rule, rows, width, scratch, |span| {
        for x in span.x0..span.x1 {
            let mut fragment = Fragment {
                x,
                y: span.y,
                varying: span.at(x),
                object: polygon.object,
                primitive: polygon.primitive,
            };
            counts.fragments += 1;
            if resolve(&mut fragment) {
                counts.writes += u64::from(band.test_and_write(&fragment, shader));
            } else {
                counts.discarded += 1;
            }
        }
    });
    counts
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
