//! Image textures: PNG / JPEG files decoded into linear-colour [`Texture`]s.

use std::path::Path;

use glam::Vec3;
use image::DynamicImage;

use super::read_file;
use crate::error::{Error, Result};
use crate::scene::{budget, Texture};

/// Loads a PNG or JPEG image as a linear-colour texture: the file's sRGB values are decoded
/// with the sRGB transfer curve; alpha is dropped; rows are stored top row first. An image
/// whose header gives a size beyond the memory budget is refused before it is decoded.
pub fn load_texture(path: &Path) -> Result<Texture> {
    let bytes = read_file(path)?;
    let cannot = |e: image::ImageError| Error::in_file(path, format!("cannot decode image: {e}"));
    let (width, height) = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| Error::in_file(path, format!("cannot decode image: {e}")))?
        .into_dimensions()
        .map_err(cannot)?;
    budget::check_image(width, height).map_err(|e| e.or_in_file(path))?;
    let image = image::load_from_memory(&bytes)
        .map_err(|e| Error::in_file(path, format!("cannot decode image: {e}")))?;
    texture_from_image(&image).map_err(|e| e.or_in_file(path))
}

/// The texture of a decoded image whose values are sRGB-encoded.
fn texture_from_image(image: &DynamicImage) -> Result<Texture> {
    let rgb = image.to_rgb32f();
    let texels = rgb
        .pixels()
        .map(|p| Vec3::from(p.0).map(srgb_to_linear))
        .collect();
    texture_from_texels(rgb.width(), rgb.height(), texels)
}

/// A texture from `width * height` linear texels, top row first. Rejects empty images, which
/// a texture lookup could not wrap into.
pub(super) fn texture_from_texels(width: u32, height: u32, texels: Vec<Vec3>) -> Result<Texture> {
    if width == 0 || height == 0 {
        return Err(Error::new(format!(
            "image is empty ({width} x {height} pixels)"
        )));
    }
    if texels.len() != width as usize * height as usize {
        return Err(Error::new(format!(
            "image has {} pixels, expected {width} x {height}",
            texels.len()
        )));
    }
    Ok(Texture {
        width,
        height,
        texels,
    })
}

/// Decodes one sRGB-encoded channel value in [0,1] to linear (IEC 61966-2-1).
pub(super) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use image::{Rgb, RgbImage};

    use super::*;

    #[test]
    fn srgb_decoding_fixed_points() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-4);
        // Continuous at the junction of the linear and power segments.
        assert!((srgb_to_linear(0.04045) - srgb_to_linear(0.040451)).abs() < 1e-6);
    }

    #[test]
    fn png_round_trip_top_row_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.png");
        let mut img = RgbImage::new(2, 2);
        img.put_pixel(0, 0, Rgb([255, 0, 0]));
        img.put_pixel(1, 0, Rgb([0, 255, 0]));
        img.put_pixel(0, 1, Rgb([0, 0, 255]));
        img.put_pixel(1, 1, Rgb([128, 128, 128]));
        img.save(&path).unwrap();
        let t = load_texture(&path).unwrap();
        assert_eq!((t.width, t.height), (2, 2));
        assert_eq!(t.texels[0], Vec3::X);
        assert_eq!(t.texels[1], Vec3::Y);
        assert_eq!(t.texels[2], Vec3::Z);
        assert!((t.texels[3].x - srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
        // OBJ-style lookup: v = 1 is the top row.
        assert_eq!(t.nearest(glam::Vec2::new(0.25, 0.75)), Vec3::X);
    }

    #[test]
    fn jpeg_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.jpg");
        RgbImage::from_pixel(8, 8, Rgb([255, 255, 255]))
            .save(&path)
            .unwrap();
        let t = load_texture(&path).unwrap();
        assert_eq!(t.texels.len(), 64);
        assert!(t.texels.iter().all(|c| c.min_element() > 0.9));
    }

    #[test]
    fn errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.png");
        let e = load_texture(&missing).unwrap_err().to_string();
        assert!(
            e.contains("missing.png") && e.contains("cannot read"),
            "{e}"
        );
        let garbage = dir.path().join("garbage.png");
        std::fs::write(&garbage, b"not an image at all").unwrap();
        let e = load_texture(&garbage).unwrap_err().to_string();
        assert!(
            e.contains("garbage.png") && e.contains("cannot decode"),
            "{e}"
        );
        assert!(texture_from_texels(0, 3, vec![]).is_err());
    }
}
