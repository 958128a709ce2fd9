//! `[projection.interpolate]` of a flexible projection: the static blend Q = a Q1 + (1 - a) Q2
//! of two flexible projections (thesis eq. 6.1), `weight` = a any finite number (outside
//! [0, 1] it extrapolates), `[projection.interpolate.first]` and `.second` each a whole
//! `type = "flexible"` projection table. Projections on different re-parameterisations blend
//! on the image's own domain (fig. 6.16).

use std::path::Path;

use toml::Spanned;

use super::raw::{RawInterpolate, RawProjection};
use super::source::Source;
use crate::calibrate;
use crate::error::Result;
use crate::projection::flexible::{FlexibleSpec, VolumeSource};
use crate::projection::ProjectionSpec;

/// Converts the flexible table `table` whose `interpolate` is `blend`, and builds it at
/// `image_size` so that a pair that cannot be blended is reported at the table.
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawProjection>,
    blend: &Spanned<RawInterpolate>,
    base_dir: &Path,
    image_size: [u32; 2],
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
    let part = |part: &Spanned<RawProjection>| {
        flexible_part(
            src,
            part,
            base_dir,
            image_size,
            "`interpolate`'s `first` and `second` need",
        )
    };
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

/// The flexible projection of table `table` (within another table), or an error at its
/// `type` beginning with `who` (what needs a flexible one).
pub(super) fn flexible_part(
    src: &Source,
    table: &Spanned<RawProjection>,
    base_dir: &Path,
    image_size: [u32; 2],
    who: &str,
) -> Result<FlexibleSpec> {
    match super::projection::convert(src, table, base_dir, image_size)? {
        ProjectionSpec::Flexible(projection) => Ok(*projection),
        other => Err(src.error(
            &table.get_ref().kind.span(),
            format!(
                "{who} type = \"flexible\" (only flexible volumes can be interpolated), not \
                 \"{}\"",
                other.kind()
            ),
        )),
    }
}
