//! An STMap of a projection against a reference camera (`flexcam raymap --stmap`): for each
//! pixel of the projection's image, where in the reference camera's image the same scene
//! point lies, so that a compositor can warp a plate shot with the reference camera into
//! the projection (Nuke's `STMap` node, and every tool that reads its convention).
//!
//! Convention (Nuke's): `s` runs from 0 at the reference image's left edge to 1 at its right,
//! `t` from 0 at its bottom edge to 1 at its top, so the centre of the reference's pixel
//! (x, y) (y counted down from the top row) is s = (x + 0.5) / w, t = 1 - (y + 0.5) / h.
//!
//! The scene point a pixel stands for ([`StPoints`]): the first surface its projector hits
//! (from a ray cast of the scene), or the point at a given distance along its projector.
//! Where the projector hits nothing, the point is at infinity along its leaving direction
//! (the background, as an environment would be). When the projection's rays share the
//! reference's eye the choice does not matter: every point of a ray maps to the same
//! reference pixel.
//!
//! A pixel gets no STMap value (`None`) where it has no projector, where the reference camera
//! does not image the point (outside its image, behind it, outside a fisheye's field), and,
//! for first hits, where the reference sees another surface in front of the point (tested by
//! casting the reference's own projector through the point's image: the point is hidden when
//! that projector's first hit lies more than [`HIDDEN_TOLERANCE`] of its depth away from it).
//! Where the reference images the point more than once (a panorama that wraps, a folding
//! mesh), the image nearest along the reference's projector is taken.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::raycast::first_hit;
use crate::error::{Error, Result};
use crate::projection::projector::{quadratic_arc_length, quadratic_point, Projector};
use crate::projection::ray_map::pixel_ray;
use crate::projection::{ImagePoint, Projection};
use crate::render::{frame_name, PreparedScene};
use crate::try_alloc;

/// Which scene point a pixel of the projection stands for (see the module documentation).
#[derive(Clone, Copy)]
pub enum StPoints<'a> {
    /// The first surface of the scene the pixel's projector hits.
    FirstHit(&'a PreparedScene),
    /// The point at this arc length along the pixel's projector (beyond its end, along its
    /// leaving direction): a sphere about a single eye, a parallel plane for orthographic
    /// rays.
    Distance(f64),
}

/// The STMap of a projection: `(s, t)` per pixel, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct StMap {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Each pixel's `(s, t)` in the reference image; `None` where the reference does not
    /// see the pixel's scene point.
    pub st: Vec<Option<DVec2>>,
}

/// How far, relative to the depth along the reference's projector, its first hit may lie
/// from the scene point and the point still count as seen: 1e-4, far above the rounding of
/// two f64 hits of one surface, far below any gap between two surfaces but a grazing one.
pub const HIDDEN_TOLERANCE: f64 = 1e-4;

/// How far a background pixel's point at infinity is put, relative to the magnitude of its
/// projector's end: far enough that any reference eye within the scene sees it along the
/// direction itself (parallax below 1e-9 radians), near enough that f64 keeps 1e-7 of it.
const FAR: f64 = 1e9;

/// The STMap of `projection` against `reference` for the scene points `points`. Errors: a
/// reference camera without an inverse (the line names its kind), a negative or non-finite
/// distance, memory that cannot be had for the map (module `try_alloc`).
pub fn st_map(
    projection: &dyn Projection,
    reference: &dyn Projection,
    points: StPoints,
) -> Result<StMap> {
    let inverse = reference.inverse().map_err(|none| {
        let why = none
            .reason
            .map_or_else(String::new, |reason| format!(": {reason}"));
        Error::new(format!(
            "the reference camera needs a projection with an inverse; {} has none{why}",
            reference.kind()
        ))
    })?;
    if let StPoints::Distance(d) = points {
        if !(d.is_finite() && d > 0.0) {
            return Err(Error::new(format!(
                "the distance must be a positive number, got {d}"
            )));
        }
    }
    let (width, height) = projection.resolution();
    let (ref_w, ref_h) = reference.resolution();
    let mut st = try_alloc::filled(width as usize * height as usize, None, || {
        format!("the STMap of {}", frame_name(width, height))
    })?;
    let st_of = |images: &mut Vec<ImagePoint>, i: usize| {
        let pixel = DVec2::new(
            (i % width as usize) as f64 + 0.5,
            (i / width as usize) as f64 + 0.5,
        );
        let projector = projection.projector(pixel)?;
        let (point, on_surface) = scene_point(&projector, points)?;
        images.clear();
        inverse.project(point, images);
        let seen = nearest_inside(images, (ref_w, ref_h))?;
        if let (StPoints::FirstHit(scene), true) = (points, on_surface) {
            let hit = first_hit(scene, &reference.projector(seen.pixel)?)?;
            if hit.point().distance(point) > HIDDEN_TOLERANCE * hit.depth {
                return None;
            }
        }
        Some(DVec2::new(
            seen.pixel.x / ref_w as f64,
            1.0 - seen.pixel.y / ref_h as f64,
        ))
    };
    st.par_iter_mut()
        .enumerate()
        .for_each_init(Vec::new, |images, (i, slot)| *slot = st_of(images, i));
    Ok(StMap { width, height, st })
}

/// The scene point `projector` stands for under `points`, and whether it is on a surface
/// (not the background at infinity); `None` where the projector has no direction.
fn scene_point(projector: &Projector, points: StPoints) -> Option<(DVec3, bool)> {
    match points {
        StPoints::FirstHit(scene) => match first_hit(scene, projector) {
            Some(hit) => Some((hit.point(), true)),
            None => {
                let ray = pixel_ray(projector)?;
                let far = FAR * (1.0 + ray.exit_origin.abs().max_element());
                Some((ray.exit_origin + far * ray.exit_direction, false))
            }
        },
        StPoints::Distance(d) => Some((point_at_length(projector, d)?, false)),
    }
}

/// The point at arc length `d` along `projector` from its start, continuing along its
/// leaving direction beyond its end; `None` where it has no direction.
fn point_at_length(projector: &Projector, d: f64) -> Option<DVec3> {
    let ray = pixel_ray(projector)?;
    let beyond = |length: f64| ray.exit_origin + (d - length) * ray.exit_direction;
    match projector {
        Projector::Straight(_) => Some(ray.origin + d * ray.direction),
        Projector::Polyline(points) => {
            let mut run = 0.0;
            for pair in points.windows(2) {
                let segment = pair[1] - pair[0];
                let length = segment.length();
                if length > 0.0 && run + length >= d {
                    return Some(pair[0] + segment * ((d - run) / length));
                }
                run += length;
            }
            Some(beyond(run))
        }
        Projector::QuadraticBezier(p) => {
            let total = quadratic_arc_length(p, 1.0);
            if d >= total {
                return Some(beyond(total));
            }
            // The arc length grows monotonically in s: bisection to f64 resolution.
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if quadratic_arc_length(p, mid) < d {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            Some(quadratic_point(p, 0.5 * (lo + hi)))
        }
    }
}

/// Of `images`, the one inside a `(w, h)` image (pixel positions in `[0, w) x [0, h)`) in
/// front of the reference (`t >= 0`) nearest along its projector, if any.
fn nearest_inside(images: &[ImagePoint], (w, h): (u32, u32)) -> Option<ImagePoint> {
    images
        .iter()
        .filter(|image| {
            let p = image.pixel;
            image.t >= 0.0 && p.x >= 0.0 && p.y >= 0.0 && p.x < w as f64 && p.y < h as f64
        })
        .min_by(|a, b| a.t.total_cmp(&b.t))
        .copied()
}
