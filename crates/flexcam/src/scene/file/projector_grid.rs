//! `projectors = { ... }` in a flexible projection: a projector grid (Brosz 2011, 5.2) sampled
//! from the projection's own volume, with node projectors placed explicitly (optionally
//! curved by a tangent), re-aimed node by node and fitted to point correspondences (with
//! tangents: curved projectors fitted). See scenes/README.md.

use std::path::Path;

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::raw::{RawNodeProjector, RawProjectors};
use super::source::Source;
use crate::error::Result;
use crate::projection::flexible::projector_grid::{Through, MAX_NODES, MIN_NODES};
use crate::projection::flexible::{Aim, GridInterpolation, NodeProjector, ProjectorGridSpec};
use crate::projection::flexible::{Correspondence, Reparam, Starts};
use crate::projection::Resolution;

/// Nodes per side when `size` is not given: the thesis's 5 x 5.
const DEFAULT_SIZE: usize = 5;

/// Converts a `projectors` table; every value is checked here so that errors point at it.
/// `reparam` is the projection's map from image positions to the grid's (u, v), which turns
/// `pixel` correspondences into (u, v).
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawProjectors>,
    reparam: &Reparam,
) -> Result<ProjectorGridSpec> {
    let raw = table.get_ref();
    let size = match &raw.size {
        Some(size) => {
            let [cols, rows] = *size.get_ref();
            let side = |n: i64| {
                usize::try_from(n)
                    .ok()
                    .filter(|n| (MIN_NODES..=MAX_NODES).contains(n))
            };
            match (side(cols), side(rows)) {
                (Some(c), Some(r)) => (c, r),
                _ => {
                    return Err(src.error(
                        &size.span(),
                        format!(
                            "projector grid `size` must be from {MIN_NODES} to {MAX_NODES} \
                             nodes per side, not [{cols}, {rows}]"
                        ),
                    ))
                }
            }
        }
        None => (DEFAULT_SIZE, DEFAULT_SIZE),
    };
    let interpolation = match &raw.interpolation {
        None => GridInterpolation::Bilinear,
        Some(name) => match name.get_ref().as_str() {
            "bilinear" => GridInterpolation::Bilinear,
            "bezier" => GridInterpolation::Bezier,
            other => {
                let expected = ["bilinear", "bezier"];
                return Err(src.unknown(&name.span(), "interpolation", other, &expected));
            }
        },
    };
    let mut projectors = Vec::new();
    for entry in raw.projector.iter().flatten() {
        projectors.push(node_projector(src, entry.get_ref(), size)?);
    }
    let mut aims = Vec::new();
    for aim in raw.aim.iter().flatten() {
        let a = aim.get_ref();
        aims.push(Aim {
            node: node(src, &a.node, size)?,
            at: finite_point(src, &a.at, "at")?,
        });
    }
    let painting = painting(src, raw)?;
    let mut correspondences = Vec::new();
    for (index, pair) in raw.fit.iter().flatten().enumerate() {
        let c = pair.get_ref();
        let entry = index + 1;
        let uv = match (&c.uv, &c.pixel) {
            (Some(uv), None) => {
                let uv_value = DVec2::from(*uv.get_ref());
                if !uv_value.is_finite()
                    || uv_value.min_element() < 0.0
                    || uv_value.max_element() > 1.0
                {
                    return Err(src.error(
                        &uv.span(),
                        format!(
                            "`fit` entry {entry}: `uv` must lie in [0, 1] x [0, 1], not [{}, {}]",
                            uv_value.x, uv_value.y
                        ),
                    ));
                }
                uv_value
            }
            (None, Some(pixel)) => painting_uv(src, painting.as_ref(), pixel, entry, reparam)?,
            (Some(_), Some(pixel)) => {
                return Err(src.error(
                    &pixel.span(),
                    format!(
                        "`fit` entry {entry} gives both `uv` and `pixel`: give one image \
                         position"
                    ),
                ))
            }
            (None, None) => {
                return Err(src.error(
                    &pair.span(),
                    format!(
                        "`fit` entry {entry} has no image position: give `pixel = [x, y]` (in \
                         the painting) or `uv = [u, v]` (in [0, 1])"
                    ),
                ))
            }
        };
        correspondences.push(Correspondence {
            uv,
            point: finite_point(src, &c.point, "point")?,
        });
    }
    let starts = starts(src, raw)?;
    Ok(ProjectorGridSpec {
        size,
        interpolation,
        projectors,
        aims,
        correspondences,
        starts,
    })
}

/// The painting's size in pixels, from the `painting` image file's header or from
/// `painting_size`; `None` when neither is given. Both keys go with `fit` only, and not
/// together.
fn painting(src: &Source, raw: &RawProjectors) -> Result<Option<Resolution>> {
    let with_fit = |span: &std::ops::Range<usize>| {
        if raw.fit.is_some() {
            return Ok(());
        }
        Err(src.error(
            span,
            "`painting` and `painting_size` go with `fit` (they give the size of the image its \
             `pixel` positions are in)",
        ))
    };
    let (given, (width, height)) = match (&raw.painting, &raw.painting_size) {
        (None, None) => return Ok(None),
        (Some(_), Some(size)) => {
            return Err(src.error(
                &size.span(),
                "give the painting as `painting = \"FILE\"` or its size as `painting_size`, \
                 not both",
            ))
        }
        (Some(name), None) => {
            with_fit(&name.span())?;
            (name.span(), painting_file_size(src, name)?)
        }
        (None, Some(size)) => {
            with_fit(&size.span())?;
            (size.span(), painting_size(src, size)?)
        }
    };
    Resolution::new(width, height)
        .map(Some)
        .map_err(|e| src.error(&given, format!("painting: {}", e.message)))
}

/// The size of the painting file `name` (relative to the scene file's folder), from its
/// header; the file is recorded as an input of the scene.
fn painting_file_size(src: &Source, name: &Spanned<String>) -> Result<(u32, u32)> {
    let base_dir = src.path.parent().unwrap_or(Path::new(""));
    let path = src.existing_file(name, base_dir, "painting")?;
    image::image_dimensions(&path).map_err(|e| {
        src.error(
            &name.span(),
            format!("painting \"{}\" cannot be read: {e}", name.get_ref()),
        )
    })
}

/// A `painting_size` value: two sides from 1 to [`MAX_PAINTING_SIDE`].
fn painting_size(src: &Source, size: &Spanned<[i64; 2]>) -> Result<(u32, u32)> {
    let [w, h] = *size.get_ref();
    let side = |n: i64| {
        u32::try_from(n)
            .ok()
            .filter(|n| (1..=MAX_PAINTING_SIDE).contains(n))
    };
    match (side(w), side(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(src.error(
            &size.span(),
            format!(
                "`painting_size` must be [width, height] in pixels, each from 1 to \
                 {MAX_PAINTING_SIDE}, not [{w}, {h}]"
            ),
        )),
    }
}

/// The largest side of a painting given by `painting_size`, in pixels (that of a large
/// photograph; the painting is only measured, never allocated, by the fit).
const MAX_PAINTING_SIDE: u32 = 1 << 16;

/// The (u, v) of `fit` entry `entry`'s `pixel` (x right, y down from the painting's
/// top-left corner, continuous: a pixel's centre at +0.5), through the projection's
/// re-parameterisation `reparam` at the painting's size. Errors: no painting given, a
/// position outside the painting or outside the map's domain (a fisheye's image circle).
fn painting_uv(
    src: &Source,
    painting: Option<&Resolution>,
    pixel: &Spanned<[f64; 2]>,
    entry: usize,
    reparam: &Reparam,
) -> Result<DVec2> {
    let at = DVec2::from(*pixel.get_ref());
    let Some(painting) = painting else {
        return Err(src.error(
            &pixel.span(),
            format!(
                "`fit` entry {entry}: `pixel` positions need the painting: give `painting = \
                 \"FILE\"` (or `painting_size = [width, height]`) in the `projectors` table"
            ),
        ));
    };
    let size = painting.size();
    let inside = at.is_finite() && at.cmpge(DVec2::ZERO).all() && at.cmple(size).all();
    let uv = inside
        .then(|| reparam.to_uv(painting, at))
        .flatten()
        .filter(|uv| uv.cmpge(DVec2::ZERO).all() && uv.cmple(DVec2::ONE).all());
    uv.ok_or_else(|| {
        let domain = if inside {
            format!(" (outside the {} map's image)", reparam.name())
        } else {
            String::new()
        };
        src.error(
            &pixel.span(),
            format!(
                "`fit` entry {entry}: pixel [{}, {}] is outside the {} x {} painting{domain}",
                at.x, at.y, painting.width, painting.height
            ),
        )
    })
}

/// The `starts` key: where the fitted projectors start (see the `fit` module); it goes with
/// `fit` only.
fn starts(src: &Source, raw: &RawProjectors) -> Result<Starts> {
    let Some(name) = &raw.starts else {
        return Ok(Starts::default());
    };
    if raw.fit.is_none() {
        return Err(src.error(
            &name.span(),
            "`starts` goes with `fit` (it says where the fitted projectors start)",
        ));
    }
    Starts::from_name(name.get_ref())
        .ok_or_else(|| src.unknown(&name.span(), "starts", name.get_ref(), &Starts::NAMES))
}

/// A `projector = [...]` entry; a zero `tangent` is allowed and means straight. With `point`
/// (the thesis's form, 5.2.1) the projector passes through it and `tangent` is its direction
/// there; `end` then cannot be given, and `length` only goes with `point`.
fn node_projector(
    src: &Source,
    raw: &RawNodeProjector,
    size: (usize, usize),
) -> Result<NodeProjector> {
    let optional = |value: &Option<Spanned<[f64; 3]>>, name| {
        value
            .as_ref()
            .map(|v| finite_point(src, v, name))
            .transpose()
    };
    let tangent = optional(&raw.tangent, "tangent")?;
    let through =
        match (&raw.point, &raw.end, &raw.length) {
            (Some(_), Some(end), _) => {
                return Err(src.error(
                    &end.span(),
                    "a node projector takes `end` or `point` (through a scene point), not both",
                ))
            }
            (None, _, Some(length)) => return Err(src.error(
                &length.span(),
                "`length` goes with `point` (a projector through a scene point); with `end` the \
                 length is the distance from `start` to `end`",
            )),
            (Some(point), None, length) => Some(Through {
                point: finite_point(src, point, "point")?,
                tangent,
                length: length.as_ref().map(|l| positive(src, l)).transpose()?,
            }),
            (None, _, None) => None,
        };
    Ok(NodeProjector {
        node: node(src, &raw.node, size)?,
        start: optional(&raw.start, "start")?,
        end: optional(&raw.end, "end")?,
        tangent: if through.is_some() { None } else { tangent },
        through,
    })
}

/// A `length` value: positive and finite.
fn positive(src: &Source, value: &Spanned<f64>) -> Result<f64> {
    let length = *value.get_ref();
    if length.is_finite() && length > 0.0 {
        return Ok(length);
    }
    Err(src.error(
        &value.span(),
        format!("`length` must be a positive number, not {length}"),
    ))
}

/// A `node = [column, row]` value, checked to lie in the grid.
fn node(src: &Source, value: &Spanned<[i64; 2]>, size: (usize, usize)) -> Result<(usize, usize)> {
    let [c, r] = *value.get_ref();
    let inside = |i: i64, n: usize| usize::try_from(i).ok().filter(|i| *i < n);
    match (inside(c, size.0), inside(r, size.1)) {
        (Some(col), Some(row)) => Ok((col, row)),
        _ => Err(src.error(
            &value.span(),
            format!(
                "projector node [{c}, {r}] is outside the {} x {} grid (columns and rows count \
                 from 0)",
                size.0, size.1
            ),
        )),
    }
}

fn finite_point(src: &Source, value: &Spanned<[f64; 3]>, name: &str) -> Result<DVec3> {
    src.all_finite(value.get_ref(), value, name)?;
    Ok(DVec3::from(*value.get_ref()))
}
