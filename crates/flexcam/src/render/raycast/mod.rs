//! The reference ray caster: a BVH built once per scene, tiles rendered in parallel.
//!
//! [`RayCaster::new`] gathers every object's world-space triangles into one BVH (binned SAH,
//! f32 traversal) and keeps what shading needs: the objects (meshes, materials,
//! `world_to_object`), lights and background. [`RayCaster::intersect`] is the exact closest-hit
//! query other renderers are checked against; [`RayCaster::render`] renders a projection into
//! a new frame, [`RayCaster::render_into`] into a frame the caller keeps.
//! See docs/raycast.md for the design and the measurements.

mod bvh;
mod curve;
mod curve_triangle;
mod hull_cull;
pub(crate) mod sampling;
mod shade;
mod tiles;
mod triangle;
pub mod workloads;

use std::sync::OnceLock;
use std::time::Instant;

use glam::{DVec3, Vec2, Vec3};

pub(crate) use self::sampling::SamplePattern;
pub(crate) use self::shade::specular;

use self::bvh::Bvh;
use self::curve_triangle::CurveTriangle;
use self::triangle::FastRay;
use crate::geometry::{intersect_triangle, Ray};
use crate::projection::Projection;
use crate::render::{Frame, RenderOptions, Stats};
use crate::scene::{Light, Object, Scene};

/// The first surface a ray meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (`ray.at(t)` is the point), within `[t_min, t_max]`.
    pub t: f64,
    /// Index of the object in `scene.objects` (not its 1-based id).
    pub object: usize,
    /// Index of the triangle within that object's mesh.
    pub triangle: usize,
    /// Barycentric weights `(u, v)` of the triangle's second and third vertices.
    pub barycentric: Vec2,
}

/// Segment `k` of polyline projector `points` as a ray over `t` in `[0, 1]`, from vertex `k`
/// to vertex `k + 1` (a zero direction where the two coincide).
fn polyline_segment(points: &[DVec3], k: usize) -> Ray {
    Ray {
        origin: points[k],
        direction: points[k + 1] - points[k],
        t_min: 0.0,
        t_max: 1.0,
    }
}

/// A hit as the f32 search reports it (see [`RayCaster::intersect_f32`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Hit32 {
    t: f32,
    object: usize,
    triangle: usize,
    barycentric: Vec2,
}

/// A scene prepared for ray casting.
#[derive(Debug, Clone)]
pub struct RayCaster {
    bvh: Bvh,
    objects: Vec<Object>,
    /// Global index of each object's first triangle, as the BVH numbers triangles.
    first_triangle: Vec<u32>,
    lights: Vec<Light>,
    background: Vec3,
    /// How far secondary rays start off a surface: a fixed fraction of the scene's largest
    /// coordinate magnitude, so it covers f32 rounding at any scene scale.
    offset: f64,
    triangle_count: usize,
    build_ms: f64,
    /// The BVH's triangles in stored order with the quadratic search's tests precomputed,
    /// built on the first quadratic search ([`RayCaster::curve_triangles`]): renders without
    /// curved projectors neither pay for it nor hold it.
    curve_triangles: OnceLock<Vec<CurveTriangle>>,
}

/// Secondary-ray offset relative to the scene's largest coordinate magnitude: 2^-16, about
/// 256 f32 ulps, well above the rounding of an f32 hit point and small against any feature.
const OFFSET_SCALE: f64 = 1.0 / 65536.0;

impl RayCaster {
    /// Builds the BVH over all triangles of `scene` and keeps what rendering needs.
    pub fn new(scene: &Scene) -> RayCaster {
        let start = Instant::now();
        let mut first_triangle = Vec::with_capacity(scene.objects.len());
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        for object in &scene.objects {
            first_triangle.push(triangles.len() as u32);
            let p = &object.mesh.positions;
            triangles.extend(
                object
                    .mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| p[i as usize])),
            );
        }
        let bvh = Bvh::build(&triangles);
        let extent = scene
            .objects
            .iter()
            .filter_map(|o| o.mesh.bounds())
            .fold(0.0f32, |m, (lo, hi)| {
                m.max(lo.abs().max_element()).max(hi.abs().max_element())
            });
        RayCaster {
            bvh,
            objects: scene.objects.clone(),
            first_triangle,
            lights: scene.lights.clone(),
            background: scene.image.background,
            offset: (extent as f64 * OFFSET_SCALE).max(f64::MIN_POSITIVE),
            triangle_count: triangles.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            curve_triangles: OnceLock::new(),
        }
    }

    /// The BVH's triangles as the quadratic search reads them, in stored order; built once,
    /// on the first call.
    fn curve_triangles(&self) -> &[CurveTriangle] {
        self.curve_triangles.get_or_init(|| {
            self.bvh
                .all_triangles()
                .iter()
                .map(CurveTriangle::from_packed)
                .collect()
        })
    }

    /// The closest hit of `ray` with `t` in `[ray.t_min, ray.t_max]`, from either side of any
    /// triangle, or `None`. Zero-area triangles are never hit; a ray with a zero or non-finite
    /// direction or origin hits nothing.
    ///
    /// The BVH search runs in f32 (the interval is honoured to f32 precision); the hit found is
    /// then refined in f64 against the triangle's vertices, so `t` and the barycentrics are
    /// accurate to f64 precision for the triangle the f32 search chose.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_f32(ray).map(|found| self.refine(ray, found))
    }

    /// The closest hit as the f32 search finds it, without the f64 refinement: `t` and the
    /// barycentrics carry f32 rounding (relative error about 1e-7 times the ratio of the
    /// origin's magnitude to the hit distance). Enough for a flat colour and a depth stored
    /// as f32; everything that spawns rays from the hit refines it first.
    fn intersect_f32(&self, ray: &Ray) -> Option<Hit32> {
        if self.misses_scene_box(ray) {
            return None;
        }
        let found = self.bvh.closest(&FastRay::new(ray)?)?;
        Some(self.hit32(found))
    }

    /// Whether `ray`'s segment (its points over `[t_min, t_max]`, both ends finite) lies
    /// outside the scene's box: then it hits nothing, and costs this comparison instead of
    /// the reciprocal directions and slab test of a traversal. Most segments of a polyline
    /// projector pass in front of or behind a small model. Rays with an infinite end (every
    /// straight camera ray, secondary rays) are never culled here.
    #[inline]
    fn misses_scene_box(&self, ray: &Ray) -> bool {
        let (a, b) = (ray.at(ray.t_min), ray.at(ray.t_max));
        a.is_finite() && b.is_finite() && !self.bvh.root_overlaps(a.min(b), a.max(b))
    }

    /// [`RayCaster::intersect_f32`] of four rays at once, with identical results: coherent
    /// rays (a 2x2 quad of primary rays) share one BVH traversal.
    fn intersect4_f32(&self, rays: [Option<&Ray>; 4]) -> [Option<Hit32>; 4] {
        let fast = rays.map(|r| self.fast_unless_outside(r));
        let found = self.bvh.closest4(fast.each_ref().map(Option::as_ref));
        found.map(|f| f.map(|f| self.hit32(f)))
    }

    /// The f32 form of `ray` for a BVH search, or `None` where it cannot hit anything: no
    /// ray, a segment outside the scene's box ([`RayCaster::misses_scene_box`]), or what
    /// [`FastRay::new`] rejects (a zero direction, an empty interval).
    #[inline]
    fn fast_unless_outside(&self, ray: Option<&Ray>) -> Option<FastRay> {
        ray.filter(|r| !self.misses_scene_box(r))
            .and_then(FastRay::new)
    }

    /// The first hits of four polyline projectors (`None`: no projector) and the segments
    /// they lie on: for each, the first segment with a hit wins, and on it the nearest hit,
    /// exactly as searching the segments one by one with [`RayCaster::intersect_f32`] finds
    /// it. Segment k of the four is searched by one shared BVH traversal
    /// ([`Bvh::closest4`]), leaving out the polylines that have hit something already or have
    /// fewer segments, and the segments that `live` rules out. Degenerate cases: a
    /// zero-length segment sees nothing (and the next segment is searched); a hit exactly at
    /// a joint, the end of segment k and the start of segment k + 1, is segment k's (both
    /// ends of a segment's interval are closed); a joint on a triangle is such a hit.
    fn intersect4_polylines(
        &self,
        polylines: [Option<&[DVec3]>; 4],
        live: hull_cull::LiveParts,
    ) -> [Option<(usize, Hit32)>; 4] {
        let segments = polylines
            .iter()
            .flatten()
            .map(|p| p.len().saturating_sub(1))
            .max()
            .unwrap_or(0);
        let mut found: [Option<(usize, Hit32)>; 4] = [None; 4];
        for k in (0..segments).filter(|&k| live.may_hit(k)) {
            let rays: [Option<Ray>; 4] = std::array::from_fn(|i| match polylines[i] {
                Some(p) if found[i].is_none() && k + 1 < p.len() => Some(polyline_segment(p, k)),
                _ => None,
            });
            let hits = self.intersect4_f32(rays.each_ref().map(Option::as_ref));
            for (slot, hit) in found.iter_mut().zip(hits) {
                if let Some(hit) = hit {
                    *slot = Some((k, hit));
                }
            }
        }
        found
    }

    /// The hit of BVH triangle `found`, known by object and triangle within its mesh.
    fn hit32(&self, found: bvh::BvhHit) -> Hit32 {
        let object = match self.first_triangle.len() {
            1 => 0,
            _ => self.first_triangle.partition_point(|&f| f <= found.id) - 1,
        };
        Hit32 {
            t: found.hit.t,
            object,
            triangle: (found.id - self.first_triangle[object]) as usize,
            barycentric: Vec2::new(found.hit.u, found.hit.v),
        }
    }

    /// `found` (a hit of `ray`) with `t` and the barycentrics recomputed in f64.
    fn refine(&self, ray: &Ray, found: Hit32) -> Hit {
        let mesh = &self.objects[found.object].mesh;
        let [a, b, c] = mesh.triangles[found.triangle];
        let vertex = |i: u32| mesh.positions[i as usize].as_dvec3();
        let vertices = [vertex(a), vertex(b), vertex(c)];
        let (t, barycentric) = match intersect_triangle(ray.origin, ray.direction, vertices) {
            Some(exact) => (exact.t, exact.barycentric.as_vec2()),
            // Grazing an edge: f32 saw a hit where f64 does not; keep the f32 values.
            None => (found.t as f64, found.barycentric),
        };
        Hit {
            t: t.clamp(ray.t_min, ray.t_max),
            object: found.object,
            triangle: found.triangle,
            barycentric,
        }
    }

    /// The colour `options.shading` gives primary ray `ray` whose first hit is `hit` (found by
    /// any means, e.g. rasterisation), exactly as [`RayCaster::render`] shades it: mirrors,
    /// glass and shadows are traced from there with this caster. Also returns the number of
    /// secondary and shadow rays that took.
    pub fn shade_hit(&self, ray: &Ray, hit: Hit, options: &RenderOptions) -> (Vec3, u64) {
        let mut tracer = shade::Tracer::new(self, options);
        let color = tracer.shade_hit(ray, hit);
        (color, tracer.counts.secondary + tracer.counts.shadow)
    }

    /// Whether anything is hit within the ray's interval (the shadow-ray query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        FastRay::new(ray).is_some_and(|r| self.bvh.occluded(&r))
    }

    /// Renders `projection` (colour, depth and object ids) with `options` into a new frame
    /// (see [`RayCaster::render_into`]). The frame starts as zeroed memory
    /// ([`Frame::zeroed`]), not cleared to the background: every pixel is written.
    pub fn render(&self, projection: &dyn Projection, options: &RenderOptions) -> (Frame, Stats) {
        let (width, height) = projection.resolution();
        let mut frame = Frame::zeroed(width, height);
        let stats = self.render_into(&mut frame, projection, options);
        (frame, stats)
    }

    /// Renders `projection` (colour, depth and object ids) with `options` into `frame`, every
    /// pixel of it overwritten, in parallel over tiles; the image does not depend on the
    /// number of threads, nor on what `frame` held. A caller drawing frame after frame keeps
    /// one frame and pays neither its allocation nor the first touch of its pages again; a
    /// frame of another size than the projection's resolution (or whose buffers do not match
    /// its size) is replaced by one of the right size. `options.spp = 0` counts as one
    /// sample. See [`shade`] for what the depth and id of a pixel are.
    pub fn render_into(
        &self,
        frame: &mut Frame,
        projection: &dyn Projection,
        options: &RenderOptions,
    ) -> Stats {
        let (width, height) = projection.resolution();
        frame.fit(width, height);
        let mut stats = tiles::render(self, projection, options, frame);
        stats.insert("bvh_build_ms", crate::render::Counter::Value(self.build_ms));
        stats.insert(
            "bvh_nodes",
            crate::render::Counter::Count(self.bvh.node_count() as u64),
        );
        stats.insert(
            "triangles",
            crate::render::Counter::Count(self.triangle_count as u64),
        );
        stats
    }

    /// A ray leaving surface point `point` (geometric normal `normal`) along `direction`,
    /// started [`RayCaster::offset`] off the surface on the side `direction` points to, so that
    /// it does not hit the surface it leaves.
    fn spawn(&self, point: DVec3, normal: DVec3, direction: DVec3) -> Ray {
        let side = if direction.dot(normal) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        Ray::new(point + normal * (side * self.offset), direction)
    }
}

#[cfg(test)]
mod projector_tests;
#[cfg(test)]
mod tests;
