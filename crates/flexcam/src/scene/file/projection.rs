//! `[projection]`: checks a projection table against its type's parameters and converts it
//! into a [`ProjectionSpec`].

use std::path::Path;

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::calibrated_projection;
use super::projection_table::{camera_frame, Required};
use super::raw::{ProjectionTypeProbe, RawProjection};
use super::source::Source;
use crate::error::Result;
use crate::projection::flexible::FlexibleSpec;
use crate::projection::{ProjectionSpec, TrilinearMesh};

/// The projection types this parser converts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Perspective,
    Orthographic,
    Fisheye,
    DomeMaster,
    Equirectangular,
    Cylindrical,
    Opencv,
    OpencvFisheye,
    Ods,
    Vr180,
    Trilinear,
    Flexible,
}

/// Type names as written in scene files.
const KINDS: [(&str, Kind); 12] = [
    ("perspective", Kind::Perspective),
    ("orthographic", Kind::Orthographic),
    ("fisheye", Kind::Fisheye),
    ("dome_master", Kind::DomeMaster),
    ("equirectangular", Kind::Equirectangular),
    ("cylindrical", Kind::Cylindrical),
    ("opencv", Kind::Opencv),
    ("opencv_fisheye", Kind::OpencvFisheye),
    ("ods", Kind::Ods),
    ("vr180", Kind::Vr180),
    ("trilinear", Kind::Trilinear),
    ("flexible", Kind::Flexible),
];

/// Projection types of the spec that are recognised but not implemented yet (none now; the
/// mechanism stays for the next one).
const UNSUPPORTED: [&str; 0] = [];

/// Keys of a trilinear projection given as a mesh (a surface file or inline arrays).
const MESH_KEYS: [&str; 5] = ["surface", "points", "normals", "screen", "triangles"];

/// Keys of a trilinear projection given as a grid (`grid` and its bases).
const GRID_KEYS: [&str; 17] = [
    "grid",
    "near",
    "far",
    "view",
    "camera",
    "focus",
    "inset",
    "magnification",
    "focus_view",
    "converge",
    "first",
    "second",
    "band",
    "sphere",
    "second_sphere",
    "ior",
    "exact",
];

/// Parameters of the single-viewpoint projections, shared by all of them.
const FRAME_KEYS: [&str; 3] = ["position", "look_at", "up"];

impl Kind {
    fn parse(name: &str) -> Option<Kind> {
        KINDS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, kind)| kind)
    }

    fn name(self) -> &'static str {
        KINDS
            .iter()
            .find(|(_, k)| *k == self)
            .map_or("", |(n, _)| n)
    }

    /// The keys (besides `type`) a table of this type may hold.
    fn keys(self) -> Vec<&'static str> {
        let own: &[&str] = match self {
            Kind::Perspective => &["fov"],
            Kind::Fisheye => &super::fisheye_projection::FISHEYE_KEYS,
            Kind::DomeMaster => &super::fisheye_projection::DOME_KEYS,
            Kind::Orthographic => &["width"],
            Kind::Equirectangular | Kind::Cylindrical => &["h_fov", "v_fov"],
            Kind::Opencv => &calibrated_projection::OPENCV_KEYS,
            Kind::OpencvFisheye => &calibrated_projection::FISHEYE_KEYS,
            Kind::Ods => &["ipd", "pole_merge_from", "pole_merge_to"],
            Kind::Vr180 => &["ipd"],
            Kind::Trilinear => {
                return MESH_KEYS.iter().chain(&GRID_KEYS).copied().collect();
            }
            Kind::Flexible => return super::flexible::KEYS.to_vec(),
        };
        FRAME_KEYS.iter().chain(own).copied().collect()
    }
}

/// Every projection type name a scene file may use, for error messages.
fn all_type_names() -> Vec<&'static str> {
    KINDS
        .iter()
        .map(|(name, _)| *name)
        .chain(UNSUPPORTED)
        .collect()
}

/// Fails with a clear message, at the `type` value, when the file asks for a projection type
/// that is recognised but not supported yet. Runs before the strict parse, which would
/// otherwise report that type's parameters as unknown keys.
pub(super) fn reject_unsupported(src: &Source) -> Result<()> {
    let Ok(probe) = toml::from_str::<ProjectionTypeProbe>(src.text) else {
        return Ok(()); // The strict parse reports the problem.
    };
    match probe.projection {
        Some(p) if UNSUPPORTED.contains(&p.kind.get_ref().as_str()) => Err(src.error(
            &p.kind.span(),
            format!(
                "projection type \"{}\" is not supported yet",
                p.kind.get_ref()
            ),
        )),
        _ => Ok(()),
    }
}

/// Converts the `[projection]` table. Relative paths (`surface`) are resolved against
/// `base_dir`; `image_size` is the scene's `[image]` size, the one a calibrated camera
/// without `calibration_size` is for. Only the file's form is checked here;
/// [`ProjectionSpec::build`] checks that the projection is not degenerate.
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawProjection>,
    base_dir: &Path,
    image_size: [u32; 2],
) -> Result<ProjectionSpec> {
    let raw = table.get_ref();
    let type_name = raw.kind.as_ref().ok_or_else(|| {
        src.error(
            &table.span(),
            format!(
                "missing field `type` (the projection type: one of {})",
                all_type_names().join(", ")
            ),
        )
    })?;
    let name = type_name.get_ref();
    let kind = Kind::parse(name).ok_or_else(|| {
        src.unknown(
            &type_name.span(),
            "projection type",
            name,
            &all_type_names(),
        )
    })?;
    src.reject_foreign_key(
        raw.present_keys(),
        &kind.keys(),
        &format!("{name} projections"),
    )?;
    let required = Required {
        src,
        table,
        type_name: kind.name(),
    };
    let angle = |value: &Option<Spanned<f64>>, key: &str, default: f64| {
        value.as_ref().map_or(Ok(default), |v| src.number(v, key))
    };
    Ok(match kind {
        Kind::Trilinear => trilinear(src, &required, base_dir)?,
        Kind::Flexible => ProjectionSpec::Flexible(Box::new(match &raw.interpolate {
            Some(blend) => {
                super::interpolate::convert(src, table, blend, image_size, |part, who| {
                    flexible_part(src, part, base_dir, image_size, who)
                })?
            }
            None => super::flexible::convert(&required, base_dir)?,
        })),
        Kind::Perspective => ProjectionSpec::Perspective {
            frame: camera_frame(src, &required)?,
            fov: src.number(required.get(&raw.fov, "fov")?, "fov")?,
        },
        Kind::Orthographic => ProjectionSpec::Orthographic {
            frame: camera_frame(src, &required)?,
            width: src.number(required.get(&raw.width, "width")?, "width")?,
        },
        Kind::Fisheye => super::fisheye_projection::fisheye(&required)?,
        Kind::DomeMaster => super::fisheye_projection::dome_master(&required)?,
        Kind::Equirectangular => ProjectionSpec::Equirectangular {
            frame: camera_frame(src, &required)?,
            h_fov: angle(&raw.h_fov, "h_fov", 360.0)?,
            v_fov: angle(&raw.v_fov, "v_fov", 180.0)?,
        },
        Kind::Cylindrical => ProjectionSpec::Cylindrical {
            frame: camera_frame(src, &required)?,
            h_fov: angle(&raw.h_fov, "h_fov", 360.0)?,
            v_fov: angle(&raw.v_fov, "v_fov", 90.0)?,
        },
        Kind::Opencv => calibrated_projection::opencv(&required, image_size)?,
        Kind::OpencvFisheye => calibrated_projection::opencv_fisheye(&required, image_size)?,
        Kind::Ods => ProjectionSpec::Ods {
            frame: camera_frame(src, &required)?,
            ipd: angle(&raw.ipd, "ipd", DEFAULT_IPD)?,
            pole_merge: pole_merge(&required)?,
        },
        Kind::Vr180 => ProjectionSpec::Vr180 {
            frame: camera_frame(src, &required)?,
            ipd: angle(&raw.ipd, "ipd", DEFAULT_IPD)?,
        },
    })
}

/// The interpupillary distance of the stereo projections when `ipd` is not given (metres):
/// a typical adult's.
const DEFAULT_IPD: f64 = 0.064;

/// `pole_merge_from` and `pole_merge_to` (degrees) of an ods projection: both or neither
/// (no merging); their range is checked when the projection is built.
fn pole_merge(required: &Required) -> Result<Option<[f64; 2]>> {
    let raw = required.raw();
    match (&raw.pole_merge_from, &raw.pole_merge_to) {
        (None, None) => Ok(None),
        (Some(from), Some(to)) => Ok(Some([
            required.src.number(from, "pole_merge_from")?,
            required.src.number(to, "pole_merge_to")?,
        ])),
        (Some(given), None) | (None, Some(given)) => Err(required.src.error(
            &given.span(),
            "ods pole merging needs both `pole_merge_from` and `pole_merge_to`",
        )),
    }
}

/// A trilinear mesh from `surface = "file.obj"`, from the inline arrays, or from `grid` (or
/// the exact view a grid samples, `exact = true`).
fn trilinear(src: &Source, required: &Required, base_dir: &Path) -> Result<ProjectionSpec> {
    let raw = required.raw();
    let present = raw.present_keys();
    if let Some(cells) = &raw.grid {
        if let Some((key, span)) = present.iter().find(|(k, _)| MESH_KEYS.contains(k)) {
            return Err(src.error(
                span,
                format!("`{key}` cannot be combined with `grid`: give a grid or a mesh"),
            ));
        }
        return super::trilinear_grid::convert(required, cells);
    }
    if let Some((key, span)) = present.iter().find(|(k, _)| GRID_KEYS.contains(k)) {
        return Err(src.error(span, format!("`{key}` belongs to a trilinear `grid`")));
    }
    if let Some(surface) = &raw.surface {
        let inline = [
            ("points", raw.points.as_ref().map(Spanned::span)),
            ("normals", raw.normals.as_ref().map(Spanned::span)),
            ("screen", raw.screen.as_ref().map(Spanned::span)),
            ("triangles", raw.triangles.as_ref().map(Spanned::span)),
        ];
        if let Some((key, Some(span))) = inline.into_iter().find(|(_, span)| span.is_some()) {
            return Err(src.error(
                &span,
                format!("`{key}` cannot be combined with `surface`: give a surface file or inline arrays"),
            ));
        }
        let path = src.existing_file(surface, base_dir, "trilinear surface")?;
        crate::scene::loaders::check_obj_file(&path)?;
        return TrilinearMesh::load_obj(&path)
            .map(ProjectionSpec::Trilinear)
            .map_err(|e| e.or_in_file(&path));
    }
    if raw.points.is_none() {
        return Err(src.error(
            &required.table.span(),
            "trilinear projection needs `surface` or the inline `points`, `normals`, `screen` and `triangles`, or a `grid`",
        ));
    }
    let points = required.get(&raw.points, "points")?;
    let normals = required.get(&raw.normals, "normals")?;
    let screen = required.get(&raw.screen, "screen")?;
    let triangles = required.get(&raw.triangles, "triangles")?;
    let n = points.get_ref().len();
    for (key, len, span) in [
        ("normals", normals.get_ref().len(), normals.span()),
        ("screen", screen.get_ref().len(), screen.span()),
    ] {
        if len != n {
            return Err(src.error(
                &span,
                format!("`{key}` has {len} entries but `points` has {n}"),
            ));
        }
    }
    src.all_finite(points.get_ref().as_flattened(), points, "points")?;
    src.all_finite(normals.get_ref().as_flattened(), normals, "normals")?;
    src.all_finite(screen.get_ref().as_flattened(), screen, "screen")?;
    if let Some((i, t)) = triangles
        .get_ref()
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&k| k as usize >= n))
    {
        return Err(src.error(
            &triangles.span(),
            format!("triangle {i} {t:?} refers to a vertex beyond the {n} `points` (indices start at 0)"),
        ));
    }
    Ok(ProjectionSpec::Trilinear(TrilinearMesh {
        points: points
            .get_ref()
            .iter()
            .map(|&p| DVec3::from_array(p))
            .collect(),
        normals: normals
            .get_ref()
            .iter()
            .map(|&d| DVec3::from_array(d))
            .collect(),
        screen: screen
            .get_ref()
            .iter()
            .map(|&s| DVec2::from_array(s))
            .collect(),
        triangles: triangles.get_ref().clone(),
    }))
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
    match convert(src, table, base_dir, image_size)? {
        ProjectionSpec::Flexible(projection) => Ok(*projection),
        other => Err(src.error(
            &table
                .get_ref()
                .kind
                .as_ref()
                .map_or(table.span(), Spanned::span),
            format!(
                "{who} type = \"flexible\" (only flexible volumes can be interpolated), not \
                 \"{}\"",
                other.kind()
            ),
        )),
    }
}
