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
//! either plane holds for the camera's rays. For the same reason any plane of the points `s`
//! along the rays serves ([`CameraPlane`], [`Camera::plane_at`]); where the rays diverge the
//! base plane may be crossed by them from both sides (rays grazing a mirror), while farther
//! along them their cone crosses the plane from one side, so each camera keeps the distances
//! whose planes it crosses steeply and a bound picks the one nearest its scene points.
//!
//! A camera triangle of a per-fragment mirror ([`TriangleMirror`]) reflects the eye's ray
//! about the interpolated normal at each pixel instead: its ray at `(u, v)` still starts at
//! the base point of barycentrics `(u, v)`, but its direction is not affine in `(u, v)`, so
//! only the base plane serves (no planes along the rays), and the bounds project along the
//! three generators of a cone that holds every direction of the (piece of the) triangle
//! ([`Camera::cone`], [`super::mirror_cone`]) instead of along the corner directions.

use glam::{DVec2, DVec3};

use super::mirror_cone;
use crate::geometry::Ray;
use crate::projection::{ProjectionTriangleCache, TriangleMirror, Trilinear};
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
#[derive(Debug, Clone)]
pub struct Camera {
    pub map: ScreenMap,
    cache: ProjectionTriangleCache,
    /// The camera plane (module doc); `None` where even the shifted base is degenerate.
    plane: Option<CameraPlane>,
    /// The ray parameters of the planes the tight bound may project onto.
    choices: PlaneChoices,
    /// The pixel bounding box `(lo, hi)` of its screen triangle.
    pub pixel_box: (DVec2, DVec2),
    /// Pixels per unit of barycentric area, for sizing bound regions (exact for the affine
    /// screen map, the value at the corners' triangle for a projective one).
    pub pixels_per_area: f64,
    /// Per-fragment mirror rays instead of interpolated ones (module doc).
    mirror: Option<TriangleMirror>,
}

/// A plane of the camera triangle: the triangle of the points `s` along its corner rays,
/// `origin + u e1 + v e2` at barycentrics `(u, v)`, where the ray at `(u, v)` crosses it
/// (`tripoint + s trinorm` is affine in `(u, v)`), and its normal `e1 x e2`.
#[derive(Debug, Clone, Copy)]
pub struct CameraPlane {
    origin: DVec3,
    e1: DVec3,
    e2: DVec3,
    normal: DVec3,
}

/// The projection of points along one direction onto a [`CameraPlane`], in its
/// barycentrics: affine in the point, so set up once per direction.
#[derive(Debug, Clone, Copy)]
pub struct AlongDirection {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
}

impl AlongDirection {
    /// The barycentrics of the point where the line through `q` along the direction meets
    /// the plane.
    #[inline]
    pub fn project(&self, q: DVec3) -> DVec2 {
        let r = q - self.origin;
        DVec2::new(r.dot(self.u), r.dot(self.v))
    }
}

impl CameraPlane {
    /// The plane through `p`, `None` when the three points (nearly) lie on a line or
    /// (nearly) coincide: its longest side below [`FLAT_SINE`] of the points' magnitude, or
    /// twice its area below [`FLAT_SINE`] of that side squared. Projections onto a plane so
    /// badly conditioned would be rounding noise.
    fn through(p: [DVec3; 3]) -> Option<CameraPlane> {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let normal = e1.cross(e2);
        let side = e1.length().max(e2.length()).max((e2 - e1).length());
        let magnitude = p.iter().map(|x| x.abs().max_element()).fold(1.0, f64::max);
        let ok = side > FLAT_SINE * magnitude
            && normal.length() > FLAT_SINE * side * side
            && normal.is_finite();
        ok.then_some(CameraPlane {
            origin: p[0],
            e1,
            e2,
            normal,
        })
    }

    /// Whether every direction of the cone spanned by `directions` crosses the plane from
    /// the same side (none parallel to it): then projecting a point along them is a central
    /// projection of the cone from the point, and the projections of a point along the cone
    /// lie in the convex hull of its projections along `directions`.
    pub fn one_sided(&self, directions: &[DVec3; 3]) -> bool {
        same_side(directions.map(|d| self.side(d)))
    }

    /// The side of the plane (`1` or `-1`, by its normal) that direction `d` crosses it
    /// towards, `0` where `d` is parallel to it (within [`GRAZING_SINE`]) or not finite.
    #[inline]
    pub fn side(&self, d: DVec3) -> i32 {
        let s = self.normal.dot(d);
        if s.abs() <= GRAZING_SINE * self.normal.length() * d.length() || !s.is_finite() {
            0
        } else {
            s.signum() as i32
        }
    }

    /// The smallest sine of the angle between the plane and `directions`.
    fn min_sine(&self, directions: &[DVec3; 3]) -> f64 {
        let n = self.normal.normalize();
        directions
            .iter()
            .map(|d| (n.dot(*d) / d.length()).abs())
            .fold(f64::INFINITY, f64::min)
    }

    /// The projection along `d` onto the plane (`None` for `d` parallel to it).
    #[inline]
    pub fn along(&self, d: DVec3) -> Option<AlongDirection> {
        let det = self.normal.dot(d);
        (det != 0.0).then(|| AlongDirection {
            origin: self.origin,
            u: self.e2.cross(d) / det,
            v: d.cross(self.e1) / det,
        })
    }

    /// The in-plane component of `d` as a linear function on barycentrics: the covector
    /// `g` with `g . (u, v) = m . (point at (u, v)) + const`, `m` being `d` without its
    /// component along the plane's normal (the normal of the paper's line `L`, which lies in
    /// the plane orthogonal to `d`). `None` where `m` vanishes (`d` orthogonal to the
    /// plane: the paper's singular case).
    pub fn in_plane_covector(&self, d: DVec3) -> Option<DVec2> {
        let n = self.normal / self.normal.length();
        let m = d - n * n.dot(d);
        (m.length() > GRAZING_SINE * d.length()).then(|| DVec2::new(m.dot(self.e1), m.dot(self.e2)))
    }
}

/// Whether the sides of [`CameraPlane::side`] for the directions of a cone are one side: its
/// every direction crosses the plane from there ([`CameraPlane::one_sided`]).
pub fn same_side(sides: [i32; 3]) -> bool {
    sides[0] != 0 && sides.iter().all(|&s| s == sides[0])
}

/// The ray parameters `s` (on a geometric grid) whose planes [`Camera::plane_at`] the cone
/// of the corner rays crosses from one side at an angle of at least [`STEEP_SINE`] (or, where
/// none does, from one side at all), in increasing order: the planes a bound may project
/// onto. Where the rays diverge, the camera plane itself may be crossed from both sides
/// (rays grazing the reflector), yet far enough along the rays the cone always crosses the
/// plane of its corner rays' points from one side (unless the directions are coplanar).
///
/// Each choice keeps its plane and the camera its central ray, built once: every (camera,
/// scene triangle) pair and every culled cluster picks a plane.
#[derive(Debug, Clone, Default)]
struct PlaneChoices {
    s: Vec<f64>,
    planes: Vec<CameraPlane>,
    /// The interpolated ray at the camera triangle's centroid, whose parameter at a point
    /// picks the plane ([`Camera::plane_near`]).
    central: Option<Ray>,
}

/// Points of the grid of ray parameters: `s = scale * GRID_RATIO^i`, `i` from
/// `-GRID_STEPS / 2`.
const GRID_STEPS: usize = 48;
const GRID_RATIO: f64 = 1.5;

/// The sine of the angle below which a plane counts as grazed by the cone.
const STEEP_SINE: f64 = 0.02;

impl PlaneChoices {
    fn of(camera: &Camera) -> PlaneChoices {
        let directions = CORNERS.map(|c| camera.cache.trinorm(c.x, c.y));
        let points = CORNERS.map(|c| camera.cache.tripoint(c.x, c.y));
        let size = (points[1] - points[0])
            .length()
            .max((points[2] - points[0]).length());
        let length = directions.iter().map(|d| d.length()).fold(0.0, f64::max);
        let scale = if size > 0.0 && length > 0.0 {
            size / length
        } else {
            1.0
        };
        let grid =
            (0..GRID_STEPS).map(|i| scale * GRID_RATIO.powi(i as i32 - GRID_STEPS as i32 / 2));
        let steepness = |s: f64| {
            let plane = camera.plane_at(s)?;
            plane
                .one_sided(&directions)
                .then(|| (plane, plane.min_sine(&directions)))
        };
        let mut out = PlaneChoices::default();
        let sines: Vec<(f64, CameraPlane, f64)> = grid
            .filter_map(|s| {
                let (plane, sine) = steepness(s)?;
                Some((s, plane, sine))
            })
            .collect();
        let steep = sines.iter().any(|&(_, _, sine)| sine >= STEEP_SINE);
        for &(s, plane, sine) in &sines {
            if sine >= STEEP_SINE || !steep {
                out.s.push(s);
                out.planes.push(plane);
            }
        }
        if !out.s.is_empty() {
            out.central = Some(camera.interpolated_ray(DVec2::splat(1.0 / 3.0)));
        }
        out
    }

    /// The plane of the choice nearest `s` in ratio (the smallest for `s <= 0`), `None` if
    /// there is none.
    fn nearest(&self, s: f64) -> Option<&CameraPlane> {
        let choices = &self.s;
        let above = choices.partition_point(|&c| c < s);
        let index = match (above.checked_sub(1), choices.get(above)) {
            (Some(below), Some(&at)) => {
                if s * s <= choices[below] * at {
                    below
                } else {
                    above
                }
            }
            (Some(below), None) => below,
            (None, Some(_)) => above,
            (None, None) => return None,
        };
        Some(&self.planes[index])
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
            .enumerate()
            .map(|(index, (t, cache))| {
                let map = ScreenMap::of_triangle(projection, t.map(|x| x as usize), *cache);
                Camera::new(map, *cache, projection.triangle_mirror(index))
            })
            .collect()
    }

    fn new(
        map: ScreenMap,
        cache: ProjectionTriangleCache,
        mirror: Option<TriangleMirror>,
    ) -> Camera {
        let mut camera = Camera {
            map,
            cache,
            plane: None,
            choices: PlaneChoices::default(),
            pixel_box: (DVec2::ZERO, DVec2::ZERO),
            pixels_per_area: 0.0,
            mirror,
        };
        if mirror.is_some() {
            // Only the base plane holds the rays' origins at their own barycentrics.
            camera.plane = camera.plane_at(0.0);
        } else {
            camera.plane = camera.plane_at(0.0).or_else(|| camera.plane_at(1.0));
            camera.choices = PlaneChoices::of(&camera);
        }
        let pixels = CORNERS.map(|c| map.pixel(c.x, c.y));
        let lo = pixels[0].min(pixels[1]).min(pixels[2]);
        let hi = pixels[0].max(pixels[1]).max(pixels[2]);
        camera.pixel_box = (lo, hi);
        camera.pixels_per_area = (pixels[1] - pixels[0])
            .perp_dot(pixels[2] - pixels[0])
            .abs();
        camera
    }

    /// The camera plane: the base triangle's, or one ray length along the rays where the
    /// base has collapsed (module doc); `None` where both are degenerate.
    pub fn plane(&self) -> Option<&CameraPlane> {
        self.plane.as_ref()
    }

    /// The plane of the points `s` along the corner rays (`None` where degenerate).
    pub fn plane_at(&self, s: f64) -> Option<CameraPlane> {
        CameraPlane::through(CORNERS.map(|c| self.cache.ray_point(c.x, c.y, s)))
    }

    /// A plane for bounding the image of points around `centre`: of the camera's
    /// [`PlaneChoices`], the one nearest the centre's distance along the central ray (in
    /// ratio), else the camera plane. Projecting along diverging rays onto a plane near the
    /// points moves them little, so their hull is small; the cone of the corner rays crosses
    /// every choice from one side.
    pub fn plane_near(&self, centre: DVec3) -> Option<&CameraPlane> {
        let Some(ray) = &self.choices.central else {
            return self.plane.as_ref();
        };
        let s = (centre - ray.origin).dot(ray.direction) / ray.direction.length_squared();
        self.choices.nearest(s)
    }

    /// A plane for bounding the image of a small set of points around `centre` (a scene
    /// triangle): the plane of the points `s` along the rays, `s` the parameter at which the
    /// camera's ray through `centre` meets it (estimated by one step: the barycentrics
    /// where `centre` projects along the central ray onto [`Camera::plane_near`]'s plane,
    /// then the parameter of `centre` along the ray there), where the cone of the corner
    /// rays crosses that plane from one side at least as steeply as the steep
    /// [`PlaneChoices`]; else [`Camera::plane_near`]'s. A point on the plane projects to the
    /// same barycentrics along every direction, so the nearer the plane to the points, the
    /// smaller the hull of their projections; any plane the cone crosses from one side
    /// serves the bounds (module doc).
    pub fn plane_through(&self, centre: DVec3) -> Option<CameraPlane> {
        let near = self.plane_near(centre).copied();
        let (Some(plane), Some(central)) = (near, self.choices.central) else {
            return near;
        };
        let refined = plane.along(central.direction).and_then(|along| {
            let b = along.project(centre);
            let ray = self.interpolated_ray(b);
            let s = (centre - ray.origin).dot(ray.direction) / ray.direction.length_squared();
            let plane = self.plane_at(s).filter(|_| s.is_finite() && s > 0.0)?;
            let directions = CORNERS.map(|c| self.cache.trinorm(c.x, c.y));
            (plane.one_sided(&directions) && plane.min_sine(&directions) >= STEEP_SINE)
                .then_some(plane)
        });
        refined.or(near)
    }

    /// The ray at barycentrics `b` (`None`: a per-fragment mirror's eye at its origin).
    pub fn ray_at(&self, b: DVec2) -> Option<Ray> {
        match &self.mirror {
            None => Some(self.interpolated_ray(b)),
            Some(mirror) => mirror.ray(b),
        }
    }

    /// The ray through pixel position `pixel` (extrapolated outside the triangle); `None`
    /// where the interpolated direction is zero or a mirror's eye is at the origin.
    #[inline]
    pub fn pixel_ray(&self, pixel: DVec2) -> Option<Ray> {
        match &self.mirror {
            None => self.map.ray(pixel),
            Some(mirror) => mirror.ray(self.map.barycentrics(pixel)),
        }
    }

    /// The interpolated ray at barycentrics `b`.
    fn interpolated_ray(&self, b: DVec2) -> Ray {
        Ray::new(self.cache.tripoint(b.x, b.y), self.cache.trinorm(b.x, b.y))
    }

    /// Three directions whose cone holds the direction of every ray of the piece `sub` of
    /// the camera triangle: its corner directions for interpolated rays (the directions in
    /// between are their convex combinations), a cone enclosing the reflected rays of a
    /// per-fragment mirror ([`mirror_cone::cone`]); `None` where no such cone is known (the
    /// bounds then take the whole piece).
    pub fn cone(&self, sub: [DVec2; 3]) -> Option<[DVec3; 3]> {
        match &self.mirror {
            None => Some(sub.map(|c| self.cache.trinorm(c.x, c.y))),
            Some(mirror) => mirror_cone::cone(mirror, sub),
        }
    }

    /// The ray direction at barycentrics `b` where the cone of a piece is its corners'
    /// directions (interpolated rays: [`Camera::cone`] of a piece with corner `b` has this
    /// direction for it); `None` for a per-fragment mirror, whose cone is the piece's own.
    #[inline]
    pub fn corner_direction(&self, b: DVec2) -> Option<DVec3> {
        self.mirror.is_none().then(|| self.cache.trinorm(b.x, b.y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::trilinear_builders::SurfaceRays;
    use crate::render::camera_triangles::tests::mirror_surface;

    /// The largest distance between the projections of `x` along the corner directions
    /// onto `plane` (zero for a point on the plane).
    fn spread(camera: &Camera, plane: &CameraPlane, x: DVec3) -> f64 {
        let p = CORNERS.map(|c| {
            let along = plane.along(camera.cache.trinorm(c.x, c.y)).unwrap();
            along.project(x)
        });
        (p[0] - p[1])
            .length()
            .max((p[1] - p[2]).length())
            .max((p[2] - p[0]).length())
    }

    /// The same plane: the same projection of a test point along a test direction, bit for
    /// bit.
    fn same_plane(a: Option<CameraPlane>, b: Option<&CameraPlane>) -> bool {
        let probe = |p: &CameraPlane| {
            let x = p
                .along(DVec3::new(0.3, 0.4, 1.0))
                .map(|a| a.project(DVec3::ONE));
            x.map(|x| (x.x.to_bits(), x.y.to_bits()))
        };
        a.as_ref().map(probe) == b.map(probe)
    }

    /// On the diverging rays of a mirror sphere's surface, a point seen by a camera off the
    /// grid of [`PlaneChoices`] gets from [`Camera::plane_through`] a plane that its
    /// projections along the corner directions spread less on than on
    /// [`Camera::plane_near`]'s (the bound's hull shrinks with that spread): under half as
    /// much for over 80 % of the points, more for under 5 % (the one step is an estimate).
    /// Degenerate cases fall back to `plane_near`: a per-fragment mirror's camera (no planes
    /// along its rays), and a point behind the rays (parameter `s <= 0`).
    #[test]
    fn plane_through_a_point_holds_it_more_closely() {
        let (projection, _) = mirror_surface("reflect-sphere-cube", SurfaceRays::Interpolated);
        let (mut cases, mut tighter, mut looser) = (0, 0, 0);
        for camera in &Camera::all(&projection) {
            let s = &camera.choices.s;
            for i in (1..s.len()).step_by(4) {
                // Between two choices, off the grid.
                let between = (s[i - 1] * s[i]).sqrt() * 1.1;
                for b in [
                    DVec2::new(0.3, 0.3),
                    DVec2::new(0.6, 0.15),
                    DVec2::new(0.1, 0.8),
                ] {
                    let x = camera.cache.ray_point(b.x, b.y, between);
                    let near = camera.plane_near(x).unwrap();
                    let through = camera.plane_through(x).unwrap();
                    let (a, n) = (spread(camera, &through, x), spread(camera, near, x));
                    cases += 1;
                    tighter += usize::from(a < 0.5 * n);
                    looser += usize::from(a > n);
                }
            }
        }
        assert!(
            cases > 100 && tighter * 10 > cases * 8 && looser * 20 < cases,
            "{tighter} tighter and {looser} looser of {cases}"
        );

        let (projection, _) = mirror_surface("reflect-sphere-cube", SurfaceRays::PerFragment);
        for camera in &Camera::all(&projection) {
            let x = camera.cache.ray_point(0.3, 0.3, 1.0);
            assert!(same_plane(camera.plane_through(x), camera.plane()));
        }

        // Slightly diverging rays along +z from the unit triangle: a point behind them
        // (parameter -5) gets the grid's plane; one in front, a plane holding it closer.
        let cache = ProjectionTriangleCache::new(
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [
                DVec3::Z,
                DVec3::new(0.1, 0.0, 1.0),
                DVec3::new(0.0, 0.1, 1.0),
            ],
        );
        let screen = [DVec2::ZERO, DVec2::new(100.0, 0.0), DVec2::new(0.0, 100.0)];
        let map = ScreenMap::new(screen, DVec2::new(100.0, 100.0), cache);
        let camera = Camera::new(map, cache, None);
        let behind = cache.ray_point(0.3, 0.3, -5.0);
        assert!(same_plane(
            camera.plane_through(behind),
            camera.plane_near(behind)
        ));
        let ahead = cache.ray_point(0.3, 0.3, 5.0 * 1.1);
        let near = camera.plane_near(ahead).unwrap();
        let through = camera.plane_through(ahead).unwrap();
        assert!(spread(&camera, &through, ahead) < 0.5 * spread(&camera, near, ahead));
    }
}
