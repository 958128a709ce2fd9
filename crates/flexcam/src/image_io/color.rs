//! The colour output in the format its extension names: PNG, 8-bit (the default) or 16-bit,
//! encoded as [`ColorEncoding`] says; OpenEXR (channels `R`, `G`, `B`) and PFM (`PF`), both
//! linear 32-bit float, the frame's colour as rendered (no transfer curve, no clamping).

use std::path::Path;

use super::float::{rgb_channels, write_exr, write_pfm};
use super::{encoded, extension, write_color_png, ColorEncoding};
use crate::error::{Error, Result};
use crate::render::Frame;

/// The bit depth of a PNG colour output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngBits {
    /// 8 bits a channel (the default).
    Eight,
    /// 16 bits a channel (`--png-bits 16`).
    Sixteen,
}

/// The file formats of the colour output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorFormat {
    /// PNG, sRGB-encoded (linear with flat shading), of the given bit depth.
    Png(PngBits),
    /// OpenEXR, linear 32-bit float RGB.
    Exr,
    /// Portable float map, linear 32-bit float RGB.
    Pfm,
}

impl ColorFormat {
    /// The extensions of the colour formats.
    pub const EXTENSIONS: [&'static str; 3] = ["png", "exr", "pfm"];

    /// The format named by the extension of `path`, a PNG of `bits`. Errors: any other
    /// extension.
    pub fn of(path: &Path, bits: PngBits) -> Result<ColorFormat> {
        match extension(path).as_str() {
            "png" => Ok(ColorFormat::Png(bits)),
            "exr" => Ok(ColorFormat::Exr),
            "pfm" => Ok(ColorFormat::Pfm),
            other => Err(Error::in_file(
                path,
                format!("unsupported colour extension \"{other}\" (expected .png, .exr or .pfm)"),
            )),
        }
    }
}

/// Writes the colour of `frame` at `path` in `format`; `encoding` applies to PNG only.
pub fn write_color(
    frame: &Frame,
    path: &Path,
    format: ColorFormat,
    encoding: ColorEncoding,
) -> Result<()> {
    match format {
        ColorFormat::Png(PngBits::Eight) => write_color_png(frame, path, encoding),
        ColorFormat::Png(PngBits::Sixteen) => write_color_png16(frame, path, encoding),
        ColorFormat::Exr => write_exr(
            (frame.width, frame.height),
            path,
            "color",
            rgb_channels(frame)?,
        ),
        ColorFormat::Pfm => write_pfm(frame, path, 3, bytemuck::cast_slice(&frame.color)),
    }
}

/// 16-bit value of a linear colour channel under `encoding`; NaN maps to 0.
pub fn encode_channel16(c: f32, encoding: ColorEncoding) -> u16 {
    (65535.0 * encoded(c, encoding)).round() as u16
}

/// Writes the colour of `frame` as a 16-bit RGB PNG at `path`.
fn write_color_png16(frame: &Frame, path: &Path, encoding: ColorEncoding) -> Result<()> {
    let samples = crate::try_alloc::collected(
        3 * frame.color.len(),
        (frame.color.iter()).flat_map(|c| c.to_array().map(|v| encode_channel16(v, encoding))),
        || super::samples_of("16-bit RGB samples", frame),
    )?;
    let buffer = image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(
        frame.width,
        frame.height,
        samples,
    )
    .ok_or_else(|| Error::new("colour buffer does not match the image size"))?;
    buffer
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
}
