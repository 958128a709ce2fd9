//! From a refined piece to the screen triangles that are filled: the panorama seam and the
//! screen cull.
//!
//! A panorama knows an image position only up to its horizontal period P (a point just left
//! of the seam and one just right of it are a whole image width apart). The corners of a
//! piece are unwrapped edge by edge (each moved by whole periods to within P/2 of the
//! previous one), which gives the piece's continuous image; if that does not close up (the
//! outline winds around a pole), the piece is dropped. A piece straddling the seam then lies
//! partly left or right of the image, so it is drawn once more shifted by P the other way,
//! and the screen clip of the rasteriser cuts both copies ("drawn twice": left and right).
//!
//! Every drawn x is `x + m P` with an integer m computed once, so two pieces sharing an edge
//! put its ends at bit-identical positions in the same copy: no crack along the seam.

use glam::DVec2;

use super::refine::unwrap;

/// What happened to one piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// Drawn this many times (0: entirely off the screen).
    Copies(u32),
    /// Its outline winds around a pole: not drawn.
    Winds,
}

/// Calls `draw` with each screen position of the piece whose corner images are `images` on
/// an image of `size` pixels (x wrapping every `period` pixels when given).
pub fn place(
    images: [DVec2; 3],
    size: DVec2,
    period: Option<f64>,
    mut draw: impl FnMut([DVec2; 3]),
) -> Placement {
    let [a, b, c] = images;
    let (xb, kb) = unwrap(b.x, a.x, period);
    let (xc, kc) = unwrap(c.x, xb, period);
    let closes = unwrap(a.x, xc, period).1 == 0;
    if !closes {
        return Placement::Winds;
    }
    let (y_lo, y_hi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
    if y_hi < 0.0 || y_lo > size.y {
        return Placement::Copies(0);
    }
    let (x_lo, x_hi) = (a.x.min(xb).min(xc), a.x.max(xb).max(xc));
    // Within 0.999 P of the edges they are measured from, both quotients below lie in
    // (-1, 0] after rounding: no shift, found without the divisions (most pieces).
    let unshifted = |p: f64| {
        let margin = 0.999 * p;
        (0.0..=margin).contains(&x_hi) && (0.0..=margin).contains(&(size.x - x_lo))
    };
    let shifts = match period {
        Some(p) if unshifted(p) => (0, 0),
        // The shifts k with [x_lo + kP, x_hi + kP] meeting [0, width].
        Some(p) => (ceil(-x_hi / p) as i64, (-ceil(-(size.x - x_lo) / p)) as i64),
        None if x_hi < 0.0 || x_lo > size.x => return Placement::Copies(0),
        None => (0, 0),
    };
    let step = period.unwrap_or(0.0);
    let mut copies = 0;
    for k in shifts.0..=shifts.1 {
        let at = |p: DVec2, m: i64| DVec2::new(p.x + (m + k) as f64 * step, p.y);
        draw([at(a, 0), at(b, kb), at(c, kc)]);
        copies += 1;
    }
    Placement::Copies(copies)
}

/// Widening of a screen triangle's box in [`covers_a_centre`], in pixels: far above the
/// rounding of the rasteriser's edge crossings, far below a pixel.
const BOX_SLACK: f64 = 1e-9;

/// Whether the box of screen triangle `corners`, widened by [`BOX_SLACK`], holds a pixel
/// centre `(i + 0.5, j + 0.5)` (any integers: the rasteriser clips to the image). A triangle
/// whose box holds none covers none, so it need not reach the rasteriser: the rasteriser
/// samples rows at centres in `[top, bottom)` and columns in `[left crossing, right
/// crossing)`, all within the box. Degenerate (zero-area, or a box thinner than the gap
/// between centres) triangles give `false` unless a centre lies in the box.
pub fn covers_a_centre(corners: [DVec2; 3]) -> bool {
    let [a, b, c] = corners;
    let (lo, hi) = (a.min(b).min(c) - BOX_SLACK, a.max(b).max(c) + BOX_SLACK);
    // The first centre at or after lo lies before hi.
    let holds = |lo: f64, hi: f64| ceil(lo - 0.5) + 0.5 < hi;
    holds(lo.x, hi.x) && holds(lo.y, hi.y)
}

/// Below this magnitude every `f64` converts to `i64` exactly, integral or not.
const EXACT_I64: f64 = 4_503_599_627_370_496.0; // 2^52

/// `v.ceil()`, computed inline by truncation below 2^52 in magnitude (on baseline x86-64
/// `ceil` is a library call, and [`place`] and [`covers_a_centre`] run for every piece).
/// Degenerate cases: -0.0 where `ceil` gives -0.0 for `v` in (-1, 0) gives +0.0 here
/// (equal as numbers and as `i64`); large, infinite and NaN `v` take `ceil` itself.
fn ceil(v: f64) -> f64 {
    if v.abs() < EXACT_I64 {
        let t = v as i64 as f64;
        if t < v {
            t + 1.0
        } else {
            t
        }
    } else {
        v.ceil()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn collect(images: [DVec2; 3], period: Option<f64>) -> (Placement, Vec<[DVec2; 3]>) {
        let mut out = Vec::new();
        let placement = place(images, DVec2::new(100.0, 50.0), period, |t| out.push(t));
        (placement, out)
    }

    #[test]
    fn inside_is_drawn_once_and_outside_not_at_all() {
        let t = [
            DVec2::new(10.0, 10.0),
            DVec2::new(20.0, 10.0),
            DVec2::new(15.0, 20.0),
        ];
        assert_eq!(collect(t, None), (Placement::Copies(1), vec![t]));
        assert_eq!(collect(t, Some(100.0)).1, vec![t]);
        let off = t.map(|p| p + DVec2::new(0.0, 100.0));
        assert_eq!(collect(off, None).0, Placement::Copies(0));
        let right = t.map(|p| p + DVec2::new(200.0, 0.0));
        assert_eq!(collect(right, None).0, Placement::Copies(0));
    }

    #[test]
    fn seam_straddler_is_drawn_on_both_sides() {
        // Corners at x = 98 and x = 3 of a 100-pixel period: 5 pixels wide across the seam.
        let t = [
            DVec2::new(98.0, 10.0),
            DVec2::new(3.0, 10.0),
            DVec2::new(99.0, 20.0),
        ];
        let (placement, copies) = collect(t, Some(100.0));
        assert_eq!(placement, Placement::Copies(2));
        assert_eq!(copies[0][1].x, 3.0);
        assert_eq!(copies[0][0].x, -2.0);
        assert_eq!(copies[1][0].x, 98.0);
        assert_eq!(copies[1][1].x, 103.0);
        // The same piece given from another corner draws the same two triangles.
        let (_, rotated) = collect([t[1], t[2], t[0]], Some(100.0));
        assert_eq!(rotated.len(), 2);
        assert!(rotated.iter().any(|r| r.contains(&DVec2::new(98.0, 10.0))));
        assert!(rotated.iter().any(|r| r.contains(&DVec2::new(103.0, 10.0))));
    }

    #[test]
    fn only_boxes_holding_a_pixel_centre_are_kept() {
        let at = |x: f64, y: f64, w: f64, h: f64| {
            [DVec2::new(x, y), DVec2::new(x + w, y), DVec2::new(x, y + h)]
        };
        // A sliver between the centres 10.5 and 11.5 in x: nothing to cover.
        assert!(!covers_a_centre(at(10.6, 3.0, 0.8, 2.0)));
        // The same sliver reaching the centre (exactly at, or just past it) is kept.
        assert!(covers_a_centre(at(10.6, 3.0, 0.9, 2.0)));
        assert!(covers_a_centre(at(10.5, 3.0, 0.0, 2.0)));
        // Thin in y likewise; negative coordinates (off the image) follow the same rule.
        assert!(!covers_a_centre(at(3.0, -2.4, 2.0, 0.8)));
        assert!(covers_a_centre(at(3.0, -2.4, 2.0, 1.0)));
        // Degenerate: a point triangle on a centre is kept, one off it is not.
        assert!(covers_a_centre(at(7.5, 7.5, 0.0, 0.0)));
        assert!(!covers_a_centre(at(7.2, 7.5, 0.0, 0.0)));
    }

    /// `ceil` is `f64::ceil` (as a number) on both sides of every kind of boundary.
    #[test]
    fn inline_ceil_is_the_librarys() {
        let big = EXACT_I64;
        for v in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            2.0 - 1e-15,
            -2.0 + 1e-15,
            1e-300,
            -1e-300,
            123456.75,
            -123456.75,
            big - 0.5,
            -(big - 0.5),
            big,
            -big,
            big * 4.0,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
        ] {
            assert_eq!(ceil(v), v.ceil(), "{v}");
        }
        assert!(ceil(f64::NAN).is_nan());
        // floor(x) = -ceil(-x), as `place` uses it.
        for v in [2.5, -2.5, 3.0, -0.25] {
            assert_eq!(-ceil(-v), v.floor(), "{v}");
        }
    }

    /// Degenerate: an outline going once around a pole has no triangle image.
    #[test]
    fn winding_around_a_pole_is_refused() {
        let t = [
            DVec2::new(0.0, 5.0),
            DVec2::new(33.0, 5.0),
            DVec2::new(66.0, 5.0),
        ];
        assert_eq!(collect(t, Some(100.0)).0, Placement::Winds);
        assert_eq!(collect(t, None).0, Placement::Copies(1));
    }
}
