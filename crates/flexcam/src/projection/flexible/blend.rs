//! Volumes of two or more control surfaces blended in t (Brosz 2011, 4.2 and 7.2): curved
//! projectors.
//!
//! - [`PiecewiseVolume`]: Q(u, v, t) is linear in t between surfaces at knots t_0 = 0 < t_1 <
//!   ... < t_{N-1} = 1 (hat-function blending): polyline projectors through every surface.
//! - [`BezierVolume`]: Q(u, v, t) = sum_i b_{i,n}(t) Q_i(u, v) with the Bernstein polynomials
//!   of degree n = N - 1 (evaluated by de Casteljau): Bezier projectors through the first and
//!   last surface only. Degree 2 gives quadratic projectors, which the ray caster intersects
//!   analytically; any degree can be rendered as a polyline of a stated number of segments.

use glam::{DVec2, DVec3};

use super::control_surface::Surface;
use crate::error::{Error, Result};
use crate::projection::{Projector, ProjectorHull};

/// Segments of the polyline that renders a Bezier volume of degree above 2 when the scene does
/// not say.
pub const DEFAULT_SEGMENTS: u32 = 16;

/// Samples per side of the grid on which a volume is checked to have a projector of non-zero
/// length.
const CHECK_SAMPLES: u32 = 17;

/// Validates `surfaces` (named `surface 1`, `surface 2`, ... in messages) and checks that at
/// least one projector on a 17 x 17 grid of (u, v) has non-zero length: otherwise every
/// projector is a point and nothing can be seen.
pub(super) fn check_surfaces(surfaces: &[Surface]) -> Result<()> {
    for (i, s) in surfaces.iter().enumerate() {
        s.validate()
            .map_err(|e| Error::new(format!("flexible surface {} {}", i + 1, e.message)))?;
    }
    let n = f64::from(CHECK_SAMPLES - 1);
    let any_length = (0..CHECK_SAMPLES).any(|i| {
        (0..CHECK_SAMPLES).any(|j| {
            let uv = DVec2::new(f64::from(i) / n, f64::from(j) / n);
            let first = surfaces[0].point(uv);
            surfaces[1..].iter().any(|s| s.point(uv) != first)
        })
    });
    if any_length {
        Ok(())
    } else {
        Err(Error::new(
            "flexible control surfaces coincide: every projector has zero length",
        ))
    }
}

/// Whether `points` (the control points of a projector) describe a projector: they do not
/// all coincide (a projector of zero length) and are finite.
fn is_projector(points: &[DVec3]) -> bool {
    let moves = points.iter().any(|p| *p != points[0]);
    moves && points.iter().all(|p| p.is_finite())
}

/// The control points of the projector of (u, v): each surface's point. `None` when they
/// are not a projector ([`is_projector`]).
fn control_points(surfaces: &[Surface], uv: DVec2) -> Option<Vec<DVec3>> {
    let points: Vec<DVec3> = surfaces.iter().map(|s| s.point(uv)).collect();
    is_projector(&points).then_some(points)
}

/// Sets `out` to the polyline through `vertices`, refilling the vertex buffer of a
/// polyline that `out` already holds instead of allocating one.
fn set_polyline(out: &mut Option<Projector>, vertices: impl Iterator<Item = DVec3>) {
    match out {
        Some(Projector::Polyline(buffer)) => {
            buffer.clear();
            buffer.extend(vertices);
        }
        _ => *out = Some(Projector::Polyline(vertices.collect())),
    }
}

/// Surfaces whose control points [`with_control_points`] keeps on the stack.
const STACK_SURFACES: usize = 8;

/// `f` of the control points of the projector of (u, v), as [`control_points`] gives them,
/// held on the stack for up to [`STACK_SURFACES`] surfaces (this runs once per pixel).
fn with_control_points<R>(
    surfaces: &[Surface],
    uv: DVec2,
    f: impl FnOnce(&[DVec3]) -> R,
) -> Option<R> {
    if surfaces.len() > STACK_SURFACES {
        return control_points(surfaces, uv).map(|points| f(&points));
    }
    let mut stack = [DVec3::ZERO; STACK_SURFACES];
    let points = &mut stack[..surfaces.len()];
    for (point, surface) in points.iter_mut().zip(surfaces) {
        *point = surface.point(uv);
    }
    is_projector(points).then(|| f(points))
}

/// [`ProjectorHull::pad`] relative to the sum of the surfaces' [`Surface::bilinear_scale`]s.
/// A control point of a projector is a surface point, or a sum of surface points with
/// non-negative weights summing to 1; either is rounded by a few ulps of that sum, below
/// 1e-14 of it, so the pad is generous by four orders of magnitude.
const HULL_PAD: f64 = 1e-10;

/// The hull of the projectors (`projector(uv)`) of every (u, v) in the rectangle `[lo, hi]`
/// of a volume whose control points are fixed linear combinations, with non-negative
/// weights summing to 1, of the points of `surfaces` at (u, v) (each polyline vertex and
/// each Bezier control point is). When every surface is bilinear in (u, v), so is every
/// control point, and over the rectangle it is a convex combination of its values at the
/// rectangle's corners. Degenerate cases, each giving `None`: a curved surface; a corner
/// without a projector; coefficients so large that evaluating a point could overflow; and
/// a rectangle where some (u, v) inside might have a projector of zero length (all
/// surfaces meeting): unless some surface stays more than twice the pad away from the first
/// one in one coordinate at all four corners, hence everywhere inside.
fn projector_hull(
    surfaces: &[Surface],
    lo: DVec2,
    hi: DVec2,
    projector: impl Fn(DVec2) -> Option<Projector>,
) -> Option<ProjectorHull> {
    let scale: f64 = surfaces
        .iter()
        .map(Surface::bilinear_scale)
        .sum::<Option<f64>>()?;
    if scale.is_nan() || scale >= f64::MAX / 64.0 {
        return None;
    }
    let pad = HULL_PAD * scale;
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let apart = surfaces[1..].iter().any(|surface| {
        let gaps = corners.map(|uv| surface.point(uv) - surfaces[0].point(uv));
        let (min, max) = gaps
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), g| {
                (lo.min(*g), hi.max(*g))
            });
        min.cmpgt(DVec3::splat(2.0 * pad)).any() || max.cmplt(DVec3::splat(-2.0 * pad)).any()
    });
    if !apart {
        return None;
    }
    let [a, b, c, d] = corners.map(projector);
    Some(ProjectorHull {
        corners: [a?, b?, c?, d?],
        pad,
    })
}

/// Reduces the de Casteljau pyramid of `points` (at least two) at `t` in place down to its
/// last two points and returns them.
fn reduce_to_pair(points: &mut Vec<DVec3>, t: f64) -> (DVec3, DVec3) {
    while points.len() > 2 {
        for i in 0..points.len() - 1 {
            points[i] = points[i].lerp(points[i + 1], t);
        }
        points.pop();
    }
    (points[0], points[1])
}

/// The Bernstein weights C(n, i) t^i (1 - t)^(n - i), i = 0..=n, of the `n + 1` control
/// points of a degree-n Bezier curve at `t`. For t in [0, 1] they are non-negative and sum to
/// 1, so the weighted sum of the control points is as well conditioned as de Casteljau's
/// lerps; at t = 0 and t = 1 one weight is exactly 1 and the others exactly 0, so the end
/// points come out exactly. Degenerate case: n = 0 gives the single weight 1.
fn bernstein_weights(n: u32, t: f64) -> Vec<f64> {
    let n = n as i32;
    let mut binomial = 1.0;
    (0..=n)
        .map(|i| {
            let w = binomial * t.powi(i) * (1.0 - t).powi(n - i);
            binomial = binomial * f64::from(n - i) / f64::from(i + 1);
            w
        })
        .collect()
}

/// sum_i weights[i] points[i] (the shorter of the two decides the count).
fn weighted_sum(weights: &[f64], points: &[DVec3]) -> DVec3 {
    weights
        .iter()
        .zip(points)
        .fold(DVec3::ZERO, |sum, (w, p)| sum + *w * *p)
}

/// Piecewise-linear blending of surfaces at knots in t.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseVolume {
    surfaces: Vec<Surface>,
    knots: Vec<f64>,
}

impl PiecewiseVolume {
    /// Surfaces at `knots` (default: equally spaced). Errors: fewer than 2 surfaces; knots
    /// whose count differs from the surfaces', that do not start at 0 and end at 1, or do not
    /// increase strictly; invalid or everywhere coincident surfaces (see `check_surfaces`).
    /// Two successive surfaces may coincide at some or all (u, v): that piece of the
    /// projector has zero length and sees nothing.
    pub fn new(surfaces: Vec<Surface>, knots: Option<Vec<f64>>) -> Result<Self> {
        let n = surfaces.len();
        if n < 2 {
            return Err(Error::new(format!(
                "a piecewise flexible volume needs at least 2 surfaces, got {n}"
            )));
        }
        let knots = knots.unwrap_or_else(|| (0..n).map(|i| i as f64 / (n - 1) as f64).collect());
        if knots.len() != n {
            return Err(Error::new(format!(
                "flexible knots must give one t per surface: {} knots for {n} surfaces",
                knots.len()
            )));
        }
        let increasing = knots.windows(2).all(|w| w[0] < w[1]);
        if knots[0] != 0.0 || knots[n - 1] != 1.0 || !increasing {
            return Err(Error::new(format!(
                "flexible knots must increase strictly from 0 to 1, got {knots:?}"
            )));
        }
        check_surfaces(&surfaces)?;
        Ok(PiecewiseVolume { surfaces, knots })
    }

    /// The control surfaces, near to far (each on the volume at its knot).
    pub fn surfaces(&self) -> &[Surface] {
        &self.surfaces
    }

    /// The t of each control surface, increasing from 0 to 1.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The piece that `t` falls in: `i` with knots[i] <= t <= knots[i+1] (t below 0 or
    /// above 1 extrapolates the first or last piece), and the local parameter in it.
    fn piece(&self, t: f64) -> (usize, f64) {
        let last = self.knots.len() - 2;
        let i = self.knots[1..=last].partition_point(|&k| k <= t).min(last);
        let (a, b) = (self.knots[i], self.knots[i + 1]);
        (i, (t - a) / (b - a))
    }

    /// Q(u, v, t).
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        let (i, s) = self.piece(t);
        self.surfaces[i]
            .point(uv)
            .lerp(self.surfaces[i + 1].point(uv), s)
    }

    /// dQ/dt at (u, v, t): constant within a piece. At an inner knot (where the projector has
    /// a corner) it is the derivative of the piece that starts there.
    pub fn tangent(&self, uv: DVec2, t: f64) -> DVec3 {
        let (i, _) = self.piece(t);
        (self.surfaces[i + 1].point(uv) - self.surfaces[i].point(uv))
            / (self.knots[i + 1] - self.knots[i])
    }

    /// The polyline through every surface's point at (u, v); `None` for a projector of zero
    /// length.
    pub fn projector(&self, uv: DVec2) -> Option<Projector> {
        control_points(&self.surfaces, uv).map(Projector::Polyline)
    }

    /// [`PiecewiseVolume::projector`] written into `out` (see `set_polyline`).
    pub fn projector_into(&self, uv: DVec2, out: &mut Option<Projector>) {
        with_control_points(&self.surfaces, uv, |points| {
            set_polyline(out, points.iter().copied())
        })
        .unwrap_or_else(|| *out = None)
    }

    /// The hull of the projectors of the (u, v) rectangle `[lo, hi]`; see
    /// `projector_hull` for when there is none.
    pub fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        projector_hull(&self.surfaces, lo, hi, |uv| self.projector(uv))
    }
}

/// Bernstein blending of surfaces: Bezier projectors.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierVolume {
    surfaces: Vec<Surface>,
    /// `None`: quadratic projectors, intersected analytically; else projectors rendered as
    /// polylines of `n` equal steps in t, through the samples at t = k / n, k = 0..=n, whose
    /// Bernstein weights (`[k]`, one per surface) are computed here once for every projector.
    polyline_weights: Option<Vec<Vec<f64>>>,
}

impl BezierVolume {
    /// A Bezier volume of degree `surfaces.len() - 1`. `segments`: render the projectors as
    /// polylines of that many steps in t; without it degree 2 is analytic and higher degrees
    /// take [`DEFAULT_SEGMENTS`]. Errors: fewer than 3 surfaces (2 are a linear volume), 0
    /// segments, invalid or everywhere coincident surfaces.
    pub fn new(surfaces: Vec<Surface>, segments: Option<u32>) -> Result<Self> {
        let n = surfaces.len();
        if n < 3 {
            return Err(Error::new(format!(
                "a bezier flexible volume needs at least 3 surfaces (2 give straight \
                 projectors: use near and far), got {n}"
            )));
        }
        if segments == Some(0) {
            return Err(Error::new("flexible segments must be at least 1"));
        }
        check_surfaces(&surfaces)?;
        let segments = match (n, segments) {
            (3, s) => s,
            (_, s) => Some(s.unwrap_or(DEFAULT_SEGMENTS)),
        };
        let degree = n as u32 - 1;
        let polyline_weights = segments.map(|steps| {
            (0..=steps)
                .map(|k| bernstein_weights(degree, f64::from(k) / f64::from(steps)))
                .collect()
        });
        Ok(BezierVolume {
            surfaces,
            polyline_weights,
        })
    }

    /// The control surfaces, near to far (the inner ones are control nets, off the volume).
    pub fn surfaces(&self) -> &[Surface] {
        &self.surfaces
    }

    /// Whether the projectors are analytic quadratic curves (three surfaces, no
    /// `segments`), not polylines.
    pub fn is_quadratic(&self) -> bool {
        self.polyline_weights.is_none()
    }

    /// The de Casteljau pyramid of the control points at (u, v) down to its last two points,
    /// at `t`: their difference times the degree is dQ/dt.
    fn last_pair(&self, uv: DVec2, t: f64) -> (DVec3, DVec3) {
        let mut points: Vec<DVec3> = self.surfaces.iter().map(|s| s.point(uv)).collect();
        reduce_to_pair(&mut points, t)
    }

    /// Q(u, v, t), the Bernstein sum of the surfaces' points.
    pub fn point(&self, uv: DVec2, t: f64) -> DVec3 {
        let points: Vec<DVec3> = self.surfaces.iter().map(|s| s.point(uv)).collect();
        weighted_sum(&bernstein_weights(points.len() as u32 - 1, t), &points)
    }

    /// dQ/dt at (u, v, t): the degree times the difference of the last de Casteljau pair.
    pub fn tangent(&self, uv: DVec2, t: f64) -> DVec3 {
        let (a, b) = self.last_pair(uv, t);
        (self.surfaces.len() - 1) as f64 * (b - a)
    }

    /// The projector of (u, v): the analytic quadratic, or the polyline through Q at
    /// `segments + 1` equally spaced t; `None` for a projector of zero length.
    pub fn projector(&self, uv: DVec2) -> Option<Projector> {
        with_control_points(&self.surfaces, uv, |points| match &self.polyline_weights {
            None => Projector::QuadraticBezier([points[0], points[1], points[2]]),
            // The control points are evaluated once per projector, not once per sample, and
            // each sample is a sum with the volume's precomputed weights.
            Some(weights) => {
                Projector::Polyline(weights.iter().map(|w| weighted_sum(w, points)).collect())
            }
        })
    }

    /// [`BezierVolume::projector`] written into `out`: a polyline refills the vertex buffer
    /// of a polyline already in `out` (see `set_polyline`).
    pub fn projector_into(&self, uv: DVec2, out: &mut Option<Projector>) {
        let Some(weights) = &self.polyline_weights else {
            *out = self.projector(uv);
            return;
        };
        with_control_points(&self.surfaces, uv, |points| {
            set_polyline(out, weights.iter().map(|w| weighted_sum(w, points)))
        })
        .unwrap_or_else(|| *out = None)
    }

    /// The hull of the projectors of the (u, v) rectangle `[lo, hi]` (polyline samples are
    /// sums of the surfaces' points with Bernstein weights, non-negative and summing to 1);
    /// see `projector_hull` for when there is none.
    pub fn projector_hull(&self, lo: DVec2, hi: DVec2) -> Option<ProjectorHull> {
        projector_hull(&self.surfaces, lo, hi, |uv| self.projector(uv))
    }
}

#[cfg(test)]
mod hull_tests;
#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, half: f64) -> Surface {
        Surface::rectangle_centred(DVec3::new(0.0, 0.0, z), DVec3::X * half, DVec3::Y * half)
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn piecewise_passes_through_every_surface_at_its_knot() {
        let surfaces = vec![square(1.0, 1.0), square(2.0, 3.0), square(4.0, 3.0)];
        let v = PiecewiseVolume::new(surfaces.clone(), Some(vec![0.0, 0.25, 1.0])).unwrap();
        let uv = DVec2::new(1.0, 0.5);
        for (s, t) in surfaces.iter().zip([0.0, 0.25, 1.0]) {
            assert!(close(v.point(uv, t), s.point(uv)));
        }
        assert!(close(v.point(uv, 0.125), DVec3::new(2.0, 0.0, 1.5)));
        assert!(close(v.tangent(uv, 0.1), DVec3::new(8.0, 0.0, 4.0)));
        // At the inner knot: the derivative of the piece that starts there.
        assert!(close(v.tangent(uv, 0.25), DVec3::new(0.0, 0.0, 8.0 / 3.0)));
        assert!(close(v.tangent(uv, 1.0), DVec3::new(0.0, 0.0, 8.0 / 3.0)));
        match v.projector(uv) {
            Some(Projector::Polyline(p)) => assert_eq!(p.len(), 3),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn default_knots_are_equally_spaced() {
        let v = PiecewiseVolume::new(
            vec![square(1.0, 1.0), square(2.0, 1.0), square(4.0, 1.0)],
            None,
        )
        .unwrap();
        assert!(close(
            v.point(DVec2::splat(0.5), 0.5),
            DVec3::new(0.0, 0.0, 2.0)
        ));
    }

    #[test]
    fn bad_knots_and_counts_are_errors() {
        let s = vec![square(1.0, 1.0), square(2.0, 1.0), square(3.0, 1.0)];
        for knots in [
            vec![0.0, 1.0],
            vec![0.0, 0.5, 0.9],
            vec![0.0, 0.6, 0.6],
            vec![0.1, 0.5, 1.0],
        ] {
            assert!(PiecewiseVolume::new(s.clone(), Some(knots)).is_err());
        }
        assert!(PiecewiseVolume::new(vec![square(1.0, 1.0)], None).is_err());
        assert!(BezierVolume::new(s[..2].to_vec(), None).is_err());
        assert!(BezierVolume::new(s.clone(), Some(0)).is_err());
        let same = vec![square(1.0, 1.0); 3];
        let e = BezierVolume::new(same, None).unwrap_err();
        assert!(e.message.contains("coincide"), "{e}");
    }

    #[test]
    fn zero_length_pieces_are_allowed_but_a_point_projector_has_none() {
        // The first two surfaces coincide: the first piece has zero length everywhere.
        let v = PiecewiseVolume::new(
            vec![square(1.0, 1.0), square(1.0, 1.0), square(2.0, 2.0)],
            None,
        )
        .unwrap();
        assert!(v.projector(DVec2::ZERO).is_some());
        // Three surfaces crossing at the centre: the projector of (1/2, 1/2) is a point.
        let crossing = vec![
            Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Y),
            Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Z),
            Surface::rectangle_centred(DVec3::ZERO, DVec3::Y, DVec3::Z),
        ];
        let b = BezierVolume::new(crossing, None).unwrap();
        assert_eq!(b.projector(DVec2::splat(0.5)), None);
        assert!(b.projector(DVec2::new(0.5, 0.9)).is_some());
    }

    /// Asserts that `write` sets any previous projector to what `projector` gives, at a few
    /// (u, v).
    fn assert_writes_new_projectors(
        projector: impl Fn(DVec2) -> Option<Projector>,
        write: impl Fn(DVec2, &mut Option<Projector>),
    ) {
        let previous = [
            None,
            Some(Projector::Polyline(vec![DVec3::X; 9])),
            Some(Projector::Polyline(vec![DVec3::Y; 2])),
            Some(Projector::QuadraticBezier([DVec3::Z; 3])),
        ];
        for uv in [
            DVec2::splat(0.5),
            DVec2::new(0.1, 0.8),
            DVec2::new(1.0, 0.0),
        ] {
            for before in &previous {
                let mut out = before.clone();
                write(uv, &mut out);
                assert_eq!(out, projector(uv), "{uv} after {before:?}");
            }
        }
    }

    #[test]
    fn projectors_written_into_any_previous_projector_equal_new_ones() {
        let squares = vec![square(1.0, 1.0), square(3.0, 1.0), square(2.0, 4.0)];
        // Three surfaces crossing at the centre: the projector of (1/2, 1/2) is a point.
        let crossing = vec![
            Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Y),
            Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Z),
            Surface::rectangle_centred(DVec3::ZERO, DVec3::Y, DVec3::Z),
        ];
        for surfaces in [squares, crossing] {
            let v = PiecewiseVolume::new(surfaces.clone(), None).unwrap();
            assert_writes_new_projectors(|uv| v.projector(uv), |uv, out| v.projector_into(uv, out));
            for segments in [None, Some(2), Some(5), Some(12)] {
                let v = BezierVolume::new(surfaces.clone(), segments).unwrap();
                assert_writes_new_projectors(
                    |uv| v.projector(uv),
                    |uv, out| v.projector_into(uv, out),
                );
            }
        }
    }

    #[test]
    fn quadratic_bezier_matches_bernstein_form_and_derivative() {
        let s = vec![square(1.0, 1.0), square(3.0, 1.0), square(2.0, 4.0)];
        let v = BezierVolume::new(s.clone(), None).unwrap();
        let uv = DVec2::new(0.2, 0.7);
        let p: Vec<DVec3> = s.iter().map(|s| s.point(uv)).collect();
        let t = 0.3;
        let want = 0.49 * p[0] + 0.42 * p[1] + 0.09 * p[2];
        assert!(close(v.point(uv, t), want));
        let want_d = 2.0 * (0.7 * (p[1] - p[0]) + 0.3 * (p[2] - p[1]));
        assert!(close(v.tangent(uv, t), want_d));
        assert!(close(v.point(uv, 1.0), p[2]));
        assert_eq!(
            v.projector(uv),
            Some(Projector::QuadraticBezier([p[0], p[1], p[2]]))
        );
    }

    #[test]
    fn bernstein_points_match_de_casteljau_and_keep_the_end_points_exact() {
        let points = [
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0, -2.0, 0.5),
            DVec3::new(3.0, 1.0, -1.0),
            DVec3::new(-0.7, 4.0, 2.0),
        ];
        let point = |points: &[DVec3], t: f64| {
            weighted_sum(&bernstein_weights(points.len() as u32 - 1, t), points)
        };
        for t in [0.0, 0.1, 1.0 / 3.0, 0.5, 0.9, 1.0] {
            let mut pyramid = points.to_vec();
            let (a, b) = reduce_to_pair(&mut pyramid, t);
            assert!(close(point(&points, t), a.lerp(b, t)), "t = {t}");
            let sum: f64 = bernstein_weights(3, t).iter().sum();
            assert!((sum - 1.0).abs() < 1e-15, "t = {t}");
        }
        assert_eq!(point(&points, 0.0), points[0]);
        assert_eq!(point(&points, 1.0), points[3]);
        // Degenerate case: a single control point is the whole curve.
        assert_eq!(bernstein_weights(0, 0.4), vec![1.0]);
        assert_eq!(point(&points[..1], 0.4), points[0]);
    }

    #[test]
    fn cubic_bezier_tangent_is_the_derivative_and_renders_as_a_polyline() {
        let s = vec![
            square(1.0, 1.0),
            square(3.0, 1.0),
            square(2.0, 4.0),
            square(5.0, 2.0),
        ];
        let v = BezierVolume::new(s, None).unwrap();
        let uv = DVec2::new(0.9, 0.1);
        let h = 1e-6;
        for t in [0.0, 0.4, 1.0] {
            let numeric = (v.point(uv, t + h) - v.point(uv, t - h)) / (2.0 * h);
            assert!((numeric - v.tangent(uv, t)).length() < 1e-6);
        }
        match v.projector(uv) {
            Some(Projector::Polyline(p)) => {
                assert_eq!(p.len(), DEFAULT_SEGMENTS as usize + 1);
                assert!(close(p[8], v.point(uv, 0.5)));
            }
            other => panic!("{other:?}"),
        }
    }
}
