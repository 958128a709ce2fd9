//! 8-bit RGB colour PNGs, 16-bit grayscale object-id PNGs and their 8-bit false-colour
//! previews.

use std::path::Path;

use super::{rgb_bytes, samples_of, ColorEncoding};
use crate::error::{Error, Result};
use crate::render::Frame;
use crate::try_alloc;

/// Writes the colour of `frame` as an 8-bit RGB PNG at `path`.
pub fn write_color_png(frame: &Frame, path: &Path, encoding: ColorEncoding) -> Result<()> {
    write_rgb8_png(frame, path, &rgb_bytes(frame, encoding)?)
}

/// Writes `bytes`, 8-bit RGB of the size of `frame`, as a PNG at `path`.
fn write_rgb8_png(frame: &Frame, path: &Path, bytes: &[u8]) -> Result<()> {
    image::save_buffer_with_format(
        path,
        bytes,
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
    if let Some(id) = frame.ids.iter().find(|&&id| u16::try_from(id).is_err()) {
        return Err(Error::new(format!(
            "object id {id} does not fit a 16-bit PNG"
        )));
    }
    let ids = try_alloc::collected(
        frame.ids.len(),
        frame.ids.iter().map(|&id| id as u16),
        || samples_of("16-bit ids", frame),
    )?;
    let buffer =
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(frame.width, frame.height, ids)
            .ok_or_else(|| Error::new("id buffer does not match the image size"))?;
    buffer
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
}

/// The false colour of object `id` in an ids preview: black for the background (0), else a
/// fixed hash of the id (the "lowbias32" integer mix of Wellons) with each channel lifted to
/// [64, 255], so that every object is visible and neighbouring ids differ.
pub fn id_preview_color(id: u32) -> [u8; 3] {
    if id == 0 {
        return [0, 0, 0];
    }
    let mut x = id;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    let [r, g, b, _] = x.to_le_bytes();
    [r, g, b].map(|v| 64 + (u16::from(v) * 191 / 255) as u8)
}

/// Writes object ids as an 8-bit RGB PNG at `path`, each id in its [`id_preview_color`].
pub fn write_ids_preview_png(frame: &Frame, path: &Path) -> Result<()> {
    let bytes = try_alloc::collected(
        3 * frame.ids.len(),
        frame.ids.iter().flat_map(|&id| id_preview_color(id)),
        || samples_of("id preview bytes", frame),
    )?;
    write_rgb8_png(frame, path, &bytes)
}
