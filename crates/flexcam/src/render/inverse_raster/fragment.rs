//! Per-fragment reconstruction and per-pixel shading: a fragment is a pixel covered by the
//! image of a piece of scene triangle; its scene point is where the pixel's projector meets
//! the plane of that triangle, so its depth, barycentrics and colour are the ray caster's
//! exactly, and only coverage (which triangle a pixel near a silhouette gets) depends on
//! subdivision.
//!
//! The depth is the ray caster's: `t |direction|`, the distance along the projector from its
//! origin. Fragments whose projector meets the plane outside the projector's range (behind a
//! perspective eye, t outside [0, 1] of a flexible volume: the per-projector near and far
//! clip), or runs parallel to it, are discarded. Barycentrics just outside the triangle (a
//! silhouette pixel the polygon covers but the exact image does not) are clamped onto it.
//!
//! Shading is deferred: the rasteriser only resolves depths, and each pixel's visible
//! fragment is shaded once afterwards ([`Shader::shade_visible`]), so hidden fragments cost
//! no shading and no secondary rays.

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::pixel_rays::PixelRays;
use crate::geometry::Ray;
use crate::render::raster::{Fragment, Target};
use crate::render::raycast::{Hit, RayCaster};
use crate::render::surface::{base_color, TextureFilter};
use crate::render::{Frame, RenderOptions, Shading};
use crate::scene::{Object, Surface};

/// Attributes carried by a fragment: none, depth only (everything else is reconstructed
/// from the pixel's projector).
pub const ATTRIBUTES: usize = 0;

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
    pub caster: Option<&'a RayCaster>,
    pub options: &'a RenderOptions<'a>,
}

impl Shader<'_> {
    /// The resolve step: the exact depth from the pixel's projector, or `false` to discard.
    pub fn resolve(&self, fragment: &mut Fragment<ATTRIBUTES>) -> bool {
        let Some((ray, t, _)) = self.reconstruct(fragment.x, fragment.y, fragment.primitive) else {
            return false;
        };
        fragment.varying.depth = t * ray.direction.length();
        true
    }

    /// Writes `target` into `frame` (resized to it) with every covered pixel's visible
    /// fragment shaded (rows in parallel), and returns the number of rays that shading cast
    /// (secondary and shadow rays of lit shading, mirrors and glass). Depths are rounded to
    /// `f32`; pixels without a fragment keep the target's colour (the background).
    pub fn shade_visible(&self, target: &Target, frame: &mut Frame) -> u64 {
        let (width, height) = (target.width(), target.height());
        let n = width as usize * height as usize;
        (frame.width, frame.height) = (width, height);
        frame.color.resize(n, Vec3::ZERO);
        frame.depth.resize(n, f32::INFINITY);
        frame.ids.resize(n, 0);
        let row = (width as usize).max(1);
        frame
            .color
            .par_chunks_mut(row)
            .zip(frame.depth.par_chunks_mut(row))
            .zip(frame.ids.par_chunks_mut(row))
            .enumerate()
            .map(|(y, ((colors, depths), ids))| {
                let first = y * row;
                let mut rays = 0;
                let pixels = colors.iter_mut().zip(depths).zip(ids).enumerate();
                for (x, ((color, depth), id)) in pixels {
                    let i = first + x;
                    (*depth, *id) = (target.depth()[i] as f32, target.ids()[i]);
                    *color = target.color()[i];
                    let (x, y) = (x as u32, y as u32);
                    if let Some((shaded, cast)) =
                        target.primitive(x, y).and_then(|key| self.shade(x, y, key))
                    {
                        (*color, rays) = (shaded, rays + cast);
                    }
                }
                rays
            })
            .sum()
    }

    /// Pixel `(x, y)`'s projector and where it meets the plane of primitive `key`: the ray
    /// parameter and the clamped barycentrics (see [`plane_hit`]).
    fn reconstruct(&self, x: u32, y: u32, key: u64) -> Option<(&Ray, f64, Vec2)> {
        let ray = self.rays.get(x, y)?;
        let (object, triangle) = unkey(key);
        let mesh = &self.objects[object].mesh;
        let corners = mesh.triangles[triangle].map(|i| mesh.positions[i as usize].as_dvec3());
        let (t, u, v) = plane_hit(ray, corners)?;
        Some((ray, t, Vec2::new(u as f32, v as f32)))
    }

    /// The colour of pixel `(x, y)` whose visible fragment belongs to primitive `key`, and
    /// the rays its shading cast.
    fn shade(&self, x: u32, y: u32, key: u64) -> Option<(Vec3, u64)> {
        let (ray, t, barycentric) = self.reconstruct(x, y, key)?;
        let (object_index, triangle) = unkey(key);
        let object = &self.objects[object_index];
        let flat = matches!(
            object.material.surface,
            Surface::Diffuse | Surface::Emissive
        );
        let base = || base_color(object, triangle, barycentric, TextureFilter::Nearest);
        Some(match (self.options.shading, self.caster) {
            (Shading::Flat, _) if flat => (base(), 0),
            (_, Some(caster)) => {
                let hit = Hit {
                    t,
                    object: object_index,
                    triangle,
                    barycentric,
                };
                caster.shade_hit(ray, hit, self.options)
            }
            // Unreachable by construction (the caster exists whenever shading needs it); the
            // base colour is the safe answer.
            _ => (base(), 0),
        })
    }
}

/// Where `ray` meets the plane of triangle `[a, b, c]`: its parameter t within the ray's
/// range and the barycentrics (u, v) of the second and third vertices, clamped onto the
/// triangle. `None` for a ray parallel to the plane (or a zero-area triangle) and for t
/// outside `[t_min, t_max]`.
pub fn plane_hit(ray: &Ray, [a, b, c]: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let q = s.cross(e1);
    let t = e2.dot(q) * inv;
    if !(ray.t_min..=ray.t_max).contains(&t) {
        return None;
    }
    let (mut u, mut v) = (
        (s.dot(p) * inv).max(0.0),
        (ray.direction.dot(q) * inv).max(0.0),
    );
    if u + v > 1.0 {
        let sum = u + v;
        (u, v) = (u / sum, v / sum);
    }
    Some((t, u, v))
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

    #[test]
    fn plane_hit_inside_and_clamped_outside() {
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.25, 0.25, -1.0));
        let (t, u, v) = plane_hit(&ray, triangle()).unwrap();
        assert!((t - 2.0).abs() < 1e-15 && (u - 0.5).abs() < 1e-15 && (v - 0.5).abs() < 1e-15);
        // Outside the triangle (u + v = 2, u < 0 would be -): clamped onto it.
        let outside = Ray::new(DVec3::ZERO, DVec3::new(1.0, 1.0, -1.0));
        let (_, u, v) = plane_hit(&outside, triangle()).unwrap();
        assert!((u + v - 1.0).abs() < 1e-15);
        let left = Ray::new(DVec3::ZERO, DVec3::new(-0.5, 0.1, -1.0));
        assert_eq!(plane_hit(&left, triangle()).unwrap().1, 0.0);
    }

    /// Degenerate: parallel rays, zero-area triangles and hits outside the ray's range.
    #[test]
    fn plane_hit_misses() {
        let parallel = Ray::new(DVec3::ZERO, DVec3::X);
        assert!(plane_hit(&parallel, triangle()).is_none());
        let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(plane_hit(&Ray::new(DVec3::Y, DVec3::NEG_Y), flat).is_none());
        let away = Ray::new(DVec3::ZERO, DVec3::Z);
        assert!(plane_hit(&away, triangle()).is_none());
        let short = Ray {
            t_max: 1.0,
            ..Ray::new(DVec3::ZERO, DVec3::NEG_Z)
        };
        assert!(plane_hit(&short, triangle()).is_none());
    }

    #[test]
    fn keys_round_trip_and_order_by_object() {
        assert_eq!(unkey(key(3, 12345)), (3, 12345));
        assert!(key(1, 0) > key(0, u32::MAX as usize));
    }
}
