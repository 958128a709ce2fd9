//! The handles of the preset keys that shape the projectors beyond a view angle or a
//! distance along the axis (docs/viewer.md, "Handles"):
//!
//! | name | point | edits |
//! | --- | --- | --- |
//! | `shift` | off_axis: the shifted window's centre at the look-at distance | both numbers: the direction from the eye to the dragged point, in half-widths and half-heights of the window |
//! | `shear` | oblique: the image centre's projector at the look-at distance (the projectors run along the view direction less `a` right and `b` up) | both numbers: minus the direction from the eye to the dragged point, right and up over forward |
//! | `twist` | twist: the middle of the far rectangle's right edge, turned | the angle of the dragged point about the view axis, counter-clockwise from the right as seen from the eye, the turn nearest the old one |
//! | `converge` | inverse_perspective: the world point the projectors meet at | that point |
//! | `slit_distance` | crossed_slits: the horizontal slit's point on the view axis | the dragged point's distance along the axis |
//! | `fovs.K` | depth_transition: where view K ends (the next transition or the far clip), its right edge | the angle of view K: its edge through the dragged point's distance right of the axis at that depth, from where view K starts, within the loader's (0, 180) (module `ranges`) |
//! | `generators.K.start`, `generators.K.end` | glc: generator ray K's points at local depth 0 and 1 | that point's two numbers: the dragged point across the view axis at that depth |
//! | `directions.K` | mcop: path point K plus half its direction (half: columns that look at one point, as an mcop's often do, keep their handles apart) | that direction: twice the dragged point less the path point |
//! | `strength` | over the image: occlusion, the point `strength` image widths right of the pole | the number, by x over the image width |
//! | `magnification` | over the image: magnifier, the point the radius over the magnification above the lens centre | the radius over the dragged point's height above the centre |
//!
//! Degenerate drags are refused with a message (the last valid projection kept): a `shift`
//! or `shear` point dragged to or behind the eye's plane, a `twist` point dragged onto the view axis
//! (no angle), a `magnification` point dragged to or below the lens centre.

use flexcam::projection::flexible::panorama::DEFAULT_FAR;
use flexcam::projection::flexible::{Preset, VolumeSource};
use flexcam::projection::{CameraBasis, ProjectionSpec};
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};
use toml_edit::Value;

use super::{image_pixel, numbers, vector, Edit, Handle, Place, ValuePath};
use crate::session::Session;

/// How a drag of one of these handles makes its key's new value from the point it is
/// dragged to.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Shape {
    /// `[sx, sy]`: the direction from `origin` to the point, over `forward` and divided by
    /// `half` along `right` and `up` (an off_axis shift: `half` the window's half-extents
    /// at unit distance; an oblique shear: `half` = (-1, -1)).
    Shift {
        origin: DVec3,
        axes: [DVec3; 3],
        half: DVec2,
    },
    /// Degrees: the point's angle about the axis through `centre`, from `right` towards
    /// `up`, the turn nearest `old`.
    Turn {
        centre: DVec3,
        right: DVec3,
        up: DVec3,
        old: f64,
    },
    /// Degrees: twice the angle of the line from (`start` depth, `start` half-width) to
    /// (`depth`, the point's distance from `origin` along `right`).
    Slope {
        origin: DVec3,
        right: DVec3,
        start: DVec2,
        depth: f64,
    },
    /// Numbers `first` and `first + 1` of an array: the point's offsets from `at` along
    /// `right` and `up`.
    Plane {
        at: DVec3,
        right: DVec3,
        up: DVec3,
        first: usize,
    },
    /// A 3-vector: `factor` times the point less `base`.
    Direction { base: DVec3, factor: f64 },
    /// A number: `length` over the point's height (pixels, y up) above `centre`.
    Ratio { centre: DVec2, length: f64 },
}

impl Shape {
    /// The new value of the key (now `old`) for the handle `name` dragged to `to`; `None`
    /// when `to` is not where this handle moves (the world or the image).
    pub(super) fn value(&self, name: &str, old: &Value, to: Place) -> Option<Result<Value>> {
        Some(match (self, to) {
            (&Shape::Shift { origin, axes, half }, Place::World(p)) => {
                let v = p - origin;
                let [right, up, forward] = axes;
                let depth = v.dot(forward);
                // Degenerate: at or behind the eye's plane, the point has no direction
                // through the window.
                if depth.is_nan() || depth <= 0.0 {
                    return Some(Err(Error::new(format!(
                        "handle `{name}`: drag it in front of the eye (it is a direction from the eye)"
                    ))));
                }
                let shift = DVec2::new(v.dot(right), v.dot(up)) / depth / half;
                Ok(flexcam::scene::file::edit::float_array(&shift.to_array()))
            }
            (
                &Shape::Turn {
                    centre,
                    right,
                    up,
                    old,
                },
                Place::World(p),
            ) => {
                let v = p - centre;
                let (x, y) = (v.dot(right), v.dot(up));
                // Degenerate: on the axis the point has no angle about it.
                if x == 0.0 && y == 0.0 {
                    return Some(Err(Error::new(format!(
                        "handle `{name}`: dragged onto the view axis (no angle about it)"
                    ))));
                }
                let angle = y.atan2(x).to_degrees();
                let turn = angle - 360.0 * ((angle - old) / 360.0).round();
                Ok(Value::from(turn))
            }
            (
                &Shape::Slope {
                    origin,
                    right,
                    start,
                    depth,
                },
                Place::World(p),
            ) => {
                let across = (p - origin).dot(right);
                let slope = (across - start.y) / (depth - start.x);
                Ok(Value::from(2.0 * slope.atan().to_degrees()))
            }
            (
                &Shape::Plane {
                    at,
                    right,
                    up,
                    first,
                },
                Place::World(p),
            ) => {
                let Some(mut n) = numbers(old).filter(|n| n.len() >= first + 2) else {
                    return Some(Err(Error::new(format!(
                        "handle `{name}`: its value is not an array of numbers"
                    ))));
                };
                n[first] = (p - at).dot(right);
                n[first + 1] = (p - at).dot(up);
                Ok(flexcam::scene::file::edit::float_array(&n))
            }
            (&Shape::Direction { base, factor }, Place::World(p)) => Ok(
                flexcam::scene::file::edit::float_array(&(factor * (p - base)).to_array()),
            ),
            (&Shape::Ratio { centre, length }, Place::Image(p)) => {
                let height = centre.y - p.y;
                // Degenerate: at or below the centre the ratio is infinite or negative.
                if height.is_nan() || height <= 0.0 {
                    return Some(Err(Error::new(format!(
                        "handle `{name}`: drag it above the lens centre"
                    ))));
                }
                Ok(Value::from(length / height))
            }
            _ => return None,
        })
    }
}

/// A handle `name` at `place` whose drag sets the key at `path` by `shape`.
fn shaped(name: String, path: ValuePath, place: Place, shape: Shape) -> Handle {
    Handle {
        name,
        place,
        net: None,
        edit: Edit::Shape { path, shape },
    }
}

/// Adds the handles of the preset's shaping keys (see the module's table), where the scene
/// file sets them.
pub(super) fn handles(session: &Session, out: &mut Vec<Handle>) {
    let ProjectionSpec::Flexible(spec) = session.spec() else {
        return;
    };
    let VolumeSource::Preset(preset) = &spec.source else {
        return;
    };
    let Ok(basis) = CameraBasis::new(&preset.frame) else {
        return;
    };
    let (width, height) = session.size();
    let (w, h) = (f64::from(width), f64::from(height));
    let [near, far] = preset.clip.unwrap_or([0.0, DEFAULT_FAR]);
    let distance = (preset.frame.look_at - preset.frame.position).length();
    let (o, right, up, forward) = (basis.origin, basis.right, basis.up, basis.forward);
    let key = ValuePath::key;
    match &preset.preset {
        &Preset::OffAxis { fov, shift } => {
            let t = (fov.to_radians() / 2.0).tan();
            let half = DVec2::new(t, t * h / w);
            let at = o + distance * (forward + shift.x * half.x * right + shift.y * half.y * up);
            let shape = Shape::Shift {
                origin: o,
                axes: [right, up, forward],
                half,
            };
            out.push(shaped(
                "shift".into(),
                key("shift"),
                Place::World(at),
                shape,
            ));
        }
        &Preset::Oblique { shear, .. } => {
            let at = o + distance * (forward - shear.x * right - shear.y * up);
            let shape = Shape::Shift {
                origin: o,
                axes: [right, up, forward],
                half: DVec2::NEG_ONE,
            };
            out.push(shaped(
                "shear".into(),
                key("shear"),
                Place::World(at),
                shape,
            ));
        }
        &Preset::Twist { fov, twist } => {
            let t = (fov.to_radians() / 2.0).tan();
            let (sin, cos) = twist.to_radians().sin_cos();
            let centre = o + far * forward;
            let at = centre + far * t * (cos * right + sin * up);
            let shape = Shape::Turn {
                centre,
                right,
                up,
                old: twist,
            };
            out.push(shaped(
                "twist".into(),
                key("twist"),
                Place::World(at),
                shape,
            ));
        }
        &Preset::InversePerspective { converge, .. } => out.push(Handle {
            name: "converge".into(),
            place: Place::World(converge),
            net: None,
            edit: Edit::Point(key("converge")),
        }),
        &Preset::CrossedSlits { slit_distance, .. } => out.push(Handle {
            name: "slit_distance".into(),
            place: Place::World(o + slit_distance * forward),
            net: None,
            edit: Edit::Along {
                path: key("slit_distance"),
                origin: o,
                axis: forward,
                factor: 1.0,
            },
        }),
        Preset::DepthTransition {
            fovs, transitions, ..
        } => {
            // The stations of the chain: view K runs from (d, h) to its end, where the
            // next starts (as the preset builds them).
            let tan = |fov: f64| (fov.to_radians() / 2.0).tan();
            let mut start = DVec2::new(near, near * fovs.first().map_or(0.0, |&f| tan(f)));
            for (k, &fov) in fovs.iter().enumerate() {
                let depth = transitions.get(k).copied().unwrap_or(far);
                let end = start.y + (depth - start.x) * tan(fov);
                let shape = Shape::Slope {
                    origin: o,
                    right,
                    start,
                    depth,
                };
                let place = Place::World(o + depth * forward + end * right);
                let edit = Edit::Shape {
                    path: key("fovs").index(k),
                    shape,
                };
                out.push(Handle {
                    name: format!("fovs.{k}"),
                    place,
                    net: None,
                    edit: Edit::Clamped {
                        edit: Box::new(edit),
                        range: crate::ranges::BELOW_HALF_TURN,
                    },
                });
                start = DVec2::new(depth, end);
            }
        }
        Preset::Glc { generators, .. } => {
            for (k, g) in generators.iter().enumerate() {
                for (which, depth, first) in [("start", 0.0, 0), ("end", 1.0, 2)] {
                    let at = o + depth * forward;
                    let place = Place::World(at + g[first] * right + g[first + 1] * up);
                    let shape = Shape::Plane {
                        at,
                        right,
                        up,
                        first,
                    };
                    let path = key("generators").index(k);
                    out.push(shaped(
                        format!("generators.{k}.{which}"),
                        path,
                        place,
                        shape,
                    ));
                }
            }
        }
        Preset::Mcop { .. } => {
            let count = session
                .value("directions")
                .and_then(Value::as_array)
                .map_or(0, |a| a.len());
            for k in 0..count {
                let direction = key("directions").index(k);
                let base = key("path").index(k).get(session).and_then(vector);
                if let (Some(base), Some(d)) = (base, direction.get(session).and_then(vector)) {
                    let shape = Shape::Direction { base, factor: 2.0 };
                    let place = Place::World(base + d / 2.0);
                    out.push(shaped(format!("directions.{k}"), direction, place, shape));
                }
            }
        }
        &Preset::Occlusion { pole, strength, .. } => {
            let at = image_pixel(pole, width, height) + DVec2::X * strength * w;
            out.push(Handle {
                name: "strength".into(),
                place: Place::Image(at),
                net: None,
                edit: Edit::Image {
                    path: key("strength"),
                    x: vec![(0, 1.0 / w)],
                    y: Vec::new(),
                },
            });
        }
        Preset::Magnifier { lens, .. } => {
            let centre = image_pixel(lens.center, width, height);
            let length = lens.radius * w.min(h);
            let at = centre - DVec2::Y * length / lens.magnification;
            let shape = Shape::Ratio { centre, length };
            let path = key("magnification");
            out.push(shaped(
                "magnification".into(),
                path,
                Place::Image(at),
                shape,
            ));
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::super::handles;
    use super::*;
    use crate::session::scratch as session;

    /// The handle `name` of the scratch session on `projection` dragged by `delta`: the
    /// edited key's new value, or the error.
    fn drag(projection: &str, name: &str, delta: Place) -> Result<Value> {
        let (_dir, session) = session(projection);
        let list = handles(&session);
        let handle = list.iter().find(|h| h.name == name).unwrap();
        let mut edits = handle.edits(&session, delta)?;
        assert_eq!(edits.len(), 1);
        Ok(edits.remove(0).1)
    }

    /// Whether world handle place `at` is within 1e-12 of `p` (tan 45 degrees is 1 to
    /// rounding).
    fn near(at: Place, p: DVec3) -> bool {
        matches!(at, Place::World(at) if (at - p).length() < 1e-12)
    }

    const FRAME: &str = "type = \"flexible\"\nposition = [0.0, 0.0, 3.0]\n\
        look_at = [0.0, 0.0, 0.0]\nclip = [0.5, 10.0]\n";

    #[test]
    fn the_shift_point_is_the_window_centre_and_refuses_the_eye_plane() {
        let projection = format!("{FRAME}preset = \"off_axis\"\nfov = 90.0\nshift = [0.5, 0.0]");
        let (_dir, s) = session(&projection);
        let list = handles(&s);
        let shift = list.iter().find(|h| h.name == "shift").unwrap();
        // tan 45 = 1: half a half-width right of the axis at the look-at distance 3.
        assert!(
            near(shift.place, DVec3::new(1.5, 0.0, 0.0)),
            "{:?}",
            shift.place
        );
        // Moved up by 0.75 at that depth: 0.75 / 3 over the half-height tan 45 * 30 / 40.
        let value = drag(
            &projection,
            "shift",
            Place::World(DVec3::new(0.0, 0.75, 0.0)),
        );
        let shift = numbers(&value.unwrap()).unwrap();
        assert!(
            (shift[0] - 0.5).abs() < 1e-12 && (shift[1] - 0.25 / 0.75).abs() < 1e-12,
            "{shift:?}"
        );
        // Degenerate: dragged onto the eye's plane (depth 0), then behind it.
        for z in [3.0, 4.0] {
            let delta = Place::World(DVec3::new(-1.5, 0.0, z));
            let error = drag(&projection, "shift", delta).unwrap_err();
            assert!(error.to_string().contains("in front of the eye"), "{error}");
        }
    }

    #[test]
    fn the_twist_turns_to_the_nearest_angle_and_refuses_the_axis() {
        let projection = format!("{FRAME}preset = \"twist\"\nfov = 90.0\ntwist = 170.0");
        // The far edge's middle: far clip 10 along -z from the eye, at 10 tan 45 from the
        // axis, turned by 170 degrees.
        let (_dir, s) = session(&projection);
        let list = handles(&s);
        let Place::World(at) = list.iter().find(|h| h.name == "twist").unwrap().place else {
            panic!("a world handle")
        };
        let (sin, cos) = 170f64.to_radians().sin_cos();
        let expected = DVec3::new(10.0 * cos, 10.0 * sin, -7.0);
        assert!((at - expected).length() < 1e-12, "{at}");
        // Dragged past 180 to -170 degrees of atan2: written as 190, the turn nearest 170.
        let (sin, cos) = (-170f64).to_radians().sin_cos();
        let to = DVec3::new(10.0 * cos, 10.0 * sin, -7.0);
        let value = drag(&projection, "twist", Place::World(to - at)).unwrap();
        assert!((value.as_float().unwrap() - 190.0).abs() < 1e-9, "{value}");
        // Degenerate: onto the view axis.
        let to = DVec3::new(0.0, 0.0, -7.0);
        let error = drag(&projection, "twist", Place::World(to - at)).unwrap_err();
        assert!(error.to_string().contains("onto the view axis"), "{error}");
    }

    #[test]
    fn the_magnification_is_the_radius_over_the_height_and_refuses_the_centre() {
        let projection = format!(
            "{FRAME}preset = \"magnifier\"\nfov = 60.0\ncenter = [0.5, 0.5]\nradius = 0.4\n\
             magnification = 2.0"
        );
        // 40 x 30: the radius 12 pixels, the point 6 above the centre (20, 15).
        let (_dir, s) = session(&projection);
        let list = handles(&s);
        let at = list.iter().find(|h| h.name == "magnification").unwrap();
        assert_eq!(at.place, Place::Image(DVec2::new(20.0, 9.0)));
        let value = drag(
            &projection,
            "magnification",
            Place::Image(DVec2::new(3.0, -2.0)),
        );
        assert_eq!(value.unwrap().as_float(), Some(12.0 / 8.0));
        // Degenerate: onto the centre's row, and below it.
        for dy in [6.0, 10.0] {
            let delta = Place::Image(DVec2::new(0.0, dy));
            let error = drag(&projection, "magnification", delta).unwrap_err();
            assert!(
                error.to_string().contains("above the lens centre"),
                "{error}"
            );
        }
        // A world move of an image handle is refused.
        let world = Place::World(DVec3::X);
        assert!(drag(&projection, "magnification", world).is_err());
    }

    #[test]
    fn each_view_of_a_depth_transition_has_its_angle_at_its_end() {
        let projection = format!(
            "{FRAME}preset = \"depth_transition\"\nfovs = [90.0, 0.0001, 90.0]\n\
             transitions = [2.0, 4.0]"
        );
        let (_dir, s) = session(&projection);
        let list = handles(&s);
        let at = |name: &str| list.iter().find(|h| h.name == name).unwrap().place;
        // View 0 from (0.5, 0.5) to depth 2 (half-width 2), view 1 nearly parallel to
        // depth 4, view 2 widening at 45 degrees to the far clip 10: 2 + 6.
        assert!(
            near(at("fovs.0"), DVec3::new(2.0, 0.0, 1.0)),
            "{:?}",
            at("fovs.0")
        );
        let Place::World(p) = at("fovs.1") else {
            panic!()
        };
        assert!((p - DVec3::new(2.0, 0.0, -1.0)).length() < 1e-5, "{p}");
        let Place::World(p) = at("fovs.2") else {
            panic!()
        };
        assert!((p - DVec3::new(8.0, 0.0, -7.0)).length() < 1e-5, "{p}");
        // View 1's end dragged 2 right: its edge rises 2 over its 2 of depth, 90 degrees.
        let value = drag(
            &projection,
            "fovs.1",
            Place::World(DVec3::new(2.0, 0.0, 0.5)),
        );
        // (The edit is of the whole `fovs` array, this view's angle changed.)
        let fovs = numbers(&value.unwrap()).unwrap();
        assert_eq!((fovs[0], fovs[2]), (90.0, 90.0));
        assert!((fovs[1] - 90.0).abs() < 1e-3, "{fovs:?}");
    }
}
