//! The keys of the calibrated lens models, `opencv` and `opencv_fisheye`: `fx`, `fy`, `cx`,
//! `cy` (pixels, OpenCV's convention), the distortion coefficients (`distortion` or `k`) and
//! `calibration_size`.

use toml::Spanned;

use super::projection_table::{camera_frame, Required};
use crate::error::Result;
use crate::projection::{CalibratedCamera, CalibrationSize, Intrinsics, ProjectionSpec};

/// Keys of an `opencv` table besides the camera frame.
pub(super) const OPENCV_KEYS: [&str; 6] =
    ["fx", "fy", "cx", "cy", "distortion", "calibration_size"];

/// Keys of an `opencv_fisheye` table besides the camera frame.
pub(super) const FISHEYE_KEYS: [&str; 6] = ["fx", "fy", "cx", "cy", "k", "calibration_size"];

/// `type = "opencv"`: `distortion` holds 4, 5 or 8 coefficients in OpenCV's order (k1, k2,
/// p1, p2[, k3[, k4, k5, k6]]); absent, no distortion.
pub(super) fn opencv(required: &Required, image_size: [u32; 2]) -> Result<ProjectionSpec> {
    let src = required.src;
    let mut distortion = [0.0; 8];
    if let Some(given) = &required.raw().distortion {
        let values = given.get_ref();
        if ![4, 5, 8].contains(&values.len()) {
            return Err(src.error(
                &given.span(),
                format!(
                    "`distortion` needs 4, 5 or 8 coefficients ([k1, k2, p1, p2, k3] or \
                     [k1, k2, p1, p2, k3, k4, k5, k6]), got {}",
                    values.len()
                ),
            ));
        }
        src.all_finite(values, given, "distortion")?;
        distortion[..values.len()].copy_from_slice(values);
    }
    Ok(ProjectionSpec::Opencv {
        camera: camera(required, image_size)?,
        distortion,
    })
}

/// `type = "opencv_fisheye"`: `k` = [k1, k2, k3, k4]; absent, the equidistant fisheye.
pub(super) fn opencv_fisheye(required: &Required, image_size: [u32; 2]) -> Result<ProjectionSpec> {
    let src = required.src;
    let mut k = [0.0; 4];
    if let Some(given) = &required.raw().k {
        let values = given.get_ref();
        if values.len() != 4 {
            return Err(src.error(
                &given.span(),
                format!(
                    "`k` needs 4 coefficients [k1, k2, k3, k4], got {}",
                    values.len()
                ),
            ));
        }
        src.all_finite(values, given, "k")?;
        k.copy_from_slice(values);
    }
    Ok(ProjectionSpec::OpencvFisheye {
        camera: camera(required, image_size)?,
        k,
    })
}

/// The frame, `fx`, `fy`, `cx`, `cy` (required) and the calibration size: `calibration_size`
/// where given, else the scene's image size `image_size`.
fn camera(required: &Required, image_size: [u32; 2]) -> Result<CalibratedCamera> {
    let src = required.src;
    let raw = required.raw();
    let number =
        |value: &Option<Spanned<f64>>, key: &str| src.number(required.get(value, key)?, key);
    let size = match &raw.calibration_size {
        Some(given) => CalibrationSize::Given(*given.get_ref()),
        None => CalibrationSize::SceneImage(image_size),
    };
    Ok(CalibratedCamera {
        frame: camera_frame(src, required)?,
        intrinsics: Intrinsics {
            fx: number(&raw.fx, "fx")?,
            fy: number(&raw.fy, "fy")?,
            cx: number(&raw.cx, "cx")?,
            cy: number(&raw.cy, "cy")?,
        },
        size,
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::super::parse;
    use super::super::tests::assert_error_at;
    use crate::projection::{CalibrationSize, ProjectionSpec};

    fn scene(projection_keys: &str) -> String {
        format!(
            "[image]\nwidth = 64\nheight = 48\n[projection]\nposition = [0, 1, 5]\n\
             look_at = [0, 1, 0]\nfx = 60\nfy = 61\ncx = 31.5\ncy = 23.5\n{projection_keys}"
        )
    }

    #[test]
    fn opencv_keys_and_defaults() {
        let text = scene("type = \"opencv\"\ndistortion = [-0.1, 0.01, 0.001, 0.002, 0.003]\n");
        let parsed = parse(&text, Path::new("s.toml")).unwrap();
        let ProjectionSpec::Opencv { camera, distortion } = parsed.projection else {
            panic!("{:?}", parsed.projection)
        };
        assert_eq!(distortion, [-0.1, 0.01, 0.001, 0.002, 0.003, 0.0, 0.0, 0.0]);
        assert_eq!(camera.intrinsics.fy, 61.0);
        assert_eq!(camera.size, CalibrationSize::SceneImage([64, 48]));
        let text = scene("type = \"opencv_fisheye\"\ncalibration_size = [640, 480]\n");
        let parsed = parse(&text, Path::new("s.toml")).unwrap();
        let ProjectionSpec::OpencvFisheye { camera, k } = parsed.projection else {
            panic!("{:?}", parsed.projection)
        };
        assert_eq!(k, [0.0; 4]);
        assert_eq!(camera.size, CalibrationSize::Given([640, 480]));
    }

    #[test]
    fn bad_calibrated_keys_are_refused_at_their_place() {
        assert_error_at(
            &scene("type = \"opencv\"\ndistortion = [0.1, 0.2, 0.3]\n"),
            12,
            14,
            "`distortion` needs 4, 5 or 8 coefficients",
        );
        assert_error_at(
            &scene("type = \"opencv_fisheye\"\nk = [0.1, 0.2]\n"),
            12,
            5,
            "`k` needs 4 coefficients",
        );
        assert_error_at(
            &scene("type = \"opencv\"\nk = [0.1, 0.2, 0.0, 0.0]\n"),
            12,
            5,
            "`k` is not a parameter of opencv projections",
        );
        assert_error_at(
            &scene("type = \"opencv\"\nfx = -3\n").replace("fx = 60\n", ""),
            4,
            1,
            "opencv fx must be a positive focal length in pixels, got -3",
        );
        let missing = scene("type = \"opencv\"\n").replace("cy = 23.5\n", "");
        assert_error_at(&missing, 4, 1, "opencv projection needs `cy`");
    }
}
