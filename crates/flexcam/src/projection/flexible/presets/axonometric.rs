//! The view frame of the axonometric preset: an orthographic camera turned to the world axes
//! by two angles, as in the drafting classification (Carlbom and Paciorek 1978):
//! isometric when the three world axes are foreshortened equally (azimuth 45 degrees,
//! elevation asin(tan 30 degrees) = 35.264 degrees), dimetric when two are (azimuth 45
//! degrees, any other elevation), trimetric otherwise.

use glam::DVec3;

use super::super::super::CameraFrame;
use crate::error::{Error, Result};

/// The camera frame that looks at `frame.look_at` from the world direction
/// (cos e sin a, sin e, cos e cos a), at the distance |position - look_at|, with +y up.
///
/// Degenerate cases (errors): a non-finite angle; an elevation of +-90 degrees or beyond,
/// where the view direction is parallel to +y and no image "up" exists. A zero distance is
/// left to [`super::CameraBasis::new`], which reports `position == look_at`.
pub(super) fn frame(frame: &CameraFrame, azimuth: f64, elevation: f64) -> Result<CameraFrame> {
    if !azimuth.is_finite() {
        return Err(Error::new(format!(
            "flexible axonometric azimuth must be finite, got {azimuth}"
        )));
    }
    if elevation.is_nan() || elevation.abs() >= 90.0 {
        return Err(Error::new(format!(
            "flexible axonometric elevation must be in (-90, 90) degrees, got {elevation}"
        )));
    }
    let (sin_a, cos_a) = azimuth.to_radians().sin_cos();
    let (sin_e, cos_e) = elevation.to_radians().sin_cos();
    let towards_eye = DVec3::new(cos_e * sin_a, sin_e, cos_e * cos_a);
    let distance = (frame.position - frame.look_at).length();
    Ok(CameraFrame {
        position: frame.look_at + distance * towards_eye,
        look_at: frame.look_at,
        up: DVec3::Y,
    })
}
