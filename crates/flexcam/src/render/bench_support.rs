//! What `flexcam bench` and the criterion benches measure apart from a whole render, behind
//! the `workloads` feature: not the library's API. A program embedding flexcam renders
//! through [`crate::render::render`]; these stages let a bench time what the entry point does
//! not separate:
//! - a renderer kept between frames, drawing into a frame it keeps (an animation's or a
//!   viewer's later frames): [`InverseRaster`] (its pixel projectors computed on the first
//!   frame), [`TrilinearRenderer`] (the scene's f64 geometry built once) and
//!   [`raycast_into`];
//! - the projection stage of the trilinear method alone ([`projection_triangles`],
//!   [`SceneGeometry`], [`project_all`]);
//! - the bench scenes ([`workloads`]).

pub use super::raster::InverseRaster;
pub use super::raycast::render_into as raycast_into;
pub use super::trilinear::{project_all, projection_triangles, SceneGeometry, TrilinearRenderer};

/// The bench scenes of each renderer's measurements.
pub mod workloads {
    pub use super::super::raster::workloads as raster;
    pub use super::super::raycast::workloads as raycast;
    pub use super::super::trilinear::workloads as trilinear;
}
