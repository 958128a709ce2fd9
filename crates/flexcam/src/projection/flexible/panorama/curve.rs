//! Planar curves parameterised by arc length: the outlines and profiles of shape-defined
//! panoramas (thesis 9.3).
//!
//! A curve is a chain of pieces, each a straight segment or a circular arc, so the arc length
//! of every named shape (circle, square, rounded square, vertical segment, arc) is exact; a
//! curve given by points is a chain of segments (the thesis's chord-length approximation of
//! arc length, exact for the polyline itself). [`ArcCurve::replace`] swaps a range of
//! fractions for one piece (the perspective edit of module `edit`) and keeps every other
//! fraction's point, so such a curve is arc-length parameterised outside that range only.
//!
//! Degenerate cases: pieces of zero length (repeated points, a corner radius of 0 or 1) are
//! dropped, as they take no arc length; a curve whose total length is zero, or with a
//! non-finite coordinate, is an error.

use glam::DVec2;

use crate::error::{Error, Result};

/// One piece of a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// The segment from `from` to `to`.
    Line {
        /// The point at fraction 0.
        from: DVec2,
        /// The point at fraction 1.
        to: DVec2,
    },
    /// The arc of the circle around `centre` of radius `radius` from angle `start` over the
    /// signed angle `sweep` (radians, counter-clockwise positive).
    Circular {
        /// The circle's centre.
        centre: DVec2,
        /// The circle's radius.
        radius: f64,
        /// The angle of the arc's first point, radians.
        start: f64,
        /// The signed angle the arc turns through, radians.
        sweep: f64,
    },
    /// The segment from `from` to `to` parameterised centrally: the slope y / x of the point
    /// seen from the origin is linear in the fraction (a perspective, not an arc-length,
    /// parameterisation; both ends must have x > 0). Outside [0, 1] the segment continues
    /// linearly. Made by [`ArcCurve::replace`] for the perspective edit (module `edit`).
    Central {
        /// The point at fraction 0 (x > 0).
        from: DVec2,
        /// The point at fraction 1 (x > 0).
        to: DVec2,
    },
}

impl Piece {
    /// The point at fraction `s` of the piece (outside [0, 1] the segment or circle
    /// continues).
    pub fn at(&self, s: f64) -> DVec2 {
        match *self {
            Piece::Line { from, to } => from + s * (to - from),
            Piece::Central { from, to } if (0.0..=1.0).contains(&s) => {
                // The point of the segment on the ray through (1-s) from/from.x + s to/to.x.
                ((1.0 - s) * to.x * from + s * from.x * to) / ((1.0 - s) * to.x + s * from.x)
            }
            Piece::Central { from, to } => from + s * (to - from),
            Piece::Circular {
                centre,
                radius,
                start,
                sweep,
            } => {
                let (sin, cos) = (start + s * sweep).sin_cos();
                centre + radius * DVec2::new(cos, sin)
            }
        }
    }

    /// The piece's length.
    pub fn length(&self) -> f64 {
        match *self {
            Piece::Line { from, to } | Piece::Central { from, to } => (to - from).length(),
            Piece::Circular { radius, sweep, .. } => (radius * sweep).abs(),
        }
    }

    /// The part of the piece between fractions `a` and `b`, re-parameterised over [0, 1]
    /// (exact for every kind: a central parameterisation restricted stays central).
    pub fn part(&self, a: f64, b: f64) -> Piece {
        match *self {
            Piece::Line { .. } => Piece::Line {
                from: self.at(a),
                to: self.at(b),
            },
            Piece::Central { .. } => Piece::Central {
                from: self.at(a),
                to: self.at(b),
            },
            Piece::Circular {
                centre,
                radius,
                start,
                sweep,
            } => Piece::Circular {
                centre,
                radius,
                start: start + a * sweep,
                sweep: (b - a) * sweep,
            },
        }
    }

    /// The smallest and largest distance from the origin of a point of the piece.
    fn distance_range(&self) -> (f64, f64) {
        let ends = [self.at(0.0).length(), self.at(1.0).length()];
        let (mut lo, mut hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
        match *self {
            Piece::Line { from, to } | Piece::Central { from, to } => {
                let d = to - from;
                let s = (-from.dot(d) / d.length_squared()).clamp(0.0, 1.0);
                lo = lo.min(self.at(s).length());
            }
            Piece::Circular {
                centre,
                start,
                sweep,
                ..
            } => {
                // The nearest and farthest points of the whole circle lie on the line through
                // the origin and the centre; they count where the arc reaches them.
                let toward = (-centre).to_angle();
                for angle in [toward, toward + std::f64::consts::PI] {
                    let turn = std::f64::consts::TAU;
                    let s = ((angle - start) / sweep).rem_euclid(turn / sweep.abs());
                    if s <= 1.0 {
                        let r = self.at(s).length();
                        lo = lo.min(r);
                        hi = hi.max(r);
                    }
                }
            }
        }
        (lo, hi)
    }
}

/// A curve parameterised by arc-length fraction s in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct ArcCurve {
    pieces: Vec<Piece>,
    /// The arc-length fraction at the end of each piece (the last is 1).
    ends: Vec<f64>,
    closed: bool,
}

/// Relative gap between the last and first points below which a curve counts as closed.
const CLOSE: f64 = 1e-9;

impl ArcCurve {
    /// A curve through `pieces` in order. `closed` curves must end where they start (within
    /// 1e-9 of their length). Errors: a non-finite number, zero total length, an open chain
    /// of pieces that do not meet, a closed curve that does not close.
    pub fn new(pieces: Vec<Piece>, closed: bool) -> Result<Self> {
        let finite = |p: &Piece| match *p {
            Piece::Line { from, to } | Piece::Central { from, to } => {
                from.is_finite() && to.is_finite()
            }
            Piece::Circular {
                centre,
                radius,
                start,
                sweep,
            } => centre.is_finite() && radius.is_finite() && start.is_finite() && sweep.is_finite(),
        };
        if !pieces.iter().all(finite) {
            return Err(Error::new("curve has a non-finite coordinate"));
        }
        let pieces: Vec<Piece> = pieces.into_iter().filter(|p| p.length() > 0.0).collect();
        let total: f64 = pieces.iter().map(Piece::length).sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(Error::new(
                "curve has zero length (all its points coincide)",
            ));
        }
        let gap = |a: &Piece, b: &Piece| (a.at(1.0) - b.at(0.0)).length() > CLOSE * total;
        if pieces.windows(2).any(|w| gap(&w[0], &w[1])) {
            return Err(Error::new("curve pieces do not join"));
        }
        if closed && gap(&pieces[pieces.len() - 1], &pieces[0]) {
            return Err(Error::new("closed curve does not end where it starts"));
        }
        let mut walked = 0.0;
        let mut ends: Vec<f64> = pieces
            .iter()
            .map(|p| {
                walked += p.length();
                walked / total
            })
            .collect();
        if let Some(last) = ends.last_mut() {
            *last = 1.0;
        }
        Ok(ArcCurve {
            pieces,
            ends,
            closed,
        })
    }

    /// The polyline through `points` (closed: back to the first point). Errors as
    /// [`ArcCurve::new`]; repeated points are allowed.
    pub fn polyline(points: &[DVec2], closed: bool) -> Result<Self> {
        let mut pieces: Vec<Piece> = points
            .windows(2)
            .map(|w| Piece::Line {
                from: w[0],
                to: w[1],
            })
            .collect();
        if let (true, Some(first), Some(last)) = (closed, points.first(), points.last()) {
            pieces.push(Piece::Line {
                from: *last,
                to: *first,
            });
        }
        ArcCurve::new(pieces, closed)
    }

    /// Whether the curve is closed.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The pieces of non-zero length.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The point at arc-length fraction `s`. A closed curve wraps (s modulo 1); an open one
    /// continues its first and last pieces beyond s = 0 and s = 1.
    pub fn at(&self, s: f64) -> DVec2 {
        let s = if self.closed { s.rem_euclid(1.0) } else { s };
        let i = self
            .ends
            .partition_point(|&end| end < s)
            .min(self.pieces.len() - 1);
        let start = if i == 0 { 0.0 } else { self.ends[i - 1] };
        self.pieces[i].at((s - start) / (self.ends[i] - start))
    }

    /// The curve with the part over fractions [`s0`, `s1`] (0 <= s0 < s1 <= 1; on a closed
    /// curve also s0 > s1: the part [s0, 1] and [0, s1] across its start, less than the
    /// whole curve) replaced by `piece`, which must join the curve at both ends; every other
    /// fraction keeps its point, so the parameterisation outside the range is unchanged
    /// (inside it is the piece's own, not the arc length of the new curve). Across the start
    /// the piece is split where its fraction reaches the curve's start, (1 - s0) / (1 - s0 +
    /// s1), so the piece is parameterised over the unwrapped range [s0, s1 + 1] and the
    /// curve's start moves onto the piece. Errors: a range outside [0, 1] or empty, a piece
    /// that does not meet the curve at both ends (within 1e-9 of the curve's length).
    pub fn replace(&self, [s0, s1]: [f64; 2], piece: Piece) -> Result<ArcCurve> {
        let unit = |s: f64| (0.0..=1.0).contains(&s);
        let across = self.closed && s1 < s0 && s0 - s1 < 1.0;
        if !(unit(s0) && unit(s1) && (s0 < s1 || across)) {
            return Err(Error::new(format!(
                "curve range must satisfy 0 <= start < end <= 1 (or start > end across the \
                 start of a closed curve), got [{s0}, {s1}]"
            )));
        }
        let total: f64 = self.pieces.iter().map(Piece::length).sum();
        let meets = |a: DVec2, b: DVec2| (a - b).length() <= CLOSE * total;
        if !(meets(piece.at(0.0), self.at(s0)) && meets(piece.at(1.0), self.at(s1))) {
            return Err(Error::new("replacement piece does not join the curve"));
        }
        let mut pieces = Vec::new();
        let mut ends = Vec::new();
        // The parts of the old pieces within [lo, hi], with their end fractions.
        let keep = |lo: f64, hi: f64, pieces: &mut Vec<Piece>, ends: &mut Vec<f64>| {
            let mut start: f64 = 0.0;
            for (p, &end) in self.pieces.iter().zip(&self.ends) {
                let (a, b) = (start.max(lo), end.min(hi));
                if a < b {
                    let span = end - start;
                    pieces.push(p.part((a - start) / span, (b - start) / span));
                    ends.push(b);
                }
                start = end;
            }
        };
        if across {
            let split = (1.0 - s0) / (1.0 - s0 + s1);
            if s1 > 0.0 {
                pieces.push(piece.part(split, 1.0));
                ends.push(s1);
            }
            keep(s1, s0, &mut pieces, &mut ends);
            if s0 < 1.0 {
                pieces.push(piece.part(0.0, split));
                ends.push(1.0);
            }
        } else {
            keep(0.0, s0, &mut pieces, &mut ends);
            pieces.push(piece);
            ends.push(s1);
            keep(s1, 1.0, &mut pieces, &mut ends);
        }
        Ok(ArcCurve {
            pieces,
            ends,
            closed: self.closed,
        })
    }

    /// The smallest and largest distance of a curve point from the origin.
    pub fn distance_range(&self) -> (f64, f64) {
        self.pieces
            .iter()
            .map(Piece::distance_range)
            .fold((f64::INFINITY, 0.0), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            })
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    use super::*;

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn polyline_is_parameterised_by_arc_length() {
        // Lengths 1 and 3: the corner is at a quarter of the length.
        let c = ArcCurve::polyline(&[DVec2::ZERO, DVec2::X, DVec2::new(1.0, 3.0)], false).unwrap();
        assert!(close(c.at(0.25), DVec2::X));
        assert!(close(c.at(0.125), DVec2::new(0.5, 0.0)));
        assert!(close(c.at(1.0), DVec2::new(1.0, 3.0)));
        // An open curve continues its end pieces.
        assert!(close(c.at(-0.25), DVec2::new(-1.0, 0.0)));
        assert!(close(c.at(1.25), DVec2::new(1.0, 4.0)));
        assert!(!c.is_closed());
    }

    #[test]
    fn closed_curves_wrap() {
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let c = ArcCurve::polyline(&square, true).unwrap();
        assert_eq!(c.pieces().len(), 4);
        assert!(close(c.at(0.875), DVec2::new(0.0, 0.5)));
        assert!(close(c.at(1.125), DVec2::new(0.5, 0.0)));
        assert!(close(c.at(-0.125), DVec2::new(0.0, 0.5)));
    }

    #[test]
    fn arcs_have_exact_length() {
        let arc = Piece::Circular {
            centre: DVec2::new(1.0, 0.0),
            radius: 2.0,
            start: 0.0,
            sweep: -PI,
        };
        assert!((arc.length() - TAU).abs() < 1e-15);
        let c = ArcCurve::new(vec![arc], false).unwrap();
        assert!(close(c.at(0.5), DVec2::new(1.0, -2.0)));
        assert_eq!(c.distance_range(), (1.0, 3.0));
    }

    #[test]
    fn repeated_points_take_no_length() {
        let c = ArcCurve::polyline(&[DVec2::ZERO, DVec2::ZERO, DVec2::X, DVec2::X], false).unwrap();
        assert_eq!(c.pieces().len(), 1);
        assert!(close(c.at(0.5), DVec2::new(0.5, 0.0)));
    }

    #[test]
    fn degenerate_curves_are_errors() {
        let e = ArcCurve::polyline(&[DVec2::ONE, DVec2::ONE], false).unwrap_err();
        assert!(e.message.contains("zero length"), "{e}");
        assert!(ArcCurve::polyline(&[DVec2::ONE], true).is_err());
        assert!(ArcCurve::polyline(&[], false).is_err());
        let nan = DVec2::new(f64::NAN, 0.0);
        assert!(ArcCurve::polyline(&[DVec2::ZERO, nan], false).is_err());
        let apart = vec![
            Piece::Line {
                from: DVec2::ZERO,
                to: DVec2::X,
            },
            Piece::Line {
                from: DVec2::Y,
                to: DVec2::ONE,
            },
        ];
        assert!(ArcCurve::new(apart.clone(), false).is_err());
        assert!(ArcCurve::new(apart[..1].to_vec(), true).is_err());
    }

    #[test]
    fn replace_keeps_the_other_fractions() {
        // The unit square from the origin; replace fractions [0.125, 0.375] (from (0.5, 0)
        // around the corner (1, 0) to (1, 0.5)) by the diagonal.
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let c = ArcCurve::polyline(&square, true).unwrap();
        let diagonal = Piece::Line {
            from: DVec2::new(0.5, 0.0),
            to: DVec2::new(1.0, 0.5),
        };
        let r = c.replace([0.125, 0.375], diagonal).unwrap();
        for s in [0.0, 0.1, 0.125, 0.375, 0.5, 0.9, 1.0] {
            assert!(close(r.at(s), c.at(s)), "{s}");
        }
        assert!(close(r.at(0.25), DVec2::new(0.75, 0.25)));
        assert!(r.is_closed());
        // A central piece: the slope y / x is linear in the fraction.
        let central = Piece::Central {
            from: DVec2::new(1.0, 0.0),
            to: DVec2::new(2.0, 2.0),
        };
        let mid = central.at(0.5);
        assert!((mid.y / mid.x - 0.5).abs() < 1e-15 && close(central.part(0.0, 1.0).at(0.5), mid));
        // Errors: a piece that misses the curve, an empty or outside range.
        let e = c.replace([0.1, 0.375], diagonal).unwrap_err();
        assert!(e.message.contains("does not join"), "{e}");
        assert!(c.replace([0.3, 0.3], diagonal).is_err());
        assert!(c.replace([0.5, 1.5], diagonal).is_err());
    }

    #[test]
    fn replace_across_the_start_of_a_closed_curve() {
        // The unit square from the origin; replace fractions [0.875, 1] + [0, 0.125] (from
        // (0, 0.5) around the start corner (0, 0) to (0.5, 0)) by the diagonal, which is
        // parameterised over the unwrapped range [0.875, 1.125]: the start moves to its
        // middle.
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let c = ArcCurve::polyline(&square, true).unwrap();
        let (from, to) = (DVec2::new(0.0, 0.5), DVec2::new(0.5, 0.0));
        let r = c.replace([0.875, 0.125], Piece::Line { from, to }).unwrap();
        for s in [0.125, 0.3, 0.5, 0.8, 0.875] {
            assert!(close(r.at(s), c.at(s)), "{s}");
        }
        assert!(close(r.at(0.0), DVec2::splat(0.25)) && close(r.at(1.0), r.at(0.0)));
        assert!(close(r.at(0.9375), from.lerp(to, 0.25)));
        assert!(close(r.at(0.0625), from.lerp(to, 0.75)));
        // An open curve has no start to cross; a range of the whole curve is empty.
        let open = ArcCurve::polyline(&square, false).unwrap();
        assert!(open.replace([0.9, 0.1], Piece::Line { from, to }).is_err());
        assert!(c.replace([1.0, 0.0], Piece::Line { from, to }).is_err());
    }

    #[test]
    fn distance_range_finds_interior_extremes() {
        let c = ArcCurve::polyline(&[DVec2::new(-1.0, 2.0), DVec2::new(1.0, 2.0)], false).unwrap();
        let (lo, hi) = c.distance_range();
        assert!((lo - 2.0).abs() < 1e-15 && (hi - 5f64.sqrt()).abs() < 1e-15);
    }
}
