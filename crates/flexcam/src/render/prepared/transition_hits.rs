//! The prepared scene's queries for the transition system (`render::transitions`): first
//! hits with the displaced objects traced as their undisplaced base triangles (the outer
//! hull, where the transition function is evaluated) or displaced by a fraction of their
//! displacement (partial displacement). Every other triangle is searched as by
//! [`PreparedScene::intersect`].

use crate::displace::{base_corners, DisplacedTriangle, Displacement};
use crate::geometry::{intersect_triangle, Ray};
use crate::render::bvh::triangle::FastRay;
use crate::render::bvh::AllTriangles;
use crate::render::prepared::{closest_shown, occluded_shown, Hit, PreparedScene};

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
        let blocked = FastRay::new(ray).is_some_and(|r| match &self.shown {
            None => self.bvh.occluded(&r, &AllTriangles),
            Some(mask) => occluded_shown(&self.bvh, &r, mask),
        });
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

    /// The first hit of `ray` with each displaced object displaced as `partial(object)`
    /// says (a fraction of its own displacement, same height field and level); hits on
    /// displaced objects are reported on the base triangle as [`PreparedScene::intersect`]
    /// reports them.
    pub(in crate::render) fn intersect_partial<'d>(
        &self,
        ray: &Ray,
        partial: impl Fn(usize) -> &'d Displacement,
    ) -> Option<Hit> {
        let found = self.undisplaced_hit(ray);
        let Some(set) = &self.displaced else {
            return found;
        };
        let limit = found.map_or(f64::INFINITY, |h| h.t);
        let hit = set.closest_by(ray, limit, false, |item, _, bounded| {
            let object = item.object as usize;
            let displacement = partial(object);
            let corners = base_corners(&self.scene.objects[object].mesh, item.triangle as usize);
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
