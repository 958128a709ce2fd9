//! The AOV file: one OpenEXR layer `aovs` holding the frame's linear colour (`R`, `G`, `B`,
//! 32-bit float), its depth along each pixel's ray (`Z`, 32-bit float, +infinity where
//! nothing was hit), its object ids (`id`, 32-bit unsigned int, 0 = background) and, when the
//! frame carries them, its surface layers (32-bit float, world space): the shading normal
//! `N.X`, `N.Y`, `N.Z`, the geometric normal `Ng.X`, `Ng.Y`, `Ng.Z`, the position `P.X`,
//! `P.Y`, `P.Z` and the texture coordinates `uv.U`, `uv.V` (see
//! [`crate::render::SurfacePoint`]; zero normals and NaN position and uv where no surface is
//! shown), so that compositing tools get every pass of a render, pixel-aligned, in one file.
//! The names follow the EXR `layer.channel` convention, which compositors (Nuke) read as
//! layers `N`, `Ng`, `P` and `uv`.

use std::path::Path;

use super::float::{rgb_channels, scalar_channel, vector_channels, write_exr, ExrSamples};
use crate::error::{Error, Result};
use crate::render::Frame;

/// Writes the AOV file of `frame` at `path`, with the surface layers when `frame` carries
/// them. Errors: a frame rendered without depth or ids (see [`crate::render::Outputs`]), a
/// write failure.
pub fn write_aovs_exr(frame: &Frame, path: &Path) -> Result<()> {
    let pixels = frame.color.len();
    if frame.depth.len() != pixels || frame.ids.len() != pixels {
        return Err(Error::new(
            "the AOV file needs a frame rendered with depth and ids",
        ));
    }
    let mut channels = rgb_channels(frame)?;
    channels.push(("Z", scalar_channel(&frame.depth, |z| *z)?));
    let ids =
        crate::try_alloc::copied(&frame.ids, || format!("an OpenEXR channel of {pixels} ids"))?;
    channels.push(("id", ExrSamples::U32(ids)));
    let surface = &frame.surface;
    if !surface.is_empty() {
        channels.extend(vector_channels(["N.X", "N.Y", "N.Z"], surface, |s| {
            s.normal.to_array()
        })?);
        channels.extend(vector_channels(["Ng.X", "Ng.Y", "Ng.Z"], surface, |s| {
            s.geometric_normal.to_array()
        })?);
        channels.extend(vector_channels(["P.X", "P.Y", "P.Z"], surface, |s| {
            s.position.to_array()
        })?);
        channels.push(("uv.U", scalar_channel(surface, |s| s.uv.x)?));
        channels.push(("uv.V", scalar_channel(surface, |s| s.uv.y)?));
    }
    write_exr((frame.width, frame.height), path, "aovs", channels)
}
