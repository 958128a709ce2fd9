//! An object's `displacement = { ... }`: a grey height map or a procedural height function,
//! with scale, level and fraction, checked against the object's mesh.
//!
//! - `map = "h.png"`: an 8- or 16-bit grey PNG, relative to the scene file (an input of the
//!   scene);
//! - `procedural = "waves"` with `waves = [[amplitude, m, n, phase], ...]` (integer
//!   frequencies `m`, `n`), or `procedural = "bumps"` with `cells = [nu, nv]` and `radius`;
//! - `scale` (world units, at least 0), `level` (0 to [`MAX_LEVEL`]), `fraction` (in [0, 1],
//!   default 1).

use std::path::Path;
use std::sync::Arc;

use serde::Deserialize;
use toml::Spanned;

use super::source::Source;
use super::strict::strict;
use crate::error::Result;
use crate::scene::displacement::{
    check_parameters, DisplacementSpec, HeightImage, HeightSource, ProceduralSpec, Wave, MAX_LEVEL,
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
    #[serde(default, deserialize_with = "strict")]
    waves: Option<Spanned<Vec<[f64; 4]>>>,
    #[serde(default, deserialize_with = "strict")]
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
    let level = *raw.level.get_ref();
    if !(0..=MAX_LEVEL as i64).contains(&level) {
        return Err(src.error(
            &raw.level.span(),
            format!("displacement level must be in 0..={MAX_LEVEL}, not {level}"),
        ));
    }
    let level = level as u32;
    // Each parameter checked alone, so that the error points at its own value.
    let checks = [
        (raw.scale.span(), check_parameters(scale, 0, 1.0)),
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use image::GrayImage;

    use crate::scene::displacement::{HeightSource, ProceduralSpec, Wave};
    use crate::scene::file::{load, parse};

    const HEAD: &str = "[image]\nwidth = 8\nheight = 8\n[projection]\ntype = \"perspective\"\n\
                        position = [0.0, 0.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\nfov = 40.0\n";

    fn object(shape: &str, displacement: &str) -> String {
        format!("{HEAD}[[object]]\nshape = \"{shape}\"\ndisplacement = {displacement}\n")
    }

    fn error(text: &str) -> String {
        parse(text, Path::new("d.toml")).unwrap_err().to_string()
    }

    #[test]
    fn procedural_displacements_are_read_with_their_defaults() {
        let text = object(
            "sphere",
            "{ procedural = \"waves\", waves = [[1.0, 3, -2, 0.5]], scale = 0.1, level = 4 }",
        );
        let scene = parse(&text, Path::new("d.toml")).unwrap();
        let spec = scene.objects[0].displacement.as_deref().unwrap();
        let wave = Wave {
            amplitude: 1.0,
            frequency: [3, -2],
            phase: 0.5,
        };
        assert_eq!(
            spec.height,
            HeightSource::Procedural(ProceduralSpec::Waves(vec![wave]))
        );
        assert_eq!((spec.scale, spec.level, spec.fraction), (0.1, 4, 1.0));
        let text = object(
            "torus",
            "{ procedural = \"bumps\", cells = [4, 2], radius = 0.5, scale = 0.0, level = 0, fraction = 0.25 }",
        );
        let scene = parse(&text, Path::new("d.toml")).unwrap();
        let spec = scene.objects[0].displacement.as_deref().unwrap();
        assert_eq!(
            spec.height,
            HeightSource::Procedural(ProceduralSpec::Bumps {
                cells: [4, 2],
                radius: 0.5
            })
        );
        assert_eq!((spec.scale, spec.level, spec.fraction), (0.0, 0, 0.25));
    }

    #[test]
    fn maps_load_relative_to_the_scene_and_are_inputs() {
        let dir = tempfile::tempdir().unwrap();
        GrayImage::from_raw(2, 1, vec![0, 51])
            .unwrap()
            .save(dir.path().join("h.png"))
            .unwrap();
        let path = dir.path().join("s.toml");
        let text = object("plane", "{ map = \"h.png\", scale = 0.5, level = 2 }");
        std::fs::write(&path, text).unwrap();
        let scene = load(&path).unwrap();
        let spec = scene.objects[0].displacement.as_deref().unwrap();
        let HeightSource::Map(image) = &spec.height else {
            panic!("{spec:?}");
        };
        assert_eq!((image.width, image.height), (2, 1));
        assert_eq!(image.values, vec![0.0, 51.0 / 255.0]);
        assert!(scene
            .inputs
            .iter()
            .any(|f| f.what == "height map" && f.path == dir.path().join("h.png")));
        let text = object("plane", "{ map = \"s.toml\", scale = 0.5, level = 2 }");
        std::fs::write(&path, text).unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!(
                "{}: a height map must be",
                dir.path().join("s.toml").display()
            )),
            "{e}"
        );
    }

    #[test]
    fn mesh_without_uvs_or_normals_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("m.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let path = dir.path().join("s.toml");
        let text = format!(
            "{HEAD}[[object]]\nname = \"tri\"\nshape = \"mesh\"\nfile = \"m.obj\"\n\
             displacement = {{ procedural = \"bumps\", cells = [1, 1], radius = 0.5, scale = 0.1, level = 1 }}\n"
        );
        std::fs::write(&path, text).unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}:13:16: `displacement` needs a mesh with texture coordinates and vertex \
                 normals; \"tri\" has no texture coordinates and vertex normals",
                path.display()
            )
        );
    }

    #[test]
    fn every_number_is_bounded_and_errors_point_at_the_value() {
        let bumps = |rest: &str| {
            error(&object(
                "sphere",
                &format!("{{ procedural = \"bumps\", cells = [2, 2], radius = 0.3, {rest} }}"),
            ))
        };
        assert_eq!(
            bumps("scale = 0.1, level = 17"),
            "d.toml:11:91: displacement level must be in 0..=16, not 17"
        );
        assert_eq!(
            bumps("scale = 0.1, level = -1"),
            "d.toml:11:91: displacement level must be in 0..=16, not -1"
        );
        assert_eq!(
            bumps("scale = -0.1, level = 1"),
            "d.toml:11:78: displacement scale must be a finite number at least 0, not -0.1"
        );
        assert_eq!(
            bumps("scale = 0.1, level = 1, fraction = 1.5"),
            "d.toml:11:105: displacement fraction must be in [0, 1], not 1.5"
        );
        assert!(bumps("scale = inf, level = 1").starts_with("d.toml:11:78: `scale` must be"));
        let e = error(&object(
            "sphere",
            "{ procedural = \"bumps\", cells = [2, 2], radius = 0.7, scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:65: bumps: radius 0.7 must be in (0, 0.5] (cell units)"
        );
        let e = error(&object(
            "sphere",
            "{ procedural = \"bumps\", cells = [0, 2], radius = 0.3, scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:48: bumps: cell counts must be in 1..=65536, not [0, 2]"
        );
        let e = error(&object(
            "sphere",
            "{ procedural = \"waves\", waves = [[1.0, 1.5, 0, 0]], scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:48: `waves`: frequencies must be integers, not 1.5 and 0"
        );
        let e = error(&object(
            "sphere",
            "{ procedural = \"waves\", waves = [[1.0, 70000, 0, 0]], scale = 0.1, level = 1 }",
        ));
        assert!(
            e.starts_with("d.toml:11:48: waves: frequencies must be integers in"),
            "{e}"
        );
        let e = error(&object(
            "sphere",
            "{ procedural = \"noise\", scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:31: unknown procedural height \"noise\"; expected one of: waves, bumps"
        );
        let e = error(&object("sphere", "{ scale = 0.1, level = 1 }"));
        assert!(
            e.starts_with("d.toml:11:16: `displacement` needs `map"),
            "{e}"
        );
        let e = error(&object(
            "sphere",
            "{ map = \"h.png\", procedural = \"waves\", scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:24: `displacement` takes either `map` or `procedural`, not both"
        );
        let e = error(&object(
            "sphere",
            "{ procedural = \"waves\", waves = [[1.0, 1, 0, 0]], cells = [1, 1], scale = 0.1, level = 1 }",
        ));
        assert_eq!(
            e,
            "d.toml:11:74: `cells` does not apply to procedural \"waves\""
        );
    }
}
