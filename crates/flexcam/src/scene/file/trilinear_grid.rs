//! `grid = N` in a trilinear `[projection]`: a regular screen grid of projection triangles
//! over a base given by two control surfaces (`near`, `far`) or by a visualisation surface
//! (`view`): see scenes/README.md.

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::control_surface::surface;
use super::projection_table::Required;
use super::raw::RawCamera;
use super::source::Source;
use crate::error::{Error, Result};
use crate::projection::trilinear_builders::{
    between_surfaces, screen_grid, DetailInContext, GridCamera, TwoViews,
};
use crate::projection::{CameraFrame, TrilinearMesh};

/// The visualisation surfaces `view` may name, with the keys (besides `grid` and `view`)
/// each takes.
const VIEWS: [(&str, &[&str]); 2] = [
    (
        "detail_in_context",
        &["camera", "focus", "inset", "magnification"],
    ),
    ("two_views", &["first", "second", "band"]),
];

/// Keys of a grid over two control surfaces (besides `grid`).
const SURFACE_KEYS: [&str; 2] = ["near", "far"];

/// The mesh of a trilinear projection table that has `grid`.
pub(super) fn convert(required: &Required, cells: &Spanned<u32>) -> Result<TrilinearMesh> {
    let src = required.src;
    let raw = required.raw();
    let present: Vec<_> = raw
        .present_keys()
        .into_iter()
        .filter(|(key, _)| *key != "grid" && *key != "view")
        .collect();
    let at_table = |e: Error| src.error(&required.table.span(), e.message);
    let mesh = match &raw.view {
        None => {
            src.reject_foreign_key(present, &SURFACE_KEYS, "grids over surfaces (no `view`)")?;
            let near = surface(src, required.get(&raw.near, "near")?, "near")?;
            let far = surface(src, required.get(&raw.far, "far")?, "far")?;
            screen_grid(*cells.get_ref(), between_surfaces(&near, &far))
        }
        Some(view) => {
            let name = view.get_ref().as_str();
            let Some((_, keys)) = VIEWS.iter().find(|(n, _)| *n == name) else {
                let names: Vec<_> = VIEWS.iter().map(|(n, _)| *n).collect();
                return Err(src.unknown(&view.span(), "view", name, &names));
            };
            src.reject_foreign_key(present, keys, &format!("view \"{name}\""))?;
            if name == "detail_in_context" {
                let table = required.get(&raw.camera, "camera")?;
                let (camera, frame) = camera(src, table)?;
                // The magnification holds at the camera's look-at distance.
                let distance = frame.look_at.distance(frame.position);
                let focus = match &raw.focus {
                    Some(f) => DVec2::from_array(src.vector(f, "focus")?),
                    None => DVec2::splat(0.5),
                };
                let inset = raw
                    .inset
                    .as_ref()
                    .map_or(Ok([0.15, 0.35]), |i| src.vector(i, "inset"))?;
                let magnification = raw
                    .magnification
                    .as_ref()
                    .map_or(Ok(3.0), |m| src.number(m, "magnification"))?;
                let surface = DetailInContext::new(camera, focus, inset, magnification, distance)
                    .map_err(|e| {
                    let key = if e.message.contains("magnification") {
                        raw.magnification.as_ref().map(Spanned::span)
                    } else if e.message.contains("inset") {
                        raw.inset.as_ref().map(Spanned::span)
                    } else {
                        Some(table.span())
                    };
                    let at = key.unwrap_or_else(|| required.table.span());
                    src.error(&at, e.message)
                })?;
                screen_grid(*cells.get_ref(), |s| surface.vertex(s))
            } else {
                let (first, _) = camera(src, required.get(&raw.first, "first")?)?;
                let (second, _) = camera(src, required.get(&raw.second, "second")?)?;
                let band = raw
                    .band
                    .as_ref()
                    .map_or(Ok([0.4, 0.6]), |b| src.vector(b, "band"))?;
                let surface = TwoViews::new(first, second, band).map_err(|e| {
                    let at = raw
                        .band
                        .as_ref()
                        .map_or(required.table.span(), Spanned::span);
                    src.error(&at, e.message)
                })?;
                screen_grid(*cells.get_ref(), |s| surface.vertex(s))
            }
        }
    };
    mesh.map_err(|e| {
        if e.message.starts_with("grid must have") {
            src.error(&cells.span(), e.message)
        } else {
            at_table(e)
        }
    })
}

/// A camera table: `position`, `look_at`, `up` (default +y) and either `h_fov` and `v_fov`
/// (a pinhole) or `width` and `height` (parallel rays); with its frame.
fn camera(src: &Source, table: &Spanned<RawCamera>) -> Result<(GridCamera, CameraFrame)> {
    let raw = table.get_ref();
    let frame = CameraFrame {
        position: src.dvec3(&raw.position, "position")?,
        look_at: src.dvec3(&raw.look_at, "look_at")?,
        up: raw
            .up
            .as_ref()
            .map_or(Ok(DVec3::Y), |up| src.dvec3(up, "up"))?,
    };
    let pair = |a: &Option<Spanned<f64>>, an: &str, b: &Option<Spanned<f64>>, bn: &str| match (a, b)
    {
        (Some(a), Some(b)) => Ok(Some((src.number(a, an)?, src.number(b, bn)?))),
        (None, None) => Ok(None),
        _ => Err(src.error(
            &table.span(),
            format!("a camera needs both `{an}` and `{bn}`"),
        )),
    };
    let camera = match (
        pair(&raw.h_fov, "h_fov", &raw.v_fov, "v_fov")?,
        pair(&raw.width, "width", &raw.height, "height")?,
    ) {
        (Some((h, v)), None) => GridCamera::perspective(&frame, h, v),
        (None, Some((w, h))) => GridCamera::orthographic(&frame, w, h),
        _ => {
            return Err(src.error(
                &table.span(),
                "a camera needs either `h_fov` and `v_fov` (perspective) or `width` and \
                 `height` (orthographic)",
            ))
        }
    };
    let camera = camera.map_err(|e| src.error(&table.span(), e.message))?;
    Ok((camera, frame))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::{DVec2, DVec3};

    use crate::projection::ProjectionSpec;
    use crate::scene::file::parse;

    fn mesh(projection: &str) -> crate::projection::TrilinearMesh {
        let text = format!("[projection]\ntype = \"trilinear\"\n{projection}");
        match parse(&text, Path::new("dir/s.toml")) {
            Ok(scene) => match scene.projection {
                ProjectionSpec::Trilinear(mesh) => mesh,
                other => panic!("{other:?}"),
            },
            Err(e) => panic!("{e}"),
        }
    }

    /// The one-line error of a trilinear table, which must start with `dir/s.toml:LINE:COL:`.
    fn error_at(projection: &str, line: usize, column: usize, needle: &str) {
        let text = format!("[projection]\ntype = \"trilinear\"\n{projection}");
        let e = parse(&text, Path::new("dir/s.toml"))
            .unwrap_err()
            .to_string();
        let prefix = format!("dir/s.toml:{line}:{column}: ");
        assert!(e.starts_with(&prefix) && e.contains(needle), "{e}");
    }

    const SURFACES: &str = "near = { surface = \"sphere\", center = [0, 1, 0], radius = 6.0 }\n\
                            far = { surface = \"point\", point = [0, 1, 0] }\n";

    #[test]
    fn grid_over_surfaces() {
        let m = mesh(&format!("grid = 4\n{SURFACES}"));
        assert_eq!((m.points.len(), m.triangles.len()), (25, 32));
        assert_eq!(m.screen[24], DVec2::ONE);
        // Inward rays: from the sphere to its centre.
        for (p, n) in m.points.iter().zip(&m.normals) {
            assert!((*p + *n - DVec3::Y).length() < 1e-12);
        }
    }

    #[test]
    fn grid_views() {
        let camera = "{ position = [0, 2, 6], look_at = [0, 1, 0], h_fov = 60, v_fov = 45 }";
        let m = mesh(&format!(
            "grid = 6\nview = \"detail_in_context\"\ncamera = {camera}\nmagnification = 2\n"
        ));
        assert_eq!(m.triangles.len(), 72);
        // The focus (default: the screen centre, vertex 24 of the 7 x 7) looks along the
        // camera's axis from the base plane at the look-at distance over the magnification.
        let (eye, look_at) = (DVec3::new(0.0, 2.0, 6.0), DVec3::new(0.0, 1.0, 0.0));
        let axis = (look_at - eye).normalize();
        assert!((m.normals[24].normalize() - axis).length() < 1e-12);
        let base = (m.points[24] - eye).length();
        assert!((base - look_at.distance(eye) / 2.0).abs() < 1e-12, "{base}");
        let m = mesh(&format!(
            "grid = 2\nview = \"two_views\"\nfirst = {camera}\n\
             second = {{ position = [0, 9, 0], look_at = [0, 0, 0], up = [0, 0, -1], width = 8, height = 6 }}\n"
        ));
        // The top row is the orthographic view from above: parallel rays straight down.
        assert!((m.normals[8] - DVec3::NEG_Y).length() < 1e-12);
        assert!(
            (m.points[0].y - 2.0).abs() < 1.0,
            "the bottom row is the first view"
        );
    }

    #[test]
    fn grid_errors_are_positioned() {
        error_at("grid = 0\nnear = { surface = \"point\", point = [0, 0, 0] }\nfar = { surface = \"point\", point = [0, 0, 1] }\n", 3, 8, "1..=256");
        error_at(
            &format!("grid = 2\nsurface = \"x.obj\"\n{SURFACES}"),
            4,
            11,
            "cannot be combined with `grid`",
        );
        error_at(SURFACES, 3, 8, "`near` belongs to a trilinear `grid`");
        error_at(
            "grid = 2\nnear = { surface = \"point\", point = [0, 0, 0] }\n",
            1,
            1,
            "needs `far`",
        );
        error_at(
            &format!("grid = 2\n{SURFACES}band = [0, 1]\n"),
            6,
            8,
            "`band` is not a parameter of grids over surfaces",
        );
        error_at(
            "grid = 2\nview = \"fisheye\"\n",
            4,
            8,
            "unknown view \"fisheye\"",
        );
        let camera = "{ position = [0, 2, 6], look_at = [0, 1, 0], h_fov = 60, v_fov = 45 }";
        error_at(
            &format!(
                "grid = 2\nview = \"detail_in_context\"\ncamera = {camera}\ninset = [0.3, 0.2]\n"
            ),
            6,
            9,
            "0 < inner < outer",
        );
        error_at(
            &format!(
                "grid = 2\nview = \"detail_in_context\"\ncamera = {camera}\nmagnification = -1\n"
            ),
            6,
            17,
            "magnification must be positive",
        );
        error_at("grid = 2\nview = \"detail_in_context\"\ncamera = { position = [0, 2, 6], look_at = [0, 1, 0], h_fov = 60 }\n", 5, 10, "both `h_fov` and `v_fov`");
        error_at("grid = 2\nview = \"detail_in_context\"\ncamera = { position = [0, 2, 6], look_at = [0, 1, 0], width = 4, height = 3 }\n", 5, 10, "needs a pinhole camera");
        error_at("grid = 2\nview = \"detail_in_context\"\ncamera = { position = [0, 2, 6], look_at = [0, 1, 0] }\n", 5, 10, "either `h_fov` and `v_fov`");
        error_at(&format!("grid = 2\nview = \"two_views\"\nfirst = {camera}\nsecond = {camera}\nband = [0.7, 0.2]\n"), 7, 8, "two_views band");
        // Rays of opposite views cancel in the middle of the band.
        let back = "{ position = [0, 2, 6], look_at = [0, 2, 12], h_fov = 60, v_fov = 45 }";
        let front = "{ position = [0, 2, 6], look_at = [0, 2, 0], h_fov = 60, v_fov = 45 }";
        error_at(&format!("grid = 2\nview = \"two_views\"\nfirst = {front}\nsecond = {back}\nband = [0.0, 1.0]\n"), 1, 1, "has no ray");
    }
}
