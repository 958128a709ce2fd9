//! Interpolation and extrapolation between two viewing volumes (thesis 6.3, eq. 6.1):
//! Q(u, v, t) = a Q1(u, v, t) + (1 - a) Q2(u, v, t) on the shared (u, v) domain, for any real
//! a (a in [0, 1] interpolates, outside it extrapolates).
//!
//! Where the blend is again a volume of the same simple kind it is built as such, so that it
//! keeps an analytic inverse: straight projectors between surfaces of matching type blend
//! surface by surface (rectangles to a rectangle, points to a point, other affine or bilinear
//! pairs to a bilinear patch through the blended corners; spheres and cylinders sharing centre
//! axis, frame and angle ranges to one with the blended radius). Every other pair becomes a
//! [`InterpolatedVolume`] that evaluates both volumes and mixes the points.

use glam::{DVec2, DVec3};

use super::control_surface::{lerp_range, CylinderPatch, SpherePatch, Surface};
use super::linear_volume::LinearVolume;
use super::volume::{mix, InterpolatedVolume, Volume};
use crate::error::{Error, Result};

/// The volume a Q1 + (1 - a) Q2. Weights 1 and 0 give `first` and `second` themselves
/// (exactly, with no rounding). Errors: a non-finite weight; a blend whose projectors all
/// have zero length (for example a = 1/2 between a volume and its mirror image through the
/// near surface).
pub fn interpolate(weight: f64, first: Volume, second: Volume) -> Result<Volume> {
    if !weight.is_finite() {
        return Err(Error::new(format!(
            "flexible interpolation weight must be finite, got {weight}"
        )));
    }
    if weight == 1.0 {
        return Ok(first);
    }
    if weight == 0.0 {
        return Ok(second);
    }
    if let (Volume::Linear(a), Volume::Linear(b)) = (&first, &second) {
        let surfaces = (
            blend_surface(weight, &a.near, &b.near),
            blend_surface(weight, &a.far, &b.far),
        );
        if let (Some(near), Some(far)) = surfaces {
            return LinearVolume::new(near, far)
                .map(|v| Volume::Linear(Box::new(v)))
                .map_err(|e| Error::new(format!("flexible interpolation: {}", e.message)));
        }
    }
    let volume = Volume::Interpolated(Box::new(InterpolatedVolume {
        weight,
        first,
        second,
    }));
    volume
        .check_projectors()
        .map_err(|e| Error::new(format!("flexible interpolation: {}", e.message)))?;
    Ok(volume)
}

/// The corners (u, v) = (0, 0), (1, 0), (1, 1), (0, 1) of a surface that is bilinear in
/// (u, v) (rectangles, bilinear patches, points, lines), `None` for curved surfaces.
fn bilinear_corners(s: &Surface) -> Option<[DVec3; 4]> {
    match s {
        Surface::Rectangle { .. } | Surface::Point(_) | Surface::Line { .. } => {
            Some([DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].map(|uv| s.point(uv)))
        }
        Surface::Bilinear { corners } => Some(*corners),
        _ => None,
    }
}

/// a S1 + (1 - a) S2 as one surface, when the pair allows it exactly; `None` otherwise
/// (including sphere or cylinder blends whose radius would be negative).
fn blend_surface(a: f64, s1: &Surface, s2: &Surface) -> Option<Surface> {
    let blended = match (s1, s2) {
        (Surface::Point(p), Surface::Point(q)) => Surface::Point(mix(a, *p, *q)),
        (
            Surface::Rectangle {
                corner,
                u_edge,
                v_edge,
            },
            Surface::Rectangle {
                corner: c2,
                u_edge: u2,
                v_edge: v2,
            },
        ) => Surface::Rectangle {
            corner: mix(a, *corner, *c2),
            u_edge: mix(a, *u_edge, *u2),
            v_edge: mix(a, *v_edge, *v2),
        },
        (Surface::Sphere(p), Surface::Sphere(q))
            if p.center == q.center
                && p.frame == q.frame
                && p.longitude == q.longitude
                && p.latitude == q.latitude =>
        {
            Surface::Sphere(SpherePatch {
                radius: a * p.radius + (1.0 - a) * q.radius,
                ..*p
            })
        }
        (Surface::Cylinder(p), Surface::Cylinder(q))
            if p.frame == q.frame && p.angle == q.angle =>
        {
            let height = |s: f64| a * lerp_range(p.height, s) + (1.0 - a) * lerp_range(q.height, s);
            Surface::Cylinder(CylinderPatch {
                center: mix(a, p.center, q.center),
                radius: a * p.radius + (1.0 - a) * q.radius,
                height: [height(0.0), height(1.0)],
                ..*p
            })
        }
        _ => {
            let (c1, c2) = (bilinear_corners(s1)?, bilinear_corners(s2)?);
            Surface::Bilinear {
                corners: [0, 1, 2, 3].map(|k| mix(a, c1[k], c2[k])),
            }
        }
    };
    blended.validate().is_ok().then_some(blended)
}
