//! What the ray caster sees at one image position: the object and the world point its
//! projector hits first (`flexcam pick`, for collecting a fit's correspondences from a
//! render). The search is the reference ray caster's ([`PreparedScene::intersect`] per
//! straight ray or polyline segment, the curve search for a quadratic projector), so a
//! picked point is on the surface that pixel's colour and id come from.

use glam::{DVec2, DVec3};

use super::hull_cull::LiveParts;
use super::pieces::{length_before, polyline_segment, tangent_ray};
use crate::geometry::Ray;
use crate::projection::projector::quadratic_arc_length;
use crate::projection::{Projection, Projector};
use crate::render::prepared::{Hit, PreparedScene};

/// The first surface a projector hits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Picked {
    /// Index of the object in `scene.objects`.
    pub object: usize,
    /// The hit point, in world coordinates.
    pub point: DVec3,
}

/// The first hit of `projection`'s projector through continuous pixel position `pixel`
/// (pixel (x, y) covers [x, x+1) x [y, y+1), y down; a pixel's centre is at +0.5), or `None`
/// where no projector passes there or it hits nothing.
pub fn pick(scene: &PreparedScene, projection: &dyn Projection, pixel: DVec2) -> Option<Picked> {
    let found = first_hit(scene, &projection.projector(pixel)?)?;
    Some(Picked {
        object: found.hit.object,
        point: found.point(),
    })
}

/// The first hit of a projector, as [`first_hit`] finds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::render) struct ProjectorHit {
    /// The straight ray the hit lies on: the projector itself, the polyline segment hit, or
    /// a quadratic projector's tangent ray at the hit; it arrives at the surface along the
    /// projector.
    pub ray: Ray,
    /// The hit on `ray`, refined in f64.
    pub hit: Hit,
    /// The arc length along the projector from its start to the hit (the frame's depth).
    pub depth: f64,
}

impl ProjectorHit {
    /// The hit point, in world coordinates.
    pub fn point(&self) -> DVec3 {
        self.ray.at(self.hit.t)
    }
}

/// The first hit of `projector` in `scene`, searched as the ray caster searches it: a
/// straight projector by [`PreparedScene::intersect`], a polyline segment by segment (the
/// first segment with a hit wins; zero-length segments see nothing), a quadratic curve by
/// the curve search. `None` when nothing is hit.
pub(in crate::render) fn first_hit(
    scene: &PreparedScene,
    projector: &Projector,
) -> Option<ProjectorHit> {
    match projector {
        Projector::Straight(ray) => {
            let hit = scene.intersect(ray)?;
            Some(ProjectorHit {
                ray: *ray,
                hit,
                depth: hit.t * ray.direction.length(),
            })
        }
        Projector::Polyline(points) => (0..points.len().saturating_sub(1)).find_map(|k| {
            let ray = polyline_segment(points, k);
            scene.intersect(&ray).map(|hit| ProjectorHit {
                ray,
                hit,
                depth: length_before(points, k) + hit.t * ray.direction.length(),
            })
        }),
        Projector::QuadraticBezier(p) => {
            let (s, found) = scene.intersect_quadratic(p, LiveParts::ALL)?;
            let ray = tangent_ray(p, s);
            Some(ProjectorHit {
                ray,
                hit: scene.refine(&ray, found),
                depth: quadratic_arc_length(p, s),
            })
        }
    }
}
