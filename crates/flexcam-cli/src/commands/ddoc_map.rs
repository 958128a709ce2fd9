//! `flexcam ddoc-map`: the displacement map of a scene's depth-discontinuity occlusion
//! camera (`preset = "ddoc"`), from the depth of its reference perspective
//! (`DdocMap::from_depth`), as a colour PFM for the preset's `map` key.

use std::path::PathBuf;

use clap::Args;
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::flexible::presets::ddoc::{self, DdocMap, MAX_MAP_SIDE, MAX_STRENGTH};
use flexcam::projection::flexible::{Flexible, FlexibleSpec, VolumeSource};
use flexcam::projection::ProjectionSpec;
use flexcam::render::{pick, PreparedScene};
use flexcam::{Error, Result};
use glam::DVec2;
use rayon::prelude::*;

use super::scene_args::SceneArgs;

/// Arguments of `flexcam ddoc-map`.
#[derive(Args, Debug)]
pub struct DdocMapArgs {
    #[command(flatten, next_help_heading = "Scene")]
    scene: SceneArgs,
    /// Write the map here (.pfm, colour: du, dv in image fractions, u right and v up, and an
    /// unused channel). `--width` and `--height` give its size (the map is smooth and
    /// sampled bilinearly, so a fraction of the image's size serves).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// How far the far samples are pushed away from a straight silhouette, in image widths
    /// (0 to 0.1); the push falls off as a Gaussian of sigma twice this across it.
    #[arg(long, value_name = "S", default_value_t = 0.04)]
    strength: f64,
}

/// Runs `flexcam ddoc-map`: ray casts the reference perspective of the scene's `ddoc`
/// projection (its `map` is not used), pixels in parallel on `--threads`, and writes the map
/// of its depth discontinuities.
pub fn run(args: &DdocMapArgs) -> Result<()> {
    if !(args.strength.is_finite() && 0.0 < args.strength && args.strength <= MAX_STRENGTH) {
        return Err(Error::new(format!(
            "--strength must be in (0, {MAX_STRENGTH}] image widths, got {}",
            args.strength
        )));
    }
    let mut outputs = OutputSet::new();
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let id = outputs.output("the ddoc map", &args.output, &["pfm"])?;
    let loaded = args.scene.load()?;
    // The scene's own map is what this command rewrites: every other input is protected.
    let inputs: Vec<_> = loaded
        .scene
        .inputs
        .iter()
        .filter(|f| f.what != "ddoc map")
        .cloned()
        .collect();
    super::declare_scene_inputs(&mut outputs, &inputs)?;
    let reference = match &loaded.scene.projection {
        ProjectionSpec::Flexible(spec) => match &spec.source {
            VolumeSource::Preset(preset) => ddoc::reference(preset),
            _ => None,
        },
        _ => None,
    };
    let Some((perspective, depths)) = reference else {
        return Err(Error::in_file(
            &loaded.source,
            "ddoc-map needs a flexible projection with preset = \"ddoc\"",
        ));
    };
    let (width, height) = (loaded.width, loaded.height);
    if width > MAX_MAP_SIDE || height > MAX_MAP_SIDE {
        return Err(Error::new(format!(
            "a ddoc map is at most {MAX_MAP_SIDE} pixels a side, got {width} x {height} (give \
             --width and --height: the map is smooth, a fraction of the image's size serves)"
        )));
    }
    let spec = FlexibleSpec {
        source: VolumeSource::Preset(perspective.clone()),
        reparam: None,
    };
    let camera = Flexible::new(&spec, width, height).map_err(|e| e.or_in_file(&loaded.source))?;
    let prepared = PreparedScene::new(&loaded.scene);
    let frame = perspective.frame;
    let forward = (frame.look_at - frame.position).normalize();
    let depth: Vec<f64> = (0..u64::from(width) * u64::from(height))
        .into_par_iter()
        .map(|k| {
            let (x, y) = (k % u64::from(width), k / u64::from(width));
            let pixel = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            pick(&prepared, &camera, pixel)
                .map_or(f64::INFINITY, |p| (p.point - frame.position).dot(forward))
        })
        .collect();
    let map = DdocMap::from_depth((width, height), &depth, depths, args.strength)
        .map_err(|e| e.or_in_file(&loaded.source))?;
    outputs.stage(id, |tmp| image_io::write_bytes(tmp, &map.to_pfm()))?;
    outputs.commit()
}
