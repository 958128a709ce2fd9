//! The prepared scene: what every renderer reads, built once per scene and command and shared
//! read-only (`&PreparedScene`) by all of them.
//!
//! [`PreparedScene::new`] gathers every object's world-space triangles into one BVH (binned
//! SAH, f32 traversal; `crate::render::bvh`) beside the scene itself (objects with their
//! meshes, materials and textures, lights, background) and the secondary-ray offset. The BVH
//! queries here are what shading and every renderer's fallbacks trace with:
//! [`PreparedScene::intersect`] is the exact closest-hit query other renderers are checked
//! against, [`PreparedScene::occluded`] the shadow-ray query. A command builds one prepared
//! scene and renders it as often as it likes (every frame of an animation, both methods of a
//! comparison); [`PreparedScene::bvh_builds`] counts the BVH builds made for it: 1.
//!
//! Reflector compositing renders parts of the scene (the scene without a reflector, the
//! reflector alone) and the scene with other materials: those are views
//! (`PreparedScene::view`) that share this scene's BVH and meshes (a scene's objects hold
//! their meshes by `Arc`, so neither preparing nor a view copies a mesh), and leave out the
//! triangles of the objects they hide by a `TriangleMask` the queries honour.

use std::any::Any;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use glam::{DVec3, Vec2, Vec3};

use crate::geometry::{intersect_triangle, Ray};
use crate::render::bvh::curve_triangle::CurveTriangle;
use crate::render::bvh::triangle::FastRay;
use crate::render::bvh::{AllTriangles, Bvh, BvhHit, Keep, LightBuffer, TriangleMask};
use crate::render::displaced::DisplacedSet;
use crate::render::shading::{face_normal, object_points};
use crate::scene::{Light, Object, Pattern, Scene};

mod displaced_hits;
mod transition_hits;

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
    /// `t` in f64 where the search that found the hit was already the exact one (displaced
    /// objects, whose barycentrics are then exact too): [`PreparedScene::refine`] keeps it
    /// instead of searching again.
    pub exact_t: Option<f64>,
}

/// A scene prepared for rendering by any method (see the module documentation).
#[derive(Debug)]
pub struct PreparedScene {
    pub(in crate::render) scene: Scene,
    /// The BVH over every object's triangles, shared by the views of this scene.
    pub(in crate::render) bvh: Arc<Bvh>,
    /// The stored triangles a view shows (`None`: all of them, the scene itself).
    shown: Option<TriangleMask>,
    /// Global index of each object's first triangle, as the BVH numbers triangles.
    pub(in crate::render) first_triangle: Arc<[u32]>,
    /// How far secondary rays start off a surface: a fixed fraction of the scene's largest
    /// coordinate magnitude, so it covers f32 rounding at any scene scale.
    pub(in crate::render) offset: f64,
    pub(in crate::render) triangle_count: usize,
    pub(in crate::render) build_ms: f64,
    /// BVH builds made for this scene (views build none).
    bvh_builds: AtomicU64,
    /// The BVH's triangles in stored order with the quadratic search's tests precomputed,
    /// built on the first quadratic search ([`PreparedScene::curve_triangles`]): renders
    /// without curved projectors neither pay for it nor hold it. Shared by the views.
    curve_triangles: Arc<OnceLock<Vec<CurveTriangle>>>,
    /// The displaced objects, whose triangles the BVH leaves out ([`crate::render::displaced`]);
    /// `None` when there are none.
    pub(in crate::render) displaced: Option<Arc<DisplacedSet>>,
    /// The unit face normal of every stored triangle ([`crate::render::shading::face_normal`]),
    /// in the numbering of `first_triangle`: the lit shading of each hit reads it instead
    /// of computing it.
    face_normals: Arc<[Vec3]>,
    /// The mesh positions in object space of every checkered object (`None` for the
    /// others), by object index: lit shading reads a hit's object-space corners here
    /// ([`crate::render::shading::TriangleBase`]) instead of transforming them per hit.
    object_points: Vec<Option<Arc<[Vec3]>>>,
    /// Working memory a renderer leaves for the next render of this scene
    /// ([`PreparedScene::keep_spare`]): the raster's z-buffer, bins and pixel projectors, so
    /// that a sequence of frames (a viewer editing its projection) does not allocate and
    /// page-fault them again every frame.
    spare: Mutex<Option<Box<dyn Any + Send>>>,
    /// Per light of the scene, its light buffer over the BVH ([`LightBuffer`]), built on
    /// the first shadow ray and kept for every later one (`None` for a light without one);
    /// shared with the views of the same lights, as the BVH is.
    light_buffers: Arc<OnceLock<Vec<Option<LightBuffer>>>>,
}

/// The fewest BVH triangles for which shadow rays are answered through light buffers
/// ([`LightBuffer`]): below it the BVH's walk is as cheap as a cell's lookup (on the
/// 686-triangle cube-floor a lit frame costs the same either way, on the 123,554-triangle
/// teapot-dense panorama the buffers save 5 to 11 %; docs/viewer.md, "Speed").
const LIGHT_BUFFER_TRIANGLES: usize = 8192;

/// Secondary-ray offset relative to the scene's largest coordinate magnitude: 2^-16, about
/// 256 f32 ulps, well above the rounding of an f32 hit point and small against any feature.
const OFFSET_SCALE: f64 = 1.0 / 65536.0;

// A view's masked queries, out of line: the unmasked queries (every render of a whole scene)
// inline only the traversal they had.

#[inline(never)]
fn closest_shown(bvh: &Bvh, ray: &FastRay, mask: &TriangleMask) -> Option<BvhHit> {
    bvh.closest(ray, mask)
}

#[inline(never)]
fn closest4_shown(
    bvh: &Bvh,
    rays: [Option<&FastRay>; 4],
    mask: &TriangleMask,
) -> [Option<BvhHit>; 4] {
    bvh.closest4(rays, mask)
}

#[inline(never)]
fn occluded_shown(bvh: &Bvh, ray: &FastRay, mask: &TriangleMask) -> bool {
    bvh.occluded(ray, mask)
}

#[inline(never)]
fn occluded4_shown(bvh: &Bvh, rays: [Option<&FastRay>; 4], mask: &TriangleMask) -> [bool; 4] {
    bvh.occluded4(rays, mask)
}

/// The f32 forms of four rays. Spelled out, as in `intersect4_f32`: `array::map` here costs
/// a closure call a ray.
#[inline]
fn fast_rays(rays: [Option<&Ray>; 4]) -> [Option<FastRay>; 4] {
    [
        rays[0].and_then(FastRay::new),
        rays[1].and_then(FastRay::new),
        rays[2].and_then(FastRay::new),
        rays[3].and_then(FastRay::new),
    ]
}

/// Whether `object`'s pattern is a checker, which reads the object-space point of a hit.
fn checkered(object: &Object) -> bool {
    matches!(object.material.pattern, Pattern::Checker { .. })
}

/// The secondary-ray offset of `scene`: [`OFFSET_SCALE`] of its largest coordinate magnitude.
fn offset_of(scene: &Scene) -> f64 {
    let extent = scene
        .objects
        .iter()
        .filter_map(|o| o.mesh.bounds())
        .fold(0.0f32, |m, (lo, hi)| {
            m.max(lo.abs().max_element()).max(hi.abs().max_element())
        });
    (extent as f64 * OFFSET_SCALE).max(f64::MIN_POSITIVE)
}

impl PreparedScene {
    /// Builds the BVH over all triangles of `scene`, a copy of which it keeps (sharing its
    /// meshes and textures).
    ///
    /// ```
    /// use flexcam::glam::{DVec2, DVec3};
    /// use flexcam::render::PreparedScene;
    ///
    /// let scene = flexcam::scene::load("builtin:cube-floor")?;
    /// let prepared = PreparedScene::new(&scene);
    /// // Every render of this scene reads it; it also answers ray queries of its own.
    /// let projection = scene.projection.build(64, 48)?;
    /// let centre = projection.ray(DVec2::new(32.0, 24.0)).expect("a pinhole sees everywhere");
    /// let hit = prepared.intersect(&centre).expect("the cube is in the middle of the view");
    /// assert_eq!(scene.objects[hit.object].name, "cube");
    /// assert!(hit.t > 0.0);
    /// // A ray pointing away from everything hits nothing.
    /// let up = flexcam::geometry::Ray::new(DVec3::new(0.0, 50.0, 0.0), DVec3::Y);
    /// assert!(prepared.intersect(&up).is_none());
    /// # Ok::<(), flexcam::Error>(())
    /// ```
    pub fn new(scene: &Scene) -> PreparedScene {
        let start = Instant::now();
        let mut first_triangle = Vec::with_capacity(scene.objects.len());
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        // Each composited reflector in a group of its own: the views that hide it, or show
        // it alone, prune the tree at its group's root.
        let mut groups = Vec::with_capacity(scene.triangle_count());
        for object in &scene.objects {
            first_triangle.push(triangles.len() as u32);
            if object.displacement.is_some() {
                continue;
            }
            let group = (scene.trilinear_reflectors.iter())
                .position(|r| r.id == object.id)
                .map_or(0, |k| k as u32 + 1);
            let p = &object.mesh.positions;
            triangles.extend(
                object
                    .mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| p[i as usize])),
            );
            groups.resize(triangles.len(), group);
        }
        let bvh = Bvh::build_grouped(&triangles, |id| groups[id as usize]);
        let face_normals = (scene.objects.iter())
            .filter(|o| o.displacement.is_none())
            .flat_map(|o| (0..o.mesh.triangles.len()).map(move |t| face_normal(o, t)))
            .collect();
        let object_points = (scene.objects.iter())
            .map(|o| checkered(o).then(|| object_points(o).into()))
            .collect();
        PreparedScene {
            face_normals,
            object_points,
            bvh: Arc::new(bvh),
            shown: None,
            scene: scene.clone(),
            first_triangle: first_triangle.into(),
            offset: offset_of(scene),
            triangle_count: triangles.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            bvh_builds: AtomicU64::new(1),
            curve_triangles: Arc::default(),
            displaced: DisplacedSet::new(scene),
            spare: Mutex::default(),
            light_buffers: Arc::default(),
        }
    }

    /// A view of this scene as `scene` shows it, sharing this scene's BVH (no build).
    /// `scene` is this scene's objects in the same order, each with this scene's mesh (the
    /// same `Arc`, not a copy) or with an empty one (hidden: the view leaves its triangles out
    /// of every query), and any materials. The view renders exactly as `scene` prepared on its own would (the
    /// secondary-ray offset is that of the shown objects), up to the order of hits at equal
    /// `t`.
    pub(in crate::render) fn view(&self, scene: Scene) -> PreparedScene {
        debug_assert_eq!(self.scene.objects.len(), scene.objects.len());
        debug_assert!(self
            .scene
            .objects
            .iter()
            .zip(&scene.objects)
            .all(|(a, b)| Arc::ptr_eq(&a.mesh, &b.mesh) || b.mesh.triangles.is_empty()));
        let object_shown: Vec<bool> = (self.scene.objects.iter().zip(&scene.objects))
            .map(|(a, b)| a.mesh.triangles.is_empty() || !b.mesh.triangles.is_empty())
            .collect();
        let shown = (!object_shown.iter().all(|&s| s)).then(|| {
            TriangleMask::by_id(&self.bvh, |id| {
                object_shown[self.first_triangle.partition_point(|&f| f <= id) - 1]
            })
        });
        // The displaced objects are not in the BVH: a view hiding one has a displaced set of
        // its own.
        let hides_displaced = (self.scene.objects.iter().zip(&object_shown))
            .any(|(o, &shown)| !shown && o.displacement.is_some());
        let displaced = if hides_displaced {
            DisplacedSet::new(&scene)
        } else {
            self.displaced.clone()
        };
        // Kept where the view's object is placed as this scene's (its mesh is this scene's).
        let object_points = (self.scene.objects.iter().zip(&scene.objects))
            .zip(&self.object_points)
            .map(|((a, b), kept)| match kept {
                Some(points) if a.world_to_object == b.world_to_object => {
                    checkered(b).then(|| Arc::clone(points))
                }
                _ => checkered(b).then(|| object_points(b).into()),
            })
            .collect();
        let scene_lights_equal = scene.lights == self.scene.lights;
        PreparedScene {
            bvh: Arc::clone(&self.bvh),
            object_points,
            shown,
            first_triangle: Arc::clone(&self.first_triangle),
            offset: offset_of(&scene),
            triangle_count: scene.triangle_count(),
            scene,
            build_ms: self.build_ms,
            bvh_builds: AtomicU64::new(0),
            curve_triangles: Arc::clone(&self.curve_triangles),
            face_normals: Arc::clone(&self.face_normals),
            displaced,
            spare: Mutex::default(),
            // The buffers bin the shared BVH's leaves by the lights' directions; each query
            // checks its ray against the light, so a view of the same lights reuses them.
            light_buffers: if scene_lights_equal {
                Arc::clone(&self.light_buffers)
            } else {
                Arc::default()
            },
        }
    }

    /// Whether stored triangle `stored` is shown (see [`PreparedScene::view`]).
    #[inline]
    pub(in crate::render) fn shows(&self, stored: usize) -> bool {
        self.shown.as_ref().is_none_or(|mask| mask.keeps(stored))
    }

    /// The unit face normal of triangle `triangle` of object index `object` (an object the
    /// BVH holds: not a displaced one), as [`crate::render::shading::face_normal`] gives it.
    #[inline]
    pub(in crate::render) fn face_normal(&self, object: usize, triangle: usize) -> Vec3 {
        self.face_normals[self.first_triangle[object] as usize + triangle]
    }

    /// The mesh positions of object index `object` in object space, kept where its pattern
    /// is a checker (the only pattern that reads them).
    #[inline]
    pub(in crate::render) fn object_points(&self, object: usize) -> Option<&[Vec3]> {
        self.object_points[object].as_deref()
    }

    /// The working memory of type `T` the last renderer left ([`PreparedScene::keep_spare`]),
    /// if any; `None` also while another renderer holds it (it then allocates its own).
    pub(in crate::render) fn take_spare<T: Any + Send>(&self) -> Option<T> {
        let mut spare = self
            .spare
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        match spare.take()?.downcast::<T>() {
            Ok(kept) => Some(*kept),
            Err(other) => {
                *spare = Some(other);
                None
            }
        }
    }

    /// Leaves `memory` for the next renderer of this scene (replacing what was left).
    pub(in crate::render) fn keep_spare<T: Any + Send>(&self, memory: T) {
        *self
            .spare
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(Box::new(memory));
    }

    /// The scene this was prepared from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// How many BVHs were built for this scene: 1 (the views reflector compositing renders
    /// share it).
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
            let ray = FastRay::new(ray)?;
            match &self.shown {
                None => self.bvh.closest(&ray, &AllTriangles),
                Some(mask) => closest_shown(&self.bvh, &ray, mask),
            }
            .map(|f| self.hit32(f))
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
        // Spelled out: `array::map` here is not inlined and costs a closure call per ray.
        let fast = [
            self.fast_unless_outside(rays[0]),
            self.fast_unless_outside(rays[1]),
            self.fast_unless_outside(rays[2]),
            self.fast_unless_outside(rays[3]),
        ];
        let fast_rays = fast.each_ref().map(Option::as_ref);
        let found = match &self.shown {
            None => self.bvh.closest4(fast_rays, &AllTriangles),
            Some(mask) => closest4_shown(&self.bvh, fast_rays, mask),
        };
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
            exact_t: None,
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
        FastRay::new(ray).is_some_and(|r| match &self.shown {
            None => self.bvh.occluded(&r, &AllTriangles),
            Some(mask) => occluded_shown(&self.bvh, &r, mask),
        }) || self.displaced_occludes(ray)
    }

    /// [`PreparedScene::occluded`] of four rays at once (`None`: no ray, answered `false`),
    /// with identical answers: coherent shadow rays (a 2x2 quad's, towards one light) share
    /// one BVH traversal ([`Bvh::occluded4`]).
    pub(in crate::render) fn occluded4(&self, rays: [Option<&Ray>; 4]) -> [bool; 4] {
        let fast = fast_rays(rays);
        let lanes = fast.each_ref().map(Option::as_ref);
        let blocked = match &self.shown {
            None => self.bvh.occluded4(lanes, &AllTriangles),
            Some(mask) => occluded4_shown(&self.bvh, lanes, mask),
        };
        self.or_displaced(rays, blocked)
    }

    /// [`PreparedScene::occluded4`] of four shadow rays towards light `light` (an index into
    /// the scene's lights), with identical answers, through that light's [`LightBuffer`]:
    /// each ray tests only the BVH leaves its direction from the light can meet.
    pub(in crate::render) fn occluded4_towards(
        &self,
        light: usize,
        rays: [Option<&Ray>; 4],
    ) -> [bool; 4] {
        let Some(buffer) = self.light_buffer(light) else {
            return self.occluded4(rays);
        };
        let fast = fast_rays(rays);
        let lane = |k: usize| Some((rays[k]?, fast[k].as_ref()?));
        let lanes = [lane(0), lane(1), lane(2), lane(3)];
        let blocked = match &self.shown {
            None => buffer.occluded4(&self.bvh, lanes, &AllTriangles),
            Some(mask) => buffer.occluded4(&self.bvh, lanes, mask),
        };
        self.or_displaced(rays, blocked)
    }

    /// [`PreparedScene::occluded`] of a shadow ray towards light `light`, with the same
    /// answer, through that light's [`LightBuffer`] (see [`PreparedScene::occluded4_towards`]).
    pub(in crate::render) fn occluded_towards(&self, light: usize, ray: &Ray) -> bool {
        let Some(buffer) = self.light_buffer(light) else {
            return self.occluded(ray);
        };
        FastRay::new(ray).is_some_and(|fast| match &self.shown {
            None => buffer.occluded(&self.bvh, ray, &fast, &AllTriangles),
            Some(mask) => buffer.occluded(&self.bvh, ray, &fast, mask),
        }) || self.displaced_occludes(ray)
    }

    /// The light buffer of light `light`, built with those of every light on the first call;
    /// `None` for a BVH of fewer than [`LIGHT_BUFFER_TRIANGLES`] triangles, whose walk costs
    /// no more than a cell's lookup.
    fn light_buffer(&self, light: usize) -> Option<&LightBuffer> {
        let buffers = self.light_buffers.get_or_init(|| {
            if self.bvh.all_triangles().len() < LIGHT_BUFFER_TRIANGLES {
                return Vec::new();
            }
            (self.scene.lights.iter())
                .map(|light| match *light {
                    Light::Point { position, .. } => {
                        LightBuffer::point(&self.bvh, position.as_dvec3())
                    }
                    // The direction of its shadow rays (`LightTerms`).
                    Light::Directional { direction, .. } => {
                        LightBuffer::parallel(&self.bvh, -direction.as_dvec3())
                    }
                })
                .collect()
        });
        buffers.get(light)?.as_ref()
    }

    /// `blocked` (the answers of the BVH to `rays`) with the displaced objects' occlusion.
    fn or_displaced(&self, rays: [Option<&Ray>; 4], blocked: [bool; 4]) -> [bool; 4] {
        if self.displaced.is_none() {
            return blocked;
        }
        std::array::from_fn(|i| {
            blocked[i] || rays[i].is_some_and(|ray| self.displaced_occludes(ray))
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A view of the same lights shares the light buffers (built once for both); a view
    /// whose light moved builds its own; both answer shadow rays as the walk does.
    #[test]
    fn views_of_the_same_lights_share_light_buffers() {
        let mut scene = crate::scene::file::parse(
            r#"
[image]
width = 8
height = 8
[projection]
type = "perspective"
position = [0.0, 1.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov = 50.0
[[object]]
name = "ball"
shape = "sphere"
size = 1.0
tessellation = 128
[[object]]
name = "floor"
shape = "plane"
size = [8.0, 8.0]
translate = [0.0, -1.0, 0.0]
[[light]]
type = "point"
position = [1.0, 4.0, 1.0]
"#,
            std::path::Path::new("test"),
        )
        .unwrap();
        let prepared = PreparedScene::new(&scene);
        assert!(prepared.bvh.all_triangles().len() >= LIGHT_BUFFER_TRIANGLES);
        let light = DVec3::new(1.0, 4.0, 1.0);
        // Shadow rays from points of the floor, some behind the ball.
        let shadow = |from: &PreparedScene, x: f64, z: f64, light: DVec3| {
            let point = DVec3::new(x, -1.0, z);
            let mut ray = from.spawn(point, DVec3::Y, light - point);
            ray.t_max = 1.0;
            ray
        };
        let check = |from: &PreparedScene, light: DVec3| {
            let mut blocked = 0;
            for k in 0..400 {
                let (x, z) = (f64::from(k % 20) * 0.3 - 3.0, f64::from(k / 20) * 0.3 - 3.0);
                let ray = shadow(from, x, z, light);
                let walked = from.occluded(&ray);
                assert_eq!(from.occluded_towards(0, &ray), walked, "{x} {z}");
                blocked += usize::from(walked);
            }
            assert!(blocked > 0 && blocked < 400, "{blocked}");
        };
        check(&prepared, light);
        assert!(prepared.light_buffer(0).is_some());
        let same = prepared.view(scene.clone());
        assert!(Arc::ptr_eq(&same.light_buffers, &prepared.light_buffers));
        check(&same, light);
        let moved = DVec3::new(-1.0, 4.0, 0.5);
        scene.lights[0] = Light::Point {
            position: moved.as_vec3(),
            color: Vec3::ONE,
            intensity: 1.0,
        };
        let other = prepared.view(scene);
        assert!(!Arc::ptr_eq(&other.light_buffers, &prepared.light_buffers));
        check(&other, moved);
    }
}
