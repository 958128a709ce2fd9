//! The environment-map baseline of reflector compositing (Hou, Wei, Shum and Guo 2006,
//! Figure 1; scene key `reflection = "env-map"`): the scene without the reflector is rendered
//! once into a cube map from the reflector's centre, and every pixel of the reflector looks
//! the cube map up along its reflected (refracted) direction, the direction of the
//! reflector surface's ray at that pixel (the same rays camera triangles follow).
//!
//! The lookup ignores where the ray starts: it is exact for content infinitely far away and
//! wrong by the parallax between the ray's origin and the cube map's centre for nearby
//! content, which is what camera triangles get right (the paper's Figure 1).

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::perspective_as_trilinear;
use crate::error::Result;
use crate::projection::{CameraFrame, Perspective, Projection, SingleImage, Trilinear};
use crate::render::prepared::PreparedScene;
use crate::render::{Frame, Method, RenderOptions, Stats};
use crate::scene::Mesh;

/// The six faces of a cube map: the pinholes (90 degrees, square) and their images.
struct CubeMap {
    faces: Vec<(Perspective, Frame)>,
    centre: DVec3,
}

/// The axis each face looks along, with its up direction.
const FACES: [(DVec3, DVec3); 6] = [
    (DVec3::X, DVec3::Y),
    (DVec3::NEG_X, DVec3::Y),
    (DVec3::Y, DVec3::Z),
    (DVec3::NEG_Y, DVec3::Z),
    (DVec3::Z, DVec3::Y),
    (DVec3::NEG_Z, DVec3::Y),
];

impl CubeMap {
    /// `others` rendered from `centre` into six `size` x `size` faces by `options.method`; the
    /// trilinear methods render each face as the same pinhole in two projection triangles
    /// ([`perspective_as_trilinear`]) by the trilinear method, as they render the main view
    /// (camera triangles would bound a pinhole only loosely).
    fn render(
        others: &PreparedScene,
        centre: DVec3,
        size: u32,
        options: &RenderOptions,
    ) -> Result<CubeMap> {
        let mut faces = Vec::with_capacity(6);
        for (axis, up) in FACES {
            let frame = CameraFrame {
                position: centre,
                look_at: centre + axis,
                up,
            };
            let face = Perspective::new(&frame, 90.0, size, size)?;
            let image = match options.method {
                Method::Trilinear | Method::CameraTriangles => {
                    let pinhole = perspective_as_trilinear(&face)?;
                    Method::Trilinear.render(others, &pinhole, options)?.0
                }
                method => method.render(others, &face, options)?.0,
            };
            faces.push((face, image));
        }
        Ok(CubeMap { faces, centre })
    }

    /// The colour the cube map holds along `direction` (nearest texel of the face whose
    /// axis is the direction's largest component). Degenerate case: a zero direction takes
    /// the first face's centre.
    fn lookup(&self, direction: DVec3) -> Vec3 {
        let a = direction.abs();
        let face = if a.x >= a.y && a.x >= a.z {
            usize::from(direction.x < 0.0)
        } else if a.y >= a.z {
            2 + usize::from(direction.y < 0.0)
        } else {
            4 + usize::from(direction.z < 0.0)
        };
        let (camera, image) = &self.faces[face];
        let pixel = camera
            .branch_image(self.centre + direction)
            .map_or(DVec2::splat(f64::from(image.width) / 2.0), |b| {
                b.image.pixel
            });
        let x = (pixel.x.floor().max(0.0) as u32).min(image.width - 1);
        let y = (pixel.y.floor().max(0.0) as u32).min(image.height - 1);
        image.color[(y * image.width + x) as usize]
    }
}

/// The image of `others` through `surface` (main-image pixels) by environment mapping: a
/// cube map of faces as large as the main image's larger side, rendered from the centre of
/// `reflector`'s bounding box ([`CubeMap::render`]), looked up along the surface's ray direction at each pixel
/// centre; pixels without a ray get the background. No counters: the faces' renders are not
/// the reflector's (`reflector_render_ms` times them).
pub fn image(
    others: &PreparedScene,
    surface: &Trilinear,
    reflector: &Mesh,
    options: &RenderOptions,
) -> Result<(Frame, Stats)> {
    let (width, height) = surface.resolution();
    let (lo, hi) = reflector.bounds().unwrap_or_default();
    let centre = ((lo + hi) / 2.0).as_dvec3();
    let cube = CubeMap::render(others, centre, width.max(height), options)?;
    let background = others.scene().image.background;
    let mut frame = Frame::try_new(width, height, background)?;
    frame
        .color
        .par_iter_mut()
        .enumerate()
        .for_each(|(k, color)| {
            let pixel = DVec2::new(
                (k % width as usize) as f64 + 0.5,
                (k / width as usize) as f64 + 0.5,
            );
            if let Some(ray) = surface.ray(pixel) {
                *color = cube.lookup(ray.direction);
            }
        });
    Ok((frame, Stats::new()))
}

#[cfg(test)]
pub(crate) mod tests;
