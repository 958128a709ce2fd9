//! `flexcam reproject`: a photo (equirectangular, cylindrical or fisheye) seen through a
//! scene's projection.

use std::path::PathBuf;

use clap::builder::PossibleValuesParser;
use clap::Args;
use flexcam::glam::DVec3;
use flexcam::image_io::{self, ColorEncoding, OutputSet};
use flexcam::projection::{FisheyeMapping, MAPPING_NAMES};
use flexcam::render::{reproject, LinearImage, Photo, PhotoProjection, PHOTO_PROJECTION_NAMES};
use flexcam::{Error, Result};

use super::scene_args::SceneArgs;

/// Arguments of `flexcam reproject`.
#[derive(Args, Debug)]
pub struct ReprojectArgs {
    /// The photo (.png, .jpg, .jpeg or .exr), laid out as --input-projection says.
    #[arg(long, value_name = "PHOTO")]
    input: PathBuf,
    /// How the photo's pixels map to directions, as the scene type of that name renders
    /// them: `equirectangular` (the default: longitude across, 0 at the centre, latitude
    /// down from the top), `cylindrical` (longitude across, tan(latitude) down) or `fisheye`
    /// (the angle off the axis grows with the distance from the photo's centre, in the
    /// circle inscribed in its shorter side).
    #[arg(
        help_heading = "Photo",
        long,
        value_name = "TYPE",
        default_value = "equirectangular",
        value_parser = PossibleValuesParser::new(PHOTO_PROJECTION_NAMES)
    )]
    input_projection: String,
    /// Equirectangular and cylindrical photos: the longitude range across the photo,
    /// degrees (default 360: the columns wrap round).
    #[arg(help_heading = "Photo", long, value_name = "DEGREES")]
    input_h_fov: Option<f64>,
    /// Equirectangular photos: the latitude range down the photo; cylindrical photos: the
    /// vertical angle at the photo's centre; degrees. Default: for a whole equirectangular
    /// panorama (no --input-h-fov) 180, whatever the photo's shape; otherwise square pixels
    /// at the centre.
    #[arg(help_heading = "Photo", long, value_name = "DEGREES")]
    input_v_fov: Option<f64>,
    /// Fisheye photos: the angle across the image circle, degrees (default 180).
    #[arg(help_heading = "Photo", long, value_name = "DEGREES")]
    input_fov: Option<f64>,
    /// Fisheye photos: how the angle off the axis maps to the distance from the centre
    /// (default equidistant).
    #[arg(
        help_heading = "Photo",
        long,
        value_name = "MAPPING",
        value_parser = PossibleValuesParser::new(MAPPING_NAMES.into_iter().filter(|m| *m != "polynomial"))
    )]
    input_mapping: Option<String>,
    /// The world direction the photo's centre looks in (default 0,0,-1).
    #[arg(
        help_heading = "Photo",
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    input_direction: Option<Vec<f64>>,
    /// The world direction that is up in the photo (default 0,1,0; only its part
    /// perpendicular to --input-direction counts).
    #[arg(
        help_heading = "Photo",
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    input_up: Option<Vec<f64>>,
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

impl ReprojectArgs {
    /// The photo's projection from the flags. Errors: a flag of another kind of photo
    /// (`--input-fov` with a cylindrical photo, ...).
    fn photo_projection(&self, width: u32, height: u32) -> Result<PhotoProjection> {
        let kind = self.input_projection.as_str();
        let refuse = |flag: &str, takes: &str| {
            Err(Error::new(format!(
                "{flag} applies to --input-projection {takes}, not {kind}"
            )))
        };
        let aspect = f64::from(height) / f64::from(width);
        let h_fov = self.input_h_fov.unwrap_or(360.0);
        Ok(match kind {
            "fisheye" => {
                if self.input_h_fov.is_some() {
                    return refuse("--input-h-fov", "equirectangular or cylindrical");
                }
                if self.input_v_fov.is_some() {
                    return refuse("--input-v-fov", "equirectangular or cylindrical");
                }
                let mapping = match self.input_mapping.as_deref() {
                    None | Some("equidistant") => FisheyeMapping::Equidistant,
                    Some("equisolid") => FisheyeMapping::Equisolid,
                    Some("stereographic") => FisheyeMapping::Stereographic,
                    Some(_) => FisheyeMapping::Orthographic,
                };
                PhotoProjection::Fisheye {
                    fov: self.input_fov.unwrap_or(180.0),
                    mapping,
                }
            }
            _ if self.input_fov.is_some() => return refuse("--input-fov", "fisheye"),
            _ if self.input_mapping.is_some() => return refuse("--input-mapping", "fisheye"),
            "cylindrical" => PhotoProjection::Cylindrical {
                h_fov,
                // Square pixels on the horizon: the height per pixel on the unit cylinder
                // equals the angle per pixel.
                v_fov: self.input_v_fov.unwrap_or_else(|| {
                    2.0 * (0.5 * h_fov.to_radians() * aspect).atan().to_degrees()
                }),
            },
            _ => PhotoProjection::Equirectangular {
                h_fov,
                v_fov: self.input_v_fov.unwrap_or(match self.input_h_fov {
                    None => 180.0,
                    Some(_) => h_fov * aspect,
                }),
            },
        })
    }
}

/// `--input-direction` or `--input-up`: three numbers, or `default`.
fn direction(flag: &str, given: &Option<Vec<f64>>, default: DVec3) -> Result<DVec3> {
    match given.as_deref() {
        None => Ok(default),
        Some(&[x, y, z]) => Ok(DVec3::new(x, y, z)),
        Some(other) => Err(Error::new(format!(
            "{flag}: needs 3 numbers, got {}",
            other.len()
        ))),
    }
}

/// Runs `flexcam reproject`: checks the output path (never the photo or a file of the
/// scene), reads the photo (an unsupported extension fails before reading), lays it out by
/// its projection, builds the scene's projection, resamples and writes the PNG atomically.
pub fn run(args: &ReprojectArgs) -> Result<()> {
    // The budget applies to the photo too, which is read before the scene.
    args.scene.memory.apply();
    let mut outputs = OutputSet::new();
    let output = outputs.output("the output", &args.output, &["png"])?;
    outputs.input("the photo", &args.input)?;
    if let Some(source) = &args.scene.scene {
        super::declare_scene_file(&mut outputs, source)?;
    }
    let look = direction("--input-direction", &args.input_direction, DVec3::NEG_Z)?;
    let up = direction("--input-up", &args.input_up, DVec3::Y)?;
    let image: LinearImage = image_io::read_linear_image(&args.input)?;
    let projection = args.photo_projection(image.width, image.height)?;
    let photo = Photo::new(image, projection, look, up).map_err(|e| {
        Error::in_file(
            &args.input,
            format!(
                "read as a photo of type {}: {}",
                projection.name(),
                e.message
            ),
        )
    })?;
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
