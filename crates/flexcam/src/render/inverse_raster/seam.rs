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
    let shifts = match period {
        // The shifts k with [x_lo + kP, x_hi + kP] meeting [0, width].
        Some(p) => (
            (-x_hi / p).ceil() as i64,
            ((size.x - x_lo) / p).floor() as i64,
        ),
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
