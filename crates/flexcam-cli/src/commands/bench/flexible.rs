//! `flexcam bench flexible`: Table 7.1 of Brosz 2011 (The Flexible Projection Framework)
//! with flexcam's BVH-accelerated ray caster.
//!
//! The thesis timed one frame at 800 x 800 through a perspective-to-perspective volume with
//! quadratic Bezier projectors and with 2 to 6 segment polylines approximating them, on six
//! models of 520 to 37,127 faces, with no acceleration structure. Its models are not
//! available; each row here renders the Utah teapot tessellated to the face count nearest the
//! thesis's (64 n^2 - 8 n triangles for n x n quads per patch), and prints the count used.
//! The volume is three rectangles (near, bent middle, far) placed around the model's bounding
//! box; the polylines are the quadratic sampled at equal steps in t.
//!
//! The second table is the panorama throughput of `--method raster`: `builtin:teapot-dense` (123,554
//! triangles) as a 1280 x 720 equirectangular panorama from the scene's camera, by
//! `--method raster` (the first frame of a new renderer; later frames of the same one,
//! whose pixel projectors and buffers are then ready, with flat and with lit shading) and
//! by the ray caster in the same run.

use std::time::Instant;

use clap::{Args, ValueEnum};
use flexcam::projection::Projection;
use flexcam::render::bench_support::workloads::raster::{
    teapot_dense_panorama, PanoramaWorkload, PANORAMA_SIZE,
};
use flexcam::render::bench_support::workloads::raycast::{table_volume, teapot_scene, TABLE_SIZE};
use flexcam::render::bench_support::InverseRaster;
use flexcam::render::{self, Counter, Frame, PreparedScene, RenderOptions, Shading};
use flexcam::scene::Scene;
use flexcam::{Error, Result};

use super::timing::{measure, Timing};

/// Table 7.1's rows: model, faces, then seconds for quadratic and 2, 3, 4, 5, 6 segments.
const THESIS: [(&str, u32, [f64; 6]); 6] = [
    ("Kia", 520, [72.74, 48.56, 59.73, 69.98, 84.99, 114.57]),
    (
        "Teapot",
        2256,
        [326.06, 185.99, 296.43, 380.10, 433.48, 474.40],
    ),
    (
        "Cowboy",
        7695,
        [1167.76, 875.53, 1261.39, 1640.88, 1807.96, 2078.57],
    ),
    (
        "Alley",
        12602,
        [1711.28, 1342.75, 1604.97, 2192.11, 2583.69, 2891.87],
    ),
    (
        "City",
        22123,
        [3494.66, 1837.91, 2537.59, 2862.20, 3345.76, 4554.37],
    ),
    (
        "Saloon",
        37127,
        [4642.61, 3235.35, 5075.96, 6175.63, 6810.99, 7239.51],
    ),
];

/// Arguments of `flexcam bench flexible`.
#[derive(Args, Debug)]
pub struct FlexibleArgs {
    /// Timed renders per cell, after one warm-up render; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Only the first N rows of the table (smallest models first).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=6))]
    rows: Option<u32>,
    /// Which tables to measure.
    #[arg(long, value_enum, default_value_t = Part::All)]
    part: Part,
    /// Also print a hash of each Table 7.1 cell's frame (the bits of every pixel's colour,
    /// depth and id), to check that a change to the caster leaves every frame bit for bit
    /// equal.
    #[arg(long)]
    hash: bool,
}

/// The tables of `flexcam bench flexible`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Part {
    /// Both tables.
    All,
    /// Table 7.1 only.
    Table,
    /// The panorama throughput only.
    Panorama,
}

/// The projector kinds of the table's columns: `None` is the analytic quadratic.
const COLUMNS: [Option<u32>; 6] = [None, Some(2), Some(3), Some(4), Some(5), Some(6)];

/// Runs the benchmarks `args.part` names.
pub fn run(args: &FlexibleArgs) -> Result<()> {
    if args.part != Part::Panorama {
        table(args)?;
    }
    if args.part != Part::Table {
        panorama(args.repeat)?;
    }
    Ok(())
}

/// Table 7.1: prints the thesis's times, ours, and the speed-up.
fn table(args: &FlexibleArgs) -> Result<()> {
    let rows = args.rows.map_or(THESIS.len(), |r| r as usize);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "Table 7.1 (Brosz 2011): {TABLE_SIZE}x{TABLE_SIZE}, lit shading (headlight), one frame per cell, median \
         of {} after one warm-up, {threads} threads; models: the Utah teapot at the tessellation nearest each \
         face count",
        args.repeat
    );
    let mut ours = Vec::with_capacity(rows);
    for (name, faces, _) in &THESIS[..rows] {
        let (scene, used) = teapot_scene(*faces);
        let (times, hashes) = row_times(&scene, args.repeat)?;
        eprintln!("{name}: {used} faces done");
        ours.push((*name, *faces, used, times, hashes));
    }
    print_table("thesis (seconds, no acceleration structure)", rows, |r| {
        THESIS[r].2.map(|t| format!("{t:.2}"))
    });
    print_table("flexcam (median seconds)", rows, |r| {
        ours[r].3.map(|t| format!("{:.4}", t.median))
    });
    print_table("speed-up (thesis / flexcam)", rows, |r| {
        std::array::from_fn(|c| format!("{:.0}x", THESIS[r].2[c] / ours[r].3[c].median))
    });
    print_table(
        "flexcam CPU seconds per frame, all threads (independent of other load)",
        rows,
        |r| ours[r].3.map(|t| t.cpu_text(1.0, 4)),
    );
    if args.hash {
        println!("\nframe hashes (FNV-1a 64 of colour, depth and id bits)");
        for (name, _, _, _, hashes) in &ours {
            let cells: Vec<String> = hashes.iter().map(|h| format!("{h:016x}")).collect();
            println!("{name:<8}{}", cells.join(" "));
        }
    }
    println!("faces used per row:");
    for (name, faces, used, _, _) in &ours {
        println!("  {name:<7} thesis {faces:>6}, teapot {used:>6}");
    }
    Ok(())
}

/// One row of Table 7.1: the [`Timing`] of one lit frame of `scene` through each column's
/// projectors, the BVH built once for the row, and the [`frame_hash`] of each column's
/// median frame.
fn row_times(scene: &Scene, repeat: u32) -> Result<([Timing; 6], [u64; 6])> {
    let caster = PreparedScene::new(scene);
    let options = RenderOptions {
        shading: Shading::Lit,
        ..RenderOptions::default()
    };
    let mut times = [Timing::default(); 6];
    let mut hashes = [0; 6];
    for ((time, hash), column) in times.iter_mut().zip(&mut hashes).zip(COLUMNS) {
        let projection = table_volume(scene, column, TABLE_SIZE)?;
        let (timing, frame) = measure(repeat, || {
            Ok(render::render(&caster, &projection, &options)?.frame)
        })?;
        (*time, *hash) = (timing, frame_hash(&frame));
    }
    Ok((times, hashes))
}

/// FNV-1a (64 bits) of the bits of every pixel's colour, depth and id, in pixel order: equal
/// frames give equal hashes, and a change in any bit almost surely changes it. Computed after
/// the timed renders.
fn frame_hash(frame: &Frame) -> u64 {
    let words = frame
        .color
        .iter()
        .flat_map(|c| c.to_array())
        .map(f32::to_bits)
        .chain(frame.depth.iter().map(|d| d.to_bits()))
        .chain(frame.ids.iter().copied());
    words
        .flat_map(u32::to_le_bytes)
        .fold(0xcbf2_9ce4_8422_2325, |h: u64, byte| {
            (h ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3)
        })
}

/// The panorama throughput table (the workload of
/// `flexcam::render::bench_support::workloads::raster`): raster (first frame of a new renderer,
/// later frames of one renderer into one kept frame, flat and lit) and ray caster, the
/// median of `repeat` frames each after one warm-up.
fn panorama(repeat: u32) -> Result<()> {
    let PanoramaWorkload { scene, projection } = teapot_dense_panorama()?;
    let projection: &dyn Projection = projection.as_ref();
    let options = |shading| RenderOptions {
        shading,
        ..RenderOptions::default()
    };
    let flat = options(Shading::Flat);
    // The scene is prepared once (BVH built and timed here) for every renderer below.
    let start = Instant::now();
    let prepared = PreparedScene::new(&scene);
    let build = start.elapsed().as_secs_f64();
    // A new renderer per frame: the pixel projectors are computed during the frame.
    let (first, _) = measure(repeat, || {
        InverseRaster::new(&prepared, projection, &flat)?.render()?;
        Ok(())
    })?;
    // Later frames, and the wall-clock milliseconds of the two stages (building the pieces;
    // filling and shading them) of the median frame, from the renderer's own counters.
    let later = |options: &RenderOptions| {
        let raster = InverseRaster::new(&prepared, projection, options)?;
        let mut frame = raster.render()?.0;
        let (timing, stats) = measure(repeat, || raster.render_into(&mut frame))?;
        let stages = ["raster_pieces_ms", "raster_fill_ms"].map(|name| match stats.get(name) {
            Some(Counter::Value(ms)) => *ms,
            _ => f64::NAN,
        });
        Ok::<_, Error>((timing, stages))
    };
    let ((later_flat, stages), (later_lit, _)) = (later(&flat)?, later(&options(Shading::Lit))?);
    let (cast, _) = measure(repeat, || {
        render::render(&prepared, projection, &flat)?;
        Ok(())
    })?;
    let (width, height) = PANORAMA_SIZE;
    println!(
        "\npanorama: teapot-dense, {} triangles, {width}x{height} equirectangular (360 x 180), \
         median of {repeat} after one warm-up",
        scene.triangle_count()
    );
    println!(
        "{:<40}{:>10}{:>8}{:>14}",
        "method", "median ms", "fps", "CPU ms/frame"
    );
    for (name, t) in [
        ("raster, first frame, flat", first),
        ("raster, later frame, flat", later_flat),
        ("raster, later frame, lit (shadow rays)", later_lit),
        ("raycast, frame, flat (BVH prebuilt)", cast),
    ] {
        println!(
            "{name:<40}{:>10.1}{:>8.1}{:>14}",
            t.median_ms(),
            1.0 / t.median,
            t.cpu_text(1e3, 1)
        );
    }
    println!("{:<40}{:>10.1}", "raycast, BVH build (once)", 1e3 * build);
    println!(
        "median later flat frame, wall ms by stage: pieces {:.1}, fill and shade {:.1}",
        stages[0], stages[1]
    );
    Ok(())
}

/// Prints one table in the thesis's layout with the cells `cell(row)`.
fn print_table(title: &str, rows: usize, cell: impl Fn(usize) -> [String; 6]) {
    println!("\n{title}");
    println!(
        "{:<8}{:>7}{:>11}{:>10}{:>10}{:>10}{:>10}{:>10}",
        "model", "faces", "quadratic", "2 seg", "3 seg", "4 seg", "5 seg", "6 seg"
    );
    for (r, (name, faces, _)) in THESIS[..rows].iter().enumerate() {
        let c = cell(r);
        println!(
            "{name:<8}{faces:>7}{:>11}{:>10}{:>10}{:>10}{:>10}{:>10}",
            c[0], c[1], c[2], c[3], c[4], c[5]
        );
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// Equal frames hash alike; one bit of a colour, a depth or an id changes the hash, and
    /// so does a swap of two pixels.
    #[test]
    fn frame_hashes_see_every_bit_and_the_pixel_order() {
        let mut frame = Frame::new(3, 2, Vec3::new(0.1, 0.2, 0.3));
        frame.depth[4] = 2.5;
        frame.ids[4] = 7;
        let base = frame_hash(&frame);
        assert_eq!(frame_hash(&frame.clone()), base);
        let flipped = |edit: &dyn Fn(&mut Frame)| {
            let mut f = frame.clone();
            edit(&mut f);
            frame_hash(&f)
        };
        let bit = |x: f32| f32::from_bits(x.to_bits() ^ 1);
        assert_ne!(flipped(&|f| f.color[5].y = bit(f.color[5].y)), base);
        assert_ne!(flipped(&|f| f.depth[0] = bit(f.depth[0])), base);
        assert_ne!(flipped(&|f| f.ids[1] ^= 1), base);
        assert_ne!(flipped(&|f| f.depth.swap(0, 4)), base);
    }
}
