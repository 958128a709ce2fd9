//! Control surface tables (`near`, `far`, each entry of `surfaces`, a trilinear grid's base):
//! a surface type name with that type's keys, checked and converted into a [`Surface`]. Shared
//! by the flexible projection tables and the trilinear `grid` tables.

use glam::DVec3;
use toml::Spanned;

use super::raw::RawSurface;
use super::source::Source;
use crate::error::{Error, Result};
use crate::projection::flexible::nurbs::MAX_CONTROL;
use crate::projection::flexible::{
    BSplinePatch, BezierPatch, CylinderPatch, LineParam, NurbsPatch, NurbsSpec, PolarFrame,
    SpherePatch, Surface,
};

/// The surface type names of scene files.
const SURFACE_NAMES: [&str; 10] = [
    "rectangle",
    "bilinear",
    "sphere",
    "hemisphere",
    "cylinder",
    "point",
    "line",
    "bezier",
    "bspline",
    "nurbs",
];

/// A bicubic Bezier surface from `control[row][column]`. Errors: not 4 rows of 4 points.
fn bezier_patch(rows: Vec<Vec<DVec3>>) -> Result<Surface> {
    let size = |rows: &[Vec<DVec3>]| {
        format!(
            "{} x {}",
            rows.len(),
            rows.iter().map(Vec::len).max().unwrap_or(0)
        )
    };
    let grid: Option<[[DVec3; 4]; 4]> = rows
        .iter()
        .map(|row| <[DVec3; 4]>::try_from(row.as_slice()).ok())
        .collect::<Option<Vec<_>>>()
        .and_then(|r| r.try_into().ok());
    match grid {
        Some(control) => Ok(Surface::Bezier(Box::new(BezierPatch { control }))),
        None => Err(Error::new(format!(
            "bezier surface needs 4 rows of 4 control points, got {}",
            size(&rows)
        ))),
    }
}

/// The keys each surface type takes (besides `surface`).
fn surface_keys(name: &str) -> &'static [&'static str] {
    match name {
        "rectangle" => &["center", "u_axis", "v_axis", "corner", "u_edge", "v_edge"],
        "bilinear" => &["corners"],
        "sphere" | "hemisphere" => &["center", "radius", "longitude", "latitude", "axis", "front"],
        "cylinder" => &["center", "radius", "angle", "height", "axis", "front"],
        "point" => &["point"],
        "bezier" | "bspline" => &["control"],
        "nurbs" => &["control", "weights", "degree", "u_knots", "v_knots"],
        _ => &["start", "end", "along"],
    }
}

/// One control surface table (`which` is `near`, `far` or `surface N`, for messages).
pub(super) fn surface(src: &Source, table: &Spanned<RawSurface>, which: &str) -> Result<Surface> {
    let raw = table.get_ref();
    let name = raw.surface.get_ref().as_str();
    if !SURFACE_NAMES.contains(&name) {
        return Err(src.unknown(&raw.surface.span(), "surface", name, &SURFACE_NAMES));
    }
    src.reject_foreign_key(
        raw.present_keys(),
        surface_keys(name),
        &format!("{name} surfaces"),
    )?;
    let need = |v: &Option<Spanned<[f64; 3]>>, key: &str| -> Result<DVec3> {
        let v = v.as_ref().ok_or_else(|| {
            src.error(
                &table.span(),
                format!("{which} {name} surface needs `{key}`"),
            )
        })?;
        src.dvec3(v, key)
    };
    let or = |v: &Option<Spanned<[f64; 3]>>, key: &str, default: DVec3| -> Result<DVec3> {
        v.as_ref().map_or(Ok(default), |v| src.dvec3(v, key))
    };
    let range =
        |v: &Option<Spanned<[f64; 2]>>, key: &str, default: Option<[f64; 2]>| match (v, default) {
            (Some(v), _) => src.vector(v, key).map(|r| r.map(f64::to_radians)),
            (None, Some(d)) => Ok(d.map(f64::to_radians)),
            (None, None) => Err(src.error(
                &table.span(),
                format!("{which} {name} surface needs `{key}`"),
            )),
        };
    let radius = || -> Result<f64> {
        let r = raw.radius.as_ref().ok_or_else(|| {
            src.error(
                &table.span(),
                format!("{which} {name} surface needs `radius`"),
            )
        })?;
        let x = src.number(r, "radius")?;
        if x < 0.0 {
            return Err(src.error(&r.span(), format!("`radius` must not be negative, got {x}")));
        }
        Ok(x)
    };
    let frame = || -> Result<PolarFrame> {
        let axis = or(&raw.axis, "axis", DVec3::Y)?;
        let front = or(&raw.front, "front", DVec3::NEG_Z)?;
        PolarFrame::new(axis, front).map_err(|e| {
            let at = raw
                .front
                .as_ref()
                .or(raw.axis.as_ref())
                .map_or(table.span(), Spanned::span);
            src.error(&at, e.message)
        })
    };
    let surface = match name {
        "rectangle" => {
            if raw.corner.is_some() {
                if let Some(c) = raw.center.as_ref() {
                    return Err(src.error(
                        &c.span(),
                        "give a rectangle by `center`, `u_axis`, `v_axis` or by `corner`, \
                         `u_edge`, `v_edge`, not both",
                    ));
                }
                Surface::Rectangle {
                    corner: need(&raw.corner, "corner")?,
                    u_edge: need(&raw.u_edge, "u_edge")?,
                    v_edge: need(&raw.v_edge, "v_edge")?,
                }
            } else {
                Surface::rectangle_centred(
                    need(&raw.center, "center")?,
                    need(&raw.u_axis, "u_axis")?,
                    need(&raw.v_axis, "v_axis")?,
                )
            }
        }
        "bilinear" => {
            let c = raw.corners.as_ref().ok_or_else(|| {
                src.error(
                    &table.span(),
                    format!("{which} bilinear surface needs `corners`"),
                )
            })?;
            src.all_finite(c.get_ref().as_flattened(), c, "corners")?;
            Surface::Bilinear {
                corners: c.get_ref().map(DVec3::from_array),
            }
        }
        "sphere" | "hemisphere" => {
            let latitude = if name == "sphere" {
                [-90.0, 90.0]
            } else {
                [90.0, 0.0]
            };
            Surface::Sphere(SpherePatch {
                center: need(&raw.center, "center")?,
                radius: radius()?,
                frame: frame()?,
                longitude: range(&raw.longitude, "longitude", Some([-180.0, 180.0]))?,
                latitude: range(&raw.latitude, "latitude", Some(latitude))?,
            })
        }
        "cylinder" => Surface::Cylinder(CylinderPatch {
            center: need(&raw.center, "center")?,
            radius: radius()?,
            frame: frame()?,
            angle: range(&raw.angle, "angle", Some([-180.0, 180.0]))?,
            height: match &raw.height {
                Some(h) => src.vector(h, "height")?,
                None => range(&None, "height", None)?,
            },
        }),
        "point" => Surface::Point(need(&raw.point, "point")?),
        "nurbs" => nurbs(src, table, which)?,
        "bezier" | "bspline" => {
            let c = raw.control.as_ref().ok_or_else(|| {
                src.error(
                    &table.span(),
                    format!("{which} {name} surface needs `control`"),
                )
            })?;
            let rows: Vec<Vec<DVec3>> = c
                .get_ref()
                .iter()
                .map(|row| row.iter().map(|p| DVec3::from_array(*p)).collect())
                .collect();
            src.all_finite(c.get_ref().concat().as_flattened(), c, "control")?;
            let patch = if name == "bezier" {
                bezier_patch(rows)
            } else {
                BSplinePatch::new(rows).map(Surface::BSpline)
            };
            patch.map_err(|e| src.error(&c.span(), format!("{which} {}", e.message)))?
        }
        _ => {
            let along = match raw.along.as_ref() {
                None => LineParam::U,
                Some(a) => match a.get_ref().as_str() {
                    "u" => LineParam::U,
                    "v" => LineParam::V,
                    other => {
                        return Err(src.error(
                            &a.span(),
                            format!("`along` must be \"u\" or \"v\", not \"{other}\""),
                        ))
                    }
                },
            };
            Surface::Line {
                start: need(&raw.start, "start")?,
                end: need(&raw.end, "end")?,
                along,
            }
        }
    };
    surface.validate().map_err(|e| {
        let at = [
            ("latitude", &raw.latitude),
            ("longitude", &raw.longitude),
            ("angle", &raw.angle),
        ]
        .into_iter()
        .find(|(key, value)| value.is_some() && e.message.contains(key))
        .and_then(|(_, value)| value.as_ref())
        .map_or(table.span(), Spanned::span);
        src.error(&at, format!("{which} {}", e.message))
    })?;
    Ok(surface)
}

/// A NURBS surface table: `control` (required), `weights`, `degree` (default [3, 3]),
/// `u_knots` and `v_knots` (default clamped uniform). Counts beyond [`MAX_CONTROL`] are
/// refused before anything is built; every other error of [`NurbsPatch::new`] is reported
/// at the key it concerns (knots at their list, weights at theirs, counts at `control`).
fn nurbs(src: &Source, table: &Spanned<RawSurface>, which: &str) -> Result<Surface> {
    let raw = table.get_ref();
    let c = raw.control.as_ref().ok_or_else(|| {
        src.error(
            &table.span(),
            format!("{which} nurbs surface needs `control`"),
        )
    })?;
    let rows = c.get_ref();
    if rows.len() > MAX_CONTROL || rows.iter().any(|row| row.len() > MAX_CONTROL) {
        return Err(src.error(
            &c.span(),
            format!(
                "{which} nurbs surface takes at most {MAX_CONTROL} x {MAX_CONTROL} control points"
            ),
        ));
    }
    src.all_finite(rows.concat().as_flattened(), c, "control")?;
    let degree = match &raw.degree {
        None => [3, 3],
        Some(d) => {
            let [p, q] = *d.get_ref();
            let fit = |x: i64| usize::try_from(x).ok().filter(|&x| x <= MAX_CONTROL);
            match (fit(p), fit(q)) {
                (Some(p), Some(q)) => [p, q],
                _ => {
                    return Err(src.error(
                        &d.span(),
                        format!(
                            "{which} nurbs surface degree must be [u, v] in 1..=7, got [{p}, {q}]"
                        ),
                    ))
                }
            }
        }
    };
    let list = |v: &Option<Spanned<Vec<f64>>>, key: &str| -> Result<Option<Vec<f64>>> {
        v.as_ref()
            .map(|k| {
                if k.get_ref().len() > 2 * MAX_CONTROL {
                    return Err(src.error(
                        &k.span(),
                        format!("`{key}` holds at most {} knots", 2 * MAX_CONTROL),
                    ));
                }
                src.all_finite(k.get_ref(), k, key)?;
                Ok(k.get_ref().clone())
            })
            .transpose()
    };
    let weights = match &raw.weights {
        None => None,
        Some(w) => {
            if w.get_ref().len() > MAX_CONTROL || w.get_ref().iter().any(|r| r.len() > MAX_CONTROL)
            {
                return Err(src.error(
                    &w.span(),
                    format!("`weights` holds at most {MAX_CONTROL} x {MAX_CONTROL} numbers"),
                ));
            }
            src.all_finite(&w.get_ref().concat(), w, "weights")?;
            Some(w.get_ref().clone())
        }
    };
    let spec = NurbsSpec {
        control: rows
            .iter()
            .map(|row| row.iter().map(|p| DVec3::from_array(*p)).collect())
            .collect(),
        weights,
        degree,
        u_knots: list(&raw.u_knots, "u_knots")?,
        v_knots: list(&raw.v_knots, "v_knots")?,
    };
    NurbsPatch::new(spec)
        .map(|patch| Surface::Nurbs(Box::new(patch)))
        .map_err(|e| {
            let m = &e.message;
            let at = if m.contains(" u knot") {
                raw.u_knots.as_ref().map(Spanned::span)
            } else if m.contains(" v knot") {
                raw.v_knots.as_ref().map(Spanned::span)
            } else if m.contains("weights") {
                raw.weights.as_ref().map(Spanned::span)
            } else if m.contains("degree along") {
                raw.degree.as_ref().map(Spanned::span)
            } else {
                None
            };
            src.error(&at.unwrap_or(c.span()), format!("{which} {m}"))
        })
}
