//! The handles of a projection: named points a person drags, in the volume view (world
//! points) or over the image (image points), and the projection keys each one edits.
//!
//! Every handle is a value of the scene file's `[projection]` table, so a drag is an edit of
//! the file's text like `set KEY VALUE`: the edited projection is built from the text, an
//! edit that does not build is refused (the last valid projection kept), and `save` writes
//! exactly what is shown. The names (docs/viewer.md, "Handles") are stable for a scene
//! file: they follow its keys, not the order handles are drawn in.
//!
//! | name | point | edits |
//! | --- | --- | --- |
//! | `position`, `look_at` | the camera frame's points | that key |
//! | `S.center`, `S.corner`, `S.point`, `S.start`, `S.end` | a surface's points (S = `near`, `far`, `surface.K` for `surfaces[K]`) | that key of the surface |
//! | `S.u`, `S.v` | `center + u_axis` (`corner + u_edge`), `center + v_axis` (`corner + v_edge`) | `u_axis` / `v_axis` (`u_edge` / `v_edge`) |
//! | `S.corner.K` | corner K of a `bilinear` surface | `corners[K]` |
//! | `S.R.C` | control point of row R, column C of a `bezier` / `bspline` patch | `control[R][C]` |
//! | `projector.C.R.start`, `projector.C.R.end` | node (column C, row R) of a projector grid | that node's `start` / `end` in `projectors.projector` (the entry is added when missing) |
//! | `fov`, `h_fov`, `v_fov` | the point at half the angle right of (`v_fov`: above) a preset's view axis, at the look-at distance | the angle: twice that of the dragged point, clamped to the preset's range (module `ranges`) |
//! | `width` | half the width right of the look-at point (orthographic, oblique, pushbroom presets; axonometric: across its turned view), of the eye on the image plane (glc) | twice the dragged point's distance right of the axis |
//! | `clip.near`, `clip.far`, `transition`, `transitions.K`, `z_near`, `z_far` | the point at that distance along the view axis | the dragged point's distance along the axis |
//! | `path.K` | point K of an mcop camera path | that point |
//! | `pole`, `center`, `radius` | over the image: the occlusion pole, the magnifier's centre and the point of its circle right of it | u right, v up (`radius`: by the shorter image side) |
//! | `outline.K`, `profile.K` (`outline.I.K`, `profile.I.K` in `outlines[I]`, `profiles[I]`) | over the image: vertex K of a panorama's `points` outline (at the column of its arc-length fraction) or profile (at the row of its fraction) | that vertex: it turns about the eye, keeping its length, to the direction of the curve's point under the pointer |
//! | `rect.corner.K` | corner K (0 bottom left, counter-clockwise) of `perspective_rect`, over the image | its two numbers |
//! | `rect.center` | the rectangle's centre, over the image | all four numbers |
//! | `shift`, `shear`, `twist`, `converge`, `slit_distance`, `fovs.K`, `generators.K.start` / `.end`, `directions.K`, `strength`, `magnification` | the preset keys that shape the projectors otherwise (module `preset_shape`) | that key |
//! | `azimuth`, `elevation`, `corner_radius`, the mcop's `v_fov`, `deep.K.center` / `.width` / `.fov` | the preset keys whose drags are clamped to the key's valid range (module `ranged`) | that key |
//!
//! Nodes of a grid with `fit` or `aim` are placed before the fit and the aims (the order the
//! scene format runs them in), so a fit may move a dragged node again.

mod preset_shape;
mod ranged;

use std::sync::Arc;

use flexcam::calibrate::build_flexible;
use flexcam::projection::flexible::{
    PanoramaShape, Preset, PresetSpec, Reparam, Volume, VolumeSource,
};
use flexcam::projection::{CameraBasis, CameraFrame, ProjectionSpec};
use flexcam::scene::file::edit::float_array;
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};
use toml_edit::{InlineTable, Item, Value};

use crate::session::Session;

/// Where a handle is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    /// A world point, dragged in the volume view.
    World(DVec3),
    /// A continuous pixel position of the image (x right, y down), dragged over the image.
    Image(DVec2),
}

/// A draggable point of the projection.
#[derive(Debug, Clone, PartialEq)]
pub struct Handle {
    /// The stable name (`near.center`, `projector.2.1.end`, `rect.corner.3`, ...).
    pub name: String,
    /// Where it is now.
    pub place: Place,
    /// For points of a grid (a control net, a projector grid's starts or ends): the grid's
    /// name and the point's (row, column), so a view can draw the net's lines.
    pub net: Option<(String, usize, usize)>,
    edit: Edit,
}

/// A step into a value: a key of an inline table or an index of an array.
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// A value of the projection table: a dotted key through its tables, then steps into the
/// value (arrays and the inline tables in them).
#[derive(Debug, Clone, PartialEq)]
struct ValuePath {
    key: String,
    steps: Vec<Step>,
}

impl ValuePath {
    fn key(key: &str) -> ValuePath {
        ValuePath {
            key: key.to_string(),
            steps: Vec::new(),
        }
    }

    /// The path one key further (a dotted key while no array has been entered).
    fn child(&self, key: &str) -> ValuePath {
        if self.steps.is_empty() {
            ValuePath::key(&format!("{}.{key}", self.key))
        } else {
            self.with(Step::Key(key.to_string()))
        }
    }

    fn index(&self, index: usize) -> ValuePath {
        self.with(Step::Index(index))
    }

    fn with(&self, step: Step) -> ValuePath {
        let mut path = self.clone();
        path.steps.push(step);
        path
    }

    fn get<'s>(&self, session: &'s Session) -> Option<&'s Value> {
        self.steps
            .iter()
            .try_fold(session.value(&self.key)?, |value, step| match step {
                Step::Key(key) => value.as_inline_table()?.get(key),
                Step::Index(index) => value.as_array()?.get(*index),
            })
    }

    /// The edit setting the value at this path to `new` (its decoration kept): the key and
    /// the whole new value under it.
    fn set(&self, session: &Session, new: Value) -> Result<(String, Value)> {
        let missing = || Error::new(format!("no value at `{}`", self.key));
        let mut root = session.value(&self.key).ok_or_else(missing)?.clone();
        let mut value = &mut root;
        for step in &self.steps {
            value = match step {
                Step::Key(key) => value.as_inline_table_mut().and_then(|t| t.get_mut(key)),
                Step::Index(index) => value.as_array_mut().and_then(|a| a.get_mut(*index)),
            }
            .ok_or_else(missing)?;
        }
        replace(value, new);
        Ok((self.key.clone(), root))
    }
}

/// Replaces `old` by `new`, keeping `old`'s decoration (the spaces around it).
fn replace(old: &mut Value, mut new: Value) {
    *new.decor_mut() = old.decor().clone();
    *old = new;
}

/// What a drag of a handle edits.
#[derive(Debug, Clone, PartialEq)]
enum Edit {
    /// A 3-vector that is the point.
    Point(ValuePath),
    /// A 3-vector that is the point's offset from `base`.
    Offset { path: ValuePath, base: DVec3 },
    /// The start (or end) of projector-grid node (`col`, `row`).
    Node { col: usize, row: usize, end: bool },
    /// A vertex (a 2-vector) of a panorama's outline (`outline`) or profile: it turns
    /// about the eye, keeping its length, to the direction of the curve's point (the
    /// blended outline, or profile, of `shape`) under the pointer.
    Curve {
        path: ValuePath,
        shape: Arc<PanoramaShape>,
        outline: bool,
    },
    /// A number, or numbers of an array, moved over the image: number i grows by f dx for
    /// each (i, f) of `x`, by f dy for each of `y`.
    Image {
        path: ValuePath,
        x: Vec<(usize, f64)>,
        y: Vec<(usize, f64)>,
    },
    /// A number that is `factor` times the point's distance from `origin` along `axis`
    /// (unit).
    Along {
        path: ValuePath,
        origin: DVec3,
        axis: DVec3,
        factor: f64,
    },
    /// An angle in degrees: twice the point's angle from `forward` towards `axis` (unit,
    /// perpendicular), seen from `origin`.
    Angle {
        path: ValuePath,
        origin: DVec3,
        axis: DVec3,
        forward: DVec3,
    },
    /// A preset key that shapes the projectors otherwise (module `preset_shape`).
    Shape {
        path: ValuePath,
        shape: preset_shape::Shape,
    },
    /// A number made by a rule of module `ranged`.
    Ranged { path: ValuePath, rule: ranged::Rule },
    /// The number `edit` makes, clamped to `range` (the key's valid range).
    Clamped { edit: Box<Edit>, range: [f64; 2] },
}

/// The numbers of a numeric array value.
fn numbers(value: &Value) -> Option<Vec<f64>> {
    value
        .as_array()?
        .iter()
        .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
        .collect()
}

fn vector(value: &Value) -> Option<DVec3> {
    <[f64; 3]>::try_from(numbers(value)?).ok().map(DVec3::from)
}

/// Every handle of `session`'s projection, in a fixed order: camera frame, surfaces,
/// projector grid, preset keys, panorama vertices, perspective rectangle.
pub fn handles(session: &Session) -> Vec<Handle> {
    let mut out = Vec::new();
    for key in ["position", "look_at"] {
        let path = ValuePath::key(key);
        out.extend(world(
            key.into(),
            path.get(session).and_then(vector),
            Edit::Point(path),
        ));
    }
    let table = session.document().get("projection");
    for name in ["near", "far"] {
        if table
            .and_then(|t| t.get(name))
            .is_some_and(Item::is_table_like)
        {
            surface(session, name, &ValuePath::key(name), &mut out);
        }
    }
    if let Some(surfaces) = session.value("surfaces").and_then(Value::as_array) {
        for k in 0..surfaces.len() {
            let path = ValuePath::key("surfaces").index(k);
            surface(session, &format!("surface.{k}"), &path, &mut out);
        }
    }
    grid_nodes(session, &mut out);
    preset_keys(session, &mut out);
    preset_shape::handles(session, &mut out);
    ranged::handles(session, &mut out);
    panorama_points(session, &mut out);
    rect(session, &mut out);
    out
}

/// The vertices of a shape-defined panorama's `points` outlines and profiles, over the
/// image where the panorama shows them: outline vertex K at the column of its arc-length
/// fraction (through the window of a panorama of less than a full turn) and the row of its
/// outline's `at` (the middle row for the single `outline`); profile vertex K at the row of
/// its fraction and the column of its profile's `at` (the middle column for the single
/// `profile`). None under a re-parameterisation other than the linear one.
fn panorama_points(session: &Session, out: &mut Vec<Handle>) {
    let ProjectionSpec::Flexible(spec) = session.spec() else {
        return;
    };
    let VolumeSource::Panorama(panorama) = &spec.source else {
        return;
    };
    if !matches!(spec.reparam, None | Some(Reparam::Linear)) {
        return;
    }
    let shape = &panorama.shape;
    let (width, height) = session.size();
    for (single, list, outline) in [
        ("outline", "outlines", true),
        ("profile", "profiles", false),
    ] {
        let attached = if outline {
            shape.outlines()
        } else {
            shape.profiles()
        };
        let mut curves = vec![(single.to_string(), ValuePath::key(single), 0.5)];
        let count = session
            .value(list)
            .and_then(Value::as_array)
            .map_or(0, |a| a.len());
        for (i, curve) in attached.iter().enumerate().take(count) {
            let path = ValuePath::key(list).index(i);
            curves.push((format!("{single}.{i}"), path, curve.at));
        }
        for (name, curve, at) in curves {
            let path = curve.child("points");
            let Some(points) = path.get(session).and_then(Value::as_array) else {
                continue;
            };
            let Some(points) = points
                .iter()
                .map(|p| numbers(p).and_then(|n| <[f64; 2]>::try_from(n).ok()))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            for (k, s) in vertex_fractions(&points, outline).into_iter().enumerate() {
                let uv = if outline {
                    DVec2::new(shape.column(s), at)
                } else {
                    DVec2::new(at, s)
                };
                out.push(Handle {
                    name: format!("{name}.{k}"),
                    place: Place::Image(image_pixel(uv, width, height)),
                    net: None,
                    edit: Edit::Curve {
                        path: path.index(k),
                        shape: Arc::clone(shape),
                        outline,
                    },
                });
            }
        }
    }
}

/// The arc-length fraction of each of `points` along their polyline (closed: back to the
/// first point), as the panorama's curves are parameterised; none for a polyline of zero
/// length (which does not build).
fn vertex_fractions(points: &[[f64; 2]], closed: bool) -> Vec<f64> {
    let point = |p: &[f64; 2]| DVec2::from_array(*p);
    let mut walked = vec![0.0];
    for w in points.windows(2) {
        walked.push(walked[walked.len() - 1] + (point(&w[1]) - point(&w[0])).length());
    }
    let mut total = walked[walked.len() - 1];
    if let (true, Some(first), Some(last)) = (closed, points.first(), points.last()) {
        total += (point(first) - point(last)).length();
    }
    if !(total > 0.0 && total.is_finite()) {
        return Vec::new();
    }
    walked.into_iter().map(|w| w / total).collect()
}

/// The pixel position (x right, y down) of image parameters `uv` (v up).
fn image_pixel(uv: DVec2, width: u32, height: u32) -> DVec2 {
    DVec2::new(uv.x * f64::from(width), (1.0 - uv.y) * f64::from(height))
}

/// The handles of a flexible projection's own keys, where the scene file sets them (names
/// as the keys): angles (`fov`, `h_fov`: the point at half the angle right of the view
/// axis; `v_fov`: above it; at the look-at distance from the eye), the `width` of the
/// orthographic, oblique and pushbroom presets (half of it right of the look-at point),
/// distances along the view axis (`clip.near`, `clip.far`, also of shape-defined
/// panoramas; `transition`, `transitions.K`; the ddoc's `z_near`, `z_far`), the mcop camera path's points (`path.K`), and
/// over the image the occlusion `pole`, the magnifier's `center` and `radius` (the point of
/// its circle right of the centre).
fn preset_keys(session: &Session, out: &mut Vec<Handle>) {
    let ProjectionSpec::Flexible(spec) = session.spec() else {
        return;
    };
    let preset = match &spec.source {
        VolumeSource::Preset(_) => session.value("preset").and_then(Value::as_str),
        VolumeSource::Panorama(_) => None,
        _ => return,
    };
    let number = |key: &str| {
        let value = session.value(key)?;
        value
            .as_float()
            .or_else(|| value.as_integer().map(|i| i as f64))
    };
    let (width, height) = session.size();
    let (w, h) = (f64::from(width), f64::from(height));
    if preset.is_some() {
        let count = session
            .value("path")
            .and_then(Value::as_array)
            .map_or(0, |a| a.len());
        for k in 0..count {
            let p = ValuePath::key("path").index(k);
            let at = p.get(session).and_then(vector);
            out.extend(world(format!("path.{k}"), at, Edit::Point(p)));
        }
        for key in ["pole", "center"] {
            let Some([u, v]) = session
                .value(key)
                .and_then(numbers)
                .and_then(|n| <[f64; 2]>::try_from(n).ok())
            else {
                continue;
            };
            let at = image_pixel(DVec2::new(u, v), width, height);
            out.push(Handle {
                name: key.into(),
                place: Place::Image(at),
                net: None,
                edit: Edit::Image {
                    path: ValuePath::key(key),
                    x: vec![(0, 1.0 / w)],
                    y: vec![(1, -1.0 / h)],
                },
            });
            if let (Some(radius), "center") = (number("radius"), key) {
                // The radius is a fraction of the shorter image side.
                let side = w.min(h);
                out.push(Handle {
                    name: "radius".into(),
                    place: Place::Image(at + DVec2::X * radius * side),
                    net: None,
                    edit: Edit::Image {
                        path: ValuePath::key("radius"),
                        x: vec![(0, 1.0 / side)],
                        y: Vec::new(),
                    },
                });
            }
        }
    }
    // The mcop columns look along their own directions from the path, the axonometric and
    // general linear cameras along their own keys', not along the frame's view axis.
    if matches!(preset, Some("mcop" | "axonometric" | "glc")) {
        if let VolumeSource::Preset(p) = &spec.source {
            out.extend(own_view_width(p));
        }
        return;
    }
    let Ok(frame) = session.camera() else {
        return;
    };
    let Ok(basis) = CameraBasis::new(&frame) else {
        return;
    };
    let origin = basis.origin;
    let distance = (frame.look_at - frame.position).length();
    let along = |name: &str, path: ValuePath, at: DVec3, axis: DVec3, factor: f64| Handle {
        name: name.into(),
        place: Place::World(at),
        net: None,
        edit: Edit::Along {
            path,
            origin,
            axis,
            factor,
        },
    };
    let forward = basis.forward;
    if let Some(clip) = session.value("clip").and_then(numbers) {
        for (i, (end, d)) in ["near", "far"].into_iter().zip(clip).enumerate() {
            let path = ValuePath::key("clip").index(i);
            out.push(along(
                &format!("clip.{end}"),
                path,
                origin + forward * d,
                forward,
                1.0,
            ));
        }
    }
    let Some(preset) = preset else {
        return;
    };
    // (Each preset has at most one of these: the ddoc its two bend distances.)
    for key in ["transition", "z_near", "z_far"] {
        if let Some(t) = number(key) {
            let path = ValuePath::key(key);
            out.push(along(key, path, origin + forward * t, forward, 1.0));
        }
    }
    if let Some(list) = session.value("transitions").and_then(numbers) {
        for (k, t) in list.into_iter().enumerate() {
            let path = ValuePath::key("transitions").index(k);
            let name = format!("transitions.{k}");
            out.push(along(&name, path, origin + forward * t, forward, 1.0));
        }
    }
    if let (Some(extent), "orthographic" | "oblique" | "pushbroom") = (number("width"), preset) {
        let at = origin + forward * distance + basis.right * extent / 2.0;
        out.push(width_handle(at, origin, basis.right));
    }
    for (key, axis) in [
        ("fov", basis.right),
        ("h_fov", basis.right),
        ("v_fov", basis.up),
    ] {
        let Some(angle) = number(key) else {
            continue;
        };
        let (sin, cos) = (angle.to_radians() / 2.0).sin_cos();
        let edit = Edit::Angle {
            path: ValuePath::key(key),
            origin,
            axis,
            forward,
        };
        out.push(Handle {
            name: key.into(),
            place: Place::World(origin + distance * (axis * sin + forward * cos)),
            net: None,
            edit: clamp_angle(edit, Some(preset), key),
        });
    }
}

/// The `width` handle at `at`, half the width right of a view's axis through `origin`
/// (`right` unit): the width is twice the dragged point's distance right of the axis.
fn width_handle(at: DVec3, origin: DVec3, right: DVec3) -> Handle {
    Handle {
        name: "width".into(),
        place: Place::World(at),
        net: None,
        edit: Edit::Along {
            path: ValuePath::key("width"),
            origin,
            axis: right,
            factor: 2.0,
        },
    }
}

/// The `width` handle of the presets that look along their own keys' directions: the
/// axonometric view (half the width right of `look_at` across the view from the eye turned
/// by `azimuth` and `elevation`, up +y, as the preset places it) and the general linear
/// camera (half the width right of the eye on its image plane, local depth 0, where the
/// image is `width` wide). `None` for the other presets or a degenerate frame.
fn own_view_width(preset: &PresetSpec) -> Option<Handle> {
    let frame = &preset.frame;
    match preset.preset {
        Preset::Axonometric {
            width,
            azimuth,
            elevation,
        } => {
            let (sin_a, cos_a) = azimuth.to_radians().sin_cos();
            let (sin_e, cos_e) = elevation.to_radians().sin_cos();
            let towards_eye = DVec3::new(cos_e * sin_a, sin_e, cos_e * cos_a);
            let distance = (frame.position - frame.look_at).length();
            let turned = CameraFrame {
                position: frame.look_at + distance * towards_eye,
                look_at: frame.look_at,
                up: DVec3::Y,
            };
            let b = CameraBasis::new(&turned).ok()?;
            let at = frame.look_at + b.right * width / 2.0;
            Some(width_handle(at, b.origin, b.right))
        }
        Preset::Glc { width, .. } => {
            let b = CameraBasis::new(frame).ok()?;
            Some(width_handle(
                b.origin + b.right * width / 2.0,
                b.origin,
                b.right,
            ))
        }
        _ => None,
    }
}

/// `edit` of angle key `key` of flexible `preset`, clamped to the range the scene loader
/// accepts ([`crate::ranges::angle`]): a drag past it stops at its end.
fn clamp_angle(edit: Edit, preset: Option<&str>, key: &str) -> Edit {
    match crate::ranges::angle("flexible", preset, key) {
        Some(range) => Edit::Clamped {
            edit: Box::new(edit),
            range,
        },
        None => edit,
    }
}

/// The handles of the surface table at `path`, named `name.*`.
fn surface(session: &Session, name: &str, path: &ValuePath, out: &mut Vec<Handle>) {
    let at = |key: &str| path.child(key).get(session).and_then(vector);
    for key in ["center", "corner", "point", "start", "end"] {
        if at(key).is_some() {
            out.extend(world(
                format!("{name}.{key}"),
                at(key),
                Edit::Point(path.child(key)),
            ));
        }
    }
    for (base, axis, handle) in [
        ("center", "u_axis", "u"),
        ("center", "v_axis", "v"),
        ("corner", "u_edge", "u"),
        ("corner", "v_edge", "v"),
    ] {
        if let (Some(b), Some(a)) = (at(base), at(axis)) {
            let edit = Edit::Offset {
                path: path.child(axis),
                base: b,
            };
            out.extend(world(format!("{name}.{handle}"), Some(b + a), edit));
        }
    }
    let corners = path.child("corners");
    if let Some(count) = corners
        .get(session)
        .and_then(Value::as_array)
        .map(|a| a.len())
    {
        for k in 0..count {
            let p = corners.index(k);
            let h = world(
                format!("{name}.corner.{k}"),
                p.get(session).and_then(vector),
                Edit::Point(p),
            );
            out.extend(h);
        }
    }
    let control = path.child("control");
    let Some(rows) = control.get(session).and_then(Value::as_array) else {
        return;
    };
    for (r, row) in rows.iter().enumerate() {
        let columns = row.as_array().map_or(0, |a| a.len());
        for c in 0..columns {
            let p = control.index(r).index(c);
            let h = world(
                format!("{name}.{r}.{c}"),
                p.get(session).and_then(vector),
                Edit::Point(p),
            );
            out.extend(h.map(|h| Handle {
                net: Some((name.to_string(), r, c)),
                ..h
            }));
        }
    }
}

/// A world handle at `at`; none where the value is not a 3-vector.
fn world(name: String, at: Option<DVec3>, edit: Edit) -> Option<Handle> {
    Some(Handle {
        name,
        place: Place::World(at?),
        net: None,
        edit,
    })
}

/// The nodes of a projector grid (`projectors`), where the projection is one.
fn grid_nodes(session: &Session, out: &mut Vec<Handle>) {
    let ProjectionSpec::Flexible(spec) = session.spec() else {
        return;
    };
    if !matches!(spec.source, VolumeSource::ProjectorGrid { .. }) {
        return;
    }
    let (width, height) = session.size();
    let Ok((flexible, _)) = build_flexible(spec, width, height) else {
        return;
    };
    let Volume::Grid(volume) = flexible.volume() else {
        return;
    };
    let grid = &volume.grid;
    let (cols, rows) = grid.size();
    for (end, points) in [(false, grid.starts()), (true, grid.ends())] {
        let which = if end { "end" } else { "start" };
        for row in 0..rows {
            for col in 0..cols {
                out.push(Handle {
                    name: format!("projector.{col}.{row}.{which}"),
                    place: Place::World(points[row * cols + col]),
                    net: Some((format!("projector.{which}"), row, col)),
                    edit: Edit::Node { col, row, end },
                });
            }
        }
    }
}

/// The corners and centre of `perspective_rect`, over the image.
fn rect(session: &Session, out: &mut Vec<Handle>) {
    let Some(r) = session.value("perspective_rect").and_then(numbers) else {
        return;
    };
    let Ok(r) = <[f64; 4]>::try_from(r) else {
        return;
    };
    let (width, height) = session.size();
    let (du, dv) = (1.0 / f64::from(width), -1.0 / f64::from(height));
    let edit = |u: &[usize], v: &[usize]| Edit::Image {
        path: ValuePath::key("perspective_rect"),
        x: u.iter().map(|&i| (i, du)).collect(),
        y: v.iter().map(|&i| (i, dv)).collect(),
    };
    let corners = [(0, 1), (2, 1), (2, 3), (0, 3)];
    for (k, (u, v)) in corners.into_iter().enumerate() {
        out.push(Handle {
            name: format!("rect.corner.{k}"),
            place: Place::Image(image_pixel(DVec2::new(r[u], r[v]), width, height)),
            net: None,
            edit: edit(&[u], &[v]),
        });
    }
    let centre = DVec2::new((r[0] + r[2]) / 2.0, (r[1] + r[3]) / 2.0);
    out.push(Handle {
        name: "rect.center".into(),
        place: Place::Image(image_pixel(centre, width, height)),
        net: None,
        edit: edit(&[0, 2], &[1, 3]),
    });
}

impl Handle {
    /// The edits (key, new value) that move this handle of `session`'s projection by
    /// `delta`: world units for a world handle, pixels (x right, y down) for an image one.
    /// Errors when the value to edit is gone (the projection changed since the handle was
    /// listed).
    pub fn edits(&self, session: &Session, delta: Place) -> Result<Vec<(String, Value)>> {
        if let (&Edit::Node { col, row, end }, Place::World(at), Place::World(d)) =
            (&self.edit, self.place, delta)
        {
            return Ok(vec![node_edit(session, col, row, end, at + d)]);
        }
        let (path, value) = self.value(&self.edit, session, delta)?;
        Ok(vec![path.set(session, value)?])
    }

    /// The error of a handle moved the wrong way (or whose value is gone).
    fn wrong(&self) -> Error {
        Error::new(format!(
            "handle `{}` is moved {}",
            self.name,
            match self.place {
                Place::World(_) => "in the world (the volume view)",
                Place::Image(_) => "over the image",
            }
        ))
    }

    /// The value `edit` (this handle's, or one it wraps) sets and its new value for a move
    /// by `delta`.
    fn value<'e>(
        &self,
        edit: &'e Edit,
        session: &Session,
        delta: Place,
    ) -> Result<(&'e ValuePath, Value)> {
        let wrong = || self.wrong();
        match (edit, self.place, delta) {
            (Edit::Point(path), Place::World(at), Place::World(d)) => {
                Ok((path, float_array(&(at + d).to_array())))
            }
            (Edit::Offset { path, base }, Place::World(at), Place::World(d)) => {
                let offset = at + d - *base;
                Ok((path, float_array(&offset.to_array())))
            }
            (
                Edit::Curve {
                    path,
                    shape,
                    outline,
                },
                Place::Image(at),
                Place::Image(d),
            ) => {
                let (width, height) = session.size();
                let pointer = at + d;
                let uv = DVec2::new(
                    pointer.x / f64::from(width),
                    1.0 - pointer.y / f64::from(height),
                );
                let toward = if *outline {
                    shape.outline(uv)
                } else {
                    shape.profile(uv)
                };
                let old = path.get(session).and_then(numbers).ok_or_else(wrong)?;
                let length = DVec2::new(old[0], old[1]).length();
                // Degenerate: the curve passes through the eye under the pointer.
                let direction = toward.try_normalize().ok_or_else(|| {
                    Error::new(format!(
                        "handle `{}`: the {} under the pointer is at the eye (no direction)",
                        self.name,
                        if *outline { "outline" } else { "profile" }
                    ))
                })?;
                let moved = direction * length;
                Ok((path, float_array(&moved.to_array())))
            }
            (Edit::Image { path, x, y }, Place::Image(_), Place::Image(d)) => {
                let value = path.get(session).ok_or_else(wrong)?;
                let scalar = value
                    .as_float()
                    .or_else(|| value.as_integer().map(|i| i as f64));
                let mut n = scalar
                    .map(|n| vec![n])
                    .or_else(|| numbers(value))
                    .ok_or_else(wrong)?;
                for &(i, f) in x {
                    n[i] += f * d.x;
                }
                for &(i, f) in y {
                    n[i] += f * d.y;
                }
                let new = match scalar {
                    Some(_) => Value::from(n[0]),
                    None => float_array(&n),
                };
                Ok((path, new))
            }
            (
                Edit::Along {
                    path,
                    origin,
                    axis,
                    factor,
                },
                Place::World(at),
                Place::World(d),
            ) => {
                let value = factor * (at + d - *origin).dot(*axis);
                Ok((path, Value::from(value)))
            }
            (
                Edit::Angle {
                    path,
                    origin,
                    axis,
                    forward,
                },
                Place::World(at),
                Place::World(d),
            ) => {
                let v = at + d - *origin;
                let angle = 2.0 * v.dot(*axis).atan2(v.dot(*forward)).to_degrees();
                Ok((path, Value::from(angle)))
            }
            (Edit::Shape { path, shape }, at, d) => {
                let old = path.get(session).ok_or_else(wrong)?;
                let value = shape.value(&self.name, old, moved(at, d).ok_or_else(wrong)?);
                Ok((path, value.ok_or_else(wrong)??))
            }
            (Edit::Ranged { path, rule }, at, d) => {
                let value = rule.value(&self.name, moved(at, d).ok_or_else(wrong)?);
                Ok((path, Value::from(value.ok_or_else(wrong)??)))
            }
            (Edit::Clamped { edit, range }, _, _) => {
                let (path, value) = self.value(edit, session, delta)?;
                let n = value.as_float().ok_or_else(wrong)?;
                // Not `f64::clamp`, which panics on a range made empty by the other numbers.
                Ok((path, Value::from(n.max(range[0]).min(range[1]))))
            }
            _ => Err(wrong()),
        }
    }
}

/// Where a handle at `at` moved by `d` goes; none when the move is not where it lives (the
/// world or the image).
fn moved(at: Place, d: Place) -> Option<Place> {
    match (at, d) {
        (Place::World(at), Place::World(d)) => Some(Place::World(at + d)),
        (Place::Image(at), Place::Image(d)) => Some(Place::Image(at + d)),
        _ => None,
    }
}

/// The edit of `projectors.projector` placing node (`col`, `row`)'s start (or end) at `at`:
/// its entry's key set, or a new entry `{ node = [col, row], start = [...] }` appended
/// (a comment after the last entry then follows the new one).
fn node_edit(session: &Session, col: usize, row: usize, end: bool, at: DVec3) -> (String, Value) {
    let key = if end { "end" } else { "start" };
    let mut entries = session
        .value("projectors.projector")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let node = |v: &Value| numbers(v) == Some(vec![col as f64, row as f64]);
    let point = float_array(&at.to_array());
    let entry = entries
        .iter_mut()
        .filter_map(Value::as_inline_table_mut)
        .find(|t| t.get("node").is_some_and(node));
    match entry {
        Some(table) => match table.get_mut(key) {
            Some(old) => replace(old, point),
            None => {
                table.insert(key, point);
            }
        },
        None => {
            let mut table = InlineTable::new();
            table.insert("node", Value::from_iter([col as i64, row as i64]));
            table.insert(key, point);
            // On a line of its own when the entries are (the last one's indentation).
            let mut entry = Value::InlineTable(table);
            let last = entries
                .iter()
                .last()
                .and_then(|v| v.decor().prefix()?.as_str());
            entry.decor_mut().set_prefix(match last {
                Some(prefix) if prefix.contains('\n') => prefix.to_string(),
                Some(_) => " ".to_string(),
                None => String::new(),
            });
            entries.push_formatted(entry);
        }
    }
    ("projectors.projector".into(), Value::Array(entries))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::scratch as session;

    fn names(list: &[Handle]) -> Vec<&str> {
        list.iter().map(|h| h.name.as_str()).collect()
    }

    fn find<'h>(handles: &'h [Handle], name: &str) -> &'h Handle {
        handles.iter().find(|h| h.name == name).unwrap()
    }

    const SURFACES: &str = "type = \"flexible\"\n\
        near = { surface = \"rectangle\", corner = [-0.5, -0.5, 1.0], u_edge = [1.0, 0.0, 0.0], v_edge = [0.0, 1.0, 0.0] }\n\
        far = { surface = \"bilinear\", corners = [[-2.0, -2.0, -3.0], [2.0, -2.0, -3.0],   [2.0, 2.0, -3.0], [-2.0, 2.0, -3.0]] } # far";

    #[test]
    fn surface_handles_are_named_after_their_keys_and_edit_them_in_place() {
        let (_dir, mut session) = session(SURFACES);
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "near.corner",
                "near.u",
                "near.v",
                "far.corner.0",
                "far.corner.1",
                "far.corner.2",
                "far.corner.3"
            ]
        );
        let u = find(&list, "near.u");
        assert_eq!(u.place, Place::World(DVec3::new(0.5, -0.5, 1.0)));
        // The u handle edits the edge vector, relative to the corner.
        let edits = u
            .edits(&session, Place::World(DVec3::new(0.0, 0.25, 0.0)))
            .unwrap();
        assert_eq!(edits.len(), 1);
        assert_eq!(edits[0].0, "near.u_edge");
        assert_eq!(numbers(&edits[0].1), Some(vec![1.0, 0.25, 0.0]));
        // A point inside an array: the array is rewritten with only that point changed.
        let before = session.document().to_string();
        let corner = find(&list, "far.corner.2");
        let edits = corner
            .edits(&session, Place::World(DVec3::new(0.0, 0.0, 0.5)))
            .unwrap();
        session.set_all(&edits).unwrap();
        assert_eq!(
            session.document().to_string(),
            before.replace("[2.0, 2.0, -3.0]", "[2.0, 2.0, -2.5]")
        );
        // An image move of a world handle is refused.
        let error = u.edits(&session, Place::Image(DVec2::ONE)).unwrap_err();
        assert!(error.to_string().contains("in the world"), "{error}");
    }

    #[test]
    fn projector_grid_nodes_edit_their_entries_or_add_one() {
        let (_dir, mut session) = session(
            "type = \"flexible\"\npreset = \"perspective\"\nposition = [0.0, 0.0, 3.0]\n\
             look_at = [0.0, 0.0, 0.0]\nfov = 60.0\nclip = [0.5, 10.0]\n\
             projectors = { size = [3, 3], projector = [{ node = [1, 1], end = [0.0, 0.2, -7.0] }] }",
        );
        let list = handles(&session);
        assert_eq!(
            list.iter()
                .filter(|h| h.name.starts_with("projector."))
                .count(),
            18
        );
        let centre_end = find(&list, "projector.1.1.end");
        assert_eq!(centre_end.place, Place::World(DVec3::new(0.0, 0.2, -7.0)));
        assert_eq!(centre_end.net, Some(("projector.end".into(), 1, 1)));
        let delta = Place::World(DVec3::new(0.5, 0.0, 0.0));
        session
            .set_all(&centre_end.edits(&session, delta).unwrap())
            .unwrap();
        let corner = find(&list, "projector.2.0.start").clone();
        let Place::World(start) = corner.place else {
            panic!()
        };
        session
            .set_all(&corner.edits(&session, delta).unwrap())
            .unwrap();
        let entries = session.value("projectors.projector").unwrap().to_string();
        let entries = entries.trim();
        let moved = float_array(&(start + DVec3::new(0.5, 0.0, 0.0)).to_array());
        assert_eq!(
            entries,
            format!(
                "[{{ node = [1, 1], end = [0.5, 0.2, -7.0] }}, {{ node = [2, 0], start = {moved} }}]"
            )
        );
        let list = handles(&session);
        assert_eq!(
            find(&list, "projector.2.0.start").place,
            Place::World(start + DVec3::new(0.5, 0.0, 0.0))
        );
    }

    #[test]
    fn the_perspective_rectangle_moves_over_the_image() {
        let (_dir, session) = session(
            "type = \"flexible\"\nposition = [0.0, 1.5, 0.0]\nlook_at = [0.0, 1.5, -1.0]\n\
             clip = [0.0, 60.0]\noutline = { shape = \"circle\" }\n\
             profile = { shape = \"arc\", elevation = [-90.0, 90.0] }\n\
             perspective_rect = [0.375, 0.2, 0.625, 0.8]",
        );
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "position",
                "look_at",
                "clip.near",
                "clip.far",
                "rect.corner.0",
                "rect.corner.1",
                "rect.corner.2",
                "rect.corner.3",
                "rect.center"
            ]
        );
        // Corner 0 is the bottom left: (u0, v0) at x = u0 * 40, y = (1 - v0) * 30.
        assert_eq!(
            find(&list, "rect.corner.0").place,
            Place::Image(DVec2::new(15.0, 24.0))
        );
        let edits = find(&list, "rect.center")
            .edits(&session, Place::Image(DVec2::new(4.0, -3.0)))
            .unwrap();
        let moved = numbers(&edits[0].1).unwrap();
        let expected = [0.375 + 0.1, 0.2 + 0.1, 0.625 + 0.1, 0.8 + 0.1];
        assert!(
            moved
                .iter()
                .zip(expected)
                .all(|(a, b)| (a - b).abs() < 1e-15),
            "{moved:?}"
        );
        let world = Place::World(DVec3::X);
        assert!(find(&list, "rect.corner.1").edits(&session, world).is_err());
    }

    #[test]
    fn outline_and_profile_vertices_sit_where_the_panorama_shows_them_and_turn_to_the_pointer() {
        // A diamond outline from behind the eye (fractions 0, 1/4, 1/2, 3/4: each side is as
        // long), and a second profile of two points in the front column.
        let (_dir, session) = session(
            "type = \"flexible\"\nposition = [0.0, 1.5, 0.0]\nlook_at = [0.0, 1.5, -1.0]\n\
             outline = { points = [[0.0, -1.0], [-1.0, 0.0], [0.0, 1.0], [1.0, 0.0]] }\n\
             profiles = [{ at = 0.0, shape = \"arc\" }, { at = 0.5, points = [[1.0, -1.0], [1.0, 1.0]] }]",
        );
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "position",
                "look_at",
                "outline.0",
                "outline.1",
                "outline.2",
                "outline.3",
                "profile.1.0",
                "profile.1.1"
            ]
        );
        // 40 x 30: the single outline on the middle row, vertex K at column K / 4.
        for (k, x) in [0.0, 10.0, 20.0, 30.0].into_iter().enumerate() {
            let at = find(&list, &format!("outline.{k}")).place;
            assert_eq!(at, Place::Image(DVec2::new(x, 15.0)), "outline.{k}");
        }
        // The profile at u = 1/2: its vertices at the bottom (v = 0) and top rows.
        assert_eq!(
            find(&list, "profile.1.0").place,
            Place::Image(DVec2::new(20.0, 30.0))
        );
        assert_eq!(
            find(&list, "profile.1.1").place,
            Place::Image(DVec2::new(20.0, 0.0))
        );
        // Outline vertex 1 dragged 5 pixels right: column 3/8, the diamond's point halfway
        // from (-1, 0) to (0, 1); the vertex turns to its direction, keeping its length 1
        // (the vertical part of the drag does not matter).
        let edits = find(&list, "outline.1")
            .edits(&session, Place::Image(DVec2::new(5.0, 4.0)))
            .unwrap();
        assert_eq!(edits[0].0, "outline.points");
        let moved = numbers(edits[0].1.as_array().unwrap().get(1).unwrap()).unwrap();
        let half = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (moved[0] + half).abs() < 1e-15 && (moved[1] - half).abs() < 1e-15,
            "{moved:?}"
        );
        // Profile vertex 0 of the second profile dragged up to the middle row: that
        // profile's point there is (1, 0); the vertex keeps its length sqrt 2.
        let edits = find(&list, "profile.1.0")
            .edits(&session, Place::Image(DVec2::new(0.0, -15.0)))
            .unwrap();
        assert_eq!(edits[0].0, "profiles");
        let profile = edits[0].1.as_array().unwrap().get(1).unwrap();
        let points = profile.as_inline_table().unwrap().get("points").unwrap();
        let moved = numbers(points.as_array().unwrap().get(0).unwrap()).unwrap();
        assert!(
            (moved[0] - 2f64.sqrt()).abs() < 1e-15 && moved[1].abs() < 1e-15,
            "{moved:?}"
        );
        // World moves are refused.
        let world = Place::World(DVec3::X);
        assert!(find(&list, "outline.0").edits(&session, world).is_err());
    }

    #[test]
    fn vertex_fractions_follow_arc_length_and_a_zero_length_curve_has_none() {
        let square = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]];
        assert_eq!(vertex_fractions(&square, true), [0.0, 0.25, 0.5, 0.75]);
        assert_eq!(
            vertex_fractions(&square, false),
            [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]
        );
        // Repeated points share a fraction; all in one point: no fractions.
        let repeated = [[1.0, 0.0], [1.0, 0.0], [1.0, 2.0]];
        assert_eq!(vertex_fractions(&repeated, false), [0.0, 0.0, 1.0]);
        assert!(vertex_fractions(&[[1.0, 1.0], [1.0, 1.0]], true).is_empty());
    }

    #[test]
    fn preset_angles_and_distances_move_with_their_points() {
        let (_dir, session) = session(
            "type = \"flexible\"\npreset = \"ortho_near_persp_far\"\n\
             position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n\
             fov = 60.0\ntransition = 2.0\nstyle = \"piecewise\"\nclip = [0.5, 10.0]",
        );
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "position",
                "look_at",
                "clip.near",
                "clip.far",
                "transition",
                "fov"
            ]
        );
        let at = |name: &str| match find(&list, name).place {
            Place::World(p) => p,
            Place::Image(_) => panic!("{name} is over the image"),
        };
        // Distances along the view axis (-z) from the eye at z = 3.
        assert_eq!(at("clip.near"), DVec3::new(0.0, 0.0, 2.5));
        assert_eq!(at("clip.far"), DVec3::new(0.0, 0.0, -7.0));
        assert_eq!(at("transition"), DVec3::new(0.0, 0.0, 1.0));
        // A drag's part across the axis is dropped: 1 further along it.
        let edits = find(&list, "clip.far")
            .edits(&session, Place::World(DVec3::new(0.3, 0.2, -1.0)))
            .unwrap();
        assert_eq!(edits[0].0, "clip");
        assert_eq!(numbers(&edits[0].1), Some(vec![0.5, 11.0]));
        // The fov point: 30 degrees right of the axis at the look-at distance 3.
        let fov = at("fov");
        let expected = DVec3::new(3.0 * 0.5, 0.0, 3.0 - 3.0 * 3f64.sqrt() / 2.0);
        assert!((fov - expected).length() < 1e-15, "{fov}");
        // Moved to 40 degrees right of the axis (at another distance): fov 80.
        let target = DVec3::new(0.0, 0.0, 3.0)
            + 2.0 * DVec3::new(40f64.to_radians().sin(), 0.0, -40f64.to_radians().cos());
        let edits = find(&list, "fov")
            .edits(&session, Place::World(target - fov))
            .unwrap();
        assert_eq!(edits[0].0, "fov");
        let angle = edits[0].1.as_float().unwrap();
        assert!((angle - 80.0).abs() < 1e-12, "{angle}");
    }

    #[test]
    fn the_ddoc_bend_distances_are_points_along_the_axis() {
        let (_dir, session) = session(
            "type = \"flexible\"\npreset = \"ddoc\"\n\
             position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n\
             fov = 60.0\nz_near = 2.0\nz_far = 4.0\nclip = [0.5, 10.0]",
        );
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "position",
                "look_at",
                "clip.near",
                "clip.far",
                "z_near",
                "z_far",
                "fov"
            ]
        );
        assert_eq!(
            find(&list, "z_far").place,
            Place::World(DVec3::new(0.0, 0.0, -1.0))
        );
        let edits = find(&list, "z_near")
            .edits(&session, Place::World(DVec3::new(0.4, 0.0, -0.5)))
            .unwrap();
        assert_eq!(edits[0].0, "z_near");
        assert_eq!(edits[0].1.as_float(), Some(2.5));
    }

    #[test]
    fn image_keys_of_presets_move_by_image_fractions() {
        let (_dir, session) = session(
            "type = \"flexible\"\npreset = \"magnifier\"\n\
             position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n\
             fov = 60.0\ncenter = [0.5, 0.5]\nradius = 0.2\nmagnification = 2.0",
        );
        let list = handles(&session);
        assert_eq!(
            names(&list),
            [
                "position",
                "look_at",
                "center",
                "radius",
                "fov",
                "magnification"
            ]
        );
        // 40 x 30: the centre at (20, 15), the radius 0.2 of the shorter side (30) right.
        assert_eq!(
            find(&list, "center").place,
            Place::Image(DVec2::new(20.0, 15.0))
        );
        assert_eq!(
            find(&list, "radius").place,
            Place::Image(DVec2::new(26.0, 15.0))
        );
        let edits = find(&list, "center")
            .edits(&session, Place::Image(DVec2::new(4.0, -3.0)))
            .unwrap();
        let moved = numbers(&edits[0].1).unwrap();
        assert!(
            (moved[0] - 0.6).abs() < 1e-15 && (moved[1] - 0.6).abs() < 1e-15,
            "{moved:?}"
        );
        let edits = find(&list, "radius")
            .edits(&session, Place::Image(DVec2::new(3.0, 5.0)))
            .unwrap();
        assert_eq!(edits[0].0, "radius");
        let radius = edits[0].1.as_float().unwrap();
        assert!((radius - 0.3).abs() < 1e-15, "{radius}");
    }
}
