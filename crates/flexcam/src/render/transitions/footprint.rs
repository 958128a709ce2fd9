//! The footprint of a pixel's ray at a hit: how far the neighbouring pixels' projectors pass
//! from the hit point, found through the projection itself (a ray differential by finite
//! differences). It needs no eye point, so it holds under every projection: a perspective
//! camera's footprint grows with distance, an orthographic one's is the pixel spacing, a
//! fisheye's widens towards the rim, a flexible projection's follows its bent projectors.

use glam::{DVec2, DVec3};

use crate::projection::{Projection, Projector};

/// The width of the ray of `pixel` at `point`: the larger of the distances from `point` to
/// the projectors of the next pixel across and the next pixel down (the previous one where
/// the next has no projector: the image's edge, outside a fisheye's circle). Infinite when
/// neither neighbour along either axis has a projector.
pub(super) fn footprint(projection: &dyn Projection, pixel: DVec2, point: DVec3) -> f64 {
    let along = |step: DVec2| {
        [pixel + step, pixel - step]
            .into_iter()
            .find_map(|q| projection.projector(q))
            .map(|p| distance(&p, point))
    };
    match (along(DVec2::X), along(DVec2::Y)) {
        (Some(a), Some(b)) => a.max(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => f64::INFINITY,
    }
}

/// The distance from `point` to projector `projector`: to the line of a straight ray, to the
/// nearest segment of a polyline, to the nearest of 16 chords of a quadratic curve.
fn distance(projector: &Projector, point: DVec3) -> f64 {
    match projector {
        Projector::Straight(ray) => {
            let d = ray.direction;
            if d == DVec3::ZERO {
                (point - ray.origin).length()
            } else {
                (point - ray.origin).cross(d).length() / d.length()
            }
        }
        Projector::Polyline(points) => polyline_distance(points, point),
        Projector::QuadraticBezier(p) => {
            let points: Vec<DVec3> = (0..=16)
                .map(|k| crate::projection::projector::quadratic_point(p, k as f64 / 16.0))
                .collect();
            polyline_distance(&points, point)
        }
    }
}

fn polyline_distance(points: &[DVec3], point: DVec3) -> f64 {
    points
        .windows(2)
        .map(|s| {
            let (a, b) = (s[0], s[1]);
            let ab = b - a;
            let t = if ab == DVec3::ZERO {
                0.0
            } else {
                ((point - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
            };
            (point - (a + ab * t)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;

    #[test]
    fn distances_to_projectors() {
        let ray = Projector::Straight(Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0)));
        assert!((distance(&ray, DVec3::new(0.3, 0.4, -7.0)) - 0.5).abs() < 1e-12);
        let line = Projector::Polyline(vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0)]);
        assert!((distance(&line, DVec3::new(0.5, -0.25, 0.0)) - 0.25).abs() < 1e-12);
        assert!((distance(&line, DVec3::new(2.0, 0.5, 0.0)) - 1.0).abs() < 1e-12);
    }
}
