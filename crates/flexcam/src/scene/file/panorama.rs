//! A flexible projection given by outlines and profiles (a shape-defined panorama, module
//! `projection::flexible::panorama`):
//!
//! ```toml
//! [projection]
//! type = "flexible"
//! position = [0, 1, 0]
//! look_at = [0, 1, -1]
//! outline = { shape = "rounded_square", radius = 0.3 }     # or `outlines = [{ at = v, ... }]`
//! profiles = [{ at = 0.5, shape = "segment", elevation = [-40, 40] },
//!             { at = 0.0, shape = "arc" }]                  # or `profile = { ... }`
//! blend = "smooth"                                          # or "linear" (the default)
//! perspective_rect = [0.4, 0.3, 0.6, 0.7]     # optional: [u0, v0, u1, v1] made perspective
//! ```
//!
//! Outline shapes: `circle`, `square`, `rounded_square` (`radius`), or `points = [[x, y],
//! ...]` in the (right, forward) plane. Profile shapes: `segment` (`elevation`, default
//! [-45, 45] degrees), `arc` (`elevation`, default [-90, 90]), or `points = [[r, h], ...]`
//! (distance from the up axis, height), bottom to top.

use std::sync::Arc;

use glam::DVec2;
use toml::Spanned;

use super::projection_table::{camera_frame, clip, Required};
use super::raw::{RawCurve, RawProjection};
use super::source::Source;
use crate::error::Result;
use crate::projection::flexible::panorama::{
    edit_source, ArcCurve, Attached, CurveBlend, OutlineShape, PanoramaShape, PanoramaSpec,
    ProfileShape,
};
use crate::projection::flexible::VolumeSource;

/// The keys of a panorama table (besides `type` and `projectors`).
pub(super) const KEYS: [&str; 13] = [
    "position",
    "look_at",
    "up",
    "clip",
    "reparam",
    "reparam_grid",
    "max_latitude",
    "outline",
    "outlines",
    "profile",
    "profiles",
    "blend",
    "perspective_rect",
];

const OUTLINE_NAMES: [&str; 3] = ["circle", "square", "rounded_square"];
const PROFILE_NAMES: [&str; 2] = ["segment", "arc"];
const BLEND_NAMES: [&str; 2] = ["linear", "smooth"];

/// Whether the table describes a panorama by outlines and profiles.
pub(super) fn is_panorama(raw: &RawProjection) -> bool {
    raw.outline.is_some()
        || raw.outlines.is_some()
        || raw.profile.is_some()
        || raw.profiles.is_some()
}

/// Which curve family a table belongs to.
#[derive(Clone, Copy, PartialEq)]
enum Family {
    Outline,
    Profile,
}

impl Family {
    fn name(self) -> &'static str {
        match self {
            Family::Outline => "outline",
            Family::Profile => "profile",
        }
    }
}

/// Converts a panorama table (its keys already checked) to a panorama source.
pub(super) fn convert(required: &Required) -> Result<VolumeSource> {
    let src = required.src;
    let raw = required.raw();
    let outlines = family(required, Family::Outline, &raw.outline, &raw.outlines)?;
    let profiles = family(required, Family::Profile, &raw.profile, &raw.profiles)?;
    let blend = match &raw.blend {
        None => CurveBlend::Linear,
        Some(b) => match b.get_ref().as_str() {
            "linear" => CurveBlend::Linear,
            "smooth" => CurveBlend::Smooth,
            other => return Err(src.unknown(&b.span(), "panorama blend", other, &BLEND_NAMES)),
        },
    };
    let at = raw
        .outlines
        .as_ref()
        .map(Spanned::span)
        .or(raw.profiles.as_ref().map(Spanned::span))
        .unwrap_or(required.table.span());
    let shape = PanoramaShape::new(outlines, profiles, blend).map_err(|e| {
        let at = match (e.message.starts_with("profile"), &raw.profiles) {
            (true, Some(p)) => p.span(),
            _ => at,
        };
        src.error(&at, e.message)
    })?;
    let panorama = VolumeSource::Panorama(PanoramaSpec {
        shape: Arc::new(shape),
        frame: camera_frame(src, required)?,
        clip: clip(src, raw)?,
    });
    match &raw.perspective_rect {
        None => Ok(panorama),
        Some(rect) => perspective_rect(src, &panorama, rect),
    }
}

/// `source` with the local perspective edit over `perspective_rect` (a panorama, or the
/// `cubic`, `rounded_cubic` and full `cylindrical` and `equirectangular` presets); errors
/// point at the rectangle.
pub(super) fn perspective_rect(
    src: &Source,
    source: &VolumeSource,
    rect: &Spanned<[f64; 4]>,
) -> Result<VolumeSource> {
    src.all_finite(rect.get_ref(), rect, "perspective_rect")?;
    edit_source(source, *rect.get_ref()).map_err(|e| src.error(&rect.span(), e.message))
}

/// The curves of one family from its single key (`outline`) or its list (`outlines`).
fn family(
    required: &Required,
    which: Family,
    one: &Option<Spanned<RawCurve>>,
    list: &Option<Spanned<Vec<Spanned<RawCurve>>>>,
) -> Result<Vec<Attached>> {
    let src = required.src;
    let name = which.name();
    match (one, list) {
        (Some(_), Some(l)) => Err(src.error(
            &l.span(),
            format!("give either `{name}` or `{name}s`, not both"),
        )),
        (None, None) => Err(src.error(
            &required.table.span(),
            format!("a panorama needs `{name}` (or `{name}s`)"),
        )),
        (Some(table), None) => {
            if let Some(at) = &table.get_ref().at {
                return Err(src.error(
                    &at.span(),
                    format!("`at` belongs to the entries of `{name}s`"),
                ));
            }
            Ok(vec![Attached {
                at: 0.0,
                curve: curve(src, table, which)?,
            }])
        }
        (None, Some(l)) => {
            if l.get_ref().is_empty() {
                return Err(src.error(&l.span(), format!("`{name}s` must not be empty")));
            }
            l.get_ref()
                .iter()
                .map(|table| {
                    let at = table.get_ref().at.as_ref().ok_or_else(|| {
                        src.error(&table.span(), format!("each entry of `{name}s` needs `at`"))
                    })?;
                    let x = src.number(at, "at")?;
                    if !(0.0..=1.0).contains(&x) {
                        return Err(
                            src.error(&at.span(), format!("`at` must lie in [0, 1], got {x}"))
                        );
                    }
                    Ok(Attached {
                        at: x,
                        curve: curve(src, table, which)?,
                    })
                })
                .collect()
        }
    }
}

/// One curve table: a named shape with its parameter, or `points`. Errors point at the key
/// concerned (the shape's parameter, `points`) or at the table.
fn curve(src: &Source, table: &Spanned<RawCurve>, which: Family) -> Result<ArcCurve> {
    let raw = table.get_ref();
    let family = which.name();
    if let Some(points) = &raw.points {
        src.reject_foreign_key(
            raw.present_keys(),
            &["points"],
            &format!("{family}s by points"),
        )?;
        src.all_finite(points.get_ref().as_flattened(), points, "points")?;
        let list: Vec<DVec2> = points
            .get_ref()
            .iter()
            .map(|&p| DVec2::from_array(p))
            .collect();
        let built = match which {
            Family::Outline => OutlineShape::Points(list).curve(),
            Family::Profile => ProfileShape::Points(list).curve(),
        };
        return built.map_err(|e| src.error(&points.span(), e.message));
    }
    let names: &[&str] = match which {
        Family::Outline => &OUTLINE_NAMES,
        Family::Profile => &PROFILE_NAMES,
    };
    let name = raw.shape.as_ref().ok_or_else(|| {
        src.error(
            &table.span(),
            format!(
                "a {family} needs `shape` ({}) or `points`",
                names.join(", ")
            ),
        )
    })?;
    let shape = name.get_ref().as_str();
    if !names.contains(&shape) {
        return Err(src.unknown(&name.span(), &format!("{family} shape"), shape, names));
    }
    let parameter = match shape {
        "rounded_square" => Some("radius"),
        "segment" | "arc" => Some("elevation"),
        _ => None,
    };
    let allowed: Vec<&str> = std::iter::once("shape").chain(parameter).collect();
    src.reject_foreign_key(raw.present_keys(), &allowed, &format!("{shape} {family}s"))?;
    let elevation = |default: [f64; 2]| -> Result<[f64; 2]> {
        let degrees = match &raw.elevation {
            Some(e) => src.vector(e, "elevation")?,
            None => default,
        };
        Ok(degrees.map(f64::to_radians))
    };
    let built = match shape {
        "circle" => OutlineShape::Circle.curve(),
        "square" => OutlineShape::Square.curve(),
        "rounded_square" => {
            let r = raw.radius.as_ref().ok_or_else(|| {
                src.error(&table.span(), "a rounded_square outline needs `radius`")
            })?;
            OutlineShape::RoundedSquare {
                radius: src.number(r, "radius")?,
            }
            .curve()
        }
        "segment" => ProfileShape::Segment {
            elevation: elevation([-45.0, 45.0])?,
        }
        .curve(),
        _ => ProfileShape::Arc {
            elevation: elevation([-90.0, 90.0])?,
        }
        .curve(),
    };
    built.map_err(|e| {
        let at = match parameter {
            Some("radius") => raw.radius.as_ref().map(Spanned::span),
            Some(_) => raw.elevation.as_ref().map(Spanned::span),
            None => None,
        };
        src.error(&at.unwrap_or(table.span()), e.message)
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::projection::flexible::panorama::make_perspective;
    use crate::projection::flexible::{Preset, VolumeSource};
    use crate::projection::ProjectionSpec;
    use crate::scene::file::parse;

    const HEAD: &str =
        "[projection]\ntype = \"flexible\"\nposition = [0, 1, 0]\nlook_at = [0, 1, -1]\n";

    fn source(text: &str) -> VolumeSource {
        let scene = parse(text, Path::new("p.toml")).unwrap_or_else(|e| panic!("{e}"));
        match scene.projection {
            ProjectionSpec::Flexible(spec) => spec.source,
            other => panic!("not flexible: {}", other.kind()),
        }
    }

    /// Asserts the one-line error `p.toml:LINE:COLUMN: ...needle...`.
    fn error_at(text: &str, line: usize, column: usize, needle: &str) {
        let e = parse(text, Path::new("p.toml")).err().unwrap().to_string();
        assert!(
            e.starts_with(&format!("p.toml:{line}:{column}: ")) && e.contains(needle),
            "{e}"
        );
        assert!(!e.contains('\n'));
    }

    #[test]
    fn cubic_presets_parse() {
        let cubic = source("[projection]\ntype = \"flexible\"\npreset = \"cubic\"\nposition = [0, 1, 0]\nlook_at = [0, 1, -1]\n");
        let VolumeSource::Preset(p) = cubic else {
            panic!("not a preset")
        };
        assert_eq!(p.preset, Preset::Cubic { v_fov: 90.0 });
        let rounded = source(
            "[projection]\ntype = \"flexible\"\npreset = \"rounded_cubic\"\nposition = [0, 1, 0]\n\
             look_at = [0, 1, -1]\nv_fov = 70\ncorner_radius = 0.25\n",
        );
        let VolumeSource::Preset(p) = rounded else {
            panic!("not a preset")
        };
        assert_eq!(
            p.preset,
            Preset::RoundedCubic {
                v_fov: 70.0,
                corner_radius: 0.25
            }
        );
    }

    #[test]
    fn outlines_and_profiles_parse() {
        let text = format!(
            "{HEAD}outlines = [{{ at = 0.2, shape = \"square\" }}, {{ at = 0.8, points = [[1, -1], [1, 1], [-1, 1], [-1, -1]] }}]\n\
             profiles = [{{ at = 0.0, shape = \"arc\" }}, {{ at = 0.5, shape = \"segment\", elevation = [-30, 40] }}]\n\
             blend = \"smooth\"\nclip = [0.5, 9]\n"
        );
        let VolumeSource::Panorama(p) = source(&text) else {
            panic!("not a panorama")
        };
        assert_eq!(p.shape.outlines().len(), 2);
        assert_eq!(p.shape.profiles()[1].at, 0.5);
        assert_eq!(p.shape.blend(), super::CurveBlend::Smooth);
        assert_eq!(p.clip, Some([0.5, 9.0]));
        // The segment between -30 and 40 degrees at distance 1.
        let top = p.shape.profiles()[1].curve.at(1.0);
        assert!((top.y - 40f64.to_radians().tan()).abs() < 1e-12);
        let one = format!(
            "{HEAD}outline = {{ shape = \"rounded_square\", radius = 0.5 }}\nprofile = {{ points = [[1, -1], [1, 1]] }}\n"
        );
        assert!(matches!(source(&one), VolumeSource::Panorama(_)));
    }

    #[test]
    fn perspective_rect_flattens_the_shape() {
        let curves = "outline = { shape = \"circle\" }\nprofile = { shape = \"arc\" }\n";
        let VolumeSource::Panorama(plain) = source(&format!("{HEAD}{curves}")) else {
            panic!("not a panorama")
        };
        let text = format!("{HEAD}{curves}perspective_rect = [0.4, 0.3, 0.6, 0.7]\n");
        let VolumeSource::Panorama(p) = source(&text) else {
            panic!("not a panorama")
        };
        let edited = make_perspective(&plain.shape, [0.4, 0.3, 0.6, 0.7]).unwrap();
        assert_eq!(*p.shape, edited);
        assert_ne!(p.shape, plain.shape);
        error_at(
            &format!("{HEAD}{curves}perspective_rect = [0.4, 0.7, 0.6, 0.3]\n"),
            7,
            20,
            "perspective rectangle [u0, v0, u1, v1] needs u0, u1, v0, v1 in [0, 1]",
        );
        error_at(
            &format!("{HEAD}{curves}perspective_rect = [0.6, 0.3, 0.4, 0.7]\n"),
            7,
            20,
            "turns 288.0 degrees around the eye",
        );
        error_at(
            &format!("{HEAD}{curves}perspective_rect = [0.2, 0.3, 0.8, 0.7]\n"),
            7,
            20,
            "turns 216.0 degrees around the eye",
        );
        error_at(
            &format!("{HEAD}{curves}perspective_rect = [0.4, 0.0, 0.6, 0.7]\n"),
            7,
            20,
            "lies on or behind the up axis",
        );
    }

    #[test]
    fn cubic_presets_take_perspective_rect() {
        let preset = |name: &str, rest: &str| {
            format!(
                "[projection]\ntype = \"flexible\"\npreset = \"{name}\"\nposition = [0, 1, 0]\n\
                 look_at = [0, 1, -1]\n{rest}"
            )
        };
        let rect = "perspective_rect = [0.9, 0.3, 0.1, 0.7]\n";
        let VolumeSource::Panorama(p) = source(&preset("cubic", rect)) else {
            panic!("not a panorama")
        };
        let VolumeSource::Preset(plain) = source(&preset("cubic", "")) else {
            panic!("not a preset")
        };
        let shape = plain.panorama().unwrap().unwrap().shape;
        assert_eq!(
            *p.shape,
            make_perspective(&shape, [0.9, 0.3, 0.1, 0.7]).unwrap()
        );
        let rounded = preset("rounded_cubic", &format!("corner_radius = 0.5\n{rect}"));
        assert!(matches!(source(&rounded), VolumeSource::Panorama(_)));
        error_at(
            &preset(
                "rounded_cubic",
                "corner_radius = 0.5\nperspective_rect = [0.1, 0.3, 0.9, 0.7]\n",
            ),
            7,
            20,
            "turns 286.9 degrees around the eye",
        );
        // The full cylindrical and equirectangular presets as their panoramas; with less
        // than 360 degrees as windowed panoramas, which refuse a rectangle across the seam
        // at the rectangle and take one inside the image.
        for name in ["cylindrical", "equirectangular"] {
            let text = preset(name, &format!("v_fov = 100\n{rect}"));
            let VolumeSource::Panorama(p) = source(&text) else {
                panic!("{name}: not a panorama")
            };
            let VolumeSource::Preset(plain) = source(&preset(name, "v_fov = 100\n")) else {
                panic!("{name}: not a preset")
            };
            let shape = plain.panorama().unwrap().unwrap().shape;
            let edited = make_perspective(&shape, [0.9, 0.3, 0.1, 0.7]).unwrap();
            assert_eq!(*p.shape, edited, "{name}");
            error_at(
                &preset(name, &format!("h_fov = 180\n{rect}")),
                7,
                20,
                "a perspective rectangle across the seam (u0 > u1",
            );
            let inside = "perspective_rect = [0.2, 0.3, 0.8, 0.7]\n";
            let VolumeSource::Panorama(p) =
                source(&preset(name, &format!("h_fov = 180\n{inside}")))
            else {
                panic!("{name} 180: not a panorama")
            };
            assert_eq!(p.shape.window(), Some([0.25, 0.75]), "{name}");
        }
        error_at(
            &preset("perspective", &format!("fov = 60\n{rect}")),
            7,
            20,
            "`perspective_rect` is not a parameter of flexible preset \"perspective\"",
        );
    }

    #[test]
    fn bad_panoramas_are_refused_at_their_values() {
        error_at(
            &format!("{HEAD}outline = {{ shape = \"oval\" }}\nprofile = {{ shape = \"arc\" }}\n"),
            5,
            21,
            "unknown outline shape \"oval\"; expected one of: circle, square, rounded_square",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\", radius = 2 }}\nprofile = {{ shape = \"arc\" }}\n"),
            5,
            40,
            "`radius` is not a parameter of circle outlines",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"rounded_square\", radius = 2 }}\nprofile = {{ shape = \"arc\" }}\n"),
            5,
            48,
            "corner radius must lie in [0, 1]",
        );
        error_at(
            &format!("{HEAD}outline = {{ points = [[1, 1], [2, 1], [2, 2]] }}\nprofile = {{ shape = \"arc\" }}\n"),
            5,
            22,
            "outline must go once around the eye",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\nprofile = {{ shape = \"segment\", elevation = [-90, 10] }}\n"),
            6,
            44,
            "segment profile elevations must increase within (-90, 90)",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\nprofile = {{ points = [[1, 1], [1, 1]] }}\n"),
            6,
            22,
            "profile curve has zero length",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\n"),
            1,
            1,
            "a panorama needs `profile` (or `profiles`)",
        );
        error_at(
            &format!(
                "{HEAD}outline = {{ shape = \"circle\" }}\nprofiles = [{{ shape = \"arc\" }}]\n"
            ),
            6,
            13,
            "each entry of `profiles` needs `at`",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\nprofiles = [{{ at = 0.5, shape = \"arc\" }}, {{ at = 0.2, shape = \"arc\" }}]\n"),
            6,
            12,
            "profile attachment parameters `at` must increase strictly",
        );
        error_at(
            &format!("{HEAD}outline = {{ at = 0.3, shape = \"circle\" }}\nprofile = {{ shape = \"arc\" }}\n"),
            5,
            18,
            "`at` belongs to the entries of `outlines`",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\nprofile = {{ shape = \"arc\" }}\nblend = \"bezier\"\n"),
            7,
            9,
            "unknown panorama blend \"bezier\"",
        );
        error_at(
            &format!("{HEAD}outline = {{ shape = \"circle\" }}\nprofile = {{ shape = \"arc\" }}\nfov = 3\n"),
            7,
            7,
            "`fov` is not a parameter of flexible panoramas given by outlines and profiles",
        );
        error_at(
            "[projection]\ntype = \"flexible\"\npreset = \"rounded_cubic\"\nposition = [0, 1, 0]\nlook_at = [0, 1, -1]\ncorner_radius = 1.5\n",
            6,
            17,
            "`corner_radius` must lie in [0, 1]",
        );
    }
}
