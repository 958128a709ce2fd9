//! The input of the rasteriser: polygons (or two-vertex lines) in continuous pixel coordinates,
//! each vertex carrying a depth and `N` attributes.
//!
//! Pixel `(x, y)` covers `[x, x + 1) x [y, y + 1)`, `y` pointing down; its centre is at
//! `(x + 0.5, y + 0.5)`.

use glam::DVec2;

use super::interpolate::Varying;
use crate::render::huge_pages::map_spare_capacity;

/// Largest accepted magnitude of any vertex component (coordinates, depth, attributes). Within
/// it every difference and interpolation the rasteriser computes is finite; shapes beyond it
/// (or with a NaN or infinite component) are skipped and counted, never drawn.
pub const LIMIT: f64 = 1e300;

/// No primitive: the key of an empty pixel, beaten by any fragment.
pub const NO_PRIMITIVE: u64 = u64::MAX;

/// One vertex of a shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex<const N: usize> {
    /// Continuous pixel coordinates.
    pub position: DVec2,
    /// Depth (smaller is nearer) and attributes, interpolated over the shape.
    pub varying: Varying<N>,
}

impl<const N: usize> Vertex<N> {
    /// A vertex at `(x, y)` with its depth and attributes.
    pub fn new(x: f64, y: f64, depth: f64, attributes: [f64; N]) -> Self {
        Vertex {
            position: DVec2::new(x, y),
            varying: Varying { depth, attributes },
        }
    }

    /// Whether every component is finite and within [`LIMIT`].
    fn is_valid(&self) -> bool {
        let ok = |v: f64| v.abs() <= LIMIT;
        ok(self.position.x)
            && ok(self.position.y)
            && ok(self.varying.depth)
            && self.varying.attributes.iter().all(|&a| ok(a))
    }
}

/// One shape to draw: a closed polygon (three or more vertices, any winding, possibly
/// non-convex or self-intersecting), or a line (two vertices).
#[derive(Debug, Clone, Copy)]
pub struct Polygon<'a, const N: usize> {
    pub vertices: &'a [Vertex<N>],
    /// Breaks depth ties (smaller wins) and tells the shader which primitive a fragment
    /// belongs to. Give every shape its own key for an image independent of input order.
    pub primitive: u64,
}

/// What a shape is drawn as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// Three or more valid vertices: filled.
    Fill,
    /// Two valid vertices: a one-pixel-wide line.
    Line,
    /// Fewer than two vertices, or an invalid component (see [`LIMIT`]): not drawn.
    Skip,
}

impl<const N: usize> Polygon<'_, N> {
    pub(super) fn kind(&self) -> Kind {
        if self.vertices.len() < 2 || !self.vertices.iter().all(Vertex::is_valid) {
            Kind::Skip
        } else if self.vertices.len() == 2 {
            Kind::Line
        } else {
            Kind::Fill
        }
    }

    /// The rows `[first, end)` the shape may touch within an image of `height` rows (empty
    /// when it misses the image), for binning into bands. Only meaningful for drawn kinds.
    pub(super) fn rows(&self, height: u32) -> (u32, u32) {
        let (lo, hi) = self
            .vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v.position.y), hi.max(v.position.y))
            });
        match self.kind() {
            Kind::Fill => centre_range(lo, hi, height),
            // Rows whose cells [y, y + 1) meet [lo, hi].
            Kind::Line => (
                pixel_bound(lo.floor(), height),
                pixel_bound(hi.floor() + 1.0, height),
            ),
            Kind::Skip => (0, 0),
        }
    }
}

/// The pixels `[first, end)` of `0..max` whose centre `i + 0.5` lies in `[lo, hi)`.
/// `v - 0.5` is exact for `0.25 <= v < 2^53`; below, only pixel 0 is at stake and it is
/// included either way, and above, everything is past `max`.
pub(super) fn centre_range(lo: f64, hi: f64, max: u32) -> (u32, u32) {
    (
        pixel_bound((lo - 0.5).ceil(), max),
        pixel_bound((hi - 0.5).ceil(), max),
    )
}

/// `v` (an integer-valued float, any magnitude) clamped to `[0, max]` as a pixel index.
pub(super) fn pixel_bound(v: f64, max: u32) -> u32 {
    v.clamp(0.0, f64::from(max)) as u32
}

/// Many shapes in one flat vertex buffer, drawn in index order.
#[derive(Debug, Clone, Default)]
pub struct PolygonBatch<const N: usize> {
    vertices: Vec<Vertex<N>>,
    shapes: Vec<Shape>,
}

/// Where one shape's vertices lie in the batch, and its primitive key.
#[derive(Debug, Clone, Copy)]
struct Shape {
    start: usize,
    end: usize,
    primitive: u64,
}

impl<const N: usize> PolygonBatch<N> {
    /// An empty batch.
    pub fn new() -> Self {
        PolygonBatch {
            vertices: Vec::new(),
            shapes: Vec::new(),
        }
    }

    /// An empty batch with room for `vertices` vertices in `shapes` shapes: a caller that
    /// knows the sizes up front pays no regrowth (each a copy of the batch so far into
    /// fresh memory). The vertices' storage, which the caller is to fill, is fresh memory
    /// written once: it is mapped at once ([`map_spare_capacity`]: huge pages advised, one
    /// system call instead of a page fault per 4 KiB; a trilinear frame of 108,000 outline
    /// points fills 8.7 MB).
    pub fn with_capacity(vertices: usize, shapes: usize) -> Self {
        let mut vertices = Vec::with_capacity(vertices);
        map_spare_capacity(&mut vertices);
        PolygonBatch {
            vertices,
            shapes: Vec::with_capacity(shapes),
        }
    }

    /// Appends a shape (see [`Polygon`]).
    pub fn push(&mut self, vertices: &[Vertex<N>], primitive: u64) {
        self.push_from(vertices.iter().copied(), primitive);
    }

    /// Appends a shape whose vertices `vertices` yields, written straight into the batch
    /// (no staging buffer).
    pub fn push_from(&mut self, vertices: impl IntoIterator<Item = Vertex<N>>, primitive: u64) {
        let start = self.vertices.len();
        self.vertices.extend(vertices);
        self.shapes.push(Shape {
            start,
            end: self.vertices.len(),
            primitive,
        });
    }

    /// Appends every shape of `other`, in order.
    pub fn append(&mut self, other: &PolygonBatch<N>) {
        let base = self.vertices.len();
        self.vertices.extend_from_slice(&other.vertices);
        self.shapes.extend(other.shapes.iter().map(|s| Shape {
            start: s.start + base,
            end: s.end + base,
            ..*s
        }));
    }

    /// The same shapes moved by `offset` pixels (depths and attributes unchanged): drawing
    /// them samples the original shapes at pixel position `(x, y) + 0.5 - offset` instead of
    /// the pixel centre, which is how a supersampling renderer places its samples.
    pub fn translated(&self, offset: DVec2) -> PolygonBatch<N> {
        PolygonBatch {
            vertices: self
                .vertices
                .iter()
                .map(|v| Vertex {
                    position: v.position + offset,
                    ..*v
                })
                .collect(),
            shapes: self.shapes.clone(),
        }
    }

    /// The vertices of all its shapes together (for sizing a batch that gathers several).
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// Shape `i`, `i < len()`.
    pub fn get(&self, i: usize) -> Polygon<'_, N> {
        let s = self.shapes[i];
        Polygon {
            vertices: &self.vertices[s.start..s.end],
            primitive: s.primitive,
        }
    }

    /// The shapes in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Polygon<'_, N>> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }
}
