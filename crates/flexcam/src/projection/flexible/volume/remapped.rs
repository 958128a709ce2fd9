//! [`RemappedVolume`]: a volume moved onto the image's own domain, so that volumes with
//! different re-parameterisations can be blended (thesis fig. 6.16, a perspective and a
//! fisheye). Its (u, v) are the image positions (s, t) = (x / W, 1 - y / H), the linear
//! map's, and its point there is the volume's at the (u, v) its own map gives that pixel.
//!
//! Beyond its own map's domain (outside a fisheye's circle) the volume is continued by the
//! map's formulas ([`Reparam::to_uv_continued`]): that is what a blend with a volume that
//! does see there mixes with. On its own it sees only its domain ([`RemappedVolume::sees`]).

use glam::DVec2;

use super::Volume;
use crate::projection::flexible::Reparam;
use crate::projection::image_coords::Resolution;

/// A volume on the image's (s, t) domain through its own map.
#[derive(Debug, Clone, PartialEq)]
pub struct RemappedVolume {
    /// The volume, on its own (u, v) domain.
    pub volume: Volume,
    /// Its re-parameterisation: pixel to its (u, v).
    pub map: Reparam,
    /// The image the map is for.
    pub resolution: Resolution,
}

impl RemappedVolume {
    /// The pixel position of image position `st`.
    fn pixel(&self, st: DVec2) -> DVec2 {
        let size = self.resolution.size();
        DVec2::new(st.x * size.x, (1.0 - st.y) * size.y)
    }

    /// The volume's own (u, v) at image position `st`, continued beyond its map's domain.
    pub fn own_uv(&self, st: DVec2) -> DVec2 {
        self.map.to_uv_continued(&self.resolution, self.pixel(st))
    }

    /// Whether the volume itself sees image position `st`: its map has a (u, v) there and
    /// the volume sees that (u, v).
    pub fn sees(&self, st: DVec2) -> bool {
        self.map
            .to_uv(&self.resolution, self.pixel(st))
            .is_some_and(|uv| self.volume.sees(uv))
    }
}
