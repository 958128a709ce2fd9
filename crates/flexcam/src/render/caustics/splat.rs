//! The second pass of the caustics (module doc of [`super`]): caustic triangles drawn into
//! the eye's image, adding their irradiance at the receiver pixels they cover.
//!
//! A caustic triangle's corners are projected by the eye's pinhole; its edges are straight
//! in the image (a triangle in space images to a triangle). A pixel whose centre lies inside
//! (edge functions, with a tie rule that gives a centre on an edge shared by two triangles to
//! exactly one of them) takes the triangle's irradiance when the main view sees the
//! triangle's receiver there (same object id) at the depth where the pixel's ray meets the
//! triangle's plane, to [`DEPTH_TOLERANCE`]: the receiver's visible side, not its hidden
//! back or a part behind something else of it.

use glam::{DVec2, Vec3};
use rayon::prelude::*;

use super::photon_map::CausticTriangle;
use crate::error::Result;
use crate::projection::{Perspective, Projection, SingleImage};
use crate::render::frame_name;
use crate::try_alloc;

/// Relative depth difference within which a pixel sees the caustic triangle's surface (a
/// chord of a curved receiver lies up to its sagitta inside it).
const DEPTH_TOLERANCE: f64 = 0.01;

/// Caustic triangles drawn per parallel task.
const CHUNK: usize = 4096;

/// Adds the irradiance of `triangles` to `irradiance` (one value per pixel of `eye`'s image,
/// rows from the top) at the pixels whose id in `ids` is the triangle's receiver and whose
/// depth in `depth` is the triangle's (module doc). Degenerate cases: a triangle with a
/// corner on or behind the eye's plane is not drawn (a caustic on the eye's side of the
/// image plane is not seen); one seen edge on covers no pixel centre. Fails when the
/// memory of the per-thread sums (one value per pixel each) cannot be had.
pub(in crate::render) fn splat(
    eye: &Perspective,
    ids: &[u32],
    depth: &[f32],
    triangles: &[CausticTriangle],
    irradiance: &mut [Vec3],
) -> Result<()> {
    let (width, height) = eye.resolution();
    let pixels = irradiance.len();
    let sum = triangles
        .par_chunks(CHUNK)
        .fold(
            || {
                try_alloc::zeroed(pixels, || {
                    format!("the caustics of {}", frame_name(width, height))
                })
            },
            |out: Result<Vec<Vec3>>, chunk| {
                let mut out = out?;
                for triangle in chunk {
                    draw(eye, (width, height), ids, depth, triangle, &mut out);
                }
                Ok(out)
            },
        )
        .reduce_with(|a, b| {
            let (mut a, b) = (a?, b?);
            a.iter_mut().zip(&b).for_each(|(x, y)| *x += *y);
            Ok(a)
        });
    if let Some(sum) = sum {
        irradiance.iter_mut().zip(&sum?).for_each(|(x, y)| *x += *y);
    }
    Ok(())
}

/// Draws one caustic triangle into `out`.
fn draw(
    eye: &Perspective,
    (width, height): (u32, u32),
    ids: &[u32],
    depth: &[f32],
    triangle: &CausticTriangle,
    out: &mut [Vec3],
) {
    let mut corners = [DVec2::ZERO; 3];
    for (corner, point) in corners.iter_mut().zip(triangle.points) {
        match eye.branch_image(point) {
            Some(image) if image.seen => *corner = image.image.pixel,
            _ => return,
        }
    }
    // Counter-clockwise in pixel coordinates (y down), so every edge function is positive
    // inside.
    let twice_area = (corners[1] - corners[0]).perp_dot(corners[2] - corners[0]);
    if twice_area == 0.0 || !twice_area.is_finite() {
        return;
    }
    if twice_area < 0.0 {
        corners.swap(1, 2);
    }
    let lo = corners[0].min(corners[1]).min(corners[2]);
    let hi = corners[0].max(corners[1]).max(corners[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0) as u32;
    let y0 = (lo.y - 0.5).ceil().max(0.0) as u32;
    let x1 = ((hi.x - 0.5).floor().min(f64::from(width) - 1.0)).max(-1.0);
    let y1 = ((hi.y - 0.5).floor().min(f64::from(height) - 1.0)).max(-1.0);
    if x1 < 0.0 || y1 < 0.0 {
        return;
    }
    let [p0, p1, p2] = triangle.points;
    let normal = (p1 - p0).cross(p2 - p0);
    for y in y0..=y1 as u32 {
        for x in x0..=x1 as u32 {
            let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            if !inside(&corners, centre) {
                continue;
            }
            let k = y as usize * width as usize + x as usize;
            if ids[k] != triangle.id {
                continue;
            }
            let Some(ray) = eye.ray(centre) else {
                continue;
            };
            let t = normal.dot(p0 - ray.origin) / normal.dot(ray.direction);
            let seen = f64::from(depth[k]);
            if (seen - t).abs() <= DEPTH_TOLERANCE * t {
                out[k] += triangle.irradiance;
            }
        }
    }
}

/// Whether `p` lies inside the counter-clockwise triangle `c`: every edge function positive,
/// or zero on an edge whose direction `(dx, dy)` has `dy > 0` or `dy = 0, dx < 0` (the same
/// edge in the neighbouring triangle runs the other way and fails this, so a point on a
/// shared edge belongs to one of them).
fn inside(c: &[DVec2; 3], p: DVec2) -> bool {
    (0..3).all(|i| {
        let (a, b) = (c[i], c[(i + 1) % 3]);
        let edge = b - a;
        let e = edge.perp_dot(p - a);
        e > 0.0 || (e == 0.0 && (edge.y > 0.0 || (edge.y == 0.0 && edge.x < 0.0)))
    })
}
