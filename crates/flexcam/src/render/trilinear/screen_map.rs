//! The map between a projection triangle's barycentrics `(u, v)` and continuous pixel
//! positions, consistent with [`Trilinear::ray`](crate::projection::Trilinear): screen
//! `s = (1 - l1 - l2) S1 + l1 S2 + l2 S3` is pixel `(s_x W, (1 - s_y) H)`, with affine screen
//! barycentrics `l = (u, v)` (the thesis's screen-space map), or `l` the projective image of
//! `(u, v)` for a projection with screen weights ([`ProjectiveMap`]: perspective-correct
//! reflection and refraction surfaces).

use glam::{DMat2, DVec2, DVec3};

use crate::geometry::Ray;
use crate::projection::{Projection, ProjectionTriangleCache, ProjectiveMap, Trilinear};

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
    /// in `(u, v)`, hence in pixel position); with a projective map, of the homogeneous
    /// `W trinorm`.
    direction_per_x: DVec3,
    /// The change of the homogeneous weight `W` from one pixel to the next along a row (0
    /// for the affine map, whose `W` is 1).
    weight_per_x: f64,
    cache: ProjectionTriangleCache,
    /// The projective screen map; `None` for the affine one.
    projective: Option<ProjectiveMap>,
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
            weight_per_x: 0.0,
            cache,
            projective: None,
        }
    }

    /// The map of `projection`'s triangle with vertices `vertices` (mesh indices), its rays
    /// from `cache`, with the projection's screen map (affine or projective).
    pub fn of_triangle(
        projection: &Trilinear,
        vertices: [usize; 3],
        cache: ProjectionTriangleCache,
    ) -> ScreenMap {
        let (width, height) = projection.resolution();
        let size = DVec2::new(f64::from(width), f64::from(height));
        let screen = vertices.map(|k| projection.mesh().screen[k]);
        ScreenMap::new(screen, size, cache).with_projective(projection.projective_map(vertices))
    }

    /// The same map with the projective screen map `projective` (`None`: affine, `self`
    /// unchanged), as [`Trilinear::projective_map`](crate::projection::Trilinear) gives it.
    pub fn with_projective(self, projective: Option<ProjectiveMap>) -> ScreenMap {
        let Some(map) = projective else {
            return self;
        };
        // Per pixel along x, the screen barycentrics change by `per_x` and the homogeneous
        // `W trinorm = sum_i l_i w_i n_i` by the weighted changes of the l_i.
        let per_x = self.inverse.x_axis;
        let changes = [-per_x.x - per_x.y, per_x.x, per_x.y];
        let w = map.weights();
        let n = [
            self.cache.trinorm(0.0, 0.0),
            self.cache.trinorm(1.0, 0.0),
            self.cache.trinorm(0.0, 1.0),
        ];
        ScreenMap {
            direction_per_x: (0..3).map(|i| changes[i] * w[i] * n[i]).sum(),
            weight_per_x: (0..3).map(|i| changes[i] * w[i]).sum(),
            projective: Some(map),
            ..self
        }
    }

    /// The pixel position of barycentrics `(u, v)`.
    pub fn pixel(&self, u: f64, v: f64) -> DVec2 {
        let b = DVec2::new(u, v);
        let l = self.projective.map_or(b, |map| map.screen(b));
        self.origin + self.axes * l
    }

    /// The barycentrics `(u, v)` of pixel position `pixel`.
    pub fn barycentrics(&self, pixel: DVec2) -> DVec2 {
        let l = self.inverse * (pixel - self.origin);
        self.projective.map_or(l, |map| map.barycentrics(l))
    }

    /// The homogeneous weight `W` at barycentrics `(u, v)` ([`ProjectiveMap`]), affine in
    /// pixel position: `None` for the affine map (where it is 1).
    pub fn homogeneous_weight(&self, u: f64, v: f64) -> Option<f64> {
        self.projective
            .map(|map| map.homogeneous_weight(DVec2::new(u, v)))
    }

    /// The projector through pixel position `pixel` (extrapolated outside the triangle),
    /// `tripoint + t trinorm` as `Trilinear::ray` builds it; `None` where `trinorm` is zero.
    pub fn ray(&self, pixel: DVec2) -> Option<Ray> {
        self.projector(pixel).map(|p| p.ray())
    }

    /// The projector through `pixel` as [`ScreenMap::ray`] gives it, with only its direction
    /// computed: the origin is built by `Projector::ray` when needed. `None` where
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

    /// The projector directions (`trinorm`, `Projector::direction`) along a row from
    /// pixel position `pixel`: `RowDirections::at``(k)` is the direction at
    /// `pixel + (k, 0)` up to rounding, for callers walking a run of pixels of this
    /// projection triangle (shading) instead of mapping each pixel on its own. Unlike
    /// [`ScreenMap::projector`] it does not single out a zero `trinorm`: the caller checks
    /// the directions it uses.
    pub fn directions_along_row(&self, pixel: DVec2) -> RowDirections {
        let uv = self.barycentrics(pixel);
        let direction = self.cache.trinorm(uv.x, uv.y);
        let weight = self.homogeneous_weight(uv.x, uv.y).unwrap_or(1.0);
        RowDirections {
            start: weight * direction,
            step: self.direction_per_x,
            weight,
            weight_step: self.weight_per_x,
        }
    }

    /// The projection triangle's point-projection cache.
    pub fn cache(&self) -> &ProjectionTriangleCache {
        &self.cache
    }
}

/// The projector directions along a row ([`ScreenMap::directions_along_row`]): the
/// homogeneous direction `W trinorm` and weight `W` are affine along the row, so each is a
/// start and a step (for the affine map `W` is exactly 1 and its step 0).
#[derive(Debug, Clone, Copy)]
pub struct RowDirections {
    start: DVec3,
    step: DVec3,
    weight: f64,
    weight_step: f64,
}

impl RowDirections {
    /// The direction `k` pixels along the row from the start.
    #[inline]
    pub fn at(&self, k: u32) -> DVec3 {
        let k = f64::from(k);
        (self.start + k * self.step) / (self.weight + k * self.weight_step)
    }

    /// The same directions where the weight is exactly 1 all along the row (every row of
    /// the affine map: a weight of 1 and a step of zero), `None` elsewhere.
    pub fn unit_weight(&self) -> Option<UnitWeightDirections> {
        (self.weight == 1.0 && self.weight_step == 0.0).then_some(UnitWeightDirections {
            start: self.start,
            step: self.step,
        })
    }
}

/// [`RowDirections`] whose weight is exactly 1 all along the row
/// ([`RowDirections::unit_weight`]).
#[derive(Debug, Clone, Copy)]
pub struct UnitWeightDirections {
    start: DVec3,
    step: DVec3,
}

impl UnitWeightDirections {
    /// [`RowDirections::at`] without dividing by the weight `1 + k 0 = 1`: the same bits
    /// (IEEE 754 division by 1 returns its operand unchanged), and shading a pixel waits on
    /// no division before its depth's square root.
    #[inline]
    pub fn at(&self, k: u32) -> DVec3 {
        self.start + f64::from(k) * self.step
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

    /// [`map`] with the projective screen map of weights 1, 0.4 and 2.5.
    fn projective() -> ScreenMap {
        map().with_projective(ProjectiveMap::new([1.0, 0.4, 2.5]))
    }

    #[test]
    fn projective_vertices_map_to_their_pixels_and_lines_stay_lines() {
        let (affine, m) = (map(), projective());
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            assert!((m.pixel(u, v) - affine.pixel(u, v)).length() < 1e-12);
        }
        // The midpoint of an edge in barycentrics is not the midpoint on screen, but it is
        // on the edge.
        let (a, b, mid) = (m.pixel(1.0, 0.0), m.pixel(0.0, 1.0), m.pixel(0.5, 0.5));
        assert!((mid - 0.5 * (a + b)).length() > 1.0);
        assert!((mid - a).perp_dot(b - a).abs() < 1e-9 * (b - a).length_squared());
        assert!(
            m.homogeneous_weight(0.2, 0.3).is_some()
                && affine.homogeneous_weight(0.2, 0.3).is_none()
        );
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
        fn projective_pixel_and_barycentrics_are_inverse(u in 0.0..1.0f64, v in 0.0..1.0f64) {
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let m = projective();
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
            let stepped = m.directions_along_row(DVec2::new(x, y)).at(k);
            let pixel = DVec2::new(x + f64::from(k), y);
            let direction = m.projector(pixel).map_or(DVec3::ZERO, |p| p.direction);
            prop_assert!(
                (stepped - direction).length() < 1e-12 * (1.0 + direction.length()),
                "{stepped} {direction}"
            );
        }

        #[test]
        fn unit_weight_directions_are_the_same_bits(
            bits in proptest::array::uniform6(proptest::num::u64::ANY),
            weight in proptest::sample::select(vec![1.0, 0.5, 1.0 - f64::EPSILON / 2.0]),
            weight_step in proptest::sample::select(vec![0.0, -0.0, 0.25, 1e-300]),
            k in 0u32..1000,
        ) {
            // Arbitrary bit patterns (NaN and infinities included) for start and step.
            let v = |i: usize| DVec3::from_array([0, 1, 2].map(|j| f64::from_bits(bits[i + j])));
            let row = RowDirections { start: v(0), step: v(3), weight, weight_step };
            let unit = row.unit_weight();
            prop_assert_eq!(unit.is_some(), weight == 1.0 && weight_step == 0.0);
            if let Some(unit) = unit {
                let bits = |d: DVec3| d.to_array().map(f64::to_bits);
                prop_assert_eq!(bits(unit.at(k)), bits(row.at(k)));
            }
        }

        #[test]
        fn projective_directions_along_a_row_are_the_projectors_directions(
            (u, v) in (0.0..1.0f64, 0.0..1.0f64),
            k in 0u32..30,
        ) {
            // From a point of the triangle along the row, within the triangle's pixel box.
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let m = projective();
            let start = m.pixel(u, v);
            let stepped = m.directions_along_row(start).at(k);
            let pixel = start + DVec2::new(f64::from(k), 0.0);
            let uv = m.barycentrics(pixel);
            let direction = m.cache().trinorm(uv.x, uv.y);
            prop_assert!(
                (stepped - direction).length() < 1e-10 * (1.0 + direction.length()),
                "{stepped} {direction}"
            );
        }
    }
}
