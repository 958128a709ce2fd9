//! `[projection.interpolate]` of a flexible projection: the static blend Q = a Q1 + (1 - a) Q2
//! of two flexible projections (thesis eq. 6.1), `weight` = a any finite number (outside
//! [0, 1] it extrapolates), `[projection.interpolate.first]` and `.second` each a whole
//! `type = "flexible"` projection table. Projections on different re-parameterisations blend
//! on the image's own domain (fig. 6.16).

use toml::Spanned;

use super::raw::{RawInterpolate, RawProjection};
use super::source::Source;
use crate::calibrate;
use crate::error::Result;
use crate::projection::flexible::{FlexibleSpec, VolumeSource};

/// Converts the flexible table `table` whose `interpolate` is `blend`, its `first` and
/// `second` tables by `part` (the projection table reader, passed in because it is the one
/// that calls this), and builds it at `image_size` so that a pair that cannot be blended is
/// reported at the table.
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawProjection>,
    blend: &Spanned<RawInterpolate>,
    image_size: [u32; 2],
    part: impl Fn(&Spanned<RawProjection>, &str) -> Result<FlexibleSpec>,
) -> Result<FlexibleSpec> {
    if let Some((key, span)) = table
        .get_ref()
        .present_keys()
        .into_iter()
        .find(|(key, _)| *key != "interpolate")
    {
        return Err(src.error(
            &span,
            format!(
                "`{key}` is not a parameter of flexible projections given by `interpolate` \
                 (they take only `interpolate`; put the volumes' keys in its `first` and \
                 `second` tables)"
            ),
        ));
    }
    let raw = blend.get_ref();
    let weight = src.number(&raw.weight, "weight")?;
    let part =
        |table: &Spanned<RawProjection>| part(table, "`interpolate`'s `first` and `second` need");
    let spec = FlexibleSpec {
        source: VolumeSource::Interpolated {
            weight,
            first: Box::new(part(&raw.first)?),
            second: Box::new(part(&raw.second)?),
        },
        reparam: None,
    };
    let [width, height] = image_size;
    calibrate::build_flexible(&spec, width, height)
        .map_err(|e| src.error(&blend.span(), e.message))?;
    Ok(spec)
}
