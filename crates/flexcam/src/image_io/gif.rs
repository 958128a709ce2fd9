//! Animated GIFs.

use std::fs;
use std::io::BufWriter;
use std::path::Path;

use super::{rgb_bytes, ColorEncoding};
use crate::error::{Error, Result};
use crate::render::Frame;

/// The frames of an animated GIF, added one at a time so that only their 8-bit colours are
/// kept, not whole [`Frame`]s.
#[derive(Debug, Default)]
pub struct GifFrames {
    frames: Vec<image::RgbaImage>,
}

impl GifFrames {
    /// Appends the colour of `frame`.
    pub fn push(&mut self, frame: &Frame, encoding: ColorEncoding) -> Result<()> {
        let rgba = crate::try_alloc::collected(
            4 * frame.color.len(),
            (rgb_bytes(frame, encoding)?.chunks_exact(3))
                .flat_map(|rgb| [rgb[0], rgb[1], rgb[2], 255]),
            || super::samples_of("8-bit RGBA bytes", frame),
        )?;
        let image = image::RgbaImage::from_raw(frame.width, frame.height, rgba)
            .ok_or_else(|| Error::new("colour buffer does not match the image size"))?;
        self.frames.push(image);
        Ok(())
    }

    /// Writes the frames at `path` as an animated GIF that loops forever, each frame shown
    /// for 1 / `fps` seconds (GIF stores delays in hundredths of a second: rounded, at least
    /// 1/100 s).
    pub fn write(self, path: &Path, fps: f64) -> Result<()> {
        use image::codecs::gif::{GifEncoder, Repeat};
        let hundredths = (100.0 / fps).round().max(1.0) as u32;
        let delay = image::Delay::from_numer_denom_ms(10 * hundredths, 1);
        let file = fs::File::create(path).map_err(|e| Error::new(format!("cannot write: {e}")))?;
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
    }
}
