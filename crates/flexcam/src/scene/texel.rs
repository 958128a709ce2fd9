//! Texel addressing shared by every image looked up by texture coordinates (colour textures,
//! height maps): OBJ-style coordinates ((0,0) bottom-left, (1,1) top-right, so v = 1 is the top
//! row), wrapping (repeat) outside \[0,1\], bilinear filtering between texel centres.
//!
//! The arithmetic is written once, generic over the texel type, so that a height map sampled
//! here agrees bit for bit with a texture of the same grey image.

use glam::{Vec2, Vec3};

/// A texel value that can be blended linearly.
pub trait Texel: Copy {
    /// `self * (1 - s) + other * s`, as [`Vec3::lerp`] computes it.
    fn lerp(self, other: Self, s: f32) -> Self;
}

impl Texel for Vec3 {
    fn lerp(self, other: Self, s: f32) -> Self {
        Vec3::lerp(self, other, s)
    }
}

impl Texel for f32 {
    fn lerp(self, other: Self, s: f32) -> Self {
        self * (1.0 - s) + other * s
    }
}

/// A `width x height` image of texels, row-major, top row first, addressed by texture
/// coordinates. The caller guarantees `texels.len() == width * height`, both non-zero.
#[derive(Debug, Clone, Copy)]
pub struct TexelGrid<'a, T> {
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The texels, row-major, top row first.
    pub texels: &'a [T],
}

impl<T: Texel> TexelGrid<'_, T> {
    /// Nearest-texel lookup.
    #[inline]
    pub fn nearest(&self, uv: Vec2) -> T {
        let (x, y) = self.texel_coords(uv);
        self.texel(x.floor() as i64, y.floor() as i64)
    }

    /// Bilinear lookup between the four nearest texel centres.
    #[inline]
    pub fn bilinear(&self, uv: Vec2) -> T {
        let (x, y) = self.texel_coords(uv);
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// Continuous texel coordinates of `uv` (x right, y down from the top row).
    #[inline]
    fn texel_coords(&self, uv: Vec2) -> (f32, f32) {
        let u = uv.x - uv.x.floor();
        let v = uv.y - uv.y.floor();
        (u * self.width as f32, (1.0 - v) * self.height as f32)
    }

    /// The texel at integer coordinates, wrapped into range.
    #[inline]
    fn texel(&self, x: i64, y: i64) -> T {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width as usize + x]
    }
}
