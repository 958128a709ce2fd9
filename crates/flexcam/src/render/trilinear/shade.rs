//! From rasterised coverage to the final frame: the exact per-fragment hit (the stage run
//! before the z-test) and the deferred shading of each pixel's winning fragment.
//!
//! A fragment's key names its projection triangle and scene triangle. Its depth and scene
//! barycentrics are not interpolated over the polygon (the map from screen to scene is not
//! affine, so interpolation would be wrong inside every curved shape): the pixel sample's
//! projector is intersected with the scene triangle's plane, in f64. The polygon's vertices
//! carry the terms of that intersection that are affine in pixel position ([`super::hit_terms`]),
//! so the rasteriser hands each fragment the terms of its own projector and the stage finishes
//! the hit with a division ([`super::gbuffer::GBuffer::draw`]). Only a fragment outside its
//! own triangle takes the general path, which builds the projector and intersects it with
//! the neighbours ([`Resolver::hit`]).
//!
//! - Inside the triangle at `t >= 0`: an **exact** fragment; the z-test compares exact ray
//!   parameters `t`, and the frame's depth is `t |trinorm|`, the distance the ray caster
//!   writes for the same projector.
//! - Outside it across an edge no other triangle shares (a silhouette): discarded, so a
//!   chord that bulges outside the true curved edge draws nothing wrong.
//! - Outside it only across edges another triangle shares, inside the **neighbour** across
//!   one of them: an exact fragment of the neighbour (its key is rewritten). Where a chord
//!   cuts inside a curved edge, the pixels between chord and curve belong to the neighbour,
//!   whose own polygon misses them, while this triangle's chord bulges over them.
//! - Outside it only across shared edges and outside those neighbours too (a pixel near a
//!   vertex where several triangles meet): a **crack filler**, shaded at the nearest point
//!   of the triangle (barycentrics clamped) with its depth pushed behind every exact
//!   fragment (`+ CRACK_FILL_DEPTH`), so that it never hides an exact fragment.
//!   Before the neighbour step the fillers did all of this, and where the true surface's
//!   pixel was left to a filler, a farther surface's exact fragment (the far side of the
//!   same object) won it: 4 such pixels in scenes/trilinear-fan.toml.
//! - Behind the view plane, or a projector parallel to the plane: discarded.
//!
//! Shading is deferred to one pass over the pixels, so that each pixel is shaded once. The
//! rasteriser's target is the band's G-buffer ([`super::gbuffer`]): its depth is the winner's
//! exact `t`, its key the triangle hit, and its barycentrics the winner's scene
//! barycentrics, so an exact winner is shaded without intersecting again (a
//! crack filler, whose depth was pushed back, is resolved again). The hit is handed to
//! [`PreparedScene::shade_hit`], which shades it exactly as the ray caster
//! does (flat: base colour, mirrors and glass passing the ray on; lit: lights, hard shadows,
//! reflection and refraction, all traced by the ray caster from the rasterised first hit),
//! except for flat shading of a surface that shows its base colour: that colour is read from
//! the scene triangle's [`TriangleColor`], prepared once per renderer (a few multiply-adds a
//! pixel instead of `base_color`'s transform and divisions; the same colours up to `f32`
//! rounding, see `render::surface::triangle_color`).
//! Pixels of projection triangles with an unprojectable pair are ray cast entirely.

use glam::{DVec2, DVec3, Vec2, Vec3};

use super::gbuffer::GBuffer;
use super::hit_terms;
use super::scene_geometry::SceneGeometry;
use super::screen_map::ScreenMap;
use crate::geometry::Ray;
use crate::projection::{Projection, Trilinear};
use crate::render::prepared::{Hit, PreparedScene};
use crate::render::scan::{FrameRows, NO_PRIMITIVE};
use crate::render::surface::triangle_color::TriangleColor;
use crate::render::RenderOptions;

/// Pixels of a run shaded together by [`Shader::flat_run`] (the bits of a `u64`).
const CHUNK: usize = 64;

/// Added to the depth of crack fillers: behind any exact fragment (depths are ray
/// parameters, far below this for any scene within the rasteriser's limits).
const CRACK_FILL_DEPTH: f64 = 1e200;

/// Finds the hit of a keyed fragment (module doc).
pub struct Resolver<'a> {
    pub maps: &'a [ScreenMap],
    pub scene: &'a SceneGeometry,
    /// Where in each pixel this pass samples, in `[0, 1)^2` (`(0.5, 0.5)`: the centre). The
    /// polygons of the pass are drawn moved so that their pixel centres are these samples
    /// (see `PolygonBatch::translated`).
    pub sample: DVec2,
}

/// A fragment's hit: the projector, the key of the triangle hit (the fragment's own, or a
/// neighbour's), the ray parameter, the barycentrics (clamped into the triangle for a crack
/// filler) and whether it is exact.
#[derive(Debug, Clone, Copy)]
pub struct FragmentHit {
    pub ray: Ray,
    pub key: u64,
    pub t: f64,
    pub barycentric: DVec2,
    pub exact: bool,
}

impl Resolver<'_> {
    /// The image position of pixel `(x, y)`'s sample.
    pub fn position(&self, x: u32, y: u32) -> DVec2 {
        DVec2::new(f64::from(x), f64::from(y)) + self.sample
    }

    /// The hit of the projector through pixel position `pixel` of the projection triangle
    /// named by `key` with the scene triangle named by `key`, or with a neighbour of it
    /// (module doc); `None` for a discarded fragment.
    pub fn hit(&self, key: u64, pixel: DVec2) -> Option<FragmentHit> {
        let map = self.maps.get((key >> 32) as usize)?;
        let k = (key & u64::from(u32::MAX)) as usize;
        let ray = map.ray(pixel)?;
        let (t, u, v) = plane_hit(&ray, self.scene.corners(k))?;
        if t < 0.0 {
            return None;
        }
        let outside = outside_edges(u, v);
        if outside == 0 {
            return Some(FragmentHit {
                ray,
                key,
                t,
                barycentric: DVec2::new(u, v),
                exact: true,
            });
        }
        if outside & !self.scene.shared_edges[k] != 0 {
            return None;
        }
        // Across a shared edge: the pixel may be the neighbour's, missed by the neighbour's
        // own polygon where its chord cuts inside the curved edge.
        // Where several triangles meet at the edge (non-manifold), each is tried in turn.
        for edge in (0..3).filter(|e| outside & (1 << e) != 0) {
            for n in self.scene.across(k, edge) {
                let Some((t, u, v)) = plane_hit(&ray, self.scene.corners(n)) else {
                    continue;
                };
                if t >= 0.0 && outside_edges(u, v) == 0 {
                    return Some(FragmentHit {
                        ray,
                        key: (key & !u64::from(u32::MAX)) | n as u64,
                        t,
                        barycentric: DVec2::new(u, v),
                        exact: true,
                    });
                }
            }
        }
        Some(FragmentHit {
            ray,
            key,
            t,
            barycentric: clamp_to_triangle(u, v),
            exact: false,
        })
    }

    /// The stage of the rasteriser for a fragment of the shape keyed `key` at pixel
    /// `(x, y)` whose hit terms there solve to `solved` ([`super::hit_terms::solve`], not
    /// yet tested for finite values): the key of the triangle hit (its own, or a
    /// neighbour's), its depth (the exact `t`, pushed back for a crack filler) and the hit's
    /// barycentrics; `None` to discard it (module doc, [`Stage::of`]).
    #[inline]
    pub fn staged(
        &self,
        key: u64,
        solved: (f64, f64, f64),
        x: u32,
        y: u32,
    ) -> Option<(u64, f64, DVec2)> {
        let (t, b1, b2) = solved;
        match Stage::of(solved) {
            Stage::Exact => Some((key, t, DVec2::new(b1, b2))),
            Stage::Discarded => None,
            Stage::Outside => self.hit(key, self.position(x, y)).map(|hit| {
                let behind = if hit.exact { 0.0 } else { CRACK_FILL_DEPTH };
                (hit.key, hit.t + behind, hit.barycentric)
            }),
        }
    }
}

/// What the stage does with a fragment's solved hit `(t, b1, b2)` (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Finite, `t >= 0`, inside its triangle (boundary included): kept as it is.
    Exact,
    /// A value not finite (a projector parallel to the plane), or behind the view plane.
    Discarded,
    /// Finite, in front, outside its triangle: resolved by [`Resolver::hit`].
    Outside,
}

impl Stage {
    /// The common case, an exact fragment, is decided first by one test of five
    /// comparisons without branches between them: `0 <= t < inf`, `b1 >= 0`, `b2 >= 0` and
    /// `b1 + b2 <= 1` hold for finite values exactly where `t >= 0` and [`outside_edges`]
    /// is 0, and fail for any NaN or infinity (every comparison with NaN is false, and an
    /// infinite `b1` or `b2` makes the sum infinite or NaN).
    #[inline(always)]
    fn of((t, b1, b2): (f64, f64, f64)) -> Stage {
        let in_front = (0.0..f64::INFINITY).contains(&t);
        if in_front & (b1 >= 0.0) & (b2 >= 0.0) & (b1 + b2 <= 1.0) {
            return Stage::Exact;
        }
        match hit_terms::finite((t, b1, b2)) {
            Some((t, _, _)) if t >= 0.0 => Stage::Outside,
            _ => Stage::Discarded,
        }
    }
}

/// Where `ray` meets the plane of triangle `[a, b, c]`: `(t, u, v)` with `u`, `v` the
/// barycentrics of `b` and `c`, unbounded (Moller-Trumbore without the inside tests).
/// `None` for a projector parallel to the plane, a degenerate triangle or non-finite input.
fn plane_hit(ray: &Ray, [a, b, c]: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let q = s.cross(e1);
    let (u, v, t) = (s.dot(p) * inv, ray.direction.dot(q) * inv, e2.dot(q) * inv);
    (det != 0.0 && u.is_finite() && v.is_finite() && t.is_finite()).then_some((t, u, v))
}

/// The edges of a triangle that a point with barycentrics `(u, v)` lies beyond, as bits of
/// `<V1V2, V1V3, V2V3>`: `v < 0` is beyond V1V2, `u < 0` beyond V1V3, `u + v > 1` beyond
/// V2V3. 0 for a point inside or on the boundary.
fn outside_edges(u: f64, v: f64) -> u8 {
    u8::from(v < 0.0) | (u8::from(u < 0.0) << 1) | (u8::from(u + v > 1.0) << 2)
}

/// The barycentrics of the point of the triangle nearest (in barycentric space) to `(u, v)`.
fn clamp_to_triangle(u: f64, v: f64) -> DVec2 {
    let (u, v) = (u.max(0.0), v.max(0.0));
    let sum = u + v;
    if sum > 1.0 {
        DVec2::new(u / sum, v / sum)
    } else {
        DVec2::new(u, v)
    }
}

/// Rays cast while shading.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShadeCounts {
    /// Secondary and shadow rays of shading rasterised hits.
    pub shading_rays: u64,
    /// Primary rays cast for pixels of fallback projection triangles.
    pub fallback_rays: u64,
}

impl std::ops::Add for ShadeCounts {
    type Output = ShadeCounts;

    fn add(self, o: ShadeCounts) -> ShadeCounts {
        ShadeCounts {
            shading_rays: self.shading_rays + o.shading_rays,
            fallback_rays: self.fallback_rays + o.fallback_rays,
        }
    }
}

/// Everything the shading pass reads.
pub struct Shader<'a> {
    pub resolver: Resolver<'a>,
    pub prepared: &'a PreparedScene,
    pub projection: &'a Trilinear,
    pub options: &'a RenderOptions<'a>,
    /// Per projection triangle: ray cast its pixels instead.
    pub fallback: &'a [bool],
    pub background: Vec3,
    /// With flat shading, per scene triangle, its base colour where flat shading shows it
    /// (`None` for mirrors and glass, shaded by the ray caster): read instead of the ray
    /// caster's per-hit `base_color`. `None` for lit shading.
    pub flat_colors: Option<&'a [Option<TriangleColor>]>,
}

/// One pixel's output.
#[derive(Clone, Copy)]
struct Pixel {
    color: Vec3,
    depth: f32,
    id: u32,
    counts: ShadeCounts,
}

/// A run of pixels `x0..x0 + len` of row `y` won by the same `key`, starting at index
/// `first` of the band (and of its rows of the frame).
struct Run {
    key: u64,
    y: u32,
    x0: u32,
    first: usize,
    len: usize,
}

impl Run {
    /// The projection triangle of the key.
    fn projection(&self) -> usize {
        (self.key >> 32) as usize
    }

    /// The scene triangle of the key.
    fn triangle(&self) -> usize {
        (self.key & u64::from(u32::MAX)) as usize
    }

    /// Writes the background into every pixel of the run. The colours are written four at a
    /// time (three 16-byte stores instead of four 12-byte ones).
    fn fill(&self, out: &mut FrameRows<'_>, background: Vec3) {
        let cells = self.first..self.first + self.len;
        let mut quads = out.color[cells.clone()].chunks_exact_mut(4);
        let quad = [background; 4];
        for colors in &mut quads {
            colors.copy_from_slice(&quad);
        }
        quads.into_remainder().fill(background);
        out.depth[cells.clone()].fill(f32::INFINITY);
        out.ids[cells].fill(0);
    }

    /// Writes pixel `k` of the run; returns its ray counts.
    fn write(&self, out: &mut FrameRows<'_>, k: usize, p: Pixel) -> ShadeCounts {
        let i = self.first + k;
        (out.color[i], out.depth[i], out.ids[i]) = (p.color, p.depth, p.id);
        p.counts
    }
}

impl Shader<'_> {
    /// Shades the drawn band `drawn` into the same rows `out` of the frame, every pixel of
    /// them written.
    ///
    /// Each row is walked in runs of pixels won by the same key: a run of background is
    /// filled at once, and a run of one triangle seen through one projection triangle looks
    /// up its map, owner and colour once and walks its projector directions along the row
    /// ([`Shader::flat_run`]). With fallback projection triangles every pixel is shaded on
    /// its own ([`Shader::pixel`]).
    pub fn rows(&self, drawn: &GBuffer, mut out: FrameRows<'_>) -> ShadeCounts {
        let any_fallback = self.fallback.iter().any(|&f| f);
        let (width, rows) = (drawn.width() as usize, drawn.rows());
        let mut counts = ShadeCounts::default();
        for (row, y) in (rows.0..rows.1).enumerate() {
            let keys = &drawn.keys[row * width..(row + 1) * width];
            let mut x0 = 0;
            while x0 < width {
                let key = keys[x0];
                let x1 = x0 + 1 + keys[x0 + 1..].iter().take_while(|&&k| k == key).count();
                let run = Run {
                    key,
                    y,
                    x0: x0 as u32,
                    first: row * width + x0,
                    len: x1 - x0,
                };
                let flat = self
                    .flat_colors
                    .and_then(|colors| colors.get(run.triangle())?.as_ref());
                counts = counts
                    + match flat {
                        _ if any_fallback => self.pixels(drawn, &run, &mut out, true),
                        _ if key == NO_PRIMITIVE => {
                            run.fill(&mut out, self.background);
                            ShadeCounts::default()
                        }
                        Some(color) => self.flat_run(drawn, &run, &mut out, color),
                        None => self.pixels(drawn, &run, &mut out, false),
                    };
                x0 = x1;
            }
        }
        counts
    }

    /// The pixels of `run` shaded one by one ([`Shader::pixel`]); `any_fallback`: whether
    /// any projection triangle is ray cast.
    fn pixels(
        &self,
        drawn: &GBuffer,
        run: &Run,
        out: &mut FrameRows<'_>,
        any_fallback: bool,
    ) -> ShadeCounts {
        let mut counts = ShadeCounts::default();
        for k in 0..run.len {
            let x = run.x0 + k as u32;
            let pixel = self.pixel(drawn, run.first + k, x, run.y, any_fallback);
            counts = counts + run.write(out, k, pixel);
        }
        counts
    }

    /// Pixel `(x, y)` at index `i` of the band `drawn`: ray cast in a fallback projection
    /// triangle (looked up only if `any_fallback`), else its winning fragment shaded, else
    /// background.
    fn pixel(&self, drawn: &GBuffer, i: usize, x: u32, y: u32, any_fallback: bool) -> Pixel {
        let key = drawn.keys[i];
        // An exact fragment comes from a polygon clipped to its projection triangle's
        // domain, so the pixel lies in that triangle (up to the clipping margin, where a
        // continuous mesh's neighbours share their rays): only where that triangle falls
        // back, or where no exact fragment won, is the pixel's triangle looked up.
        let exact = key != NO_PRIMITIVE && drawn.depth[i] < CRACK_FILL_DEPTH;
        let lookup = any_fallback && (!exact || self.fallback[(key >> 32) as usize]);
        let pixel = if lookup && self.in_fallback(x, y) {
            self.cast(x, y)
        } else if key == NO_PRIMITIVE {
            None
        } else {
            let barycentric = Vec2::from(drawn.barycentrics[i]);
            self.rasterised(key, drawn.depth[i], barycentric, x, y)
        };
        pixel.unwrap_or(Pixel {
            color: self.background,
            depth: f32::INFINITY,
            id: 0,
            counts: ShadeCounts::default(),
        })
    }

    /// The pixels of `run` (a triangle of flat colour `color`, no fallback) shaded as
    /// [`Shader::pixel`] shades them, with the map, owner and colour looked up once and the
    /// projector's direction (for the depth `t |trinorm|`) stepped along the row
    /// ([`ScreenMap::directions_along_row`]). A crack filler is resolved
    /// again ([`Shader::rasterised`]). Degenerate case: where the stepped direction is zero
    /// (a projector of zero `trinorm`, which [`ScreenMap::projector`] refuses), the pixel
    /// is background, as [`Shader::pixel`] leaves it.
    /// With the affine map the directions are not divided by their weight of 1
    /// ([`super::screen_map::RowDirections::unit_weight`], the same bits).
    #[inline]
    fn flat_run(
        &self,
        drawn: &GBuffer,
        run: &Run,
        out: &mut FrameRows<'_>,
        color: &TriangleColor,
    ) -> ShadeCounts {
        let Some(map) = self.resolver.maps.get(run.projection()) else {
            return self.pixels(drawn, run, out, false);
        };
        let directions = map.directions_along_row(self.resolver.position(run.x0, run.y));
        match directions.unit_weight() {
            Some(unit) => self.flat_run_along(drawn, run, out, color, |k| unit.at(k)),
            None => self.flat_run_along(drawn, run, out, color, |k| directions.at(k)),
        }
    }

    /// [`Shader::flat_run`] with the projector direction of the run's pixel `k` given by
    /// `direction(k)`. The run is shaded in chunks of [`CHUNK`] pixels: colours
    /// ([`TriangleColor::fill`], a chunk at once), ids and the squared lengths of the
    /// directions first, then all the chunk's depths
    /// `t |direction|` in one loop without branches (compiled to two square roots an
    /// instruction: the square root is the shading's largest single cost), then the pixels
    /// that need more (crack fillers, a zero direction) through [`Shader::pixel`], which
    /// overwrites all three. Each pixel's operations are those of shading it on its own.
    #[inline(always)]
    fn flat_run_along(
        &self,
        drawn: &GBuffer,
        run: &Run,
        out: &mut FrameRows<'_>,
        color: &TriangleColor,
        direction: impl Fn(u32) -> DVec3,
    ) -> ShadeCounts {
        let id = self.resolver.scene.owners[run.triangle()].id;
        let mut counts = ShadeCounts::default();
        for chunk in (0..run.len).step_by(CHUNK) {
            let cells = run.first + chunk..run.first + run.len.min(chunk + CHUNK);
            let ts = &drawn.depth[cells.clone()];
            let mut length_squared = [0.0; CHUNK];
            // Bit `k`: pixel `chunk + k` is shaded by `Shader::pixel`.
            let mut others = 0u64;
            // Every colour of the chunk; `Shader::pixel` overwrites those of the others.
            color.fill(
                &drawn.barycentrics[cells.clone()],
                &mut out.color[cells.clone()],
            );
            let pixels = ts
                .iter()
                .zip(&mut out.ids[cells.clone()])
                .zip(&mut length_squared);
            for (k, ((&t, out_id), length_squared)) in pixels.enumerate() {
                let direction = direction((chunk + k) as u32);
                if t < CRACK_FILL_DEPTH && direction != DVec3::ZERO {
                    *out_id = id;
                } else {
                    others |= 1 << k;
                }
                *length_squared = direction.length_squared();
            }
            for ((out_depth, &t), &length_squared) in out.depth[cells.clone()]
                .iter_mut()
                .zip(ts)
                .zip(&length_squared)
            {
                *out_depth = (t * length_squared.sqrt()) as f32;
            }
            while others != 0 {
                let k = chunk + others.trailing_zeros() as usize;
                others &= others - 1;
                let p = self.pixel(drawn, run.first + k, run.x0 + k as u32, run.y, false);
                counts = counts + run.write(out, k, p);
            }
        }
        counts
    }

    fn in_fallback(&self, x: u32, y: u32) -> bool {
        self.projection
            .locate(self.resolver.position(x, y))
            .is_some_and(|(triangle, _, _)| self.fallback[triangle])
    }

    /// Pixel `(x, y)`'s winning fragment (`key`, G-buffer depth and barycentrics), shaded. An exact winner is read from the G-buffer (module doc) and its projector's
    /// origin is built only if shading needs the ray (`PreparedScene::shade_hit_lazy`); a crack
    /// filler is resolved again. `None` where there is no hit after all (no projector).
    #[inline]
    fn rasterised(&self, key: u64, depth: f64, barycentric: Vec2, x: u32, y: u32) -> Option<Pixel> {
        let position = self.resolver.position(x, y);
        if depth < CRACK_FILL_DEPTH {
            let projector = self.resolver.maps[(key >> 32) as usize].projector(position)?;
            Some(
                self.shaded(key, depth, barycentric, projector.direction, || {
                    projector.ray()
                }),
            )
        } else {
            let found = self.resolver.hit(key, position)?;
            let ray = found.ray;
            let barycentric = found.barycentric.as_vec2();
            Some(self.shaded(found.key, found.t, barycentric, ray.direction, || ray))
        }
    }

    /// The hit at ray parameter `t` and `barycentric` of the scene triangle named by `key`
    /// on the projector along `direction`, shaded (flat: from [`Shader::flat_colors`]
    /// where it has the triangle); `ray` builds the whole projector.
    #[inline]
    fn shaded(
        &self,
        key: u64,
        t: f64,
        barycentric: Vec2,
        direction: DVec3,
        ray: impl FnOnce() -> Ray,
    ) -> Pixel {
        let k = (key & u64::from(u32::MAX)) as usize;
        let owner = self.resolver.scene.owners[k];
        let flat = self.flat_colors.and_then(|colors| colors[k].as_ref());
        let (color, rays) = match flat {
            Some(color) => (color.at(barycentric), 0),
            None => {
                let hit = Hit {
                    t,
                    object: owner.object as usize,
                    triangle: owner.triangle as usize,
                    barycentric,
                };
                self.prepared.shade_hit_lazy(ray, hit, self.options)
            }
        };
        Pixel {
            color,
            depth: (t * direction.length()) as f32,
            id: owner.id,
            counts: ShadeCounts {
                shading_rays: rays,
                fallback_rays: 0,
            },
        }
    }

    /// The pixel ray cast like the reference renderer does it.
    fn cast(&self, x: u32, y: u32) -> Option<Pixel> {
        let ray = self.projection.ray(self.resolver.position(x, y))?;
        let counts = ShadeCounts {
            shading_rays: 0,
            fallback_rays: 1,
        };
        let Some(hit) = self.prepared.intersect(&ray) else {
            return Some(Pixel {
                color: self.background,
                depth: f32::INFINITY,
                id: 0,
                counts,
            });
        };
        let (color, rays) = self.prepared.shade_hit(&ray, hit, self.options);
        Some(Pixel {
            color,
            depth: (hit.t * ray.direction.length()) as f32,
            id: self.resolver.scene.object_ids[hit.object],
            counts: ShadeCounts {
                shading_rays: rays,
                ..counts
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// [`Stage::of`] as the stage decided it before the single test: finite values first,
    /// then `t >= 0` and [`outside_edges`].
    fn stage_in_order(solved: (f64, f64, f64)) -> Stage {
        match hit_terms::finite(solved) {
            Some((t, b1, b2)) if t >= 0.0 && outside_edges(b1, b2) == 0 => Stage::Exact,
            Some((t, _, _)) if t < 0.0 => Stage::Discarded,
            None => Stage::Discarded,
            Some(_) => Stage::Outside,
        }
    }

    /// Values at and around the tests' boundaries, and the non-finite ones.
    const SPECIAL: [f64; 16] = [
        0.0,
        -0.0,
        5e-324,
        -5e-324,
        0.5,
        0.5 + f64::EPSILON / 2.0,
        1.0,
        1.0 + f64::EPSILON,
        1.0 - f64::EPSILON / 2.0,
        -1.0,
        2.0,
        f64::MAX,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];

    #[test]
    fn one_test_stages_as_the_tests_in_order_on_special_values() {
        let mut seen = [false; 3];
        for t in SPECIAL {
            for b1 in SPECIAL {
                for b2 in SPECIAL {
                    let stage = stage_in_order((t, b1, b2));
                    assert_eq!(Stage::of((t, b1, b2)), stage, "{t} {b1} {b2}");
                    seen[stage as usize] = true;
                }
            }
        }
        assert_eq!(seen, [true; 3]);
    }

    proptest! {
        #[test]
        fn one_test_stages_as_the_tests_in_order(
            t in prop_oneof![-2.0..2.0f64, proptest::num::f64::ANY],
            b1 in prop_oneof![-0.5..1.5f64, proptest::num::f64::ANY],
            b2 in prop_oneof![-0.5..1.5f64, proptest::num::f64::ANY],
        ) {
            prop_assert_eq!(Stage::of((t, b1, b2)), stage_in_order((t, b1, b2)));
        }
    }
}
