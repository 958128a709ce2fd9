//! Reading colour images (the photo of `flexcam reproject`): PNG and JPEG decoded from sRGB
//! to linear, OpenEXR as it is.

use std::path::Path;

use glam::Vec3;

use super::{extension, srgb_decode};
use crate::error::{Error, Result};
use crate::file_read::{check_regular, MAX_DATA_FILE_BYTES};
use crate::scene::budget;

pub use crate::render::LinearImage;

/// The input extensions [`read_linear_image`] accepts.
pub const INPUT_EXTENSIONS: [&str; 4] = ["png", "jpg", "jpeg", "exr"];

/// Reads a PNG or JPEG (sRGB-encoded: decoded to linear) or an OpenEXR file (linear; its
/// first layer's R, G and B, alpha ignored). Errors (each one line naming the file): an
/// unsupported extension, a missing or unreadable file, one that is not a regular file (a
/// FIFO would block), an image of zero width or height.
pub fn read_linear_image(path: &Path) -> Result<LinearImage> {
    let ext = extension(path);
    let regular = || check_regular(path, "image", MAX_DATA_FILE_BYTES);
    let image = match ext.as_str() {
        "png" | "jpg" | "jpeg" => regular().and_then(|()| read_srgb_image(path)),
        "exr" => regular().and_then(|()| read_exr_image(path)),
        other => Err(Error::new(format!(
            "unsupported input format \"{other}\" (expected {})",
            INPUT_EXTENSIONS
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
    .map_err(|e| Error::in_file(path, e.message))?;
    if image.width == 0 || image.height == 0 {
        return Err(Error::in_file(
            path,
            format!("image has zero size ({} x {})", image.width, image.height),
        ));
    }
    Ok(image)
}

/// Fails when a `width` x `height` image is beyond the memory budget, before it is decoded.
fn check_size(width: usize, height: usize) -> Result<()> {
    let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    budget::check_image(side(width), side(height))
}

fn read_srgb_image(path: &Path) -> Result<LinearImage> {
    let (width, height) =
        image::image_dimensions(path).map_err(|e| Error::new(format!("cannot read image: {e}")))?;
    check_size(width as usize, height as usize)?;
    let decoded = image::open(path)
        .map_err(|e| Error::new(format!("cannot read image: {e}")))?
        .to_rgb32f();
    Ok(LinearImage {
        width: decoded.width(),
        height: decoded.height(),
        pixels: decoded
            .pixels()
            .map(|p| Vec3::from_array(p.0.map(srgb_decode)))
            .collect(),
    })
}

fn read_exr_image(path: &Path) -> Result<LinearImage> {
    use exr::prelude::*;
    let cannot =
        |e: exr::error::Error| crate::error::Error::new(format!("cannot read OpenEXR: {e}"));
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(cannot)?;
    for header in &meta.headers {
        check_size(header.layer_size.width(), header.layer_size.height())?;
    }
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![Vec3::ZERO; size.area()]),
        |(width, pixels), position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[position.y() * *width + position.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(cannot)?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    let dimension = |n: usize| {
        u32::try_from(n)
            .map_err(|_| crate::error::Error::new(format!("OpenEXR image too large: {n}")))
    };
    Ok(LinearImage {
        width: dimension(size.width())?,
        height: dimension(size.height())?,
        pixels,
    })
}
