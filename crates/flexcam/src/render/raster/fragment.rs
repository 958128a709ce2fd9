//! Per-fragment reconstruction and per-pixel shading: a fragment is a pixel covered by the
//! image of a piece of scene triangle; its scene point is where the pixel's projector meets
//! the plane of that triangle, so its depth, barycentrics and colour are the ray caster's
//! exactly, and only coverage (which triangle a pixel near a silhouette gets) depends on
//! subdivision.
//!
//! The depth is the ray caster's: `t |direction|`, the distance along the projector from its
//! origin (for a polyline projector the length of the segments before the one that meets the
//! plane, plus the distance along that one). Fragments whose projector meets the plane
//! outside the projector's range (behind a perspective eye, t outside [0, 1] of a flexible
//! volume: the per-projector near and far clip), or runs parallel to it, are discarded.
//! Barycentrics just outside the triangle (a silhouette pixel the polygon covers but the
//! exact image does not) are clamped onto it.
//!
//! A polyline may meet the triangle's plane in several segments; the fragment takes the first
//! segment that meets it inside the triangle, else (a silhouette pixel) the one that meets it
//! nearest the triangle (the least barycentric overshoot), where the pixel's projector passes
//! the triangle's edge, not where it crosses the plane far from the triangle.
//!
//! Shading is deferred: fragments are only reconstructed and z-tested, and each pixel's
//! visible fragment is shaded once afterwards ([`Shader::shade`]), from the values its one
//! reconstruction gave, so hidden fragments cost no shading and no secondary rays.

use glam::{DVec3, Vec2, Vec3};

use super::pixel_rays::PixelRays;
use crate::geometry::{solve_quadratic, Ray};
use crate::projection::projector::{quadratic_arc_length, quadratic_point};
use crate::projection::Projector;
use crate::render::prepared::{Hit, PreparedScene};
use crate::render::raycast::pieces::{length_before, polyline_segment, tangent_ray};
use crate::render::scan::NO_PRIMITIVE;
use crate::render::shading::trace::{shows_base_color, HitShader};
use crate::render::shading::{base_color, TextureFilter};
use crate::render::{RenderOptions, Shading};
use crate::scene::Object;

/// The primitive key of triangle `triangle` of object index `object`: objects in the high
/// half, so keys order like (object, triangle).
pub fn key(object: usize, triangle: usize) -> u64 {
    ((object as u64) << 32) | triangle as u64
}

/// The object index and triangle of a key.
fn unkey(key: u64) -> (usize, usize) {
    ((key >> 32) as usize, (key & 0xffff_ffff) as usize)
}

/// Reconstructs and shades fragments of one render.
pub struct Shader<'a> {
    pub objects: &'a [Object],
    pub rays: &'a PixelRays<'a>,
    /// The ray caster, for what flat base colours cannot give: lit shading (lights,
    /// shadows) and mirrors and glass (secondary rays). `None` when neither is needed.
    pub caster: Option<&'a PreparedScene>,
    pub options: &'a RenderOptions<'a>,
}

/// A pixel's nearest fragment so far: its exact depth (the ray caster's distance along the
/// projector), the segment of the projector it lies on (0 for a straight one) and the ray
/// parameter on it (the curve parameter of a quadratic projector), primitive key and clamped barycentrics, all from the one reconstruction
/// of the fragment ([`Shader::fragment`]), kept for shading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visible {
    pub depth: f64,
    pub segment: usize,
    pub t: f64,
    pub key: u64,
    pub barycentric: Vec2,
}

impl Visible {
    /// No fragment: beaten by any.
    pub const NONE: Visible = Visible {
        depth: f64::INFINITY,
        segment: 0,
        t: f64::INFINITY,
        key: NO_PRIMITIVE,
        barycentric: Vec2::ZERO,
    };

    /// The rasteriser's z-test: nearer, or as near with a smaller key, so the winner does
    /// not depend on the order of the fragments.
    pub fn beats(&self, other: &Visible) -> bool {
        self.depth < other.depth || (self.depth == other.depth && self.key < other.key)
    }
}

impl Shader<'_> {
    /// The scene corners of primitive `key`, looked up once per screen triangle.
    pub fn corners(&self, key: u64) -> [DVec3; 3] {
        let (object, triangle) = unkey(key);
        let mesh = &self.objects[object].mesh;
        mesh.triangles[triangle].map(|i| mesh.positions[i as usize].as_dvec3())
    }

    /// The fragment of primitive `key`, whose plane is `plane`, at pixel `(x, y)`,
    /// reconstructed from the pixel's projector, or `None` to discard it (see
    /// [`TrianglePlane::hit`]; also a pixel without a projector).
    pub fn fragment(&self, x: u32, y: u32, key: u64, plane: &mut TrianglePlane) -> Option<Visible> {
        let (segment, before, ray, (t, u, v)) = match self.rays.get(x, y)? {
            Projector::Straight(ray) => (0, 0.0, *ray, plane.hit(ray)?),
            Projector::Polyline(points) => {
                let hits = (0..points.len() - 1).filter_map(|k| {
                    let ray = polyline_segment(points, k);
                    plane.hit_unclamped(&ray).map(|hit| ((k, ray), hit))
                });
                let ((k, ray), (t, u, v)) = first_inside(hits)?;
                let (u, v) = clamp(u, v);
                (k, length_before(points, k), ray, (t, u, v))
            }
            Projector::QuadraticBezier(p) => {
                let (_, (s, u, v)) = first_inside(plane.curve_hits(p).map(|hit| ((), hit)))?;
                let (u, v) = clamp(u, v);
                return Some(Visible {
                    depth: quadratic_arc_length(p, s),
                    segment: 0,
                    t: s,
                    key,
                    barycentric: Vec2::new(u as f32, v as f32),
                });
            }
        };
        Some(Visible {
            depth: before + t * ray.direction.length(),
            segment,
            t,
            key,
            barycentric: Vec2::new(u as f32, v as f32),
        })
    }

    /// The object id of primitive `key`.
    pub fn id(&self, key: u64) -> u32 {
        self.objects[unkey(key).0].id
    }

    /// The colours of up to four pixels `(x, y)` with their visible fragments (a 2x2 quad;
    /// `None`: no fragment there), each what the ray caster's shading gives its reconstructed
    /// hit ([`HitShader::shade_hits4`], which traces the quad's shadow rays together) or, in
    /// flat shading of a surface that shows its base colour, that colour; and the number of
    /// rays their shading cast.
    ///
    /// Out of line: inlined, it takes the fill's inlining budget from the fragments'
    /// reconstruction ([`Shader::fragment`]), which then costs more than the call does.
    #[inline(never)]
    pub fn shade4(&self, pixels: [Option<(u32, u32, &Visible)>; 4]) -> ([Vec3; 4], u64) {
        let mut colors = [Vec3::ZERO; 4];
        let mut traced = [None; 4];
        let mut rays = [None; 4];
        for lane in 0..4 {
            let Some((x, y, visible)) = pixels[lane] else {
                continue;
            };
            match self.traced_hit(x, y, visible) {
                Some((ray, hit)) => {
                    rays[lane] = Some(ray);
                    traced[lane] = Some(hit);
                }
                None => colors[lane] = self.base(visible),
            }
        }
        let Some(caster) = self.caster.filter(|_| traced.iter().any(Option::is_some)) else {
            return (colors, 0);
        };
        let lane = |k: usize| Some((rays[k].as_ref()?, traced[k]?));
        let hits = [lane(0), lane(1), lane(2), lane(3)];
        let mut shader = HitShader::new(caster, self.options);
        let shaded = shader.shade_hits4(hits);
        for lane in 0..4 {
            if traced[lane].is_some() {
                colors[lane] = shaded[lane];
            }
        }
        let counts = shader.counts;
        (colors, counts.secondary + counts.shadow)
    }

    /// The primary ray and hit through which the ray caster shades pixel `(x, y)` whose
    /// visible fragment is `visible`; `None` where the fragment's flat base colour is its
    /// colour (flat shading of a surface that shows it). The caster exists whenever shading
    /// needs it, and a visible fragment's pixel has a projector (`None` otherwise too: the
    /// base colour is the safe answer).
    fn traced_hit(&self, x: u32, y: u32, visible: &Visible) -> Option<(Ray, Hit)> {
        let (object, triangle) = unkey(visible.key);
        let finish = self.objects[object].material.finish;
        if self.options.shading == Shading::Flat && shows_base_color(finish) {
            return None;
        }
        self.caster?;
        // A quadratic projector continues as its tangent ray at the hit, the hit at its
        // origin, as in the ray caster.
        let (ray, t) = match self.rays.get(x, y)? {
            Projector::Straight(ray) => (*ray, visible.t),
            Projector::Polyline(points) => (polyline_segment(points, visible.segment), visible.t),
            Projector::QuadraticBezier(p) => (tangent_ray(p, visible.t), 0.0),
        };
        let hit = Hit {
            t,
            object,
            triangle,
            barycentric: visible.barycentric,
        };
        Some((ray, hit))
    }

    /// The flat base colour of `visible`'s surface at its barycentrics (nearest texels).
    fn base(&self, visible: &Visible) -> Vec3 {
        let (object, triangle) = unkey(visible.key);
        base_color(
            &self.objects[object],
            triangle,
            visible.barycentric,
            TextureFilter::Nearest,
        )
    }
}

/// A scene triangle `[a, b, c]` set up for the fragments of its screen triangles: its
/// edges, and the terms of the intersection that depend on the projector's origin only,
/// kept for the last origin seen (every projector of a panorama, of a perspective camera
/// and of a flexible volume with a point near surface leaves one eye, so they are computed
/// once per screen triangle there). The arithmetic is that of the Moeller-Trumbore test
/// term for term, so the results do not depend on what was kept.
#[derive(Debug, Clone, Copy)]
pub struct TrianglePlane {
    a: DVec3,
    e1: DVec3,
    e2: DVec3,
    from: Option<FromOrigin>,
}

/// The origin-dependent terms of [`TrianglePlane::hit`] for one projector origin.
#[derive(Debug, Clone, Copy)]
struct FromOrigin {
    origin: DVec3,
    /// origin - a.
    s: DVec3,
    /// s x e1.
    q: DVec3,
    /// e2 . q, the numerator of the ray parameter.
    t_numerator: f64,
}

impl TrianglePlane {
    pub fn new([a, b, c]: [DVec3; 3]) -> Self {
        TrianglePlane {
            a,
            e1: b - a,
            e2: c - a,
            from: None,
        }
    }

    /// Where `ray` meets the plane: its parameter t within the ray's range and the
    /// barycentrics (u, v) of the second and third vertices, clamped onto the triangle.
    /// `None` for a ray parallel to the plane (or a zero-area triangle) and for t outside
    /// `[t_min, t_max]`.
    ///
    /// Degenerate case: a projector whose origin lies in the triangle's plane meets it at
    /// its origin (t = t_min = 0) whatever its direction, so the triangle is seen edge-on and
    /// its screen triangle is a sliver whose fragments would all lie at depth 0 and win
    /// every depth test. Such a hit counts, as in the ray caster, only where the origin lies
    /// inside the triangle (unclamped barycentrics).
    pub fn hit(&mut self, ray: &Ray) -> Option<(f64, f64, f64)> {
        let (t, u, v) = self.hit_unclamped(ray)?;
        let (u, v) = clamp(u, v);
        Some((t, u, v))
    }

    /// Where quadratic projector `p` meets the plane: each curve parameter s in [0, 1] at
    /// which it does, ascending, with the unclamped barycentrics of the curve's point there.
    /// The arithmetic is the ray caster's curve test term for term (the signed distance of
    /// the curve to the plane is a quadratic in s), so a hit inside the triangle has its s.
    /// Degenerate cases: a zero-area triangle, or a curve lying in the plane (the quadratic
    /// identically zero), meets it nowhere, as in the ray caster.
    pub fn curve_hits(&self, p: &[DVec3; 3]) -> impl Iterator<Item = (f64, f64, f64)> {
        let (a, e1, e2, p) = (self.a, self.e1, self.e2, *p);
        let normal = e1.cross(e2);
        let area2 = normal.length_squared();
        let [x0, x1, x2] = p.map(|q| normal.dot(q - a));
        let roots =
            (area2 != 0.0).then(|| solve_quadratic(x0 - 2.0 * x1 + x2, 2.0 * (x1 - x0), x0));
        roots
            .into_iter()
            .flatten()
            .filter(|s| (0.0..=1.0).contains(s))
            .map(move |s| {
                let w = quadratic_point(&p, s) - a;
                let u = w.cross(e2).dot(normal) / area2;
                let v = e1.cross(w).dot(normal) / area2;
                (s, u, v)
            })
    }

    /// [`TrianglePlane::hit`] before the barycentrics are clamped onto the triangle.
    pub fn hit_unclamped(&mut self, ray: &Ray) -> Option<(f64, f64, f64)> {
        let (e1, e2) = (self.e1, self.e2);
        let p = ray.direction.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let from = match self.from {
            Some(from) if from.origin == ray.origin => from,
            _ => {
                let s = ray.origin - self.a;
                let q = s.cross(e1);
                let from = FromOrigin {
                    origin: ray.origin,
                    s,
                    q,
                    t_numerator: e2.dot(q),
                };
                self.from = Some(from);
                from
            }
        };
        let t = from.t_numerator * inv;
        if !(ray.t_min..=ray.t_max).contains(&t) {
            return None;
        }
        let (u_plane, v_plane) = (from.s.dot(p) * inv, ray.direction.dot(from.q) * inv);
        if t <= 0.0 && !(u_plane >= 0.0 && v_plane >= 0.0 && u_plane + v_plane <= 1.0) {
            return None;
        }
        Some((t, u_plane, v_plane))
    }
}

/// Of the hits of a projector's parts on a triangle's plane, in order along the projector
/// (each with its unclamped parameter and barycentrics), the first inside the triangle, else
/// (a silhouette pixel) the one nearest the triangle: the least barycentric overshoot.
fn first_inside<P>(
    hits: impl Iterator<Item = (P, (f64, f64, f64))>,
) -> Option<(P, (f64, f64, f64))> {
    // How far outside the triangle (u, v) lies: <= 0 inside.
    let outside = |u: f64, v: f64| (-u).max(-v).max(u + v - 1.0);
    let mut nearest: Option<(P, (f64, f64, f64))> = None;
    for (part, (t, u, v)) in hits {
        if outside(u, v) <= 0.0 {
            return Some((part, (t, u, v)));
        }
        if nearest
            .as_ref()
            .is_none_or(|(_, (_, a, b))| outside(u, v) < outside(*a, *b))
        {
            nearest = Some((part, (t, u, v)));
        }
    }
    nearest
}

/// Barycentrics (u, v) clamped onto the triangle: negative ones to 0, then a sum above 1
/// scaled down to 1.
fn clamp(u: f64, v: f64) -> (f64, f64) {
    let (u, v) = (u.max(0.0), v.max(0.0));
    if u + v > 1.0 {
        (u / (u + v), v / (u + v))
    } else {
        (u, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> [DVec3; 3] {
        [
            DVec3::new(0.0, 0.0, -2.0),
            DVec3::new(1.0, 0.0, -2.0),
            DVec3::new(0.0, 1.0, -2.0),
        ]
    }

    /// A projector starting in the triangle's plane meets it at its start only where the
    /// start lies inside the triangle (the edge-on case of `hit`).
    #[test]
    fn an_origin_in_the_plane_hits_only_inside_the_triangle() {
        let direction = DVec3::new(0.1, 0.2, -1.0);
        let outside = Ray::new(DVec3::new(2.0, 2.0, -2.0), direction);
        assert_eq!(TrianglePlane::new(triangle()).hit(&outside), None);
        let inside = Ray::new(DVec3::new(0.25, 0.25, -2.0), direction);
        let (t, u, v) = TrianglePlane::new(triangle()).hit(&inside).unwrap();
        assert_eq!(t, 0.0);
        assert!(
            (u - 0.25).abs() < 1e-12 && (v - 0.25).abs() < 1e-12,
            "{u} {v}"
        );
    }

    #[test]
    fn plane_hit_inside_and_clamped_outside() {
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.25, 0.25, -1.0));
        let (t, u, v) = TrianglePlane::new(triangle()).hit(&ray).unwrap();
        assert!((t - 2.0).abs() < 1e-15 && (u - 0.5).abs() < 1e-15 && (v - 0.5).abs() < 1e-15);
        // Outside the triangle (u + v = 2, u < 0 would be -): clamped onto it.
        let outside = Ray::new(DVec3::ZERO, DVec3::new(1.0, 1.0, -1.0));
        let (_, u, v) = TrianglePlane::new(triangle()).hit(&outside).unwrap();
        assert!((u + v - 1.0).abs() < 1e-15);
        let left = Ray::new(DVec3::ZERO, DVec3::new(-0.5, 0.1, -1.0));
        assert_eq!(TrianglePlane::new(triangle()).hit(&left).unwrap().1, 0.0);
    }

    /// Degenerate: parallel rays, zero-area triangles and hits outside the ray's range.
    #[test]
    fn plane_hit_misses() {
        let parallel = Ray::new(DVec3::ZERO, DVec3::X);
        assert!(TrianglePlane::new(triangle()).hit(&parallel).is_none());
        let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(TrianglePlane::new(flat)
            .hit(&Ray::new(DVec3::Y, DVec3::NEG_Y))
            .is_none());
        let away = Ray::new(DVec3::ZERO, DVec3::Z);
        assert!(TrianglePlane::new(triangle()).hit(&away).is_none());
        let short = Ray {
            t_max: 1.0,
            ..Ray::new(DVec3::ZERO, DVec3::NEG_Z)
        };
        assert!(TrianglePlane::new(triangle()).hit(&short).is_none());
    }

    /// A plane kept across projectors of one origin, then of another and back, gives each
    /// projector the result of a fresh set-up, bit for bit.
    #[test]
    fn kept_origin_terms_give_a_fresh_setups_hits() {
        let mut kept = TrianglePlane::new(triangle());
        let eye = DVec3::ZERO;
        let other = DVec3::new(0.2, 0.1, 0.5);
        for (origin, direction) in [
            (eye, DVec3::new(0.25, 0.25, -1.0)),
            (eye, DVec3::new(0.1, 0.3, -1.0)),
            (other, DVec3::new(0.0, 0.1, -1.0)),
            (other, DVec3::new(1.0, 1.0, -1.0)),
            (eye, DVec3::new(0.3, 0.1, -1.0)),
            (eye, DVec3::X),
        ] {
            let ray = Ray::new(origin, direction);
            assert_eq!(kept.hit(&ray), TrianglePlane::new(triangle()).hit(&ray));
        }
    }

    #[test]
    fn keys_round_trip_and_order_by_object() {
        assert_eq!(unkey(key(3, 12345)), (3, 12345));
        assert!(key(1, 0) > key(0, u32::MAX as usize));
    }
}
