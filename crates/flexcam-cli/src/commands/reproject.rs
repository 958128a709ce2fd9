//! `flexcam reproject`: an equirectangular photo seen through a scene's projection.

use std::path::PathBuf;

use clap::Args;
use flexcam::image_io::{self, ColorEncoding};
use flexcam::render::reproject::{reproject, EquirectPhoto};
use flexcam::{Error, Result};

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

/// Runs `flexcam reproject`: checks the output path, reads the photo (an unsupported
/// extension fails before reading), builds the scene's
/// projection, resamples and writes the PNG atomically.
pub fn run(args: &ReprojectArgs) -> Result<()> {
    image_io::check_output_path(&args.output, &["png"])?;
    if args.input == args.output {
        return Err(Error::in_file(
            &args.output,
            "the output would overwrite the input photo",
        ));
    }
    let photo = EquirectPhoto::new(image_io::read_linear_image(&args.input)?)
        .map_err(|e| e.or_in_file(&args.input))?;
    let loaded = args.scene.load()?;
    let frame = reproject(
        &photo,
        loaded.projection.as_ref(),
        args.spp,
        loaded.scene.image.background,
    );
    image_io::write_color_png(&frame, &args.output, ColorEncoding::Srgb)?.commit()
}
