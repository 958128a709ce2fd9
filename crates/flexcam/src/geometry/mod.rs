//! Geometric primitives shared by projections and renderers.
//!
//! Projection algebra is done in f64 ([`glam::DVec3`]); meshes and the ray-casting inner loops
//! use f32 ([`glam::Vec3`]) where precision has been shown to suffice.

mod ray;

pub use ray::Ray;
