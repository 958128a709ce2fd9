//! The named outlines and profiles of shape-defined panoramas, and outlines and profiles
//! given by points, as arc-length curves.
//!
//! Coordinates: an outline lies in the horizontal plane of the camera, as (x, y) = (right,
//! forward) from the eye; a profile lies in a vertical half-plane, as (x, y) = (distance from
//! the up axis, height). Every outline is parameterised from the seam, where it crosses the
//! ray straight behind the eye (0, -1), through the left (-1, 0), the front (0, 1) at half
//! its length for the symmetric shapes, and the right: u = 1/2 is the view direction and u
//! grows to the right of the image, as in the cylindrical and equirectangular presets. A
//! profile runs from v = 0 (the bottom of the image) to v = 1 (the top) in the order given.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec2;

use super::curve::{ArcCurve, Piece};
use crate::error::{Error, Result};

/// An outline: a closed curve around the eye.
#[derive(Debug, Clone, PartialEq)]
pub enum OutlineShape {
    /// The unit circle (cylindrical and spherical panoramas).
    Circle,
    /// The square of half-width 1 (the cubic panorama: four 90-degree perspective views).
    Square,
    /// The square of half-width 1 with corners rounded to quarter circles of radius `radius`
    /// in [0, 1] (0: the square, 1: the circle).
    RoundedSquare {
        /// Corner radius, in [0, 1].
        radius: f64,
    },
    /// The polygon through `points`, listed in either direction; it must go once around the
    /// eye (the origin) without passing through it.
    Points(Vec<DVec2>),
}

/// A profile: an open curve in the half-plane of distance from the up axis and height.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileShape {
    /// The vertical segment at distance 1 from the axis between the elevations `elevation`
    /// (radians, within (-90, 90) degrees, increasing): the cylindrical and cubic profiles.
    Segment {
        /// The lowest and highest elevation, radians.
        elevation: [f64; 2],
    },
    /// The unit-radius arc between the elevations `elevation` (radians, within [-90, 90]
    /// degrees, increasing): [-90, 90] degrees is the semicircle of the spherical panorama.
    Arc {
        /// The lowest and highest elevation, radians.
        elevation: [f64; 2],
    },
    /// The polyline through `points`, from the bottom of the image to the top.
    Points(Vec<DVec2>),
}

impl OutlineShape {
    /// The outline as a closed arc-length curve starting at the seam. Errors: a corner
    /// radius outside [0, 1]; a point list with fewer than three points, a non-finite point,
    /// no area, passing through the eye or not going once around it.
    pub fn curve(&self) -> Result<ArcCurve> {
        match self {
            OutlineShape::Circle => rounded_square(1.0),
            OutlineShape::Square => rounded_square(0.0),
            OutlineShape::RoundedSquare { radius } => {
                if !(0.0..=1.0).contains(radius) {
                    return Err(Error::new(format!(
                        "rounded square corner radius must lie in [0, 1], got {radius}"
                    )));
                }
                rounded_square(*radius)
            }
            OutlineShape::Points(points) => polygon(points),
        }
    }
}

impl ProfileShape {
    /// The profile as an open arc-length curve. Errors: elevations out of range or not
    /// increasing; a point list with fewer than two distinct points or a non-finite point.
    pub fn curve(&self) -> Result<ArcCurve> {
        match *self {
            ProfileShape::Segment {
                elevation: [lo, hi],
            } => {
                check_elevations("segment", [lo, hi], false)?;
                ArcCurve::polyline(
                    &[DVec2::new(1.0, lo.tan()), DVec2::new(1.0, hi.tan())],
                    false,
                )
            }
            ProfileShape::Arc {
                elevation: [lo, hi],
            } => {
                check_elevations("arc", [lo, hi], true)?;
                let arc = Piece::Circular {
                    centre: DVec2::ZERO,
                    radius: 1.0,
                    start: lo,
                    sweep: hi - lo,
                };
                ArcCurve::new(vec![arc], false)
            }
            ProfileShape::Points(ref points) => {
                if points.len() < 2 {
                    return Err(Error::new(format!(
                        "a profile needs at least 2 points, got {}",
                        points.len()
                    )));
                }
                ArcCurve::polyline(points, false)
                    .map_err(|e| Error::new(format!("profile {}", e.message)))
            }
        }
    }
}

/// Elevations `[lo, hi]` must increase and lie within +-90 degrees (`poles`: reaching them
/// is allowed).
fn check_elevations(what: &str, [lo, hi]: [f64; 2], poles: bool) -> Result<()> {
    let limit = FRAC_PI_2 * (1.0 + 1e-12);
    let inside = |a: f64| {
        if poles {
            a.abs() <= limit
        } else {
            a.abs() < FRAC_PI_2
        }
    };
    if lo.is_finite() && hi.is_finite() && inside(lo) && inside(hi) && lo < hi {
        Ok(())
    } else {
        let range = if poles { "[-90, 90]" } else { "(-90, 90)" };
        Err(Error::new(format!(
            "{what} profile elevations must increase within {range} degrees, got [{}, {}]",
            lo.to_degrees(),
            hi.to_degrees()
        )))
    }
}

/// The square of half-width 1 with corners of radius `r` in [0, 1], from the seam (0, -1)
/// through the left, front and right (clockwise in the (right, forward) plane).
fn rounded_square(r: f64) -> Result<ArcCurve> {
    let inner = 1.0 - r;
    // Corner centres in order back-left, front-left, front-right, back-right, each with the
    // angle at which its arc starts; each arc turns clockwise by 90 degrees.
    let corners = [
        (DVec2::new(-inner, -inner), -FRAC_PI_2),
        (DVec2::new(-inner, inner), PI),
        (DVec2::new(inner, inner), FRAC_PI_2),
        (DVec2::new(inner, -inner), 0.0),
    ];
    let mut pieces = Vec::with_capacity(9);
    let mut at = DVec2::new(0.0, -1.0);
    for (centre, start) in corners {
        let arc = Piece::Circular {
            centre,
            radius: r,
            start,
            sweep: -FRAC_PI_2,
        };
        pieces.push(Piece::Line {
            from: at,
            to: arc.at(0.0),
        });
        pieces.push(arc);
        at = arc.at(1.0);
    }
    pieces.push(Piece::Line {
        from: at,
        to: DVec2::new(0.0, -1.0),
    });
    ArcCurve::new(pieces, true)
}

/// The polygon through `points` as an outline: oriented clockwise in the (right, forward)
/// plane and started at its crossing of the backward ray nearest the eye.
fn polygon(points: &[DVec2]) -> Result<ArcCurve> {
    if points.len() < 3 {
        return Err(Error::new(format!(
            "an outline needs at least 3 points, got {}",
            points.len()
        )));
    }
    if !points.iter().all(|p| p.is_finite()) {
        return Err(Error::new("outline has a non-finite point"));
    }
    let edges = || (0..points.len()).map(|i| (points[i], points[(i + 1) % points.len()]));
    let size = points.iter().map(|p| p.length()).fold(0.0, f64::max);
    let through_eye = edges().any(|(a, b)| {
        let d = b - a;
        let s = if d == DVec2::ZERO {
            0.0
        } else {
            (-a.dot(d) / d.length_squared()).clamp(0.0, 1.0)
        };
        (a + s * d).length() <= 1e-12 * size
    });
    if through_eye {
        return Err(Error::new(
            "outline passes through the eye (the origin): its projectors there have no length",
        ));
    }
    // Winding number about the origin by the angle swept along the edges.
    let swept: f64 = edges().map(|(a, b)| a.perp_dot(b).atan2(a.dot(b))).sum();
    let winding = (swept / TAU).round();
    if winding.abs() != 1.0 {
        return Err(Error::new(format!(
            "outline must go once around the eye (the origin); it goes around {} times",
            winding.abs()
        )));
    }
    let mut ordered: Vec<DVec2> = points.to_vec();
    if winding > 0.0 {
        ordered.reverse();
    }
    // The crossings of the backward ray x = 0, y < 0: the one nearest the eye is the seam.
    let n = ordered.len();
    let seam = (0..n)
        .filter_map(|i| {
            let (a, b) = (ordered[i], ordered[(i + 1) % n]);
            if (a.x > 0.0) == (b.x > 0.0) && a.x != 0.0 && b.x != 0.0 {
                return None;
            }
            let s = if a.x == b.x { 0.0 } else { a.x / (a.x - b.x) };
            let y = a.y + s * (b.y - a.y);
            (y < 0.0).then_some((i, DVec2::new(0.0, y)))
        })
        .max_by(|a, b| a.1.y.total_cmp(&b.1.y));
    let Some((edge, start)) = seam else {
        return Err(Error::new("outline does not cross the ray behind the eye"));
    };
    let mut chain = vec![start];
    chain.extend((1..=n).map(|k| ordered[(edge + k) % n]));
    ArcCurve::polyline(&chain, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn circle_starts_behind_and_passes_left_front_right() {
        let c = OutlineShape::Circle.curve().unwrap();
        assert!(close(c.at(0.0), DVec2::new(0.0, -1.0)));
        assert!(close(c.at(0.25), DVec2::new(-1.0, 0.0)));
        assert!(close(c.at(0.5), DVec2::new(0.0, 1.0)));
        assert!(close(c.at(0.75), DVec2::new(1.0, 0.0)));
        let a = 0.3 * TAU - PI;
        assert!(close(c.at(0.3), DVec2::new(a.sin(), a.cos())));
    }

    #[test]
    fn square_faces_are_linear_in_u() {
        let c = OutlineShape::Square.curve().unwrap();
        // The front face spans u in [3/8, 5/8].
        for k in 0..=8 {
            let x = -1.0 + 0.25 * f64::from(k);
            assert!(close(c.at(0.5 + x / 8.0), DVec2::new(x, 1.0)));
        }
        assert!(close(c.at(0.125), DVec2::new(-1.0, -1.0)));
        assert!(close(c.at(0.875), DVec2::new(1.0, -1.0)));
    }

    #[test]
    fn rounded_square_ends_are_square_and_circle() {
        let half = OutlineShape::RoundedSquare { radius: 0.5 }.curve().unwrap();
        assert_eq!(half.pieces().len(), 9);
        // The middle of the front-right corner arc, symmetric about the diagonal.
        let p = half.at(0.625);
        assert!((p.x - p.y).abs() < 1e-12);
        assert!(close(p, DVec2::splat(0.5 + 0.5 * 0.5f64.sqrt())));
        let circle = OutlineShape::RoundedSquare { radius: 1.0 }.curve().unwrap();
        let reference = OutlineShape::Circle.curve().unwrap();
        for s in [0.1, 0.4, 0.77] {
            assert!(close(circle.at(s), reference.at(s)));
        }
        let square = OutlineShape::RoundedSquare { radius: 0.0 }.curve().unwrap();
        assert_eq!(square.pieces().len(), 5);
        assert!(OutlineShape::RoundedSquare { radius: 1.5 }.curve().is_err());
        assert!(OutlineShape::RoundedSquare { radius: -0.1 }
            .curve()
            .is_err());
    }

    #[test]
    fn point_outlines_are_oriented_and_started_at_the_seam() {
        let counter = vec![
            DVec2::new(2.0, -1.0),
            DVec2::new(2.0, 3.0),
            DVec2::new(-2.0, 3.0),
            DVec2::new(-2.0, -1.0),
        ];
        let mut clockwise = counter.clone();
        clockwise.reverse();
        for points in [counter, clockwise] {
            let c = OutlineShape::Points(points).curve().unwrap();
            assert!(close(c.at(0.0), DVec2::new(0.0, -1.0)));
            // Length 16: the back-left corner is 2 along.
            assert!(close(c.at(2.0 / 16.0), DVec2::new(-2.0, -1.0)));
            assert!(close(c.at(0.5), DVec2::new(0.0, 3.0)));
        }
    }

    #[test]
    fn bad_point_outlines_are_errors() {
        let outline = |p: &[[f64; 2]]| {
            OutlineShape::Points(p.iter().map(|&q| DVec2::from_array(q)).collect()).curve()
        };
        let e = outline(&[[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]).unwrap_err();
        assert!(e.message.contains("around the eye"), "{e}");
        let e = outline(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).unwrap_err();
        assert!(e.message.contains("passes through the eye"), "{e}");
        assert!(outline(&[[1.0, 1.0], [-1.0, 1.0]]).is_err());
        assert!(outline(&[[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]]).is_err());
        assert!(outline(&[[1.0, f64::INFINITY], [-1.0, 1.0], [0.0, -1.0]]).is_err());
        // Twice around the eye.
        let mut twice = Vec::new();
        for k in 0..10 {
            let a = TAU * f64::from(k) / 5.0 + 0.1;
            twice.push([a.cos(), a.sin()]);
        }
        assert!(outline(&twice).unwrap_err().message.contains("2 times"));
    }

    #[test]
    fn profiles_run_from_bottom_to_top() {
        let s = ProfileShape::Segment {
            elevation: [-FRAC_PI_2 / 2.0, FRAC_PI_2 / 2.0],
        }
        .curve()
        .unwrap();
        assert!(close(s.at(0.0), DVec2::new(1.0, -1.0)));
        assert!(close(s.at(0.75), DVec2::new(1.0, 0.5)));
        let a = ProfileShape::Arc {
            elevation: [-FRAC_PI_2, FRAC_PI_2],
        }
        .curve()
        .unwrap();
        assert!(close(a.at(0.0), DVec2::new(0.0, -1.0)));
        assert!(close(a.at(0.5), DVec2::X));
        assert!(close(a.at(0.75), DVec2::splat(0.5f64.sqrt())));
    }

    #[test]
    fn bad_profiles_are_errors() {
        let seg = |lo: f64, hi: f64| {
            ProfileShape::Segment {
                elevation: [lo.to_radians(), hi.to_radians()],
            }
            .curve()
        };
        assert!(seg(-90.0, 10.0).is_err());
        assert!(seg(10.0, 10.0).is_err());
        assert!(seg(20.0, 10.0).is_err());
        let arc = |lo: f64, hi: f64| {
            ProfileShape::Arc {
                elevation: [lo.to_radians(), hi.to_radians()],
            }
            .curve()
        };
        assert!(arc(-90.0, 90.0).is_ok());
        assert!(arc(-91.0, 0.0).is_err());
        let points = |p: Vec<DVec2>| ProfileShape::Points(p).curve();
        assert!(points(vec![DVec2::ONE]).is_err());
        assert!(points(vec![DVec2::ONE, DVec2::ONE])
            .unwrap_err()
            .message
            .starts_with("profile curve has zero length"));
    }
}
