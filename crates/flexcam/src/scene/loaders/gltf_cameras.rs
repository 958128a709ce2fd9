//! The cameras of a glTF document (glTF 2.0 section 3.10): each camera a node of the loaded
//! scene places, with the node's world transform.
//!
//! They are read as the file states them and checked only when one is used as a view
//! ([`ModelCamera::check`]), so that a model whose camera is odd still loads as an object
//! of a scene that does not use it. `znear` and `zfar` are not read: flexcam's perspective
//! and orthographic projections have no clip planes.

use std::f64::consts::PI;

use ::gltf::json::camera::Type;
use ::gltf::json::validation::Checked;
use ::gltf::{Document, Node};
use glam::{Affine3A, DVec3, Vec3};

use crate::error::{Error, Result};

/// What a glTF camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CameraLens {
    /// `yfov`: the vertical field of view, radians; `aspect_ratio`: the image's width over
    /// its height, when the file fixes it (otherwise the image's own is used).
    Perspective {
        /// Vertical field of view, radians.
        yfov: f64,
        /// Image width over height, when the file fixes it.
        aspect_ratio: Option<f64>,
    },
    /// `xmag`, `ymag`: half the width and half the height of the view, world units.
    Orthographic {
        /// Half the view's width, world units.
        xmag: f64,
        /// Half the view's height, world units.
        ymag: f64,
    },
}

/// A glTF camera placed in the world by a node. The camera looks down the node's -Z axis
/// with +Y up (glTF 2.0 section 3.10.1).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelCamera {
    /// The camera's index in the file's `cameras`.
    pub index: usize,
    /// The camera's `name`, if any.
    pub name: Option<String>,
    /// The index of the node that places it.
    pub node: usize,
    /// The node's `name`, if any.
    pub node_name: Option<String>,
    /// What the camera projects.
    pub lens: CameraLens,
    /// The eye: the node's origin in world space.
    pub position: DVec3,
    /// The view direction, unit: the node's -Z axis in world space.
    pub forward: DVec3,
    /// The image's up, unit: the node's +Y axis in world space (orthogonal to `forward`
    /// unless the node's transform shears).
    pub up: DVec3,
}

/// The number a file wrote that was read as the single-precision `x` (the gltf crate reads
/// numbers as f32): its shortest decimal form read as f64, so that `yfov: 0.9` is 0.9 and
/// not 0.8999999761581421.
fn decimal(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

impl ModelCamera {
    /// The camera of `node` with the node's world transform `world` (finite and invertible:
    /// the loader's node checks), or `None` when the node has none.
    pub(super) fn of_node(document: &Document, node: &Node, world: &Affine3A) -> Option<Self> {
        let camera = node.camera()?;
        let json = document.as_json().cameras.get(camera.index())?;
        // The gltf crate's own accessor unwraps the table of the declared type, which its
        // validation does not require; read the JSON and let `check` refuse what is missing.
        let lens = match (&json.type_, &json.perspective, &json.orthographic) {
            (Checked::Valid(Type::Perspective), Some(p), _) => CameraLens::Perspective {
                yfov: decimal(p.yfov),
                aspect_ratio: p.aspect_ratio.map(decimal),
            },
            (Checked::Valid(Type::Orthographic), _, Some(o)) => CameraLens::Orthographic {
                xmag: decimal(o.xmag),
                ymag: decimal(o.ymag),
            },
            // No lens of the declared type: a lens no image can have, refused by `check`.
            _ => CameraLens::Orthographic {
                xmag: f64::NAN,
                ymag: f64::NAN,
            },
        };
        let axis = |v: Vec3| world.transform_vector3(v).as_dvec3().normalize();
        Some(ModelCamera {
            index: camera.index(),
            name: camera.name().map(str::to_string),
            node: node.index(),
            node_name: node.name().map(str::to_string),
            lens,
            position: world
                .transform_point3(Vec3::ZERO)
                .to_array()
                .map(decimal)
                .into(),
            forward: axis(Vec3::NEG_Z),
            up: axis(Vec3::Y),
        })
    }

    /// How the camera is named in messages: `camera 0 "Name"` (the node's name when the
    /// camera has none).
    pub fn label(&self) -> String {
        match self.name.as_ref().or(self.node_name.as_ref()) {
            Some(name) => format!("camera {} \"{name}\"", self.index),
            None => format!("camera {}", self.index),
        }
    }

    /// Whether `key` names this camera: its index, its name or its node's name.
    pub fn is_named(&self, key: &str) -> bool {
        key.parse::<usize>().ok() == Some(self.index)
            || self.name.as_deref() == Some(key)
            || self.node_name.as_deref() == Some(key)
    }

    /// Fails unless the lens can make an image: a perspective `yfov` in (0, 180) degrees and
    /// a positive finite `aspectRatio`; an orthographic `xmag` and `ymag` positive and
    /// finite (glTF 2.0 forbids zero and advises against negative magnifications, which
    /// would mirror the image). Also refuses a lens missing its table.
    pub fn check(&self) -> Result<()> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let problem = match self.lens {
            CameraLens::Perspective { yfov, .. } if !(positive(yfov) && yfov < PI) => {
                format!("yfov {yfov} is not in (0, pi) radians")
            }
            CameraLens::Perspective {
                aspect_ratio: Some(a),
                ..
            } if !positive(a) => format!("aspectRatio {a} is not positive"),
            CameraLens::Orthographic { xmag, ymag } if xmag.is_nan() && ymag.is_nan() => {
                "has no table of its type (perspective or orthographic)".to_string()
            }
            CameraLens::Orthographic { xmag, ymag } if !(positive(xmag) && positive(ymag)) => {
                format!("xmag {xmag} and ymag {ymag} must both be positive")
            }
            _ => return Ok(()),
        };
        Err(Error::new(format!("{}: {problem}", self.label())))
    }

    /// The image aspect ratio (width over height) the camera fixes, if any: a perspective
    /// camera's `aspectRatio`, an orthographic camera's `xmag / ymag`.
    pub fn fixed_aspect(&self) -> Option<f64> {
        match self.lens {
            CameraLens::Perspective { aspect_ratio, .. } => aspect_ratio,
            CameraLens::Orthographic { xmag, ymag } => Some(xmag / ymag),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(lens: CameraLens) -> ModelCamera {
        ModelCamera {
            index: 2,
            name: None,
            node: 5,
            node_name: Some("Eye".into()),
            lens,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }

    #[test]
    fn numbers_are_read_as_written() {
        assert_eq!(decimal(0.9), 0.9);
        assert_eq!(decimal(2.2), 2.2);
        assert_eq!(decimal(-1e-30), -1e-30);
        assert_eq!(decimal(f32::MAX), 3.4028235e38);
    }

    #[test]
    fn named_by_index_camera_name_or_node_name() {
        let mut c = camera(CameraLens::Perspective {
            yfov: 1.0,
            aspect_ratio: None,
        });
        assert!(c.is_named("2") && c.is_named("Eye") && !c.is_named("0"));
        assert_eq!(c.label(), "camera 2 \"Eye\"");
        c.name = Some("Cam".into());
        assert!(c.is_named("Cam") && c.is_named("Eye"));
        assert_eq!(c.label(), "camera 2 \"Cam\"");
    }

    /// Degenerate lenses: each is refused by name.
    #[test]
    fn lenses_that_make_no_image_are_refused() {
        let perspective = |yfov, aspect_ratio| CameraLens::Perspective { yfov, aspect_ratio };
        let orthographic = |xmag, ymag| CameraLens::Orthographic { xmag, ymag };
        for (lens, says) in [
            (perspective(0.0, None), "yfov 0"),
            (perspective(PI, None), "yfov 3.14"),
            (perspective(f64::NAN, None), "yfov NaN"),
            (perspective(1.0, Some(0.0)), "aspectRatio 0"),
            (perspective(1.0, Some(f64::INFINITY)), "aspectRatio inf"),
            (orthographic(0.0, 1.0), "xmag 0"),
            (orthographic(1.0, -1.0), "ymag -1"),
            (orthographic(f64::NAN, f64::NAN), "no table"),
        ] {
            let e = camera(lens).check().unwrap_err().to_string();
            assert!(
                e.starts_with("camera 2 \"Eye\": ") && e.contains(says),
                "{e}"
            );
        }
        assert!(camera(perspective(3.0, Some(0.5))).check().is_ok());
        assert!(camera(orthographic(2.0, 1.0)).check().is_ok());
        assert_eq!(camera(orthographic(2.0, 1.0)).fixed_aspect(), Some(2.0));
        assert_eq!(camera(perspective(1.0, None)).fixed_aspect(), None);
    }
}
