//! `[projection] type = "flexible"`: a named preset placed by a camera frame, two explicit
//! control surfaces `near` and `far`, or a list `surfaces` blended in t (`blend`, `knots`,
//! `segments`), a shape-defined panorama (`outline`/`outlines` and `profile`/`profiles`,
//! module `panorama`), with an optional re-parameterisation; or `pieces`, several such
//! projections each owning an image rectangle (module `pieces`).

use std::f64::consts::PI;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::control_surface::surface;
use super::projection_table::{camera_frame, clip, Required};
use super::raw::{RawProjection, RawSurface};
use super::source::Source;
use crate::error::Result;
use crate::projection::flexible::presets::{
    DdocMap, DeepArea, DepthStyle, Magnifier, DEPTH_STYLE_NAMES, PRESET_NAMES,
};
use crate::projection::flexible::reparam::{DEFAULT_MERCATOR_LATITUDE, REPARAM_NAMES};
use crate::projection::flexible::{
    BezierVolume, Blend, FlexibleSpec, PiecewiseVolume, Preset, PresetSpec, Reparam, Surface,
    VolumeSource,
};

/// Every key of a flexible table (besides `type`).
pub(super) const KEYS: [&str; 50] = [
    "preset",
    "position",
    "look_at",
    "up",
    "converge",
    "fov",
    "width",
    "h_fov",
    "v_fov",
    "clip",
    "shear",
    "slit_distance",
    "near",
    "far",
    "surfaces",
    "blend",
    "knots",
    "segments",
    "reparam",
    "reparam_grid",
    "interpolate",
    "max_latitude",
    "shift",
    "twist",
    "azimuth",
    "elevation",
    "generators",
    "projectors",
    "corner_radius",
    "outline",
    "outlines",
    "profile",
    "profiles",
    "perspective_rect",
    "transition",
    "transitions",
    "fovs",
    "style",
    "pole",
    "strength",
    "path",
    "directions",
    "center",
    "radius",
    "magnification",
    "deep",
    "pieces",
    "z_near",
    "z_far",
    "map",
];

/// Keys every preset accepts (but `up` for the axonometric one, which is always +y).
const PRESET_COMMON: [&str; 7] = [
    "preset",
    "position",
    "look_at",
    "up",
    "clip",
    "reparam",
    "reparam_grid",
];

/// Keys of a flexible table given by a near and a far surface.
const SURFACE_KEYS: [&str; 5] = ["near", "far", "reparam", "reparam_grid", "max_latitude"];

/// Keys of a flexible table given by a list of surfaces blended in t.
const BLEND_KEYS: [&str; 7] = [
    "surfaces",
    "blend",
    "knots",
    "segments",
    "reparam",
    "reparam_grid",
    "max_latitude",
];

/// The `blend` names of scene files.
const BLEND_NAMES: [&str; 2] = ["piecewise", "bezier"];

/// The preset's own keys, besides [`PRESET_COMMON`] (and `max_latitude` with the map
/// re-parameterisations).
fn preset_keys(name: &str) -> &'static [&'static str] {
    match name {
        "perspective" | "fisheye" => &["fov"],
        "inverse_perspective" => &["fov", "converge"],
        "orthographic" => &["width"],
        "off_axis" => &["fov", "shift"],
        "twist" => &["fov", "twist"],
        "axonometric" => &["width", "azimuth", "elevation"],
        "glc" => &["width", "generators"],
        "oblique" => &["width", "shear"],
        "pushbroom" => &["width", "v_fov"],
        "crossed_slits" => &["fov", "v_fov", "slit_distance"],
        "cubic" => &["v_fov", "perspective_rect"],
        "rounded_cubic" => &["v_fov", "corner_radius", "perspective_rect"],
        "cylindrical" | "equirectangular" => &["h_fov", "v_fov", "perspective_rect"],
        "ortho_near_persp_far" => &["fov", "transition", "style"],
        "depth_transition" => &["fovs", "transitions", "style"],
        "occlusion" => &["fov", "transition", "pole", "strength"],
        "mcop" => &["directions", "path", "v_fov"],
        "long_scene" => &["width", "v_fov", "deep"],
        "magnifier" => &["fov", "center", "radius", "magnification"],
        "ddoc" => &["fov", "z_near", "z_far", "map"],
        _ => &["h_fov", "v_fov"],
    }
}

/// Converts a flexible projection table; a grid map's file is found in `base_dir`.
pub(super) fn convert(required: &Required, base_dir: &Path) -> Result<FlexibleSpec> {
    let src = required.src;
    let raw = required.raw();
    let reparam = reparam(src, raw, base_dir)?;
    if let Some(list) = &raw.pieces {
        let present = raw.present_keys();
        reject_keys(
            src,
            &present,
            |key| key == "pieces",
            || {
                "projections made of `pieces` (they take only `pieces`; each piece has its own keys)".to_string()
            },
        )?;
        return Ok(FlexibleSpec {
            source: super::pieces::convert(src, list, |piece| convert(piece, base_dir))?,
            reparam: None,
        });
    }
    // `projectors` goes with any volume of straight projectors, `rect` is a piece's
    // rectangle (module `pieces`; refused elsewhere by the projection's key list); the
    // checks below are for the keys of the volume itself.
    let present: Vec<_> = raw
        .present_keys()
        .into_iter()
        .filter(|(key, _)| *key != "projectors" && *key != "rect")
        .collect();
    let source = match &raw.preset {
        Some(name) => {
            let own = preset_keys(name.get_ref());
            if !PRESET_NAMES.contains(&name.get_ref().as_str()) {
                return Err(src.unknown(
                    &name.span(),
                    "flexible preset",
                    name.get_ref(),
                    &PRESET_NAMES,
                ));
            }
            reparam_matches_preset(src, raw, name)?;
            // The axonometric preset's up is always +y; the magnifier's map is its lens.
            let common = |key: &str| {
                PRESET_COMMON.contains(&key)
                    && !(key == "up" && name.get_ref() == "axonometric")
                    && !(key.starts_with("reparam") && name.get_ref() == "magnifier")
            };
            let allowed = |key: &str| {
                common(key)
                    || own.contains(&key)
                    || (key == "max_latitude" && reparam.as_ref().is_some_and(has_latitude))
            };
            reject_keys(src, &present, allowed, || {
                let takes: Vec<&str> = PRESET_COMMON
                    .iter()
                    .copied()
                    .filter(|key| common(key))
                    .chain(own.iter().copied())
                    .collect();
                format!(
                    "preset \"{}\" (it takes: {})",
                    name.get_ref(),
                    takes.join(", ")
                )
            })?;
            let source = VolumeSource::Preset(preset(required, name.get_ref(), base_dir)?);
            match &raw.perspective_rect {
                None => source,
                Some(rect) => super::panorama::perspective_rect(src, &source, rect)?,
            }
        }
        None if super::panorama::is_panorama(raw) => {
            reject_keys(
                src,
                &present,
                |key| super::panorama::KEYS.contains(&key),
                || {
                    format!(
                        "panoramas given by outlines and profiles (they take: {})",
                        super::panorama::KEYS.join(", ")
                    )
                },
            )?;
            super::panorama::convert(required)?
        }
        None if raw.surfaces.is_some() || raw.blend.is_some() => {
            reject_keys(
                src,
                &present,
                |key| BLEND_KEYS.contains(&key),
                || {
                    format!(
                        "projections given by `surfaces` (they take: {})",
                        BLEND_KEYS.join(", ")
                    )
                },
            )?;
            let list = required.get(&raw.surfaces, "surfaces")?;
            let source = blended(src, raw, list)?;
            if let VolumeSource::Blended { surfaces, .. } = &source {
                reparam_needs_curved(src, raw, surfaces)?;
            }
            source
        }
        None => {
            reject_keys(
                src,
                &present,
                |key| SURFACE_KEYS.contains(&key),
                || {
                    format!(
                        "projections without a `preset` (they take: {})",
                        SURFACE_KEYS.join(", ")
                    )
                },
            )?;
            let near = required.get(&raw.near, "near (or a preset)")?;
            let far = required.get(&raw.far, "far")?;
            let (near, far) = (surface(src, near, "near")?, surface(src, far, "far")?);
            reparam_needs_curved(src, raw, &[near.clone(), far.clone()])?;
            VolumeSource::Surfaces { near, far }
        }
    };
    if let (Some(at), Some(r)) = (&raw.max_latitude, &reparam) {
        if !has_latitude(r) {
            return Err(src.error(
                &at.span(),
                "`max_latitude` belongs to reparam = \"mercator\" or \"equal_area\"",
            ));
        }
    }
    let source = match &raw.projectors {
        None => source,
        Some(table) => {
            if matches!(source, VolumeSource::Blended { .. }) {
                return Err(src.error(
                    &table.span(),
                    "a projector grid starts from a volume with straight projectors (a preset \
                     or near and far surfaces), not from blended `surfaces`",
                ));
            }
            // The map the built projection takes (`build_volume`): the given one, else the
            // preset's own, else linear.
            let uv_map = reparam.clone().unwrap_or_else(|| match &source {
                VolumeSource::Preset(p) => p.preset.default_reparam(),
                _ => Reparam::Linear,
            });
            VolumeSource::ProjectorGrid {
                grid: super::projector_grid::convert(src, table, &uv_map)?,
                base: Box::new(FlexibleSpec {
                    source,
                    reparam: None,
                }),
            }
        }
    };
    Ok(FlexibleSpec { source, reparam })
}

/// The largest `segments` of a bezier blend: each projector is a polyline of that many
/// steps, evaluated per ray; far more steps than pixels along a projector change nothing
/// but the time and memory taken.
pub(super) const MAX_SEGMENTS: u32 = 4096;

/// `surfaces = [...]` with `blend` (default piecewise), `knots` (piecewise only) and
/// `segments` (bezier only). Counts and knot values are checked when the volume is built;
/// the errors point at the key they concern.
fn blended(
    src: &Source,
    raw: &RawProjection,
    list: &Spanned<Vec<Spanned<RawSurface>>>,
) -> Result<VolumeSource> {
    let surfaces = list
        .get_ref()
        .iter()
        .enumerate()
        .map(|(i, table)| surface(src, table, &format!("surface {}", i + 1)))
        .collect::<Result<Vec<_>>>()?;
    let name = raw
        .blend
        .as_ref()
        .map_or("piecewise", |b| b.get_ref().as_str());
    let at_blend = raw.blend.as_ref().map_or(list.span(), Spanned::span);
    let blend = match name {
        "piecewise" => {
            if let Some(s) = &raw.segments {
                return Err(src.error(&s.span(), "`segments` belongs to blend = \"bezier\""));
            }
            let knots = match &raw.knots {
                Some(k) => {
                    src.all_finite(k.get_ref(), k, "knots")?;
                    Some(k.get_ref().clone())
                }
                None => None,
            };
            Blend::Piecewise { knots }
        }
        "bezier" => {
            if let Some(k) = &raw.knots {
                return Err(src.error(&k.span(), "`knots` belongs to blend = \"piecewise\""));
            }
            if let Some(s) = raw
                .segments
                .as_ref()
                .filter(|s| *s.get_ref() > MAX_SEGMENTS)
            {
                return Err(src.error(
                    &s.span(),
                    format!(
                        "`segments` must be at most {MAX_SEGMENTS}, not {}",
                        s.get_ref()
                    ),
                ));
            }
            Blend::Bezier {
                segments: raw.segments.as_ref().map(|s| *s.get_ref()),
            }
        }
        other => return Err(src.unknown(&at_blend, "blend", other, &BLEND_NAMES)),
    };
    // Build the volume once here so that a bad count, knot list or segment count is
    // reported at its key, not later without a position.
    let check = match &blend {
        Blend::Piecewise { knots } => {
            PiecewiseVolume::new(surfaces.clone(), knots.clone()).map(|_| ())
        }
        Blend::Bezier { segments } => BezierVolume::new(surfaces.clone(), *segments).map(|_| ()),
    };
    check.map_err(|e| {
        let at = if e.message.contains("knots") {
            raw.knots.as_ref().map(Spanned::span)
        } else if e.message.contains("segments") {
            raw.segments.as_ref().map(Spanned::span)
        } else {
            None
        };
        src.error(&at.unwrap_or(list.span()), e.message)
    })?;
    Ok(VolumeSource::Blended { surfaces, blend })
}

/// Whether the re-parameterisation is a map projection with a `max_latitude`.
fn has_latitude(reparam: &Reparam) -> bool {
    matches!(
        reparam,
        Reparam::Mercator { .. } | Reparam::EqualArea { .. }
    )
}

/// Fails at the first present key that `allowed` refuses.
fn reject_keys(
    src: &Source,
    present: &[(&'static str, Range<usize>)],
    allowed: impl Fn(&str) -> bool,
    what: impl Fn() -> String,
) -> Result<()> {
    match present.iter().find(|(key, _)| !allowed(key)) {
        Some((key, span)) => Err(src.error(
            span,
            format!("`{key}` is not a parameter of flexible {}", what()),
        )),
        None => Ok(()),
    }
}

/// An error at the `reparam` key where its map assumes a (u, v) that preset `preset` does
/// not have: the polar maps (`polar`, `lens`) read v as the angle off a fisheye's axis and u
/// as its azimuth; the latitude maps (`mercator`, `equal_area`) read v as a latitude linear
/// over the image's height. With another preset either gives an image of no projection. The
/// angle maps (`equisolid`, `equiangular`) name their preset themselves
/// (`preset_angle_map`); `linear` and the `magnifier` preset's own refusal stand apart.
fn reparam_matches_preset(
    src: &Source,
    raw: &RawProjection,
    preset: &Spanned<String>,
) -> Result<()> {
    let Some(map) = &raw.reparam else {
        return Ok(());
    };
    let (owner, why) = match map.get_ref().as_str() {
        "polar" | "lens" => (
            "fisheye",
            "it reads v as the angle off a fisheye's axis and u as the azimuth",
        ),
        "mercator" | "equal_area" => (
            "equirectangular",
            "it reads v as a latitude spread evenly over the image's height",
        ),
        _ => return Ok(()),
    };
    let preset = preset.get_ref();
    if preset == owner || preset == "magnifier" {
        return Ok(());
    }
    Err(src.error(
        &map.span(),
        format!(
            "reparam \"{}\" does not go with preset \"{preset}\": {why}, which only the \
             \"{owner}\" preset's volume has",
            map.get_ref()
        ),
    ))
}

/// An error at the `reparam` key where its map reads (u, v) as angles on a sphere (the polar
/// maps: the angle off the axis and the azimuth; the latitude maps: latitude and longitude)
/// but every one of the explicit control surfaces `surfaces` is flat (a rectangle, bilinear
/// patch, point or line), so the image would be of no projection.
fn reparam_needs_curved(src: &Source, raw: &RawProjection, surfaces: &[Surface]) -> Result<()> {
    let Some(map) = &raw.reparam else {
        return Ok(());
    };
    let reads = match map.get_ref().as_str() {
        "polar" | "lens" => "v as the angle off a fisheye's axis and u as the azimuth",
        "mercator" | "equal_area" => "v as a latitude and u as a longitude",
        _ => return Ok(()),
    };
    let flat = |s: &Surface| {
        matches!(
            s,
            Surface::Rectangle { .. }
                | Surface::Bilinear { .. }
                | Surface::Point(_)
                | Surface::Line { .. }
        )
    };
    if !surfaces.iter().all(flat) {
        return Ok(());
    }
    let kinds: Vec<&str> = surfaces.iter().map(Surface::kind).collect();
    Err(src.error(
        &map.span(),
        format!(
            "reparam \"{}\" does not go with flat control surfaces ({}): it reads {reads}, \
             which needs a sphere or hemisphere among them (use reparam = \"linear\" or \
             \"grid\")",
            map.get_ref(),
            kinds.join(", ")
        ),
    ))
}

/// `reparam` (with `max_latitude` or `reparam_grid`); `None` when absent. A grid map's file
/// is found in `base_dir`.
fn reparam(src: &Source, raw: &RawProjection, base_dir: &Path) -> Result<Option<Reparam>> {
    let is_grid = raw.reparam.as_ref().is_some_and(|r| r.get_ref() == "grid");
    if let (Some(table), false) = (&raw.reparam_grid, is_grid) {
        return Err(src.error(
            &table.span(),
            "`reparam_grid` belongs to reparam = \"grid\"",
        ));
    }
    let Some(name) = &raw.reparam else {
        return Ok(None);
    };
    Ok(Some(match name.get_ref().as_str() {
        "linear" => Reparam::Linear,
        "polar" => Reparam::Polar,
        "lens" => Reparam::Lens,
        "grid" => {
            let table = raw.reparam_grid.as_ref().ok_or_else(|| {
                src.error(
                    &name.span(),
                    "reparam = \"grid\" needs `reparam_grid = { size = [columns, rows], uv = \
                     [[u, v], ...] }` (or `file = \"...\"` instead of `uv`)",
                )
            })?;
            super::reparam_grid::convert(src, table, base_dir)?
        }
        "equisolid" | "equiangular" => preset_angle_map(src, raw, name)?,
        map @ ("mercator" | "equal_area") => {
            let (default, make): (f64, fn(f64) -> Reparam) = if map == "mercator" {
                (DEFAULT_MERCATOR_LATITUDE, |max_latitude| {
                    Reparam::Mercator { max_latitude }
                })
            } else {
                (90.0, |max_latitude| Reparam::EqualArea { max_latitude })
            };
            let degrees = raw
                .max_latitude
                .as_ref()
                .map_or(Ok(default), |v| src.number(v, "max_latitude"))?;
            let reparam = make(degrees.to_radians());
            reparam.validate().map_err(|e| {
                let at = raw.max_latitude.as_ref().map_or(name.span(), Spanned::span);
                src.error(&at, e.message)
            })?;
            reparam
        }
        other => return Err(src.unknown(&name.span(), "reparam", other, &REPARAM_NAMES)),
    }))
}

/// A re-parameterisation that takes its angle from its preset's `fov` (radians of half of
/// it): `reparam = "equisolid"` belongs to the fisheye preset (fov / 2 is the angle at the
/// rim of the image circle), `reparam = "equiangular"` to the perspective preset (fov / 2
/// is the horizontal half angle, spread evenly across the image). Another preset is an
/// error at the reparam's name, a bad angle at `fov`. A missing `fov` is left to the
/// preset's own error (the map then gets a placeholder, 180 degrees, that is never used).
fn preset_angle_map(src: &Source, raw: &RawProjection, name: &Spanned<String>) -> Result<Reparam> {
    let (preset, why, make): (&str, &str, fn(f64) -> Reparam) = match name.get_ref().as_str() {
        "equisolid" => (
            "fisheye",
            "its fov / 2 is the angle at the rim of the image circle",
            |a| Reparam::Equisolid { max_angle: a },
        ),
        _ => (
            "perspective",
            "its fov is the horizontal angle spread evenly across the image",
            |a| Reparam::Equiangular { half_fov: a },
        ),
    };
    if raw.preset.as_ref().is_none_or(|p| p.get_ref() != preset) {
        return Err(src.error(
            &name.span(),
            format!(
                "reparam \"{}\" belongs to the {preset} preset ({why})",
                name.get_ref()
            ),
        ));
    }
    let Some(fov) = &raw.fov else {
        return Ok(make(0.5 * PI));
    };
    let reparam = make(0.5 * src.number(fov, "fov")?.to_radians());
    reparam
        .validate()
        .map_err(|e| src.error(&fov.span(), e.message))?;
    Ok(reparam)
}

/// `converge` of the inverse perspective: the point its projectors meet. Required, with a
/// message that says what to write: before it existed the projectors met at `look_at`, so a
/// scene written then gets that point spelled out (`look_at` now only aims the camera).
fn converge(required: &Required) -> Result<DVec3> {
    let (src, raw) = (required.src, required.raw());
    match &raw.converge {
        Some(point) => src.dvec3(point, "converge"),
        None => {
            let old = raw.look_at.as_ref().map_or_else(
                || "the point they should meet".to_string(),
                |l| {
                    let [x, y, z] = *l.get_ref();
                    format!("[{x:?}, {y:?}, {z:?}] (this table's look_at, where they met before)")
                },
            );
            Err(src.error(
                &required.table.span(),
                format!(
                    "flexible inverse_perspective needs `converge = [x, y, z]`, the point its \
                     projectors meet (look_at only aims the camera): add converge = {old}"
                ),
            ))
        }
    }
}

/// A preset with its camera frame and parameters (already checked to belong to it); a
/// `ddoc` map file is found in `base_dir`.
fn preset(required: &Required, name: &str, base_dir: &Path) -> Result<PresetSpec> {
    let src = required.src;
    let raw = required.raw();
    let number = |v: &Option<Spanned<f64>>, key: &str| -> Result<f64> {
        src.number(required.get(v, key)?, key)
    };
    let optional = |v: &Option<Spanned<f64>>, key: &str, default: f64| -> Result<f64> {
        v.as_ref().map_or(Ok(default), |v| src.number(v, key))
    };
    let preset = match name {
        "perspective" => Preset::Perspective {
            fov: number(&raw.fov, "fov")?,
        },
        "inverse_perspective" => Preset::InversePerspective {
            fov: number(&raw.fov, "fov")?,
            converge: converge(required)?,
        },
        "orthographic" => Preset::Orthographic {
            width: number(&raw.width, "width")?,
        },
        "oblique" => Preset::Oblique {
            width: number(&raw.width, "width")?,
            shear: DVec2::from_array(src.vector(required.get(&raw.shear, "shear")?, "shear")?),
        },
        "pushbroom" => Preset::Pushbroom {
            width: number(&raw.width, "width")?,
            v_fov: number(&raw.v_fov, "v_fov")?,
        },
        "crossed_slits" => Preset::CrossedSlits {
            fov: number(&raw.fov, "fov")?,
            v_fov: raw
                .v_fov
                .as_ref()
                .map(|v| src.number(v, "v_fov"))
                .transpose()?,
            slit_distance: number(&raw.slit_distance, "slit_distance")?,
        },
        "cylindrical" => Preset::Cylindrical {
            h_fov: optional(&raw.h_fov, "h_fov", 360.0)?,
            v_fov: optional(&raw.v_fov, "v_fov", 90.0)?,
        },
        "equirectangular" => Preset::Equirectangular {
            h_fov: optional(&raw.h_fov, "h_fov", 360.0)?,
            v_fov: optional(&raw.v_fov, "v_fov", 180.0)?,
        },
        "fisheye" => Preset::Fisheye {
            fov: number(&raw.fov, "fov")?,
        },
        "cubic" => Preset::Cubic {
            v_fov: optional(&raw.v_fov, "v_fov", 90.0)?,
        },
        "rounded_cubic" => Preset::RoundedCubic {
            v_fov: optional(&raw.v_fov, "v_fov", 90.0)?,
            corner_radius: {
                let r = required.get(&raw.corner_radius, "corner_radius")?;
                let x = src.number(r, "corner_radius")?;
                if !(0.0..=1.0).contains(&x) {
                    return Err(src.error(
                        &r.span(),
                        format!("`corner_radius` must lie in [0, 1], got {x}"),
                    ));
                }
                x
            },
        },
        "off_axis" => Preset::OffAxis {
            fov: number(&raw.fov, "fov")?,
            shift: DVec2::from_array(src.vector(required.get(&raw.shift, "shift")?, "shift")?),
        },
        "twist" => Preset::Twist {
            fov: number(&raw.fov, "fov")?,
            twist: number(&raw.twist, "twist")?,
        },
        "axonometric" => Preset::Axonometric {
            width: number(&raw.width, "width")?,
            azimuth: number(&raw.azimuth, "azimuth")?,
            elevation: number(&raw.elevation, "elevation")?,
        },
        "glc" => Preset::Glc {
            width: number(&raw.width, "width")?,
            generators: generators(src, required.get(&raw.generators, "generators")?)?,
        },
        "ortho_near_persp_far" => Preset::OrthoNearPerspFar {
            fov: number(&raw.fov, "fov")?,
            transition: number(&raw.transition, "transition")?,
            style: style(src, raw)?,
        },
        "depth_transition" => {
            let list = |v: &Option<Spanned<Vec<f64>>>, key: &str| -> Result<Vec<f64>> {
                let v = required.get(v, key)?;
                src.all_finite(v.get_ref(), v, key)?;
                Ok(v.get_ref().clone())
            };
            Preset::DepthTransition {
                fovs: list(&raw.fovs, "fovs")?,
                transitions: list(&raw.transitions, "transitions")?,
                style: style(src, raw)?,
            }
        }
        "occlusion" => Preset::Occlusion {
            fov: number(&raw.fov, "fov")?,
            transition: number(&raw.transition, "transition")?,
            pole: DVec2::from_array(src.vector(required.get(&raw.pole, "pole")?, "pole")?),
            strength: number(&raw.strength, "strength")?,
        },
        "mcop" => {
            let points = |v: &Spanned<Vec<[f64; 3]>>, key: &str| -> Result<Vec<DVec3>> {
                src.all_finite(v.get_ref().as_flattened(), v, key)?;
                Ok(v.get_ref().iter().map(|p| DVec3::from_array(*p)).collect())
            };
            Preset::Mcop {
                path: points(required.get(&raw.path, "path")?, "path")?,
                directions: raw
                    .directions
                    .as_ref()
                    .map(|d| points(d, "directions"))
                    .transpose()?,
                v_fov: optional(&raw.v_fov, "v_fov", 60.0)?,
            }
        }
        "long_scene" => Preset::LongScene {
            width: number(&raw.width, "width")?,
            v_fov: number(&raw.v_fov, "v_fov")?,
            deep: match &raw.deep {
                None => Vec::new(),
                Some(d) => {
                    src.all_finite(d.get_ref().as_flattened(), d, "deep")?;
                    d.get_ref()
                        .iter()
                        .map(|&[center, width, fov]| DeepArea { center, width, fov })
                        .collect()
                }
            },
        },
        "ddoc" => Preset::Ddoc {
            fov: number(&raw.fov, "fov")?,
            z_near: number(&raw.z_near, "z_near")?,
            z_far: number(&raw.z_far, "z_far")?,
            map: match &raw.map {
                None => None,
                Some(name) => {
                    let path = src.existing_file(name, base_dir, "ddoc map")?;
                    Some(Arc::new(DdocMap::read(&path)?))
                }
            },
        },
        _ => Preset::Magnifier {
            fov: number(&raw.fov, "fov")?,
            lens: Magnifier {
                center: DVec2::from_array(
                    src.vector(required.get(&raw.center, "center")?, "center")?,
                ),
                radius: number(&raw.radius, "radius")?,
                magnification: number(&raw.magnification, "magnification")?,
            },
        },
    };
    let spec = PresetSpec {
        preset,
        frame: camera_frame(src, required)?,
        clip: clip(src, raw)?,
    };
    check_preset(src, raw, &spec)?;
    Ok(spec)
}

/// `style`: "piecewise" (the default) or "quadratic".
fn style(src: &Source, raw: &RawProjection) -> Result<DepthStyle> {
    let Some(name) = &raw.style else {
        return Ok(DepthStyle::Piecewise);
    };
    match name.get_ref().as_str() {
        "piecewise" => Ok(DepthStyle::Piecewise),
        "quadratic" => Ok(DepthStyle::Quadratic),
        other => Err(src.unknown(&name.span(), "style", other, &DEPTH_STYLE_NAMES)),
    }
}

/// Builds the volume and map of the presets whose parameters are only checked then (the
/// depth transitions, occlusion, mcop, long scene, magnifier, ddoc) at a nominal aspect ratio, so that a bad value is
/// reported at its key: the first present key (the preset's own, then `up`, `clip`,
/// `position`, `look_at`) named in the message, else the preset name.
fn check_preset(src: &Source, raw: &RawProjection, spec: &PresetSpec) -> Result<()> {
    let checked_late = matches!(
        spec.preset,
        Preset::OrthoNearPerspFar { .. }
            | Preset::DepthTransition { .. }
            | Preset::Occlusion { .. }
            | Preset::Mcop { .. }
            | Preset::LongScene { .. }
            | Preset::Magnifier { .. }
            | Preset::Ddoc { .. }
    );
    if !checked_late {
        return Ok(());
    }
    let built = spec
        .volume(0.75)
        .and_then(|_| spec.preset.default_reparam().validate());
    let Err(e) = built else {
        return Ok(());
    };
    let name = spec.preset.name();
    let present = raw.present_keys();
    let at = preset_keys(name)
        .iter()
        .chain(&["up", "clip", "position", "look_at"])
        .filter(|key| e.message.contains(*key))
        .find_map(|key| present.iter().find(|(k, _)| k == key))
        .map(|(_, span)| span.clone());
    let fallback = raw.preset.as_ref().map_or(0..0, Spanned::span);
    Err(src.error(&at.unwrap_or(fallback), e.message))
}

/// `generators`: exactly three finite rays [x0, y0, x1, y1].
fn generators(src: &Source, value: &Spanned<Vec<[f64; 4]>>) -> Result<[[f64; 4]; 3]> {
    let rays: [[f64; 4]; 3] = value.get_ref().as_slice().try_into().map_err(|_| {
        src.error(
            &value.span(),
            format!(
                "`generators` must hold exactly three rays [x0, y0, x1, y1], got {}",
                value.get_ref().len()
            ),
        )
    })?;
    src.all_finite(rays.as_flattened(), value, "generators")?;
    Ok(rays)
}
