//! Displacement mapping: height fields, the micro-geometry of displaced triangles, and exact
//! ray tracing of it.
//!
//! A base triangle with vertex positions, normals and texture coordinates is subdivided `L`
//! times by 4-to-1 midpoint subdivision, and every micro-vertex moves along its normal by
//! `S * (h(uv) - h_max) * F` (scale `S`, fraction `F`), so the undisplaced mesh is the outer
//! hull ([`micro`]). Rays meet exactly these `4^L` micro-triangles; [`intersect`] finds the
//! nearest through a min/max hierarchy over the subdivision, computed on the fly from height
//! bounds, with no tessellation stored.
//!
//! [`simplify`] reduces polygon meshes by edge collapses and records the vertex splits that
//! rebuild them exactly; [`progressive`] builds on it the chart-based progressive mesh of a
//! displaced object and its discrete levels of detail.
//!
//! For the transition system (Becker and Max 1993, Ramsey 2005 chapter 7), a height field
//! laid flat ([`normal_distribution::Chart`]) gives the distributions of the normals visible
//! from each view angle, and from them the diffuse BRDF ([`brdf_table`]) and redistributed
//! bump mapping ([`bump`]); [`transition`] chooses among them and displacement per ray.
//!
//! This layer sits beside [`crate::scene`] and uses geometry and scene types only.

pub mod brdf_table;
pub mod bump;
pub mod height;
pub mod intersect;
pub mod micro;
pub mod normal_distribution;
pub mod procedural;
pub mod progressive;
pub mod simplify;
pub mod square_map;
pub mod tessellate;
pub mod transition;

pub use height::{HeightField, HeightMap};
pub use intersect::{CachedBox, DisplacedTriangle, Frame};
pub use micro::{BaseVertex, Displacement, MicroGrid, MicroHit, MicroTriangle, MAX_LEVEL};
pub use procedural::{Procedural, Wave};
pub use tessellate::{base_corners, tessellate};
