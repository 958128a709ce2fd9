//! `pieces = [ { rect = [u0, v0, u1, v1], ... }, ... ]` of a flexible projection: several
//! flexible projections, each owning an image rectangle (module
//! `projection::flexible::pieces`). Each piece is a flexible projection table without
//! `type` (or with `type = "flexible"`) plus its `rect`; the table holding `pieces` takes
//! nothing else. Errors point at the piece, the rectangle or the key at fault; two
//! overlapping rectangles are reported at the later one, naming both.

use toml::Spanned;

use super::projection_table::Required;
use super::raw::RawProjection;
use super::source::Source;
use crate::error::Result;
use crate::projection::flexible::pieces::{check_rect, overlapping, MAX_PIECES};
use crate::projection::flexible::{FlexibleSpec, Piece, VolumeSource};

/// Converts the list of pieces, each piece's table by `flexible` (the flexible table's own
/// conversion, passed in so that this module stays below it).
pub(super) fn convert(
    src: &Source,
    list: &Spanned<Vec<Spanned<RawProjection>>>,
    flexible: impl Fn(&Required) -> Result<FlexibleSpec>,
) -> Result<VolumeSource> {
    let tables = list.get_ref();
    if tables.is_empty() || tables.len() > MAX_PIECES {
        return Err(src.error(
            &list.span(),
            format!(
                "`pieces` must hold 1 to {MAX_PIECES} pieces, got {}",
                tables.len()
            ),
        ));
    }
    let mut pieces: Vec<Piece> = Vec::with_capacity(tables.len());
    for (index, table) in tables.iter().enumerate() {
        let number = index + 1;
        let raw = table.get_ref();
        if let Some(kind) = raw.kind.as_ref().filter(|k| k.get_ref() != "flexible") {
            return Err(src.error(
                &kind.span(),
                format!(
                    "piece {number} is a flexible projection: leave out `type` or write \
                     type = \"flexible\", not \"{}\"",
                    kind.get_ref()
                ),
            ));
        }
        if let Some(inner) = &raw.pieces {
            return Err(src.error(
                &inner.span(),
                format!("piece {number} holds `pieces` of its own: pieces do not nest"),
            ));
        }
        let rect = raw.rect.as_ref().ok_or_else(|| {
            src.error(
                &table.span(),
                format!(
                    "piece {number} needs `rect = [u0, v0, u1, v1]`, the image rectangle it owns"
                ),
            )
        })?;
        check_rect(*rect.get_ref())
            .map_err(|e| src.error(&rect.span(), format!("piece {number}: {}", e.message)))?;
        let required = Required {
            src,
            table,
            type_name: "flexible",
        };
        let spec = flexible(&required)?;
        pieces.push(Piece {
            rect: *rect.get_ref(),
            spec,
        });
        let rects: Vec<[f64; 4]> = pieces.iter().map(|p| p.rect).collect();
        if let Some((first, _)) = overlapping(&rects) {
            return Err(src.error(
                &rect.span(),
                format!(
                    "piece {number}'s rect {:?} overlaps piece {}'s rect {:?}: pieces may only \
                     touch",
                    rect.get_ref(),
                    first + 1,
                    rects[first]
                ),
            ));
        }
    }
    Ok(VolumeSource::Pieces(pieces))
}
