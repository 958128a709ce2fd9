//! flexcam: rendering 3D scenes through nonlinear and multi-perspective projections.
//!
//! The centre of the design is the [`projection::Projection`] trait: an image position maps to
//! a ray, and, where the projection allows it, a scene point maps back to all of its image
//! positions. Scenes ([`scene::Scene`]) are triangle meshes with materials and lights, loaded
//! from the TOML scene format, model files or the built-in scenes. Renderers ([`render`]) turn
//! a scene and a projection into a [`render::Frame`]; the ray caster is the exact reference.

pub mod calibrate;
pub mod displace;
pub mod error;
pub mod file_read;
pub mod geometry;
pub mod image_io;
pub mod projection;
pub mod render;
pub mod scene;

pub use error::{Error, Result};
