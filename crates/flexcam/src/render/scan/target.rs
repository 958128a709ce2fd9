//! The depth-tested render target of the reference rasteriser (`super::reference`): colour,
//! depth and the winning primitive per pixel, cut into horizontal bands that can be written
//! in parallel. Its frame's id buffer names the winning primitive ([`id_of`]); the renderers
//! find an object's id from the primitive key themselves.

use glam::Vec3;
use rayon::prelude::*;

use super::interpolate::Varying;
use super::NO_PRIMITIVE;
use crate::render::Frame;

/// The id the target's frame holds for the winning primitive key: the key's low 32 bits plus
/// one (wrapping), 0 where nothing was drawn, so that two frames of the same shapes have
/// equal id buffers exactly when the same primitives won (for keys below `u32::MAX`).
pub fn id_of(primitive: u64) -> u32 {
    if primitive == NO_PRIMITIVE {
        0
    } else {
        (primitive as u32).wrapping_add(1)
    }
}

/// One covered pixel centre of one shape, as handed to the shader.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment<const N: usize> {
    pub x: u32,
    pub y: u32,
    /// Depth and attributes interpolated at the pixel centre.
    pub varying: Varying<N>,
    /// The shape's primitive key (see [`super::Polygon`]).
    pub primitive: u64,
}

/// A framebuffer with an `f64` z-buffer and, per pixel, the primitive key that won it.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    width: u32,
    height: u32,
    color: Vec<Vec3>,
    depth: Vec<f64>,
    primitives: Vec<u64>,
}

impl Target {
    /// An empty target: `background` colour, infinite depth, no primitive.
    pub fn new(width: u32, height: u32, background: Vec3) -> Self {
        let n = width as usize * height as usize;
        Target {
            width,
            height,
            color: filled(n, background),
            depth: filled(n, f64::INFINITY),
            primitives: filled(n, NO_PRIMITIVE),
        }
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major depths; `f64::INFINITY` where nothing was drawn.
    pub fn depth(&self) -> &[f64] {
        &self.depth
    }

    /// The primitive key of the fragment visible at pixel `(x, y)` (inside the target);
    /// `None` where nothing was drawn.
    pub fn primitive(&self, x: u32, y: u32) -> Option<u64> {
        let p = self.primitives[y as usize * self.width as usize + x as usize];
        (p != NO_PRIMITIVE).then_some(p)
    }

    /// How many pixels hold a fragment.
    pub fn covered(&self) -> u64 {
        self.primitives
            .iter()
            .filter(|&&p| p != NO_PRIMITIVE)
            .count() as u64
    }

    /// The image as a [`Frame`] (depth rounded to `f32`).
    pub fn into_frame(self) -> Frame {
        Frame {
            width: self.width,
            height: self.height,
            color: self.color,
            depth: self.depth.par_iter().map(|&d| d as f32).collect(),
            ids: self.primitives.par_iter().map(|&p| id_of(p)).collect(),
            surface: Vec::new(),
        }
    }

    /// The whole target as one band.
    pub(super) fn band(&mut self) -> Band<'_> {
        Band {
            width: self.width,
            rows: (0, self.height),
            color: &mut self.color,
            depth: &mut self.depth,
            primitives: &mut self.primitives,
        }
    }

    /// The target cut into bands of `rows` rows (the last may be shorter), top first.
    pub(super) fn bands(&mut self, rows: u32) -> Vec<Band<'_>> {
        let width = self.width;
        let n = (rows.max(1) as usize * width as usize).max(1);
        self.color
            .chunks_mut(n)
            .zip(self.depth.chunks_mut(n))
            .zip(self.primitives.chunks_mut(n))
            .enumerate()
            .map(|(i, ((color, depth), primitives))| {
                let first = (i * n / width as usize) as u32;
                Band {
                    width,
                    rows: (first, first + (color.len() / width as usize) as u32),
                    color,
                    depth,
                    primitives,
                }
            })
            .collect()
    }
}

/// `n` copies of `value`, written in parallel: a new frame-sized buffer's first touch (its
/// page faults) is shared by the cores instead of serialised in `vec![value; n]`.
fn filled<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
    let mut values = Vec::with_capacity(n);
    values.par_extend(rayon::iter::repeat_n(value, n));
    values
}

/// Rows `[rows.0, rows.1)` of a [`Target`], borrowed mutably.
pub(super) struct Band<'a> {
    pub width: u32,
    pub rows: (u32, u32),
    color: &'a mut [Vec3],
    depth: &'a mut [f64],
    primitives: &'a mut [u64],
}

impl<'a> Band<'a> {
    /// The z-test: the fragment wins when `(depth, primitive)` is lexicographically smaller
    /// than the stored pair, so the result does not depend on the order of distinct shapes.
    /// On a win the shader is run and colour, depth and key are written. `fragment` must
    /// lie in the band; its depth is finite (see [`super::LIMIT`]).
    pub fn test_and_write<const N: usize>(
        &mut self,
        fragment: &Fragment<N>,
        shader: &impl Fn(&Fragment<N>) -> Vec3,
    ) -> bool {
        let i = (fragment.y - self.rows.0) as usize * self.width as usize + fragment.x as usize;
        let depth = fragment.varying.depth;
        let wins = depth < self.depth[i]
            || (depth == self.depth[i] && fragment.primitive < self.primitives[i]);
        if wins {
            self.color[i] = shader(fragment);
            self.depth[i] = depth;
            self.primitives[i] = fragment.primitive;
        }
        wins
    }
}
