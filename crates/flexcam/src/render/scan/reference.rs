//! The reference rasteriser the tests hold the renderers' scan conversion to: shapes drawn
//! one fragment at a time, in input order (or in parallel bands with the same result), each
//! fragment z-tested and shaded into a [`Target`]. The renderers draw spans of their own
//! ([`super::spans`], [`super::for_each_band`]); this is the simple exact path they are
//! checked against.

use glam::Vec3;
use rayon::prelude::*;

use super::target::{Band, Fragment, Target};
use super::{bins, spans, FillRule, Polygon, PolygonBatch, RasterStats, Scratch};

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

impl RasterStats {
    /// Adds the fragment counts of some drawing.
    fn add_fragments(&mut self, counts: FragmentCounts) {
        self.fragments += counts.fragments;
        self.writes += counts.writes;
        self.discarded += counts.discarded;
    }
}

/// What drawing some shapes did with their fragments.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct FragmentCounts {
    pub fragments: u64,
    pub writes: u64,
    pub discarded: u64,
}

impl std::ops::Add for FragmentCounts {
    type Output = FragmentCounts;

    fn add(self, other: FragmentCounts) -> FragmentCounts {
        FragmentCounts {
            fragments: self.fragments + other.fragments,
            writes: self.writes + other.writes,
            discarded: self.discarded + other.discarded,
        }
    }
}
