//! `flexcam render --atlas FILE`: the joint texture atlas of every trilinear reflector with
//! `reflection = "atlas"`, one image each, named after the reflector and the light path
//! rendered into it (docs/camera-triangles.md, "The joint texture atlas").

use std::path::{Path, PathBuf};

use flexcam::image_io::{self, ColorEncoding, ColorFormat, OutputId, OutputSet, PngBits};
use flexcam::projection::trilinear_builders::Optic;
use flexcam::render::{AtlasImage, Shading};
use flexcam::scene::{Finish, ReflectionImage, Scene};
use flexcam::{Error, Result};

/// One atlas the render will make: its reflector, the light path, the output it goes to.
struct Wanted {
    id: u32,
    name: String,
    reflection: bool,
    output: OutputId,
    path: PathBuf,
}

/// The atlas outputs of one `flexcam render`, declared before it renders.
pub struct AtlasOutputs {
    wanted: Vec<Wanted>,
    format: ColorFormat,
}

impl AtlasOutputs {
    /// Declares in `outputs` the atlas images `--atlas base` asks of `scene` in `shading`:
    /// for each trilinear reflector with `reflection = "atlas"`, `STEM-NAME-reflection.EXT`
    /// for a mirror and `STEM-NAME-refraction.EXT` for glass (`STEM`, `EXT` those of `base`,
    /// `NAME` the reflector's object name, characters other than letters, digits, `-` and
    /// `_` as `_`), and for glass in lit shading also its Fresnel reflection's
    /// `STEM-NAME-reflection.EXT`. Errors: an extension that is not a colour output's, a
    /// scene without such a reflector, an output the set refuses.
    pub fn declare(
        outputs: &mut OutputSet,
        base: &Path,
        scene: &Scene,
        shading: Shading,
    ) -> Result<AtlasOutputs> {
        let format = ColorFormat::of(base, PngBits::Eight)?;
        let mut wanted = Vec::new();
        for reflector in &scene.trilinear_reflectors {
            if reflector.reflection != ReflectionImage::Atlas {
                continue;
            }
            let Some(object) = scene.objects.iter().find(|o| o.id == reflector.id) else {
                continue;
            };
            let name = file_safe(&object.name);
            let paths = match object.material.finish {
                Finish::Glass { .. } if shading != Shading::Flat => vec![false, true],
                Finish::Glass { .. } => vec![false],
                _ => vec![true],
            };
            for reflection in paths {
                let path = named(base, &name, reflection);
                let output = outputs.output("the atlas output", &path, &ColorFormat::EXTENSIONS)?;
                wanted.push(Wanted {
                    id: reflector.id,
                    name: name.clone(),
                    reflection,
                    output,
                    path,
                });
            }
        }
        if wanted.is_empty() {
            return Err(Error::in_file(
                base,
                "--atlas: the scene has no trilinear reflector with reflection = \"atlas\"",
            ));
        }
        Ok(AtlasOutputs { wanted, format })
    }

    /// Stages every declared atlas from `atlases` (the render's), encoded as the main
    /// image is. Errors: a declared atlas the render did not make (a reflector out of view
    /// has no camera triangles), an image that cannot be written.
    pub fn stage(
        self,
        outputs: &mut OutputSet,
        atlases: &[AtlasImage],
        encoding: ColorEncoding,
    ) -> Result<()> {
        for wanted in self.wanted {
            let atlas = atlases.iter().find(|a| {
                a.id == wanted.id && matches!(a.optic, Optic::Reflect) == wanted.reflection
            });
            let Some(atlas) = atlas else {
                return Err(Error::in_file(
                    &wanted.path,
                    format!(
                        "--atlas: reflector \"{}\" has no atlas in this view (no camera \
                         triangle of it is seen)",
                        wanted.name
                    ),
                ));
            };
            outputs.stage(wanted.output, |tmp| {
                image_io::write_color(&atlas.image, tmp, self.format, encoding)
            })?;
        }
        Ok(())
    }
}

/// `base` with `-NAME-reflection` or `-NAME-refraction` added to its stem.
fn named(base: &Path, name: &str, reflection: bool) -> PathBuf {
    let stem = base
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let path = if reflection {
        "reflection"
    } else {
        "refraction"
    };
    let mut file = format!("{stem}-{name}-{path}");
    if let Some(extension) = base.extension() {
        file.push('.');
        file.push_str(&extension.to_string_lossy());
    }
    base.with_file_name(file)
}

/// `name` with every character but ASCII letters, digits, `-` and `_` replaced by `_`.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
