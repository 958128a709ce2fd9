//! Scan conversion of polygons by sampling pixel centres, with an explicit fill rule, and the
//! interpolation of depth and attributes across each span.
//!
//! Coverage: the centre `(x + 0.5, y + 0.5)` of a pixel is covered when it is inside the
//! polygon by the [`FillRule`], where "inside" is decided by the polygon edges crossing the
//! horizontal line through the centre:
//! - an edge takes part in row `y` when `y_top <= y + 0.5 < y_bottom` (half-open in y, so a
//!   vertex on the line is counted once and horizontal edges never);
//! - the crossings at `x <= x + 0.5` are counted (with sign: +1 for an edge going down, -1 going
//!   up), so a centre exactly on a left edge is inside and one on a right edge is outside.
//!
//! This is the top-left tie rule: a centre on a shared edge belongs to exactly one of the two
//! polygons beside it. The crossing of an edge is computed from its top endpoint whatever
//! the polygon's winding, so both polygons find the same crossing bit for bit: polygons that
//! tile a region cover each pixel centre in it exactly once, with no cracks and no double hits.
//!
//! Interpolation (scanline edge interpolation): depth and attributes are interpolated linearly
//! along each edge to its crossing with the row, and linearly in x between the two crossings
//! that bound the pixel centre. For a triangle this is the affine (screen-space barycentric)
//! interpolation of its vertex values, up to rounding. For more vertices it is well defined for
//! any polygon, convex or not, self-intersecting or not, under either rule, but only piecewise
//! linear: it is exact for values that are affine over the polygon, and otherwise depends on
//! the scan direction, with kinks where the bounding pair of edges changes.
//!
//! Cost: `O(rows x vertices)` per polygon, meant for the small polygons (up to ~64 vertices) of
//! the fast renderers.

use glam::DVec2;

use super::interpolate::Varying;
use super::polygon::{centre_range, Polygon};

/// Which points a closed, possibly self-intersecting polygon covers, by the winding number
/// `w` of the polygon around the point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FillRule {
    /// `w` odd: regions overlapped an even number of times (the centre of a pentagram, the
    /// doubly wound part of a self-overlapping polygon) are holes.
    #[default]
    EvenOdd,
    /// `w != 0`: everything the outline encloses, however often.
    NonZero,
}

impl FillRule {
    fn inside(self, winding: i32) -> bool {
        match self {
            FillRule::EvenOdd => winding & 1 != 0,
            FillRule::NonZero => winding != 0,
        }
    }
}

/// A non-horizontal polygon edge, oriented downwards.
#[derive(Debug, Clone, Copy)]
struct Edge<const N: usize> {
    top: DVec2,
    bottom: DVec2,
    at_top: Varying<N>,
    at_bottom: Varying<N>,
    /// +1 if the polygon runs down along this edge, -1 if up.
    winding: i32,
}

/// Where an edge crosses the current row.
#[derive(Debug, Clone, Copy)]
struct Crossing<const N: usize> {
    x: f64,
    winding: i32,
    varying: Varying<N>,
}

/// Buffers reused from polygon to polygon.
#[derive(Debug, Clone, Default)]
pub struct Scratch<const N: usize> {
    edges: Vec<Edge<N>>,
    crossings: Vec<Crossing<N>>,
}

/// A run of covered pixel centres `x0..x1` (non-empty) of row `y`, between two crossings of
/// a shape's outline with the row, and the values interpolated along it.
#[derive(Debug, Clone, Copy)]
pub struct Span<'a, const N: usize> {
    pub y: u32,
    pub x0: u32,
    pub x1: u32,
    /// The left crossing's x and the reciprocal of the crossings' distance (0 for a single
    /// pixel of a line, whose values are `left`'s).
    left_x: f64,
    per_x: f64,
    left: &'a Varying<N>,
    right: &'a Varying<N>,
}

impl<const N: usize> Span<'_, N> {
    /// The values at pixel centre `x` (`x0 <= x < x1`): linear between the two crossings,
    /// clamped to them.
    #[inline]
    pub fn at(&self, x: u32) -> Varying<N> {
        let u = ((f64::from(x) + 0.5 - self.left_x) * self.per_x).clamp(0.0, 1.0);
        self.left.lerp(self.right, u)
    }

    /// The values at pixel centre `x0` ([`Span::at`]) and their change from one pixel to the
    /// next: the value at `x0 + k` is `start + k step` up to rounding, for callers stepping
    /// along the span instead of interpolating each pixel on its own. The steps are finite
    /// (the values are bounded by [`super::LIMIT`], the crossings at least a pixel centre
    /// apart where the span has two pixels or more).
    #[inline]
    pub fn start_and_step(&self) -> (Varying<N>, Varying<N>) {
        let start = self.at(self.x0);
        let step = Varying {
            depth: (self.right.depth - self.left.depth) * self.per_x,
            attributes: std::array::from_fn(|i| {
                (self.right.attributes[i] - self.left.attributes[i]) * self.per_x
            }),
        };
        (start, step)
    }

    /// The one-pixel span of pixel `(x, y)` with `values`: a pixel of a line.
    pub(super) fn pixel(x: u32, y: u32, values: &Varying<N>) -> Span<'_, N> {
        Span {
            y,
            x0: x,
            x1: x + 1,
            left_x: f64::from(x) + 0.5,
            per_x: 0.0,
            left: values,
            right: values,
        }
    }
}

/// Calls `emit` with the spans of pixel centres in rows `rows.0..rows.1` and columns
/// `0..width` that `polygon` covers by `rule`, row by row, left to right, each pixel in at
/// most one span. The polygon must be of
/// [`super::polygon::Kind::Fill`] (finite, bounded vertices).
pub(super) fn fill_spans<const N: usize>(
    polygon: &Polygon<'_, N>,
    rule: FillRule,
    rows: (u32, u32),
    width: u32,
    scratch: &mut Scratch<N>,
    mut emit: impl FnMut(&Span<'_, N>),
) {
    let vertices = polygon.vertices;
    scratch.edges.clear();
    for (i, a) in vertices.iter().enumerate() {
        let b = &vertices[(i + 1) % vertices.len()];
        let (top, bottom, winding) = if a.position.y < b.position.y {
            (a, b, 1)
        } else if a.position.y > b.position.y {
            (b, a, -1)
        } else {
            continue; // horizontal: never crosses a row through its own height
        };
        scratch.edges.push(Edge {
            top: top.position,
            bottom: bottom.position,
            at_top: top.varying,
            at_bottom: bottom.varying,
            winding,
        });
    }
    let (lo, hi) = scratch
        .edges
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| {
            (lo.min(e.top.y), hi.max(e.bottom.y))
        });
    let (first, end) = centre_range(lo, hi, rows.1);
    for y in first.max(rows.0)..end {
        let yc = f64::from(y) + 0.5;
        scratch.crossings.clear();
        scratch.crossings.extend(
            scratch
                .edges
                .iter()
                .filter(|e| e.top.y <= yc && yc < e.bottom.y)
                .map(|e| {
                    // In [0, 1]: top.y <= yc < bottom.y.
                    let s = (yc - e.top.y) / (e.bottom.y - e.top.y);
                    Crossing {
                        x: e.top.x + s * (e.bottom.x - e.top.x),
                        winding: e.winding,
                        varying: e.at_top.lerp(&e.at_bottom, s),
                    }
                }),
        );
        // Stable: crossings at the same x stay in edge order, so the output is deterministic.
        scratch.crossings.sort_by(|a, b| a.x.total_cmp(&b.x));
        let mut winding = 0;
        for pair in scratch.crossings.windows(2) {
            let (left, right) = (&pair[0], &pair[1]);
            winding += left.winding;
            if !rule.inside(winding) {
                continue;
            }
            let (x0, x1) = centre_range(left.x, right.x, width);
            if x1 > x0 {
                // x1 > x0 implies right.x > left.x: the reciprocal is finite.
                emit(&Span {
                    y,
                    x0,
                    x1,
                    left_x: left.x,
                    per_x: 1.0 / (right.x - left.x),
                    left: &left.varying,
                    right: &right.varying,
                });
            }
        }
    }
}
