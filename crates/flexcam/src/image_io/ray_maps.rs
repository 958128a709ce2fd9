//! OpenEXR files of per-pixel rays and STMaps (`flexcam raymap`), 32-bit float channels,
//! row by row from the top like every flexcam image.
//!
//! The ray map (layer `rays`): `origin.X`, `origin.Y`, `origin.Z` and `direction.X`,
//! `direction.Y`, `direction.Z` (unit) of each pixel's projector, world space; for a
//! projection with curved projectors also `exit_origin.*` and `exit_direction.*` (where and
//! along which unit direction the projector ends, see
//! [`crate::projection::ray_map::PixelRay`]); `A` = 1 where the pixel has a ray, 0 where it
//! has none (every other channel 0 there).
//!
//! The STMap (layer `stmap`): `R` = s and `G` = t in the reference image (Nuke's
//! convention, [`crate::render::StMap`]), `B` = 0, and `A` = 1 where the reference camera
//! sees the pixel's scene point, 0 where it does not (s = t = 0 there). As a PNG: the same
//! channels as 16-bit RGBA, round(65535 s) and round(65535 t), alpha 65535 or 0 (steps of
//! 1/65535: 0.06 pixels of a 4K reference; the EXR keeps f32).

use std::path::Path;

use glam::DVec3;

use super::extension;
use super::float::{scalar_channel, vector_channels, write_exr, ExrSamples};
use crate::error::{Error, Result};
use crate::projection::ray_map::{PixelRay, RayMap};
use crate::render::StMap;

/// Writes `map` as the ray map file at `path`.
pub fn write_ray_map_exr(map: &RayMap, path: &Path) -> Result<()> {
    let vector = |get: fn(&PixelRay) -> DVec3| {
        move |ray: &Option<PixelRay>| ray.map_or([0.0; 3], |r| get(&r).as_vec3().to_array())
    };
    let rays = &map.rays;
    let mut channels = vector_channels(
        ["origin.X", "origin.Y", "origin.Z"],
        rays,
        vector(|r| r.origin),
    )?;
    channels.extend(vector_channels(
        ["direction.X", "direction.Y", "direction.Z"],
        rays,
        vector(|r| r.direction),
    )?);
    if map.curved {
        channels.extend(vector_channels(
            ["exit_origin.X", "exit_origin.Y", "exit_origin.Z"],
            rays,
            vector(|r| r.exit_origin),
        )?);
        channels.extend(vector_channels(
            ["exit_direction.X", "exit_direction.Y", "exit_direction.Z"],
            rays,
            vector(|r| r.exit_direction),
        )?);
    }
    channels.push(("A", alpha(rays)?));
    write_exr((map.width, map.height), path, "rays", channels)
}

/// The file formats of an STMap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StMapFormat {
    /// OpenEXR, 32-bit float.
    Exr,
    /// PNG, 16-bit RGBA.
    Png,
}

impl StMapFormat {
    /// The extensions of the STMap formats.
    pub const EXTENSIONS: [&'static str; 2] = ["exr", "png"];

    /// The format named by the extension of `path`. Errors: any other extension.
    pub fn of(path: &Path) -> Result<StMapFormat> {
        match extension(path).as_str() {
            "exr" => Ok(StMapFormat::Exr),
            "png" => Ok(StMapFormat::Png),
            other => Err(Error::in_file(
                path,
                format!("unsupported STMap extension \"{other}\" (expected .exr or .png)"),
            )),
        }
    }
}

/// Writes `map` as the STMap file at `path` in `format`.
pub fn write_stmap(map: &StMap, path: &Path, format: StMapFormat) -> Result<()> {
    match format {
        StMapFormat::Exr => write_stmap_exr(map, path),
        StMapFormat::Png => write_stmap_png(map, path),
    }
}

/// Writes `map` as a 16-bit RGBA PNG at `path`.
fn write_stmap_png(map: &StMap, path: &Path) -> Result<()> {
    let code = |v: f64| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
    let samples = crate::try_alloc::collected(
        4 * map.st.len(),
        (map.st.iter()).flat_map(|st| match st {
            Some(st) => [code(st.x), code(st.y), 0, u16::MAX],
            None => [0; 4],
        }),
        || {
            format!(
                "the 16-bit samples of the {} x {} STMap",
                map.width, map.height
            )
        },
    )?;
    image::ImageBuffer::<image::Rgba<u16>, Vec<u16>>::from_raw(map.width, map.height, samples)
        .ok_or_else(|| Error::new("STMap does not match its image size"))?
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| Error::new(format!("cannot write PNG: {e}")))
}

/// Writes `map` as the STMap OpenEXR at `path`.
fn write_stmap_exr(map: &StMap, path: &Path) -> Result<()> {
    let st = &map.st;
    let channel = |k: usize| scalar_channel(st, |st| st.map_or(0.0, |st| st[k] as f32));
    let channels = vec![
        ("R", channel(0)?),
        ("G", channel(1)?),
        ("B", scalar_channel(st, |_| 0.0)?),
        ("A", alpha(st)?),
    ];
    write_exr((map.width, map.height), path, "stmap", channels)
}

/// 1 where a pixel has a value, 0 where it has none.
fn alpha<T>(values: &[Option<T>]) -> Result<ExrSamples> {
    scalar_channel(values, |v| if v.is_some() { 1.0 } else { 0.0 })
}
