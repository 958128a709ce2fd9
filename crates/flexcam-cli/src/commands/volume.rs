//! `flexcam volume`: a scene projection's viewing volume as geometry (OBJ and MTL): the
//! control surfaces of a flexible volume, a sample of projectors, the image grid carried
//! onto the volume (module `flexcam::projection::volume_geometry`).

use std::path::PathBuf;

use clap::Args;
use flexcam::glam::{DVec2, DVec3};
use flexcam::image_io::{self, OutputSet};
use flexcam::projection::volume_geometry::{PartKind, VolumeGeometry, VolumeOptions, MAX_SAMPLES};
use flexcam::projection::Projection;
use flexcam::scene::Scene;
use flexcam::{Error, Result};

use super::scene_args::SceneArgs;

/// Arguments of `flexcam volume`.
#[derive(Args, Debug)]
pub struct VolumeArgs {
    /// The scene whose projection is drawn (its `[projection]` and `[image]`; its objects
    /// set how far the rays of projections other than flexible volumes are drawn).
    #[command(flatten)]
    scene: SceneArgs,
    /// The OBJ file to write; its material library is written beside it, with the same
    /// name ending in `.mtl`.
    #[arg(short, long, value_name = "FILE.obj")]
    output: PathBuf,
    /// Projectors drawn: N across and N down the image, its edges included.
    #[arg(long, value_name = "N", default_value_t = 7,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SAMPLES)))]
    projectors: u32,
    /// Cells along each side of a control surface's mesh.
    #[arg(long, value_name = "N", default_value_t = 16,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SAMPLES)))]
    surface_steps: u32,
    /// Cells of the image grid along each side of the image.
    #[arg(long, value_name = "N", default_value_t = 8,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SAMPLES)))]
    grid: u32,
    /// Where along the projectors the image grid lies, from 0 (their start) to 1 (their
    /// end). Default: a flexible volume's near surface (its far one when the near one is a
    /// point or a line), 1/5 of the way along the rays of other projections.
    #[arg(long, value_name = "F")]
    grid_at: Option<f64>,
    /// How far the rays of projections other than flexible volumes are drawn, world units.
    /// Default: from the image centre's ray start to the farthest corner of the box around
    /// the scene's objects (1 without objects). Flexible projectors end on their far surface.
    #[arg(long, value_name = "LENGTH")]
    reach: Option<f64>,
    /// Write every line (projectors, image grid) as a thin square tube of this radius, in
    /// world units, instead of an OBJ `l` line: renderers that draw only triangles, flexcam
    /// among them, then show the lines.
    #[arg(long, value_name = "RADIUS")]
    tube_radius: Option<f64>,
}

/// Runs `flexcam volume`: checks both outputs (never an input of the scene), loads the
/// scene, samples the volume and writes the OBJ and MTL together, then prints one line per
/// part.
pub fn run(args: &VolumeArgs) -> Result<()> {
    let mut outputs = OutputSet::new();
    let obj = outputs.output("the output", &args.output, &["obj"])?;
    let mtl_path = args.output.with_extension("mtl");
    let mtl = outputs.output("the material library output", &mtl_path, &["mtl"])?;
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let loaded = args.scene.load()?;
    super::declare_scene_inputs(&mut outputs, &loaded.scene.inputs)?;
    super::scene_args::print_warnings(&loaded);
    let projection = loaded.projection.as_ref();
    let reach = match args.reach {
        Some(reach) => reach,
        None => reach_past_objects(projection, &loaded.scene),
    };
    let options = VolumeOptions {
        projectors: args.projectors,
        surface_steps: args.surface_steps,
        grid_cells: args.grid,
        grid_at: args.grid_at,
        reach,
    };
    let mut geometry =
        VolumeGeometry::of(projection, &options).map_err(|e| e.or_in_file(&loaded.source))?;
    if let Some(radius) = args.tube_radius {
        geometry = geometry
            .with_tubes(radius)
            .map_err(|e| Error::new(format!("--tube-radius: {}", e.message)))?;
    }
    let (width, height) = projection.resolution();
    let header = [format!(
        "flexcam volume of {}: a {} projection at {width} x {height}",
        loaded.source,
        projection.kind()
    )];
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let obj_text = geometry.obj(&header, &mtl_name);
    let mtl_text = geometry.mtl();
    outputs.stage(obj, |tmp| image_io::write_bytes(tmp, obj_text.as_bytes()))?;
    outputs.stage(mtl, |tmp| image_io::write_bytes(tmp, mtl_text.as_bytes()))?;
    outputs.commit()?;
    super::print_stdout(&summary(&geometry))
}

/// One line per part: what was written of it.
fn summary(geometry: &VolumeGeometry) -> String {
    geometry
        .parts
        .iter()
        .map(|part| {
            let what = match (part.kind, part.is_empty()) {
                (PartKind::ControlSurface, true) => {
                    "no area (a point or a line), not written".to_string()
                }
                (_, true) => "nothing to draw, not written".to_string(),
                _ => format!(
                    "{} vertices, {} triangles, {} lines",
                    part.points.len(),
                    part.triangles.len(),
                    part.segments.len()
                ),
            };
            format!("{}: {what}\n", part.name)
        })
        .collect()
}

/// The default `--reach`: from the start of the image centre's ray (the eye of a
/// single-viewpoint camera) to the farthest corner of the box around the scene's objects;
/// 1 when the scene has no objects or the centre has no ray.
fn reach_past_objects(projection: &dyn Projection, scene: &Scene) -> f64 {
    let (w, h) = projection.resolution();
    let centre = DVec2::new(f64::from(w), f64::from(h)) / 2.0;
    let start = projection.ray(centre).map(|r| r.at(r.t_min));
    let bounds = scene
        .objects
        .iter()
        .filter_map(|o| o.mesh.bounds())
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
    let (Some(start), Some((lo, hi))) = (start, bounds) else {
        return 1.0;
    };
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let reach = (0..8)
        .map(|k| {
            let corner = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            (corner - start).length()
        })
        .fold(0.0, f64::max);
    if reach > 0.0 {
        reach
    } else {
        1.0
    }
}
