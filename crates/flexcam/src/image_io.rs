//! Writing frames: PNG colour, 16-bit PNG object ids, depth as OpenEXR or PFM, animated GIF.
//!
//! Writers never leave a partial file behind: each output goes to a temporary file beside its
//! destination ([`StagedFile`]) and is renamed into place only when the caller commits all of
//! a render's outputs together.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Error, Result};
use crate::render::Frame;

/// How linear colour is turned into 8-bit PNG values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorEncoding {
    /// The sRGB transfer curve (for `lit` images).
    Srgb,
    /// `round(255 * c)` with no transfer curve, so that flat colours round-trip exactly.
    Linear,
}

/// An output written to a temporary path, renamed to its destination by [`StagedFile::commit`]
/// and removed if dropped uncommitted.
#[derive(Debug)]
pub struct StagedFile {
    temporary: PathBuf,
    destination: PathBuf,
    committed: bool,
}

impl StagedFile {
    /// Reserves a temporary path in the destination's folder (so the final rename is atomic).
    fn new(destination: &Path) -> StagedFile {
        let name = destination
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let temporary =
            destination.with_file_name(format!(".{name}.{}.partial", std::process::id()));
        StagedFile {
            temporary,
            destination: destination.to_path_buf(),
            committed: false,
        }
    }

    /// Moves the finished file to its destination.
    pub fn commit(mut self) -> Result<()> {
        fs::rename(&self.temporary, &self.destination)
            .map_err(|e| Error::in_file(&self.destination, format!("cannot write: {e}")))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_file(&self.temporary);
        }
    }
}

/// Lower-case extension of `path`, or "" when it has none.
fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Checks before rendering that an output path can be written later: a known extension and an
/// existing folder. (Rendering can take long; a typo should fail at once.)
pub fn check_output_path(path: &Path, allowed_extensions: &[&str]) -> Result<()> {
    let ext = extension(path);
    if !allowed_extensions.contains(&ext.as_str()) {
        return Err(Error::in_file(
            path,
            format!(
                "unsupported output extension \"{ext}\" (expected {})",
                allowed_extensions
                    .iter()
                    .map(|e| format!(".{e}"))
                    .collect::<Vec<_>>()
                    .join(" or ")
            ),
        ));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        return Err(Error::in_file(
            path,
            format!("output folder {} does not exist", folder.display()),
        ));
    }
    Ok(())
}

/// Runs `write` on a staged temporary file for `destination`.
fn stage(destination: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<StagedFile> {
    let staged = StagedFile::new(destination);
    write(&staged.temporary).map_err(|e| Error::in_file(destination, e.message))?;
    Ok(staged)
}

/// Writes `bytes` (a stats report, say) to a staged file for `destination`.
pub fn write_bytes(destination: &Path, bytes: &[u8]) -> Result<StagedFile> {
    stage(destination, |tmp| {
        fs::write(tmp, bytes).map_err(|e| Error::new(format!("cannot write: {e}")))
    })
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

/// 8-bit value of a linear colour channel under `encoding`; NaN maps to 0.
pub fn encode_channel(c: f32, encoding: ColorEncoding) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c };
    let v = match encoding {
        ColorEncoding::Srgb => srgb_encode(c),
        ColorEncoding::Linear => c.clamp(0.0, 1.0),
    };
    (255.0 * v).round() as u8
}

/// The 8-bit RGB bytes of the colour of `frame`, row by row from the top.
fn rgb_bytes(frame: &Frame, encoding: ColorEncoding) -> Vec<u8> {
    frame
        .color
        .iter()
        .flat_map(|c: &Vec3| c.to_array().map(|v| encode_channel(v, encoding)))
        .collect()
}

/// Writes the colour of `frame` as an 8-bit RGB PNG (staged).
pub fn write_color_png(frame: &Frame, path: &Path, encoding: ColorEncoding) -> Result<StagedFile> {
    let bytes = rgb_bytes(frame, encoding);
    stage(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &bytes,
            frame.width,
            frame.height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
    })
}

/// The frames of an animated GIF, added one at a time so that only their 8-bit colours are
/// kept, not whole [`Frame`]s.
#[derive(Debug, Default)]
pub struct GifFrames {
    frames: Vec<image::RgbaImage>,
}

impl GifFrames {
    /// Appends the colour of `frame`.
    pub fn push(&mut self, frame: &Frame, encoding: ColorEncoding) -> Result<()> {
        let rgba: Vec<u8> = rgb_bytes(frame, encoding)
            .chunks_exact(3)
            .flat_map(|rgb| [rgb[0], rgb[1], rgb[2], 255])
            .collect();
        let image = image::RgbaImage::from_raw(frame.width, frame.height, rgba)
            .ok_or_else(|| Error::new("colour buffer does not match the image size"))?;
        self.frames.push(image);
        Ok(())
    }

    /// Writes the frames as an animated GIF that loops forever, each frame shown for
    /// 1 / `fps` seconds (GIF stores delays in hundredths of a second: rounded, at least
    /// 1/100 s), staged.
    pub fn write(self, path: &Path, fps: f64) -> Result<StagedFile> {
        use image::codecs::gif::{GifEncoder, Repeat};
        let hundredths = (100.0 / fps).round().max(1.0) as u32;
        let delay = image::Delay::from_numer_denom_ms(10 * hundredths, 1);
        stage(path, |tmp| {
            let file =
                fs::File::create(tmp).map_err(|e| Error::new(format!("cannot write: {e}")))?;
            let mut encoder = GifEncoder::new_with_speed(BufWriter::new(file), 10);
            let gif_error = |e: image::ImageError| Error::new(format!("cannot write GIF: {e}"));
            encoder.set_repeat(Repeat::Infinite).map_err(gif_error)?;
            encoder
                .encode_frames(
                    self.frames
                        .into_iter()
                        .map(|f| image::Frame::from_parts(f, 0, 0, delay)),
                )
                .map_err(gif_error)
        })
    }
}

/// Writes object ids as a 16-bit grayscale PNG (0 = background); ids above 65535 are an error
/// rather than silently wrapping.
pub fn write_ids_png(frame: &Frame, path: &Path) -> Result<StagedFile> {
    let ids: Vec<u16> = frame
        .ids
        .iter()
        .map(|&id| {
            u16::try_from(id).map_err(|_| {
                Error::in_file(path, format!("object id {id} does not fit a 16-bit PNG"))
            })
        })
        .collect::<Result<_>>()?;
    let buffer =
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(frame.width, frame.height, ids)
            .ok_or_else(|| Error::in_file(path, "id buffer does not match the image size"))?;
    stage(path, |tmp| {
        buffer
            .save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
    })
}

/// Writes the depth AOV, OpenEXR (one 32-bit float channel `Z`) or PFM (grayscale `Pf`,
/// little-endian, rows bottom to top as PFM requires) by extension. Pixels where nothing was
/// hit hold +infinity in both formats.
pub fn write_depth(frame: &Frame, path: &Path) -> Result<StagedFile> {
    match extension(path).as_str() {
        "exr" => stage(path, |tmp| write_depth_exr(frame, tmp)),
        "pfm" => stage(path, |tmp| write_depth_pfm(frame, tmp)),
        other => Err(Error::in_file(
            path,
            format!("unsupported depth extension \"{other}\" (expected .exr or .pfm)"),
        )),
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

pub use crate::render::LinearImage;

/// The input extensions [`read_linear_image`] accepts.
pub const INPUT_EXTENSIONS: [&str; 4] = ["png", "jpg", "jpeg", "exr"];

/// Reads a PNG or JPEG (sRGB-encoded: decoded to linear) or an OpenEXR file (linear; its
/// first layer's R, G and B, alpha ignored). Errors (each one line naming the file): an
/// unsupported extension, a missing or unreadable file, an image of zero width or height.
pub fn read_linear_image(path: &Path) -> Result<LinearImage> {
    let ext = extension(path);
    let image = match ext.as_str() {
        "png" | "jpg" | "jpeg" => read_srgb_image(path),
        "exr" => read_exr_image(path),
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

fn read_srgb_image(path: &Path) -> Result<LinearImage> {
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
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![Vec3::ZERO; size.area()]),
        |(width, pixels), position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[position.y() * *width + position.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| crate::error::Error::new(format!("cannot read OpenEXR: {e}")))?;
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

/// The inverse of the sRGB transfer curve: an encoded value in [0, 1] to linear.
pub fn srgb_decode(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        let mut f = Frame::new(3, 2, Vec3::new(0.2, 0.4, 0.6));
        f.depth[0] = 1.5;
        f.ids[0] = 7;
        f
    }

    #[test]
    fn linear_encoding_round_trips_flat_colours() {
        for k in 0..=255u8 {
            assert_eq!(encode_channel(k as f32 / 255.0, ColorEncoding::Linear), k);
        }
        assert_eq!(encode_channel(f32::NAN, ColorEncoding::Srgb), 0);
        assert_eq!(encode_channel(0.5, ColorEncoding::Srgb), 188);
    }

    #[test]
    fn png_ids_and_pfm_are_written_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("c.png");
        let staged = write_color_png(&frame(), &png, ColorEncoding::Linear).unwrap();
        assert!(!png.exists());
        staged.commit().unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.get_pixel(2, 1).0, [51, 102, 153]);

        let ids = dir.path().join("i.png");
        write_ids_png(&frame(), &ids).unwrap().commit().unwrap();
        let img = image::open(&ids).unwrap().to_luma16();
        assert_eq!(img.get_pixel(0, 0).0, [7]);

        let pfm = dir.path().join("d.pfm");
        write_depth(&frame(), &pfm).unwrap().commit().unwrap();
        let bytes = fs::read(&pfm).unwrap();
        let header = b"Pf\n3 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        // Pixel (0,0) is in the top row, which PFM stores last.
        let top_row = header.len() + 3 * 4;
        assert_eq!(
            f32::from_le_bytes(bytes[top_row..top_row + 4].try_into().unwrap()),
            1.5
        );
        assert!(
            f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap())
                .is_infinite()
        );
    }

    #[test]
    fn gif_frames_read_back_in_order_with_their_delay() {
        use image::AnimationDecoder;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let mut gif = GifFrames::default();
        let mut second = frame();
        second
            .color
            .iter_mut()
            .for_each(|c| *c = Vec3::new(0.0, 0.0, 1.0));
        gif.push(&frame(), ColorEncoding::Linear).unwrap();
        gif.push(&second, ColorEncoding::Linear).unwrap();
        let staged = gif.write(&path, 25.0).unwrap();
        assert!(!path.exists());
        staged.commit().unwrap();
        let file = std::io::BufReader::new(fs::File::open(&path).unwrap());
        let decoded = image::codecs::gif::GifDecoder::new(file)
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(decoded.len(), 2);
        assert_eq!(decoded[0].delay().numer_denom_ms(), (40, 1));
        assert_eq!(decoded[1].buffer().get_pixel(0, 0).0, [0, 0, 255, 255]);
    }

    #[test]
    fn dropped_staged_file_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("d.exr");
        drop(write_depth(&frame(), &exr).unwrap());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn exr_depth_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("d.exr");
        write_depth(&frame(), &exr).unwrap().commit().unwrap();
        let image = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
        let samples = &image.layer_data[0].channel_data.list[0].sample_data;
        assert_eq!(samples.value_by_flat_index(0).to_f32(), 1.5);
        assert!(samples.value_by_flat_index(1).to_f32().is_infinite());
    }

    #[test]
    fn output_path_checks() {
        let dir = tempfile::tempdir().unwrap();
        assert!(check_output_path(&dir.path().join("a.png"), &["png"]).is_ok());
        let e = check_output_path(&dir.path().join("a.jpg"), &["png"]).unwrap_err();
        assert!(e.to_string().contains("expected .png"), "{e}");
        let e = check_output_path(&dir.path().join("no/a.png"), &["png"]).unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        assert!(write_depth(&frame(), &dir.path().join("d.tif")).is_err());
    }
}
