//! `[[light]]`: point and directional lights.

use glam::Vec3;
use toml::Spanned;

use super::raw::RawLight;
use super::source::Source;
use crate::error::Result;
use crate::scene::Light;

/// Light type names as written in scene files.
const LIGHT_TYPES: [&str; 2] = ["point", "directional"];

/// Converts one light table. `intensity` defaults to 1 and `color` to white.
pub(super) fn convert(src: &Source, table: &Spanned<RawLight>) -> Result<Light> {
    let raw = table.get_ref();
    let color = raw
        .color
        .as_ref()
        .map_or(Ok(Vec3::ONE), |c| src.color(c, "color"))?;
    let intensity = match &raw.intensity {
        None => 1.0,
        Some(i) => {
            let value = src.number(i, "intensity")?;
            if value < 0.0 {
                return Err(src.error(
                    &i.span(),
                    format!("`intensity` must not be negative, not {value}"),
                ));
            }
            value as f32
        }
    };
    let kind = raw.kind.get_ref().as_str();
    // Each type takes one placement key and forbids the other's.
    let (key, own, other) = match kind {
        "point" => ("position", &raw.position, ("direction", &raw.direction)),
        "directional" => ("direction", &raw.direction, ("position", &raw.position)),
        _ => return Err(src.unknown(&raw.kind.span(), "light type", kind, &LIGHT_TYPES)),
    };
    if let (other_key, Some(value)) = other {
        return Err(src.error(
            &value.span(),
            format!("`{other_key}` does not apply to {kind} lights"),
        ));
    }
    let placement = own
        .as_ref()
        .ok_or_else(|| src.error(&table.span(), format!("{kind} light needs `{key}`")))?;
    let vector = src.vec3(placement, key)?;
    Ok(if kind == "point" {
        Light::Point {
            position: vector,
            color,
            intensity,
        }
    } else {
        Light::Directional {
            direction: vector
                .try_normalize()
                .ok_or_else(|| src.error(&placement.span(), "`direction` must not be zero"))?,
            color,
            intensity,
        }
    })
}
