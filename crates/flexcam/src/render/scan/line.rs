//! Lines: the shapes of two vertices (a polygon seen edge-on), drawn one pixel wide.
//!
//! A DDA over pixel centres along the major axis (x when `|dx| >= |dy|`, else y): every
//! column (row) whose cells the closed segment meets gets one pixel, the one containing the
//! segment's point at the column's (row's) centre, clamped to the segment. Lines are thus
//! connected and one pixel thick, and a segment shorter than a pixel still draws one pixel.
//! Depth and attributes are interpolated linearly along the segment. The endpoints are put
//! in a canonical order first, so a line and its reverse draw the same fragments.

use super::interpolate::Varying;
use super::polygon::{pixel_bound, Vertex};

/// Calls `emit(x, y, varying)` for the pixels of the line from `a` to `b` in rows
/// `rows.0..rows.1` and columns `0..width`, each at most once. The vertices must be finite
/// and bounded (see [`super::LIMIT`]).
pub(super) fn line<const N: usize>(
    a: &Vertex<N>,
    b: &Vertex<N>,
    rows: (u32, u32),
    width: u32,
    mut emit: impl FnMut(u32, u32, Varying<N>),
) {
    let d = (b.position - a.position).abs();
    let x_major = d.x >= d.y;
    // (major, minor) coordinates.
    let axes = |v: &Vertex<N>| {
        if x_major {
            (v.position.x, v.position.y)
        } else {
            (v.position.y, v.position.x)
        }
    };
    let (a, b) = if axes(a) <= axes(b) { (a, b) } else { (b, a) };
    let ((p0, q0), (p1, q1)) = (axes(a), axes(b));
    let (major_range, minor_range) = if x_major {
        ((0, width), rows)
    } else {
        (rows, (0, width))
    };
    let first = pixel_bound(p0.floor(), major_range.1).max(major_range.0);
    let end = pixel_bound(p1.floor() + 1.0, major_range.1);
    for m in first..end {
        let p = (f64::from(m) + 0.5).clamp(p0, p1);
        let s = if p1 > p0 { (p - p0) / (p1 - p0) } else { 0.0 };
        let q = (q0 + s * (q1 - q0)).floor();
        if q < f64::from(minor_range.0) || q >= f64::from(minor_range.1) {
            continue;
        }
        let n = q as u32;
        let (x, y) = if x_major { (m, n) } else { (n, m) };
        emit(x, y, a.varying.lerp(&b.varying, s));
    }
}
