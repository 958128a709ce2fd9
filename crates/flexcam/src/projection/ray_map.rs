//! Every pixel's ray, for tools that trace or warp with a flexcam projection elsewhere
//! (`flexcam raymap`): where each pixel centre's projector starts and which way it goes, and
//! for curved projectors also where and which way it ends.
//!
//! Degenerate cases: a pixel without a projector (outside a fisheye's circle or a trilinear
//! mesh's triangles), and a projector with no direction (a zero-direction straight ray, a
//! polyline whose segments all have zero length), give no ray (`None`). A curve whose
//! tangent vanishes at an end (a control point on that end) takes the chord to or from its
//! middle control point there, and the chord between its ends where that is zero too.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::projector::{quadratic_tangent, Projector};
use super::Projection;
use crate::error::Result;
use crate::try_alloc;

/// Where a pixel's projector starts and ends, with its unit directions there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelRay {
    /// The start of the projector (a straight ray's point at its `t_min`, a polyline's first
    /// vertex, a curve's first control point).
    pub origin: DVec3,
    /// The unit direction of its first segment (the curve's tangent at its start).
    pub direction: DVec3,
    /// Where the projector ends: a polyline's last vertex, a curve's last control point,
    /// the far end of a straight ray with a finite `t_max` (else its origin).
    pub exit_origin: DVec3,
    /// The unit direction it leaves along: its last segment's (the curve's tangent at its
    /// end); a straight ray's own direction.
    pub exit_direction: DVec3,
}

/// The rays of every pixel of an image, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct RayMap {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Each pixel centre's ray, `None` where it has none.
    pub rays: Vec<Option<PixelRay>>,
    /// Whether any projector is curved (a polyline or a quadratic curve): then its leaving
    /// direction says something the first segment does not.
    pub curved: bool,
}

/// The ray map of `projection`: the projector through each pixel's centre. Fails when the
/// map's memory cannot be had (module `try_alloc`).
pub fn ray_map(projection: &dyn Projection) -> Result<RayMap> {
    let (width, height) = projection.resolution();
    let pixels = width as usize * height as usize;
    let mut rays = try_alloc::filled(pixels, None, || {
        format!("the ray map of the {width} x {height} image")
    })?;
    let curved = rays
        .par_iter_mut()
        .enumerate()
        .map(|(i, ray)| {
            let pixel = DVec2::new(
                (i % width as usize) as f64 + 0.5,
                (i / width as usize) as f64 + 0.5,
            );
            let Some(projector) = projection.projector(pixel) else {
                return false;
            };
            *ray = pixel_ray(&projector);
            !matches!(projector, Projector::Straight(_))
        })
        .reduce(|| false, |a, b| a || b);
    Ok(RayMap {
        width,
        height,
        curved,
        rays,
    })
}

/// The start and end of `projector` with their unit directions (see [`PixelRay`]), or `None`
/// where it has no direction.
pub fn pixel_ray(projector: &Projector) -> Option<PixelRay> {
    let unit = |d: DVec3| d.try_normalize();
    match projector {
        Projector::Straight(ray) => {
            let direction = unit(ray.direction)?;
            let origin = if ray.t_min.is_finite() {
                ray.at(ray.t_min)
            } else {
                ray.origin
            };
            let exit_origin = if ray.t_max.is_finite() {
                ray.at(ray.t_max)
            } else {
                origin
            };
            Some(PixelRay {
                origin,
                direction,
                exit_origin,
                exit_direction: direction,
            })
        }
        Projector::Polyline(points) => {
            let segments = || points.windows(2).map(|pair| pair[1] - pair[0]);
            Some(PixelRay {
                origin: *points.first()?,
                direction: segments().find_map(unit)?,
                exit_origin: *points.last()?,
                exit_direction: segments().rev().find_map(unit)?,
            })
        }
        Projector::QuadraticBezier(p) => {
            let chord = p[2] - p[0];
            let start = [quadratic_tangent(p, 0.0), p[1] - p[0], chord];
            let end = [quadratic_tangent(p, 1.0), p[2] - p[1], chord];
            Some(PixelRay {
                origin: p[0],
                direction: start.into_iter().find_map(unit)?,
                exit_origin: p[2],
                exit_direction: end.into_iter().find_map(unit)?,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;

    #[test]
    fn a_straight_ray_starts_at_its_t_min_and_leaves_along_itself() {
        let ray = Ray {
            origin: DVec3::ZERO,
            direction: DVec3::new(0.0, 0.0, -2.0),
            t_min: 0.5,
            t_max: f64::INFINITY,
        };
        let r = pixel_ray(&Projector::Straight(ray)).unwrap();
        assert_eq!(r.origin, DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(r.direction, DVec3::NEG_Z);
        assert_eq!((r.exit_origin, r.exit_direction), (r.origin, r.direction));
        let zero = Ray::new(DVec3::ZERO, DVec3::ZERO);
        assert_eq!(pixel_ray(&Projector::Straight(zero)), None);
    }

    #[test]
    fn a_polyline_skips_zero_segments_at_both_ends() {
        let p = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        let points = vec![
            p(0.0, 0.0),
            p(0.0, 0.0),
            p(0.0, -1.0),
            p(1.0, -1.0),
            p(1.0, -1.0),
        ];
        let r = pixel_ray(&Projector::Polyline(points)).unwrap();
        assert_eq!((r.origin, r.direction), (DVec3::ZERO, DVec3::NEG_Z));
        assert_eq!((r.exit_origin, r.exit_direction), (p(1.0, -1.0), DVec3::X));
        let still = vec![DVec3::ONE; 3];
        assert_eq!(pixel_ray(&Projector::Polyline(still)), None);
    }

    #[test]
    fn a_curve_leaves_along_its_end_tangents_or_chords() {
        let c = [
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
        ];
        let r = pixel_ray(&Projector::QuadraticBezier(c)).unwrap();
        assert_eq!((r.direction, r.exit_direction), (DVec3::NEG_Z, DVec3::X));
        assert_eq!(r.exit_origin, c[2]);
        // The middle control point on the start: the tangent there vanishes, the chord
        // to the middle point too, so the chord to the end stands in.
        let c = [DVec3::ZERO, DVec3::ZERO, DVec3::new(3.0, 0.0, 4.0)];
        let r = pixel_ray(&Projector::QuadraticBezier(c)).unwrap();
        assert!(r.direction.distance(DVec3::new(0.6, 0.0, 0.8)) < 1e-15);
        assert_eq!(
            pixel_ray(&Projector::QuadraticBezier([DVec3::ONE; 3])),
            None
        );
    }
}
