//! Built-in analytic shapes, tessellated into meshes in object space (y up, centred on the
//! origin unless stated). `tessellation` is the number of segments around a full circle.
//!
//! Every shape has per-vertex unit normals pointing outward, texture coordinates in
//! `[0,1]^2` and counter-clockwise triangles seen from outside; closed shapes (box, sphere,
//! cylinder, torus, each part of the walker) are closed once coincident positions are welded. Degenerate parameters
//! never panic or produce NaN: tessellation is raised to each shape's minimum and negative
//! sizes are taken by absolute value (the scene-file parser rejects them before this).

mod cuboid;
mod cylinder;
mod grid;
mod plane;
mod sphere;
mod teapot;
mod teapot_patches;
mod torus;
mod walker;

#[cfg(test)]
mod test_support;

pub use cuboid::cuboid;
pub use cylinder::cylinder;
pub use plane::plane;
pub use sphere::sphere;
pub use teapot::teapot;
pub use torus::torus;
pub use walker::{walker, WALKER_PARTS};
