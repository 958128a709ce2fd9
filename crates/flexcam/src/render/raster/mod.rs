//! `--method raster`: rasterisation of nonlinear projections by their analytic inverse
//! (Brosz 2011, 7.3 and 9.4).
//!
//! Per frame:
//! 1. every scene vertex is projected once through the projection's continuous inverse
//!    ([`crate::projection::ContinuousInverse`], looked up once per renderer; the per-vertex
//!    cache shared by the triangles around it);
//! 2. each triangle is clipped in 3D to the chart's half-spaces (`clip`), cut by the
//!    uniform grid and refined adaptively (`refine`) until the straight polygon of each
//!    piece's projected corners follows its curved image within the tolerance;
//! 3. each piece is placed on the screen (`seam`): unwrapped across a panorama's seam and
//!    drawn once more on the other side when it straddles it; pieces around a pole are
//!    dropped (they cover no pixel centre), and so are pieces whose screen box holds no
//!    pixel centre (most pieces of a finely tessellated model); the others are sorted into
//!    bands of rows by the parallel job that built them (`coverage::Bins`);
//! 4. the bands are filled in parallel by the polygon rasteriser's fill and tie rule
//!    specialised to triangles (`coverage::cover`); each fragment reconstructs its exact
//!    depth and barycentrics once from its pixel's projector (`fragment`; the projectors
//!    are computed on first use and kept for later frames, `pixel_rays`);
//! 5. each band's visible fragments are shaded once, from that reconstruction, straight
//!    into the frame (`band_fill`), so depth and shading are the ray caster's and only
//!    coverage near silhouettes depends on the subdivision.
//!
//! Shading: flat base colours are computed here; lit shading (lights and shadows) and the
//! secondary rays of mirrors and glass are delegated, per visible pixel, to the ray caster's
//! own shading of the reconstructed hit ([`PreparedScene::shade_hit`]), so a BVH is built when
//! the render needs one; the rays it casts are counted (`shading_rays`). One sample per
//! pixel (`--spp 1`).
//!
//! An [`InverseRaster`] is meant to render many frames of one projection (an animation of
//! the scene, an interactive viewer): the pixel projectors, the BVH, the bins and the
//! z-buffer are kept between frames, and [`InverseRaster::render_into`] reuses the caller's
//! frame. When it is dropped, its z-buffer, bins and projector tiles are left with the
//! prepared scene ([`PreparedScene::keep_spare`]) for the next renderer of that scene, so
//! frames of a projection that changes every frame (a viewer's drag) reuse that memory
//! too, their projectors being computed again into it.
//!
//! Supported: every projection with an `InverseChart` (perspective, orthographic,
//! fisheye, equirectangular, cylindrical, and the flexible volumes described in
//! `projection::flexible::chart`), and projections made of such views (the stereo pairs,
//! drawn view by view: `views`); others are refused with one line naming the projection.

mod band_fill;
mod clip;
mod coverage;
#[cfg(test)]
mod flexible_maps_tests;
mod fragment;
mod kept;
mod kept_coordinates;
mod pixel_rays;
mod pole_clearance;
mod refine;
mod seam;
mod subdivision;
#[cfg(test)]
mod tests;
mod views;
// Bench scenes, for `flexcam bench` and the criterion benches only (`bench_support`).
#[cfg(any(test, feature = "workloads"))]
pub mod workloads;

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use glam::DVec2;
use rayon::prelude::*;

pub use subdivision::Subdivision;
pub use views::render;

use self::band_fill::{fill_and_shade, BAND_ROWS};
use self::coverage::{Bins, ScreenTriangle};
use self::fragment::{key, Shader, Visible};
use self::kept_coordinates::KeptCoordinates;
use self::pixel_rays::{PixelRays, Tile};
use self::pole_clearance::PoleClearance;
use self::refine::{Node, Refiner};
use self::seam::{covers_a_centre, place, Placement};
use crate::error::{Error, Result};
use crate::projection::{Charted, NoInverse, Projection};
use crate::render::prepared::PreparedScene;
use crate::render::{Counter, Frame, RenderOptions, Shading, Stats};
use crate::scene::{Finish, Scene};

/// Scene triangles per parallel task when building pieces.
const CHUNK: usize = 2048;

/// A scene and a projection prepared for rasterisation: the chart, the pixel projectors
/// (filled in as frames need them), the buffers frames reuse and, when shading needs rays,
/// the prepared scene they are traced through.
pub struct InverseRaster<'a> {
    prepared: &'a PreparedScene,
    scene: &'a Scene,
    projection: &'a dyn Projection,
    /// The projection's continuous inverse and its chart, looked up once.
    inverse: Charted<'a>,
    rays: PixelRays<'a>,
    caster: Option<&'a PreparedScene>,
    options: RenderOptions<'a>,
    setup_ms: f64,
    /// The buffers of a frame, kept from frame to frame (cleared, not reallocated).
    buffers: Mutex<Buffers>,
    /// A recycled frame ([`recycle_frame`]) for [`InverseRaster::render`].
    spare_frame: Mutex<Option<Frame>>,
}

/// The memory a renderer leaves for the next renderer of the same prepared scene.
#[derive(Default)]
struct Spare {
    buffers: Buffers,
    tiles: Vec<Tile>,
    /// A frame its caller is done with ([`recycle_frame`]), for the next
    /// [`InverseRaster::render`] to draw into.
    frame: Option<Frame>,
}

/// Leaves `frame`, one its caller is done with (a viewer's preview, once shown), for the
/// next raster render of `prepared` to draw into: a sequence of frames (a viewer's drag)
/// then does not allocate and page-fault a frame every time (18 bytes a pixel with depth
/// and ids; a frame rendered for colour alone brings back its colour buffer). Every pixel of
/// it is overwritten. Dropped when a renderer of the scene is running (it keeps its own
/// memory) or leaves its memory after this.
pub fn recycle_frame(prepared: &PreparedScene, frame: Frame) {
    let mut spare = prepared.take_spare::<Spare>().unwrap_or_default();
    spare.frame = Some(frame);
    prepared.keep_spare(spare);
}

/// What a frame writes besides the caller's frame, kept by the renderer.
#[derive(Debug, Default)]
struct Buffers {
    /// The image of every scene vertex, per object (`None` on the singular set).
    images: Vec<Vec<Option<DVec2>>>,
    /// The screen triangles of each piece-building job, sorted into bands.
    bins: Vec<Bins>,
    /// Each pixel's visible fragment.
    zbuffer: Vec<Visible>,
    /// Which scene triangles are far from the poles, while the poles stay put.
    clearance: PoleClearance,
    /// The first stage of a staged inverse per vertex, while its key stays the same.
    coordinates: KeptCoordinates,
}

/// What piece building did, for `--stats`.
#[derive(Debug, Clone, Copy, Default)]
struct PieceCounts {
    /// Scene triangles clipped by a chart half-space (partly or wholly outside).
    clipped: u64,
    /// Scene triangles that `Refiner::far_from_poles` does not clear, refined and tested
    /// with the pole rule (the others are proven to need neither).
    near_poles: u64,
    /// Pieces after subdivision.
    pieces: u64,
    /// Pieces crossed by a pole or lying within its clearance, dropped.
    pole_pieces: u64,
    /// Pieces with a corner on the singular set (an eye, a pole), dropped.
    singular: u64,
    /// Pieces whose outline winds around a pole, dropped.
    winding: u64,
    /// Screen triangles whose box holds no pixel centre, dropped before the fill.
    empty: u64,
    /// Screen triangles filled (a seam straddler counts twice).
    drawn: u64,
    /// Screen triangles with a non-finite or huge coordinate, not filled.
    invalid: u64,
}

impl std::ops::AddAssign for PieceCounts {
    fn add_assign(&mut self, o: PieceCounts) {
        self.clipped += o.clipped;
        self.near_poles += o.near_poles;
        self.pieces += o.pieces;
        self.pole_pieces += o.pole_pieces;
        self.singular += o.singular;
        self.winding += o.winding;
        self.empty += o.empty;
        self.drawn += o.drawn;
        self.invalid += o.invalid;
    }
}

/// The one-line refusal of method raster for a projection of `kind` without an inverse.
fn no_inverse(kind: &str, none: NoInverse) -> Error {
    let why = none.reason.map_or_else(
        || {
            ": it maps pixels to rays only, with no inverse from a scene point to its pixel"
                .to_string()
        },
        |reason| format!(": {reason}"),
    );
    Error::new(format!(
        "method raster needs a projection with an analytic inverse; {kind} has none{why} \
         (use --method raycast)"
    ))
}

/// The projection's charted inverse, or the one-line refusal of method raster.
pub fn supported_chart(projection: &dyn Projection) -> Result<Charted<'_>> {
    let kind = projection.kind();
    let inverse = projection
        .inverse()
        .map_err(|none| no_inverse(kind, none))?;
    let charted = inverse.charted().ok_or_else(|| {
        Error::new(format!(
            "method raster needs a projection with an analytic inverse it can fill triangles \
             by; this {kind} projection's inverse is not continuous in a way it handles \
             (see docs/raster.md; use --method raycast)"
        ))
    })?;
    let chart = &charted.chart;
    if chart.clip.len() > clip::MAX_PLANES {
        return Err(Error::new(format!(
            "method raster: {kind} projection clips by {} planes, at most {} are supported \
             (use --method raycast)",
            chart.clip.len(),
            clip::MAX_PLANES
        )));
    }
    Ok(charted)
}

impl Drop for InverseRaster<'_> {
    /// Leaves the z-buffer, bins and projector tiles to the next renderer of the scene.
    fn drop(&mut self) {
        let buffers = std::mem::take(
            self.buffers
                .get_mut()
                .unwrap_or_else(std::sync::PoisonError::into_inner),
        );
        let tiles = self.rays.take_tiles();
        let frame = self
            .spare_frame
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        self.prepared.keep_spare(Spare {
            buffers,
            tiles,
            frame,
        });
    }
}

impl<'a> InverseRaster<'a> {
    /// Prepares `prepared` and `projection` with `options`. Errors: a projection outside
    /// the supported class, an invalid subdivision, more than one sample per pixel.
    pub fn new(
        prepared: &'a PreparedScene,
        projection: &'a dyn Projection,
        options: &RenderOptions<'a>,
    ) -> Result<Self> {
        let inverse = supported_chart(projection)?;
        options.subdivision.validate()?;
        if options.spp != 1 {
            return Err(Error::new(format!(
                "method raster renders one sample per pixel; got --spp {} (use --spp 1, or \
                 --method raycast for more samples)",
                options.spp
            )));
        }
        let start = Instant::now();
        let scene = prepared.scene();
        let spare = prepared.take_spare::<Spare>().unwrap_or_default();
        let rays = PixelRays::reusing(projection, spare.tiles);
        let specular = scene
            .objects
            .iter()
            .any(|o| !matches!(o.material.finish, Finish::Diffuse | Finish::Emissive));
        let caster = (options.shading == Shading::Lit || specular).then_some(prepared);
        Ok(InverseRaster {
            buffers: Mutex::new(spare.buffers),
            spare_frame: Mutex::new(spare.frame),
            prepared,
            scene,
            projection,
            inverse,
            rays,
            caster,
            options: *options,
            setup_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// Renders one frame: colour, depth (the ray caster's distance along the projector) and
    /// object ids, with the counters of every stage, into a recycled frame ([`recycle_frame`])
    /// when there is one. Fails only when the memory of the frame or the z-buffer cannot be
    /// had (module `try_alloc`).
    pub fn render(&self) -> Result<(Frame, Stats)> {
        let recycled = self
            .spare_frame
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        let mut frame = match recycled {
            // `render_into` overwrites colour, depth and ids; no other layer is drawn.
            Some(mut frame) => {
                frame.surface.clear();
                frame
            }
            None => Frame::new(0, 0, self.scene.image.background),
        };
        let stats = self.render_into(&mut frame)?;
        Ok((frame, stats))
    }

    /// [`InverseRaster::render`] into `frame`, whose buffers are resized to the image and
    /// overwritten: a sequence of frames (an animation, a viewer, the throughput bench)
    /// reusing one `frame` allocates no image buffer after the first. Fails as
    /// [`InverseRaster::render`] does.
    pub fn render_into(&self, frame: &mut Frame) -> Result<Stats> {
        let start = Instant::now();
        // Every frame overwrites the buffers, so ones left by a panicked frame are as good
        // as any.
        let mut buffers = self
            .buffers
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let Buffers {
            images,
            bins,
            zbuffer,
            clearance,
            coordinates,
        } = &mut *buffers;
        let counts = self.pieces(images, bins, (clearance, coordinates));
        let pieces_ms = start.elapsed().as_secs_f64() * 1e3;
        let shader = Shader {
            objects: &self.scene.objects,
            rays: &self.rays,
            caster: self.caster,
            options: &self.options,
        };
        let size = self.projection.resolution();
        let filled = fill_and_shade(
            &shader,
            bins,
            zbuffer,
            frame,
            size,
            self.scene.image.background,
        );
        drop(buffers);
        let filled = filled?;
        let fill_ms = start.elapsed().as_secs_f64() * 1e3 - pieces_ms;
        let mut stats = Stats::new();
        filled
            .raster_stats(counts.drawn, counts.invalid)
            .record(&mut stats);
        let shading_rays = filled.shading_rays;
        let count = |n: u64| Counter::Count(n);
        for (name, value) in [
            ("triangles", self.scene.triangle_count() as u64),
            ("raster_clipped_triangles", counts.clipped),
            ("raster_near_pole_triangles", counts.near_poles),
            ("raster_pieces", counts.pieces),
            ("raster_pole_pieces", counts.pole_pieces),
            ("raster_singular_pieces", counts.singular),
            ("raster_winding_pieces", counts.winding),
            ("raster_empty_pieces", counts.empty),
            ("raster_screen_triangles", counts.drawn),
            ("raster_ray_tiles", self.rays.computed_tiles()),
            ("shading_rays", shading_rays),
            (
                "raster_uniform",
                u64::from(self.options.subdivision.uniform),
            ),
        ] {
            stats.insert(name, count(value));
        }
        let tolerance = self.options.subdivision.tolerance.unwrap_or(0.0);
        for (name, value) in [
            ("raster_tolerance_px", tolerance),
            ("raster_setup_ms", self.setup_ms),
            ("raster_pieces_ms", pieces_ms),
            ("raster_fill_ms", fill_ms),
        ] {
            stats.insert(name, Counter::Value(value));
        }
        Ok(stats)
    }

    /// Steps 1 to 3 of the module documentation: the vertex images of every object into
    /// `images`, then the screen triangles of every scene triangle, sorted into bands by
    /// parallel jobs of [`CHUNK`] scene triangles, one element of `bins` per job, with their
    /// counters (both buffers resized and overwritten); which triangles are far from the
    /// poles is read from `clearance`, and a staged inverse's first stage from
    /// `coordinates` (both brought up to date first).
    fn pieces(
        &self,
        images: &mut Vec<Vec<Option<DVec2>>>,
        bins: &mut Vec<Bins>,
        (clearance, coordinates): (&mut PoleClearance, &mut KeptCoordinates),
    ) -> PieceCounts {
        let refiner = Refiner::new(&self.inverse, self.options.subdivision.tolerance);
        let far = clearance.update(self.scene, &refiner, &self.inverse.chart.poles);
        images.resize_with(self.scene.objects.len(), Vec::new);
        if let Some(staged) = self.inverse.map.staged() {
            let coordinates = coordinates.update(self.scene, staged);
            for (kept, images) in coordinates.iter().zip(images.iter_mut()) {
                kept.par_iter()
                    .map(|c| c.map(|c| staged.pixel(c)))
                    .collect_into_vec(images);
            }
        } else {
            for (object, images) in self.scene.objects.iter().zip(images.iter_mut()) {
                object
                    .mesh
                    .positions
                    .par_iter()
                    .map(|p| refiner.node(p.as_dvec3()).image)
                    .collect_into_vec(images);
            }
        }
        let images = &*images;
        let jobs: Vec<(usize, Range<usize>)> = self
            .scene
            .objects
            .iter()
            .enumerate()
            .flat_map(|(o, object)| {
                let n = object.mesh.triangles.len();
                (0..n.div_ceil(CHUNK)).map(move |k| (o, k * CHUNK..((k + 1) * CHUNK).min(n)))
            })
            .collect();
        let done = AtomicU64::new(0);
        let bands = self.projection.resolution().1.div_ceil(BAND_ROWS) as usize;
        bins.resize_with(jobs.len(), Bins::default);
        jobs.par_iter()
            .zip(bins.par_iter_mut())
            .map(|((o, range), bins)| {
                bins.reset(bands);
                let mut counts = PieceCounts::default();
                let mut grid = Vec::new();
                for triangle in range.clone() {
                    let part = (&mut *bins, &mut counts);
                    let far = far[*o][triangle];
                    self.triangle(&refiner, &images[*o], (*o, triangle, far), &mut grid, part);
                }
                if let Some(progress) = self.options.progress {
                    progress(done.fetch_add(1, Ordering::Relaxed) + 1, jobs.len() as u64);
                }
                counts
            })
            .reduce(PieceCounts::default, |mut a, b| {
                a += b;
                a
            })
    }

    /// Clips, subdivides and places triangle `triangle` of object index `object`, whose
    /// vertex images are `images` and which `Refiner::far_from_poles` clears when `far`,
    /// into `bins`.
    fn triangle(
        &self,
        refiner: &Refiner<'_>,
        images: &[Option<DVec2>],
        (object, triangle, far): (usize, usize, bool),
        grid: &mut Vec<Node>,
        (bins, counts): (&mut Bins, &mut PieceCounts),
    ) {
        // Arrays built element by element here and below: `array::map` is not inlined in
        // this function, and its out-of-line calls and copies of the nodes cost about 5 %
        // of a 123,554-triangle panorama's frame.
        let item = &self.scene.objects[object];
        let [a, b, c] = item.mesh.triangles[triangle];
        let corners = [a as usize, b as usize, c as usize];
        let position = |k: usize| item.mesh.positions[corners[k]].as_dvec3();
        let points = [position(0), position(1), position(2)];
        let key = key(object, triangle);
        let (width, height) = self.projection.resolution();
        let size = DVec2::new(f64::from(width), f64::from(height));
        let period = self.inverse.chart.period;
        let inside = self
            .inverse
            .chart
            .clip
            .iter()
            .all(|h| points.iter().all(|&p| h.signed_distance(p) >= 0.0));
        if !inside {
            counts.clipped += 1;
        }
        let poles = !far;
        counts.near_poles += u64::from(poles);
        let mut draw = |nodes: [Node; 3]| {
            counts.pieces += 1;
            let [na, nb, nc] = nodes;
            let points = [na.point, nb.point, nc.point];
            if poles && (refiner.is_pole_piece(points) || refiner.is_within_clearance(points)) {
                counts.pole_pieces += 1;
                return;
            }
            let (Some(a), Some(b), Some(c)) = (na.image, nb.image, nc.image) else {
                counts.singular += 1;
                return;
            };
            let (mut empty, mut invalid) = (0, 0);
            let placed = place([a, b, c], size, period, |corners| {
                let screen = ScreenTriangle { corners, key };
                if !covers_a_centre(corners) {
                    empty += 1;
                } else if screen.is_valid() {
                    bins.push(screen, BAND_ROWS, height);
                } else {
                    invalid += 1;
                }
            });
            match placed {
                Placement::Copies(n) => {
                    counts.drawn += u64::from(n) - empty - invalid;
                    counts.empty += empty;
                    counts.invalid += invalid;
                }
                Placement::Winds => counts.winding += 1,
            }
        };
        let uniform = self.options.subdivision.uniform;
        let mut subdivide = |nodes: [Node; 3], grid: &mut Vec<Node>| {
            // Most triangles of a finely tessellated model are far from the poles and too
            // short to bend: refinement would emit them whole, so they are drawn at once
            // (and most of those then cover no pixel centre and are dropped by the cull).
            if uniform <= 1 && !poles && refiner.stays_whole(&nodes) {
                draw(nodes);
                return;
            }
            refiner.uniform(nodes, uniform, grid, &mut |piece| {
                refiner.refine(piece, [0; 3], poles, &mut draw)
            });
        };
        if inside {
            let node = |k: usize| Node {
                point: points[k],
                image: images[corners[k]],
            };
            subdivide([node(0), node(1), node(2)], grid);
        } else {
            let clipped = clip::clip(points, &self.inverse.chart.clip);
            for fan in clipped.fan() {
                subdivide(fan.map(|p| refiner.node(p)), grid);
            }
        }
    }
}
