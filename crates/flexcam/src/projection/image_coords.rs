//! The image rectangle, and conversion between pixel positions (y down, origin top-left)
//! and centred positions (y up, origin at the image centre), both in pixel units.

use glam::DVec2;

use crate::error::{Error, Result};

/// A validated image size (both sides at least one pixel).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resolution {
    /// Width in pixels, at least 1.
    pub width: u32,
    /// Height in pixels, at least 1.
    pub height: u32,
}

impl Resolution {
    /// Errors when either side is zero.
    pub fn new(width: u32, height: u32) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::new(format!(
                "image size {width}x{height} is empty: width and height must be at least 1"
            )));
        }
        Ok(Resolution { width, height })
    }

    /// Width and height as floats.
    pub fn size(&self) -> DVec2 {
        DVec2::new(f64::from(self.width), f64::from(self.height))
    }

    /// The position of continuous pixel `pixel` relative to the image centre, y up.
    pub fn centred(&self, pixel: DVec2) -> DVec2 {
        let half = 0.5 * self.size();
        DVec2::new(pixel.x - half.x, half.y - pixel.y)
    }

    /// The continuous pixel position of centred position `centred` (inverse of
    /// [`Resolution::centred`]).
    pub fn pixel(&self, centred: DVec2) -> DVec2 {
        let half = 0.5 * self.size();
        DVec2::new(centred.x + half.x, half.y - centred.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_and_corners() {
        let r = Resolution::new(4, 2).unwrap();
        assert_eq!(r.centred(DVec2::new(2.0, 1.0)), DVec2::ZERO);
        assert_eq!(r.centred(DVec2::ZERO), DVec2::new(-2.0, 1.0));
        assert_eq!(
            r.pixel(r.centred(DVec2::new(3.25, 0.5))),
            DVec2::new(3.25, 0.5)
        );
    }

    #[test]
    fn empty_image_is_an_error() {
        assert!(Resolution::new(0, 5).is_err());
        assert!(Resolution::new(5, 0).is_err());
    }
}
