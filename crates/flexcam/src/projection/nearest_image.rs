//! Where a projection images a scene point, found by search over the image: the continuous
//! pixel position whose projector passes nearest the point. It works for every projection
//! through its projectors alone, so it serves those without an analytic inverse (projector
//! grids, fitted to a painting's correspondences: `flexcam fit --overlay` marks where the fit
//! images each point).
//!
//! The miss at pixel p is the vector r(p) = (X - q) / |X - s| from q, the point of p's
//! projector nearest X, to X, over X's distance from the projector's start s: the sine of
//! the angle at which the projector misses X, seen from its start (zero where it passes
//! through X). The search samples r over a grid of about 48 (`SAMPLES`) positions per image
//! side, then refines the 4 (`STARTS`) best by Levenberg-Marquardt on |r|^2 with central
//! differences, inside the image, and keeps the least miss.
//!
//! Degenerate cases: a projection with no projector anywhere on the sample grid gives
//! `None`; a point at a projector's start is on it (miss 0); a point the projection does not
//! image (behind it, or beyond the image's edge) gives the pixel whose projector passes
//! nearest, with its miss, so that callers judge by [`NearestImage::miss_pixels`]; where
//! neighbouring projectors coincide (no change of r across pixels) the miss in pixels is
//! infinite unless the miss itself is zero.

use glam::{DMat2, DVec2, DVec3};

use super::projector::{quadratic_closest, quadratic_point, Projector};
use super::Projection;

/// Sample positions per image side of the first search (fewer where the image is smaller).
const SAMPLES: u32 = 48;

/// Sample positions the refinement starts from (the least misses of the first search).
const STARTS: usize = 4;

/// Levenberg-Marquardt steps per start, at most.
const STEPS: usize = 60;

/// The step of the central differences, in pixels.
const STEP_PX: f64 = 1e-4;

/// The image of a scene point found by [`nearest_image`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearestImage {
    /// The continuous pixel position (x right, y down from the top-left corner) whose
    /// projector passes nearest the point.
    pub pixel: DVec2,
    /// The sine of the angle at which that projector misses the point, seen from its start
    /// (0: the projector passes through it).
    pub miss: f64,
    /// The miss over the change of the miss per pixel there (the geometric mean of the two
    /// singular values of dr/dp): how many pixels off the image the point lies. Below about
    /// 0.5 the point is seen at [`NearestImage::pixel`].
    pub miss_pixels: f64,
}

/// The image of `point` through `projection`: the position inside the image whose projector
/// passes nearest it (see the module docs for the search and its degenerate cases).
pub fn nearest_image(projection: &dyn Projection, point: DVec3) -> Option<NearestImage> {
    let (width, height) = projection.resolution();
    let size = DVec2::new(f64::from(width), f64::from(height));
    let miss = |p: DVec2| miss_vector(projection, point, p);
    let (columns, rows) = (width.clamp(1, SAMPLES), height.clamp(1, SAMPLES));
    let mut samples: Vec<(f64, DVec2)> = (0..rows)
        .flat_map(|j| (0..columns).map(move |i| (i, j)))
        .filter_map(|(i, j)| {
            let p = DVec2::new(
                (f64::from(i) + 0.5) * size.x / f64::from(columns),
                (f64::from(j) + 0.5) * size.y / f64::from(rows),
            );
            miss(p).map(|r| (r.length_squared(), p))
        })
        .collect();
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    samples
        .iter()
        .take(STARTS)
        .map(|&(_, p)| refine(&miss, p, size))
        .min_by(|a, b| a.miss.total_cmp(&b.miss))
}

/// Levenberg-Marquardt on |r(p)|^2 from `p`, kept inside [0, size]; the result's miss in
/// pixels from the final Jacobian.
fn refine(miss: &impl Fn(DVec2) -> Option<DVec3>, mut p: DVec2, size: DVec2) -> NearestImage {
    let inside = |q: DVec2| q.clamp(DVec2::ZERO, size);
    let mut r = miss(p).unwrap_or(DVec3::ZERO);
    let mut damping: f64 = 1e-3;
    let mut jacobian = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..STEPS {
        jacobian = derivatives(miss, p, size);
        let (jx, jy) = jacobian;
        let normal = DMat2::from_cols(
            DVec2::new(jx.dot(jx), jx.dot(jy)),
            DVec2::new(jx.dot(jy), jy.dot(jy)),
        );
        let gradient = DVec2::new(jx.dot(r), jy.dot(r));
        let mut improved = false;
        while damping < 1e12 {
            let diagonal = DVec2::new(normal.x_axis.x, normal.y_axis.y).max(DVec2::splat(1e-300));
            let scaled = normal + DMat2::from_diagonal(damping * diagonal);
            let step = -(scaled.inverse() * gradient);
            let next = inside(p + step);
            match miss(next).filter(|n| n.length_squared() < r.length_squared()) {
                Some(n) if step.is_finite() => {
                    let moved = (next - p).length();
                    (p, r, improved) = (next, n, true);
                    damping = (damping * 0.3).max(1e-12);
                    if moved < 1e-10 {
                        return finish(p, r, derivatives(miss, p, size));
                    }
                    break;
                }
                _ => damping *= 10.0,
            }
        }
        if !improved || r == DVec3::ZERO {
            break;
        }
    }
    finish(p, r, jacobian)
}

/// The result at `p` with miss `r` and Jacobian columns `(dr/dx, dr/dy)`.
fn finish(pixel: DVec2, r: DVec3, (jx, jy): (DVec3, DVec3)) -> NearestImage {
    let miss = r.length();
    // sqrt(det(J^T J)) is the product of the singular values.
    let scale = (jx.length_squared() * jy.length_squared() - jx.dot(jy).powi(2))
        .max(0.0)
        .sqrt()
        .sqrt();
    let miss_pixels = if miss == 0.0 { 0.0 } else { miss / scale };
    NearestImage {
        pixel,
        miss,
        miss_pixels,
    }
}

/// dr/dx and dr/dy at `p` by central differences (one-sided at the image's edges, zero
/// where the projectors there are missing).
fn derivatives(miss: &impl Fn(DVec2) -> Option<DVec3>, p: DVec2, size: DVec2) -> (DVec3, DVec3) {
    let along = |axis: DVec2| {
        let lo = (p - STEP_PX * axis).clamp(DVec2::ZERO, size);
        let hi = (p + STEP_PX * axis).clamp(DVec2::ZERO, size);
        let span = (hi - lo).dot(axis);
        match (miss(lo), miss(hi)) {
            (Some(a), Some(b)) if span > 0.0 => (b - a) / span,
            _ => DVec3::ZERO,
        }
    };
    (along(DVec2::X), along(DVec2::Y))
}

/// r(p) of the module docs; `None` where `p` has no projector.
fn miss_vector(projection: &dyn Projection, point: DVec3, p: DVec2) -> Option<DVec3> {
    let projector = projection.projector(p)?;
    let (start, nearest) = match &projector {
        Projector::Straight(ray) => {
            let t_min = if ray.t_min.is_finite() {
                ray.t_min
            } else {
                0.0
            };
            let along = ray.direction.length_squared();
            let t = if along > 0.0 {
                ((point - ray.origin).dot(ray.direction) / along).clamp(t_min, ray.t_max)
            } else {
                t_min
            };
            (ray.at(t_min), ray.at(t))
        }
        Projector::QuadraticBezier(c) => (c[0], quadratic_point(c, quadratic_closest(c, point))),
        Projector::Polyline(vertices) => {
            let nearest = vertices
                .windows(2)
                .map(|w| nearest_on_segment(w[0], w[1], point))
                .min_by(|a, b| {
                    (*a - point)
                        .length_squared()
                        .total_cmp(&(*b - point).length_squared())
                })?;
            (vertices[0], nearest)
        }
    };
    let reach = (point - start).length().max(f64::MIN_POSITIVE);
    let r = (point - nearest) / reach;
    r.is_finite().then_some(r)
}

/// The point of segment [a, b] nearest `x` (a where the segment has no length).
fn nearest_on_segment(a: DVec3, b: DVec3, x: DVec3) -> DVec3 {
    let d = b - a;
    let along = d.length_squared();
    if along == 0.0 {
        return a;
    }
    a + d * ((x - a).dot(d) / along).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests;
