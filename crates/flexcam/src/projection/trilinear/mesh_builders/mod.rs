//! Builders of trilinear projection meshes from a description instead of vertex by vertex:
//! from reflector and lens meshes, visualisation surfaces and grids over control surfaces
//! (Vallance 2005, chapters 6 and 7, calls the results surfaces to project through; re-exported
//! as `projection::trilinear_builders`).
//!
//! - [`screen_grid`]: a regular n x n grid of screen cells ([`screen_grid_cells`]: columns x
//!   rows) (two projection triangles each,
//!   shared vertices and ray directions) over any base given as a function from screen
//!   position to a base point and ray direction ([`GridVertex`]); [`between_surfaces`] takes
//!   the base from two control surfaces of a flexible volume (a bent, cylindrical or
//!   spherical base; [`inward_sphere`] is the mapping surface of section 6.3).
//! - [`DetailInContext`] and [`TwoViews`]: the visualisation surfaces of sections 6.1 and
//!   6.2, defined over [`GridCamera`]s.
//! - [`BallView`]: a pinhole's view through a mirror or glass ball (7.4, 7.3.3), as a grid
//!   and exactly ([`BallProjection`], the grid's limit, its reference).
//! - [`reflector_surface`]: the reflection and refraction surfaces of chapter 7, built from a
//!   reflector mesh and the main camera, so that the image through them is already in the
//!   main image's coordinates.
//!
//! See docs/trilinear-surfaces.md for the design and the degenerate cases.

mod ball;
mod camera;
mod grid;
mod reflector;
mod visualisation;

pub use ball::{BallOptic, BallProjection, BallView};
pub use camera::GridCamera;
pub use grid::{between_surfaces, screen_grid, screen_grid_cells, GridVertex, MAX_GRID_CELLS};
pub(crate) use reflector::vertex_normals;
pub use reflector::{
    enters, reflector_surface, vertex_ray, Optic, ReflectorSurface, SurfaceRays, SurfaceScreenMap,
};
pub use visualisation::{inward_sphere, DetailInContext, FocusView, TwoViews};
