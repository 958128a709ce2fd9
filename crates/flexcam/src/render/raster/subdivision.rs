//! How finely scene triangles are cut before their images are filled (`--subdiv`,
//! `--raster-tolerance`).

use crate::error::{Error, Result};

/// The default adaptive tolerance: half a pixel.
pub const DEFAULT_TOLERANCE: f64 = 0.5;

/// The smallest adaptive tolerance accepted, in pixels. Below it the rule would split edges
/// that are straight up to rounding (a perspective edge's midpoint is off its chord by about
/// 1e-12 pixels) all the way to [`MAX_LEVEL`], up to 4^18 pieces per triangle: a render that
/// never ends. A thousandth of a pixel is far below what one sample per pixel can show, and
/// bounds the work (the default scene's panorama at 1024 x 512 takes about ten times the
/// default's time there).
pub const MIN_TOLERANCE: f64 = 1e-3;

/// The largest uniform subdivision accepted (each triangle becomes its square pieces).
pub const MAX_UNIFORM: u32 = 64;

/// How many times an edge may be halved by the adaptive rule: enough to bring a
/// 180-degree edge within a thousandth of a degree of a pole, and a bound on the work a
/// triangle reaching a singularity can cause.
pub const MAX_LEVEL: u32 = 18;

/// Uniform and adaptive subdivision, applied in that order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Subdivision {
    /// Each triangle is first cut into `uniform`^2 pieces by a regular grid (1: not cut).
    pub uniform: u32,
    /// Then every edge whose projected midpoint lies more than this many pixels off the
    /// straight line between its projected ends is halved, recursively (`None`: no adaptive
    /// step). Edges near a panorama's pole are halved as well, whatever this is (see the
    /// `refine` module).
    pub tolerance: Option<f64>,
}

impl Default for Subdivision {
    /// Adaptive with the default tolerance of 0.5 pixels.
    fn default() -> Self {
        Subdivision {
            uniform: 1,
            tolerance: Some(DEFAULT_TOLERANCE),
        }
    }
}

impl Subdivision {
    /// Only the uniform grid, `n` x `n` pieces per triangle.
    pub fn uniform(n: u32) -> Self {
        Subdivision {
            uniform: n,
            tolerance: None,
        }
    }

    /// Only the adaptive rule, with `tolerance` pixels.
    pub fn adaptive(tolerance: f64) -> Self {
        Subdivision {
            uniform: 1,
            tolerance: Some(tolerance),
        }
    }

    /// Errors: `uniform` outside [1, 64], a tolerance that is not a finite
    /// number of pixels of at least 0.001.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_UNIFORM).contains(&self.uniform) {
            return Err(Error::new(format!(
                "subdivision must be between 1 and {MAX_UNIFORM}, got {}",
                self.uniform
            )));
        }
        if let Some(tolerance) = self.tolerance {
            if !(tolerance.is_finite() && tolerance >= MIN_TOLERANCE) {
                return Err(Error::new(format!(
                    "raster tolerance must be a number of pixels of at least {MIN_TOLERANCE}, \
                     got {tolerance:e}"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_bad_values() {
        assert_eq!(Subdivision::default(), Subdivision::adaptive(0.5));
        assert!(Subdivision::uniform(8).validate().is_ok());
        for bad in [Subdivision::uniform(0), Subdivision::uniform(65)] {
            let e = bad.validate().unwrap_err();
            assert!(e
                .message
                .starts_with("subdivision must be between 1 and 64"));
        }
        assert!(Subdivision::adaptive(MIN_TOLERANCE).validate().is_ok());
        // Tolerances below rounding would split every edge to the deepest level (a render
        // that never ends): refused.
        for t in [
            0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            1e-30,
            0.999 * MIN_TOLERANCE,
        ] {
            let e = Subdivision::adaptive(t).validate().unwrap_err();
            assert!(e.message.starts_with("raster tolerance"), "{e}");
        }
    }
}
