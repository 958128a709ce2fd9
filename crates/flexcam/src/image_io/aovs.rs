//! The AOV file: one OpenEXR layer `aovs` holding the frame's linear colour (`R`, `G`, `B`,
//! 32-bit float), its depth along each pixel's ray (`Z`, 32-bit float, +infinity where
//! nothing was hit) and its object ids (`id`, 32-bit unsigned int, 0 = background), so that
//! compositing tools get every pass of a render, pixel-aligned, in one file.

use std::path::Path;

use super::float::{rgb_channels, write_exr, ExrSamples};
use crate::error::{Error, Result};
use crate::render::Frame;

/// Writes the AOV file of `frame` at `path`. Errors: a frame rendered without depth or ids
/// (see [`crate::render::Outputs`]), a write failure.
pub fn write_aovs_exr(frame: &Frame, path: &Path) -> Result<()> {
    let pixels = frame.color.len();
    if frame.depth.len() != pixels || frame.ids.len() != pixels {
        return Err(Error::new(
            "the AOV file needs a frame rendered with depth and ids",
        ));
    }
    let mut channels = rgb_channels(frame);
    channels.push(("Z", ExrSamples::F32(frame.depth.clone())));
    channels.push(("id", ExrSamples::U32(frame.ids.clone())));
    write_exr(frame, path, "aovs", channels)
}
