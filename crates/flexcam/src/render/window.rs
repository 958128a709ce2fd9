//! A rectangle of an image's pixels ([`PixelWindow`], `RenderOptions::crop`, `--crop`): a
//! render of a window is that rectangle of the whole frame, byte for byte, so that a large
//! frame can be split into tiles rendered on different machines and put back together.
//!
//! The ray caster renders the window's pixels alone (every pixel's samples depend on its
//! position in the whole image only, never on its neighbours or on the tiling). The other
//! methods, and the ray caster when it composites trilinear reflectors or shades by the
//! transition system, render the whole frame and keep the window: rasterisers draw
//! triangles, not pixels, and a window of their work is the whole of it for most scenes.

use crate::error::{Error, Result};
use crate::render::{frame_name, Frame};
use crate::try_alloc;

/// Columns `x0..x1` and rows `y0..y1` of an image (pixel (0, 0) the top-left).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelWindow {
    /// First column inside the window.
    pub x0: u32,
    /// First row inside the window.
    pub y0: u32,
    /// First column past the window (exclusive).
    pub x1: u32,
    /// First row past the window (exclusive).
    pub y1: u32,
}

impl PixelWindow {
    /// The whole of a `width` x `height` image.
    pub fn whole(width: u32, height: u32) -> PixelWindow {
        PixelWindow {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Columns in the window.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Rows in the window.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Fails unless the window holds at least one pixel and lies within a `width` x
    /// `height` image.
    pub fn check(&self, (width, height): (u32, u32)) -> Result<()> {
        let PixelWindow { x0, y0, x1, y1 } = *self;
        if x0 >= x1 || y0 >= y1 {
            return Err(Error::new(format!(
                "crop window {x0},{y0},{x1},{y1} is empty (it needs X0 < X1 and Y0 < Y1)"
            )));
        }
        if x1 > width || y1 > height {
            return Err(Error::new(format!(
                "crop window {x0},{y0},{x1},{y1} does not fit in the {width} x {height} image"
            )));
        }
        Ok(())
    }

    /// The window's pixels of `frame` (a frame of the whole image), buffers not held left
    /// empty. Fails when the memory cannot be had (module `try_alloc`).
    pub(crate) fn cut(&self, frame: &Frame) -> Result<Frame> {
        Ok(Frame {
            width: self.width(),
            height: self.height(),
            color: self.rows(&frame.color, frame.width)?,
            depth: self.rows(&frame.depth, frame.width)?,
            ids: self.rows(&frame.ids, frame.width)?,
            surface: self.rows(&frame.surface, frame.width)?,
        })
    }

    /// The window's part of `buffer`, an image `width` pixels wide row by row (empty for an
    /// empty buffer).
    fn rows<T: Copy>(&self, buffer: &[T], width: u32) -> Result<Vec<T>> {
        let mut rows = Vec::new();
        if buffer.is_empty() {
            return Ok(rows);
        }
        let (x0, x1) = (self.x0 as usize, self.x1 as usize);
        let what = || frame_name(self.width(), self.height());
        try_alloc::reserve(&mut rows, (x1 - x0) * self.height() as usize, what)?;
        for y in self.y0 as usize..self.y1 as usize {
            let row = y * width as usize;
            rows.extend_from_slice(&buffer[row + x0..row + x1]);
        }
        Ok(rows)
    }
}
