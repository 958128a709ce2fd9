//! Sampling of a pixel's primary projectors by the ray caster: each projector's first hit
//! through the prepared scene's BVH, shaded by [`crate::render::shading`].
//!
//! Depth and object id are those of the FIRST surface the primary ray hits, whatever happens
//! after (a mirror reports its own depth and id, not those of what it reflects); depth is the
//! Euclidean distance `t * |direction|` along the primary projector.
//!

use glam::{DVec3, Vec3};

use super::hull_cull::LiveParts;
use super::pieces::{length_before, polyline_segment, tangent_ray};
use crate::geometry::Ray;
use crate::projection::projector::quadratic_arc_length;
use crate::projection::Projector;
use crate::render::prepared::{Hit32, PreparedScene};
use crate::render::shading::trace::{shows_base_color, HitShader};
use crate::render::shading::{base_color, TextureFilter};
use crate::render::{RenderOptions, Shading};

/// What one sample of a pixel reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Sample {
    pub color: Vec3,
    pub depth: f32,
    pub id: u32,
}
/// Traces primary rays of one render; counts what it casts.
pub(super) struct Tracer<'a> {
    /// Shades the hits and counts every ray cast.
    pub shader: HitShader<'a>,
    /// Which parts (polyline segments, quadratic pieces) of the projectors now sampled
    /// may meet the scene (see `hull_cull`); the others are not searched.
    pub live: LiveParts,
}

impl<'a> Tracer<'a> {
    pub fn new(caster: &'a PreparedScene, options: &RenderOptions) -> Tracer<'a> {
        Tracer {
            shader: HitShader::new(caster, options),
            live: LiveParts::ALL,
        }
    }

    /// The sample a pixel gets for `primary` (`None`: no projector there, the background).
    pub fn sample(&mut self, primary: Option<&Ray>) -> Sample {
        let background = Sample {
            color: self.shader.caster.scene.image.background,
            depth: f32::INFINITY,
            id: 0,
        };
        let Some(ray) = primary else {
            return background;
        };
        let found = self.shader.caster.intersect_f32(ray);
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
                        self.shader.caster.intersect_f32(&ray)
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
                let found = self.shader.caster.intersect_quadratic(p, self.live);
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
        let found = self.shader.caster.intersect4_f32(primary);
        let mut samples = [Sample {
            color: self.shader.caster.scene.image.background,
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
    /// ([`PreparedScene::intersect_quadratic4`]).
    fn sample4_quadratics(&mut self, curves: [Option<&[DVec3; 3]>; 4]) -> [Sample; 4] {
        let found = self.shader.caster.intersect_quadratic4(curves, self.live);
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
    /// BVH traversal ([`PreparedScene::intersect4_polylines`]), leaving out the segments
    /// `self.live` rules out.
    fn sample4_polylines(&mut self, polylines: [Option<&[DVec3]>; 4]) -> [Sample; 4] {
        let found = self
            .shader
            .caster
            .intersect4_polylines(polylines, self.live);
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
        self.shader.counts.primary += 1;
        let object = &self.shader.caster.scene.objects[found.object];
        let (color, t) = match self.shader.shading {
            // The common flat case, a diffuse or emissive first hit, needs neither an exact
            // hit point nor normals: the f32 hit gives the colour and the depth.
            Shading::Flat if shows_base_color(object.material.finish) => (
                base_color(
                    object,
                    found.triangle,
                    found.barycentric,
                    TextureFilter::Nearest,
                ),
                found.t as f64,
            ),
            _ => {
                let hit = self.shader.caster.refine(ray, found);
                (self.shader.shade_hit(ray, hit), hit.t)
            }
        };
        Sample {
            color,
            depth: (before + t * ray.direction.length()) as f32,
            id: object.id,
        }
    }

    /// The sample of a primary projector that hits nothing: the background.
    pub(super) fn shade_miss(&mut self) -> Sample {
        self.shader.counts.primary += 1;
        Sample {
            color: self.shader.caster.scene.image.background,
            depth: f32::INFINITY,
            id: 0,
        }
    }
}
