//! 8-bit RGB colour PNGs and 16-bit grayscale object-id PNGs.

use std::path::Path;

use super::{rgb_bytes, ColorEncoding};
use crate::error::{Error, Result};
use crate::render::Frame;

/// Writes the colour of `frame` as an 8-bit RGB PNG at `path`.
pub fn write_color_png(frame: &Frame, path: &Path, encoding: ColorEncoding) -> Result<()> {
    let bytes = rgb_bytes(frame, encoding);
    image::save_buffer_with_format(
        path,
        &bytes,
        frame.width,
        frame.height,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
}

/// Writes object ids as a 16-bit grayscale PNG at `path` (0 = background); ids above 65535
/// are an error rather than silently wrapping.
pub fn write_ids_png(frame: &Frame, path: &Path) -> Result<()> {
    let ids: Vec<u16> = frame
        .ids
        .iter()
        .map(|&id| {
            u16::try_from(id)
                .map_err(|_| Error::new(format!("object id {id} does not fit a 16-bit PNG")))
        })
        .collect::<Result<_>>()?;
    let buffer =
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(frame.width, frame.height, ids)
            .ok_or_else(|| Error::new("id buffer does not match the image size"))?;
    buffer
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
}
