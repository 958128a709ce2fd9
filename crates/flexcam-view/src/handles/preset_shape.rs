//! The handles of the preset keys that shape the projectors beyond a view angle or a
//! distance along the axis (docs/viewer.md, "Handles"):
//!
//! | name | point | edits |
//! | --- | --- | --- |
//! | `shift` | off_axis: the shifted window's centre at the look-at distance | both numbers: the direction from the eye to the dragged point, in half-widths and half-heights of the window |
//! | `twist` | twist: the middle of the far rectangle's right edge, turned | the angle of the dragged point about the view axis, counter-clockwise from the right as seen from the eye, the turn nearest the old one |
//! | `slit_distance` | crossed_slits: the horizontal slit's point on the view axis | the dragged point's distance along the axis |
//! | `fovs.K` | depth_transition: where view K ends (the next transition or the far clip), its right edge | the angle of view K: its edge through the dragged point's distance right of the axis at that depth, from where view K starts |
//! | `generators.K.start`, `generators.K.end` | glc: generator ray K's points at local depth 0 and 1 | that point's two numbers: the dragged point across the view axis at that depth |
//! | `directions.K` | mcop: path point K plus half its direction (half: columns that look at one point, as an mcop's often do, keep their handles apart) | that direction: twice the dragged point less the path point |
//! | `strength` | over the image: occlusion, the point `strength` image widths right of the pole | the number, by x over the image width |
//! | `magnification` | over the image: magnifier, the point the radius over the magnification above the lens centre | the radius over the dragged point's height above the centre |
//!
//! Degenerate drags are refused with a message (the last valid projection kept): a `shift`
//! point dragged to or behind the eye's plane, a `twist` point dragged onto the view axis
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
    /// `half` (the window's half-extents at unit distance) along `right` and `up`.
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
                if !(depth > 0.0) {
                    return Some(Err(Error::new(format!(
                        "handle `{name}`: drag it in front of the eye (it is the window's centre seen from the eye)"
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
                if !(height > 0.0) {
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
                out.push(shaped(
                    format!("fovs.{k}"),
                    key("fovs").index(k),
                    place,
                    shape,
                ));
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
