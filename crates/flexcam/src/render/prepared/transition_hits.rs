//! The prepared scene's queries for the transition system (`render::transitions`): first
//! hits with the displaced objects traced as their undisplaced base triangles (the outer
//! hull, where the transition function is evaluated), displaced by a fraction of their
//! displacement (partial displacement), or at a coarser level of detail (a scene whose
//! displaced objects have coarser meshes, and its set). Every other triangle is searched as
//! by [`PreparedScene::intersect`].

use crate::displace::{base_corners, DisplacedTriangle, Displacement};
use crate::geometry::{intersect_triangle, Ray};
use crate::render::bvh::triangle::FastRay;
use crate::render::bvh::AllTriangles;
use crate::render::displaced::DisplacedSet;
use crate::render::prepared::{closest_shown, occluded_shown, Hit, PreparedScene};
use crate::scene::Scene;

impl PreparedScene {
    /// The first hit of `ray` on the triangle BVH alone (displaced objects left out), in f64.
    fn undisplaced_hit(&self, ray: &Ray) -> Option<Hit> {
        if self.misses_scene_box(ray) {
            return None;
        }
        let fast = FastRay::new(ray)?;
        let found = match &self.shown {
            None => self.bvh.closest(&fast, &AllTriangles),
            Some(mask) => closest_shown(&self.bvh, &fast, mask),
        }?;
        Some(self.refine(ray, self.hit32(found)))
    }

    /// Whether a triangle of the BVH (displaced objects left out) blocks `ray`.
    fn undisplaced_occluded(&self, ray: &Ray) -> bool {
        FastRay::new(ray).is_some_and(|r| match &self.shown {
            None => self.bvh.occluded(&r, &AllTriangles),
            Some(mask) => occluded_shown(&self.bvh, &r, mask),
        })
    }

    /// The first hit of `ray` with every displaced object undisplaced (its base triangles,
    /// the outer hull of its displaced surface).
    pub(in crate::render) fn intersect_hull(&self, ray: &Ray) -> Option<Hit> {
        let found = self.undisplaced_hit(ray);
        let Some(set) = &self.displaced else {
            return found;
        };
        let limit = found.map_or(f64::INFINITY, |h| h.t);
        let hull = set.closest_by(ray, limit, false, |item, _, bounded| {
            let mesh = &self.scene.objects[item.object as usize].mesh;
            let corners = mesh.triangles[item.triangle as usize]
                .map(|i| mesh.positions[i as usize].as_dvec3());
            intersect_triangle(bounded.origin, bounded.direction, corners)
                .filter(|h| h.t >= bounded.t_min && h.t <= bounded.t_max)
                .map(|h| (h.t, h))
        });
        match hull {
            Some((object, triangle, h)) if h.t < limit => Some(Hit {
                t: h.t,
                object,
                triangle,
                barycentric: h.barycentric.as_vec2(),
            }),
            _ => found,
        }
    }

    /// Whether anything blocks `ray` with every displaced object undisplaced (the shadow
    /// rays of the bump and BRDF methods, whose relief is below a few footprints).
    pub(in crate::render) fn occluded_hull(&self, ray: &Ray) -> bool {
        let blocked = self.undisplaced_occluded(ray);
        blocked
            || self.displaced.as_ref().is_some_and(|set| {
                set.closest_by(ray, f64::INFINITY, true, |item, _, bounded| {
                    let mesh = &self.scene.objects[item.object as usize].mesh;
                    let corners = mesh.triangles[item.triangle as usize]
                        .map(|i| mesh.positions[i as usize].as_dvec3());
                    intersect_triangle(bounded.origin, bounded.direction, corners)
                        .filter(|h| h.t >= bounded.t_min && h.t <= bounded.t_max)
                        .map(|h| (h.t, ()))
                })
                .is_some()
            })
    }

    /// The first hit of `ray` with the displaced objects of `scene` (this scene's objects,
    /// their meshes at some level of detail; `set` their displaced set) fully displaced;
    /// hits on them are reported on their base triangles (of `scene`'s meshes) as
    /// [`PreparedScene::intersect`] reports them.
    pub(in crate::render) fn intersect_level(
        &self,
        ray: &Ray,
        scene: &Scene,
        set: &DisplacedSet,
    ) -> Option<Hit> {
        let found = self.undisplaced_hit(ray);
        let limit = found.map_or(f64::INFINITY, |h| h.t);
        match set.closest(scene, ray, limit, false) {
            Some(d) if d.micro.t < limit => {
                let level = set.displacement(d.object).map_or(0, Displacement::level);
                Some(Hit {
                    t: d.micro.t,
                    object: d.object,
                    triangle: d.triangle,
                    barycentric: d
                        .micro
                        .triangle
                        .base_barycentric(level, d.micro.barycentric)
                        .as_vec2(),
                })
            }
            _ => found,
        }
    }

    /// Whether anything blocks `ray` with the displaced objects of `scene` (a level of
    /// detail, as for [`PreparedScene::intersect_level`]) fully displaced.
    pub(in crate::render) fn occluded_level(
        &self,
        ray: &Ray,
        scene: &Scene,
        set: &DisplacedSet,
    ) -> bool {
        self.undisplaced_occluded(ray) || set.closest(scene, ray, f64::INFINITY, true).is_some()
    }

    /// The first hit of `ray` with each displaced object of `scene` (this scene's objects
    /// at some level of detail; `set` their displaced set) displaced as `partial(object)`
    /// says (a fraction of its own displacement, same height field and level); hits on
    /// displaced objects are reported on the base triangle as [`PreparedScene::intersect`]
    /// reports them.
    pub(in crate::render) fn intersect_partial<'d>(
        &self,
        ray: &Ray,
        scene: &Scene,
        set: &DisplacedSet,
        partial: impl Fn(usize) -> &'d Displacement,
    ) -> Option<Hit> {
        let found = self.undisplaced_hit(ray);
        let limit = found.map_or(f64::INFINITY, |h| h.t);
        let hit = set.closest_by(ray, limit, false, |item, _, bounded| {
            let object = item.object as usize;
            let displacement = partial(object);
            let corners = base_corners(&scene.objects[object].mesh, item.triangle as usize);
            DisplacedTriangle::new(corners, displacement)
                .intersect(bounded)
                .map(|micro| (micro.t, (micro, displacement.level())))
        });
        match hit {
            Some((object, triangle, (micro, level))) if micro.t < limit => Some(Hit {
                t: micro.t,
                object,
                triangle,
                barycentric: micro
                    .triangle
                    .base_barycentric(level, micro.barycentric)
                    .as_vec2(),
            }),
            _ => found,
        }
    }
}
