//! Materials: a base colour pattern and how light leaves the surface.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::texel::TexelGrid;

/// How the base colour varies over a surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// The material's `color` everywhere.
    Solid,
    /// A 3D checker in object space, alternating `color` and `other`, cells `size` wide:
    /// cell parity is `floor(x/size) + floor(y/size) + floor(z/size)` (as POV-Ray's `checker`),
    /// evaluated at the object-space hit point nudged by `1e-4 * size` so that an axis-aligned
    /// face lying on a cell boundary (a floor at y = 0) does not flicker between cells.
    Checker {
        /// The second colour, linear RGB (the first is the material's `color`).
        other: Vec3,
        /// Cell width, object-space units.
        size: f32,
    },
    /// An image texture looked up by the mesh's texture coordinates, multiplied by `color`.
    Texture(Arc<Texture>),
}

/// How light leaves the surface: an object's finish (scene-file key `surface`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Finish {
    /// Lambert diffuse plus a Phong highlight in `lit` shading.
    Diffuse,
    /// A perfect mirror.
    Mirror,
    /// A dielectric with index of refraction `ior` (refraction and Fresnel reflection).
    Glass {
        /// Index of refraction (1.5 for window glass).
        ior: f32,
    },
    /// Emits its base colour; not lit.
    Emissive,
}

/// A material: base colour, pattern and finish. The base colour at a point is
/// `color * pattern * vertex colour` (the glTF convention: factor times texture times vertex
/// colour; meshes without vertex colours count as white).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The base colour factor, linear RGB.
    pub color: Vec3,
    /// What varies the base colour over the surface (solid, checker, texture).
    pub pattern: Pattern,
    /// How light leaves the surface (diffuse, mirror, glass, emissive).
    pub finish: Finish,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            color: Vec3::splat(0.8),
            pattern: Pattern::Solid,
            finish: Finish::Diffuse,
        }
    }
}

/// An RGB image in linear colour, addressed with OBJ-style texture coordinates
/// ((0,0) bottom-left, (1,1) top-right), wrapping (repeat) outside \[0,1\].
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first.
    pub texels: Vec<Vec3>,
}

impl Texture {
    /// Nearest-texel lookup (no filtering, as `--shading flat` requires).
    pub fn nearest(&self, uv: Vec2) -> Vec3 {
        self.grid().nearest(uv)
    }

    /// Bilinear lookup between the four nearest texel centres.
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        self.grid().bilinear(uv)
    }

    fn grid(&self) -> TexelGrid<'_, Vec3> {
        TexelGrid {
            width: self.width,
            height: self.height,
            texels: &self.texels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_one() -> Texture {
        Texture {
            width: 2,
            height: 1,
            texels: vec![Vec3::ZERO, Vec3::ONE],
        }
    }

    #[test]
    fn nearest_wraps_and_picks_texel() {
        let t = two_by_one();
        assert_eq!(t.nearest(Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert_eq!(t.nearest(Vec2::new(0.75, 0.5)), Vec3::ONE);
        assert_eq!(t.nearest(Vec2::new(1.75, -3.5)), Vec3::ONE);
    }

    #[test]
    fn bilinear_blends_between_centres() {
        let t = two_by_one();
        let mid = t.bilinear(Vec2::new(0.5, 0.5));
        assert!((mid - Vec3::splat(0.5)).length() < 1e-6);
    }
}
