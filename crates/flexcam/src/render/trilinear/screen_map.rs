//! The affine map between a projection triangle's barycentrics `(u, v)` and continuous pixel
//! positions, consistent with [`Trilinear::ray`](crate::projection::Trilinear): screen
//! `s = (1 - u - v) S1 + u S2 + v S3` is pixel `(s_x W, (1 - s_y) H)`.

use glam::{DMat2, DVec2, DVec3};

use crate::geometry::Ray;
use crate::projection::ProjectionTriangleCache;

/// One projection triangle's screen placement and rays.
#[derive(Debug, Clone, Copy)]
pub struct ScreenMap {
    /// Pixel position of `(u, v) = (0, 0)`.
    origin: DVec2,
    /// Pixel displacement per unit `u` and per unit `v` (the columns).
    axes: DMat2,
    /// The inverse of `axes` (the screen triangle is validated non-degenerate).
    inverse: DMat2,
    /// The change of `trinorm` from one pixel to the next along a row (`trinorm` is affine
    /// in `(u, v)`, hence in pixel position).
    direction_per_x: DVec3,
    cache: ProjectionTriangleCache,
}

impl ScreenMap {
    /// The map of the projection triangle with screen vertices `screen` (in `[0,1]^2`, y up)
    /// in an image of `size` pixels, its rays from `cache`.
    pub fn new(screen: [DVec2; 3], size: DVec2, cache: ProjectionTriangleCache) -> ScreenMap {
        let pixel = |s: DVec2| DVec2::new(s.x * size.x, (1.0 - s.y) * size.y);
        let [p0, p1, p2] = screen.map(pixel);
        let axes = DMat2::from_cols(p1 - p0, p2 - p0);
        let inverse = axes.inverse();
        // (u, v) changes by the inverse's first column per pixel along x.
        let per_x = inverse.x_axis;
        let direction_per_x = cache.trinorm(per_x.x, per_x.y) - cache.trinorm(0.0, 0.0);
        ScreenMap {
            origin: p0,
            axes,
            inverse,
            direction_per_x,
            cache,
        }
    }

    /// The pixel position of barycentrics `(u, v)`.
    pub fn pixel(&self, u: f64, v: f64) -> DVec2 {
        self.origin + self.axes * DVec2::new(u, v)
    }

    /// The barycentrics `(u, v)` of pixel position `pixel`.
    pub fn barycentrics(&self, pixel: DVec2) -> DVec2 {
        self.inverse * (pixel - self.origin)
    }

    /// The projector through pixel position `pixel` (extrapolated outside the triangle),
    /// `tripoint + t trinorm` as `Trilinear::ray` builds it; `None` where `trinorm` is zero.
    pub fn ray(&self, pixel: DVec2) -> Option<Ray> {
        self.projector(pixel).map(|p| p.ray())
    }

    /// The projector through `pixel` as [`ScreenMap::ray`] gives it, with only its direction
    /// computed: the origin is built by [`Projector::ray`] when needed. `None` where
    /// `trinorm` is zero.
    pub fn projector(&self, pixel: DVec2) -> Option<Projector<'_>> {
        let uv = self.barycentrics(pixel);
        let direction = self.cache.trinorm(uv.x, uv.y);
        (direction != DVec3::ZERO).then_some(Projector {
            cache: &self.cache,
            uv,
            direction,
        })
    }

    /// The projector directions (`trinorm`, [`Projector::direction`]) along a row: the
    /// direction at pixel position `pixel`, then the change from one pixel to the next, so
    /// that the direction at `pixel + (k, 0)` is `start + k step` up to rounding, for
    /// callers walking a run of pixels of this projection triangle (shading) instead of
    /// mapping each pixel on its own. Unlike [`ScreenMap::projector`] it does not single out
    /// a zero `trinorm`: the caller checks the directions it uses.
    pub fn directions_along_row(&self, pixel: DVec2) -> (DVec3, DVec3) {
        let uv = self.barycentrics(pixel);
        (self.cache.trinorm(uv.x, uv.y), self.direction_per_x)
    }

    /// The projection triangle's point-projection cache.
    pub fn cache(&self) -> &ProjectionTriangleCache {
        &self.cache
    }
}

/// A projector through a pixel whose origin is not computed yet (see
/// [`ScreenMap::projector`]).
#[derive(Debug, Clone, Copy)]
pub struct Projector<'a> {
    cache: &'a ProjectionTriangleCache,
    uv: DVec2,
    /// `trinorm` at the pixel: the ray's direction, non-zero.
    pub direction: DVec3,
}

impl Projector<'_> {
    /// The whole ray, `tripoint + t trinorm`.
    pub fn ray(&self) -> Ray {
        Ray::new(self.cache.tripoint(self.uv.x, self.uv.y), self.direction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn map() -> ScreenMap {
        let cache = ProjectionTriangleCache::new(
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [
                DVec3::Z,
                DVec3::new(0.1, 0.0, 1.0),
                DVec3::new(0.0, 0.2, 1.0),
            ],
        );
        let screen = [
            DVec2::new(0.1, 0.2),
            DVec2::new(0.9, 0.3),
            DVec2::new(0.4, 0.95),
        ];
        ScreenMap::new(screen, DVec2::new(200.0, 100.0), cache)
    }

    #[test]
    fn vertices_map_to_their_pixels() {
        let m = map();
        assert!((m.pixel(0.0, 0.0) - DVec2::new(20.0, 80.0)).length() < 1e-12);
        assert!((m.pixel(1.0, 0.0) - DVec2::new(180.0, 70.0)).length() < 1e-12);
        assert!((m.pixel(0.0, 1.0) - DVec2::new(80.0, 5.0)).length() < 1e-12);
        let ray = m.ray(m.pixel(1.0, 0.0)).unwrap();
        assert!((ray.origin - DVec3::X).length() < 1e-12);
        assert!((ray.direction - DVec3::new(0.1, 0.0, 1.0)).length() < 1e-12);
    }

    proptest! {
        #[test]
        fn pixel_and_barycentrics_are_inverse(u in -2.0..2.0f64, v in -2.0..2.0f64) {
            let m = map();
            let back = m.barycentrics(m.pixel(u, v));
            prop_assert!((back - DVec2::new(u, v)).length() < 1e-12);
        }

        #[test]
        fn directions_along_a_row_are_the_projectors_directions(
            x in -50.0..250.0f64,
            y in -50.0..150.0f64,
            k in 0u32..400,
        ) {
            let m = map();
            let (start, step) = m.directions_along_row(DVec2::new(x, y));
            let stepped = start + f64::from(k) * step;
            let pixel = DVec2::new(x + f64::from(k), y);
            let direction = m.projector(pixel).map_or(DVec3::ZERO, |p| p.direction);
            prop_assert!(
                (stepped - direction).length() < 1e-12 * (1.0 + direction.length()),
                "{stepped} {direction}"
            );
        }
    }
}
