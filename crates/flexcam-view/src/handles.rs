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
//! | `outline.K`, `profile.K` (`outline.I.K`, `profile.I.K` in `outlines[I]`, `profiles[I]`) | point K of a panorama's `points` outline (in the eye's horizontal plane) or profile (in the vertical half-plane ahead), at unit distance around the eye | that point; the drag moves it within its plane |
//! | `rect.corner.K` | corner K (0 bottom left, counter-clockwise) of `perspective_rect`, over the image | its two numbers |
//! | `rect.center` | the rectangle's centre, over the image | all four numbers |
//!
//! Nodes of a grid with `fit` or `aim` are placed before the fit and the aims (the order the
//! scene format runs them in), so a fit may move a dragged node again.

use flexcam::calibrate::build_flexible;
use flexcam::projection::flexible::{Volume, VolumeSource};
use flexcam::projection::{CameraBasis, ProjectionSpec};
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
    /// A 2-vector of a panorama curve: the point's camera-local components `axes` (0
    /// right, 1 up, 2 forward) around the eye of `basis`, the rest 0.
    Planar {
        path: ValuePath,
        basis: CameraBasis,
        axes: (usize, usize),
    },
    /// Numbers of `perspective_rect`: the u values at `u` move with x, the v values at `v`
    /// with y (v up).
    Rect { u: Vec<usize>, v: Vec<usize> },
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
/// projector grid, perspective rectangle.
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
    panorama_points(session, &mut out);
    rect(session, &mut out);
    out
}

/// The points of a shape-defined panorama's `points` outlines and profiles, at unit
/// distance around the eye: an outline's (right, forward) point in the horizontal plane of
/// the eye, a profile's (distance, height) point in the vertical half-plane ahead.
fn panorama_points(session: &Session, out: &mut Vec<Handle>) {
    let Some(basis) = session
        .camera()
        .ok()
        .and_then(|f| CameraBasis::new(&f).ok())
    else {
        return;
    };
    for (single, list, axes) in [
        ("outline", "outlines", (0, 2)),
        ("profile", "profiles", (2, 1)),
    ] {
        let mut curves = vec![(single.to_string(), ValuePath::key(single).child("points"))];
        let count = session
            .value(list)
            .and_then(Value::as_array)
            .map_or(0, |a| a.len());
        for i in 0..count {
            let path = ValuePath::key(list).index(i).child("points");
            curves.push((format!("{single}.{i}"), path));
        }
        for (name, path) in curves {
            let count = path
                .get(session)
                .and_then(Value::as_array)
                .map_or(0, |a| a.len());
            for k in 0..count {
                let point = path.index(k);
                let Some([a, b]) = point
                    .get(session)
                    .and_then(numbers)
                    .and_then(|n| <[f64; 2]>::try_from(n).ok())
                else {
                    continue;
                };
                let mut local = DVec3::ZERO;
                local[axes.0] = a;
                local[axes.1] = b;
                out.push(Handle {
                    name: format!("{name}.{k}"),
                    place: Place::World(basis.origin + basis.to_world(local)),
                    net: Some((name.clone(), 0, k)),
                    edit: Edit::Planar {
                        path: point,
                        basis,
                        axes,
                    },
                });
            }
        }
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
    let Ok([u0, v0, u1, v1]) = <[f64; 4]>::try_from(r) else {
        return;
    };
    let (width, height) = session.size();
    let pixel = |u: f64, v: f64| DVec2::new(u * f64::from(width), (1.0 - v) * f64::from(height));
    let corners = [(0, 1), (2, 1), (2, 3), (0, 3)];
    for (k, (u, v)) in corners.into_iter().enumerate() {
        let at = pixel([u0, v0, u1, v1][u], [u0, v0, u1, v1][v]);
        out.push(Handle {
            name: format!("rect.corner.{k}"),
            place: Place::Image(at),
            net: None,
            edit: Edit::Rect {
                u: vec![u],
                v: vec![v],
            },
        });
    }
    out.push(Handle {
        name: "rect.center".into(),
        place: Place::Image(pixel((u0 + u1) / 2.0, (v0 + v1) / 2.0)),
        net: None,
        edit: Edit::Rect {
            u: vec![0, 2],
            v: vec![1, 3],
        },
    });
}

impl Handle {
    /// The edits (key, new value) that move this handle of `session`'s projection by
    /// `delta`: world units for a world handle, pixels (x right, y down) for an image one.
    /// Errors when the value to edit is gone (the projection changed since the handle was
    /// listed).
    pub fn edits(&self, session: &Session, delta: Place) -> Result<Vec<(String, Value)>> {
        let wrong = || {
            Error::new(format!(
                "handle `{}` is moved {}",
                self.name,
                match self.place {
                    Place::World(_) => "in the world (the volume view)",
                    Place::Image(_) => "over the image",
                }
            ))
        };
        match (&self.edit, self.place, delta) {
            (Edit::Point(path), Place::World(at), Place::World(d)) => {
                Ok(vec![path.set(session, float_array(&(at + d).to_array()))?])
            }
            (Edit::Offset { path, base }, Place::World(at), Place::World(d)) => {
                let offset = at + d - *base;
                Ok(vec![path.set(session, float_array(&offset.to_array()))?])
            }
            (Edit::Planar { path, basis, axes }, Place::World(at), Place::World(d)) => {
                // The drag's component out of the curve's plane is dropped.
                let local = basis.to_local(at + d - basis.origin);
                Ok(vec![path.set(
                    session,
                    float_array(&[local[axes.0], local[axes.1]]),
                )?])
            }
            (&Edit::Node { col, row, end }, Place::World(at), Place::World(d)) => {
                Ok(vec![node_edit(session, col, row, end, at + d)])
            }
            (Edit::Rect { u, v }, Place::Image(_), Place::Image(d)) => {
                let path = ValuePath::key("perspective_rect");
                let mut r = path.get(session).and_then(numbers).ok_or_else(wrong)?;
                let (width, height) = session.size();
                for &i in u {
                    r[i] += d.x / f64::from(width);
                }
                for &i in v {
                    r[i] -= d.y / f64::from(height);
                }
                Ok(vec![path.set(session, float_array(&r))?])
            }
            _ => Err(wrong()),
        }
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
    fn outline_points_move_in_the_eye_s_horizontal_plane() {
        let (_dir, session) = session(
            "type = \"flexible\"\nposition = [0.0, 1.5, 0.0]\nlook_at = [0.0, 1.5, -1.0]\n\
             outline = { points = [[0.0, -1.0], [-1.0, 0.0], [-0.6, 0.8], [0.6, 0.8], [1.0, 0.0]] }\n\
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
                "outline.4",
                "profile.1.0",
                "profile.1.1"
            ]
        );
        // (right, forward) = (-0.6, 0.8): right is +x, forward -z.
        let point = find(&list, "outline.2");
        assert_eq!(point.place, Place::World(DVec3::new(-0.6, 1.5, -0.8)));
        // A profile point (distance, height) lies ahead: (1, -1) is 1 forward, 1 down.
        assert_eq!(
            find(&list, "profile.1.0").place,
            Place::World(DVec3::new(0.0, 0.5, -1.0))
        );
        // The drag's vertical part is dropped: the point stays in the horizontal plane.
        let edits = point
            .edits(&session, Place::World(DVec3::new(0.1, 0.3, -0.2)))
            .unwrap();
        assert_eq!(edits[0].0, "outline.points");
        let moved = numbers(edits[0].1.as_array().unwrap().get(2).unwrap()).unwrap();
        assert!(
            (moved[0] + 0.5).abs() < 1e-15 && (moved[1] - 1.0).abs() < 1e-15,
            "{moved:?}"
        );
    }
}
