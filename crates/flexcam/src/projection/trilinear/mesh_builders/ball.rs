//! A pinhole camera's view through a ball (Vallance 2005, 7.4, Figures 7.3 and 7.4; 7.3.3):
//! its rays reflected by a mirror ball, or refracted into and out of a glass ball. As a
//! trilinear grid ([`BallView::vertex`] at the grid's vertices, interpolated between them,
//! the thesis's N x N reflection surface) and exactly, ray by ray ([`BallProjection`]: the
//! limit of the grid as it is refined, what the grid is measured against).

use glam::{DVec2, DVec3};

use super::camera::GridCamera;
use super::grid::GridVertex;
use crate::error::{Error, Result};
use crate::geometry::optics::{reflect, refract};
use crate::geometry::Ray;
use crate::projection::{AnalyticInverse, NoInverse, Projection};

/// What the ball does to the camera's rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BallOptic {
    /// A mirror ball: each ray is reflected where it first meets the sphere (7.2.1, first-hit
    /// reflection).
    Mirror,
    /// A solid glass ball of index of refraction `ior` in air: each ray is refracted in where
    /// it meets the sphere and out where it leaves it (7.3.3, multi-hit refraction).
    Glass {
        /// Index of refraction of the glass, at least 1.
        ior: f64,
    },
}

/// A camera looking at a ball that fills its whole view, and what the ball does to its rays.
///
/// The ray of screen position `s` (`(0, 0)` the bottom-left, `(1, 1)` the top-right) starts
/// at the eye along the camera's direction `d` there and meets the sphere first at `p`
/// (outward unit normal `n`). The view's ray there is
/// - mirror: from `p` along `d - 2 (d . n) n` (unit length);
/// - glass: refracted at `p` into the glass (Snell's law, relative index `1 / ior`), along the
///   chord to the exit point `q`, refracted out there (relative index `ior`, normal `-n(q)`):
///   from `q` along the leaving direction (unit length). A chord meets the sphere at equal
///   angles at both ends, so the leaving ray exists (no total internal reflection); where
///   rounding puts the exit just past the critical angle (rays grazing the sphere), the
///   leaving ray is the grazing limit, tangent to the sphere at `q`.
///
/// With a second mirror ball ([`BallView::with_second_ball`]; 7.2.3, multi-hit reflection)
/// a reflected ray that meets it is reflected once more, from that point; a ray is followed
/// through two hits at the most (one that would come back to the first ball is not).
///
/// Nothing between the eye and the ball, nor inside the glass, is seen: the view starts on
/// the sphere. Degenerate cases, all errors of [`BallView::new`]: a camera with parallel rays
/// (the thesis's view has a view point); a radius that is not finite and positive, or a
/// centre that is not finite; an `ior` below 1 or not finite (a ball less dense than the air
/// reflects grazing rays totally where they enter); the eye on or inside the sphere; a view
/// corner whose ray misses the ball. The rays meeting a sphere from an eye outside it form a
/// convex cone, so when the four corners' rays meet it every ray of the view does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallView {
    camera: GridCamera,
    eye: DVec3,
    center: DVec3,
    radius: f64,
    optic: BallOptic,
    /// A second mirror ball: centre and radius.
    second: Option<(DVec3, f64)>,
}

impl BallView {
    /// The view of pinhole `camera` through the ball of `radius` around `center` with
    /// `optic`. Errors: the degenerate cases of the type's doc.
    pub fn new(camera: GridCamera, center: DVec3, radius: f64, optic: BallOptic) -> Result<Self> {
        let GridCamera::Perspective { basis, .. } = camera else {
            return Err(Error::new(
                "a view through a ball needs a pinhole camera (h_fov and v_fov): its rays \
                 leave one eye",
            ));
        };
        if !center.is_finite() || !radius.is_finite() || radius <= 0.0 {
            return Err(Error::new(format!(
                "the ball needs a finite centre and a positive radius, got centre {center}, \
                 radius {radius}"
            )));
        }
        if let BallOptic::Glass { ior } = optic {
            if !ior.is_finite() || ior < 1.0 {
                return Err(Error::new(format!(
                    "ior must be at least 1 (glass denser than air), got {ior}"
                )));
            }
        }
        let eye = basis.origin;
        if eye.distance(center) <= radius {
            return Err(Error::new(format!(
                "the camera at {eye} is on or inside the ball (centre {center}, radius \
                 {radius}): it must look at the ball from outside"
            )));
        }
        let view = BallView {
            camera,
            eye,
            center,
            radius,
            optic,
            second: None,
        };
        for corner in [DVec2::ZERO, DVec2::X, DVec2::Y, DVec2::ONE] {
            if view.ray(corner).is_none() {
                return Err(Error::new(format!(
                    "the camera's ray at screen corner {corner} misses the ball: the ball \
                     must fill the camera's whole view (narrow h_fov and v_fov, or move the \
                     camera nearer)"
                )));
            }
        }
        Ok(view)
    }

    /// The same view with a second mirror ball of `radius` around `center`, off which the
    /// reflected rays that meet it are reflected again. Errors: a glass ball view (its rays
    /// are refracted, not reflected); a radius that is not finite and positive or a centre
    /// that is not finite; a second ball that overlaps the first or holds the eye.
    pub fn with_second_ball(self, center: DVec3, radius: f64) -> Result<Self> {
        if self.optic != BallOptic::Mirror {
            return Err(Error::new(
                "a second ball needs view = \"sphere_mirror\": it reflects the first ball's \
                 reflections",
            ));
        }
        if !center.is_finite() || !radius.is_finite() || radius <= 0.0 {
            return Err(Error::new(format!(
                "the second ball needs a finite centre and a positive radius, got centre \
                 {center}, radius {radius}"
            )));
        }
        if center.distance(self.center) < radius + self.radius {
            return Err(Error::new(format!(
                "the second ball (centre {center}, radius {radius}) overlaps the first"
            )));
        }
        if center.distance(self.eye) <= radius {
            return Err(Error::new(format!(
                "the camera at {} is inside the second ball (centre {center}, radius {radius})",
                self.eye
            )));
        }
        Ok(BallView {
            second: Some((center, radius)),
            ..self
        })
    }

    /// The exact ray of the view at screen position `screen` (base point on the sphere, unit
    /// direction), or `None` where the camera's ray misses the ball (never inside the view's
    /// screen square, see the type's doc).
    pub fn ray(&self, screen: DVec2) -> Option<GridVertex> {
        let d = self.camera.vertex(screen).direction.normalize();
        let p = sphere_hit(self.center, self.radius, self.eye, d)?;
        let n = (p - self.center) / self.radius;
        match self.optic {
            BallOptic::Mirror => {
                let first = GridVertex {
                    point: p,
                    direction: reflect(d, n).normalize(),
                };
                Some(self.second_hit(first))
            }
            BallOptic::Glass { ior } => {
                // Entering: the normal faces the arriving ray (d . n <= 0 at a first hit);
                // refraction into a denser medium always exists.
                let inside = refract(d, n, 1.0 / ior)?.direction;
                // The chord from p: |p + s inside - c| = r with |p - c| = r.
                let s = -2.0 * inside.dot(p - self.center);
                let q = p + s.max(0.0) * inside;
                let out_normal = (q - self.center) / self.radius;
                let direction = refract(inside, -out_normal, ior).map_or_else(
                    || (inside - inside.dot(out_normal) * out_normal).normalize(),
                    |r| r.direction,
                );
                Some(GridVertex {
                    point: q,
                    direction,
                })
            }
        }
    }

    /// The vertex of the view's trilinear grid at `screen` (pass to [`super::screen_grid`]):
    /// the exact ray there; a zero direction where there is none, which the grid reports.
    pub fn vertex(&self, screen: DVec2) -> GridVertex {
        self.ray(screen).unwrap_or(GridVertex {
            point: self.eye,
            direction: DVec3::ZERO,
        })
    }

    /// `ray` reflected off the second ball where it meets it; `ray` itself without a second
    /// ball or where it misses.
    fn second_hit(&self, ray: GridVertex) -> GridVertex {
        let Some((center, radius)) = self.second else {
            return ray;
        };
        match sphere_hit(center, radius, ray.point, ray.direction) {
            Some(q) => GridVertex {
                point: q,
                direction: reflect(ray.direction, (q - center) / radius).normalize(),
            },
            None => ray,
        }
    }
}

/// The first point where the ray from `origin` (outside the sphere) along unit `d` meets the
/// sphere of `radius` around `center` (the tangent point of a grazing ray), or `None` when it
/// misses.
fn sphere_hit(center: DVec3, radius: f64, origin: DVec3, d: DVec3) -> Option<DVec3> {
    let to_origin = origin - center;
    let b = d.dot(to_origin);
    let c = to_origin.length_squared() - radius * radius;
    let discriminant = b * b - c;
    if discriminant < 0.0 {
        return None;
    }
    // The nearer root, in the form without cancellation (origin outside: c > 0, b < 0).
    let far = -b + discriminant.sqrt();
    if far <= 0.0 {
        return None;
    }
    let t = c / far;
    (t >= 0.0).then_some(origin + t * d)
}

/// The exact view through a ball at a given image size: every pixel's ray computed from the
/// ball itself ([`BallView::ray`]), not interpolated. Rendered by ray casting only (it has no
/// analytic inverse); the reference the view's trilinear grid converges to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallProjection {
    view: BallView,
    width: u32,
    height: u32,
}

impl BallProjection {
    /// `view` at `width` x `height` pixels (both positive, checked by the caller's size
    /// validation; a zero size has no pixels to ask for).
    pub fn new(view: BallView, width: u32, height: u32) -> Self {
        BallProjection {
            view,
            width,
            height,
        }
    }
}

impl Projection for BallProjection {
    fn kind(&self) -> &'static str {
        "trilinear"
    }

    fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The ray at pixel position `(x, y)` (y down) is the view's at screen position
    /// `(x / width, 1 - y / height)`, as a trilinear grid maps its screen.
    fn ray(&self, pixel: DVec2) -> Option<Ray> {
        let screen = DVec2::new(
            pixel.x / f64::from(self.width),
            1.0 - pixel.y / f64::from(self.height),
        );
        self.view
            .ray(screen)
            .map(|v| Ray::new(v.point, v.direction))
    }

    fn inverse(&self) -> std::result::Result<&dyn AnalyticInverse, NoInverse> {
        Err(NoInverse {
            reason: Some(
                "the exact view through a ball has no analytic inverse: render its grid \
                 (without `exact`) for one"
                    .into(),
            ),
        })
    }
}

#[cfg(test)]
mod tests;
