//! The depth AOV as OpenEXR (one 32-bit float channel `Z`) or PFM (grayscale `Pf`,
//! little-endian, rows bottom to top as PFM requires). Pixels where nothing was hit hold
//! +infinity in both formats.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::extension;
use crate::error::{Error, Result};
use crate::render::Frame;

/// The file formats of the depth AOV.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthFormat {
    Exr,
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
        DepthFormat::Pfm => write_depth_pfm(frame, path),
    }
}

fn write_depth_exr(frame: &Frame, path: &Path) -> Result<()> {
    use exr::prelude::*;
    let channel = AnyChannel::new("Z", FlatSamples::F32(frame.depth.clone()));
    let layer = Layer::new(
        (frame.width as usize, frame.height as usize),
        LayerAttributes::named("depth"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(vec![channel])),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| crate::error::Error::new(format!("cannot write OpenEXR: {e}")))
}

fn write_depth_pfm(frame: &Frame, path: &Path) -> Result<()> {
    let io = |e: std::io::Error| Error::new(format!("cannot write PFM: {e}"));
    let mut out = BufWriter::new(fs::File::create(path).map_err(io)?);
    write!(out, "Pf\n{} {}\n-1.0\n", frame.width, frame.height).map_err(io)?;
    for row in frame.depth.chunks(frame.width as usize).rev() {
        for d in row {
            out.write_all(&d.to_le_bytes()).map_err(io)?;
        }
    }
    out.flush().map_err(io)
}
