//! The micro-geometry of a displaced base triangle, and the brute-force reference that tests
//! every micro-triangle.
//!
//! A base triangle `(a, b, c)` is subdivided `L` times by the 4-to-1 midpoint subdivision of
//! Algorithm 6.12 (Ramsey 2005, after Loop): each edge midpoint gets the mean position, the mean
//! uv and the normalised mean normal of the edge's ends ([`BaseVertex::midpoint`]). After `L`
//! levels every micro-vertex moves along its normal ([`Displacement::displace`]).
//!
//! # Micro-vertices are path-independent
//! With `n = 2^L`, the micro-vertices are the grid points `(i, j)`, `i, j >= 0`, `i + j <= n`,
//! whose barycentric weights for `(a, b, c)` are `((n - i - j) / n, i / n, j / n)`. Every grid
//! point not a corner is created at exactly one level, as the midpoint of exactly one edge of
//! the coarser grid, so its value depends only on that edge's two end values, which by
//! induction depend on nothing else. [`BaseVertex::midpoint`] is symmetric bit for bit (IEEE
//! addition commutes), so the order in which a traversal meets an edge's ends does not matter:
//! the hierarchy's recursion, the grid of [`MicroGrid`], and a neighbouring base triangle that
//! shares the edge's two base vertices (with the same position, normal and uv) all produce
//! identical micro-vertices along it. Displaced meshes have no cracks wherever the base mesh
//! shares vertices; a uv or normal seam (different uv or normals on the two sides of an edge)
//! displaces each side by its own values and opens there, as any displacement does.
//!
//! # Micro-triangles
//! Micro-triangle `(i, j)` pointing up has the grid vertices `(i, j), (i + 1, j), (i, j + 1)`
//! (`i + j <= n - 1`); pointing down, `(i + 1, j + 1), (i, j + 1), (i + 1, j)` (`i + j <= n -
//! 2`). Both keep the base triangle's orientation. Hits report barycentric weights of the second
//! and third vertex in that order, from [`intersect_triangle`] on the displaced positions; a
//! ray within 1e-6 (sine of the angle) of a micro-triangle's plane does not hit it (see
//! `GRAZING`).

use glam::{DVec2, DVec3};

use super::height::HeightField;
use crate::error::{Error, Result};
use crate::geometry::{intersect_triangle, Ray};
use crate::scene::displacement::DisplacementSpec;

pub use crate::scene::displacement::MAX_LEVEL;

/// A base-triangle vertex or an undisplaced micro-vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseVertex {
    /// Position before displacement, world units.
    pub position: DVec3,
    /// The direction displacement moves the vertex along (unit, or zero: not displaced).
    pub normal: DVec3,
    /// Texture coordinates the height field is sampled at.
    pub uv: DVec2,
}

impl BaseVertex {
    /// The edge midpoint of Algorithm 6.12: mean position, mean uv, normalised mean normal
    /// (zero where the two normals are opposite; such a vertex is not displaced). Symmetric in
    /// its two arguments, bit for bit.
    #[inline]
    pub fn midpoint(self, other: BaseVertex) -> BaseVertex {
        BaseVertex {
            position: (self.position + other.position) * 0.5,
            normal: ((self.normal + other.normal) * 0.5).normalize_or_zero(),
            uv: (self.uv + other.uv) * 0.5,
        }
    }
}

/// How a mesh is displaced: the height field, scale `S`, fraction `F` and level `L`.
#[derive(Debug, Clone, PartialEq)]
pub struct Displacement {
    height: HeightField,
    h_max: f64,
    scale: f64,
    fraction: f64,
    level: u32,
}

impl Displacement {
    /// Errors: a scale or fraction that is not finite, a level above [`MAX_LEVEL`].
    pub fn new(height: HeightField, scale: f64, fraction: f64, level: u32) -> Result<Self> {
        if !scale.is_finite() {
            return Err(Error::new(format!(
                "displacement scale {scale} is not finite"
            )));
        }
        if !fraction.is_finite() {
            return Err(Error::new(format!(
                "displacement fraction {fraction} is not finite"
            )));
        }
        if level > MAX_LEVEL {
            return Err(Error::new(format!(
                "displacement level {level} is above the largest, {MAX_LEVEL}"
            )));
        }
        Ok(Displacement::build(height, scale, fraction, level))
    }

    /// The displacement a scene describes (validated when the scene loaded).
    pub fn from_spec(spec: &DisplacementSpec) -> Self {
        let height = HeightField::new(&spec.height);
        Displacement::build(height, spec.scale, spec.fraction, spec.level)
    }

    fn build(height: HeightField, scale: f64, fraction: f64, level: u32) -> Self {
        Displacement {
            h_max: height.max(),
            height,
            scale,
            fraction,
            level,
        }
    }

    /// The height field h(u, v).
    pub fn height(&self) -> &HeightField {
        &self.height
    }

    /// The subdivision level L.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The scale `S`.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The fraction `F`.
    pub fn fraction(&self) -> f64 {
        self.fraction
    }

    /// The same displacement with fraction `fraction` in place of `F` (partial displacement
    /// of the transition system).
    pub fn with_fraction(&self, fraction: f64) -> Displacement {
        Displacement {
            fraction,
            ..self.clone()
        }
    }

    /// The displaced micro-vertex `P + N * S * (h(uv) - h_max) * F`, evaluated left to right
    /// in exactly that order.
    #[inline]
    pub fn displace(&self, v: &BaseVertex) -> DVec3 {
        v.position + v.normal * self.scale * (self.height.sample(v.uv) - self.h_max) * self.fraction
    }

    /// `[lo, hi]` bounding the signed offset `S * (h - h_max) * F` for heights in `[h_lo,
    /// h_hi]`, widened by a relative rounding allowance.
    pub(super) fn offset_range(&self, [h_lo, h_hi]: [f64; 2]) -> [f64; 2] {
        let k = self.scale * self.fraction;
        let (x, y) = (k * (h_lo - self.h_max), k * (h_hi - self.h_max));
        let slack = 1e-12 * (x.abs().max(y.abs()) + k.abs());
        [x.min(y) - slack, x.max(y) + slack]
    }
}

/// One micro-triangle of a base triangle: grid position and orientation (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct MicroTriangle {
    /// Grid column of its first vertex (module docs).
    pub i: u32,
    /// Grid row of its first vertex (module docs).
    pub j: u32,
    /// Whether it points up (vertices (i, j), (i + 1, j), (i, j + 1)) or down.
    pub up: bool,
}

impl MicroTriangle {
    /// Its three grid vertices, in the order hits' barycentrics refer to.
    pub fn vertices(&self) -> [[u32; 2]; 3] {
        let (i, j) = (self.i, self.j);
        if self.up {
            [[i, j], [i + 1, j], [i, j + 1]]
        } else {
            [[i + 1, j + 1], [i, j + 1], [i + 1, j]]
        }
    }
}

impl MicroTriangle {
    /// The micro-triangle of a base triangle subdivided `level` times that holds the point
    /// with barycentric weights `barycentric` (of the base triangle's second and third
    /// vertex); a point on an edge between two goes to one of them, a point outside the
    /// base triangle to the nearest along the grid.
    pub fn containing(level: u32, barycentric: DVec2) -> MicroTriangle {
        let n = (1u32 << level) as f64;
        let (x, y) = (barycentric.x * n, barycentric.y * n);
        let last = n - 1.0;
        let i = x.floor().clamp(0.0, last);
        let j = y.floor().clamp(0.0, last - i);
        let up = i + j >= last || (x - i) + (y - j) <= 1.0;
        MicroTriangle {
            i: i as u32,
            j: j as u32,
            up,
        }
    }

    /// The base-triangle barycentrics (of its second and third vertex) of the point with
    /// barycentrics `barycentric` on this micro-triangle, at subdivision `level`.
    pub fn base_barycentric(&self, level: u32, barycentric: DVec2) -> DVec2 {
        let [g0, g1, g2] = self.vertices().map(|[i, j]| DVec2::new(i as f64, j as f64));
        let grid =
            g0 * (1.0 - barycentric.x - barycentric.y) + g1 * barycentric.x + g2 * barycentric.y;
        grid / (1u32 << level) as f64
    }
}

/// The nearest micro-triangle hit: ray parameter, which micro-triangle, and the barycentric
/// weights of its second and third vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MicroHit {
    /// The ray parameter of the hit.
    pub t: f64,
    /// The micro-triangle hit.
    pub triangle: MicroTriangle,
    /// Barycentric weights of the micro-triangle's second and third vertex.
    pub barycentric: DVec2,
}

impl MicroHit {
    /// Whether `self` comes before `other`: nearer, or as near and lower in
    /// [`MicroTriangle`]'s order (so every method picks the same triangle on a shared edge).
    #[inline]
    pub fn before(&self, other: &MicroHit) -> bool {
        self.t < other.t || (self.t == other.t && self.triangle < other.triangle)
    }
}

/// Rays closer than this (the sine of the angle) to a micro-triangle's plane do not hit it.
pub(super) const GRAZING: f64 = 1e-6;

/// Tests `triangle` (displaced positions in its vertex order) against `ray` with
/// [`intersect_triangle`], except that a ray within [`GRAZING`] of the triangle's plane
/// misses it: there, the f64 test's barycentrics and `t` are dominated by rounding and could
/// report a point far from the triangle; such a ray meets the neighbouring micro-triangles.
/// With this rule every reported hit lies within `2e-10` of the distance from the ray origin
/// to the triangle of the triangle itself, which the hierarchy's boxes allow for.
#[inline]
pub(super) fn hit_micro_triangle(
    ray: &Ray,
    triangle: MicroTriangle,
    positions: [DVec3; 3],
) -> Option<MicroHit> {
    let [a, b, c] = positions;
    let area = (b - a).cross(c - a);
    if area.dot(ray.direction).abs() <= GRAZING * area.length() * ray.direction.length() {
        return None;
    }
    let hit = intersect_triangle(ray.origin, ray.direction, positions)?;
    (hit.t >= ray.t_min && hit.t <= ray.t_max).then_some(MicroHit {
        t: hit.t,
        triangle,
        barycentric: hit.barycentric,
    })
}

/// Every micro-vertex of one base triangle, built level by level from the edge each was
/// created on: the reference the hierarchy is tested against, and a tessellation for tests
/// and comparisons (`(2^L + 1)^2` vertices: not for rendering).
#[derive(Debug, Clone)]
pub struct MicroGrid {
    n: u32,
    vertices: Vec<BaseVertex>,
    displaced: Vec<DVec3>,
}

impl MicroGrid {
    /// Every micro-vertex of the base triangle `corners` at the displacement's level, undisplaced
    /// and displaced.
    pub fn new(corners: &[BaseVertex; 3], displacement: &Displacement) -> MicroGrid {
        let n = 1u32 << displacement.level;
        let side = n as usize + 1;
        let index = |i: u32, j: u32| i as usize * side + j as usize;
        let mut vertices = vec![corners[0]; side * side];
        vertices[index(n, 0)] = corners[1];
        vertices[index(0, n)] = corners[2];
        for level in 1..=displacement.level {
            let s = n >> level;
            for i in (0..=n).step_by(s as usize) {
                for j in (0..=n - i).step_by(s as usize) {
                    let (a, b, c) = ((i / s) % 2, (j / s) % 2, ((n - i - j) / s) % 2);
                    let [p, q] = match (a, b, c) {
                        (1, 1, _) => [index(i - s, j + s), index(i + s, j - s)],
                        (1, 0, _) => [index(i - s, j), index(i + s, j)],
                        (0, 1, _) => [index(i, j - s), index(i, j + s)],
                        _ => continue,
                    };
                    vertices[index(i, j)] = vertices[p].midpoint(vertices[q]);
                }
            }
        }
        let displaced = vertices.iter().map(|v| displacement.displace(v)).collect();
        MicroGrid {
            n,
            vertices,
            displaced,
        }
    }

    /// The undisplaced micro-vertex at grid point `(i, j)`.
    pub fn vertex(&self, [i, j]: [u32; 2]) -> BaseVertex {
        self.vertices[i as usize * (self.n as usize + 1) + j as usize]
    }

    /// The displaced micro-vertex at grid point `(i, j)`.
    pub fn displaced(&self, [i, j]: [u32; 2]) -> DVec3 {
        self.displaced[i as usize * (self.n as usize + 1) + j as usize]
    }

    /// All `4^L` micro-triangles.
    pub fn triangles(&self) -> impl Iterator<Item = MicroTriangle> + '_ {
        let n = self.n;
        (0..n).flat_map(move |i| {
            (0..n - i).flat_map(move |j| {
                let up = MicroTriangle { i, j, up: true };
                let down = MicroTriangle { i, j, up: false };
                std::iter::once(up).chain((i + j + 2 <= n).then_some(down))
            })
        })
    }

    /// The displaced positions of `triangle`'s vertices.
    pub fn positions(&self, triangle: MicroTriangle) -> [DVec3; 3] {
        triangle.vertices().map(|v| self.displaced(v))
    }

    /// The first micro-triangle hit in the ray's interval, testing every one: the reference.
    pub fn intersect(&self, ray: &Ray) -> Option<MicroHit> {
        let mut best: Option<MicroHit> = None;
        for triangle in self.triangles() {
            if let Some(hit) = hit_micro_triangle(ray, triangle, self.positions(triangle)) {
                if best.is_none_or(|b| hit.before(&b)) {
                    best = Some(hit);
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests;
