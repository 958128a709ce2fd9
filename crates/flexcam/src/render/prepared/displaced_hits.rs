//! The prepared scene's queries over its displaced objects ([`crate::render::displaced`]):
//! hits on displaced base triangles as prepared-scene hits, their f64 refinement and normals.
//! A displaced hit is reported on its base triangle, with the base-triangle barycentrics of
//! the hit's place in the subdivision; its normal is the micro-triangle's face normal.

use glam::{DVec2, Vec3};

use crate::displace::{Displacement, MicroTriangle};
use crate::geometry::Ray;
use crate::render::displaced::DisplacedHit;
use crate::render::prepared::{Hit, Hit32, PreparedScene};

impl PreparedScene {
    /// The displaced hit `found` as a hit of the prepared scene: base triangle and base
    /// barycentrics (module docs).
    pub(in crate::render) fn displaced_hit32(&self, found: DisplacedHit) -> Hit32 {
        Hit32 {
            t: found.micro.t as f32,
            object: found.object,
            triangle: found.triangle,
            barycentric: self.base_barycentric(&found).as_vec2(),
            exact_t: Some(found.micro.t),
        }
    }

    fn base_barycentric(&self, found: &DisplacedHit) -> DVec2 {
        let level = self
            .displaced
            .as_ref()
            .and_then(|d| d.displacement(found.object))
            .map_or(0, Displacement::level);
        found
            .micro
            .triangle
            .base_barycentric(level, found.micro.barycentric)
    }

    /// [`PreparedScene::intersect_f32`]'s hit `found` (from the triangle BVH) or a nearer
    /// one on a displaced object.
    #[inline]
    pub(in crate::render) fn nearer_displaced(
        &self,
        ray: &Ray,
        found: Option<Hit32>,
    ) -> Option<Hit32> {
        let Some(set) = &self.displaced else {
            return found;
        };
        let limit = found.map_or(f64::INFINITY, |f| f.t as f64);
        // On equal distance the triangle BVH's hit stays.
        match set.closest(&self.scene, ray, limit, false) {
            Some(d) if d.micro.t < limit => Some(self.displaced_hit32(d)),
            _ => found,
        }
    }

    /// Whether a displaced object blocks `ray` (the shadow-ray query's second half).
    pub(in crate::render) fn displaced_occludes(&self, ray: &Ray) -> bool {
        self.displaced
            .as_ref()
            .is_some_and(|set| set.closest(&self.scene, ray, f64::INFINITY, true).is_some())
    }

    /// The f64 hit of `ray` on displaced base triangle `found`: as the displaced search found
    /// it (`exact_t`, the same hit as searching the base triangle again: the nearest within
    /// it, which the search bounded beyond it did not miss), or searched again in f64; `None`
    /// when `found` is not on a displaced object.
    pub(in crate::render) fn refine_displaced(&self, ray: &Ray, found: Hit32) -> Option<Hit> {
        let set = self.displaced.as_ref()?;
        let displacement = set.displacement(found.object)?;
        if let Some(t) = found.exact_t {
            return Some(Hit {
                t,
                object: found.object,
                triangle: found.triangle,
                barycentric: found.barycentric,
            });
        }
        let hit = set
            .triangle(&self.scene, found.object, found.triangle, displacement)
            .intersect(ray);
        Some(match hit {
            Some(micro) => {
                let d = DisplacedHit {
                    object: found.object,
                    triangle: found.triangle,
                    micro,
                };
                Hit {
                    t: micro.t,
                    object: found.object,
                    triangle: found.triangle,
                    barycentric: self.base_barycentric(&d).as_vec2(),
                }
            }
            // Not found again (cannot happen: the same f64 search); keep the f32 values.
            None => Hit {
                t: found.t as f64,
                object: found.object,
                triangle: found.triangle,
                barycentric: found.barycentric,
            },
        })
    }

    /// The unit face normal (by its winding) of the micro-triangle holding `hit` on a
    /// displaced object, the normal shading uses there (module docs); `None` when the object
    /// is not displaced.
    pub(in crate::render) fn displaced_face_normal(&self, hit: &Hit) -> Option<Vec3> {
        let set = self.displaced.as_ref()?;
        let displacement = set.displacement(hit.object)?;
        let micro = MicroTriangle::containing(displacement.level(), hit.barycentric.as_dvec2());
        let [a, b, c] = set
            .triangle(&self.scene, hit.object, hit.triangle, displacement)
            .positions(micro);
        Some((b - a).cross(c - a).normalize_or_zero().as_vec3())
    }

    /// Whether object `object` is displaced (the tests tell displaced hits apart by it).
    #[cfg(test)]
    pub(in crate::render) fn is_displaced(&self, object: usize) -> bool {
        self.displaced
            .as_ref()
            .is_some_and(|set| set.displacement(object).is_some())
    }

    /// The name of the first displaced object, if any.
    pub(in crate::render) fn first_displaced(&self) -> Option<&str> {
        let set = self.displaced.as_ref()?;
        (0..self.scene.objects.len())
            .find(|&i| set.displacement(i).is_some())
            .map(|i| self.scene.objects[i].name.as_str())
    }
}
