//! `flexcam reproject`: an equirectangular photo seen through a scene's projection.

use std::path::PathBuf;

use clap::Args;
use flexcam::image_io::{self, ColorEncoding, OutputSet};
use flexcam::render::{reproject, EquirectPhoto};
use flexcam::Result;

use super::scene_args::SceneArgs;

/// Arguments of `flexcam reproject`.
#[derive(Args, Debug)]
pub struct ReprojectArgs {
    /// The equirectangular photo (.png, .jpg, .jpeg or .exr): longitude across (0 at the
    /// centre, along -z; +90 degrees along +x), latitude down from +90 at the top.
    #[arg(long, value_name = "PHOTO")]
    input: PathBuf,
    /// The projection: the scene file's `[projection]` and `[image]` (objects are ignored).
    #[command(flatten)]
    scene: SceneArgs,
    /// The image to write (PNG).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel (averaged, in the ray caster's pattern).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: u32,
}

/// Runs `flexcam reproject`: checks the output path (never the photo or a file of the
/// scene), reads the photo (an unsupported extension fails before reading), builds the
/// scene's projection, resamples and writes the PNG atomically.
pub fn run(args: &ReprojectArgs) -> Result<()> {
    // The budget applies to the photo too, which is read before the scene.
    args.scene.memory.apply();
    let mut outputs = OutputSet::new();
    let output = outputs.output("the output", &args.output, &["png"])?;
    outputs.input("the photo", &args.input)?;
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let photo = EquirectPhoto::new(image_io::read_linear_image(&args.input)?)
        .map_err(|e| e.or_in_file(&args.input))?;
    let loaded = args.scene.load()?;
    super::declare_scene_inputs(&mut outputs, &loaded.scene.inputs)?;
    let frame = reproject(
        &photo,
        loaded.projection.as_ref(),
        args.spp,
        loaded.scene.image.background,
    )
    .map_err(|e| e.or_in_file(&loaded.source))?;
    outputs.stage(output, |tmp| {
        image_io::write_color_png(&frame, tmp, ColorEncoding::Srgb)
    })?;
    outputs.commit()
}
