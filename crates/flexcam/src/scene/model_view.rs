//! The view and light of a model file given where a scene is expected: a camera that frames
//! the model, or one of the model's own glTF cameras.
//!
//! The framing rule: a perspective camera of horizontal field [`FRAME_FOV`] looks at the
//! centre of the model's bounding box (over the vertices of its triangles) from the
//! direction of azimuth [`FRAME_AZIMUTH`] and elevation [`FRAME_ELEVATION`] (a three-quarter
//! view from above), +y up, at the distance where the box's bounding sphere would just touch
//! the image's nearer edges, times [`FRAME_MARGIN`]. The light is one white directional
//! light of intensity 1 arriving from behind the camera, above and to its left
//! ([`key_light`]); there is no floor.

use glam::DVec3;

use crate::error::{Error, Result};
use crate::projection::CameraFrame;
use crate::scene::loaders::{CameraLens, ModelCamera};
use crate::scene::Mesh;

/// The horizontal field of view of the framing camera, degrees.
pub const FRAME_FOV: f64 = 50.0;

/// The azimuth of the framing camera seen from the model's centre, degrees about +y from
/// +z towards +x.
pub const FRAME_AZIMUTH: f64 = 45.0;

/// The elevation of the framing camera seen from the model's centre, degrees above the
/// horizontal.
pub const FRAME_ELEVATION: f64 = 30.0;

/// How much farther than touching the framing camera stands: the bounding sphere fills
/// 1 / `FRAME_MARGIN` of the half-field of the image's narrower side (in sine).
pub const FRAME_MARGIN: f64 = 1.1;

/// What a model's view projects, with the values a scene file's `[projection]` takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lens {
    /// `type = "perspective"`: `fov` the horizontal field of view, degrees.
    Perspective {
        /// Horizontal field of view, degrees.
        fov: f64,
    },
    /// `type = "orthographic"`: `width` the horizontal extent, world units.
    Orthographic {
        /// Horizontal extent, world units.
        width: f64,
    },
}

/// A camera for a model: where it stands and what it projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Where the camera stands and looks.
    pub frame: CameraFrame,
    /// What it projects.
    pub lens: Lens,
}

/// The axis-aligned bounding box (low and high corners) of the vertices of the triangles of
/// `meshes`; `None` when they have no triangles. Vertices no triangle uses are left out:
/// they are not drawn.
pub fn triangle_bounds<'m>(meshes: impl IntoIterator<Item = &'m Mesh>) -> Option<[DVec3; 2]> {
    let mut bounds: Option<[DVec3; 2]> = None;
    for mesh in meshes {
        for &k in mesh.triangles.iter().flatten() {
            let p = mesh.positions[k as usize].as_dvec3();
            bounds = Some(match bounds {
                None => [p, p],
                Some([lo, hi]) => [lo.min(p), hi.max(p)],
            });
        }
    }
    bounds
}

/// The framing camera of a model whose triangles span `bounds`, for an image of aspect
/// ratio `aspect` (width over height, positive). Degenerate case: a box of no extent
/// (every triangle at one point) has nothing to frame, an error.
pub fn framing(bounds: [DVec3; 2], aspect: f64) -> Result<View> {
    let [lo, hi] = bounds;
    let centre = (lo + hi) / 2.0;
    let radius = (hi - lo).length() / 2.0;
    if radius <= 0.0 {
        return Err(Error::new(
            "every triangle lies at one point: there is nothing to frame",
        ));
    }
    let half_width = (FRAME_FOV / 2.0).to_radians();
    let half_height = (half_width.tan() / aspect).atan();
    let distance = FRAME_MARGIN * radius / half_width.min(half_height).sin();
    let (azimuth, elevation) = (FRAME_AZIMUTH.to_radians(), FRAME_ELEVATION.to_radians());
    let towards_eye = DVec3::new(
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
        elevation.cos() * azimuth.cos(),
    );
    Ok(View {
        frame: CameraFrame {
            position: centre + distance * towards_eye,
            look_at: centre,
            up: DVec3::Y,
        },
        lens: Lens::Perspective { fov: FRAME_FOV },
    })
}

/// The view of the glTF camera `camera` for a `width` x `height` image, `centre` the model's
/// centre. A perspective camera keeps its vertical field `yfov`: the horizontal field is
/// 2 atan(a tan(yfov / 2)), a its `aspectRatio` or else the image's; an orthographic one
/// is `2 xmag` wide. `look_at` is the point ahead at the distance of `centre` (1 unit when
/// the eye is at the centre).
///
/// Errors: a lens that makes no image ([`ModelCamera::check`]), and an image whose aspect
/// ratio is not the one the camera fixes (`aspectRatio`, or `xmag / ymag`) to the nearest
/// pixel: the camera would be stretched.
pub fn camera_view(camera: &ModelCamera, width: u32, height: u32, centre: DVec3) -> Result<View> {
    camera.check()?;
    let image_aspect = f64::from(width) / f64::from(height);
    if let Some(aspect) = camera.fixed_aspect() {
        let nearest = |x: f64| x.round().max(1.0);
        let fits = nearest(f64::from(width) / aspect) == f64::from(height)
            || nearest(f64::from(height) * aspect) == f64::from(width);
        if !fits {
            let what = match camera.lens {
                CameraLens::Perspective { .. } => "aspectRatio",
                CameraLens::Orthographic { .. } => "xmag / ymag",
            };
            return Err(Error::new(format!(
                "{} has {what} {aspect}, the image {width} x {height} another: give --width \
                 or --height alone (the other follows the camera), or both in that ratio",
                camera.label()
            )));
        }
    }
    let lens = match camera.lens {
        CameraLens::Perspective { yfov, aspect_ratio } => {
            let aspect = aspect_ratio.unwrap_or(image_aspect);
            Lens::Perspective {
                fov: (2.0 * (aspect * (yfov / 2.0).tan()).atan()).to_degrees(),
            }
        }
        CameraLens::Orthographic { xmag, .. } => Lens::Orthographic { width: 2.0 * xmag },
    };
    let ahead = match camera.position.distance(centre) {
        d if d > 0.0 => d,
        _ => 1.0,
    };
    Ok(View {
        frame: CameraFrame {
            position: camera.position,
            look_at: camera.position + ahead * camera.forward,
            up: camera.up,
        },
        lens,
    })
}

/// The direction (unit, the way the light travels) of the light of a model's view: from
/// behind the camera, above and to its left, along back + up - right / 2 in the camera's
/// own axes (back from `look_at` to the eye, up orthogonalised against it).
pub fn key_light(frame: &CameraFrame) -> DVec3 {
    let back = (frame.position - frame.look_at).normalize();
    let right = frame.up.cross(back).normalize();
    let up = back.cross(right);
    -(back + up - right / 2.0).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A pinhole written independently of the projection module: the pixel position (x
    /// right, y down, pixel centres at +0.5) of `point` seen by `view` (perspective).
    fn pinhole(view: &View, width: f64, height: f64, point: DVec3) -> (f64, f64) {
        let Lens::Perspective { fov } = view.lens else {
            panic!("not perspective")
        };
        let f = view.frame;
        let forward = (f.look_at - f.position).normalize();
        let right = forward.cross(f.up).normalize();
        let up = right.cross(forward);
        let d = point - f.position;
        let scale = (width / 2.0) / (fov.to_radians() / 2.0).tan();
        let (x, y, z) = (d.dot(right), d.dot(up), d.dot(forward));
        (width / 2.0 + scale * x / z, height / 2.0 - scale * y / z)
    }

    /// The distance rule: the bounding sphere's silhouette touches the narrower image side
    /// with the margin, and the view looks at the box's centre from the stated direction.
    #[test]
    fn the_bounding_sphere_fills_the_narrower_side_with_the_margin() {
        let bounds = [DVec3::new(-1.0, 0.0, 2.0), DVec3::new(3.0, 2.0, 6.0)];
        let radius = (bounds[1] - bounds[0]).length() / 2.0;
        for aspect in [4.0 / 3.0, 0.5, 3.0] {
            let view = framing(bounds, aspect).unwrap();
            assert_eq!(view.frame.look_at, DVec3::new(1.0, 1.0, 4.0));
            let eye = view.frame.position - view.frame.look_at;
            let (half_w, half_h) = (
                25f64.to_radians(),
                (25f64.to_radians().tan() / aspect).atan(),
            );
            let expected = 1.1 * radius / half_w.min(half_h).sin();
            assert!(
                (eye.length() - expected).abs() < 1e-12 * expected,
                "{aspect}"
            );
            // 45 degrees round y from +z to +x, 30 degrees up.
            let unit = eye / eye.length();
            assert!((unit.x - unit.z).abs() < 1e-12 && unit.x > 0.0);
            assert!((unit.y - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn a_box_of_no_extent_is_refused() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        let e = framing([p, p], 1.0).unwrap_err().to_string();
        assert!(e.contains("nothing to frame"), "{e}");
    }

    #[test]
    fn bounds_count_only_vertices_of_triangles() {
        let mesh = Mesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::splat(100.0)]
                .into_iter()
                .map(|p| p.as_vec3())
                .collect(),
            triangles: vec![[0, 1, 2]],
            ..Mesh::default()
        };
        assert_eq!(
            triangle_bounds([&mesh]),
            Some([DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0)])
        );
        assert_eq!(triangle_bounds([&Mesh::default()]), None);
    }

    fn camera(lens: CameraLens) -> ModelCamera {
        ModelCamera {
            index: 0,
            name: Some("Cam".into()),
            node: 0,
            node_name: None,
            lens,
            position: DVec3::new(0.0, 0.0, 5.0),
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }

    /// yfov is the full vertical angle: a point at the top edge of that angle lands on the
    /// image's top edge, whatever aspect ratio fixes the horizontal.
    #[test]
    fn yfov_is_the_vertical_field_and_the_aspect_ratio_the_horizontal() {
        let yfov = 0.8f64;
        for (aspect_ratio, (w, h)) in [(Some(1.5), (600, 400)), (None, (300, 500))] {
            let view = camera_view(
                &camera(CameraLens::Perspective { yfov, aspect_ratio }),
                w,
                h,
                DVec3::ZERO,
            )
            .unwrap();
            assert_eq!(view.frame.look_at, DVec3::ZERO);
            let (w, h) = (f64::from(w), f64::from(h));
            let top = DVec3::new(0.0, 5.0 * (yfov / 2.0).tan(), 0.0);
            let (x, y) = pinhole(&view, w, h, top);
            assert!((x - w / 2.0).abs() < 1e-9 && y.abs() < 1e-9, "{x} {y}");
            let right = DVec3::new(5.0 * (yfov / 2.0).tan() * w / h, 0.0, 0.0);
            let (x, _) = pinhole(&view, w, h, right);
            assert!((x - w).abs() < 1e-9, "{x}");
        }
    }

    #[test]
    fn xmag_is_half_the_width() {
        let view = camera_view(
            &camera(CameraLens::Orthographic {
                xmag: 2.0,
                ymag: 1.5,
            }),
            800,
            600,
            DVec3::ZERO,
        )
        .unwrap();
        assert_eq!(view.lens, Lens::Orthographic { width: 4.0 });
    }

    /// A camera that fixes its aspect ratio takes an image of that ratio to the nearest
    /// pixel, and refuses another, naming the camera.
    #[test]
    fn an_image_of_another_aspect_ratio_is_refused() {
        let c = camera(CameraLens::Perspective {
            yfov: 0.8,
            aspect_ratio: Some(1.5),
        });
        for (w, h) in [(800, 533), (801, 534), (3, 2), (1, 1)] {
            assert!(camera_view(&c, w, h, DVec3::ZERO).is_ok(), "{w} x {h}");
        }
        let e = camera_view(&c, 400, 400, DVec3::ZERO)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("camera 0 \"Cam\" has aspectRatio 1.5, the image 400 x 400"),
            "{e}"
        );
        let o = camera(CameraLens::Orthographic {
            xmag: 2.0,
            ymag: 1.0,
        });
        let e = camera_view(&o, 400, 400, DVec3::ZERO)
            .unwrap_err()
            .to_string();
        assert!(e.contains("xmag / ymag 2"), "{e}");
    }

    /// Degenerate case: an eye at the model's centre looks one unit ahead.
    #[test]
    fn an_eye_at_the_centre_looks_one_unit_ahead() {
        let c = camera(CameraLens::Perspective {
            yfov: 0.8,
            aspect_ratio: None,
        });
        let view = camera_view(&c, 8, 6, c.position).unwrap();
        assert_eq!(view.frame.look_at, DVec3::new(0.0, 0.0, 4.0));
    }

    #[test]
    fn the_light_comes_from_behind_above_and_left() {
        let frame = framing([DVec3::splat(-1.0), DVec3::ONE], 1.0)
            .unwrap()
            .frame;
        let towards_light = -key_light(&frame);
        let back = (frame.position - frame.look_at).normalize();
        let right = frame.up.cross(back).normalize();
        assert!(towards_light.dot(back) > 0.0);
        assert!(towards_light.dot(DVec3::Y) > 0.0);
        assert!(towards_light.dot(right) < 0.0);
        assert!((towards_light.length() - 1.0).abs() < 1e-12);
    }

    proptest! {
        /// Every corner of any box, seen from the framing camera at any aspect ratio, lands
        /// inside the image, and the box's centre at the image's centre.
        #[test]
        fn the_framed_box_is_inside_the_image(
            lo in prop::array::uniform3(-1e3f64..1e3),
            size in prop::array::uniform3(1e-3f64..1e3),
            aspect in 0.2f64..5.0,
        ) {
            let lo = DVec3::from(lo);
            let hi = lo + DVec3::from(size);
            let view = framing([lo, hi], aspect).unwrap();
            let (w, h) = (100.0 * aspect, 100.0);
            let (cx, cy) = pinhole(&view, w, h, (lo + hi) / 2.0);
            prop_assert!((cx - w / 2.0).abs() < 1e-6 && (cy - h / 2.0).abs() < 1e-6);
            for corner in 0..8 {
                let pick = |bit: usize, a: f64, b: f64| if corner & bit == 0 { a } else { b };
                let p = DVec3::new(pick(1, lo.x, hi.x), pick(2, lo.y, hi.y), pick(4, lo.z, hi.z));
                let (x, y) = pinhole(&view, w, h, p);
                prop_assert!((0.0..=w).contains(&x) && (0.0..=h).contains(&y), "{x} {y}");
            }
        }
    }
}
