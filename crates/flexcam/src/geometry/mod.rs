//! Geometric primitives shared by projections and renderers: rays, triangles, boxes, robust
//! polynomial roots, borrowed mesh views, and the optics of reflection and refraction.
//!
//! Projection algebra is done in f64 ([`glam::DVec3`]); meshes and the ray-casting inner loops
//! use f32 ([`glam::Vec3`]) where precision has been shown to suffice.

mod aabb;
mod bilinear_patch;
mod mesh_view;
pub(crate) mod optics;
mod ray;
mod roots;
mod triangle;

pub use aabb::Aabb;
pub use bilinear_patch::{BilinearPatch, PatchHit};
pub use mesh_view::MeshView;
pub use optics::{reflect_above, REFLECTION_LIFT};
pub use ray::Ray;
pub use roots::{solve_cubic, solve_quadratic, Roots};
pub use triangle::{intersect_triangle, TriangleHit};
