//! Light sources for `lit` shading.

use glam::Vec3;

/// A light source. `intensity` scales `color`. Point lights do not fall off with distance
/// (as POV-Ray's default `light_source`), so a scene is lit the same at any scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    Point {
        position: Vec3,
        color: Vec3,
        intensity: f32,
    },
    /// Light arriving from infinitely far along `direction` (the direction the light travels).
    Directional {
        direction: Vec3,
        color: Vec3,
        intensity: f32,
    },
}
