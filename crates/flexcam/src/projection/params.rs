//! Validation of the numeric parameters of projection descriptions (angles, extents), with
//! one-line messages that name the projection type and the parameter.

use crate::error::{Error, Result};

/// The upper end of an angle's allowed range, in degrees, and whether it is allowed itself.
#[derive(Debug, Clone, Copy)]
pub(crate) enum UpTo {
    Below(f64),
    Including(f64),
}

/// Checks that `degrees` (parameter `name` of projection `kind`) is finite, positive and
/// within `max`, and returns it in radians.
pub(crate) fn angle_radians(kind: &str, name: &str, degrees: f64, max: UpTo) -> Result<f64> {
    let (max_degrees, inside, bracket) = match max {
        UpTo::Below(m) => (m, degrees < m, ')'),
        UpTo::Including(m) => (m, degrees <= m, ']'),
    };
    if !degrees.is_finite() || degrees <= 0.0 || !inside {
        return Err(Error::new(format!(
            "{kind} {name} must be in (0, {max_degrees}{bracket} degrees, got {degrees}"
        )));
    }
    Ok(degrees.to_radians())
}

/// Checks that `value` (parameter `name` of projection `kind`) is finite and positive.
pub(crate) fn positive_length(kind: &str, name: &str, value: f64) -> Result<f64> {
    if !value.is_finite() || value <= 0.0 {
        return Err(Error::new(format!(
            "{kind} {name} must be a positive length, got {value}"
        )));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_range_ends() {
        assert!(angle_radians("p", "fov", 179.9, UpTo::Below(180.0)).is_ok());
        assert!(angle_radians("p", "fov", 180.0, UpTo::Below(180.0)).is_err());
        assert!(angle_radians("p", "fov", 360.0, UpTo::Including(360.0)).is_ok());
        assert!(angle_radians("p", "fov", 0.0, UpTo::Including(360.0)).is_err());
        assert!(angle_radians("p", "fov", -5.0, UpTo::Including(360.0)).is_err());
        let nan = angle_radians("fisheye", "fov", f64::NAN, UpTo::Including(360.0));
        assert_eq!(
            nan.unwrap_err().message,
            "fisheye fov must be in (0, 360] degrees, got NaN"
        );
        let r = angle_radians("p", "fov", 90.0, UpTo::Below(180.0)).unwrap();
        assert!((r - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn lengths_must_be_positive_and_finite() {
        assert_eq!(positive_length("o", "width", 2.5).unwrap(), 2.5);
        for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
            assert!(positive_length("o", "width", bad).is_err());
        }
    }
}
