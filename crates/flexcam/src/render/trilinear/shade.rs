//! Deferred shading of each pixel's winning fragment, after the exact per-fragment hit of
//! [`super::resolve`].
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
//! rounding, see `render::shading::triangle_color`).
//! Pixels of projection triangles with an unprojectable pair are ray cast entirely.

use glam::{DVec3, Vec2, Vec3};

use super::gbuffer::GBuffer;
use super::resolve::{Resolver, CRACK_FILL_DEPTH};
use crate::geometry::Ray;
use crate::projection::{Projection, Trilinear};
use crate::render::prepared::{Hit, PreparedScene};
use crate::render::scan::{FrameRows, NO_PRIMITIVE};
use crate::render::shading::trace::HitShader;
use crate::render::shading::triangle_color::TriangleColor;
use crate::render::RenderOptions;

/// Pixels of a run shaded together by [`Shader::flat_run`] (the bits of a `u64`).
const CHUNK: usize = 64;

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
    /// ([`Shader::flat_run`]); a run without a flat colour (lit, or a mirror or glass) is
    /// shaded four neighbours at a time ([`Shader::traced_run`]). With fallback projection
    /// triangles every pixel is shaded on its own ([`Shader::pixel`]).
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
                        None => self.traced_run(drawn, &run, &mut out),
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

    /// The pixels of `run` (no fallback) shaded as [`Shader::pixel`] shades them, four
    /// neighbours at a time: the exact winners of a group are handed together to
    /// [`HitShader::shade_hits4`], which gives each the colour and ray count
    /// [`PreparedScene::shade_hit`] gives it and traces their shadow rays towards each
    /// light as one packet (neighbours on one scene triangle send nearly parallel shadow
    /// rays through the same nodes of the scene's hierarchy). Crack fillers and pixels
    /// without a projector go through [`Shader::pixel`] one by one.
    fn traced_run(&self, drawn: &GBuffer, run: &Run, out: &mut FrameRows<'_>) -> ShadeCounts {
        let k_triangle = run.triangle();
        let owner = self.resolver.scene.owners[k_triangle];
        let map = self.resolver.map(run.projection());
        let mut counts = ShadeCounts::default();
        for group in (0..run.len).step_by(4) {
            let lanes = (run.len - group).min(4);
            let mut traced: [Option<(Ray, Hit, f32)>; 4] = [None; 4];
            for (lane, slot) in traced.iter_mut().enumerate().take(lanes) {
                let k = group + lane;
                let (i, x) = (run.first + k, run.x0 + k as u32);
                let t = drawn.depth[i];
                let projector = map
                    .filter(|_| t < CRACK_FILL_DEPTH)
                    .and_then(|map| map.projector(self.resolver.position(x, run.y)));
                match projector {
                    Some(projector) => {
                        let hit = owner.hit(t, Vec2::from(drawn.barycentrics[i]));
                        let depth = (t * projector.direction.length()) as f32;
                        *slot = Some((projector.ray(), hit, depth));
                    }
                    None => {
                        let p = self.pixel(drawn, i, x, run.y, false);
                        counts = counts + run.write(out, k, p);
                    }
                }
            }
            if traced.iter().all(Option::is_none) {
                continue;
            }
            let mut shader = HitShader::new(self.prepared, self.options);
            let lane = |k: usize| traced[k].as_ref().map(|(ray, hit, _)| (ray, *hit));
            let colors = shader.shade_hits4([lane(0), lane(1), lane(2), lane(3)]);
            for (k, (traced, color)) in traced.iter().zip(colors).enumerate() {
                if let Some((_, _, depth)) = traced {
                    let pixel = Pixel {
                        color,
                        depth: *depth,
                        id: owner.id,
                        counts: ShadeCounts::default(),
                    };
                    run.write(out, group + k, pixel);
                }
            }
            counts.shading_rays += shader.counts.secondary + shader.counts.shadow;
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
        let Some(map) = self.resolver.map(run.projection()) else {
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
            let projector = self.resolver.triangles[(key >> 32) as usize]
                .map
                .projector(position)?;
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
            None => self
                .prepared
                .shade_hit_lazy(ray, owner.hit(t, barycentric), self.options),
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
