//! Reading and writing images: colour as PNG (8- or 16-bit), OpenEXR or PFM, 16-bit PNG
//! object ids and their false-colour previews, depth as OpenEXR or PFM, the multi-channel
//! OpenEXR of every AOV, ray maps and STMaps (OpenEXR), animated GIF, and the photos `flexcam reproject` reads.
//!
//! Writers write to the path they are given; [`OutputSet`] gives a command's outputs their
//! safety: refused when aimed at an input or at each other, staged in temporary files,
//! committed all together or not at all.

mod aovs;
mod byte_encoder;
mod color;
mod depth;
mod float;
mod gif;
mod identity;
mod outputs;
mod png;
mod ray_maps;
mod read;

use std::path::Path;

use glam::Vec3;

use crate::render::{Frame, Shading};

pub use aovs::write_aovs_exr;
pub use byte_encoder::{ByteEncoder, RgbEncoder};
pub use color::{encode_channel16, write_color, ColorFormat, PngBits};
pub use depth::{write_depth, DepthFormat};
pub use gif::GifFrames;
pub use identity::{FileIdentity, Target};
pub use outputs::{check_extension, write_bytes, OutputId, OutputSet};
pub use png::{id_preview_color, write_color_png, write_ids_png, write_ids_preview_png};
pub use ray_maps::{write_ray_map_exr, write_stmap, StMapFormat};
pub use read::{read_linear_image, LinearImage, INPUT_EXTENSIONS};

/// How linear colour is turned into 8- or 16-bit PNG values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorEncoding {
    /// The sRGB transfer curve (for `lit` images).
    Srgb,
    /// `round(255 * c)` with no transfer curve, so that flat colours round-trip exactly.
    Linear,
}

impl ColorEncoding {
    /// How images rendered with `shading` are written: linear where colours are exact codes
    /// (flat base colours, the transition methods' colours), sRGB for lit images.
    pub fn of_shading(shading: Shading) -> ColorEncoding {
        match shading {
            Shading::Flat => ColorEncoding::Linear,
            Shading::Transitions(t) if t.methods => ColorEncoding::Linear,
            Shading::Lit | Shading::Transitions(_) => ColorEncoding::Srgb,
        }
    }
}

/// Lower-case extension of `path`, or "" when it has none.
fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// The sRGB transfer curve of one linear channel value, clamped to [0,1].
fn srgb_encode(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear colour channel value encoded under `encoding`, in [0, 1]; NaN maps to 0.
fn encoded(c: f32, encoding: ColorEncoding) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c };
    match encoding {
        ColorEncoding::Srgb => srgb_encode(c),
        ColorEncoding::Linear => c.clamp(0.0, 1.0),
    }
}

/// 8-bit value of a linear colour channel under `encoding`; NaN maps to 0.
pub fn encode_channel(c: f32, encoding: ColorEncoding) -> u8 {
    (255.0 * encoded(c, encoding)).round() as u8
}

/// The 8-bit RGB bytes of the colour of `frame`, row by row from the top (allocated
/// fallibly: an error names the bytes).
fn rgb_bytes(frame: &Frame, encoding: ColorEncoding) -> crate::error::Result<Vec<u8>> {
    let mut encoder = RgbEncoder::new(ByteEncoder::of(encoding));
    let bytes = (frame.color.iter()).flat_map(|&c: &Vec3| encoder.rgb(c));
    crate::try_alloc::collected(3 * frame.color.len(), bytes, || {
        samples_of("8-bit RGB bytes", frame)
    })
}

/// Names an image writer's buffer for an allocation error: "the 8-bit RGB bytes of the
/// 800 x 600 image".
fn samples_of(what: &str, frame: &Frame) -> String {
    format!("the {what} of the {} x {} image", frame.width, frame.height)
}

/// The inverse of the sRGB transfer curve: an encoded value in [0, 1] to linear.
pub fn srgb_decode(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests;
