//! An object's `displacement = { ... }`: a grey height map or a procedural height function,
//! with scale, level and fraction, checked against the object's mesh.
//!
//! - `map = "h.png"`: an 8- or 16-bit grey PNG, relative to the scene file (an input of the
//!   scene);
//! - `procedural = "waves"` with `waves = [[amplitude, m, n, phase], ...]` (integer
//!   frequencies `m`, `n`), or `procedural = "bumps"` with `cells = [nu, nv]` and `radius`;
//! - `scale` (world units, at least 0), `level` (0 to [`crate::scene::displacement::MAX_LEVEL`]), `fraction` (in [0, 1],
//!   default 1).

use std::path::Path;
use std::sync::Arc;

use serde::Deserialize;
use toml::Spanned;

use super::source::Source;
use crate::error::Result;
use crate::scene::displacement::{
    check_parameters, DisplacementSpec, HeightImage, HeightSource, ProceduralSpec, Wave,
};
use crate::scene::Mesh;

/// The table as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDisplacement {
    map: Option<Spanned<String>>,
    procedural: Option<Spanned<String>>,
    scale: Spanned<f64>,
    level: Spanned<i64>,
    fraction: Option<Spanned<f64>>,
    waves: Option<Spanned<Vec<[f64; 4]>>>,
    cells: Option<Spanned<[i64; 2]>>,
    radius: Option<Spanned<f64>>,
}

/// Procedural height functions by name.
const PROCEDURALS: [&str; 2] = ["waves", "bumps"];

/// The displacement `table` describes, for an object whose meshes are `meshes` (named
/// `name`). Errors, at the offending value: a mesh without texture coordinates or vertex
/// normals, neither or both of `map` and `procedural`, an unknown procedural name, a
/// parameter of the other height source, a number out of bounds, an unreadable map (the
/// map's own errors name the map file).
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawDisplacement>,
    base_dir: &Path,
    name: &str,
    meshes: &[&Mesh],
) -> Result<Arc<DisplacementSpec>> {
    let raw = table.get_ref();
    let at = table.span();
    for mesh in meshes {
        let missing = match (mesh.uvs.is_empty(), mesh.normals.is_empty()) {
            (true, true) => Some("texture coordinates and vertex normals"),
            (true, false) => Some("texture coordinates"),
            (false, true) => Some("vertex normals"),
            (false, false) => None,
        };
        if let Some(missing) = missing {
            return Err(src.error(
                &at,
                format!(
                    "`displacement` needs a mesh with texture coordinates and vertex normals; \
                     \"{name}\" has no {missing}"
                ),
            ));
        }
    }
    let height =
        match (&raw.map, &raw.procedural) {
            (Some(map), None) => {
                reject(src, &raw.waves, "waves", "a height map")?;
                reject(src, &raw.cells, "cells", "a height map")?;
                reject(src, &raw.radius, "radius", "a height map")?;
                let path = src.existing_file(map, base_dir, "height map")?;
                HeightSource::Map(HeightImage::load(&path)?)
            }
            (None, Some(kind)) => HeightSource::Procedural(procedural(src, raw, kind)?),
            (Some(map), Some(_)) => {
                return Err(src.error(
                    &map.span(),
                    "`displacement` takes either `map` or `procedural`, not both",
                ))
            }
            (None, None) => return Err(src.error(
                &at,
                "`displacement` needs `map = \"FILE.png\"` or `procedural = \"waves\"` / \"bumps\"",
            )),
        };
    let scale = src.number(&raw.scale, "scale")?;
    let fraction = match &raw.fraction {
        Some(f) => src.number(f, "fraction")?,
        None => 1.0,
    };
    let level = u32::try_from(*raw.level.get_ref()).unwrap_or(u32::MAX);
    // Each parameter checked alone, so that the error points at its own value.
    let checks = [
        (raw.scale.span(), check_parameters(scale, 0, 1.0)),
        (raw.level.span(), check_parameters(0.0, level, 1.0)),
        (
            raw.fraction.as_ref().map_or(at.clone(), Spanned::span),
            check_parameters(0.0, 0, fraction),
        ),
    ];
    for (span, check) in checks {
        check.map_err(|e| src.error(&span, e.to_string()))?;
    }
    let spec = DisplacementSpec::new(height, scale, level, fraction)
        .map_err(|e| src.error(&at, e.to_string()))?;
    Ok(Arc::new(spec))
}

/// Fails at `value` (key `key`) if present: it does not apply to `what`.
fn reject<T>(src: &Source, value: &Option<Spanned<T>>, key: &str, what: &str) -> Result<()> {
    match value {
        Some(v) => Err(src.error(&v.span(), format!("`{key}` does not apply to {what}"))),
        None => Ok(()),
    }
}

/// The procedural height function named `kind`.
fn procedural(
    src: &Source,
    raw: &RawDisplacement,
    kind: &Spanned<String>,
) -> Result<ProceduralSpec> {
    match kind.get_ref().as_str() {
        "waves" => {
            reject(src, &raw.cells, "cells", "procedural \"waves\"")?;
            reject(src, &raw.radius, "radius", "procedural \"waves\"")?;
            let Some(waves) = &raw.waves else {
                return Err(src.error(
                    &kind.span(),
                    "procedural \"waves\" needs `waves = [[amplitude, m, n, phase], ...]`",
                ));
            };
            let mut out = Vec::with_capacity(waves.get_ref().len());
            for w in waves.get_ref() {
                src.all_finite(w, waves, "waves")?;
                let [amplitude, m, n, phase] = *w;
                if m.fract() != 0.0 || n.fract() != 0.0 {
                    return Err(src.error(
                        &waves.span(),
                        format!("`waves`: frequencies must be integers, not {m} and {n}"),
                    ));
                }
                let clamp = |x: f64| x.clamp(i32::MIN as f64, i32::MAX as f64) as i32;
                out.push(Wave {
                    amplitude,
                    frequency: [clamp(m), clamp(n)],
                    phase,
                });
            }
            ProceduralSpec::waves(out).map_err(|e| src.error(&waves.span(), e.to_string()))
        }
        "bumps" => {
            reject(src, &raw.waves, "waves", "procedural \"bumps\"")?;
            let (Some(cells), Some(radius)) = (&raw.cells, &raw.radius) else {
                return Err(src.error(
                    &kind.span(),
                    "procedural \"bumps\" needs `cells = [nu, nv]` and `radius`",
                ));
            };
            let [nu, nv] = *cells.get_ref();
            let count = |n: i64| u32::try_from(n).unwrap_or(0);
            let r = src.number(radius, "radius")?;
            ProceduralSpec::bumps([count(nu), count(nv)], r).map_err(|e| {
                let span = if e.to_string().contains("radius") {
                    radius.span()
                } else {
                    cells.span()
                };
                src.error(&span, e.to_string())
            })
        }
        other => Err(src.unknown(&kind.span(), "procedural height", other, &PROCEDURALS)),
    }
}
