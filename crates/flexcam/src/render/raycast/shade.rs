//! Shading of one primary ray, `flat` or `lit`, and what a pixel sample reports.
//!
//! Depth and object id are those of the FIRST surface the primary ray hits, whatever happens
//! after (a mirror reports its own depth and id, not those of what it reflects); depth is the
//! Euclidean distance `t * |direction|` along the primary projector.
//!
//! Specular materials take the same paths in both modes: a mirror reflects about the shading
//! normal; glass enters when the ray opposes the triangle's face normal (eta = 1/ior), else
//! leaves (eta = ior), and reflects on total internal reflection. A ray may bounce at most
//! `max_bounces` times: a specular surface reached after that yields the background.
//!
//! - `flat`: the base colour of the first non-specular surface (nearest texel), untinted by
//!   the mirrors and glass on the way; no Fresnel mixing.
//! - `lit`: emissive shows its base colour; diffuse is an ambient term plus, per light,
//!   Lambert + a white Phong highlight if a shadow ray reaches the light (any surface, glass
//!   included, casts a hard shadow); a scene without lights gets an unshadowed headlight along
//!   the ray. Mirrors reflect tinted by their base colour; glass mixes reflection and
//!   refraction by the exact Fresnel reflectance, its transmission tinted by the base colour.
//!   Branches whose weight in the pixel drops below [`MIN_WEIGHT`] yield the background, as
//!   at the depth limit, so that nested glass costs at most a few hundred rays.

use glam::{DVec3, Vec3};

use super::hull_cull::LiveParts;
use super::{polyline_segment, Hit, Hit32, RayCaster};
use crate::geometry::optics::{reflect, refract};
use crate::geometry::Ray;
use crate::projection::projector::{quadratic_arc_length, quadratic_point, quadratic_tangent};
use crate::projection::Projector;
use crate::render::surface::{base_color, normals, Normals, TextureFilter};
use crate::render::{RenderOptions, Shading};
use crate::scene::{Light, Surface};

/// Ambient fraction of the base colour in `lit` shading.
const AMBIENT: f32 = 0.1;
/// Strength and Phong exponent of the highlight.
const SPECULAR: f32 = 0.3;
const SHININESS: i32 = 32;
/// Lit branches weighing less than this in the final pixel are not traced.
const MIN_WEIGHT: f32 = 1.0 / 1024.0;

/// Whether flat shading shows the base colour of `surface` (else it is specular and passes
/// the ray on).
fn shows_base_color(surface: Surface) -> bool {
    matches!(surface, Surface::Diffuse | Surface::Emissive)
}

impl RayCaster {
    /// Whether flat shading shows the base colour of object `object` (an index into the
    /// scene's objects) wherever it is hit, so that a hit's colour is the surface's base
    /// colour at the hit ([`crate::render::surface::base_color`], nearest texels) and casts
    /// no ray; `false` for a mirror or glass, which pass the ray on.
    pub fn flat_shows_base_color(&self, object: usize) -> bool {
        shows_base_color(self.objects[object].material.surface)
    }

    /// [`RayCaster::shade_hit`] for a caller that builds the primary ray only where shading
    /// reads it: flat shading of a surface that shows its base colour reads only the hit (as
    /// `Tracer::flat` does at its first hit), so `ray` is not called there. Same colour and
    /// ray count as `shade_hit(&ray(), hit, options)`.
    pub fn shade_hit_lazy(
        &self,
        ray: impl FnOnce() -> Ray,
        hit: Hit,
        options: &RenderOptions,
    ) -> (Vec3, u64) {
        let object = &self.objects[hit.object];
        if options.shading == Shading::Flat && shows_base_color(object.material.surface) {
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
}

/// What one sample of a pixel reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Sample {
    pub color: Vec3,
    pub depth: f32,
    pub id: u32,
}

/// Rays cast so far, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct RayCounts {
    pub primary: u64,
    pub secondary: u64,
    pub shadow: u64,
}

/// The straight ray a quadratic projector `p` continues as at its hit `s`: origin B(s),
/// direction the tangent B'(s), with the hit at ray parameter 0 (any t is accepted, so that
/// the f64 refinement may move it by rounding). Degenerate case: where B'(s) = 0 (a cusp of a
/// curve doubling back on itself) the chord P2 - P0 stands in for the tangent, and P1 - P0
/// where that is zero too (a closed curve).
fn tangent_ray(p: &[DVec3; 3], s: f64) -> Ray {
    let direction = [quadratic_tangent(p, s), p[2] - p[0], p[1] - p[0]]
        .into_iter()
        .find(|d| *d != DVec3::ZERO)
        .unwrap_or(DVec3::X);
    Ray {
        origin: quadratic_point(p, s),
        direction,
        t_min: f64::NEG_INFINITY,
        t_max: f64::INFINITY,
    }
}

/// The length of polyline `points` before its segment `k`: the sum of the lengths of
/// segments 0 to k - 1, in order. Computed only for the segment that hits, not as the search
/// passes each segment (most projectors hit nothing).
fn length_before(points: &[DVec3], k: usize) -> f64 {
    points[..=k]
        .windows(2)
        .fold(0.0, |sum, pair| sum + (pair[1] - pair[0]).length())
}

/// Traces primary rays of one render; counts what it casts.
pub(super) struct Tracer<'a> {
    pub caster: &'a RayCaster,
    pub shading: Shading,
    pub max_bounces: u32,
    pub counts: RayCounts,
    /// Which parts (polyline segments, quadratic pieces) of the projectors now sampled
    /// may meet the scene (see `hull_cull`); the others are not searched.
    pub live: LiveParts,
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

impl<'a> Tracer<'a> {
    pub fn new(caster: &'a RayCaster, options: &RenderOptions) -> Tracer<'a> {
        Tracer {
            caster,
            shading: options.shading,
            max_bounces: options.max_bounces,
            counts: RayCounts::default(),
            live: LiveParts::ALL,
        }
    }

    /// The sample a pixel gets for `primary` (`None`: no projector there, the background).
    pub fn sample(&mut self, primary: Option<&Ray>) -> Sample {
        let background = Sample {
            color: self.caster.background,
            depth: f32::INFINITY,
            id: 0,
        };
        let Some(ray) = primary else {
            return background;
        };
        let found = self.caster.intersect_f32(ray);
        self.shade(ray, found, 0.0)
    }

    /// The sample a pixel gets for its projector (`None`: the background). A polyline is
    /// searched segment by segment (each a ray over t in [0, 1]; zero-length segments see
    /// nothing), the first segment with a hit winning; a quadratic Bezier analytically. Depth
    /// is the arc length along the projector up to the hit; shading and secondary rays start
    /// from a straight ray at the hit along the projector's tangent there.
    pub fn sample_projector(&mut self, projector: Option<&Projector>) -> Sample {
        match projector {
            None => self.sample(None),
            Some(Projector::Straight(ray)) => self.sample(Some(ray)),
            Some(Projector::Polyline(points)) => {
                for k in 0..points.len().saturating_sub(1) {
                    let ray = polyline_segment(points, k);
                    let found = if self.live.may_hit(k) {
                        self.caster.intersect_f32(&ray)
                    } else {
                        None
                    };
                    if let Some(found) = found {
                        return self.shade(&ray, Some(found), length_before(points, k));
                    }
                }
                self.shade_miss()
            }
            Some(Projector::QuadraticBezier(p)) => {
                let found = self.caster.intersect_quadratic(p, self.live);
                self.shade_quadratic(p, found)
            }
        }
    }

    /// The sample of quadratic projector `p` whose first hit (curve parameter and hit) is
    /// `found`: shaded along the tangent ray there, at the arc length up to it.
    fn shade_quadratic(&mut self, p: &[DVec3; 3], found: Option<(f64, Hit32)>) -> Sample {
        match found {
            Some((s, found)) => {
                let ray = tangent_ray(p, s);
                self.shade(&ray, Some(found), quadratic_arc_length(p, s))
            }
            None => self.shade_miss(),
        }
    }

    /// The samples of four primary rays (a 2x2 pixel quad), exactly those of [`Tracer::sample`]
    /// on each: the first hits come from one shared BVH traversal.
    pub fn sample4(&mut self, primary: [Option<&Ray>; 4]) -> [Sample; 4] {
        let found = self.caster.intersect4_f32(primary);
        let mut samples = [Sample {
            color: self.caster.background,
            depth: f32::INFINITY,
            id: 0,
        }; 4];
        for ((sample, ray), found) in samples.iter_mut().zip(primary).zip(found) {
            if let Some(ray) = ray {
                *sample = self.shade(ray, found, 0.0);
            }
        }
        samples
    }

    /// The samples of four projectors (a 2x2 pixel quad): [`Tracer::sample4`] when all are
    /// straight (or absent), [`Tracer::sample4_polylines`] when all are polylines (or
    /// absent), [`Tracer::sample4_quadratics`] when all are quadratic (or absent), else one
    /// by one.
    pub fn sample4_projectors(&mut self, projectors: &[Option<Projector>; 4]) -> [Sample; 4] {
        fn straight(p: &Option<Projector>) -> Option<Option<&Ray>> {
            match p {
                Some(Projector::Straight(ray)) => Some(Some(ray)),
                None => Some(None),
                Some(_) => None,
            }
        }
        fn polyline(p: &Option<Projector>) -> Option<Option<&[DVec3]>> {
            match p {
                Some(Projector::Polyline(points)) => Some(Some(points)),
                None => Some(None),
                Some(_) => None,
            }
        }
        if let [Some(a), Some(b), Some(c), Some(d)] = projectors.each_ref().map(straight) {
            return self.sample4([a, b, c, d]);
        }
        fn quadratic(p: &Option<Projector>) -> Option<Option<&[DVec3; 3]>> {
            match p {
                Some(Projector::QuadraticBezier(points)) => Some(Some(points)),
                None => Some(None),
                Some(_) => None,
            }
        }
        if let [Some(a), Some(b), Some(c), Some(d)] = projectors.each_ref().map(polyline) {
            return self.sample4_polylines([a, b, c, d]);
        }
        if let [Some(a), Some(b), Some(c), Some(d)] = projectors.each_ref().map(quadratic) {
            return self.sample4_quadratics([a, b, c, d]);
        }
        projectors
            .each_ref()
            .map(|p| self.sample_projector(p.as_ref()))
    }

    /// The samples of four quadratic projectors (`None`: no projector), exactly those of
    /// [`Tracer::sample_projector`] on each: their pieces are searched by shared BVH walks
    /// ([`RayCaster::intersect_quadratic4`]).
    fn sample4_quadratics(&mut self, curves: [Option<&[DVec3; 3]>; 4]) -> [Sample; 4] {
        let found = self.caster.intersect_quadratic4(curves, self.live);
        let mut samples = [self.sample(None); 4];
        for ((sample, curve), found) in samples.iter_mut().zip(curves).zip(found) {
            if let Some(p) = curve {
                *sample = self.shade_quadratic(p, found);
            }
        }
        samples
    }

    /// The samples of four polyline projectors (`None`: no projector), exactly those of
    /// [`Tracer::sample_projector`] on each: segment k of the four is searched by one shared
    /// BVH traversal ([`RayCaster::intersect4_polylines`]), leaving out the segments
    /// `self.live` rules out.
    fn sample4_polylines(&mut self, polylines: [Option<&[DVec3]>; 4]) -> [Sample; 4] {
        let found = self.caster.intersect4_polylines(polylines, self.live);
        let mut samples = [self.sample(None); 4];
        for ((sample, polyline), found) in samples.iter_mut().zip(polylines).zip(found) {
            *sample = match (polyline, found) {
                (Some(points), Some((k, hit))) => {
                    let ray = polyline_segment(points, k);
                    self.shade(&ray, Some(hit), length_before(points, k))
                }
                (Some(_), None) => self.shade_miss(),
                (None, _) => self.sample(None),
            };
        }
        samples
    }

    /// The sample of primary ray `ray` whose first hit (the f32 search's) is `found`; the
    /// projector has run `before` before the ray's origin (added to the depth).
    fn shade(&mut self, ray: &Ray, found: Option<Hit32>, before: f64) -> Sample {
        let Some(found) = found else {
            return self.shade_miss();
        };
        self.counts.primary += 1;
        let object = &self.caster.objects[found.object];
        let (color, t) = match self.shading {
            // The common flat case, a diffuse or emissive first hit, needs neither an exact
            // hit point nor normals: the f32 hit gives the colour and the depth.
            Shading::Flat if shows_base_color(object.material.surface) => (
                base_color(
                    object,
                    found.triangle,
                    found.barycentric,
                    TextureFilter::Nearest,
                ),
                found.t as f64,
            ),
            _ => {
                let hit = self.caster.refine(ray, found);
                (self.shade_hit(ray, hit), hit.t)
            }
        };
        Sample {
            color,
            depth: (before + t * ray.direction.length()) as f32,
            id: object.id,
        }
    }

    /// The colour of primary ray `ray` whose first hit is `hit` (exact, f64).
    pub fn shade_hit(&mut self, ray: &Ray, hit: Hit) -> Vec3 {
        match self.shading {
            Shading::Flat => self.flat(ray, hit),
            Shading::Lit => self.lit(ray, hit, 0, 1.0),
        }
    }

    /// The sample of a primary projector that hits nothing: the background.
    pub(super) fn shade_miss(&mut self) -> Sample {
        self.counts.primary += 1;
        Sample {
            color: self.caster.background,
            depth: f32::INFINITY,
            id: 0,
        }
    }

    /// Flat shading from the first hit on: follow mirrors and glass, show a base colour.
    fn flat(&mut self, ray: &Ray, hit: Hit) -> Vec3 {
        let (mut ray, mut hit) = (*ray, hit);
        for bounce in 0.. {
            let object = &self.caster.objects[hit.object];
            if shows_base_color(object.material.surface) {
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
            let direction = specular(&ray, &normals, object.material.surface).main;
            ray = self
                .caster
                .spawn(ray.at(hit.t), normals.geometric.as_dvec3(), direction);
            self.counts.secondary += 1;
            match self.caster.intersect(&ray) {
                Some(next) => hit = next,
                None => break,
            }
        }
        self.caster.background
    }

    /// Lit shading of `hit` on `ray`, which has bounced `bounce` times and weighs `weight`.
    fn lit(&mut self, ray: &Ray, hit: Hit, bounce: u32, weight: f32) -> Vec3 {
        let object = &self.caster.objects[hit.object];
        let normals = self.normals(ray, &hit);
        let base = base_color(
            object,
            hit.triangle,
            hit.barycentric,
            TextureFilter::Bilinear,
        );
        let position = ray.at(hit.t);
        match object.material.surface {
            Surface::Emissive => base,
            Surface::Diffuse => self.direct(ray, position, &normals, base),
            surface => {
                let specular = specular(ray, &normals, surface);
                let main_weight = match (surface, specular.fresnel) {
                    (Surface::Mirror, _) => base,
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
            return self.caster.background;
        }
        let ray = self.caster.spawn(from.position, from.normal, direction);
        self.counts.secondary += 1;
        match self.caster.intersect(&ray) {
            Some(hit) => self.lit(&ray, hit, from.bounce, weight),
            None => self.caster.background,
        }
    }

    /// Ambient plus Lambert and Phong from each light that a shadow ray reaches.
    fn direct(&mut self, ray: &Ray, position: DVec3, normals: &Normals, base: Vec3) -> Vec3 {
        let view = ray.direction.normalize();
        let normal = normals.shading.as_dvec3();
        let geometric = normals.geometric.as_dvec3();
        let shade = |to_light: DVec3| {
            let cos = normal.dot(to_light) as f32;
            let highlight = reflect(-to_light, normal).dot(-view).max(0.0) as f32;
            base * cos + Vec3::splat(SPECULAR * highlight.powi(SHININESS))
        };
        if self.caster.lights.is_empty() {
            return base * AMBIENT + shade(-view);
        }
        let mut color = base * AMBIENT;
        for light in &self.caster.lights {
            let (to_light, t_max, radiance) = match *light {
                Light::Point {
                    position: p,
                    color,
                    intensity,
                } => (p.as_dvec3() - position, 1.0, color * intensity),
                Light::Directional {
                    direction,
                    color,
                    intensity,
                } => (-direction.as_dvec3(), f64::INFINITY, color * intensity),
            };
            let unit = to_light.normalize_or_zero();
            if normal.dot(unit) <= 0.0 {
                continue;
            }
            let mut shadow = self.caster.spawn(position, geometric, to_light);
            shadow.t_max = t_max;
            self.counts.shadow += 1;
            if !self.caster.occluded(&shadow) {
                color += radiance * shade(unit);
            }
        }
        color
    }

    /// The normals at `hit` as seen along `ray`.
    fn normals(&self, ray: &Ray, hit: &Hit) -> Normals {
        let object = &self.caster.objects[hit.object];
        normals(
            object,
            hit.triangle,
            hit.barycentric,
            ray.direction.as_vec3(),
        )
    }
}

/// Where `surface` sends `ray` (seen with `normals`): a mirror reflects; glass refracts and
/// also reflects by its Fresnel reflectance, or only reflects on total internal reflection.
/// Shared with the trilinear composites (`render::composite`), which mix the same way.
pub(crate) fn specular(ray: &Ray, normals: &Normals, surface: Surface) -> Specular {
    let direction = ray.direction.normalize();
    let normal = normals.shading.as_dvec3();
    let reflected = reflect(direction, normal);
    let refracted = match surface {
        Surface::Glass { ior } => {
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
