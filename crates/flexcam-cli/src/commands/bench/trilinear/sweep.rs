//! `flexcam bench trilinear --sweep reflection|refraction`: Vallance 2005, Figure 7.4 (the
//! cube reflected in a sphere through 1 x 1 to 5 x 5 surfaces) carried on to finer grids, and
//! its refraction twin (7.3.3). The view through a ball (`trilinear-sphere-mirror.toml`, or
//! `trilinear-sphere-glass.toml` with its rays refracted in and out) as an N x N trilinear grid
//! (2 N^2 projection triangles, `-D projection.grid=N`) is rendered by the trilinear rasteriser
//! and measured against the exact view (`-D projection.exact=true`: every pixel's ray from the
//! ball itself) ray cast: object-id agreement away from id edges and the thesis's relative
//! RGB error, against N. The interpolated rays' error falls about as 1 / N^2. The glass
//! ball focuses its rays: the pairs reaching across the depth where the rays of a projection
//! triangle cross are split there by the trilinear renderer (`split_pairs`,
//! docs/trilinear-raster.md); `fallback_triangles` counts what is still ray cast.

use std::path::Path;

use clap::ValueEnum;
use flexcam::render::{CurveOptions, PreparedScene};
use flexcam::scene::file::Definition;
use flexcam::scene::{self, LoadedScene, Overrides};
use flexcam::Result;

use super::study::{against, fixed, reference, Table};

/// The ball of a sweep (`--sweep`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    /// The mirror ball, `trilinear-sphere-mirror.toml` (Figure 7.4).
    Reflection,
    /// The glass ball, `trilinear-sphere-glass.toml` (7.3.3).
    Refraction,
}

impl Sweep {
    /// The example scene of the scenes folder.
    fn scene(self) -> &'static str {
        match self {
            Sweep::Reflection => "trilinear-sphere-mirror.toml",
            Sweep::Refraction => "trilinear-sphere-glass.toml",
        }
    }

    /// The thesis's trilinear times (ms) at 800 x 800 for N = 1 to 5 (Table 8.1): Figure 7.4
    /// (b)-(f), the cube reflected in a sphere, and for refraction Figure 7.6 (b)-(f), its
    /// lens (the thesis has no glass ball).
    fn thesis_ms(self) -> [f64; 5] {
        match self {
            Sweep::Reflection => [24.4, 70.1, 150.1, 230.2, 360.7],
            Sweep::Refraction => [18.5, 72.3, 167.0, 287.8, 467.3],
        }
    }

    /// The table's title.
    pub fn title(self) -> &'static str {
        match self {
            Sweep::Reflection => {
                "Figure 7.4 (Vallance 2005): the view reflected in a mirror ball as an N x N \
                 trilinear grid against the exact mirror ball, ray cast"
            }
            Sweep::Refraction => {
                "7.3.3 (Vallance 2005): the view refracted through a glass ball as an N x N \
                 trilinear grid against the exact glass ball, ray cast"
            }
        }
    }
}

/// Grid sizes N (2 N^2 projection triangles): the thesis's 1 to 5, then finer.
const SIZES: [u32; 8] = [1, 2, 3, 4, 5, 8, 16, 32];
/// The sizes of `--quick`.
const QUICK_SIZES: [u32; 3] = [1, 4, 16];

pub const COLUMNS: &[&str] = &[
    "n",
    "projections",
    "width",
    "height",
    "trilinear_ms",
    "raycast_ms",
    "ids_interior",
    "interior_pixels",
    "rgb_error",
    "shapes",
    "split_pairs",
    "fallback_triangles",
    "thesis_ms",
];

/// Measures each grid size (1, 4 and 16 alone with `quick`) at the scene's size, or at
/// width `width` with the scene's aspect ratio.
pub fn run(
    sweep: Sweep,
    scenes: &Path,
    width: Option<u32>,
    repeat: u32,
    quick: bool,
) -> Result<Table> {
    let source = scenes.join(sweep.scene());
    let source = source.to_string_lossy();
    let load = |definition: String| -> Result<LoadedScene> {
        let overrides = Overrides {
            width,
            definitions: vec![definition.parse::<Definition>()?],
            ..Overrides::default()
        };
        scene::load_with(&source, &overrides)
    };
    let exact = load("projection.exact=true".into())?;
    // The objects do not depend on the projection: one prepared scene serves every grid.
    let prepared = PreparedScene::new(&exact.scene);
    let (raycast, frame) = reference(&prepared, exact.projection.as_ref(), repeat)?;
    let sizes: &[u32] = if quick { &QUICK_SIZES } else { &SIZES };
    let mut table = Table::new(COLUMNS);
    for &n in sizes {
        let grid = load(format!("projection.grid={n}"))?;
        let m = against(
            &frame,
            &prepared,
            grid.projection.as_ref(),
            CurveOptions::default(),
            repeat,
        )?;
        let thesis = sweep
            .thesis_ms()
            .get(n as usize - 1)
            .map_or("-".to_string(), |ms| fixed(*ms, 1));
        table.push(vec![
            n.to_string(),
            m.count("projection_triangles").to_string(),
            grid.width.to_string(),
            grid.height.to_string(),
            fixed(m.timing.median_ms(), 3),
            fixed(raycast.median_ms(), 3),
            fixed(m.interior.0, 5),
            m.interior.1.to_string(),
            fixed(m.comparison.relative_rgb_error, 6),
            m.count("shapes").to_string(),
            m.count("split_pairs").to_string(),
            m.count("fallback_triangles").to_string(),
            thesis,
        ]);
    }
    Ok(table)
}
