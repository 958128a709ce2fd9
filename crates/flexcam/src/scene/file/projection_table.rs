//! Readers shared by every `[projection]` type's conversion: the parameters a type cannot do
//! without (a missing one reported at the table's header), the camera frame and the `clip`
//! range.

use glam::DVec3;
use toml::Spanned;

use super::raw::RawProjection;
use super::source::Source;
use crate::error::Result;
use crate::projection::CameraFrame;

/// Looks up parameters a projection type cannot do without; a missing one is reported at the
/// table's header.
pub(super) struct Required<'a> {
    pub src: &'a Source<'a>,
    pub table: &'a Spanned<RawProjection>,
    /// The projection type's name, for messages.
    pub type_name: &'static str,
}

impl Required<'_> {
    pub fn raw(&self) -> &RawProjection {
        self.table.get_ref()
    }

    pub fn get<'v, T>(&self, value: &'v Option<Spanned<T>>, key: &str) -> Result<&'v Spanned<T>> {
        value.as_ref().ok_or_else(|| {
            self.src.error(
                &self.table.span(),
                format!("{} projection needs `{key}`", self.type_name),
            )
        })
    }
}

/// `position`, `look_at` (required) and `up` (default +y).
pub(super) fn camera_frame(src: &Source, required: &Required) -> Result<CameraFrame> {
    let raw = required.raw();
    Ok(CameraFrame {
        position: src.dvec3(required.get(&raw.position, "position")?, "position")?,
        look_at: src.dvec3(required.get(&raw.look_at, "look_at")?, "look_at")?,
        up: raw
            .up
            .as_ref()
            .map_or(Ok(DVec3::Y), |up| src.dvec3(up, "up"))?,
    })
}

/// `clip = [near, far]` with 0 <= near < far, when given.
pub(super) fn clip(src: &Source, raw: &RawProjection) -> Result<Option<[f64; 2]>> {
    let Some(c) = &raw.clip else {
        return Ok(None);
    };
    let [near, far] = src.vector(c, "clip")?;
    if !(0.0 <= near && near < far) {
        return Err(src.error(
            &c.span(),
            format!("`clip` must be [near, far] with 0 <= near < far, got [{near}, {far}]"),
        ));
    }
    Ok(Some([near, far]))
}
