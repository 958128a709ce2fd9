//! The band-local G-buffer of trilinear rasterisation: the shapes of one band of rows are
//! drawn span by span ([`crate::render::scan::spans`]), each fragment finished to its exact
//! hit by the stage of [`Resolver`] and z-tested, and the band is then shaded from it
//! ([`super::shade::Shader::rows`]).
//!
//! Along a span the hit terms are stepped (the value at the next pixel centre is the value
//! here plus the span's per-pixel change, [`Span::start_and_step`]) instead of interpolated
//! pixel by pixel, and the exact case (inside the fragment's own triangle, in front of the
//! view plane) is z-tested and written without building a fragment; the general path
//! ([`Resolver::hit`]) is taken only outside the triangle. Per pixel the buffer keeps what
//! shading reads: the winner's depth (exact `t`, pushed back for a crack filler), its key,
//! and its scene barycentrics (`f32`, the precision `Hit` carries). 24 bytes a pixel.
//!
//! The z-test is the rasteriser's: the fragment wins when `(depth, key)` is
//! lexicographically smaller than the stored pair, so the result depends neither on the
//! order of the shapes nor on the band size or thread count.

use super::hit_terms::{self, Terms, TERMS};
use super::resolve::Resolver;
use crate::error::Result;
use crate::render::scan::{spans, FillRule, Polygon, RasterStats, Scratch, Span, NO_PRIMITIVE};
use crate::try_alloc;

/// How the errors of a failed buffer allocation name a band buffer of `rows` rows of an
/// image `width` pixels wide.
pub(in crate::render) fn band_name(width: u32, rows: u32) -> String {
    format!("a band buffer of {width} x {rows} pixels")
}

/// The drawn state of one band of rows: per pixel the winner's depth, key and scene
/// barycentrics. Camera-triangle rendering keeps its winners in the same buffer (its
/// `BandBuffer` wraps one), drawn by its own per-fragment stage.
#[derive(Debug, Clone)]
pub struct GBuffer {
    width: u32,
    /// The rows `[rows.0, rows.1)` of the image the buffer holds now.
    rows: (u32, u32),
    /// The winner's depth; `f64::INFINITY` where nothing was drawn.
    pub(in crate::render) depth: Vec<f64>,
    /// The winner's key; [`NO_PRIMITIVE`] where nothing was drawn.
    pub(in crate::render) keys: Vec<u64>,
    /// The winner's scene barycentrics (weights of the second and third corners); only
    /// meaningful where a key was written.
    pub(in crate::render) barycentrics: Vec<[f32; 2]>,
}

impl GBuffer {
    /// A buffer for bands of up to `rows` rows of an image `width` pixels wide. Fails when
    /// its memory cannot be had.
    pub fn new(width: u32, rows: u32) -> Result<GBuffer> {
        let n = width as usize * rows as usize;
        let what = || band_name(width, rows);
        Ok(GBuffer {
            width,
            rows: (0, 0),
            depth: try_alloc::filled(n, f64::INFINITY, what)?,
            keys: try_alloc::filled(n, NO_PRIMITIVE, what)?,
            barycentrics: try_alloc::zeroed(n, what)?,
        })
    }

    /// Empties the buffer for rows `rows` of the image (at most as many rows as it was made
    /// for). The barycentrics are not cleared: they are read only where a key was written.
    pub fn start_band(&mut self, rows: (u32, u32)) {
        let n = (rows.1 - rows.0) as usize * self.width as usize;
        self.rows = rows;
        self.depth[..n].fill(f64::INFINITY);
        self.keys[..n].fill(NO_PRIMITIVE);
    }

    /// Draws `polygon` (whose vertices carry the hit terms of its own scene triangle) into
    /// the band by the non-zero rule, finishing each fragment with `resolver`'s stage before
    /// the z-test. Returns the fragment counts (`covered`: pixels this shape was the first
    /// to cover).
    pub fn draw(
        &mut self,
        polygon: &Polygon<'_, TERMS>,
        resolver: &Resolver<'_>,
        scratch: &mut Scratch<TERMS>,
    ) -> RasterStats {
        let mut counts = RasterStats::default();
        let (rows, width) = (self.rows, self.width);
        spans(polygon, FillRule::NonZero, rows, width, scratch, |span| {
            self.span(span, polygon.primitive, resolver, &mut counts);
        });
        counts
    }

    /// One span of a shape keyed `key`. Where the terms' weight is exactly 1 along the
    /// whole span (the affine screen map), each hit is solved without dividing by it
    /// ([`hit_terms::solve_unit_weight`], the same bits). Degenerate case: the step of a
    /// one-pixel span (a line's pixel, a sliver's) may be huge or infinite where its
    /// crossings nearly coincide; it is only added after the span's last pixel, never read
    /// (and a non-finite weight step takes the general [`hit_terms::solve`]).
    #[inline]
    fn span(
        &mut self,
        span: &Span<'_, TERMS>,
        key: u64,
        resolver: &Resolver<'_>,
        counts: &mut RasterStats,
    ) {
        let (start, step) = span.start_and_step();
        let (start, step) = (&start.attributes, &step.attributes);
        if hit_terms::unit_weight_along(start, step) {
            self.span_with(
                span,
                start,
                step,
                key,
                resolver,
                counts,
                hit_terms::solve_unit_weight,
            );
        } else {
            self.span_with(span, start, step, key, resolver, counts, hit_terms::solve);
        }
    }

    /// The pixels of `span` from the terms `start` stepped by `step`, each hit solved by
    /// `solve`, staged ([`Resolver::staged`]) and z-tested against the span's cells of the
    /// buffer (sliced once: no bounds check a pixel), written where it wins. The counts are
    /// kept in locals (registers) and added once.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn span_with(
        &mut self,
        span: &Span<'_, TERMS>,
        start: &Terms,
        step: &Terms,
        key: u64,
        resolver: &Resolver<'_>,
        counts: &mut RasterStats,
        solve: impl Fn(&Terms) -> (f64, f64, f64),
    ) {
        let mut terms: Terms = *start;
        let row = (span.y - self.rows.0) as usize * self.width as usize;
        let cells = row + span.x0 as usize..row + span.x1 as usize;
        let stored = self.depth[cells.clone()]
            .iter_mut()
            .zip(&mut self.keys[cells.clone()])
            .zip(&mut self.barycentrics[cells]);
        let (mut discarded, mut writes, mut covered) = (0, 0, 0);
        for (x, ((stored_depth, stored_key), stored_barycentric)) in (span.x0..span.x1).zip(stored)
        {
            match resolver.staged(key, solve(&terms), x, span.y) {
                Some((key, depth, barycentric)) => {
                    if depth < *stored_depth || (depth == *stored_depth && key < *stored_key) {
                        writes += 1;
                        covered += u64::from(*stored_key == NO_PRIMITIVE);
                        (*stored_depth, *stored_key) = (depth, key);
                        *stored_barycentric = [barycentric.x as f32, barycentric.y as f32];
                    }
                }
                None => discarded += 1,
            }
            for (term, change) in terms.iter_mut().zip(step) {
                *term += change;
            }
        }
        counts.fragments += u64::from(span.x1 - span.x0);
        counts.discarded += discarded;
        counts.writes += writes;
        counts.covered += covered;
    }

    /// The band's rows.
    pub fn rows(&self) -> (u32, u32) {
        self.rows
    }

    pub fn width(&self) -> u32 {
        self.width
    }
}
