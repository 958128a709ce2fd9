//! Shading of a surface hit, `flat` or `lit`, the same for every renderer: the ray caster
//! shades its primary hits with it, the rasterising renderers the hits they reconstruct, and
//! secondary rays (mirrors, glass, shadows) are traced through the prepared scene's BVH.
//!
//! Specular materials take the same paths in both modes: a mirror reflects about the shading
//! normal, lifted back out of the face where that image points into it (interpolated
//! normals near a coarse mesh's rim: `optics::reflect_above`); glass enters when the ray
//! opposes the triangle's face normal (eta = 1/ior), else leaves (eta = ior), and reflects
//! on total internal reflection (its Fresnel reflection lifted as a mirror's). A ray may
//! bounce at most `max_bounces` times: a specular surface reached after that yields the
//! background.
//!
//! - `flat`: the base colour of the first non-specular surface (nearest texel), untinted by
//!   the mirrors and glass on the way; no Fresnel mixing.
//! - `lit`: emissive shows its base colour; diffuse is an ambient term plus, per light,
//!   Lambert + a white Phong highlight if a shadow ray reaches the light (any surface, glass
//!   included, casts a hard shadow); a scene without lights gets an unshadowed headlight along
//!   the ray. Mirrors reflect tinted by their base colour; glass mixes reflection and
//!   refraction by the exact Fresnel reflectance, its transmission tinted by the base colour.
//!   Branches whose weight in the pixel drops below `MIN_WEIGHT` yield the background, as
//!   at the depth limit, so that nested glass costs at most a few hundred rays.

use glam::{DVec3, Vec3};

use super::lanes::{DVec3x4, F64x4};
use crate::geometry::optics::{reflect, reflect_above, refract};
use crate::geometry::Ray;
use crate::render::prepared::{Hit, PreparedScene};
use crate::render::shading::{base_color, Normals, TextureFilter, TriangleBase, VertexNormals};
use crate::render::{RenderOptions, Shading};
use crate::scene::{Finish, Light};

/// Ambient fraction of the base colour in `lit` shading.
const AMBIENT: f32 = 0.1;
/// Strength and Phong exponent of the highlight.
const SPECULAR: f32 = 0.3;
const SHININESS: i32 = 32;
/// Lit branches weighing less than this in the final pixel are not traced.
const MIN_WEIGHT: f32 = 1.0 / 1024.0;

/// Whether flat shading shows the base colour of `finish` (else it is specular and passes
/// the ray on).
pub(in crate::render) fn shows_base_color(finish: Finish) -> bool {
    matches!(finish, Finish::Diffuse | Finish::Emissive)
}

impl PreparedScene {
    /// Whether flat shading shows the base colour of object `object` (an index into the
    /// scene's objects) wherever it is hit, so that a hit's colour is the surface's base
    /// colour at the hit ([`crate::render::shading::base_color`], nearest texels) and casts
    /// no ray; `false` for a mirror or glass, which pass the ray on.
    pub(in crate::render) fn flat_shows_base_color(&self, object: usize) -> bool {
        shows_base_color(self.scene.objects[object].material.finish)
    }

    /// [`PreparedScene::shade_hit`] for a caller that builds the primary ray only where shading
    /// reads it: flat shading of a surface that shows its base colour reads only the hit (as
    /// `Tracer::flat` does at its first hit), so `ray` is not called there. Same colour and
    /// ray count as `shade_hit(&ray(), hit, options)`.
    pub(in crate::render) fn shade_hit_lazy(
        &self,
        ray: impl FnOnce() -> Ray,
        hit: Hit,
        options: &RenderOptions,
    ) -> (Vec3, u64) {
        let object = &self.scene.objects[hit.object];
        if options.shading == Shading::Flat && shows_base_color(object.material.finish) {
            let color = base_color(
                object,
                hit.triangle,
                hit.barycentric,
                TextureFilter::Nearest,
            );
            return (color, 0);
        }
        self.shade_hit(&ray(), hit, options)
    }

    /// The colour `options.shading` gives primary ray `ray` whose first hit is `hit` (found by
    /// any means: a ray cast, a rasterised fragment), exactly as the ray caster shades its own
    /// hits: mirrors, glass and shadows are traced from there through this scene. Also returns
    /// the number of secondary and shadow rays that took.
    pub(in crate::render) fn shade_hit(
        &self,
        ray: &Ray,
        hit: Hit,
        options: &RenderOptions,
    ) -> (Vec3, u64) {
        let mut shader = HitShader::new(self, options);
        let color = shader.shade_hit(ray, hit);
        (color, shader.counts.secondary + shader.counts.shadow)
    }
}

/// Rays cast so far, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(in crate::render) struct RayCounts {
    pub primary: u64,
    pub secondary: u64,
    pub shadow: u64,
}
/// Shades hits of one render and traces their secondary rays; counts what it casts.
pub(in crate::render) struct HitShader<'a> {
    pub caster: &'a PreparedScene,
    pub shading: Shading,
    pub max_bounces: u32,
    pub counts: RayCounts,
}

/// Where a specular surface sends a ray.
pub(crate) struct Specular {
    /// The path flat shading follows: the mirror reflection, the refraction, or the
    /// reflection on total internal reflection.
    pub main: DVec3,
    /// With a refraction: the reflected direction and the Fresnel reflectance.
    pub fresnel: Option<(DVec3, f32)>,
}

/// The start of a secondary ray: a surface point, its geometric normal, and how many
/// bounces the ray will have made.
struct Segment {
    position: DVec3,
    normal: DVec3,
    bounce: u32,
}
impl<'a> HitShader<'a> {
    pub fn new(caster: &'a PreparedScene, options: &RenderOptions) -> HitShader<'a> {
        HitShader {
            caster,
            shading: options.shading,
            max_bounces: options.max_bounces,
            counts: RayCounts::default(),
        }
    }

    /// The colour of primary ray `ray` whose first hit is `hit` (exact, f64).
    pub(in crate::render) fn shade_hit(&mut self, ray: &Ray, hit: Hit) -> Vec3 {
        match self.shading {
            Shading::Flat => self.flat(ray, hit),
            // The transition system shades displaced objects itself and the others lit.
            Shading::Lit | Shading::Transitions(_) => self.lit(ray, hit, 0, 1.0),
        }
    }

    /// Flat shading from the first hit on: follow mirrors and glass, show a base colour.
    fn flat(&mut self, ray: &Ray, hit: Hit) -> Vec3 {
        let (mut ray, mut hit) = (*ray, hit);
        for bounce in 0.. {
            let object = &self.caster.scene.objects[hit.object];
            if shows_base_color(object.material.finish) {
                return base_color(
                    object,
                    hit.triangle,
                    hit.barycentric,
                    TextureFilter::Nearest,
                );
            }
            if bounce >= self.max_bounces {
                break;
            }
            let normals = self.normals(&ray, &hit);
            let direction = specular(&ray, &normals, object.material.finish).main;
            ray = self
                .caster
                .spawn(ray.at(hit.t), normals.geometric.as_dvec3(), direction);
            self.counts.secondary += 1;
            match self.caster.intersect(&ray) {
                Some(next) => hit = next,
                None => break,
            }
        }
        self.caster.scene.image.background
    }

    /// Lit shading of `hit` on `ray`, which has bounced `bounce` times and weighs `weight`.
    fn lit(&mut self, ray: &Ray, hit: Hit, bounce: u32, weight: f32) -> Vec3 {
        let object = &self.caster.scene.objects[hit.object];
        let (normals, base) = self.lit_surface(ray, &hit);
        let position = ray.at(hit.t);
        match object.material.finish {
            Finish::Emissive => base,
            Finish::Diffuse => self.direct(ray, position, &normals, base),
            surface => {
                let specular = specular(ray, &normals, surface);
                let main_weight = match (surface, specular.fresnel) {
                    (Finish::Mirror, _) => base,
                    (_, Some((_, reflectance))) => base * (1.0 - reflectance),
                    (_, None) => Vec3::ONE,
                };
                let next = Segment {
                    position,
                    normal: normals.geometric.as_dvec3(),
                    bounce: bounce + 1,
                };
                let mut color = main_weight
                    * self.radiance(&next, specular.main, weight * main_weight.max_element());
                if let Some((direction, reflectance)) = specular.fresnel {
                    color += reflectance * self.radiance(&next, direction, weight * reflectance);
                }
                color
            }
        }
    }

    /// Light arriving at `from.position` along `direction`, for a branch weighing `weight`.
    fn radiance(&mut self, from: &Segment, direction: DVec3, weight: f32) -> Vec3 {
        if from.bounce > self.max_bounces || weight < MIN_WEIGHT {
            return self.caster.scene.image.background;
        }
        let ray = self.caster.spawn(from.position, from.normal, direction);
        self.counts.secondary += 1;
        match self.caster.intersect(&ray) {
            Some(hit) => self.lit(&ray, hit, from.bounce, weight),
            None => self.caster.scene.image.background,
        }
    }

    /// The colours of up to four primary rays with their first hits (a 2x2 pixel quad;
    /// `None`: no pixel there), each exactly what [`HitShader::shade_hit`] gives it, with
    /// the same rays counted: the shadow rays of the diffuse hits towards each light are
    /// traced four at a time ([`PreparedScene::occluded4`]), which coherent rays (those of
    /// neighbouring pixels towards one light) make cheaper, and the diffuse hits' view and
    /// light directions, Lambert and Phong terms are computed in four lanes
    /// ([`DiffuseQuad`]), the same operations per lane.
    pub(in crate::render) fn shade_hits4(&mut self, hits: [Option<(&Ray, Hit)>; 4]) -> [Vec3; 4] {
        let background = self.caster.scene.image.background;
        let mut colors = [background; 4];
        if self.shading == Shading::Flat {
            for (color, hit) in colors.iter_mut().zip(hits) {
                if let Some((ray, hit)) = hit {
                    *color = self.flat(ray, hit);
                }
            }
            return colors;
        }
        let mut quad = DiffuseQuad::default();
        // The triangle looked up last: a quad's pixels nearly always lie on one.
        let mut surface: Option<Surface> = None;
        for lane in 0..4 {
            let Some((ray, hit)) = hits[lane] else {
                continue;
            };
            let object = &self.caster.scene.objects[hit.object];
            if object.material.finish != Finish::Diffuse {
                colors[lane] = self.lit(ray, hit, 0, 1.0);
                continue;
            }
            let on = match surface {
                Some(s) if (s.object, s.triangle) == (hit.object, hit.triangle) => s,
                _ => *surface.insert(self.surface(&hit)),
            };
            let (normals, base) = self.lit_surface_on(&on, ray, &hit);
            quad.set(lane, ray, ray.at(hit.t), &normals, base);
        }
        if quad.present == [false; 4] {
            return colors;
        }
        quad.view = quad.view.normalize();
        let lights = &self.caster.scene.lights;
        for (lane, color) in colors.iter_mut().enumerate() {
            if quad.present[lane] {
                *color = quad.point(lane).unshadowed(lights);
            }
        }
        let mut rays: [Option<Ray>; 4] = [None; 4];
        for (index, light) in lights.iter().enumerate() {
            let terms = LightTerms::of(light);
            let lit = quad.light(&terms);
            for (lane, ray) in rays.iter_mut().enumerate() {
                *ray = None;
                if quad.present[lane] && lit.reaches[lane] {
                    *ray = Some(shadow_ray(
                        self.caster,
                        quad.position.lane(lane),
                        quad.geometric.lane(lane),
                        lit.to_light.lane(lane),
                        lit.t_max,
                    ));
                    self.counts.shadow += 1;
                }
            }
            let blocked = self.caster.occluded4_towards(
                index,
                [
                    rays[0].as_ref(),
                    rays[1].as_ref(),
                    rays[2].as_ref(),
                    rays[3].as_ref(),
                ],
            );
            for lane in 0..4 {
                if rays[lane].is_some() && !blocked[lane] {
                    colors[lane] += terms.radiance
                        * lambert_phong(quad.base[lane], lit.cos.0[lane], lit.highlight.0[lane]);
                }
            }
        }
        colors
    }

    /// Ambient plus Lambert and Phong from each light that a shadow ray reaches.
    fn direct(&mut self, ray: &Ray, position: DVec3, normals: &Normals, base: Vec3) -> Vec3 {
        let point = DiffusePoint::new(ray, position, normals, base);
        let mut color = point.unshadowed(&self.caster.scene.lights);
        for (index, light) in self.caster.scene.lights.iter().enumerate() {
            if let Some((shadow, added)) = point.light(self.caster, &LightTerms::of(light)) {
                self.counts.shadow += 1;
                if !self.caster.occluded_towards(index, &shadow) {
                    color += added;
                }
            }
        }
        color
    }

    /// What lit shading reads of the surface at `hit`: its normals as seen along `ray` and
    /// its base colour (bilinear texels).
    fn lit_surface(&self, ray: &Ray, hit: &Hit) -> (Normals, Vec3) {
        self.lit_surface_on(&self.surface(hit), ray, hit)
    }

    /// [`HitShader::lit_surface`] with `hit`'s triangle looked up as `surface`.
    #[inline]
    fn lit_surface_on(&self, surface: &Surface, ray: &Ray, hit: &Hit) -> (Normals, Vec3) {
        let base = self.base_color(hit);
        (self.normals_on(&surface.normals, ray, hit), base)
    }

    /// The base colour at `hit` (bilinear texels), a checker's object-space corners read
    /// from the points the prepared scene keeps rather than transformed per hit.
    fn base_color(&self, hit: &Hit) -> Vec3 {
        let object = &self.caster.scene.objects[hit.object];
        let points = self.caster.object_points(hit.object);
        TriangleBase::of(object, hit.triangle, points).at(hit.barycentric, TextureFilter::Bilinear)
    }

    /// The normals at `hit` as seen along `ray`, its triangle's vertex normals being
    /// `vertex`.
    #[inline]
    fn normals_on(&self, vertex: &VertexNormals, ray: &Ray, hit: &Hit) -> Normals {
        let incoming = ray.direction.as_vec3();
        match self.caster.displaced_face_normal(hit) {
            Some(face) => Normals::of_face(face, incoming),
            None => vertex.normals(
                self.caster.face_normal(hit.object, hit.triangle),
                hit.barycentric,
                incoming,
            ),
        }
    }

    /// What shading reads of the triangle `hit` lies on, looked up once for the hits on it.
    #[inline]
    fn surface(&self, hit: &Hit) -> Surface {
        let object = &self.caster.scene.objects[hit.object];
        Surface {
            object: hit.object,
            triangle: hit.triangle,
            normals: VertexNormals::of(object, hit.triangle),
        }
    }

    /// The normals at `hit` as seen along `ray`.
    fn normals(&self, ray: &Ray, hit: &Hit) -> Normals {
        let object = &self.caster.scene.objects[hit.object];
        self.normals_on(&VertexNormals::of(object, hit.triangle), ray, hit)
    }
}

/// What shading reads of one triangle (object index `object`, triangle `triangle` of its
/// mesh) before the barycentrics of a hit on it: its vertex normals. The base colour is
/// read per hit (from the kept object-space points): sharing that lookup as well made a
/// cube-floor frame slower, not faster.
#[derive(Debug, Clone, Copy)]
struct Surface {
    object: usize,
    triangle: usize,
    normals: VertexNormals,
}

/// A diffuse surface point as lit shading sees it, split from its shadow rays so that
/// those of several points can be traced together ([`HitShader::shade_hits4`]): its colour
/// is [`DiffusePoint::unshadowed`] plus, light by light in the scene's order, what
/// [`DiffusePoint::light`] adds where the shadow ray is not blocked.
#[derive(Debug, Clone, Copy)]
struct DiffusePoint {
    position: DVec3,
    /// The unit direction of the primary ray.
    view: DVec3,
    /// The shading and geometric normals.
    normal: DVec3,
    geometric: DVec3,
    base: Vec3,
}

impl DiffusePoint {
    fn new(ray: &Ray, position: DVec3, normals: &Normals, base: Vec3) -> DiffusePoint {
        DiffusePoint {
            position,
            view: ray.direction.normalize(),
            normal: normals.shading.as_dvec3(),
            geometric: normals.geometric.as_dvec3(),
            base,
        }
    }

    /// Lambert and a white Phong highlight for a unit direction `to_light`.
    #[inline]
    fn shade(&self, to_light: DVec3) -> Vec3 {
        let cos = self.normal.dot(to_light);
        let highlight = reflect(-to_light, self.normal).dot(-self.view).max(0.0);
        lambert_phong(self.base, cos, highlight)
    }

    /// The colour before any light's shadowed term: the ambient term, plus the unshadowed
    /// headlight along the ray when the scene has no `lights`.
    fn unshadowed(&self, lights: &[Light]) -> Vec3 {
        if lights.is_empty() {
            self.base * AMBIENT + self.shade(-self.view)
        } else {
            self.base * AMBIENT
        }
    }

    /// The shadow ray towards the light of `terms` (spawned off the surface through
    /// `caster`) and what the light adds when nothing blocks it; `None` where the light is
    /// behind the shading normal (no ray is cast).
    #[inline]
    fn light(&self, caster: &PreparedScene, terms: &LightTerms) -> Option<(Ray, Vec3)> {
        let (to_light, t_max) = terms.to_light(self.position);
        let unit = terms.unit(to_light);
        if !light_reaches(self.normal.dot(unit)) {
            return None;
        }
        let shadow = shadow_ray(caster, self.position, self.geometric, to_light, t_max);
        Some((shadow, terms.radiance * self.shade(unit)))
    }
}

/// Whether a light whose unit direction makes cosine `cos` with the shading normal is cast
/// a shadow ray (and may add its terms): in front of the normal, or a NaN cosine (a
/// degenerate normal or direction), which is not known to be behind it.
#[inline]
fn light_reaches(cos: f64) -> bool {
    cos > 0.0 || cos.is_nan()
}

/// The shadow ray from surface point `position` towards the light along `to_light`,
/// spawned off the surface by its geometric normal `geometric` ([`PreparedScene::spawn`]),
/// reaching the light at parameter `t_max` ([`LightTerms::to_light`]).
#[inline]
fn shadow_ray(
    caster: &PreparedScene,
    position: DVec3,
    geometric: DVec3,
    to_light: DVec3,
    t_max: f64,
) -> Ray {
    let mut shadow = caster.spawn(position, geometric, to_light);
    shadow.t_max = t_max;
    shadow
}

/// Lambert and a white Phong highlight on base colour `base`, from the cosine between the
/// shading normal and the unit direction to the light and the highlight's cosine (the
/// reflected light direction against the view, at least 0).
#[inline]
fn lambert_phong(base: Vec3, cos: f64, highlight: f64) -> Vec3 {
    base * cos as f32 + Vec3::splat(SPECULAR * (highlight as f32).powi(SHININESS))
}

/// The diffuse points of a 2x2 quad, [`DiffusePoint`]s stored four lanes a coordinate, so
/// that the per-light arithmetic of [`DiffusePoint::light`] is done for the four at once
/// ([`DiffuseQuad::light`]): each lane the same operations on the same values, so the same
/// bits (lanes without a point compute on zeros and are not read).
#[derive(Debug, Clone, Copy, Default)]
struct DiffuseQuad {
    /// Which lanes hold a point.
    present: [bool; 4],
    position: DVec3x4,
    /// The primary rays' directions, normalised once every lane is set.
    view: DVec3x4,
    normal: DVec3x4,
    geometric: DVec3x4,
    base: [Vec3; 4],
}

/// What one light gives the points of a [`DiffuseQuad`], lane by lane.
struct QuadLight {
    /// The vector from each point to the light and the shadow rays' parameter at the light.
    to_light: DVec3x4,
    t_max: f64,
    /// Whether the light is in front of the shading normal (else no shadow ray is cast).
    reaches: [bool; 4],
    /// The Lambert and highlight cosines of [`lambert_phong`].
    cos: F64x4,
    highlight: F64x4,
}

impl DiffuseQuad {
    /// Puts a point in lane `lane`: [`DiffusePoint::new`]'s values, the view not yet
    /// normalised.
    fn set(&mut self, lane: usize, ray: &Ray, position: DVec3, normals: &Normals, base: Vec3) {
        self.present[lane] = true;
        self.position.set(lane, position);
        self.view.set(lane, ray.direction);
        self.normal.set(lane, normals.shading.as_dvec3());
        self.geometric.set(lane, normals.geometric.as_dvec3());
        self.base[lane] = base;
    }

    /// Lane `lane` as a [`DiffusePoint`] (the view normalised).
    fn point(&self, lane: usize) -> DiffusePoint {
        DiffusePoint {
            position: self.position.lane(lane),
            view: self.view.lane(lane),
            normal: self.normal.lane(lane),
            geometric: self.geometric.lane(lane),
            base: self.base[lane],
        }
    }

    /// [`DiffusePoint::light`] of every lane, the shadow ray's spawning aside: the same
    /// vector to the light, unit direction, test against the shading normal and Lambert and
    /// Phong cosines.
    #[inline]
    fn light(&self, terms: &LightTerms) -> QuadLight {
        let (to_light, unit, t_max) = match terms.reach {
            Reach::Point(p) => {
                let to_light = DVec3x4::splat(p) - self.position;
                (to_light, to_light.normalize_or_zero(), 1.0)
            }
            Reach::Directional { to_light, unit } => (
                DVec3x4::splat(to_light),
                DVec3x4::splat(unit),
                f64::INFINITY,
            ),
        };
        let cos = self.normal.dot(unit);
        // reflect(-unit, normal) = -unit - 2 (-unit . normal) normal.
        let from_light = -unit;
        let two_dot = F64x4::splat(2.0) * from_light.dot(self.normal);
        let reflected = from_light - self.normal.scale(two_dot);
        let highlight = reflected.dot(-self.view).max(F64x4::splat(0.0));
        let c = cos.0;
        QuadLight {
            to_light,
            t_max,
            reaches: [
                light_reaches(c[0]),
                light_reaches(c[1]),
                light_reaches(c[2]),
                light_reaches(c[3]),
            ],
            cos,
            highlight,
        }
    }
}

/// What shading reads of a light, with the terms that do not depend on the lit point
/// worked out once (for all the points of a quad): its radiance and, for a directional
/// light, the vector towards it and its unit direction.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct LightTerms {
    pub radiance: Vec3,
    reach: Reach,
}

/// Where a light is, as [`LightTerms`] keeps it.
#[derive(Debug, Clone, Copy)]
enum Reach {
    Point(DVec3),
    /// The vector towards the light and its unit form (zero for a zero direction).
    Directional {
        to_light: DVec3,
        unit: DVec3,
    },
}

impl LightTerms {
    pub fn of(light: &Light) -> LightTerms {
        match *light {
            Light::Point {
                position,
                color,
                intensity,
            } => LightTerms {
                radiance: color * intensity,
                reach: Reach::Point(position.as_dvec3()),
            },
            Light::Directional {
                direction,
                color,
                intensity,
            } => {
                let to_light = -direction.as_dvec3();
                LightTerms {
                    radiance: color * intensity,
                    reach: Reach::Directional {
                        to_light,
                        unit: to_light.normalize_or_zero(),
                    },
                }
            }
        }
    }

    /// The vector from surface point `position` to the light (not normalised) and the
    /// parameter of a shadow ray along it that reaches the light (1 for a point light,
    /// infinity for a directional one).
    #[inline]
    pub fn to_light(self, position: DVec3) -> (DVec3, f64) {
        match self.reach {
            Reach::Point(p) => (p - position, 1.0),
            Reach::Directional { to_light, .. } => (to_light, f64::INFINITY),
        }
    }

    /// `to_light` (from [`LightTerms::to_light`]) normalised, zero where it is zero.
    #[inline]
    fn unit(&self, to_light: DVec3) -> DVec3 {
        match self.reach {
            Reach::Point(_) => to_light.normalize_or_zero(),
            Reach::Directional { unit, .. } => unit,
        }
    }
}

/// Where `finish` sends `ray` (seen with `normals`): a mirror reflects; glass refracts and
/// also reflects by its Fresnel reflectance, or only reflects on total internal reflection.
/// Shared with the trilinear composites (`render::composite`), which mix the same way.
pub(crate) fn specular(ray: &Ray, normals: &Normals, finish: Finish) -> Specular {
    let direction = ray.direction.normalize();
    let normal = normals.shading.as_dvec3();
    let reflected = reflect_above(direction, normal, normals.geometric.as_dvec3());
    let refracted = match finish {
        Finish::Glass { ior } => {
            let ior = ior as f64;
            let eta = if normals.front_face { 1.0 / ior } else { ior };
            refract(direction, normal, eta)
        }
        _ => None,
    };
    match refracted {
        Some(r) => Specular {
            main: r.direction,
            fresnel: Some((reflected, r.reflectance as f32)),
        },
        None => Specular {
            main: reflected,
            fresnel: None,
        },
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3, Vec3};

    use super::*;

    /// The quads of a 2x2 block of pixels of cube-floor (each lane on the checkered floor or
    /// the vertex-coloured cube, several lanes on one triangle, or none), shaded together,
    /// are each what shading the hit alone gives, with the same rays counted.
    #[test]
    fn a_quads_shading_is_each_hits_shading() {
        let scene = crate::scene::load("builtin:cube-floor").unwrap();
        let prepared = PreparedScene::new(&scene);
        let projection = scene.projection.build(64, 48).unwrap();
        let options = RenderOptions {
            shading: Shading::Lit,
            ..RenderOptions::default()
        };
        let mut quads = 0;
        for top in (0..48).step_by(2) {
            for left in (0..64).step_by(2) {
                let rays: Vec<Ray> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|&(dx, dy)| {
                        let centre = DVec2::new(left as f64 + dx as f64, top as f64 + dy as f64);
                        projection.ray(centre + 0.5).unwrap()
                    })
                    .collect();
                let hits: Vec<Option<Hit>> = rays.iter().map(|r| prepared.intersect(r)).collect();
                let lane = |k: usize| hits[k].map(|h| (&rays[k], h));
                let mut shader = HitShader::new(&prepared, &options);
                let colors = shader.shade_hits4([lane(0), lane(1), lane(2), lane(3)]);
                let mut counted = 0;
                for k in 0..4 {
                    let (alone, rays_alone) = match hits[k] {
                        Some(hit) => prepared.shade_hit(&rays[k], hit, &options),
                        None => (scene.image.background, 0),
                    };
                    assert_eq!(
                        colors[k],
                        alone,
                        "pixel ({}, {})",
                        left + k % 2,
                        top + k / 2
                    );
                    counted += rays_alone;
                }
                assert_eq!(shader.counts.secondary + shader.counts.shadow, counted);
                quads += 1;
            }
        }
        assert_eq!(quads, 32 * 24);
    }

    /// A light's terms are those it gives every point: a point light's vector reaches it at
    /// t = 1, a directional light's points against its direction with no end; a zero
    /// direction (degenerate, refused by the scene loader) gives a zero unit vector, and
    /// then no ray is cast (the shading normal's dot product with it is 0).
    #[test]
    fn light_terms_reach_the_light() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        let point = LightTerms::of(&Light::Point {
            position: Vec3::new(4.0, 6.0, 3.0),
            color: Vec3::new(1.0, 0.5, 0.25),
            intensity: 2.0,
        });
        assert_eq!(point.radiance, Vec3::new(2.0, 1.0, 0.5));
        assert_eq!(point.to_light(p), (DVec3::new(3.0, 4.0, 0.0), 1.0));
        let to_point = DVec3::new(3.0, 4.0, 0.0);
        assert_eq!(point.unit(to_point), to_point.normalize_or_zero());
        let sun = LightTerms::of(&Light::Directional {
            direction: Vec3::new(0.0, -2.0, 0.0),
            color: Vec3::ONE,
            intensity: 0.5,
        });
        assert_eq!(sun.radiance, Vec3::splat(0.5));
        assert_eq!(sun.to_light(p), (DVec3::new(0.0, 2.0, 0.0), f64::INFINITY));
        assert_eq!(sun.unit(DVec3::new(0.0, 2.0, 0.0)), DVec3::Y);
        let zero = LightTerms::of(&Light::Directional {
            direction: Vec3::ZERO,
            color: Vec3::ONE,
            intensity: 1.0,
        });
        assert_eq!(zero.unit(zero.to_light(p).0), DVec3::ZERO);
    }
}
