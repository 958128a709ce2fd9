//! The prepared scene: what every renderer reads, built once per scene and command and shared
//! read-only (`&PreparedScene`) by all of them.
//!
//! [`PreparedScene::new`] gathers every object's world-space triangles into one BVH (binned
//! SAH, f32 traversal; [`crate::render::bvh`]) beside the scene itself (objects with their
//! meshes, materials and textures, lights, background) and the secondary-ray offset. The BVH
//! queries here are what shading and every renderer's fallbacks trace with:
//! [`PreparedScene::intersect`] is the exact closest-hit query other renderers are checked
//! against, [`PreparedScene::occluded`] the shadow-ray query. A command builds one prepared
//! scene and renders it as often as it likes (every frame of an animation, both methods of a
//! comparison); [`PreparedScene::bvh_builds`] counts the BVH builds made for it, including
//! those of the scene variants reflector compositing renders ([`PreparedScene::variant`]).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use glam::{DVec3, Vec2};

use crate::geometry::{intersect_triangle, Ray};
use crate::render::bvh::curve_triangle::CurveTriangle;
use crate::render::bvh::triangle::FastRay;
use crate::render::bvh::{Bvh, BvhHit};
use crate::render::displaced::DisplacedSet;
use crate::scene::Scene;

mod displaced_hits;

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

/// A hit as the f32 search reports it (see [`PreparedScene::intersect_f32`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct Hit32 {
    pub t: f32,
    pub object: usize,
    pub triangle: usize,
    pub barycentric: Vec2,
}

/// A scene prepared for rendering by any method (see the module documentation).
#[derive(Debug)]
pub struct PreparedScene {
    pub(in crate::render) scene: Scene,
    pub(in crate::render) bvh: Bvh,
    /// Global index of each object's first triangle, as the BVH numbers triangles.
    pub(in crate::render) first_triangle: Vec<u32>,
    /// How far secondary rays start off a surface: a fixed fraction of the scene's largest
    /// coordinate magnitude, so it covers f32 rounding at any scene scale.
    pub(in crate::render) offset: f64,
    pub(in crate::render) triangle_count: usize,
    pub(in crate::render) build_ms: f64,
    /// BVH builds made for this scene: its own, and those of the variants built from it.
    bvh_builds: AtomicU64,
    /// The BVH's triangles in stored order with the quadratic search's tests precomputed,
    /// built on the first quadratic search ([`PreparedScene::curve_triangles`]): renders
    /// without curved projectors neither pay for it nor hold it.
    curve_triangles: OnceLock<Vec<CurveTriangle>>,
    /// The displaced objects, whose triangles the BVH leaves out ([`crate::render::displaced`]);
    /// `None` when there are none.
    pub(in crate::render) displaced: Option<Arc<DisplacedSet>>,
}

/// Secondary-ray offset relative to the scene's largest coordinate magnitude: 2^-16, about
/// 256 f32 ulps, well above the rounding of an f32 hit point and small against any feature.
const OFFSET_SCALE: f64 = 1.0 / 65536.0;

impl PreparedScene {
    /// Builds the BVH over all triangles of `scene` (a copy of which it keeps).
    pub fn new(scene: &Scene) -> PreparedScene {
        let start = Instant::now();
        let mut first_triangle = Vec::with_capacity(scene.objects.len());
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        for object in &scene.objects {
            first_triangle.push(triangles.len() as u32);
            if object.displacement.is_some() {
                continue;
            }
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
        PreparedScene {
            bvh,
            scene: scene.clone(),
            first_triangle,
            offset: (extent as f64 * OFFSET_SCALE).max(f64::MIN_POSITIVE),
            triangle_count: triangles.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            bvh_builds: AtomicU64::new(1),
            curve_triangles: OnceLock::new(),
            displaced: DisplacedSet::new(scene),
        }
    }

    /// A prepared scene for `scene`, a variant of this one (another set of objects, e.g. the
    /// scene without a reflector), with its own BVH; the build is counted here too.
    pub(in crate::render) fn variant(&self, scene: &Scene) -> PreparedScene {
        self.bvh_builds.fetch_add(1, Ordering::Relaxed);
        PreparedScene::new(scene)
    }

    /// This scene with the materials of `scene`, whose objects' meshes must be this scene's
    /// (only materials differ): the BVH is copied, not built again.
    pub(in crate::render) fn with_materials(&self, scene: &Scene) -> PreparedScene {
        debug_assert!(self
            .scene
            .objects
            .iter()
            .zip(&scene.objects)
            .all(|(a, b)| a.mesh == b.mesh));
        PreparedScene {
            scene: scene.clone(),
            bvh: self.bvh.clone(),
            first_triangle: self.first_triangle.clone(),
            offset: self.offset,
            triangle_count: self.triangle_count,
            build_ms: self.build_ms,
            bvh_builds: AtomicU64::new(0),
            curve_triangles: OnceLock::new(),
            displaced: self.displaced.clone(),
        }
    }

    /// The scene this was prepared from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// How many BVHs were built for this scene so far: 1 for itself, plus one per variant
    /// that reflector compositing built from it.
    pub fn bvh_builds(&self) -> u64 {
        self.bvh_builds.load(Ordering::Relaxed)
    }

    /// Milliseconds the BVH build took.
    pub fn bvh_build_ms(&self) -> f64 {
        self.build_ms
    }

    /// The BVH's triangles as the quadratic search reads them, in stored order; built once,
    /// on the first call.
    pub(in crate::render) fn curve_triangles(&self) -> &[CurveTriangle] {
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
    pub(in crate::render) fn intersect_f32(&self, ray: &Ray) -> Option<Hit32> {
        let found = if self.misses_scene_box(ray) {
            None
        } else {
            self.bvh.closest(&FastRay::new(ray)?).map(|f| self.hit32(f))
        };
        self.nearer_displaced(ray, found)
    }

    /// Whether `ray`'s segment (its points over `[t_min, t_max]`, both ends finite) lies
    /// outside the scene's box: then it hits nothing, and costs this comparison instead of
    /// the reciprocal directions and slab test of a traversal. Most segments of a polyline
    /// projector pass in front of or behind a small model. Rays with an infinite end (every
    /// straight camera ray, secondary rays) are never culled here.
    #[inline]
    pub(in crate::render) fn misses_scene_box(&self, ray: &Ray) -> bool {
        let (a, b) = (ray.at(ray.t_min), ray.at(ray.t_max));
        a.is_finite() && b.is_finite() && !self.bvh.root_overlaps(a.min(b), a.max(b))
    }

    /// [`PreparedScene::intersect_f32`] of four rays at once, with identical results:
    /// coherent rays (a 2x2 quad of primary rays) share one BVH traversal.
    pub(in crate::render) fn intersect4_f32(&self, rays: [Option<&Ray>; 4]) -> [Option<Hit32>; 4] {
        let fast = rays.map(|r| self.fast_unless_outside(r));
        let found = self.bvh.closest4(fast.each_ref().map(Option::as_ref));
        let found = found.map(|f| f.map(|f| self.hit32(f)));
        if self.displaced.is_none() {
            return found;
        }
        std::array::from_fn(|i| match rays[i] {
            Some(ray) => self.nearer_displaced(ray, found[i]),
            None => None,
        })
    }

    /// The f32 form of `ray` for a BVH search, or `None` where it cannot hit anything: no
    /// ray, a segment outside the scene's box ([`PreparedScene::misses_scene_box`]), or what
    /// [`FastRay::new`] rejects (a zero direction, an empty interval).
    #[inline]
    fn fast_unless_outside(&self, ray: Option<&Ray>) -> Option<FastRay> {
        ray.filter(|r| !self.misses_scene_box(r))
            .and_then(FastRay::new)
    }

    /// The hit of BVH triangle `found`, known by object and triangle within its mesh.
    pub(in crate::render) fn hit32(&self, found: BvhHit) -> Hit32 {
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
    pub(in crate::render) fn refine(&self, ray: &Ray, found: Hit32) -> Hit {
        if let Some(hit) = self.refine_displaced(ray, found) {
            return hit;
        }
        let mesh = &self.scene.objects[found.object].mesh;
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

    /// Whether anything is hit within the ray's interval (the shadow-ray query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        FastRay::new(ray).is_some_and(|r| self.bvh.occluded(&r)) || self.displaced_occludes(ray)
    }

    /// A ray leaving surface point `point` (geometric normal `normal`) along `direction`,
    /// started [`PreparedScene::offset`] off the surface on the side `direction` points to,
    /// so that it does not hit the surface it leaves.
    pub(in crate::render) fn spawn(&self, point: DVec3, normal: DVec3, direction: DVec3) -> Ray {
        let side = if direction.dot(normal) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        Ray::new(point + normal * (side * self.offset), direction)
    }
}
