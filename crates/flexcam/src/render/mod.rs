//! Renderers and what they produce: a [`Frame`] (colour, depth, object ids) and counters.

use std::collections::BTreeMap;

use glam::Vec3;

/// How surfaces are shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// The base colour of the first surface hit, mirrors and glass passing the ray on (the
    /// exact contract of the scene-and-CLI spec).
    Flat,
    /// Lambert + Phong with hard shadows, recursive reflection and refraction with Fresnel.
    #[default]
    Lit,
}

/// Options shared by all renderers.
#[derive(Clone, Copy)]
pub struct RenderOptions<'a> {
    pub shading: Shading,
    /// Samples per pixel (1 = one ray through each pixel centre).
    pub spp: u32,
    /// Maximum number of specular bounces.
    pub max_bounces: u32,
    /// How method `raster` subdivides triangles (other methods ignore it).
    pub subdivision: inverse_raster::Subdivision,
    /// How method trilinear follows curved edges.
    pub curves: trilinear::CurveOptions,
    /// Called from worker threads with (work units done, total) as rendering progresses.
    pub progress: Option<&'a (dyn Fn(u64, u64) + Sync)>,
}

impl Default for RenderOptions<'_> {
    fn default() -> Self {
        RenderOptions {
            shading: Shading::Lit,
            spp: 1,
            max_bounces: 8,
            subdivision: inverse_raster::Subdivision::default(),
            curves: trilinear::CurveOptions::ADAPTIVE,
            progress: None,
        }
    }
}

/// A rendered image with its arbitrary output variables, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Linear RGB.
    pub color: Vec<Vec3>,
    /// Distance from the projector's origin to the first hit, along the projector;
    /// `f32::INFINITY` where nothing is hit.
    pub depth: Vec<f32>,
    /// Object id of the first hit, 0 for background.
    pub ids: Vec<u32>,
}

impl Frame {
    /// A frame filled with `background`, infinite depth and id 0.
    pub fn new(width: u32, height: u32, background: Vec3) -> Self {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![background; n],
            depth: vec![f32::INFINITY; n],
            ids: vec![0; n],
        }
    }

    /// A frame of zeros (black, depth 0, id 0) for a renderer that overwrites every pixel:
    /// its buffers come zeroed from the allocator (`alloc_zeroed`, fresh pages from the
    /// kernel for a large frame), so nothing is written here and each page is first touched
    /// by the renderer's own (parallel) writes instead of by a fill that they overwrite.
    /// Degenerate case: a width or height of 0 gives empty buffers (no allocation).
    pub fn for_overwrite(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: zeroed_colors(n),
            depth: vec![0.0; n],
            ids: vec![0; n],
        }
    }
}

/// `n` colours `Vec3::ZERO`, allocated zeroed: `vec![Vec3::ZERO; n]` writes every element
/// (only primitive element types get a zeroed allocation), which for a frame means touching
/// every page. Degenerate case: `n == 0` gives an empty vector without allocating (a
/// zero-sized allocation is not allowed).
fn zeroed_colors(n: usize) -> Vec<Vec3> {
    let layout = std::alloc::Layout::array::<Vec3>(n).expect("frame size overflows");
    if layout.size() == 0 {
        return Vec::new();
    }
    // SAFETY: the layout has a non-zero size. `Vec3` is `#[repr(C)]` of three `f32`, for
    // which all-zero bytes are the valid value 0.0, so the `n` elements are initialised;
    // the pointer comes from the global allocator with `Vec3`'s alignment and a size of
    // exactly `n * size_of::<Vec3>()` bytes, as `Vec::from_raw_parts` requires.
    unsafe {
        let ptr = std::alloc::alloc_zeroed(layout).cast::<Vec3>();
        if ptr.is_null() {
            std::alloc::handle_alloc_error(layout);
        }
        Vec::from_raw_parts(ptr, n, n)
    }
}

/// One counter of a renderer's statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Counter {
    Count(u64),
    Value(f64),
}

/// Named counters a renderer reports (rays cast, build times, ...), for `--stats`.
pub type Stats = BTreeMap<&'static str, Counter>;
pub mod compare;
pub mod composite;
pub mod inverse_raster;
mod method;
pub mod raster;
pub mod raycast;
pub mod reproject;
pub mod surface;
pub mod trilinear;
pub use method::Method;

#[cfg(test)]
mod tests {
    use super::*;

    /// `for_overwrite` gives buffers of the frame's size holding zeros, and empty buffers
    /// (its degenerate case) for a width or height of 0.
    #[test]
    fn for_overwrite_is_zeroed_and_sized() {
        let frame = Frame::for_overwrite(7, 5);
        assert_eq!((frame.width, frame.height), (7, 5));
        assert_eq!(frame.color, vec![Vec3::ZERO; 35]);
        assert_eq!(frame.depth, vec![0.0; 35]);
        assert_eq!(frame.ids, vec![0; 35]);
        for (width, height) in [(0, 4), (4, 0), (0, 0)] {
            let frame = Frame::for_overwrite(width, height);
            assert!(frame.color.is_empty() && frame.depth.is_empty() && frame.ids.is_empty());
        }
    }
}
