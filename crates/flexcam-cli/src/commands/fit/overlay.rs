//! `flexcam fit --overlay`: the fitted scene rendered at the painting's size, blended half and
//! half with the painting (or alone, without one), and every correspondence marked: a ring
//! where it was given (its entry number beside it), a square where the fitted projection
//! images its scene point (`flexcam::projection::nearest_image`), a line between them, all
//! coloured by the distance between the two in pixels (the residual in the painting): green
//! at 0, yellow at [`YELLOW_PX`], red from [`RED_PX`]. A point the fit does not image
//! within half a pixel (its projectors pass it by) gets a magenta cross on its ring and no
//! residual.

use std::path::Path;

use flexcam::image_io::LinearImage;
use flexcam::projection::nearest_image::nearest_image;
use flexcam::projection::{Flexible, ProjectionSpec, Resolution};
use flexcam::render::{self, Outputs, PreparedScene, RenderOptions};
use flexcam::scene::file::{self, FittedScene};
use flexcam::{Error, Result};
use glam::Vec3;

use super::marks;

/// The residual, in pixels, drawn yellow (half way from green to red).
pub const YELLOW_PX: f64 = 2.0;
/// The residual, in pixels, from which marks are red.
pub const RED_PX: f64 = 4.0;
/// The radius of the ring at a given position, in pixels.
const RING_PX: f64 = 4.0;
/// The largest miss, in pixels at the found position, of a point counted as imaged.
const IMAGED_PX: f64 = 0.5;
/// The colour of the cross on a point the fit does not image (linear RGB).
const NOT_IMAGED: Vec3 = Vec3::new(0.9, 0.05, 0.9);

/// The overlay image and each correspondence's residual in pixels (`None`: not imaged).
pub struct Overlay {
    /// The picture, linear colours, at the painting's size.
    pub frame: render::Frame,
    /// Per correspondence, in the order of the `fit` entries.
    pub residuals: Vec<Option<f64>>,
}

/// Draws the overlay of `fitted` (whose text is loaded as if at `scene_path`, so that its
/// relative paths resolve) over `painting`; without a painting over the render alone, at
/// `painting_size` or else the scene's image size.
pub fn draw(
    fitted: &FittedScene,
    scene_path: &Path,
    painting: Option<&LinearImage>,
) -> Result<Overlay> {
    let scene = file::parse(&fitted.text, scene_path)?;
    let [width, height] = match (painting, fitted.painting_size) {
        (Some(p), _) => [p.width, p.height],
        (None, Some(size)) => size,
        (None, None) => [scene.image.width, scene.image.height],
    };
    let ProjectionSpec::Flexible(spec) = &scene.projection else {
        return Err(Error::in_file(
            scene_path,
            "the fitted scene lost its projection",
        ));
    };
    let projection = Flexible::new(spec, width, height)?;
    let options = RenderOptions {
        outputs: Outputs::COLOR,
        ..RenderOptions::default()
    };
    let prepared = PreparedScene::new(&scene);
    let mut frame = render::render(&prepared, &projection, &options)?.frame;
    if let Some(painting) = painting {
        for (pixel, under) in frame.color.iter_mut().zip(&painting.pixels) {
            *pixel = 0.5 * (*pixel + *under);
        }
    }
    let resolution = Resolution::new(width, height)?;
    let mut residuals = Vec::new();
    for (index, c) in fitted.correspondences.iter().enumerate() {
        // (u, v) in [0, 1]^2 always has a position (the scene's conversion checked it).
        let Some(given) = projection.reparam().to_pixel(&resolution, c.uv) else {
            residuals.push(None);
            continue;
        };
        let image = nearest_image(&projection, c.point).filter(|i| i.miss_pixels <= IMAGED_PX);
        let residual = image.map(|i| (i.pixel - given).length());
        match (image, residual) {
            (Some(i), Some(r)) => {
                let color = ramp(r);
                marks::line(&mut frame, given, i.pixel, color);
                marks::ring(&mut frame, given, RING_PX, color);
                marks::square(&mut frame, i.pixel, 1, color);
                marks::number(
                    &mut frame,
                    given + glam::DVec2::new(6.0, -9.0),
                    index + 1,
                    color,
                );
            }
            _ => {
                marks::ring(&mut frame, given, RING_PX, NOT_IMAGED);
                marks::cross(&mut frame, given, RING_PX - 1.0, NOT_IMAGED);
                marks::number(
                    &mut frame,
                    given + glam::DVec2::new(6.0, -9.0),
                    index + 1,
                    NOT_IMAGED,
                );
            }
        }
        residuals.push(residual);
    }
    Ok(Overlay { frame, residuals })
}

/// Green at 0 px, yellow at [`YELLOW_PX`], red from [`RED_PX`] (linear RGB).
fn ramp(residual_px: f64) -> Vec3 {
    let (green, yellow, red) = (
        Vec3::new(0.05, 0.85, 0.05),
        Vec3::new(0.95, 0.85, 0.0),
        Vec3::new(0.95, 0.02, 0.02),
    );
    if residual_px <= YELLOW_PX {
        green.lerp(yellow, (residual_px / YELLOW_PX) as f32)
    } else {
        let t = ((residual_px - YELLOW_PX) / (RED_PX - YELLOW_PX)).min(1.0);
        yellow.lerp(red, t as f32)
    }
}

/// One line on the residuals: the largest (with its entry, from 1), the RMS, and the entries
/// not imaged.
pub fn summary(residuals: &[Option<f64>]) -> String {
    let imaged: Vec<(usize, f64)> = residuals
        .iter()
        .enumerate()
        .filter_map(|(k, r)| Some((k + 1, (*r)?)))
        .collect();
    let missing: Vec<String> = residuals
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_none())
        .map(|(k, _)| (k + 1).to_string())
        .collect();
    let mut text = match imaged.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
        Some(&(entry, max)) => {
            let rms = (imaged.iter().map(|(_, r)| r * r).sum::<f64>() / imaged.len() as f64).sqrt();
            format!(
                "residual in the image max {max:.2} px (entry {entry}), rms {rms:.2} px over {} \
                 correspondences",
                imaged.len()
            )
        }
        None => "no correspondence imaged".to_string(),
    };
    if !missing.is_empty() {
        text += &format!("; not imaged by the fit: entries {}", missing.join(", "));
    }
    text
}
