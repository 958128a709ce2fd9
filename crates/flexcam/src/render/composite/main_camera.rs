//! The main view of a reflector composite as a pinhole camera.
//!
//! Reflection and refraction surfaces are built from one eye point and one pixel-to-ray map
//! (Vallance 2005, chapter 7), so the composite needs the view it renders as a
//! [`Perspective`]. That view is whatever projection the caller renders through: the scene's
//! own camera for `render`, a keyframe for `animate`, an edited camera in the viewer. It is
//! therefore read from the projection's rays, never from the scene file alone: a camera taken
//! from the scene while another view is rendered would reflect one view into another.
//!
//! Invariant: the returned camera has the rendered view's rays at every checked pixel (the
//! corners, edge midpoints and a 5 x 5 grid): each ray's line passes through the camera's eye
//! and has the camera's direction, to a relative tolerance of [`TOLERANCE`]. Where the scene's
//! own perspective camera at the view's resolution passes that check it is returned as is, so
//! a plain `render` composites with exactly the camera of its scene file.
//!
//! Degenerate cases (each refused with one line, tested): a view whose rays are parallel
//! (orthographic) or do not meet in one point (a fisheye's rays do, but bend away from a
//! pinhole's: the direction check refuses it); a view with no ray at a checked pixel; a
//! field of view of 180 degrees or more.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::{CameraFrame, Perspective, Projection, ProjectionSpec};
use crate::scene::Scene;

/// Relative tolerance of the pinhole check: distances from the eye to a ray's line over the
/// scene's scale, and angles between directions in radians.
pub const TOLERANCE: f64 = 1e-9;

/// The pinhole camera `main` renders (module doc). Errors: `main` is not a pinhole view.
pub fn main_camera(scene: &Scene, main: &dyn Projection) -> Result<Perspective> {
    let (width, height) = main.resolution();
    if let ProjectionSpec::Perspective { frame, fov } = &scene.projection {
        if let Ok(own) = Perspective::new(frame, *fov, width, height) {
            if same_rays(&own, main) {
                return Ok(own);
            }
        }
    }
    pinhole_of(main)
        .filter(|camera| same_rays(camera, main))
        .ok_or_else(|| {
            Error::new(format!(
                "trilinear reflectors need a perspective projection (the main camera): the \
                 {} view rendered here has rays that do not meet in one point as a pinhole's do",
                main.kind()
            ))
        })
}

/// The pinhole whose eye, view direction, up and horizontal field of view match `view`'s
/// rays at the image centre, the middle of the right edge and the middle of the top edge;
/// `None` where those rays are missing, parallel, or span 180 degrees or more.
fn pinhole_of(view: &dyn Projection) -> Option<Perspective> {
    let (width, height) = view.resolution();
    let (w, h) = (f64::from(width), f64::from(height));
    let centre = view.ray(DVec2::new(0.5 * w, 0.5 * h))?;
    let right = view.ray(DVec2::new(w, 0.5 * h))?;
    let top = view.ray(DVec2::new(0.5 * w, 0.0))?;
    let forward = centre.direction.normalize();
    let eye = closest_point(&centre, &right)?;
    let to_right = right.direction.normalize();
    let half_fov = forward
        .cross(to_right)
        .length()
        .atan2(forward.dot(to_right));
    let up = top.direction - top.direction.dot(forward) * forward;
    let frame = CameraFrame {
        position: eye,
        look_at: eye + forward,
        up,
    };
    Perspective::new(&frame, 2.0 * half_fov.to_degrees(), width, height).ok()
}

/// The point of line `a` nearest to line `b` (the two meet there when they intersect);
/// `None` for parallel lines.
fn closest_point(a: &Ray, b: &Ray) -> Option<DVec3> {
    let (da, db) = (a.direction.normalize(), b.direction.normalize());
    let w = a.origin - b.origin;
    let along = da.dot(db);
    let denominator = 1.0 - along * along;
    if !denominator.is_finite() || denominator <= TOLERANCE {
        return None;
    }
    let s = (along * db.dot(w) - da.dot(w)) / denominator;
    Some(a.origin + s * da)
}

/// Whether `camera` has `view`'s rays at the checked pixels (module doc): each of `view`'s
/// ray lines passes through the camera's eye, in the camera's direction.
fn same_rays(camera: &Perspective, view: &dyn Projection) -> bool {
    let (width, height) = view.resolution();
    if camera.resolution() != (width, height) {
        return false;
    }
    let eye = camera.basis().origin;
    let size = DVec2::new(f64::from(width), f64::from(height));
    (0..=4).all(|i| {
        (0..=4).all(|j| {
            let pixel = DVec2::new(f64::from(i), f64::from(j)) / 4.0 * size;
            match (camera.ray(pixel), view.ray(pixel)) {
                (Some(own), Some(seen)) => {
                    let direction = seen.direction.normalize();
                    let offset = eye - seen.origin;
                    let scale = 1.0 + eye.length() + offset.length();
                    offset.cross(direction).length() <= TOLERANCE * scale
                        && own.direction.normalize().angle_between(direction) <= TOLERANCE.sqrt()
                }
                _ => false,
            }
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::flexible::presets::{Preset, PresetSpec};
    use crate::projection::flexible::{FlexibleSpec, VolumeSource};
    use crate::scene::reflector_fixtures::sphere_and_cube;

    const ELSEWHERE: DVec3 = DVec3::new(-1.5, 2.0, 2.5);

    fn frame(position: DVec3) -> CameraFrame {
        CameraFrame {
            position,
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
        }
    }

    /// The scene's own camera is returned exactly when it is the view rendered.
    #[test]
    fn the_scenes_own_camera_is_kept_exactly() {
        let scene = sphere_and_cube(8);
        let main = scene.projection.build(64, 48).unwrap();
        let camera = main_camera(&scene, main.as_ref()).unwrap();
        let ProjectionSpec::Perspective { frame, fov } = &scene.projection else {
            panic!("the fixture is perspective");
        };
        assert_eq!(camera, Perspective::new(frame, *fov, 64, 48).unwrap());
    }

    /// A view from elsewhere (an animation frame) gives that view's camera, not the scene's.
    #[test]
    fn another_pinhole_view_gives_its_own_camera() {
        let scene = sphere_and_cube(8);
        let elsewhere = Perspective::new(&frame(ELSEWHERE), 75.0, 64, 48).unwrap();
        let camera = main_camera(&scene, &elsewhere).unwrap();
        assert!(camera.basis().origin.distance(ELSEWHERE) < 1e-9);
        for pixel in [DVec2::ZERO, DVec2::new(64.0, 48.0), DVec2::new(10.5, 40.25)] {
            let (a, b) = (camera.ray(pixel).unwrap(), elsewhere.ray(pixel).unwrap());
            assert!(a.direction.angle_between(b.direction) < 1e-9, "{pixel}");
        }
    }

    /// The flexible `perspective` preset (what `animate` renders) is a pinhole: its rays
    /// start on the near plane, and the camera found has the preset's eye.
    #[test]
    fn a_flexible_perspective_preset_is_a_pinhole() {
        let spec = FlexibleSpec {
            source: VolumeSource::Preset(PresetSpec {
                preset: Preset::Perspective { fov: 60.0 },
                frame: frame(ELSEWHERE),
                clip: Some([0.5, 100.0]),
            }),
            reparam: None,
        };
        let main = ProjectionSpec::Flexible(Box::new(spec))
            .build(64, 48)
            .unwrap();
        let camera = main_camera(&sphere_and_cube(8), main.as_ref()).unwrap();
        assert!(camera.basis().origin.distance(ELSEWHERE) < 1e-6);
    }

    /// Views that are not pinholes are refused: parallel rays, and a fisheye's bent ones.
    #[test]
    fn views_that_are_not_pinholes_are_refused() {
        let orthographic = ProjectionSpec::Orthographic {
            frame: frame(ELSEWHERE),
            width: 4.0,
        };
        let fisheye = ProjectionSpec::Fisheye {
            frame: frame(ELSEWHERE),
            fov: 120.0,
        };
        for spec in [orthographic, fisheye] {
            let main = spec.build(64, 48).unwrap();
            let e = main_camera(&sphere_and_cube(8), main.as_ref()).unwrap_err();
            assert!(e.message.contains("need a perspective projection"), "{e}");
        }
    }
}
