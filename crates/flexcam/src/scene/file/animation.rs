//! `[animation]`: `frames` frames at `fps` frames per second, with `[[animation.key]]` tables
//! that each hold a `time` (seconds) and a flexible `projection` table (a keyframed camera),
//! or none when objects move (`orbit`) and the camera is the scene's `[projection]`. Every key and every blend of neighbouring keys is built here, at the
//! scene's image size, so that an incompatible pair is reported at its key before any frame
//! is rendered.

use std::path::Path;

use toml::Spanned;

use super::raw::{RawAnimation, RawKey};
use super::source::Source;
use crate::calibrate;
use crate::error::Result;
use crate::projection::flexible::{Animation, Easing, FlexibleSpec, Keyframe, VolumeSource};
use crate::scene::ImageSettings;

/// Frames per second when `fps` is absent.
pub const DEFAULT_FPS: f64 = 24.0;

/// The most frames an animation may have: over an hour at 24 frames per second. Every
/// frame's output is named before the first is rendered, and a GIF holds them all.
pub const MAX_FRAMES: u32 = 100_000;

/// Converts and checks the `[animation]` table; `moving_objects`: some object has an `orbit`
/// (then the keys may be left out).
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawAnimation>,
    base_dir: &Path,
    image: &ImageSettings,
    moving_objects: bool,
) -> Result<Animation> {
    let raw = table.get_ref();
    let frames = *raw.frames.get_ref();
    if !(1..=MAX_FRAMES).contains(&frames) {
        return Err(src.error(
            &raw.frames.span(),
            format!("`frames` must be in 1..={MAX_FRAMES}, not {frames}"),
        ));
    }
    let fps = raw
        .fps
        .as_ref()
        .map_or(Ok(DEFAULT_FPS), |v| src.positive(v, "fps"))?;
    let easing = match raw.interpolation.as_ref() {
        None => Easing::Linear,
        Some(name) => match name.get_ref().as_str() {
            "linear" => Easing::Linear,
            "smooth" => Easing::Smooth,
            other => {
                return Err(src.unknown(
                    &name.span(),
                    "interpolation",
                    other,
                    &["linear", "smooth"],
                ))
            }
        },
    };
    if raw.key.is_empty() && !moving_objects {
        return Err(src.error(
            &table.span(),
            "[animation] needs at least one [[animation.key]] with a `time` and a `projection`, \
             or an object that moves (`orbit`)",
        ));
    }
    let mut keys: Vec<Keyframe> = Vec::with_capacity(raw.key.len());
    for (index, key) in raw.key.iter().enumerate() {
        let keyframe = keyframe(src, key.get_ref(), base_dir, image)?;
        let time = &key.get_ref().time;
        if keyframe.time < 0.0 {
            return Err(src.error(
                &time.span(),
                format!(
                    "animation key time must be at least 0 seconds, got {}",
                    keyframe.time
                ),
            ));
        }
        let at_projection = |message: String| src.error(&key.get_ref().projection.span(), message);
        calibrate::build_flexible(&keyframe.projection, image.width, image.height)
            .map_err(|e| at_projection(e.message))?;
        if let Some(before) = keys.last() {
            if keyframe.time <= before.time {
                return Err(src.error(
                    &time.span(),
                    format!(
                        "animation key time {} must be later than the key before it ({})",
                        keyframe.time, before.time
                    ),
                ));
            }
            let halfway = FlexibleSpec {
                source: VolumeSource::Interpolated {
                    weight: 0.5,
                    first: Box::new(before.projection.clone()),
                    second: Box::new(keyframe.projection.clone()),
                },
                reparam: None,
            };
            calibrate::build_flexible(&halfway, image.width, image.height).map_err(|e| {
                at_projection(format!(
                    "keys {} and {index} cannot be interpolated: {}",
                    index - 1,
                    e.message
                ))
            })?;
        }
        keys.push(keyframe);
    }
    Animation::new(frames, fps, easing, keys).map_err(|e| src.error(&table.span(), e.message))
}

/// One key: its time and its projection, which must be flexible.
fn keyframe(
    src: &Source,
    key: &RawKey,
    base_dir: &Path,
    image: &ImageSettings,
) -> Result<Keyframe> {
    let time = src.number(&key.time, "time")?;
    let projection = super::projection::flexible_part(
        src,
        &key.projection,
        base_dir,
        [image.width, image.height],
        "animation keys need",
    )?;
    Ok(Keyframe { time, projection })
}
