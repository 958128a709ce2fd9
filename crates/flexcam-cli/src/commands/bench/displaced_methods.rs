//! `flexcam bench displaced --part table-8-1`: Table 8.1 of Ramsey 2005, every way the
//! dissertation rendered its displaced three-holed torus, at its three camera positions,
//! beside its seconds per frame.
//!
//! The rows: the torus's undisplaced mesh, detailed and at its coarsest level of detail
//! (`M20` of its progressive mesh), ray traced lit; full displacement at subdivision levels 2
//! and 3 on the detailed mesh and on `M20`; the BRDF, plain bump mapping and redistributed
//! bump mapping alone; and the transition system at levels 2 and 3. Every row with a
//! displaced surface or its tables is `--shading transition-lit` with the method forced
//! (`--transition-method`) and the level fixed (`--lod`), so that they share one shader
//! (diffuse, shadow rays); the undisplaced rows are `--shading lit` of plain meshes.
//!
//! The camera positions are the dissertation's `e` in the torus's frame (z up, the torus in
//! the xy plane), carried into the scene's (y up) and scaled by the torus's half-width `R`
//! (half the larger horizontal side of the displaced objects' bounding box), looking at the
//! box's centre: from above at `R` (`(0, 0, 1)`), from above at `10 R` (`(0, 0, 10)`), and
//! low and to the side (`(1.1, 0.2, 0.34)`).

use std::sync::Arc;

use flexcam::displace::progressive::{ProgressiveMesh, LOD_PERCENTS};
use flexcam::glam::DVec3;
use flexcam::projection::{CameraFrame, ProjectionSpec};
use flexcam::render::{
    render, LodSelection, PreparedScene, RenderOptions, Shading, TransitionMethod,
    TransitionShading,
};
use flexcam::scene::Scene;
use flexcam::{Error, Result};

use super::displaced::with_level;
use super::timing::measure;

/// The dissertation's camera positions (its frame: z up), with their names here.
const VIEWS: [(&str, [f64; 3]); 3] = [
    ("e=(0,0,1)", [0.0, 0.0, 1.0]),
    ("e=(0,0,10)", [0.0, 0.0, 10.0]),
    ("e=(1.1,0.2,0.34)", [1.1, 0.2, 0.34]),
];

/// What a row renders.
#[derive(Clone, Copy)]
enum Variant {
    /// The undisplaced mesh, lit; `simplified`: its coarsest level of detail.
    Plain { simplified: bool },
    /// `transition-lit` at subdivision `level` with `method` and level of detail `lod`.
    Displaced {
        level: u32,
        method: TransitionMethod,
        lod: LodSelection,
    },
}

/// The coarsest level of detail (`M20`).
const COARSEST: LodSelection = LodSelection::Level(LOD_PERCENTS.len() - 1);

/// Table 8.1's rows: name, what flexcam renders for it, and the dissertation's seconds per
/// frame at the three views (one 600 MHz R14000, 180 x 180; its transition system's
/// first two views are the same at both levels).
const ROWS: [(&str, Variant, [f64; 3]); 11] = [
    (
        "fully detailed LOD",
        Variant::Plain { simplified: false },
        [0.33, 0.11, 0.38],
    ),
    (
        "fully simplified LOD",
        Variant::Plain { simplified: true },
        [0.40, 0.11, 0.38],
    ),
    (
        "displaced detailed (2)",
        displaced(2, TransitionMethod::Displacement, LodSelection::Finest),
        [6.54, 1.34, 10.75],
    ),
    (
        "displaced simplified (2)",
        displaced(2, TransitionMethod::Displacement, COARSEST),
        [5.25, 1.08, 7.12],
    ),
    (
        "displaced detailed (3)",
        displaced(3, TransitionMethod::Displacement, LodSelection::Finest),
        [24.95, 5.09, 41.52],
    ),
    (
        "displaced simplified (3)",
        displaced(3, TransitionMethod::Displacement, COARSEST),
        [19.48, 3.93, 26.93],
    ),
    (
        "BRDF",
        displaced(3, TransitionMethod::Brdf, LodSelection::Finest),
        [0.40, 0.11, 0.45],
    ),
    (
        "bump map",
        displaced(3, TransitionMethod::Bump, LodSelection::Finest),
        [0.42, 0.11, 0.48],
    ),
    (
        "redistributed bump",
        displaced(3, TransitionMethod::RedistributedBump, LodSelection::Finest),
        [3.70, 1.40, 3.99],
    ),
    (
        "transition system (2)",
        displaced(2, TransitionMethod::Auto, LodSelection::Footprint),
        [3.70, 1.33, 9.31],
    ),
    (
        "transition system (3)",
        displaced(3, TransitionMethod::Auto, LodSelection::Footprint),
        [3.70, 1.33, 31.28],
    ),
];

const fn displaced(level: u32, method: TransitionMethod, lod: LodSelection) -> Variant {
    Variant::Displaced { level, method, lod }
}

/// Prints Table 8.1 at `size` x `size`, each cell the median of `repeat` renders after a
/// warm-up (which builds the transition tables and levels of detail of its prepared scene).
pub fn table_8_1(size: u32, repeat: u32, base: &Scene) -> Result<()> {
    let views = views(base)?;
    println!(
        "Table 8.1 (Ramsey 2005): the displaced torus by every method, {size}x{size}, ms per \
         frame (median of {repeat}); dissertation: s per frame, 180x180, one 600 MHz R14000"
    );
    for ((name, _), spec) in VIEWS.iter().zip(&views) {
        if let ProjectionSpec::Perspective { frame, .. } = spec {
            println!(
                "{name}: eye ({:.3}, {:.3}, {:.3}) looking at ({:.3}, {:.3}, {:.3})",
                frame.position.x,
                frame.position.y,
                frame.position.z,
                frame.look_at.x,
                frame.look_at.y,
                frame.look_at.z
            );
        }
    }
    println!(
        "{:<26} {:>11} {:>11} {:>17} | {:>9} {:>9} {:>9}",
        "method", VIEWS[0].0, VIEWS[1].0, VIEWS[2].0, "diss. s", "diss. s", "diss. s"
    );
    let plain = [undisplaced(base, false)?, undisplaced(base, true)?];
    let levels = [2, 3].map(|level| PreparedScene::new(&with_level(base, level)));
    let mut times = Vec::with_capacity(ROWS.len());
    for (name, variant, dissertation) in ROWS {
        let (prepared, shading) = match variant {
            Variant::Plain { simplified } => (&plain[usize::from(simplified)], Shading::Lit),
            Variant::Displaced { level, method, lod } => (
                &levels[level as usize - 2],
                Shading::Transitions(
                    TransitionShading::with_default_d(false)
                        .with_method(method)
                        .with_lod(lod),
                ),
            ),
        };
        let options = RenderOptions {
            shading,
            ..RenderOptions::default()
        };
        let mut ms = [0.0; 3];
        for (m, spec) in ms.iter_mut().zip(&views) {
            let projection = spec.build(size, size)?;
            let (timing, _) = measure(repeat, || render(prepared, projection.as_ref(), &options))?;
            *m = timing.median_ms();
        }
        println!(
            "{name:<26} {:>11.1} {:>11.1} {:>17.1} | {:>9.2} {:>9.2} {:>9.2}",
            ms[0], ms[1], ms[2], dissertation[0], dissertation[1], dissertation[2]
        );
        times.push(ms);
    }
    let row = |name: &str| ROWS.iter().position(|r| r.0 == name).expect("a row");
    for level in [2, 3] {
        let full = row(&format!("displaced detailed ({level})"));
        let transition = row(&format!("transition system ({level})"));
        let ratio = |t: &[[f64; 3]], k: usize| t[full][k] / t[transition][k];
        let ours = [0, 1, 2].map(|k| ratio(&times, k));
        let theirs = [0, 1, 2].map(|k| ROWS[full].2[k] / ROWS[transition].2[k]);
        println!(
            "transition system against full displacement, level {level}: {:.2}x {:.2}x {:.2}x \
             (dissertation {:.2}x {:.2}x {:.2}x)",
            ours[0], ours[1], ours[2], theirs[0], theirs[1], theirs[2]
        );
    }
    println!(
        "views: the dissertation's camera positions e (its z up) in the torus's half-width R, \
         looking at its centre; plain rows: --shading lit; the others: --shading \
         transition-lit with --transition-method and --lod fixed (simplified: m20)"
    );
    Ok(())
}

/// `base` with its displaced objects undisplaced, at their coarsest level of detail if
/// `simplified`, prepared (an error naming the object whose progressive mesh fails).
fn undisplaced(base: &Scene, simplified: bool) -> Result<PreparedScene> {
    let mut scene = base.clone();
    for object in &mut scene.objects {
        if object.displacement.take().is_some() && simplified {
            let levels = ProgressiveMesh::new(&object.mesh).map_err(|e| {
                Error::new(format!(
                    "object \"{}\": no levels of detail: {e}",
                    object.name
                ))
            })?;
            let coarsest = levels
                .lods
                .last()
                .expect("a progressive mesh has its levels");
            object.mesh = Arc::new(coarsest.mesh.clone());
        }
    }
    Ok(PreparedScene::new(&scene))
}

/// The perspective cameras of [`VIEWS`] for `base` (its perspective's field of view).
fn views(base: &Scene) -> Result<[ProjectionSpec; 3]> {
    let ProjectionSpec::Perspective { fov, .. } = base.projection else {
        return Err(Error::new(
            "the displaced torus bench needs a perspective camera",
        ));
    };
    let (lo, hi) = base
        .objects
        .iter()
        .filter(|o| o.displacement.is_some())
        .filter_map(|o| o.mesh.bounds())
        .fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), (a, b)| (lo.min(a.as_dvec3()), hi.max(b.as_dvec3())),
        );
    if !lo.is_finite() || !hi.is_finite() {
        return Err(Error::new(
            "the displaced torus bench needs a displaced object",
        ));
    }
    let centre = (lo + hi) / 2.0;
    let half_width = ((hi.x - lo.x).max(hi.z - lo.z)) / 2.0;
    Ok(VIEWS.map(|(_, [x, y, z])| {
        let overhead = x == 0.0 && y == 0.0;
        ProjectionSpec::Perspective {
            frame: CameraFrame {
                position: centre + DVec3::new(x, z, y) * half_width,
                look_at: centre,
                up: if overhead { DVec3::NEG_Z } else { DVec3::Y },
            },
            fov,
        }
    }))
}
