//! What a scene says about an object's displacement: the height source (a grey map read at
//! load time, or a procedural function's parameters), scale, level and fraction, validated.
//!
//! This is the description only; [`crate::displace`] builds the height field with its bounds
//! from it and traces the displaced micro-geometry. Everything a user can get wrong is
//! checked here, when the scene loads, so that preparing and rendering a loaded scene cannot
//! fail on it.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::file_read::{read_regular, MAX_DATA_FILE_BYTES};

/// Deepest subdivision level accepted (`4^16` micro-triangles per base triangle).
pub const MAX_LEVEL: u32 = 16;

/// An object's displacement: heights `h(u, v)` in [0, 1], scale `S` (world units), level `L`
/// and fraction `F`; every micro-vertex moves to `P + N * S * (h(uv) - h_max) * F`.
#[derive(Debug, Clone, PartialEq)]
pub struct DisplacementSpec {
    /// The height field h(u, v), values in [0, 1].
    pub height: HeightSource,
    /// S: the displacement of height 1, world units.
    pub scale: f64,
    /// L: each base triangle is split into 4^L micro-triangles.
    pub level: u32,
    /// F: how much of the displacement is applied, in [0, 1].
    pub fraction: f64,
}

impl DisplacementSpec {
    /// Errors: a scale that is negative or not finite, a fraction outside [0, 1], a level
    /// above [`MAX_LEVEL`].
    pub fn new(height: HeightSource, scale: f64, level: u32, fraction: f64) -> Result<Self> {
        check_parameters(scale, level, fraction)?;
        Ok(DisplacementSpec {
            height,
            scale,
            level,
            fraction,
        })
    }
}

/// The checks of [`DisplacementSpec::new`], alone.
pub fn check_parameters(scale: f64, level: u32, fraction: f64) -> Result<()> {
    if !(scale >= 0.0 && scale.is_finite()) {
        return Err(Error::new(format!(
            "displacement scale must be a finite number at least 0, not {scale}"
        )));
    }
    if !(0.0..=1.0).contains(&fraction) {
        return Err(Error::new(format!(
            "displacement fraction must be in [0, 1], not {fraction}"
        )));
    }
    if level > MAX_LEVEL {
        return Err(Error::new(format!(
            "displacement level must be at most {MAX_LEVEL}, not {level}"
        )));
    }
    Ok(())
}

/// Where heights come from.
#[derive(Debug, Clone, PartialEq)]
pub enum HeightSource {
    /// A grey image sampled at the mesh's texture coordinates.
    Map(HeightImage),
    /// A height function evaluated in closed form.
    Procedural(ProceduralSpec),
}

/// A grey height image: `width * height` values in [0, 1], row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightImage {
    /// Width in height samples.
    pub width: u32,
    /// Height in height samples (rows).
    pub height: u32,
    /// The heights, in [0, 1].
    pub values: Vec<f32>,
    /// The file it was read from (none for images made in code).
    pub path: Option<PathBuf>,
}

impl HeightImage {
    /// Reads an 8- or 16-bit grey PNG: h is the grey value over 255 or 65535, linear (no sRGB
    /// decoding). Errors (one line, naming the file): unreadable, not a PNG, not grey (RGB,
    /// with alpha, ...), empty.
    pub fn load(path: &Path) -> Result<HeightImage> {
        let bytes = read_regular(path, "file", MAX_DATA_FILE_BYTES)?;
        let not_grey = |what: &str| {
            Error::in_file(
                path,
                format!("a height map must be an 8- or 16-bit grey PNG, this is {what}"),
            )
        };
        match image::guess_format(&bytes) {
            Ok(image::ImageFormat::Png) => {}
            Ok(format) => return Err(not_grey(&format!("{format:?}"))),
            Err(_) => return Err(not_grey("not an image")),
        }
        let image = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .map_err(|e| Error::in_file(path, format!("cannot decode PNG: {e}")))?;
        let (width, height) = (image.width(), image.height());
        let values = match &image {
            image::DynamicImage::ImageLuma8(grey) => {
                grey.as_raw().iter().map(|&g| g as f32 / 255.0).collect()
            }
            image::DynamicImage::ImageLuma16(grey) => {
                grey.as_raw().iter().map(|&g| g as f32 / 65535.0).collect()
            }
            other => return Err(not_grey(&format!("{:?}", other.color()))),
        };
        let mut image = HeightImage::new(width, height, values).map_err(|e| e.or_in_file(path))?;
        image.path = Some(path.to_path_buf());
        Ok(image)
    }

    /// An image from `width * height` heights, top row first. Errors: an empty image, a
    /// wrong count, a value outside [0, 1] (NaN included).
    pub fn new(width: u32, height: u32, values: Vec<f32>) -> Result<HeightImage> {
        if width == 0 || height == 0 {
            return Err(Error::new(format!(
                "height map is empty ({width} x {height} pixels)"
            )));
        }
        if values.len() != width as usize * height as usize {
            return Err(Error::new(format!(
                "height map has {} values, expected {width} x {height}",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|h| !(0.0..=1.0).contains(h)) {
            return Err(Error::new(format!(
                "height {} at pixel ({}, {}) is outside [0, 1]",
                values[i],
                i % width as usize,
                i / width as usize
            )));
        }
        Ok(HeightImage {
            width,
            height,
            values,
            path: None,
        })
    }
}

/// One term of [`ProceduralSpec::Waves`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wave {
    /// The wave's height amplitude.
    pub amplitude: f64,
    /// Whole periods (m, n) over the unit square in u and v.
    pub frequency: [i32; 2],
    /// Phase offset, radians.
    pub phase: f64,
}

/// Largest frequency magnitude a wave may have: far beyond any visible detail, small enough
/// that `2 pi (m u + n v)` keeps its precision over the uv ranges meshes use.
pub const MAX_FREQUENCY: i32 = 1 << 16;

/// Parameters of a procedural height function (see [`crate::displace::Procedural`] for the
/// functions), validated by the constructors.
#[derive(Debug, Clone, PartialEq)]
pub enum ProceduralSpec {
    /// A sum of sine waves over (u, v).
    Waves(Vec<Wave>),
    /// Round bumps on a grid of cells.
    Bumps {
        /// Cells (nu, nv) over the unit square, one round bump in each.
        cells: [u32; 2],
        /// The bump's radius in cell units, in (0, 1/2].
        radius: f64,
    },
}

impl ProceduralSpec {
    /// A sum of waves. Errors: no wave, an amplitude that is not positive and finite, a
    /// frequency above [`MAX_FREQUENCY`] in magnitude, a phase that is not finite.
    pub fn waves(waves: Vec<Wave>) -> Result<ProceduralSpec> {
        if waves.is_empty() {
            return Err(Error::new("waves: at least one wave is needed"));
        }
        for w in &waves {
            if !(w.amplitude > 0.0 && w.amplitude.is_finite()) {
                return Err(Error::new(format!(
                    "waves: amplitude {} must be positive and finite",
                    w.amplitude
                )));
            }
            if w.frequency
                .iter()
                .any(|f| f.unsigned_abs() > MAX_FREQUENCY as u32)
            {
                return Err(Error::new(format!(
                    "waves: frequencies must be integers in [-{MAX_FREQUENCY}, {MAX_FREQUENCY}], not {:?}",
                    w.frequency
                )));
            }
            if !w.phase.is_finite() {
                return Err(Error::new("waves: phase must be finite"));
            }
        }
        Ok(ProceduralSpec::Waves(waves))
    }

    /// A grid of round bumps. Errors: a cell count outside 1..=65536, a radius outside
    /// (0, 1/2].
    pub fn bumps(cells: [u32; 2], radius: f64) -> Result<ProceduralSpec> {
        if cells.iter().any(|&n| !(1..=1 << 16).contains(&n)) {
            return Err(Error::new(format!(
                "bumps: cell counts must be in 1..=65536, not {cells:?}"
            )));
        }
        if !(radius > 0.0 && radius <= 0.5) {
            return Err(Error::new(format!(
                "bumps: radius {radius} must be in (0, 0.5] (cell units)"
            )));
        }
        Ok(ProceduralSpec::Bumps { cells, radius })
    }
}
