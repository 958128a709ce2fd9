//! Linear float images: OpenEXR (one layer of named channels, 32-bit float or unsigned int,
//! lossless compression) and PFM (`Pf` grayscale or `PF` RGB, little-endian, rows bottom to
//! top as PFM requires). Samples are given row by row from the top, as frames hold them.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::{Error, Result};
use crate::render::Frame;

/// The samples of one EXR channel, one per pixel, row by row from the top.
pub enum ExrSamples {
    F32(Vec<f32>),
    U32(Vec<u32>),
}

/// Writes one EXR layer named `layer` of `(width, height)` pixels holding `channels` (name,
/// samples). Readers list the channels sorted by name, as the format stores them.
pub fn write_exr(
    (width, height): (u32, u32),
    path: &Path,
    layer: &str,
    channels: Vec<(&str, ExrSamples)>,
) -> Result<()> {
    use exr::prelude::*;
    let channels: Vec<AnyChannel<FlatSamples>> = channels
        .into_iter()
        .map(|(name, samples)| {
            let samples = match samples {
                ExrSamples::F32(v) => FlatSamples::F32(v),
                ExrSamples::U32(v) => FlatSamples::U32(v),
            };
            AnyChannel::new(name, samples)
        })
        .collect();
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named(layer),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| crate::error::Error::new(format!("cannot write OpenEXR: {e}")))
}

/// The red, green and blue channels of the linear colour of `frame`, for [`write_exr`]
/// (allocated fallibly).
pub fn rgb_channels(frame: &Frame) -> Result<Vec<(&'static str, ExrSamples)>> {
    vector_channels(["R", "G", "B"], &frame.color, |c| c.to_array())
}

/// One EXR channel of `value` at each of `pixels`, allocated fallibly.
pub fn scalar_channel<T>(pixels: &[T], value: impl Fn(&T) -> f32) -> Result<ExrSamples> {
    let samples = crate::try_alloc::collected(pixels.len(), pixels.iter().map(value), || {
        format!("an OpenEXR channel of {} samples", pixels.len())
    })?;
    Ok(ExrSamples::F32(samples))
}

/// The channels `LAYER.X`, `LAYER.Y`, `LAYER.Z` (names given in `names`) of one vector a
/// pixel, for [`write_exr`] (allocated fallibly).
pub fn vector_channels<T>(
    names: [&'static str; 3],
    pixels: &[T],
    vector: impl Fn(&T) -> [f32; 3],
) -> Result<Vec<(&'static str, ExrSamples)>> {
    (0..3)
        .map(|k| Ok((names[k], scalar_channel(pixels, |p| vector(p)[k])?)))
        .collect()
}

/// Writes a PFM of the size of `frame` at `path`: `samples` holds `channels` (1 or 3)
/// interleaved values a pixel, row by row from the top.
pub fn write_pfm(frame: &Frame, path: &Path, channels: usize, samples: &[f32]) -> Result<()> {
    let io = |e: std::io::Error| Error::new(format!("cannot write PFM: {e}"));
    let tag = if channels == 3 { "PF" } else { "Pf" };
    let mut out = BufWriter::new(fs::File::create(path).map_err(io)?);
    write!(out, "{tag}\n{} {}\n-1.0\n", frame.width, frame.height).map_err(io)?;
    for row in samples.chunks(frame.width as usize * channels).rev() {
        for v in row {
            out.write_all(&v.to_le_bytes()).map_err(io)?;
        }
    }
    out.flush().map_err(io)
}
