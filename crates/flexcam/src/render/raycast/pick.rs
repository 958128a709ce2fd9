//! What the ray caster sees at one image position: the object and the world point its
//! projector hits first (`flexcam pick`, for collecting a fit's correspondences from a
//! render). The search is the reference ray caster's ([`PreparedScene::intersect`] per
//! straight ray or polyline segment, the curve search for a quadratic projector), so a
//! picked point is on the surface that pixel's colour and id come from.

use glam::{DVec2, DVec3};

use super::hull_cull::LiveParts;
use super::pieces::polyline_segment;
use crate::projection::projector::quadratic_point;
use crate::projection::{Projection, Projector};
use crate::render::prepared::PreparedScene;

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
    match projection.projector(pixel)? {
        Projector::Straight(ray) => {
            let hit = scene.intersect(&ray)?;
            Some(Picked {
                object: hit.object,
                point: ray.at(hit.t),
            })
        }
        Projector::Polyline(points) => (0..points.len().saturating_sub(1)).find_map(|k| {
            let ray = polyline_segment(&points, k);
            scene.intersect(&ray).map(|hit| Picked {
                object: hit.object,
                point: ray.at(hit.t),
            })
        }),
        Projector::QuadraticBezier(p) => {
            let (s, hit) = scene.intersect_quadratic(&p, LiveParts::ALL)?;
            Some(Picked {
                object: hit.object,
                point: quadratic_point(&p, s),
            })
        }
    }
}
