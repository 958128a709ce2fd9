//! One camera triangle (Hou, Wei, Shum and Guo 2006, section 2): a projection triangle of a
//! trilinear projection seen as a multi-perspective camera. The pixel at barycentrics
//! `(u, v)` emits the ray from `tripoint(u, v)` along `trinorm(u, v)` (both interpolated
//! barycentrically, so rays are C0 across shared edges), exactly the ray of
//! [`Trilinear::ray`](crate::projection::Trilinear); the map between barycentrics and
//! pixels is the projection's own ([`ScreenMap`]).
//!
//! The bounds of [`super::bound`] project scene points along a direction onto the *camera
//! plane*, in barycentric coordinates. The plane is the base triangle's, or, where the base
//! triangle has collapsed (a pinhole's base points all at the eye), the triangle of the
//! points one ray length along the rays: the ray at `(u, v)` is the same line either way
//! (`tripoint + s trinorm` is affine in `(u, v)` for any fixed `s`), so a bound computed on
//! either plane holds for the camera's rays.

use glam::{DVec2, DVec3};

use crate::geometry::Ray;
use crate::projection::{ProjectionTriangleCache, Trilinear};
use crate::render::trilinear::ScreenMap;

/// A base triangle counts as collapsed when twice its area is below this fraction of the
/// product of its two edge lengths (the sine of its angle).
const FLAT_SINE: f64 = 1e-9;

/// A direction counts as parallel to the camera plane when the sine of its angle with the
/// plane is below this.
const GRAZING_SINE: f64 = 1e-9;

/// The corners of a camera triangle in its own barycentrics `(u, v)`.
pub const CORNERS: [DVec2; 3] = [DVec2::ZERO, DVec2::X, DVec2::Y];

/// A camera triangle: its rays, its pixels and its camera plane.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub map: ScreenMap,
    cache: ProjectionTriangleCache,
    /// The camera plane (module doc); `None` where even the shifted base is degenerate.
    plane: Option<Plane>,
    /// The pixel bounding box `(lo, hi)` of its screen triangle.
    pub pixel_box: (DVec2, DVec2),
    /// Pixels per unit of barycentric area, for sizing bound regions (exact for the affine
    /// screen map, the value at the corners' triangle for a projective one).
    pub pixels_per_area: f64,
}

/// The plane `origin + u e1 + v e2` and its normal `e1 x e2`.
#[derive(Debug, Clone, Copy)]
struct Plane {
    origin: DVec3,
    e1: DVec3,
    e2: DVec3,
    normal: DVec3,
}

impl Plane {
    /// The plane through `p`, `None` when the three points (nearly) lie on a line or
    /// (nearly) coincide: its longest side below [`FLAT_SINE`] of the points' magnitude, or
    /// twice its area below [`FLAT_SINE`] of that side squared. Projections onto a plane so
    /// badly conditioned would be rounding noise.
    fn through(p: [DVec3; 3]) -> Option<Plane> {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let normal = e1.cross(e2);
        let side = e1.length().max(e2.length()).max((e2 - e1).length());
        let magnitude = p.iter().map(|x| x.abs().max_element()).fold(1.0, f64::max);
        let ok = side > FLAT_SINE * magnitude
            && normal.length() > FLAT_SINE * side * side
            && normal.is_finite();
        ok.then_some(Plane {
            origin: p[0],
            e1,
            e2,
            normal,
        })
    }
}

impl Camera {
    /// The camera triangles of `projection`, in mesh order.
    pub fn all(projection: &Trilinear) -> Vec<Camera> {
        projection
            .mesh()
            .triangles
            .iter()
            .zip(projection.triangle_caches())
            .map(|(t, cache)| {
                let map = ScreenMap::of_triangle(projection, t.map(|x| x as usize), *cache);
                Camera::new(map, *cache)
            })
            .collect()
    }

    fn new(map: ScreenMap, cache: ProjectionTriangleCache) -> Camera {
        let at = |s: f64| CORNERS.map(|c| cache.tripoint(c.x, c.y) + s * cache.trinorm(c.x, c.y));
        let plane = Plane::through(at(0.0)).or_else(|| Plane::through(at(1.0)));
        let pixels = CORNERS.map(|c| map.pixel(c.x, c.y));
        let lo = pixels[0].min(pixels[1]).min(pixels[2]);
        let hi = pixels[0].max(pixels[1]).max(pixels[2]);
        let pixels_per_area = (pixels[1] - pixels[0])
            .perp_dot(pixels[2] - pixels[0])
            .abs();
        Camera {
            map,
            cache,
            plane,
            pixel_box: (lo, hi),
            pixels_per_area,
        }
    }

    /// The ray at barycentrics `b`.
    pub fn ray_at(&self, b: DVec2) -> Ray {
        Ray::new(self.cache.tripoint(b.x, b.y), self.cache.trinorm(b.x, b.y))
    }

    /// The ray direction at barycentrics `b`.
    pub fn direction(&self, b: DVec2) -> DVec3 {
        self.cache.trinorm(b.x, b.y)
    }

    /// Whether every direction of the cone spanned by `directions` crosses the camera plane
    /// from the same side (none parallel to it): then projecting a point along them is a
    /// central projection of the cone from the point, and the projections of a point along
    /// the cone lie in the convex hull of its projections along `directions`.
    pub fn one_sided(&self, directions: &[DVec3; 3]) -> bool {
        let Some(plane) = &self.plane else {
            return false;
        };
        let n = plane.normal.length();
        let signs = directions.map(|d| {
            let s = plane.normal.dot(d);
            if s.abs() <= GRAZING_SINE * n * d.length() || !s.is_finite() {
                0
            } else {
                s.signum() as i32
            }
        });
        signs[0] != 0 && signs.iter().all(|&s| s == signs[0])
    }

    /// The barycentrics of the point where the line through `q` along `d` meets the camera
    /// plane (`None` without a plane or for `d` parallel to it).
    #[inline]
    pub fn project_along(&self, q: DVec3, d: DVec3) -> Option<DVec2> {
        let plane = self.plane.as_ref()?;
        let det = plane.normal.dot(d);
        if det == 0.0 {
            return None;
        }
        let r = q - plane.origin;
        let u = r.dot(plane.e2.cross(d)) / det;
        let v = plane.e1.dot(r.cross(d)) / det;
        Some(DVec2::new(u, v))
    }

    /// The in-plane component of `d` as a linear function on barycentrics: the covector
    /// `g` with `g . (u, v) = m . (point at (u, v)) + const`, `m` being `d` without its
    /// component along the plane's normal (the normal of the paper's line `L`, which lies in
    /// the plane orthogonal to `d`). `None` without a plane or where `m` vanishes (`d`
    /// orthogonal to the plane: the paper's singular case).
    pub fn in_plane_covector(&self, d: DVec3) -> Option<DVec2> {
        let plane = self.plane.as_ref()?;
        let n = plane.normal / plane.normal.length();
        let m = d - n * n.dot(d);
        (m.length() > GRAZING_SINE * d.length())
            .then(|| DVec2::new(m.dot(plane.e1), m.dot(plane.e2)))
    }
}
