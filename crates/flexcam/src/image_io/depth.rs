//! The depth AOV as OpenEXR (one 32-bit float channel `Z`) or PFM (grayscale `Pf`,
//! little-endian, rows bottom to top as PFM requires). Pixels where nothing was hit hold
//! +infinity in both formats.

use std::path::Path;

use super::extension;
use super::float::{scalar_channel, write_exr, write_pfm};
use crate::error::{Error, Result};
use crate::render::Frame;

/// The file formats of the depth AOV.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthFormat {
    /// OpenEXR, one 32-bit float channel `Z`.
    Exr,
    /// Portable float map, one 32-bit float channel.
    Pfm,
}

impl DepthFormat {
    /// The extensions of the depth formats.
    pub const EXTENSIONS: [&'static str; 2] = ["exr", "pfm"];

    /// The format named by the extension of `path`. Errors: any other extension.
    pub fn of(path: &Path) -> Result<DepthFormat> {
        match extension(path).as_str() {
            "exr" => Ok(DepthFormat::Exr),
            "pfm" => Ok(DepthFormat::Pfm),
            other => Err(Error::in_file(
                path,
                format!("unsupported depth extension \"{other}\" (expected .exr or .pfm)"),
            )),
        }
    }
}

/// Writes the depth of `frame` at `path` in `format`.
pub fn write_depth(frame: &Frame, path: &Path, format: DepthFormat) -> Result<()> {
    match format {
        DepthFormat::Exr => write_depth_exr(frame, path),
        DepthFormat::Pfm => write_pfm(frame, path, 1, &frame.depth),
    }
}

fn write_depth_exr(frame: &Frame, path: &Path) -> Result<()> {
    let depth = scalar_channel(&frame.depth, |z| *z)?;
    write_exr(
        (frame.width, frame.height),
        path,
        "depth",
        vec![("Z", depth)],
    )
}
