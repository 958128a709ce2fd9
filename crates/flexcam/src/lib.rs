//! flexcam: rendering 3D scenes through nonlinear and multi-perspective projections.
//!
//! The centre of the design is the [`projection::Projection`] trait: an image position maps to
//! a ray, and, where the projection allows it, a scene point maps back to all of its image
//! positions. Scenes ([`scene::Scene`]) are triangle meshes with materials and lights, loaded
//! from the TOML scene format, model files or the built-in scenes. Renderers ([`render`]) turn
//! a scene and a projection into a [`render::Frame`]; the ray caster is the exact reference.
//!
//! Every public item is documented (`missing_docs` warns, and CI denies warnings): the crate
//! is meant to be embedded (see `docs/library.md` and the examples).

#![warn(missing_docs)]

pub mod calibrate;
pub mod displace;
pub mod error;
pub mod file_read;
pub mod geometry;
pub mod image_io;
pub mod projection;
pub mod render;
pub mod scene;
pub mod try_alloc;

pub use error::{Error, Result};

/// The vector library of flexcam's API (positions and directions are `glam::DVec3`, pixel
/// positions `glam::DVec2`, colours `glam::Vec3`), re-exported so that a program uses the
/// very version flexcam was built with: write `flexcam::glam::DVec3` instead of adding a
/// `glam` dependency whose version must match.
pub use glam;
