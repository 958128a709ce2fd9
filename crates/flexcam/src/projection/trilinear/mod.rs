//! The trilinear projection (Vallance 2005) as a ray generator: a mesh of projection triangles
//! whose screen triangles tile (part of) the image.
//!
//! Vertex k has base point p_k, ray direction n_k and screen position S_k. A screen point at
//! barycentrics (u, v) of a triangle's screen triangle emits the ray
//! tripoint(u, v) + t * trinorm(u, v), t >= 0, where tripoint and trinorm interpolate the
//! p_k and n_k linearly (trinorm is never renormalised: its length is the depth scale).
//! The inverse solves a cubic per projection triangle ([`point_projection`], with the cached
//! N/K form of each triangle): [`AnalyticInverse::project`] returns every visible image.
//!
//! The map from screen position to `(u, v)` is affine (the thesis's screen-space
//! interpolation) unless the projection has screen weights
//! ([`Trilinear::with_screen_weights`]): then it is the projective map of
//! [`projective_map`], which makes a surface whose screen positions are an eye's image of its
//! base points send each screen point's ray from the base point that the eye sees there.

mod fragment_mirror;
pub mod mesh_builders;
mod obj;
mod point_projection;
mod projective_map;
pub mod ray_fan;
mod screen_locator;
mod shapes;

use glam::{DVec2, DVec3};

use super::image_coords::Resolution;
use super::{
    AnalyticInverse, Charted, ImagePoint, ImageSegment, NoInverse, Projection, TrilinearMesh,
    SAME_IMAGE_PIXELS,
};
use crate::error::{Error, Result};
use crate::geometry::Ray;
pub use fragment_mirror::{FragmentMirror, TriangleMirror};
pub use point_projection::{ProjectionTriangleCache, Solutions, TriangleSolution};
pub use projective_map::ProjectiveMap;
pub use ray_fan::{FanSolution, RayFan};
use screen_locator::ScreenLocator;
pub use shapes::{
    project_solved_triangle, project_triangle, SceneEdge, Shape, ShapeVertex, TriangleShapes,
    Unprojectable,
};

/// A screen triangle counts as degenerate when twice its area is below this fraction of the
/// product of its two edge lengths from the first vertex (the sine of its angle there).
const DEGENERATE_SINE: f64 = 1e-12;

/// A validated trilinear mesh bound to an image size.
#[derive(Debug, Clone, PartialEq)]
pub struct Trilinear {
    mesh: TrilinearMesh,
    locator: ScreenLocator,
    resolution: Resolution,
    /// The point-projection cache of each triangle, same order as `mesh.triangles`.
    caches: Vec<ProjectionTriangleCache>,
    /// The per-vertex screen weights, `None` for the affine screen map.
    weights: Option<Vec<f64>>,
    /// The projective screen map of each triangle (same order); empty for the affine map.
    maps: Vec<ProjectiveMap>,
    /// Per-fragment mirror rays instead of interpolated ones ([`FragmentMirror`]).
    mirror: Option<FragmentMirror>,
}

impl Trilinear {
    /// Validates `mesh` and prepares the screen lookup. Errors: an empty image; no
    /// triangles; `points`, `normals` and `screen` of different lengths; a vertex index out
    /// of range; a non-finite value; a zero-length normal; a zero-area (degenerate) screen
    /// triangle. Screen triangles may overlap (the lowest index wins) and have either
    /// orientation; screen positions outside \[0,1\]^2 simply fall outside the image.
    pub fn new(mesh: &TrilinearMesh, width: u32, height: u32) -> Result<Self> {
        let resolution = Resolution::new(width, height)?;
        validate(mesh)?;
        let screen_triangles = mesh
            .triangles
            .iter()
            .map(|t| t.map(|k| mesh.screen[k as usize]))
            .collect();
        let caches = mesh
            .triangles
            .iter()
            .map(|t| {
                let [i, j, k] = t.map(|k| k as usize);
                ProjectionTriangleCache::new(
                    [mesh.points[i], mesh.points[j], mesh.points[k]],
                    [mesh.normals[i], mesh.normals[j], mesh.normals[k]],
                )
            })
            .collect();
        Ok(Trilinear {
            mesh: mesh.clone(),
            locator: ScreenLocator::new(screen_triangles),
            resolution,
            caches,
            weights: None,
            maps: Vec::new(),
            mirror: None,
        })
    }

    /// As [`Trilinear::new`], with the projective screen map of per-vertex screen weights
    /// `weights` (same order as the mesh's vertices; [`ProjectiveMap`]): the screen point
    /// with affine barycentrics `l` in a screen triangle takes the ray at barycentrics
    /// `b_i = l_i w_i / sum_j l_j w_j`. With `w_i = 1 / depth_i`, the forward depths of the
    /// base points from an eye whose image of them the screen positions are, every screen
    /// point gets the ray from the base point the eye sees there. Errors: those of
    /// [`Trilinear::new`]; a weight count other than the vertex count; a weight that is not
    /// finite and positive (a vertex at the eye or behind it, or a zero weight: the map
    /// would be singular inside a triangle).
    pub fn with_screen_weights(
        mesh: &TrilinearMesh,
        weights: &[f64],
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let mut trilinear = Trilinear::new(mesh, width, height)?;
        if weights.len() != mesh.points.len() {
            return Err(Error::new(format!(
                "trilinear screen weights: {} for {} vertices",
                weights.len(),
                mesh.points.len()
            )));
        }
        trilinear.maps = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(index, t)| {
                ProjectiveMap::new(t.map(|k| weights[k as usize])).ok_or_else(|| {
                    Error::new(format!(
                        "trilinear triangle {index} has screen weights {:?}: each must be \
                         finite and positive",
                        t.map(|k| weights[k as usize])
                    ))
                })
            })
            .collect::<Result<_>>()?;
        trilinear.weights = Some(weights.to_vec());
        Ok(trilinear)
    }

    /// The same projection with per-fragment mirror rays ([`FragmentMirror`]): each screen
    /// point reflects the eye's ray about the interpolated vertex normals instead of taking
    /// the interpolated vertex rays. It has no analytic inverse (its rays are not the
    /// trilinear family). Errors: those of [`FragmentMirror`]'s validation.
    pub fn with_fragment_mirror(mut self, mirror: FragmentMirror) -> Result<Self> {
        mirror.validate(self.mesh.points.len())?;
        self.mirror = Some(mirror);
        Ok(self)
    }

    /// The per-fragment mirror, if the projection has one.
    pub fn fragment_mirror(&self) -> Option<&FragmentMirror> {
        self.mirror.as_ref()
    }

    /// The per-fragment mirror of projection triangle `index`, if the projection has one.
    pub fn triangle_mirror(&self, index: usize) -> Option<TriangleMirror> {
        let vertices = self.mesh.triangles[index].map(|k| k as usize);
        let points = vertices.map(|k| self.mesh.points[k]);
        Some(self.mirror.as_ref()?.triangle(points, vertices))
    }

    /// The projective screen map of the triangle with vertices `vertices`; `None` for the
    /// affine map (or a vertex index out of range).
    pub fn projective_map(&self, vertices: [usize; 3]) -> Option<ProjectiveMap> {
        let weights = self.weights.as_ref()?;
        let [a, b, c] = vertices.map(|k| weights.get(k).copied());
        ProjectiveMap::new([a?, b?, c?])
    }

    /// The barycentrics of triangle `index`'s ray at affine screen barycentrics `screen`.
    fn barycentrics_at_screen(&self, index: usize, screen: DVec2) -> DVec2 {
        match self.maps.get(index) {
            Some(map) => map.barycentrics(screen),
            None => screen,
        }
    }

    /// The affine screen barycentrics of triangle `index`'s ray at barycentrics `b`.
    fn screen_at_barycentrics(&self, index: usize, b: DVec2) -> DVec2 {
        match self.maps.get(index) {
            Some(map) => map.screen(b),
            None => b,
        }
    }

    /// The projection mesh.
    pub fn mesh(&self) -> &TrilinearMesh {
        &self.mesh
    }

    /// The projection triangle whose screen triangle covers `pixel` (the one [`Projection::ray`]
    /// uses there), with the barycentrics `(u, v)` of the pixel in it; `None` where no screen
    /// triangle covers it.
    pub fn locate(&self, pixel: DVec2) -> Option<(usize, f64, f64)> {
        let size = self.resolution.size();
        let screen = DVec2::new(pixel.x / size.x, 1.0 - pixel.y / size.y);
        self.locator.locate(screen).map(|hit| {
            let b = self.barycentrics_at_screen(hit.triangle, DVec2::new(hit.u, hit.v));
            (hit.triangle, b.x, b.y)
        })
    }

    /// Whether [`Trilinear::locate`] finds a screen triangle at the centre of each pixel of a
    /// `width` x `height` grid (row-major; the pixels scaled by this projection's resolution
    /// as `locate` scales them): the same tests at the same points, made along rows
    /// (the screen locator's `covered_runs`) instead of point by point.
    pub fn covered_pixels(&self, width: u32, height: u32) -> Vec<bool> {
        let size = self.resolution.size();
        let columns: Vec<f64> = (0..width).map(|x| (f64::from(x) + 0.5) / size.x).collect();
        let rows: Vec<f64> = (0..height)
            .map(|y| 1.0 - (f64::from(y) + 0.5) / size.y)
            .collect();
        let mut covered = vec![false; columns.len() * rows.len()];
        self.locator.covered_runs(&columns, &rows, |y, xs| {
            let row = y * columns.len();
            covered[row + xs.start..row + xs.end].fill(true);
        });
        covered
    }

    /// The point-projection cache of each projection triangle (same order as the mesh's
    /// triangles): all solutions of a scene point, any `t`, inside or not.
    pub fn triangle_caches(&self) -> &[ProjectionTriangleCache] {
        &self.caches
    }
}

fn validate(mesh: &TrilinearMesh) -> Result<()> {
    if mesh.triangles.is_empty() {
        return Err(Error::new("trilinear projection has no triangles"));
    }
    let count = mesh.points.len();
    if mesh.normals.len() != count || mesh.screen.len() != count {
        return Err(Error::new(format!(
            "trilinear points, normals and screen must have the same length, got {}, {} and {}",
            count,
            mesh.normals.len(),
            mesh.screen.len()
        )));
    }
    for k in 0..count {
        let finite =
            mesh.points[k].is_finite() && mesh.normals[k].is_finite() && mesh.screen[k].is_finite();
        if !finite {
            return Err(Error::new(format!(
                "trilinear vertex {k} has a non-finite point, normal or screen value"
            )));
        }
        if mesh.normals[k] == DVec3::ZERO {
            return Err(Error::new(format!(
                "trilinear normal {k} has zero length: every vertex needs a ray direction"
            )));
        }
    }
    for (index, triangle) in mesh.triangles.iter().enumerate() {
        if let Some(&k) = triangle.iter().find(|&&k| k as usize >= count) {
            return Err(Error::new(format!(
                "trilinear triangle {index} refers to vertex {k}, \
                 but there are only {count} vertices"
            )));
        }
        if is_degenerate_screen_triangle(triangle.map(|k| mesh.screen[k as usize])) {
            return Err(Error::new(format!(
                "trilinear triangle {index} has a zero-area (degenerate) screen triangle"
            )));
        }
    }
    Ok(())
}

/// Whether a screen triangle has zero area up to [`DEGENERATE_SINE`] (such a triangle cannot
/// locate a screen position).
pub(super) fn is_degenerate_screen_triangle([a, b, c]: [DVec2; 3]) -> bool {
    let (e1, e2) = (b - a, c - a);
    e1.perp_dot(e2).abs() <= DEGENERATE_SINE * e1.length() * e2.length()
}

impl Projection for Trilinear {
    fn kind(&self) -> &'static str {
        "trilinear"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.resolution.width, self.resolution.height)
    }

    /// Pixel (x, y) is screen (x / W, 1 - y / H); its barycentrics `(u, v)` are affine in the
    /// screen position, or projective with screen weights. `None` where no screen triangle covers it,
    /// and where the interpolated direction trinorm is exactly zero (possible inside a
    /// triangle whose normals point in opposing directions: the projector is a single point).
    /// With a per-fragment mirror, its ray at the pixel's barycentrics ([`TriangleMirror::ray`]).
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let (triangle, u, v) = self.locate(pixel)?;
        if let Some(mirror) = self.triangle_mirror(triangle) {
            return mirror.ray(DVec2::new(u, v));
        }
        let [i, j, k] = self.mesh.triangles[triangle].map(|k| k as usize);
        let w = 1.0 - u - v;
        let interpolate = |values: &[DVec3]| w * values[i] + u * values[j] + v * values[k];
        let direction = interpolate(&self.mesh.normals);
        if direction == DVec3::ZERO {
            return None;
        }
        Some(Ray::new(interpolate(&self.mesh.points), direction))
    }

    /// None with a per-fragment mirror, whose rays are not the trilinear family.
    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        match self.mirror {
            None => Ok(self),
            Some(_) => Err(NoInverse {
                reason: Some(
                    "a trilinear surface with per-fragment mirror rays has no analytic inverse"
                        .into(),
                ),
            }),
        }
    }

    fn trilinear(&self) -> Option<&Trilinear> {
        Some(self)
    }
}

impl AnalyticInverse for Trilinear {
    /// Appends every image of `point`: per projection triangle, each solution of the cubic
    /// that is inside (up to [`ProjectionTriangleCache::INSIDE_TOL`] in barycentrics)
    /// and on a ray (`t >= 0`), at pixel `(s_x W, (1 - s_y) H)` of its screen position `s`
    /// (the inverse of the pixel-to-screen map of [`Projection::ray`]). `t < 0` solutions
    /// (behind the view plane) and outside ones are available from
    /// [`Trilinear::triangle_caches`]. Details:
    ///
    /// * `t` slightly below 0 (the point is on the base triangle, within rounding:
    ///   `-t |trinorm| <= 64 EPSILON (|point| + |p1| + triangle size)`) is reported as 0.
    /// * A solution whose interpolated direction is (relative to the largest of the three
    ///   normals, `1e-12`) zero is skipped: its projector is a single point, not a ray.
    /// * Where screen triangles overlap, `ray` uses the lowest-index one: a solution of
    ///   another triangle is only kept if the covering triangle's ray there is the same
    ///   (relative `1e-8`), as on a shared edge of a continuous mesh.
    /// * Images closer than [`SAME_IMAGE_PIXELS`] are one image (a point on an edge or
    ///   vertex shared by several projection triangles is found by each of them).
    /// * A triangle whose rays form a fan ([`RayFan`]) sees a point on the fan along a
    ///   segment ([`AnalyticInverse::project_segments`]); only its zero-length lines (the
    ///   apex's ray) are listed here.
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>) {
        let start = out.len();
        let mut push = |pixel: DVec2, t: f64| {
            if !out[start..]
                .iter()
                .any(|o| (o.pixel - pixel).length() <= SAME_IMAGE_PIXELS)
            {
                out.push(ImagePoint { pixel, t });
            }
        };
        for (index, cache) in self.caches.iter().enumerate() {
            let solutions = cache.project_point(point);
            if solutions.is_every_t() {
                self.fan_images(index, point, |[a, b], t| {
                    if a.distance(b) <= SAME_IMAGE_PIXELS {
                        push(a, t);
                    }
                });
                continue;
            }
            let i = self.mesh.triangles[index][0] as usize;
            let largest = self.largest_normal(index);
            for s in solutions.iter().filter(|s| s.inside) {
                let direction = cache.trinorm(s.u, s.v);
                let length = direction.length();
                if length <= 1e-12 * largest {
                    continue;
                }
                let base = cache.tripoint(s.u, s.v).distance(self.mesh.points[i]);
                let Some(t) = self.in_front(point, i, base, s.t, length) else {
                    continue;
                };
                let screen = self.screen_at(index, DVec2::new(s.u, s.v));
                if self.covers(index, screen, cache, s, t) {
                    push(self.pixel_of(screen), t);
                }
            }
        }
    }

    /// Per projection triangle whose rays form a fan ([`RayFan`]; its cubic vanishes for
    /// every point, so [`Self::project`] finds nothing there), every ray of the fan through
    /// `point` in front of the view plane (`t` as in [`Self::project`]), seen along the whole
    /// line of the screen triangle of its apex weight, where that triangle is the one
    /// [`Projection::ray`] uses (tested at the line's middle). A line of zero length (the
    /// apex's own ray) is a point and is listed by [`Self::project`] instead.
    fn project_segments(&self, point: DVec3, out: &mut Vec<ImageSegment>) {
        for index in 0..self.caches.len() {
            self.fan_images(index, point, |ends, t| {
                if ends[0].distance(ends[1]) > SAME_IMAGE_PIXELS {
                    out.push(ImageSegment { ends, t });
                }
            });
        }
    }

    /// `None`: the mesh's inverse folds (a point can have several images, which appear and
    /// vanish across the mesh's fold lines), which no chart describes.
    fn charted(&self) -> Option<Charted<'_>> {
        None
    }
}

impl Trilinear {
    /// The larger length of triangle `index`'s three vertex normals.
    fn largest_normal(&self, index: usize) -> f64 {
        self.mesh.triangles[index].iter().fold(0.0_f64, |m, &k| {
            m.max(self.mesh.normals[k as usize].length())
        })
    }

    /// `t` of a solution of triangle `index` at `base` from its first vertex's base point
    /// `p_i`, with ray direction length `length`: itself where `t >= 0`, 0 where the point
    /// is on the base triangle within rounding (`-t |trinorm| <= 64 EPSILON (|point| + |p_i|
    /// + base)`), else `None` (behind the view plane).
    fn in_front(&self, point: DVec3, i: usize, base: f64, t: f64, length: f64) -> Option<f64> {
        if t >= 0.0 {
            return Some(t);
        }
        let slack = 64.0
            * f64::EPSILON
            * (point.abs().max_element() + self.mesh.points[i].abs().max_element() + base);
        (-t * length <= slack).then_some(0.0)
    }

    /// The screen position of barycentrics `b` of triangle `index` (the inverse of the
    /// screen-to-barycentrics map of [`Projection::ray`]).
    fn screen_at(&self, index: usize, b: DVec2) -> DVec2 {
        let [i, j, k] = self.mesh.triangles[index].map(|k| k as usize);
        let l = self.screen_at_barycentrics(index, b);
        (1.0 - l.x - l.y) * self.mesh.screen[i]
            + l.x * self.mesh.screen[j]
            + l.y * self.mesh.screen[k]
    }

    /// The continuous pixel `(s_x W, (1 - s_y) H)` of screen position `s`.
    fn pixel_of(&self, screen: DVec2) -> DVec2 {
        let size = self.resolution.size();
        DVec2::new(screen.x * size.x, (1.0 - screen.y) * size.y)
    }

    /// Calls `image` with the pixel ends of each line of triangle `index` that sees `point`
    /// along one ray of its fan, and that ray's `t` (see
    /// [`AnalyticInverse::project_segments`]); nothing unless the triangle is a fan.
    fn fan_images(&self, index: usize, point: DVec3, mut image: impl FnMut([DVec2; 2], f64)) {
        let cache = &self.caches[index];
        let Some(fan) = RayFan::of(cache) else {
            return;
        };
        let i = self.mesh.triangles[index][0] as usize;
        let largest = self.largest_normal(index);
        for solution in fan.project_point(point) {
            let ray = fan.ray(solution.w);
            let length = ray.direction.length();
            if length <= 1e-12 * largest {
                continue;
            }
            let base = ray.origin.distance(self.mesh.points[i]);
            let Some(t) = self.in_front(point, i, base, solution.t, length) else {
                continue;
            };
            let ends = fan.line_ends(solution.w);
            let middle = 0.5 * (ends[0] + ends[1]);
            let at_middle = TriangleSolution {
                t,
                u: middle.x,
                v: middle.y,
                inside: true,
                multiplicity: 1,
            };
            if self.covers(index, self.screen_at(index, middle), cache, at_middle, t) {
                image(ends.map(|b| self.pixel_of(self.screen_at(index, b))), t);
            }
        }
    }

    /// Whether the ray at screen position `screen` is that of solution `s` of triangle
    /// `index`: the locator picks `index` there, or picks another triangle whose ray at
    /// `screen` reaches the same point at `t` (a shared edge of a continuous mesh), or
    /// picks none (outside the covered screen, where `ray` gives nothing either: the image
    /// position is still reported, callers clip).
    fn covers(
        &self,
        index: usize,
        screen: DVec2,
        cache: &ProjectionTriangleCache,
        s: TriangleSolution,
        t: f64,
    ) -> bool {
        let Some(hit) = self.locator.locate(screen) else {
            return true;
        };
        if hit.triangle == index {
            return true;
        }
        let other = &self.caches[hit.triangle];
        let b = self.barycentrics_at_screen(hit.triangle, DVec2::new(hit.u, hit.v));
        let theirs = other.ray_point(b.x, b.y, t);
        let ours = cache.ray_point(s.u, s.v, t);
        let scale = ours.abs().max_element()
            + other.tripoint(b.x, b.y).abs().max_element()
            + t * other.trinorm(b.x, b.y).length();
        (theirs - ours).length() <= 1e-8 * scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::linear::Perspective;
    use crate::projection::trilinear_builders::{screen_grid, GridVertex};
    use crate::projection::CameraFrame;

    /// A 2 x 2 quad grid (8 triangles) on the image plane at distance 1 in front of `eye`
    /// (looking down -z), with n_k = p_k - eye: a pinhole camera with horizontal half-angle
    /// tangent `half_w` and vertical `half_h`.
    fn pinhole_mesh(eye: DVec3, half_w: f64, half_h: f64) -> TrilinearMesh {
        screen_grid(2, |s| {
            let point =
                eye + DVec3::new((2.0 * s.x - 1.0) * half_w, (2.0 * s.y - 1.0) * half_h, -1.0);
            GridVertex {
                point,
                direction: point - eye,
            }
        })
        .unwrap()
    }

    /// The eye and image size of [`pinhole_and_perspective`].
    const PINHOLE_EYE: DVec3 = DVec3::new(0.5, 1.0, 4.0);
    const PINHOLE_SIZE: (u32, u32) = (64, 48);

    /// A 64 x 48 trilinear mesh built from a pinhole (n_i = p_i - eye) and the perspective
    /// projection it must reproduce (70 degrees horizontal, looking down -z).
    fn pinhole_and_perspective() -> (Trilinear, Perspective) {
        let eye = PINHOLE_EYE;
        let (width, height) = PINHOLE_SIZE;
        let fov = 70.0_f64;
        let half_w = (0.5 * fov.to_radians()).tan();
        let half_h = half_w * f64::from(height) / f64::from(width);
        let trilinear = Trilinear::new(&pinhole_mesh(eye, half_w, half_h), width, height).unwrap();
        let frame = CameraFrame {
            position: eye,
            look_at: eye + DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let perspective = Perspective::new(&frame, fov, width, height).unwrap();
        (trilinear, perspective)
    }

    #[test]
    fn pinhole_mesh_matches_the_perspective_projection() {
        let (trilinear, perspective) = pinhole_and_perspective();
        for y in 0..PINHOLE_SIZE.1 {
            for x in 0..PINHOLE_SIZE.0 {
                let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let tri = trilinear.ray(pixel).unwrap();
                let persp = perspective.ray(pixel).unwrap();
                let direction = tri.direction.normalize();
                assert!(
                    (direction - persp.direction).length() < 1e-12,
                    "pixel {pixel}"
                );
                // The origin lies on the perspective ray, one unit of trinorm from the PINHOLE_EYE.
                assert!((tri.origin - tri.direction - PINHOLE_EYE).length() < 1e-12);
            }
        }
    }

    /// One projection triangle whose vertices 1 and 2 share a base point and ray (a fan,
    /// [`RayFan`]), screen corners (0, 0), (1, 0), (0, 1) of a 100 x 100 image: a point on
    /// the fan's ray of apex weight 0.25 is seen along the screen line of that weight (from
    /// (75, 100) to (0, 25) in pixels, y down) and not by `project`; a point on the apex's
    /// own ray is one point image, at the apex; a point off the fan has no image.
    #[test]
    fn a_fan_triangle_sees_a_point_along_a_segment() {
        let (points, normals) = super::ray_fan::pole_row();
        let mesh = TrilinearMesh {
            points: points.to_vec(),
            normals: normals.to_vec(),
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        };
        let trilinear = Trilinear::new(&mesh, 100, 100).unwrap();
        let fan = RayFan::of(&trilinear.triangle_caches()[0]).unwrap();
        let point = fan.ray(0.25).at(1.5);
        let (mut images, mut segments) = (Vec::new(), Vec::new());
        trilinear.project(point, &mut images);
        trilinear.project_segments(point, &mut segments);
        assert!(images.is_empty(), "{images:?}");
        assert_eq!(segments.len(), 1, "{segments:?}");
        let ImageSegment { ends, t } = segments[0];
        assert!((t - 1.5).abs() < 1e-12, "{t}");
        assert!(ends[0].distance(DVec2::new(75.0, 100.0)) < 1e-9, "{ends:?}");
        assert!(ends[1].distance(DVec2::new(0.0, 25.0)) < 1e-9, "{ends:?}");
        // Every position along it sees the point.
        for s in [0.1, 0.5, 0.9] {
            let ray = trilinear.ray(ends[0].lerp(ends[1], s)).unwrap();
            assert!(ray.at(t).distance(point) < 1e-12);
        }
        let apex = points[0] + 2.0 * normals[0];
        trilinear.project(apex, &mut images);
        trilinear.project_segments(apex, &mut segments);
        assert_eq!(segments.len(), 1, "{segments:?}");
        assert_eq!(images.len(), 1, "{images:?}");
        assert!(images[0].pixel.distance(DVec2::new(0.0, 100.0)) < 1e-9);
        assert!((images[0].t - 2.0).abs() < 1e-12);
        let (mut off, mut off_segments) = (Vec::new(), Vec::new());
        trilinear.project(point + DVec3::Z * 0.1, &mut off);
        trilinear.project_segments(point + DVec3::Z * 0.1, &mut off_segments);
        assert!(off.is_empty() && off_segments.is_empty());
    }

    #[test]
    fn covering_mesh_leaves_no_cracks() {
        // Every pixel centre and every pixel corner (which lie on the shared edges and
        // vertices of the 2 x 2 grid for even sizes) gets exactly one ray.
        let mesh = pinhole_mesh(DVec3::ZERO, 1.0, 1.0);
        let trilinear = Trilinear::new(&mesh, 16, 16).unwrap();
        for y in 0..32 {
            for x in 0..32 {
                let pixel = DVec2::new(f64::from(x), f64::from(y)) * 0.5;
                assert!(trilinear.ray(pixel).is_some(), "crack at {pixel}");
            }
        }
        assert!(
            trilinear.ray(DVec2::new(16.0, 3.0)).is_none(),
            "right edge is outside"
        );
        assert!(
            trilinear.ray(DVec2::new(3.0, 16.0)).is_none(),
            "bottom edge is outside"
        );
    }

    #[test]
    fn uncovered_pixels_and_zero_directions_see_nothing() {
        let mesh = TrilinearMesh {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z, DVec3::NEG_Z, DVec3::Z],
            screen: vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)],
            triangles: vec![[0, 1, 2]],
        };
        let t = Trilinear::new(&mesh, 10, 10).unwrap();
        assert!(
            t.ray(DVec2::new(9.5, 0.5)).is_none(),
            "upper-right half is uncovered"
        );
        // Where u = 1/2 the interpolated normal (1 - 2u) z vanishes.
        assert!(t.ray(DVec2::new(5.0, 7.5)).is_none());
        assert!(t.ray(DVec2::new(5.5, 7.5)).is_some());
        let r = t.ray(DVec2::new(2.0, 8.0)).unwrap();
        assert!((r.origin - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-12);
        assert!(
            (r.direction - DVec3::new(0.0, 0.0, 0.6)).length() < 1e-12,
            "not renormalised"
        );
    }

    /// `covered_pixels` holds exactly where `locate` finds a triangle at the pixel centre: a
    /// fan reaching past the screen's edges with a triangle overlapping it, at a resolution
    /// whose pixel centres are not dyadic, on its own grid and on a wider one.
    #[test]
    fn covered_pixels_are_where_locate_finds_a_triangle() {
        let screen = [
            (0.0, 0.0),
            (0.6, -0.1),
            (1.1, 0.3),
            (0.7, 0.7),
            (0.2, 1.0),
            (-0.05, 0.5),
            (0.45, 0.4),
        ]
        .map(|(x, y)| DVec2::new(x, y));
        let mut triangles: Vec<[u32; 3]> = (0..6).map(|k| [6, k, (k + 1) % 6]).collect();
        triangles.push([0, 2, 4]);
        let mesh = TrilinearMesh {
            points: screen.iter().map(|p| p.extend(0.0)).collect(),
            normals: vec![DVec3::Z; screen.len()],
            screen: screen.to_vec(),
            triangles,
        };
        let t = Trilinear::new(&mesh, 37, 23).unwrap();
        for (width, height) in [(37, 23), (45, 30)] {
            let covered = t.covered_pixels(width, height);
            assert_eq!(covered.len(), (width * height) as usize);
            let mut count = 0;
            for y in 0..height {
                for x in 0..width {
                    let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let k = (y * width + x) as usize;
                    assert_eq!(covered[k], t.locate(centre).is_some(), "pixel ({x}, {y})");
                    count += usize::from(covered[k]);
                }
            }
            assert!(count > 0 && count < covered.len());
        }
    }

    fn triangle_mesh() -> TrilinearMesh {
        TrilinearMesh {
            points: vec![DVec3::ZERO; 3],
            normals: vec![DVec3::Z; 3],
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        }
    }

    fn error_of(mesh: TrilinearMesh) -> String {
        Trilinear::new(&mesh, 8, 8).unwrap_err().message
    }

    #[test]
    fn validation_errors() {
        assert!(Trilinear::new(&triangle_mesh(), 8, 8).is_ok());
        assert!(Trilinear::new(&triangle_mesh(), 0, 8).is_err());
        let mut m = triangle_mesh();
        m.triangles.clear();
        assert_eq!(error_of(m), "trilinear projection has no triangles");
        let mut m = triangle_mesh();
        m.normals.pop();
        assert!(error_of(m).contains("same length, got 3, 2 and 3"));
        let mut m = triangle_mesh();
        m.triangles[0][1] = 7;
        assert!(error_of(m).contains("triangle 0 refers to vertex 7"));
        let mut m = triangle_mesh();
        m.normals[2] = DVec3::ZERO;
        assert!(error_of(m).contains("normal 2 has zero length"));
        let mut m = triangle_mesh();
        m.points[1].y = f64::NAN;
        assert!(error_of(m).contains("vertex 1 has a non-finite"));
        let mut m = triangle_mesh();
        m.screen[0] = DVec2::new(f64::INFINITY, 0.0);
        assert!(error_of(m).contains("vertex 0 has a non-finite"));
        let mut m = triangle_mesh();
        m.triangles.push([0, 1, 1]);
        assert!(error_of(m).contains("triangle 1 has a zero-area"));
        let mut m = triangle_mesh();
        m.screen[2] = DVec2::new(0.5, 0.0); // collinear
        assert!(error_of(m).contains("triangle 0 has a zero-area"));
    }

    #[test]
    fn pinhole_mesh_projects_like_the_perspective_projection() {
        let (trilinear, perspective) = pinhole_and_perspective();
        let mut checked = 0;
        for k in 0..2000 {
            // A deterministic spread of points in front of and behind the image plane.
            let a = f64::from(k);
            let local = DVec3::new(
                (a * 0.618_034).fract() * 2.0 - 1.0,
                (a * 0.754_877).fract() * 2.0 - 1.0,
                -0.2 - 9.0 * (a * 0.569_84).fract(),
            );
            let point = PINHOLE_EYE + DVec3::new(local.x * -local.z, local.y * -local.z, local.z);
            let (mut tri, mut persp) = (Vec::new(), Vec::new());
            trilinear.project(point, &mut tri);
            perspective.project(point, &mut persp);
            let [expected] = persp[..] else {
                panic!("perspective: {persp:?}")
            };
            let inside = expected.pixel.x >= 0.0
                && expected.pixel.x <= f64::from(PINHOLE_SIZE.0)
                && expected.pixel.y >= 0.0
                && expected.pixel.y <= f64::from(PINHOLE_SIZE.1);
            if !inside || local.z > -1.0 {
                // Outside the mesh, or between the PINHOLE_EYE and the image plane (t < 0).
                assert!(tri.is_empty() || inside, "{point}: {tri:?}");
                if local.z > -1.0 {
                    assert!(tri.is_empty(), "behind the view plane: {tri:?}");
                }
                continue;
            }
            assert_eq!(tri.len(), 1, "{point}: {tri:?}");
            let got = tri[0];
            assert!(
                (got.pixel - expected.pixel).length() < 1e-9,
                "{got:?} vs {expected:?}"
            );
            let ray = trilinear.ray(got.pixel).unwrap();
            assert!((ray.at(got.t) - point).length() < 1e-12 * (1.0 + point.length()));
            // Distance from the PINHOLE_EYE = (1 + t) |trinorm|.
            let distance = (1.0 + got.t) * ray.direction.length();
            assert!((distance - expected.t).abs() < 1e-12 * expected.t);
            checked += 1;
        }
        assert!(checked > 500, "{checked}");
    }

    #[test]
    fn shared_edges_and_vertices_give_one_image() {
        let mesh = pinhole_mesh(DVec3::ZERO, 1.0, 1.0);
        let trilinear = Trilinear::new(&mesh, 16, 16).unwrap();
        let mut out = Vec::new();
        // The centre vertex (shared by six triangles), a point on a shared diagonal and one
        // on a shared grid line, at depth t = 2 (distance 3 along n).
        for screen in [
            DVec2::new(0.5, 0.5),
            DVec2::new(0.25, 0.25),
            DVec2::new(0.5, 0.8),
        ] {
            let pixel = DVec2::new(screen.x * 16.0, (1.0 - screen.y) * 16.0);
            let ray = trilinear.ray(pixel).unwrap();
            out.clear();
            trilinear.project(ray.at(2.0), &mut out);
            assert_eq!(out.len(), 1, "{screen}: {out:?}");
            assert!((out[0].pixel - pixel).length() < 1e-9);
            assert!((out[0].t - 2.0).abs() < 1e-12);
        }
    }

    #[test]
    fn parallel_normals_mesh_projects_orthographically() {
        let mut mesh = pinhole_mesh(DVec3::ZERO, 1.0, 1.0);
        let n = DVec3::new(0.1, 0.05, -2.0);
        mesh.normals.iter_mut().for_each(|x| *x = n);
        let trilinear = Trilinear::new(&mesh, 20, 10).unwrap();
        let mut out = Vec::new();
        trilinear.project(DVec3::new(0.3, -0.5, -1.0) + 4.0 * n, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        // Base (0.3, -0.5) on the plane z = -1 spanning [-1, 1]^2 -> screen (0.65, 0.25).
        assert!(
            (out[0].pixel - DVec2::new(13.0, 7.5)).length() < 1e-9,
            "{out:?}"
        );
        assert!((out[0].t - 4.0).abs() < 1e-12);
        // Behind the view plane: no image.
        out.clear();
        trilinear.project(DVec3::new(0.3, -0.5, -1.0) - 0.5 * n, &mut out);
        assert!(out.is_empty());
        // On it: t = 0.
        trilinear.project(DVec3::new(0.3, -0.5, -1.0), &mut out);
        assert_eq!(out.len(), 1);
        assert!(out[0].t.abs() < 1e-15 && (out[0].pixel - DVec2::new(13.0, 7.5)).length() < 1e-9);
    }

    #[test]
    fn folded_mesh_images_a_point_several_times() {
        // One quad whose rays are ray(x, y) = (x, y, 0) + t (1 - 3x, 0, 1 + 2x): they cross,
        // and the point (0.3, 0.5, 1) is seen from x = (2.6 +- sqrt(1.16)) / 4.
        let (left, right) = (DVec3::new(1.0, 0.0, 1.0), DVec3::new(-2.0, 0.0, 3.0));
        let mesh = TrilinearMesh {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
            normals: vec![left, right, left, right],
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y, DVec2::ONE],
            triangles: vec![[0, 1, 3], [0, 3, 2]],
        };
        let trilinear = Trilinear::new(&mesh, 100, 80).unwrap();
        let point = DVec3::new(0.3, 0.5, 1.0);
        let mut out = Vec::new();
        trilinear.project(point, &mut out);
        out.sort_by(|a, b| a.pixel.x.total_cmp(&b.pixel.x));
        assert_eq!(out.len(), 2, "{out:?}");
        let root = 1.16_f64.sqrt();
        for (image, x) in out.iter().zip([(2.6 - root) / 4.0, (2.6 + root) / 4.0]) {
            assert!(
                (image.pixel - DVec2::new(100.0 * x, 40.0)).length() < 1e-9,
                "{out:?}"
            );
            assert!((image.t - 1.0 / (1.0 + 2.0 * x)).abs() < 1e-12);
            let ray = trilinear.ray(image.pixel).unwrap();
            assert!((ray.at(image.t) - point).length() < 1e-12);
        }
    }

    #[test]
    fn overlapping_screen_triangles_keep_only_the_visible_ray() {
        // Two projection triangles with the same screen triangle: `ray` uses the first, so
        // only its image of a point counts.
        let mesh = TrilinearMesh {
            points: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(0.0, 1.0, 1.0),
            ],
            normals: vec![DVec3::Z; 6],
            screen: vec![
                DVec2::ZERO,
                DVec2::X,
                DVec2::Y,
                DVec2::ZERO,
                DVec2::X,
                DVec2::Y,
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let trilinear = Trilinear::new(&mesh, 10, 10).unwrap();
        let mut out = Vec::new();
        trilinear.project(DVec3::new(0.2, 0.3, 3.0), &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!((out[0].t - 3.0).abs() < 1e-12, "{out:?}");
    }

    /// A 3 x 3-cell surface seen by an eye at the origin looking down +z, whose screen
    /// position `s` images `(4 s - 2) z` at depth `z` (the grid vertex's `depths` entry):
    /// base points at varying depths, rays `(tilt, 1) length`, and weights `1 / z`.
    fn eye_surface(depths: &[f64], tilts: &[(f64, f64, f64)]) -> (TrilinearMesh, Vec<f64>) {
        let index = |s: DVec2| (4.0 * (3.0 * s.y).round() + (3.0 * s.x).round()) as usize;
        let mesh = screen_grid(3, |s| {
            let z = depths[index(s)];
            let (tx, ty, len) = tilts[index(s)];
            GridVertex {
                point: DVec3::new((4.0 * s.x - 2.0) * z, (4.0 * s.y - 2.0) * z, z),
                direction: DVec3::new(tx, ty, 1.0) * len,
            }
        })
        .unwrap();
        let weights = mesh.points.iter().map(|p| 1.0 / p.z).collect();
        (mesh, weights)
    }

    #[test]
    fn screen_weights_are_validated() {
        let (mesh, mut weights) = eye_surface(&[2.0; 16], &[(0.0, 0.0, 1.0); 16]);
        assert!(Trilinear::with_screen_weights(&mesh, &weights, 8, 8).is_ok());
        let short = Trilinear::with_screen_weights(&mesh, &weights[1..], 8, 8);
        assert!(short.unwrap_err().message.contains("15 for 16 vertices"));
        for bad in [0.0, -0.5, f64::NAN, f64::INFINITY] {
            weights[5] = bad;
            let error = Trilinear::with_screen_weights(&mesh, &weights, 8, 8).unwrap_err();
            assert!(error.message.contains("finite and positive"), "{bad}");
        }
        // The affine projection has no weights.
        let affine = Trilinear::new(&mesh, 8, 8).unwrap();
        assert!(affine.projective_map([0, 1, 2]).is_none());
    }

    mod projective_round_trip {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(300))]

            /// Pixel -> ray -> point -> project -> the pixel again (and every image's ray
            /// reaches the point), and each pixel's ray starts on the eye's ray through the
            /// pixel: the projective map is the eye's.
            #[test]
            fn pixel_to_point_to_pixel_through_an_eye_surface(
                depths in proptest::collection::vec(2.0..6.0f64, 16),
                tilts in proptest::collection::vec(
                    (-0.01..0.01f64, -0.01..0.01f64, 0.5..2.0f64), 16),
                (x, y) in (0.0..1.0f64, 0.0..1.0f64),
                t in 0.0..10.0f64,
            ) {
                let (mesh, weights) = eye_surface(&depths, &tilts);
                let (width, height) = (640, 480);
                let trilinear =
                    Trilinear::with_screen_weights(&mesh, &weights, width, height).unwrap();
                let pixel = DVec2::new(x * f64::from(width), y * f64::from(height));
                let ray = trilinear.ray(pixel).unwrap();
                let eye_ray = DVec3::new(4.0 * x - 2.0, 4.0 * (1.0 - y) - 2.0, 1.0);
                prop_assert!(
                    ray.origin.cross(eye_ray).length() <= 1e-12 * ray.origin.length() * eye_ray.length(),
                    "origin {} off the eye ray {}", ray.origin, eye_ray
                );
                round_trip::check(&trilinear, pixel, ray.at(t), t)?;
            }
        }
    }

    mod round_trip {
        use super::*;
        use proptest::prelude::*;
        use proptest::test_runner::TestCaseError;

        /// `point`, at `t` on the ray of `pixel`, projects back to `pixel` at `t` among its
        /// images, and every image's ray reaches it.
        pub(super) fn check(
            trilinear: &Trilinear,
            pixel: DVec2,
            point: DVec3,
            t: f64,
        ) -> std::result::Result<(), TestCaseError> {
            let mut out = Vec::new();
            trilinear.project(point, &mut out);
            let found = out.iter().any(|image| {
                (image.pixel - pixel).length() <= 1e-6 && (image.t - t).abs() <= 1e-9 * t.max(1.0)
            });
            prop_assert!(found, "{pixel} t {t}: {out:?}");
            for image in &out {
                let r = trilinear.ray(image.pixel).unwrap();
                prop_assert!((r.at(image.t) - point).length() <= 1e-9 * (1.0 + point.length()));
            }
            Ok(())
        }

        /// A 4 x 4 vertex grid on screen; points on a plane grid with offsets up to 0.1 of
        /// the spacing, normals (0, 0, 1) tilted by up to 0.01 per component (rays cross no
        /// earlier than t ~ 15, so no fold for t <= 10), lengths 0.5..2.
        fn perturbed_grid() -> impl Strategy<Value = TrilinearMesh> {
            let n = 16;
            (
                proptest::collection::vec((-0.1..0.1f64, -0.1..0.1f64, -0.1..0.1f64), n),
                proptest::collection::vec((-0.01..0.01f64, -0.01..0.01f64, 0.5..2.0f64), n),
                -100.0..100.0f64,
            )
                .prop_map(|(offsets, tilts, shift)| {
                    screen_grid(3, |s| {
                        // The vertex's index, row by row from the bottom.
                        let (i, j) = ((3.0 * s.x).round(), (3.0 * s.y).round());
                        let k = (4.0 * j + i) as usize;
                        let (ox, oy, oz) = offsets[k];
                        let (tx, ty, len) = tilts[k];
                        GridVertex {
                            point: DVec3::new(shift + s.x + ox / 3.0, s.y + oy / 3.0, oz / 3.0),
                            direction: DVec3::new(tx, ty, 1.0) * len,
                        }
                    })
                    .unwrap()
                })
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(500))]

            #[test]
            fn pixel_to_point_to_pixel(
                mesh in perturbed_grid(),
                (x, y) in (0.0..1.0f64, 0.0..1.0f64),
                t in 0.0..10.0f64,
            ) {
                let (width, height) = (640, 480);
                let trilinear = Trilinear::new(&mesh, width, height).unwrap();
                let pixel = DVec2::new(x * f64::from(width), y * f64::from(height));
                let ray = trilinear.ray(pixel).unwrap();
                round_trip::check(&trilinear, pixel, ray.at(t), t)?;
            }
        }
    }
}
