//! Camera-frame navigation: orbit, pan and dolly of a projection's `position` around its
//! `look_at`, the `up` hint unchanged.
//!
//! Orbiting turns the eye about the up axis through the look-at point (yaw) and about the
//! view's right axis (pitch); the pitch stops [`MIN_POLE_ANGLE_DEG`] short of the up axis
//! either way, where the frame would lose its right axis.

use flexcam::projection::CameraFrame;
use glam::DVec3;

/// How close (degrees) an orbit may bring the view direction to the up axis.
pub const MIN_POLE_ANGLE_DEG: f64 = 1.0;

/// Orbit, pan and dolly of a camera frame.
pub trait Navigate: Sized {
    /// The frame with the eye turned `yaw_deg` degrees about the up axis through `look_at`
    /// (positive: the eye moves to its right, the view turns left) and `pitch_deg` degrees
    /// about the view's right axis (positive: the eye rises), at the same distance.
    fn orbit(self, yaw_deg: f64, pitch_deg: f64) -> Self;
    /// The frame moved sideways: `dx` along the view's right axis and `dy` along its true
    /// up axis, both in units of the eye's distance to `look_at`.
    fn pan(self, dx: f64, dy: f64) -> Self;
    /// The frame with the eye's distance to `look_at` multiplied by `factor` (> 0; below 1
    /// moves closer).
    fn dolly(self, factor: f64) -> Self;
}

impl Navigate for CameraFrame {
    fn orbit(self, yaw_deg: f64, pitch_deg: f64) -> CameraFrame {
        let up = self.up.normalize_or_zero();
        let offset = self.position - self.look_at;
        if up == DVec3::ZERO || offset.length_squared() == 0.0 {
            return self;
        }
        let yawed = rotate(offset, up, yaw_deg.to_radians());
        // The angle between the offset and the up axis, kept inside (min, 180 - min).
        let polar = yawed.angle_between(up).to_degrees();
        let lo = MIN_POLE_ANGLE_DEG;
        let target = (polar - pitch_deg).clamp(lo, 180.0 - lo);
        let right = yawed.cross(up).normalize_or_zero();
        let pitched = if right == DVec3::ZERO {
            yawed
        } else {
            rotate(yawed, right, (polar - target).to_radians())
        };
        CameraFrame {
            position: self.look_at + pitched,
            ..self
        }
    }

    fn pan(self, dx: f64, dy: f64) -> CameraFrame {
        let view = self.look_at - self.position;
        let distance = view.length();
        let right = view.cross(self.up).normalize_or_zero();
        let true_up = right.cross(view).normalize_or_zero();
        let shift = (right * dx + true_up * dy) * distance;
        CameraFrame {
            position: self.position + shift,
            look_at: self.look_at + shift,
            up: self.up,
        }
    }

    fn dolly(self, factor: f64) -> CameraFrame {
        if !(factor.is_finite() && factor > 0.0) {
            return self;
        }
        CameraFrame {
            position: self.look_at + (self.position - self.look_at) * factor,
            ..self
        }
    }
}

/// `v` rotated by `angle` radians about the unit axis `axis` (Rodrigues).
fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (sin, cos) = angle.sin_cos();
    v * cos + axis.cross(v) * sin + axis * axis.dot(v) * (1.0 - cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(1.0, 2.0, 6.0),
            look_at: DVec3::new(1.0, 2.0, 1.0),
            up: DVec3::Y,
        }
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn yaw_keeps_distance_and_height() {
        let f = frame().orbit(90.0, 0.0);
        // The eye moves to its right (+x seen from +z looking at -z).
        assert!(
            close(f.position, DVec3::new(6.0, 2.0, 1.0)),
            "{:?}",
            f.position
        );
        assert_eq!(f.look_at, frame().look_at);
    }

    #[test]
    fn pitch_raises_the_eye_and_stops_short_of_the_pole() {
        let f = frame().orbit(0.0, 90.0);
        let offset = f.position - f.look_at;
        assert!((offset.length() - 5.0).abs() < 1e-12);
        let polar = offset.angle_between(DVec3::Y).to_degrees();
        assert!((polar - MIN_POLE_ANGLE_DEG).abs() < 1e-9, "{polar}");
        let f = frame().orbit(0.0, 30.0);
        assert!(close(
            f.position - f.look_at,
            DVec3::new(0.0, 2.5, 5.0 * 30f64.to_radians().cos())
        ));
    }

    #[test]
    fn pan_moves_both_points_and_dolly_scales_the_distance() {
        let f = frame().pan(0.1, -0.2);
        assert!(close(f.position, DVec3::new(1.5, 1.0, 6.0)));
        assert!(close(f.look_at, DVec3::new(1.5, 1.0, 1.0)));
        let f = frame().dolly(0.5);
        assert!(close(f.position, DVec3::new(1.0, 2.0, 3.5)));
        assert_eq!(frame().dolly(0.0), frame());
        assert_eq!(frame().dolly(f64::NAN), frame());
    }

    #[test]
    fn degenerate_frames_are_left_alone() {
        let mut f = frame();
        f.position = f.look_at;
        assert_eq!(f.orbit(10.0, 10.0), f);
    }
}
