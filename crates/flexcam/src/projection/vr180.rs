//! VR180: two half-equirectangular images (180 x 180 degrees each) side by side, left eye on
//! the left, from two eyes ipd apart along the camera's right axis that look in parallel
//! along the view direction (the VR180 video format's layout).
//!
//! Each eye is an [`Equirectangular`] panorama of 180 x 180 degrees from `position -+ ipd/2
//! right`, so a point in front of the eye plane has one image in each half: longitude within
//! [-90, 90) degrees of that eye's view direction. Degenerate cases: an eye itself has no
//! image in its half; a point straight above or below an eye is seen by a whole row of that
//! half and has the centre column only; a point behind an eye's plane (longitude outside
//! [-90, 90)) is not seen by that eye.

use glam::DVec3;

use super::camera_basis::CameraBasis;
use super::params::positive_length;
use super::stereo::{Layout, StereoPair};
use super::{CameraFrame, Equirectangular};
use crate::error::Result;

/// A VR180 pair.
pub type Vr180 = StereoPair<Equirectangular>;

/// Builds the side-by-side pair for a `width` x `height` image. Errors: a degenerate frame,
/// an empty image or an odd width, `ipd` not a positive length.
pub fn vr180(frame: &CameraFrame, ipd: f64, width: u32, height: u32) -> Result<Vr180> {
    let half = 0.5 * positive_length("vr180", "ipd", ipd)?;
    let (w, h) = Layout::SideBySide.eye_size("vr180", width, height)?;
    let right = CameraBasis::new(frame)?.right;
    let eye = |side: f64| {
        let shift: DVec3 = side * half * right;
        let shifted = CameraFrame {
            position: frame.position + shift,
            look_at: frame.look_at + shift,
            up: frame.up,
        };
        Equirectangular::new(&shifted, 180.0, 180.0, w, h)
    };
    Ok(StereoPair::new(
        "vr180",
        [eye(-1.0)?, eye(1.0)?],
        Layout::SideBySide,
        None,
    ))
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::*;
    use crate::projection::stereo::tests::{frame, near, EYE};
    use crate::projection::Projection;

    /// The ray through `pixel`, by hand: halves of 180 x 180 degrees, the left eye 0.032 to
    /// the left.
    #[test]
    fn rays_of_given_pixels() {
        let v = vr180(&frame(), 0.064, 360, 180).unwrap();
        let left = EYE - DVec3::new(0.032, 0.0, 0.0);
        let right = EYE + DVec3::new(0.032, 0.0, 0.0);
        let r = v.ray(DVec2::new(90.0, 90.0)).unwrap();
        assert!(near(r.origin, left) && near(r.direction, DVec3::NEG_Z));
        let r = v.ray(DVec2::new(270.0, 90.0)).unwrap();
        assert!(near(r.origin, right) && near(r.direction, DVec3::NEG_Z));
        // The left edge of each half looks 90 degrees left, the top row straight up.
        let r = v.ray(DVec2::new(180.0, 90.0)).unwrap();
        assert!(near(r.origin, right) && near(r.direction, DVec3::NEG_X));
        let r = v.ray(DVec2::new(0.0, 90.0)).unwrap();
        assert!(near(r.origin, left) && near(r.direction, DVec3::NEG_X));
        let r = v.ray(DVec2::new(45.0, 0.0)).unwrap();
        assert!(near(r.origin, left) && near(r.direction, DVec3::Y));
    }

    /// A point straight ahead at distance 2: one image per half, each eye turned by
    /// atan(ipd/2 / 2) towards it.
    #[test]
    fn a_point_ahead_has_an_image_in_each_half() {
        let v = vr180(&frame(), 0.064, 360, 180).unwrap();
        let mut out = Vec::new();
        v.inverse()
            .unwrap()
            .project(EYE + DVec3::new(0.0, 0.0, -2.0), &mut out);
        let turn = 0.016f64.atan().to_degrees();
        assert_eq!(out.len(), 2);
        assert!((out[0].pixel - DVec2::new(90.0 + turn, 90.0)).length() < 1e-11);
        assert!((out[1].pixel - DVec2::new(270.0 - turn, 90.0)).length() < 1e-11);
        let t = (4.0f64 + 0.032 * 0.032).sqrt();
        assert!((out[0].t - t).abs() < 1e-14 && (out[1].t - t).abs() < 1e-14);
    }

    /// Behind the eyes, or just behind their plane: no image. On their plane between them:
    /// 90 degrees right of the left eye (the right edge of its half, which belongs to the
    /// other tile: dropped) and 90 degrees left of the right eye (kept). An eye itself has
    /// no image in its own half.
    #[test]
    fn points_an_eye_does_not_see() {
        let v = vr180(&frame(), 0.064, 360, 180).unwrap();
        let inverse = v.inverse().unwrap();
        let mut out = Vec::new();
        inverse.project(EYE + DVec3::new(0.0, 0.0, 1.0), &mut out);
        assert!(out.is_empty(), "{out:?}");
        // Just behind the eyes' plane on the right: seen by neither.
        inverse.project(EYE + DVec3::new(5.0, 0.0, 1e-6), &mut out);
        assert!(out.is_empty(), "{out:?}");
        // Between the eyes, on their plane: the left eye sees it at +90 degrees (the right
        // edge of its half, which belongs to the other tile), the right eye at -90 (its
        // left edge, kept).
        inverse.project(EYE, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].pixel - DVec2::new(180.0, 90.0)).length() < 1e-12);
        // The left eye itself: only the right eye sees it.
        out.clear();
        inverse.project(EYE - DVec3::new(0.032, 0.0, 0.0), &mut out);
        assert_eq!(out.len(), 1);
        assert!(out[0].pixel.x >= 180.0);
    }

    #[test]
    fn invalid_parameters_are_errors() {
        let f = frame();
        let e = vr180(&f, -1.0, 8, 8).err().unwrap();
        assert!(e.message.starts_with("vr180 ipd must be a positive length"));
        let e = vr180(&f, 0.064, 7, 8).err().unwrap();
        assert!(e.message.contains("even image width"), "{e}");
        assert!(vr180(&f, 0.064, 8, 7).is_ok());
    }
}
