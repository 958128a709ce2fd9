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
    pub subdivision: raster::Subdivision,
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
            subdivision: raster::Subdivision::default(),
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

    /// A frame of zero bits in every channel (black, depth 0, id 0), for a renderer that
    /// then overwrites every pixel. The buffers come zeroed from the allocator
    /// (`alloc_zeroed`), so a frame-sized allocation of fresh memory is zero pages that no
    /// clearing pass writes: their first touch (page faults) is the renderer's own writes,
    /// in the threads that make them, and the 20 bytes a pixel are written once, not twice
    /// (memory the allocator reuses is cleared by it, in the calling thread).
    /// Large buffers are mapped with transparent huge pages where the system allows
    /// ([`huge_pages::advise_huge_pages`]): far fewer page faults on that first touch.
    pub(crate) fn zeroed(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        let mut frame = Frame {
            width,
            height,
            color: bytemuck::zeroed_vec(n),
            depth: bytemuck::zeroed_vec(n),
            ids: bytemuck::zeroed_vec(n),
        };
        huge_pages::advise_huge_pages(&mut frame.color);
        huge_pages::advise_huge_pages(&mut frame.depth);
        huge_pages::advise_huge_pages(&mut frame.ids);
        frame
    }

    /// Makes this frame `width` x `height` for a renderer that overwrites every pixel: a
    /// frame of that size (whose three buffers hold `width * height` pixels) is kept as it
    /// is, contents and all, so a caller drawing frame after frame pays neither its
    /// allocation nor the first touch of its pages again; any other is replaced by
    /// [`Frame::zeroed`].
    pub(crate) fn fit(&mut self, width: u32, height: u32) {
        let n = width as usize * height as usize;
        let fits = (self.width, self.height) == (width, height)
            && [self.color.len(), self.depth.len(), self.ids.len()] == [n; 3];
        if !fits {
            *self = Frame::zeroed(width, height);
        }
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
pub(crate) mod bvh;
pub mod compare;
pub mod composite;
mod huge_pages;
mod method;
pub mod prepared;
pub mod raster;
pub mod raycast;
pub mod reproject;
pub mod scan;
pub mod surface;
pub mod trilinear;
pub use method::Method;
pub use prepared::PreparedScene;
