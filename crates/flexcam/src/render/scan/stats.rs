//! What a rasterisation pass did, for `--stats`.

use super::polygon::{Kind, PolygonBatch};
use crate::render::{Counter, Stats};

/// Counters of one or more rasterisation passes; they add up across bands and passes and do
/// not depend on the thread count or band size.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RasterStats {
    /// Shapes of three or more vertices filled.
    pub polygons: u64,
    /// Two-vertex shapes drawn as lines.
    pub lines: u64,
    /// Shapes not drawn: fewer than two vertices, or a NaN, infinite or huge component.
    pub skipped: u64,
    /// Pixel centres covered by some shape, each tested against the z-buffer.
    pub fragments: u64,
    /// Fragments that passed the z-test and were shaded and written.
    pub writes: u64,
    /// Fragments dropped by a resolve step before the z-test (see
    /// [`super::rasterize_parallel_resolved`]).
    pub discarded: u64,
    /// Pixels of the target holding a fragment after the pass.
    pub covered: u64,
}

impl RasterStats {
    /// The shape counts of a batch (polygons, lines, skipped), the other counts zero.
    pub fn of_shapes<const N: usize>(polygons: &PolygonBatch<N>) -> RasterStats {
        let mut stats = RasterStats::default();
        for polygon in polygons.iter() {
            match polygon.kind() {
                Kind::Fill => stats.polygons += 1,
                Kind::Line => stats.lines += 1,
                Kind::Skip => stats.skipped += 1,
            }
        }
        stats
    }

    /// Adds `other`'s counts to these (`covered` too: callers set it once per pass).
    pub fn add(&mut self, other: &RasterStats) {
        self.polygons += other.polygons;
        self.lines += other.lines;
        self.skipped += other.skipped;
        self.fragments += other.fragments;
        self.writes += other.writes;
        self.discarded += other.discarded;
        self.covered += other.covered;
    }

    /// Fragments per covered pixel (1 = no overdraw); 0 when nothing is covered.
    pub fn overdraw(&self) -> f64 {
        if self.covered == 0 {
            0.0
        } else {
            self.fragments as f64 / self.covered as f64
        }
    }

    /// Inserts the counters into `stats` under `raster_*` names.
    pub fn record(&self, stats: &mut Stats) {
        for (name, value) in [
            ("raster_polygons", self.polygons),
            ("raster_lines", self.lines),
            ("raster_skipped", self.skipped),
            ("raster_fragments", self.fragments),
            ("raster_discarded", self.discarded),
            ("raster_writes", self.writes),
            ("raster_covered", self.covered),
        ] {
            stats.insert(name, Counter::Count(value));
        }
        stats.insert("raster_overdraw", Counter::Value(self.overdraw()));
    }
}
