//! `flexcam raymap`: a scene projection's per-pixel rays, and its STMap against a reference
//! camera, as OpenEXR files for compositors and other renderers (`image_io::write_ray_map_exr`,
//! `image_io::write_stmap`).

use std::path::{Path, PathBuf};

use clap::Args;
use flexcam::image_io::{self, OutputSet, StMapFormat};
use flexcam::projection::ray_map::ray_map;
use flexcam::render::{st_map, PreparedScene, StPoints};
use flexcam::scene::{self, Overrides};
use flexcam::{try_alloc, Error, Result};

use super::scene_args::{print_warnings, SceneArgs};

/// Arguments of `flexcam raymap`.
#[derive(Args, Debug)]
pub struct RaymapArgs {
    #[command(flatten, next_help_heading = "Scene")]
    scene: SceneArgs,
    /// Write each pixel centre's ray (.exr): `origin.X/Y/Z`, unit `direction.X/Y/Z` of the
    /// projector's first segment, for curved projectors also `exit_origin.*` and
    /// `exit_direction.*` where it ends; `A` = 1 where the pixel has a ray, 0 where not.
    #[arg(help_heading = "Outputs", short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write the STMap against `--reference` (.exr float, or .png 16-bit): `R` = s, `G` = t
    /// of the reference image pixel seeing the same scene point (Nuke's convention:
    /// s = (x + 0.5) / w, t = 1 - (y + 0.5) / h), `B` = 0, `A` = 0 where the reference does
    /// not see it.
    #[arg(
        help_heading = "Outputs",
        long,
        value_name = "FILE",
        requires = "reference"
    )]
    stmap: Option<PathBuf>,
    /// The reference camera of `--stmap`: a scene file (or `builtin:NAME`) whose projection
    /// and image size are the camera's (its objects are not used); it needs an inverse.
    #[arg(help_heading = "STMap", long, value_name = "SCENE", requires = "stmap")]
    reference: Option<String>,
    /// The scene point of a pixel is the point at this distance along its projector, not
    /// the first surface the scene's ray cast hits (`--stmap` only).
    #[arg(help_heading = "STMap", long, value_name = "D", requires = "stmap")]
    distance: Option<f64>,
}

/// Runs `flexcam raymap`: both outputs are written together, or none.
pub fn run(args: &RaymapArgs) -> Result<()> {
    if args.output.is_none() && args.stmap.is_none() {
        return Err(Error::new(
            "raymap: nothing to write (give -o FILE.exr, --stmap FILE.exr, or both)",
        ));
    }
    if let Some(d) = args.distance.filter(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(Error::new(format!(
            "--distance must be a positive number, got {d}"
        )));
    }
    let mut outputs = OutputSet::new();
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    if let Some(reference) = args
        .reference
        .as_deref()
        .filter(|r| !r.starts_with("builtin:"))
    {
        outputs.input("the reference camera", Path::new(reference))?;
    }
    let rays = args
        .output
        .as_deref()
        .map(|path| outputs.output("the ray map", path, &["exr"]))
        .transpose()?;
    let stmap = args
        .stmap
        .as_deref()
        .map(|path| {
            let id = outputs.output("the STMap", path, &StMapFormat::EXTENSIONS)?;
            Ok::<_, Error>((id, StMapFormat::of(path)?))
        })
        .transpose()?;

    let loaded = args.scene.load()?;
    super::declare_scene_inputs(&mut outputs, &loaded.scene.inputs)?;
    let projection = loaded.projection.as_ref();
    if let Some(id) = rays {
        let map = ray_map(projection).map_err(|e| e.or_in_file(&loaded.source))?;
        outputs.stage(id, |tmp| image_io::write_ray_map_exr(&map, tmp))?;
    }
    if let (Some((id, format)), Some(source)) = (stmap, &args.reference) {
        let reference = scene::load_with(source, &Overrides::default())?;
        let prepared;
        let points = match args.distance {
            Some(d) => StPoints::Distance(d),
            None => {
                prepared = PreparedScene::new(&loaded.scene);
                StPoints::FirstHit(&prepared)
            }
        };
        // The map is of the scene's image: memory it cannot have is the scene's.
        let map = st_map(projection, reference.projection.as_ref(), points).map_err(|e| {
            let file = if try_alloc::is_out_of_memory(&e) {
                &loaded.source
            } else {
                &reference.source
            };
            e.or_in_file(file)
        })?;
        outputs.stage(id, |tmp| image_io::write_stmap(&map, tmp, format))?;
    }
    outputs.commit()?;
    print_warnings(&loaded);
    Ok(())
}
