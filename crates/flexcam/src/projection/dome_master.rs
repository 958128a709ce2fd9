//! `type = "dome_master"`: the fulldome frame, an equidistant (azimuthal) fisheye looking at
//! the dome's apex.
//!
//! Fulldome convention (planetarium dome masters; Paul Bourke's fisheye pages, Ringling's
//! "The Dome Master"): the image centre is the apex of the dome, the bottom centre of the
//! image is the dome's front, the top centre its back, and left is left and right is right
//! for a viewer facing the front; 180 degrees across the circle. A dome tilted forward by
//! `tilt` degrees has its apex that far from the zenith towards the front.
//!
//! The scene keys say this in the dome's terms: `up` is the zenith, `look_at` a point in
//! front (its direction is projected onto the horizon), `tilt` and `fov`. The camera frame
//! follows: the view axis is the zenith turned towards the front by `tilt`, and the image's
//! up is the back, turned likewise.

use super::camera_basis::CameraBasis;
use super::fisheye::{Fisheye, FisheyeLens};
use super::CameraFrame;
use crate::error::{Error, Result};

/// The camera frame of a dome master whose dome has `frame.up` as its zenith and faces
/// `frame.look_at`, tilted forward by `tilt_degrees`. Errors: the frame's own (a zenith
/// parallel to the direction to `look_at` leaves no front), `tilt` not in [-90, 90].
fn dome_camera_frame(frame: &CameraFrame, tilt_degrees: f64) -> Result<CameraFrame> {
    if !(tilt_degrees.is_finite() && (-90.0..=90.0).contains(&tilt_degrees)) {
        return Err(Error::new(format!(
            "dome_master tilt must be in [-90, 90] degrees, got {tilt_degrees}"
        )));
    }
    // CameraBasis checks the frame: its forward is towards look_at, its up the zenith
    // made perpendicular to it, its right the viewer's right.
    let basis = CameraBasis::new(frame)?;
    let zenith = frame.up.normalize();
    let front = zenith.cross(basis.right).normalize();
    let (sin, cos) = tilt_degrees.to_radians().sin_cos();
    let axis = cos * zenith + sin * front;
    let image_up = sin * zenith - cos * front;
    Ok(CameraFrame {
        position: frame.position,
        look_at: frame.position + axis,
        up: image_up,
    })
}

/// The dome master as a fisheye (equidistant, circle inscribed in the shorter side).
pub(super) fn dome_master(
    frame: &CameraFrame,
    fov_degrees: f64,
    tilt_degrees: f64,
    width: u32,
    height: u32,
) -> Result<Fisheye> {
    let camera = dome_camera_frame(frame, tilt_degrees)?;
    Fisheye::with_lens(
        "dome_master",
        &camera,
        fov_degrees,
        &FisheyeLens::default(),
        width,
        height,
    )
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use super::*;
    use crate::projection::Projection;

    fn dome(tilt: f64) -> Fisheye {
        let frame = CameraFrame {
            position: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(1.0, 5.0, -7.0), // front: -z, whatever its elevation
            up: DVec3::Y,
        };
        dome_master(&frame, 180.0, tilt, 200, 200).unwrap()
    }

    fn direction(d: &Fisheye, pixel: [f64; 2]) -> DVec3 {
        d.ray(DVec2::from_array(pixel)).unwrap().direction
    }

    #[test]
    fn fulldome_orientation() {
        let d = dome(0.0);
        assert!((direction(&d, [100.0, 100.0]) - DVec3::Y).length() < 1e-15); // apex
        assert!((direction(&d, [100.0, 200.0]) - DVec3::NEG_Z).length() < 1e-15); // front
        assert!((direction(&d, [100.0, 0.0]) - DVec3::Z).length() < 1e-15); // back
        assert!((direction(&d, [200.0, 100.0]) - DVec3::X).length() < 1e-15); // right
        assert!((direction(&d, [0.0, 100.0]) - DVec3::NEG_X).length() < 1e-15); // left
    }

    #[test]
    fn tilt_moves_the_apex_towards_the_front() {
        let d = dome(30.0);
        let (s, c) = 30f64.to_radians().sin_cos();
        let apex = direction(&d, [100.0, 100.0]);
        assert!((apex - DVec3::new(0.0, c, -s)).length() < 1e-15, "{apex}");
        // Halfway down the image, 45 degrees from the apex towards the front.
        let (s, c) = 75f64.to_radians().sin_cos();
        let d45 = direction(&d, [100.0, 150.0]);
        assert!((d45 - DVec3::new(0.0, c, -s)).length() < 1e-15, "{d45}");
        assert!((direction(&d, [200.0, 100.0]) - DVec3::X).length() < 1e-15);
        assert!((direction(&dome(90.0), [100.0, 100.0]) - DVec3::NEG_Z).length() < 1e-15);
    }

    #[test]
    fn bad_tilt_and_front_are_errors() {
        let frame = CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        for tilt in [90.5, -91.0, f64::NAN] {
            let e = dome_master(&frame, 180.0, tilt, 10, 10).unwrap_err();
            assert!(e
                .message
                .starts_with("dome_master tilt must be in [-90, 90]"));
        }
        let straight_up = CameraFrame {
            look_at: DVec3::Y,
            ..frame
        };
        assert!(dome_master(&straight_up, 180.0, 0.0, 10, 10).is_err());
        assert_eq!(dome(10.0).kind(), "dome_master");
    }
}
