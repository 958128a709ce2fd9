//! `flexcam bench trilinear --study tessellation`: the two ways of following curved edges of
//! Vallance 2005, section 4.5, per tessellation factor (section 8.5, Figures 8.9 to 8.12,
//! Tables D.18 to D.31): scene-triangle tessellation (`--curves tessellate`, factor =
//! segments per scene edge) and parametric slicing (`--curves slice`, factor = slices per
//! shape), on each appendix C configuration at 640^2 pixels, timed and measured against the
//! ray caster (the thesis's relative RGB error: mean |difference| over mean reference RGB).
//! Rows of configuration `mean` average the seven (Figures 8.11 and 8.12), beside the
//! thesis's averages of its Tables D.18 to D.31.

use std::path::Path;

use flexcam::render::{CurveMode, CurveOptions, PreparedScene};
use flexcam::Result;

use super::configurations::{self, CONFIGURATIONS, SIDE};
use super::study::{against, fixed, reference, Table};

/// The thesis's tessellation factors.
const FACTORS: [u32; 19] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100,
];
/// The factors of `--quick`.
const QUICK_FACTORS: [u32; 3] = [1, 10, 100];

/// The thesis's averages over its seven configurations per factor of [`FACTORS`]: ms and
/// relative error, scene-triangle tessellation (Tables D.18-D.24) then parametric slicing
/// (D.25-D.31).
const THESIS_MEANS: [[(f64, f64); 19]; 2] = [
    [
        (0.110, 0.70095),
        (0.161, 0.53064),
        (0.229, 0.37913),
        (0.303, 0.28666),
        (0.411, 0.32265),
        (0.614, 0.27689),
        (0.799, 0.21222),
        (1.019, 0.20456),
        (1.276, 0.20093),
        (1.557, 0.19398),
        (5.846, 0.15099),
        (12.699, 0.12890),
        (22.383, 0.12554),
        (35.217, 0.11960),
        (49.741, 0.11907),
        (69.431, 0.11848),
        (90.263, 0.11922),
        (118.819, 0.12056),
        (146.846, 0.11732),
    ],
    [
        (0.104, 0.61488),
        (0.137, 0.44983),
        (0.166, 0.36193),
        (0.190, 0.24185),
        (0.216, 0.20157),
        (0.254, 0.20312),
        (0.280, 0.20706),
        (0.310, 0.16439),
        (0.343, 0.15273),
        (0.371, 0.15310),
        (0.659, 0.12928),
        (0.954, 0.12123),
        (1.259, 0.12018),
        (1.559, 0.11959),
        (1.864, 0.11898),
        (2.166, 0.11905),
        (2.457, 0.11910),
        (2.780, 0.11831),
        (3.074, 0.11949),
    ],
];

/// The two modes, in the order of [`THESIS_MEANS`].
const MODES: [CurveMode; 2] = [CurveMode::Tessellate, CurveMode::Slice];

pub const COLUMNS: &[&str] = &[
    "configuration",
    "mode",
    "factor",
    "pixels",
    "trilinear_ms",
    "raycast_ms",
    "rgb_error",
    "ids_interior",
    "depth_mean",
    "thesis_ms",
    "thesis_rgb_error",
];

/// Measures every configuration, mode and factor (the factors 1, 10 and 100 alone with
/// `quick`) at `side x side` pixels (default 640), then the means.
pub fn run(scenes: &Path, side: Option<u32>, repeat: u32, quick: bool) -> Result<Table> {
    let side = side.unwrap_or(SIDE);
    let factors: &[u32] = if quick { &QUICK_FACTORS } else { &FACTORS };
    let pixels = (u64::from(side) * u64::from(side)).to_string();
    let mut table = Table::new(COLUMNS);
    // Per mode and factor: the sums of trilinear ms, ray-cast ms and relative error.
    let mut sums = vec![[[0.0f64; 3]; 2]; factors.len()];
    for (name, _, _) in CONFIGURATIONS {
        let scene = configurations::load(scenes, name)?;
        let projection = scene.projection.build(side, side)?;
        let prepared = PreparedScene::new(&scene);
        let (raycast, frame) = reference(&prepared, projection.as_ref(), repeat)?;
        for (k, &mode) in MODES.iter().enumerate() {
            for (f, &factor) in factors.iter().enumerate() {
                let curves = CurveOptions::new(mode, Some(factor))?;
                let m = against(&frame, &prepared, projection.as_ref(), curves, repeat)?;
                let error = m.comparison.relative_rgb_error;
                let sum = &mut sums[f][k];
                sum[0] += m.timing.median_ms();
                sum[1] += raycast.median_ms();
                sum[2] += error;
                table.push(vec![
                    name.to_string(),
                    mode.name().to_string(),
                    factor.to_string(),
                    pixels.clone(),
                    fixed(m.timing.median_ms(), 3),
                    fixed(raycast.median_ms(), 3),
                    fixed(error, 6),
                    fixed(m.interior.0, 5),
                    format!("{:.2e}", m.comparison.depth_mean),
                    "-".to_string(),
                    "-".to_string(),
                ]);
            }
        }
    }
    let n = CONFIGURATIONS.len() as f64;
    for (k, &mode) in MODES.iter().enumerate() {
        for (f, &factor) in factors.iter().enumerate() {
            let [ms, raycast_ms, error] = sums[f][k].map(|s| s / n);
            let thesis = FACTORS
                .iter()
                .position(|&x| x == factor)
                .map(|i| THESIS_MEANS[k][i]);
            let (thesis_ms, thesis_error) = thesis.map_or(("-".into(), "-".into()), |(t, e)| {
                (fixed(t, 3), fixed(e, 5))
            });
            table.push(vec![
                "mean".to_string(),
                mode.name().to_string(),
                factor.to_string(),
                pixels.clone(),
                fixed(ms, 3),
                fixed(raycast_ms, 3),
                fixed(error, 6),
                "-".to_string(),
                "-".to_string(),
                thesis_ms,
                thesis_error,
            ]);
        }
    }
    Ok(table)
}
