//! `grid = N` (or `[columns, rows]`) in a trilinear `[projection]`: a regular screen grid of
//! projection triangles
//! over a base given by two control surfaces (`near`, `far`) or by a visualisation surface
//! or a view through a ball (`view`); with `exact = true` a view through a ball is the exact
//! view the grid samples instead: see scenes/README.md.

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::control_surface::surface;
use super::projection_table::Required;
use super::raw::{Numbers, RawCamera};
use super::source::Source;
use crate::error::{Error, Result};
use crate::projection::trilinear_builders::{
    between_surfaces, screen_grid_cells, BallOptic, BallView, DetailInContext, FocusView,
    GridCamera, TwoViews, MAX_GRID_CELLS,
};
use crate::projection::{CameraFrame, ProjectionSpec};

/// The views `view` may name, with the keys (besides `grid` and `view`) each takes.
const VIEWS: [(&str, &[&str]); 4] = [
    (
        "detail_in_context",
        &[
            "camera",
            "focus",
            "inset",
            "magnification",
            "focus_view",
            "converge",
        ],
    ),
    ("two_views", &["first", "second", "band"]),
    (
        "sphere_mirror",
        &["camera", "sphere", "second_sphere", "exact"],
    ),
    ("sphere_glass", &["camera", "sphere", "ior", "exact"]),
];

/// The focus views of `detail_in_context` (`focus_view`).
const FOCUS_VIEWS: [&str; 2] = ["orthographic", "inverse_perspective"];

/// Keys of a grid over two control surfaces (besides `grid`).
const SURFACE_KEYS: [&str; 2] = ["near", "far"];

/// The projection of a trilinear projection table that has `grid`: its mesh, or with
/// `exact = true` the exact view through a ball.
pub(super) fn convert(required: &Required, cells: &Spanned<Numbers>) -> Result<ProjectionSpec> {
    let src = required.src;
    let raw = required.raw();
    let present: Vec<_> = raw
        .present_keys()
        .into_iter()
        .filter(|(key, _)| *key != "grid" && *key != "view")
        .collect();
    let at_table = |e: Error| src.error(&required.table.span(), e.message);
    let [columns, rows] = grid_cells(required.src, cells)?;
    let mut exact = None;
    let mesh = match &raw.view {
        None => {
            src.reject_foreign_key(present, &SURFACE_KEYS, "grids over surfaces (no `view`)")?;
            let near = surface(src, required.get(&raw.near, "near")?, "near")?;
            let far = surface(src, required.get(&raw.far, "far")?, "far")?;
            screen_grid_cells(columns, rows, between_surfaces(&near, &far))
        }
        Some(view) => {
            let name = view.get_ref().as_str();
            let Some((_, keys)) = VIEWS.iter().find(|(n, _)| *n == name) else {
                let names: Vec<_> = VIEWS.iter().map(|(n, _)| *n).collect();
                return Err(src.unknown(&view.span(), "view", name, &names));
            };
            src.reject_foreign_key(present, keys, &format!("view \"{name}\""))?;
            match name {
                "detail_in_context" => {
                    let surface = detail_in_context(required)?;
                    screen_grid_cells(columns, rows, |s| surface.vertex(s))
                }
                "two_views" => {
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
                    screen_grid_cells(columns, rows, |s| surface.vertex(s))
                }
                _ => {
                    let view = ball_view(required, name == "sphere_glass")?;
                    if raw.exact.as_ref().is_some_and(|e| *e.get_ref()) {
                        exact = Some(view);
                    }
                    screen_grid_cells(columns, rows, |s| view.vertex(s))
                }
            }
        }
    };
    // The cells were checked above: what remains is the base's.
    let mesh = mesh.map_err(at_table)?;
    // The grid is built with `exact` too: its size is checked the same way.
    Ok(match exact {
        Some(view) => ProjectionSpec::ExactBall(view),
        None => ProjectionSpec::Trilinear(mesh),
    })
}

/// The cells of `grid`: one whole number `n` (n x n cells) or `[columns, rows]`, each from 1
/// to [`MAX_GRID_CELLS`], refused at the value's span otherwise.
fn grid_cells(src: &Source, cells: &Spanned<Numbers>) -> Result<[u32; 2]> {
    let refuse = |what: String| src.error(&cells.span(), what);
    let counts = match cells.get_ref().as_slice() {
        [n] => [*n, *n],
        [columns, rows] => [*columns, *rows],
        other => {
            return Err(refuse(format!(
                "`grid` is a number of cells N or [columns, rows], got {} numbers",
                other.len()
            )))
        }
    };
    let mut out = [0; 2];
    for (slot, n) in out.iter_mut().zip(counts) {
        if n.fract() != 0.0 || !(1.0..=f64::from(MAX_GRID_CELLS)).contains(&n) {
            return Err(refuse(format!(
                "grid must have 1..={MAX_GRID_CELLS} cells per side (whole numbers), got {n}"
            )));
        }
        *slot = n as u32;
    }
    Ok(out)
}

/// The surface of `view = "detail_in_context"`: `camera`, `focus`, `inset`,
/// `magnification`, and `focus_view` with its `converge`.
fn detail_in_context(required: &Required) -> Result<DetailInContext> {
    let (src, raw) = (required.src, required.raw());
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
    let surface =
        DetailInContext::new(camera, focus, inset, magnification, distance).map_err(|e| {
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
    let inverse = match &raw.focus_view {
        None => false,
        Some(v) => match v.get_ref().as_str() {
            "orthographic" => false,
            "inverse_perspective" => true,
            other => return Err(src.unknown(&v.span(), "focus_view", other, &FOCUS_VIEWS)),
        },
    };
    match (&raw.converge, inverse) {
        (Some(given), false) => Err(src.error(
            &given.span(),
            "`converge` is the point an inverse-perspective focus converges on: it needs \
             focus_view = \"inverse_perspective\"",
        )),
        (None, false) => Ok(surface),
        (_, true) => {
            let given = required.get(&raw.converge, "converge")?;
            let converge = src.dvec3(given, "converge")?;
            surface
                .with_focus_view(FocusView::InversePerspective { converge })
                .map_err(|e| src.error(&given.span(), e.message))
        }
    }
}

/// The view of `view = "sphere_mirror"` (or `"sphere_glass"` when `glass`): `camera`,
/// `sphere = { center, radius }` and, for a mirror, `second_sphere`, for glass, `ior`
/// (default 1.5).
fn ball_view(required: &Required, glass: bool) -> Result<BallView> {
    let (src, raw) = (required.src, required.raw());
    let table = required.get(&raw.camera, "camera")?;
    let (camera, _) = camera(src, table)?;
    let sphere = required.get(&raw.sphere, "sphere")?;
    let center = src.dvec3(&sphere.get_ref().center, "center")?;
    let radius = src.number(&sphere.get_ref().radius, "radius")?;
    let optic = if glass {
        let ior = raw.ior.as_ref().map_or(Ok(1.5), |i| src.number(i, "ior"))?;
        BallOptic::Glass { ior }
    } else {
        BallOptic::Mirror
    };
    let view = BallView::new(camera, center, radius, optic).map_err(|e| {
        let at = if e.message.starts_with("ior") {
            raw.ior
                .as_ref()
                .map_or(required.table.span(), Spanned::span)
        } else if e.message.starts_with("the ball needs") {
            sphere.span()
        } else {
            table.span()
        };
        src.error(&at, e.message)
    })?;
    let Some(second) = &raw.second_sphere else {
        return Ok(view);
    };
    let center = src.dvec3(&second.get_ref().center, "center")?;
    let radius = src.number(&second.get_ref().radius, "radius")?;
    view.with_second_ball(center, radius)
        .map_err(|e| src.error(&second.span(), e.message))
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
        // Columns x rows: 6 x 3 vertices, the last at the screen's corner.
        let m = mesh(&format!("grid = [5, 2]\n{SURFACES}"));
        assert_eq!((m.points.len(), m.triangles.len()), (18, 20));
        assert_eq!(m.screen[17], DVec2::ONE);
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

    /// A pinhole 3 from a unit ball at (0, 1, 0) (angular radius 19.5 degrees) whose view's
    /// corners are 12.4 degrees off its axis.
    const BALL_CAMERA: &str =
        "{ position = [0, 1, 3], look_at = [0, 1, 0], h_fov = 20, v_fov = 15 }";
    const SPHERE: &str = "sphere = { center = [0, 1, 0], radius = 1.0 }";

    #[test]
    fn grid_views_through_a_ball() {
        let m = mesh(&format!(
            "grid = 4\nview = \"sphere_mirror\"\ncamera = {BALL_CAMERA}\n{SPHERE}\n"
        ));
        assert_eq!((m.points.len(), m.triangles.len()), (25, 32));
        for (p, n) in m.points.iter().zip(&m.normals) {
            assert!(((*p - DVec3::Y).length() - 1.0).abs() < 1e-12);
            assert!((n.length() - 1.0).abs() < 1e-12);
        }
        // The central ray meets the ball head on and comes straight back.
        assert!((m.points[12] - DVec3::new(0.0, 1.0, 1.0)).length() < 1e-12);
        assert!((m.normals[12] - DVec3::Z).length() < 1e-12);
        // Glass: the central ray goes straight through and leaves at the far side.
        let m = mesh(&format!(
            "grid = 4\nview = \"sphere_glass\"\ncamera = {BALL_CAMERA}\n{SPHERE}\nior = 1.6\n"
        ));
        assert!((m.points[12] - DVec3::new(0.0, 1.0, -1.0)).length() < 1e-12);
        assert!((m.normals[12] - DVec3::NEG_Z).length() < 1e-12);
        // `exact = true`: the view itself, not its grid.
        let text = format!(
            "[projection]\ntype = \"trilinear\"\ngrid = 4\nview = \"sphere_glass\"\n\
             camera = {BALL_CAMERA}\n{SPHERE}\nexact = true\n"
        );
        let scene = parse(&text, Path::new("dir/s.toml")).unwrap();
        assert!(matches!(scene.projection, ProjectionSpec::ExactBall(_)));
        assert_eq!(scene.projection.kind(), "trilinear");
        let exact = scene.projection.build(32, 24).unwrap();
        assert!(exact.trilinear().is_none() && exact.ray(DVec2::new(16.0, 12.0)).is_some());
    }

    #[test]
    fn inverse_perspective_focus() {
        let camera = "{ position = [0, 2, 6], look_at = [0, 1, 0], h_fov = 60, v_fov = 45 }";
        let converge = DVec3::new(0.0, 1.0, -2.0);
        let m = mesh(&format!(
            "grid = 6\nview = \"detail_in_context\"\ncamera = {camera}\n\
             focus_view = \"inverse_perspective\"\nconverge = [0, 1, -2]\n"
        ));
        // The focus centre (vertex 24) looks at the convergence point.
        let to = converge - m.points[24];
        assert!(to.cross(m.normals[24]).length() < 1e-12 * to.length());
        assert!(to.dot(m.normals[24]) > 0.0);
        let ortho = mesh(&format!(
            "grid = 6\nview = \"detail_in_context\"\ncamera = {camera}\nfocus_view = \"orthographic\"\n"
        ));
        assert_eq!(
            ortho,
            mesh(&format!(
                "grid = 6\nview = \"detail_in_context\"\ncamera = {camera}\n"
            ))
        );
    }

    #[test]
    fn view_errors_are_positioned() {
        let mirror = |rest: &str| {
            format!("grid = 2\nview = \"sphere_mirror\"\ncamera = {BALL_CAMERA}\n{rest}")
        };
        let glass = |rest: &str| {
            format!("grid = 2\nview = \"sphere_glass\"\ncamera = {BALL_CAMERA}\n{SPHERE}\n{rest}")
        };
        error_at(&mirror(""), 1, 1, "needs `sphere`");
        error_at(
            &mirror(&format!("{SPHERE}\nior = 1.5\n")),
            7,
            7,
            "`ior` is not a parameter of view \"sphere_mirror\"",
        );
        error_at(&glass("ior = 0.5\n"), 7, 7, "ior must be at least 1");
        error_at(
            &mirror(&format!(
                "{SPHERE}\nsecond_sphere = {{ center = [1.5, 1, 0], radius = 1.0 }}\n"
            )),
            7,
            17,
            "overlaps the first",
        );
        error_at(
            &glass("second_sphere = { center = [0, 1, 9], radius = 1.0 }\n"),
            7,
            17,
            "`second_sphere` is not a parameter of view \"sphere_glass\"",
        );
        error_at(
            &mirror("sphere = { center = [0, 1, 0], radius = -1.0 }\n"),
            6,
            10,
            "positive radius",
        );
        let ball = |camera: &str| {
            format!("grid = 2\nview = \"sphere_mirror\"\ncamera = {camera}\n{SPHERE}\n")
        };
        error_at(
            &ball("{ position = [0, 1, 3], look_at = [0, 1, 0], h_fov = 60, v_fov = 45 }"),
            5,
            10,
            "misses the ball",
        );
        error_at(
            &ball("{ position = [0, 1, 0.5], look_at = [0, 1, 0], h_fov = 20, v_fov = 15 }"),
            5,
            10,
            "inside the ball",
        );
        error_at(
            &ball("{ position = [0, 1, 3], look_at = [0, 1, 0], width = 1, height = 1 }"),
            5,
            10,
            "needs a pinhole camera",
        );
        error_at(
            &format!("grid = 2\nview = \"two_views\"\nfirst = {BALL_CAMERA}\nsecond = {BALL_CAMERA}\nexact = true\n"),
            7,
            9,
            "`exact` is not a parameter of view \"two_views\"",
        );
        let detail = |rest: &str| {
            format!("grid = 2\nview = \"detail_in_context\"\ncamera = {{ position = [0, 2, 6], look_at = [0, 1, 0], h_fov = 60, v_fov = 45 }}\n{rest}")
        };
        error_at(
            &detail("focus_view = \"fisheye\"\n"),
            6,
            14,
            "unknown focus_view \"fisheye\"",
        );
        error_at(
            &detail("converge = [0, 1, -2]\n"),
            6,
            12,
            "needs focus_view = \"inverse_perspective\"",
        );
        error_at(
            &detail("focus_view = \"inverse_perspective\"\n"),
            1,
            1,
            "needs `converge`",
        );
        error_at(
            &detail("focus_view = \"inverse_perspective\"\nconverge = [0, 2, 6]\n"),
            7,
            12,
            "beyond the base plane",
        );
    }

    #[test]
    fn grid_errors_are_positioned() {
        error_at("grid = 0\nnear = { surface = \"point\", point = [0, 0, 0] }\nfar = { surface = \"point\", point = [0, 0, 1] }\n", 3, 8, "1..=256");
        let points = "near = { surface = \"point\", point = [0, 0, 0] }\nfar = { surface = \"point\", point = [0, 0, 1] }\n";
        error_at(&format!("grid = [20, 0]\n{points}"), 3, 8, "got 0");
        error_at(&format!("grid = 2.5\n{points}"), 3, 8, "whole numbers");
        error_at(
            &format!("grid = [2, 3, 4]\n{points}"),
            3,
            8,
            "[columns, rows]",
        );

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
