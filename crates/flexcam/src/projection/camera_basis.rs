//! The orthonormal camera basis of the single-viewpoint projections, built from a
//! [`CameraFrame`].

use glam::DVec3;

use super::CameraFrame;
use crate::error::{Error, Result};

/// `up` counts as parallel to the view direction when the sine of the angle between them is
/// below this: the basis would then be dominated by rounding.
const PARALLEL_SINE: f64 = 1e-9;

/// An eye position and a right-handed orthonormal basis: `right` is +x in the image,
/// `up` is up in the image and `forward` is the view direction.
///
/// Camera-local coordinates are (right, up, forward) components: x right, y up, z forward.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraBasis {
    /// The eye (the frame's `position`).
    pub origin: DVec3,
    /// Unit vector to the image's right.
    pub right: DVec3,
    /// Unit vector up in the image, perpendicular to `forward`.
    pub up: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
}

impl CameraBasis {
    /// forward = normalize(look_at - position), right = normalize(forward x up),
    /// up = right x forward.
    ///
    /// Errors (degenerate frames): a non-finite component, `look_at == position` (no view
    /// direction), and `up` zero or parallel to the view direction (no right vector).
    pub fn new(frame: &CameraFrame) -> Result<Self> {
        for (name, value) in [
            ("position", frame.position),
            ("look_at", frame.look_at),
            ("up", frame.up),
        ] {
            if !value.is_finite() {
                return Err(Error::new(format!(
                    "projection {name} has a non-finite component: {value}"
                )));
            }
        }
        let view = frame.look_at - frame.position;
        let forward = view.try_normalize().ok_or_else(|| {
            Error::new("projection position and look_at are the same point: no view direction")
        })?;
        let up_hint = frame.up.try_normalize().ok_or_else(|| {
            Error::new("projection up is zero: it must point away from the view direction")
        })?;
        let side = forward.cross(up_hint);
        if side.length() < PARALLEL_SINE {
            return Err(Error::new(
                "projection up is parallel to the view direction (look_at - position)",
            ));
        }
        let right = side.normalize();
        Ok(CameraBasis {
            origin: frame.position,
            right,
            up: right.cross(forward),
            forward,
        })
    }

    /// The world vector with camera-local components `local` (x right, y up, z forward).
    pub fn to_world(&self, local: DVec3) -> DVec3 {
        local.x * self.right + local.y * self.up + local.z * self.forward
    }

    /// The camera-local components of the world vector `world` (inverse of
    /// [`CameraBasis::to_world`]).
    pub fn to_local(&self, world: DVec3) -> DVec3 {
        DVec3::new(
            world.dot(self.right),
            world.dot(self.up),
            world.dot(self.forward),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(position: DVec3, look_at: DVec3, up: DVec3) -> CameraFrame {
        CameraFrame {
            position,
            look_at,
            up,
        }
    }

    #[test]
    fn basis_is_right_handed_and_orthonormal() {
        let b = CameraBasis::new(&frame(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-2.0, 0.5, 1.0),
            DVec3::new(0.3, 1.0, 0.2),
        ))
        .unwrap();
        for v in [b.right, b.up, b.forward] {
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
        assert!(b.right.dot(b.up).abs() < 1e-12);
        assert!(b.right.dot(b.forward).abs() < 1e-12);
        assert!((b.right.cross(b.up) - (-b.forward)).length() < 1e-12);
        let v = DVec3::new(0.4, -1.5, 2.5);
        assert!((b.to_world(b.to_local(v)) - v).length() < 1e-12);
    }

    #[test]
    fn looking_down_minus_z_with_y_up_gives_x_right() {
        let b = CameraBasis::new(&frame(DVec3::ZERO, DVec3::NEG_Z, DVec3::Y)).unwrap();
        assert!((b.right - DVec3::X).length() < 1e-15);
        assert!((b.up - DVec3::Y).length() < 1e-15);
    }

    #[test]
    fn degenerate_frames_are_errors() {
        let coincident = CameraBasis::new(&frame(DVec3::ONE, DVec3::ONE, DVec3::Y));
        assert!(coincident.unwrap_err().message.contains("same point"));
        let zero_up = CameraBasis::new(&frame(DVec3::ZERO, DVec3::X, DVec3::ZERO));
        assert!(zero_up.unwrap_err().message.contains("up is zero"));
        let parallel = CameraBasis::new(&frame(DVec3::ZERO, DVec3::Y, DVec3::new(0.0, -3.0, 0.0)));
        assert!(parallel.unwrap_err().message.contains("parallel"));
        let nan = CameraBasis::new(&frame(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::X, DVec3::Y));
        assert!(nan
            .unwrap_err()
            .message
            .contains("position has a non-finite"));
        let inf = CameraBasis::new(&frame(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.0, f64::INFINITY, 0.0),
        ));
        assert!(inf.unwrap_err().message.contains("up has a non-finite"));
    }
}
