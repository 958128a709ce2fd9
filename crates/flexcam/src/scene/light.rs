//! Light sources for `lit` shading.

use glam::Vec3;

/// A light source. `intensity` scales `color`. Point lights do not fall off with distance
/// (as POV-Ray's default `light_source`), so a scene is lit the same at any scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Light from one point in every direction, casting shadows from it.
    Point {
        /// Where the light is, world units.
        position: Vec3,
        /// Linear RGB of the light.
        color: Vec3,
        /// Factor on `color`.
        intensity: f32,
    },
    /// Light arriving from infinitely far along `direction` (the direction the light travels).
    Directional {
        /// The direction the light travels (towards the scene).
        direction: Vec3,
        /// Linear RGB of the light.
        color: Vec3,
        /// Factor on `color`.
        intensity: f32,
    },
}
