//! An object's `orbit = { center = [x, y, z], axis = [x, y, z], period = S }`: the object
//! turns rigidly about the line through `center` along `axis` (default `[0, 1, 0]`), one turn
//! every `period` seconds (negative: the other way), over `flexcam animate`'s frames.

use serde::Deserialize;
use toml::Spanned;

use super::source::Source;
use super::strict::strict;
use crate::error::Result;
use crate::scene::{ObjectMotion, Orbit};

/// The `orbit` table as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOrbit {
    #[serde(deserialize_with = "strict")]
    center: Spanned<[f64; 3]>,
    #[serde(default, deserialize_with = "strict")]
    axis: Option<Spanned<[f64; 3]>>,
    period: Spanned<f64>,
}

/// The motion of object `id` from its `orbit` table. Errors (at the value): a center or axis
/// that is not finite, an axis of zero length, a period that is not finite or is zero.
pub(super) fn convert(src: &Source, table: &Spanned<RawOrbit>, id: u32) -> Result<ObjectMotion> {
    let raw = table.get_ref();
    let center = src.dvec3(&raw.center, "center")?;
    let axis = match &raw.axis {
        Some(value) => {
            let axis = src.dvec3(value, "axis")?;
            axis.try_normalize()
                .ok_or_else(|| src.error(&value.span(), "the orbit `axis` must not be zero"))?
        }
        None => glam::DVec3::Y,
    };
    let period = src.number(&raw.period, "period")?;
    if period == 0.0 {
        return Err(src.error(
            &raw.period.span(),
            "the orbit `period` (seconds per turn) must not be zero",
        ));
    }
    Ok(ObjectMotion {
        id,
        orbit: Orbit {
            center,
            axis,
            period,
        },
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::DVec3;

    use super::super::parse_animated;
    use super::super::tests::{assert_error_at, scene};

    const CAMERA: &str = "[projection]\ntype = \"perspective\"\nposition = [0, 0, 5]\n\
                          look_at = [0, 0, 0]\nfov = 60\n";

    fn ball(orbit: &str) -> String {
        format!("{CAMERA}[[object]]\nshape = \"sphere\"\ntranslate = [2, 0, 0]\norbit = {orbit}\n")
    }

    #[test]
    fn orbits_parse_with_their_object_ids_and_a_unit_axis() {
        let text = format!(
            "{}[[object]]\nshape = \"box\"\norbit = {{ center = [1, 2, 3], axis = [0, 0, 2], \
             period = -3 }}\n",
            ball("{ center = [0, 0, 0], period = 4 }")
        );
        let motions = scene(&text).motions;
        assert_eq!(motions.len(), 2);
        assert_eq!((motions[0].id, motions[1].id), (1, 2));
        assert_eq!(motions[0].orbit.axis, DVec3::Y);
        assert_eq!(motions[0].orbit.period, 4.0);
        assert_eq!(motions[1].orbit.center, DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(motions[1].orbit.axis, DVec3::Z);
        assert!(scene(CAMERA).motions.is_empty());
    }

    #[test]
    fn bad_orbits_are_errors_at_their_values() {
        let at = |orbit: &str, column, needle| assert_error_at(&ball(orbit), 9, column, needle);
        at(
            "{ center = [0, 0, 0], period = 0 }",
            40,
            "`period` (seconds per turn) must not be zero",
        );
        at("{ center = [0, 0, 0], period = nan }", 40, "period");
        at(
            "{ center = [0, 0, 0], axis = [0, 0, 0], period = 1 }",
            38,
            "`axis` must not be zero",
        );
        at("{ center = [0, inf, 0], period = 1 }", 20, "center");
        at("{ period = 1 }", 9, "center");
        at("{ center = [0, 0, 0], period = 1, speed = 2 }", 43, "speed");
    }

    #[test]
    fn an_animation_needs_camera_keys_or_moving_objects() {
        let timeline = "[animation]\nframes = 4\nfps = 2\n";
        assert_error_at(
            &format!("{CAMERA}{timeline}"),
            6,
            1,
            "or an object that moves (`orbit`)",
        );
        let text = format!("{}{timeline}", ball("{ center = [0, 0, 0], period = 4 }"));
        let (scene, animation) = parse_animated(&text, Path::new("dir/s.toml")).unwrap();
        let animation = animation.expect("an animation");
        assert!(animation.keys().is_empty());
        assert_eq!((animation.frames(), animation.time(1)), (4, 0.5));
        assert_eq!(scene.motions.len(), 1);
    }
}
