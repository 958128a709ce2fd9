//! The pixel centres a screen triangle covers, and the screen triangles of a frame sorted
//! into horizontal bands, for the band-by-band fill of [`super::band_fill`].
//!
//! Nearly every piece of a finely tessellated model covers one or two pixel centres (the
//! panorama workload's 31,730 screen triangles cover about as many pixels), so the general
//! polygon scan of `render::scan` (edge list, crossing list, sort, interpolated
//! attributes, one shared bin list) costs far more than the centres themselves. [`cover`]
//! is that scan specialised to one triangle without attributes: the same fill and tie rule
//! computed by the same floating-point expressions, so it covers exactly the centres the
//! rasteriser covers (test `coverage_is_the_rasterisers`).

use glam::DVec2;

use crate::render::scan::LIMIT;

/// One screen triangle to fill: its corners in continuous pixel coordinates and the
/// primitive key of its scene triangle (`fragment::key`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenTriangle {
    pub corners: [DVec2; 3],
    pub key: u64,
}

impl ScreenTriangle {
    /// Whether every coordinate is finite and within the rasteriser's [`LIMIT`]; others
    /// are not drawn (as the rasteriser skips them).
    pub fn is_valid(&self) -> bool {
        self.corners
            .iter()
            .all(|p| p.x.abs() <= LIMIT && p.y.abs() <= LIMIT)
    }

    /// The rows `[first, end)` of an image of `height` rows whose centres the triangle may
    /// cover (those with `y + 0.5` in `[min y, max y)`).
    fn rows(&self, height: u32) -> (u32, u32) {
        let [a, b, c] = self.corners;
        centre_range(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), height)
    }
}

/// The pixels `[first, end)` of `0..max` whose centre `i + 0.5` lies in `[lo, hi)`, as the
/// rasteriser's scan counts them (`v - 0.5` is exact for `0.25 <= v < 2^53`; below only
/// pixel 0 is at stake and it is included either way, above everything is past `max`).
fn centre_range(lo: f64, hi: f64, max: u32) -> (u32, u32) {
    let bound = |v: f64| v.clamp(0.0, f64::from(max)) as u32;
    (bound((lo - 0.5).ceil()), bound((hi - 0.5).ceil()))
}

/// Calls `emit(x, y)` for every pixel centre of rows `rows.0..rows.1` and columns
/// `0..width` that `triangle` covers, row by row, left to right.
///
/// The rule is the rasteriser's (`render::scan::fill`, which a triangle's fill and tie
/// rules reduce to): an edge takes part in row `y` when `top.y <= y + 0.5 < bottom.y`, its
/// crossing is interpolated from its top end, and the centres in `[left crossing, right
/// crossing)` are covered. A row through a triangle meets exactly two of its
/// non-horizontal edges (the long edge spans the rows of the two others, which split it
/// half-open), with opposite orientations, so the winding number between them is never
/// zero and the even-odd and non-zero rules agree.
///
/// Degenerate cases: a triangle with all corners on one horizontal line covers nothing (no
/// edge takes part); a zero-width row (both crossings equal) covers nothing; the caller
/// skips triangles that are not [`ScreenTriangle::is_valid`].
pub fn cover(
    triangle: &ScreenTriangle,
    rows: (u32, u32),
    width: u32,
    mut emit: impl FnMut(u32, u32),
) {
    let mut edges = [(DVec2::ZERO, DVec2::ZERO); 3];
    let mut count = 0;
    for (i, &a) in triangle.corners.iter().enumerate() {
        let b = triangle.corners[(i + 1) % 3];
        if a.y != b.y {
            edges[count] = if a.y < b.y { (a, b) } else { (b, a) };
            count += 1;
        }
    }
    let edges = &edges[..count];
    let (first, end) = triangle.rows(rows.1);
    for y in first.max(rows.0)..end {
        let yc = f64::from(y) + 0.5;
        let mut crossings = [0.0; 2];
        let mut found = 0;
        for &(top, bottom) in edges {
            if top.y <= yc && yc < bottom.y && found < 2 {
                let s = (yc - top.y) / (bottom.y - top.y);
                crossings[found] = top.x + s * (bottom.x - top.x);
                found += 1;
            }
        }
        if found < 2 {
            continue;
        }
        let [left, right] = if crossings[1] < crossings[0] {
            [crossings[1], crossings[0]]
        } else {
            crossings
        };
        let (x0, x1) = centre_range(left, right, width);
        for x in x0..x1 {
            emit(x, y);
        }
    }
}

/// Screen triangles sorted into bands of rows: a triangle goes into every band holding a
/// row whose centres it may cover, in the order pushed. Kept from frame to frame (cleared,
/// not freed) so that a frame allocates nothing once the bins have grown.
#[derive(Debug, Default)]
pub struct Bins {
    bands: Vec<Vec<ScreenTriangle>>,
}

impl Bins {
    /// Empties the bins and sets their number to `bands`.
    pub fn reset(&mut self, bands: usize) {
        self.bands.resize_with(bands, Vec::new);
        for band in &mut self.bands {
            band.clear();
        }
    }

    /// Adds `triangle` to the bands of `band_rows` rows (of an image `height` rows high)
    /// it may cover a centre in; returns whether it went into any. `band_rows` >= 1.
    pub fn push(&mut self, triangle: ScreenTriangle, band_rows: u32, height: u32) -> bool {
        let (first, end) = triangle.rows(height);
        if first >= end {
            return false;
        }
        let bands = (first / band_rows) as usize..=((end - 1) / band_rows) as usize;
        for band in &mut self.bands[bands] {
            band.push(triangle);
        }
        true
    }

    /// The triangles of band `band`, in the order pushed (empty past the last band).
    pub fn band(&self, band: usize) -> &[ScreenTriangle] {
        self.bands.get(band).map_or(&[], Vec::as_slice)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use proptest::prelude::*;

    use super::*;
    use crate::render::scan::{rasterize, FillRule, PolygonBatch, Target, Vertex};

    const SIZE: (u32, u32) = (24, 16);

    /// Pixels as `(x, y)`.
    type Pixels = Vec<(u32, u32)>;

    /// The centres `cover` finds over the whole image, and those `render::scan` fills.
    fn both(corners: [DVec2; 3]) -> (Pixels, Pixels) {
        let triangle = ScreenTriangle { corners, key: 7 };
        let mut ours = Vec::new();
        cover(&triangle, (0, SIZE.1), SIZE.0, |x, y| ours.push((x, y)));
        let mut target = Target::new(SIZE.0, SIZE.1, Vec3::ZERO);
        let mut batch = PolygonBatch::<0>::new();
        batch.push(&corners.map(|p| Vertex::new(p.x, p.y, 0.0, [])), 7);
        rasterize(&mut target, &batch, FillRule::NonZero, &|_| Vec3::ONE);
        let theirs = (0..SIZE.1)
            .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
            .filter(|&(x, y)| target.primitive(x, y).is_some())
            .collect();
        (ours, theirs)
    }

    /// Coordinates on a quarter-pixel grid (centres, edges and in between, so that ties
    /// on edges and corners are frequent) or anywhere, partly off the image.
    fn coordinate(max: f64) -> impl Strategy<Value = f64> {
        prop_oneof![
            (-8i32..(4.0 * max) as i32 + 8).prop_map(|q| f64::from(q) / 4.0),
            -2.0..max + 2.0,
        ]
    }

    fn corner() -> impl Strategy<Value = DVec2> {
        (coordinate(f64::from(SIZE.0)), coordinate(f64::from(SIZE.1)))
            .prop_map(|(x, y)| DVec2::new(x, y))
    }

    proptest! {
        #[test]
        fn coverage_is_the_rasterisers(a in corner(), b in corner(), c in corner()) {
            let (ours, theirs) = both([a, b, c]);
            prop_assert_eq!(ours, theirs);
        }

        /// Tiny triangles (the common case), with either winding.
        #[test]
        fn tiny_coverage_is_the_rasterisers(
            a in corner(),
            d in prop::array::uniform4(-1.5f64..1.5),
        ) {
            let (b, c) = (a + DVec2::new(d[0], d[1]), a + DVec2::new(d[2], d[3]));
            let (ours, theirs) = both([a, b, c]);
            prop_assert_eq!(ours, theirs);
        }
    }

    /// Two triangles tiling a square cover each centre in it once; degenerate triangles
    /// (horizontal, a point, a vertical segment) cover nothing.
    #[test]
    fn shared_edges_and_degenerate_triangles() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let (upper, _) = both([p(1.5, 1.5), p(5.5, 1.5), p(1.5, 5.5)]);
        let (lower, _) = both([p(5.5, 1.5), p(5.5, 5.5), p(1.5, 5.5)]);
        let mut all = [upper.clone(), lower.clone()].concat();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), upper.len() + lower.len());
        assert_eq!(all.len(), 16);
        assert!(both([p(1.0, 2.5), p(9.0, 2.5), p(4.0, 2.5)]).0.is_empty());
        assert!(both([p(2.5, 2.5); 3]).0.is_empty());
        assert!(both([p(2.5, 1.0), p(2.5, 6.0), p(2.5, 3.0)]).0.is_empty());
    }

    #[test]
    fn bins_hold_triangles_in_every_band_they_reach() {
        let at = |y0: f64, y1: f64| ScreenTriangle {
            corners: [
                DVec2::new(1.0, y0),
                DVec2::new(3.0, y0),
                DVec2::new(2.0, y1),
            ],
            key: 0,
        };
        let mut bins = Bins::default();
        bins.reset(3);
        // Rows 6 and 7 (band 1 of 4-row bands), rows 3 and 4 (bands 0 and 1).
        assert!(bins.push(at(5.6, 7.9), 4, 12));
        assert!(bins.push(at(3.2, 4.9), 4, 12));
        // No centre row (between 8.5 and 9.5), and below the image: in no band.
        assert!(!bins.push(at(8.6, 9.4), 4, 12));
        assert!(!bins.push(at(20.0, 30.0), 4, 12));
        assert_eq!(bins.band(0), &[at(3.2, 4.9)]);
        assert_eq!(bins.band(1), &[at(5.6, 7.9), at(3.2, 4.9)]);
        assert!(bins.band(2).is_empty() && bins.band(5).is_empty());
        bins.reset(2);
        assert!(bins.band(1).is_empty());
        // Invalid coordinates are recognised.
        let mut bad = at(1.0, 2.0);
        bad.corners[1].x = f64::NAN;
        assert!(!bad.is_valid() && at(1.0, 2.0).is_valid());
    }
}
