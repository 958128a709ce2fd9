//! The image cut into square tiles rendered in parallel (rayon); each tile is rendered into its
//! own buffers and copied into its place in the frame, so the result does not depend on the
//! number of threads or the order tiles finish in. The frame is cut into bands of one row of
//! tiles; the bands are filled in parallel too, each from its own tiles, so that no thread
//! copies the whole frame after the tiles are rendered.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, Vec3};
use rayon::prelude::*;

use super::hull_cull::LiveParts;
use super::sampling::SamplePattern;
use super::shade::{Sample, Tracer};
use crate::projection::{Projection, Projector};
use crate::render::prepared::PreparedScene;
use crate::render::shading::trace::RayCounts;
use crate::render::{Counter, Frame, PixelWindow, RenderOptions, Stats};

/// Tile edge in pixels: small enough to balance two to many cores, large enough that the
/// per-tile bookkeeping is negligible.
const TILE: u32 = 16;

/// Edge in pixels of the blocks whose projectors are culled together by their hull (module
/// `hull_cull`): where a tile's hull does not cull all of it, each block's hull is tried,
/// which also tells which parts (segments, pieces) of the block's projectors need searching.
const BLOCK: u32 = 8;

/// Blocks per tile side.
const BLOCKS: usize = (TILE / BLOCK) as usize;

/// One rendered tile: its rectangle's left column and width, and its row-major pixels.
struct Tile {
    x0: u32,
    width: u32,
    color: Vec<Vec3>,
    depth: Vec<f32>,
    ids: Vec<u32>,
    counts: RayCounts,
    /// Blocks of the tile whose projectors were all culled by their hull (see `hull_cull`).
    culled_blocks: u64,
}

/// Renders the pixels of `window` of `projection`'s image into `frame`, which must already
/// be of the window's size; see [`raycast::render_into`]. The tiles start at the window's
/// corner; the bands and their tiles cover the frame, so every pixel is overwritten
/// whatever the frame held.
pub(super) fn render(
    caster: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
    window: PixelWindow,
    frame: &mut Frame,
) -> Stats {
    let (width, height) = (window.width(), window.height());
    debug_assert_eq!((frame.width, frame.height), (width, height));
    let pattern = SamplePattern::new(options.spp);
    let tiles_x = width.div_ceil(TILE);
    let total = tiles_x as u64 * height.div_ceil(TILE) as u64;
    let done = AtomicU64::new(0);
    // One band of the frame per row of tiles; no band of a buffer not wanted.
    let band = TILE as usize * width as usize;
    let rows = height.div_ceil(TILE) as usize;
    let tallies: Vec<(RayCounts, u64)> = frame
        .color
        .par_chunks_mut(band)
        .zip(bands(&mut frame.depth, band, rows))
        .zip(bands(&mut frame.ids, band, rows))
        .enumerate()
        .map(|(row, ((color, depth), ids))| {
            let y0 = row as u32 * TILE;
            let tiles: Vec<Tile> = (0..tiles_x)
                .into_par_iter()
                .map(|column| {
                    let x0 = column * TILE;
                    let rect = (
                        window.x0 + x0,
                        window.y0 + y0,
                        TILE.min(width - x0),
                        TILE.min(height - y0),
                    );
                    let tile = render_tile(caster, projection, options, &pattern, rect);
                    if let Some(progress) = options.progress {
                        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    }
                    tile
                })
                .collect();
            let mut tally = (RayCounts::default(), 0);
            for tile in &tiles {
                let w = tile.width as usize;
                for (r, src) in (0..tile.color.len() / w).map(|r| (r, r * w..(r + 1) * w)) {
                    let start = r * width as usize + (tile.x0 - window.x0) as usize;
                    let dst = start..start + w;
                    color[dst.clone()].copy_from_slice(&tile.color[src.clone()]);
                    if !depth.is_empty() {
                        depth[dst.clone()].copy_from_slice(&tile.depth[src.clone()]);
                    }
                    if !ids.is_empty() {
                        ids[dst].copy_from_slice(&tile.ids[src]);
                    }
                }
                tally.0.primary += tile.counts.primary;
                tally.0.secondary += tile.counts.secondary;
                tally.0.shadow += tile.counts.shadow;
                tally.1 += tile.culled_blocks;
            }
            tally
        })
        .collect();
    let mut counts = RayCounts::default();
    let mut culled = 0;
    for (tally, blocks) in tallies {
        counts.primary += tally.primary;
        counts.secondary += tally.secondary;
        counts.shadow += tally.shadow;
        culled += blocks;
    }
    Stats::from([
        ("primary_rays", Counter::Count(counts.primary)),
        ("secondary_rays", Counter::Count(counts.secondary)),
        ("shadow_rays", Counter::Count(counts.shadow)),
        (
            "rays_cast",
            Counter::Count(counts.primary + counts.secondary + counts.shadow),
        ),
        ("blocks_culled", Counter::Count(culled)),
    ])
}

/// `buffer` cut into `rows` bands of `band` pixels (the last one shorter), or `rows` empty
/// bands when `buffer` is empty (an output not wanted).
fn bands<T: Send>(buffer: &mut [T], band: usize, rows: usize) -> Vec<&mut [T]> {
    if buffer.is_empty() {
        (0..rows).map(|_| &mut [][..]).collect()
    } else {
        buffer.chunks_mut(band).collect()
    }
}

/// Which parts of the projectors of each block (`[row][column]`) of tile
/// `(x0, y0, width, height)` may hit the scene ([`LiveParts::ALL`] where the projection
/// gives no hull); blocks outside an edge tile are left at the tile's value.
fn block_parts(
    caster: &PreparedScene,
    projection: &dyn Projection,
    pattern: &SamplePattern,
    (x0, y0, width, height): (u32, u32, u32, u32),
) -> [[LiveParts; BLOCKS]; BLOCKS] {
    // Every sample position of a rectangle of pixels lies in the rectangle of its corner
    // pixels' extreme sample offsets.
    let (lo, hi) = pattern
        .offsets
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), o| {
            (lo.min(*o), hi.max(*o))
        });
    let parts = |(x, y, w, h): (u32, u32, u32, u32), within: LiveParts| {
        let first = DVec2::new(x as f64, y as f64);
        let last = first + DVec2::new((w - 1) as f64, (h - 1) as f64);
        projection
            .projector_hull(first + lo, last + hi)
            .map(|hull| caster.live_parts(&hull, within))
    };
    let whole = parts((x0, y0, width, height), LiveParts::ALL);
    let mut blocks = [[whole.unwrap_or(LiveParts::ALL); BLOCKS]; BLOCKS];
    let Some(whole) = whole.filter(|w| !w.none()) else {
        return blocks;
    };
    for (row, line) in blocks.iter_mut().enumerate() {
        for (column, block) in line.iter_mut().enumerate() {
            let (bx, by) = (column as u32 * BLOCK, row as u32 * BLOCK);
            if bx < width && by < height {
                let (w, h) = (BLOCK.min(width - bx), BLOCK.min(height - by));
                // The tile's hull bounds the block too: only the tile's live parts are
                // tested, and the tile's stand in where the block has no hull.
                *block = parts((x0 + bx, y0 + by, w, h), whole).unwrap_or(whole);
            }
        }
    }
    blocks
}

/// Renders the pixels of rectangle `(x0, y0, width, height)`: each averages its samples'
/// colours and reports the depth and id of the sample nearest its centre.
fn render_tile(
    caster: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
    pattern: &SamplePattern,
    (x0, y0, width, height): (u32, u32, u32, u32),
) -> Tile {
    let n = (width * height) as usize;
    let mut tile = Tile {
        x0,
        width,
        color: vec![Vec3::ZERO; n],
        depth: vec![f32::INFINITY; n],
        ids: vec![0; n],
        counts: RayCounts::default(),
        culled_blocks: 0,
    };
    let blocks = block_parts(caster, projection, pattern, (x0, y0, width, height));
    let (rows, columns) = (
        height.div_ceil(BLOCK) as usize,
        width.div_ceil(BLOCK) as usize,
    );
    tile.culled_blocks = blocks[..rows]
        .iter()
        .flat_map(|line| &line[..columns])
        .filter(|parts| parts.none())
        .count() as u64;
    let live =
        |(x, y): (u32, u32)| blocks[((y - y0) / BLOCK) as usize][((x - x0) / BLOCK) as usize];
    let mut tracer = Tracer::new(caster, options);
    let store = |tile: &mut Tile, (x, y): (u32, u32), color: Vec3, sample: Sample| {
        let i = ((y - y0) * width + (x - x0)) as usize;
        tile.color[i] = color;
        tile.depth[i] = sample.depth;
        tile.ids[i] = sample.id;
    };
    // One sample per pixel: 2x2 quads of pixels trace their first hits together (identical
    // results, one BVH traversal for four coherent rays); the odd last row / column of an
    // edge tile goes pixel by pixel.
    let quads = if pattern.offsets.len() == 1 { 2 } else { 0 };
    let (quad_w, quad_h) = (width / 2 * quads, height / 2 * quads);
    let offset = pattern.offsets[0];
    // The projectors are generated into these, reused from sample to sample (a polyline's
    // vertex buffer is refilled, not allocated: `Projection::projector_into`).
    let mut projectors: [Option<Projector>; 4] = Default::default();
    for qy in (0..quad_h).step_by(2) {
        for qx in (0..quad_w).step_by(2) {
            let (x, y) = (x0 + qx, y0 + qy);
            let pixels = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
            // BLOCK is even: the quad lies in one block.
            let parts = live((x, y));
            let samples = if parts.none() {
                [(); 4].map(|_| tracer.shade_miss())
            } else {
                tracer.live = parts;
                for (slot, (x, y)) in projectors.iter_mut().zip(pixels) {
                    projection.projector_into(DVec2::new(x as f64, y as f64) + offset, slot);
                }
                tracer.sample4_projectors(&projectors)
            };
            for (pixel, sample) in pixels.into_iter().zip(samples) {
                store(&mut tile, pixel, Vec3::ZERO + sample.color, sample);
            }
        }
    }
    let scale = 1.0 / pattern.offsets.len() as f32;
    for y in y0..y0 + height {
        for x in x0..x0 + width {
            if x - x0 < quad_w && y - y0 < quad_h {
                continue;
            }
            let mut color = Vec3::ZERO;
            let mut centre = None;
            let parts = live((x, y));
            tracer.live = parts;
            for (k, offset) in pattern.offsets.iter().enumerate() {
                let pixel = DVec2::new(x as f64, y as f64) + *offset;
                let sample = if parts.none() {
                    tracer.shade_miss()
                } else {
                    let slot = &mut projectors[0];
                    projection.projector_into(pixel, slot);
                    tracer.sample_projector(slot.as_ref())
                };
                color += sample.color;
                if k == pattern.centre {
                    centre = Some(sample);
                }
            }
            let centre = centre.expect("the centre sample is one of the pattern's");
            store(&mut tile, (x, y), color * scale, centre);
        }
    }
    tile.counts = tracer.shader.counts;
    tile
}
