//! The handles of the preset keys whose drags are clamped to the key's valid range
//! (docs/viewer.md, "Handles"):
//!
//! | name | point | edits |
//! | --- | --- | --- |
//! | `azimuth` | axonometric: the point half the eye's distance from `look_at`, level with it, towards the eye | the dragged point's angle about +y through `look_at`, from +z towards +x, the turn nearest the old one |
//! | `elevation` | axonometric: the eye (`look_at` plus the eye's distance along the view's direction) | the dragged point's angle above the level plane through `look_at`, within [-89.9, 89.9] |
//! | `corner_radius` | rounded_cubic: the middle of the front-right rounded corner, the outline scaled to the far clip (without `clip`: the look-at distance) | the radius that puts that middle at the dragged point's distance along the diagonal, within [0, 1] |
//! | `v_fov` | mcop: the middle column's point at half the angle above its look direction, at the look-at distance | twice the dragged point's angle above that direction, within [0.1, 179.9] |
//! | `deep.K.center`, `deep.K.width` | over the image: long_scene deep area K's middle, and its right edge, on the middle row | its centre by x over the image width; its width by twice that; kept a pixel inside the image |
//! | `deep.K.fov` | long_scene: deep area K's right edge on the far surface (the edge projector's end), level with the eye | the angle whose edge projector, from the area's edge on the slit, passes the dragged point's distance right of the axis at the far clip, within [0.1, 179.9] |
//!
//! Degenerate drags are refused with a message (the last valid projection kept): an
//! `azimuth` point dragged onto the vertical through `look_at` (no angle about it), an
//! `elevation` point dragged onto `look_at` (no direction). The bounds of a deep area's
//! neighbours are left to the build, which refuses areas that touch.

use std::f64::consts::SQRT_2;

use flexcam::projection::flexible::panorama::DEFAULT_FAR;
use flexcam::projection::flexible::presets::McopPath;
use flexcam::projection::flexible::{Preset, VolumeSource};
use flexcam::projection::{CameraBasis, ProjectionSpec};
use flexcam::{Error, Result};
use glam::{DVec2, DVec3};

use super::preset_shape::Shape;
use super::{image_pixel, Edit, Handle, Place, ValuePath};
use crate::session::Session;

/// The valid range of an angle of view below 180 degrees.
const ANGLE: [f64; 2] = crate::ranges::BELOW_HALF_TURN;

/// The axonometric elevation's range: (-90, 90) is valid, and at +-90 the view has no up.
const ELEVATION: [f64; 2] = [-89.9, 89.9];

/// How a drag makes its key's number from the point it is dragged to.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Rule {
    /// Degrees: the point's angle above the plane through `centre` perpendicular to `up`
    /// (unit).
    Elevation { centre: DVec3, up: DVec3 },
    /// A rounded square's corner radius: the one whose corner middle is the point's
    /// distance from `origin` along `diagonal` (unit) over `scale`.
    Corner {
        origin: DVec3,
        diagonal: DVec3,
        scale: f64,
    },
}

impl Rule {
    /// The number for the handle `name` dragged to `to`; `None` when `to` is over the
    /// image (these rules are of world points).
    pub(super) fn value(&self, name: &str, to: Place) -> Option<Result<f64>> {
        let Place::World(p) = to else {
            return None;
        };
        Some(match *self {
            Rule::Elevation { centre, up } => {
                let v = p - centre;
                let height = v.dot(up);
                let level = (v - height * up).length();
                // Degenerate: at the centre the point has no direction.
                if height == 0.0 && level == 0.0 {
                    Err(Error::new(format!(
                        "handle `{name}`: dragged onto the look-at point (no direction)"
                    )))
                } else {
                    Ok(height.atan2(level).to_degrees())
                }
            }
            Rule::Corner {
                origin,
                diagonal,
                scale,
            } => Ok((SQRT_2 - (p - origin).dot(diagonal) / scale) / (SQRT_2 - 1.0)),
        })
    }
}

/// The distance of the middle of a rounded square's corner (half-width 1, corner radius
/// `r`) from its centre: sqrt 2 (1 - r) to the arc's centre, plus r.
fn corner_middle(r: f64) -> f64 {
    SQRT_2 - r * (SQRT_2 - 1.0)
}

/// A handle `name` at `place` whose drag sets the number at `path` by `edit`, clamped to
/// `range`.
fn clamped(name: String, place: Place, edit: Edit, range: [f64; 2]) -> Handle {
    Handle {
        name,
        place,
        net: None,
        edit: Edit::Clamped {
            edit: Box::new(edit),
            range,
        },
    }
}

/// Adds the handles of the module's table, where the preset has those keys.
pub(super) fn handles(session: &Session, out: &mut Vec<Handle>) {
    let ProjectionSpec::Flexible(spec) = session.spec() else {
        return;
    };
    let VolumeSource::Preset(preset) = &spec.source else {
        return;
    };
    let frame = &preset.frame;
    let distance = (frame.look_at - frame.position).length();
    let key = ValuePath::key;
    match &preset.preset {
        &Preset::Axonometric {
            azimuth, elevation, ..
        } => {
            let (sin_a, cos_a) = azimuth.to_radians().sin_cos();
            let (sin_e, cos_e) = elevation.to_radians().sin_cos();
            let level = DVec3::new(sin_a, 0.0, cos_a);
            out.push(Handle {
                name: "azimuth".into(),
                place: Place::World(frame.look_at + distance / 2.0 * level),
                net: None,
                // From +z (the turn's "right") towards +x (its "up"), about +y.
                edit: Edit::Shape {
                    path: key("azimuth"),
                    shape: Shape::Turn {
                        centre: frame.look_at,
                        right: DVec3::Z,
                        up: DVec3::X,
                        old: azimuth,
                    },
                },
            });
            let towards_eye = cos_e * level + sin_e * DVec3::Y;
            let rule = Rule::Elevation {
                centre: frame.look_at,
                up: DVec3::Y,
            };
            out.push(clamped(
                "elevation".into(),
                Place::World(frame.look_at + distance * towards_eye),
                Edit::Ranged {
                    path: key("elevation"),
                    rule,
                },
                ELEVATION,
            ));
        }
        &Preset::RoundedCubic { corner_radius, .. } => {
            let Ok(b) = CameraBasis::new(frame) else {
                return;
            };
            // At the far clip (the look-at distance without one): a panorama's look-at
            // point is often close to the eye, where the corner's whole range would be a
            // few pixels of the volume view.
            let scale = preset.clip.map_or(distance, |[_, far]| far);
            let diagonal = (b.right + b.forward) / SQRT_2;
            let at = b.origin + scale * corner_middle(corner_radius) * diagonal;
            let rule = Rule::Corner {
                origin: b.origin,
                diagonal,
                scale,
            };
            let edit = Edit::Ranged {
                path: key("corner_radius"),
                rule,
            };
            out.push(clamped(
                "corner_radius".into(),
                Place::World(at),
                edit,
                [0.0, 1.0],
            ));
        }
        Preset::Mcop {
            path,
            directions,
            v_fov,
        } => {
            // The key has a default: a handle only where the file sets it.
            if session.value("v_fov").is_none() {
                return;
            }
            let Ok(b) = CameraBasis::new(frame) else {
                return;
            };
            let looks = directions
                .clone()
                .unwrap_or_else(|| vec![b.forward; path.len()]);
            let Ok(mcop) = McopPath::new(path.clone(), looks, frame.up) else {
                return;
            };
            // The middle column, and its image up: the frame's up made perpendicular to
            // its look direction (as the mcop's columns are).
            let (origin, forward) = mcop.station(0.5);
            let Some(up) = (frame.up - frame.up.dot(forward) * forward).try_normalize() else {
                return;
            };
            let (sin, cos) = (v_fov.to_radians() / 2.0).sin_cos();
            let edit = Edit::Angle {
                path: key("v_fov"),
                origin,
                axis: up,
                forward,
            };
            let at = origin + distance * (forward * cos + up * sin);
            out.push(clamped("v_fov".into(), Place::World(at), edit, ANGLE));
        }
        Preset::LongScene { width, deep, .. } => {
            let Ok(b) = CameraBasis::new(frame) else {
                return;
            };
            let (width_px, height_px) = session.size();
            let [near, far] = preset.clip.unwrap_or([0.0, DEFAULT_FAR]);
            let pixel = 1.0 / f64::from(width_px);
            for (k, area) in deep.iter().enumerate() {
                let path = key("deep").index(k);
                let number = |i: usize, x: f64| Edit::Image {
                    path: path.index(i),
                    x: vec![(0, x)],
                    y: Vec::new(),
                };
                let (c, half) = (area.center, area.width / 2.0);
                let row =
                    |u: f64| Place::Image(image_pixel(DVec2::new(u, 0.5), width_px, height_px));
                out.push(clamped(
                    format!("deep.{k}.center"),
                    row(c),
                    number(0, pixel),
                    [half + pixel, 1.0 - half - pixel],
                ));
                out.push(clamped(
                    format!("deep.{k}.width"),
                    row(c + half),
                    number(1, 2.0 * pixel),
                    [pixel, 2.0 * (c.min(1.0 - c) - pixel)],
                ));
                // The area's edge on the slit (the near surface) and its edge projector's
                // end at the far clip (the long_scene module's knots).
                let edge = (c - 0.5) * width + half * width;
                let reach = edge + (far - near) * (area.fov.to_radians() / 2.0).tan();
                let shape = Shape::Slope {
                    origin: b.origin,
                    right: b.right,
                    start: DVec2::new(near, edge),
                    depth: far,
                };
                let at = b.origin + far * b.forward + reach * b.right;
                let edit = Edit::Shape {
                    path: path.index(2),
                    shape,
                };
                out.push(clamped(
                    format!("deep.{k}.fov"),
                    Place::World(at),
                    edit,
                    ANGLE,
                ));
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::{handles, numbers};
    use super::*;
    use crate::session::scratch as session;

    const AXONOMETRIC: &str = "type = \"flexible\"\npreset = \"axonometric\"\n\
        position = [0.0, 0.0, 20.0]\nlook_at = [1.0, 0.5, -2.0]\nwidth = 4.0\n\
        azimuth = AZ\nelevation = EL\nclip = [0.0, 40.0]";
    const ROUNDED: &str = "type = \"flexible\"\npreset = \"rounded_cubic\"\n\
        position = [0.0, 1.5, 0.0]\nlook_at = [0.0, 1.5, -2.0]\nv_fov = 100.0\n\
        corner_radius = R\nclip = [0.0, 60.0]";
    const MCOP: &str = "type = \"flexible\"\npreset = \"mcop\"\n\
        position = [0.0, 3.0, 7.0]\nlook_at = [0.0, 1.0, 0.0]\n\
        path = [[-7.0, 3.0, 0.0], [-4.95, 3.0, 4.95], [0.0, 3.0, 7.0]]\n\
        directions = [[7.0, -2.0, 0.0], [4.95, -2.0, -4.95], [0.0, -2.0, -7.0]]\n\
        v_fov = V\nclip = [0.0, 30.0]";
    const LONG: &str = "type = \"flexible\"\npreset = \"long_scene\"\n\
        position = [0.0, 2.5, 3.0]\nlook_at = [0.0, 2.5, 0.0]\nwidth = 100.0\n\
        v_fov = 90.0\nclip = [1.0, 25.0]\ndeep = [[0.2, 0.05, 20.0], [C, W, F]]";

    /// `template` with each (placeholder, number) written in (as a float).
    fn fill(template: &str, values: &[(&str, f64)]) -> String {
        values.iter().fold(template.to_string(), |t, (k, v)| {
            t.replace(k, &format!("{v:?}"))
        })
    }

    /// Where handle `name` is in the scratch session of `projection`.
    fn place(projection: &str, name: &str) -> Place {
        let (_dir, s) = session(projection);
        let list = handles(&s);
        list.iter().find(|h| h.name == name).unwrap().place
    }

    /// The edits of handle `name` of the session of `from` dragged to `to`, or the error.
    fn drag(from: &str, name: &str, to: Place) -> Result<Vec<(String, toml_edit::Value)>> {
        let (_dir, s) = session(from);
        let list = handles(&s);
        let handle = list.iter().find(|h| h.name == name).unwrap();
        let delta = match (handle.place, to) {
            (Place::World(a), Place::World(b)) => Place::World(b - a),
            (Place::Image(a), Place::Image(b)) => Place::Image(b - a),
            _ => panic!("{name}: moved across places"),
        };
        handle.edits(&s, delta)
    }

    /// The new number of the key (a number) of handle `name` of `from` dragged to `to`.
    fn drag_to(from: &str, name: &str, to: Place) -> Result<f64> {
        let edits = drag(from, name, to)?;
        assert_eq!(edits.len(), 1);
        Ok(edits[0].1.as_float().unwrap())
    }

    /// Number `index` of deep area 1 after a drag of its handle `name` to `to`.
    fn deep_number(from: &str, name: &str, to: Place, index: usize) -> f64 {
        let edits = drag(from, name, to).unwrap();
        assert_eq!(edits[0].0, "deep");
        let area = edits[0].1.as_array().unwrap().get(1).unwrap();
        numbers(area).unwrap()[index]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        #[test]
        fn axonometric_angles_round_trip(
            (az, el) in (-170.0f64..170.0, -85.0f64..85.0),
            (az2, el2) in (-170.0f64..170.0, -85.0f64..85.0),
        ) {
            let from = fill(AXONOMETRIC, &[("AZ", az), ("EL", el)]);
            let to = fill(AXONOMETRIC, &[("AZ", az2), ("EL", el2)]);
            let azimuth = drag_to(&from, "azimuth", place(&to, "azimuth")).unwrap();
            // The same direction, written as the turn nearest the old azimuth.
            let turns = (azimuth - az2) / 360.0;
            prop_assert!((turns - turns.round()).abs() < 1e-11, "{azimuth} {az2}");
            prop_assert!((azimuth - az).abs() <= 180.0, "{azimuth} {az}");
            let elevation = drag_to(&from, "elevation", place(&to, "elevation")).unwrap();
            prop_assert!((elevation - el2).abs() < 1e-9, "{elevation} {el2}");
        }

        #[test]
        fn corner_radius_round_trips(r in 0.0f64..=1.0, r2 in 0.0f64..=1.0) {
            let from = fill(ROUNDED, &[("R", r)]);
            let to = fill(ROUNDED, &[("R", r2)]);
            let radius = drag_to(&from, "corner_radius", place(&to, "corner_radius")).unwrap();
            prop_assert!((radius - r2).abs() < 1e-12, "{radius} {r2}");
        }

        #[test]
        fn mcop_v_fov_round_trips(v in 1.0f64..179.0, v2 in 1.0f64..179.0) {
            let from = fill(MCOP, &[("V", v)]);
            let to = fill(MCOP, &[("V", v2)]);
            let v_fov = drag_to(&from, "v_fov", place(&to, "v_fov")).unwrap();
            prop_assert!((v_fov - v2).abs() < 1e-9, "{v_fov} {v2}");
        }

        #[test]
        fn deep_areas_round_trip(
            (c, w, f) in (0.6f64..0.8, 0.03f64..0.1, 5.0f64..60.0),
            (c2, w2, f2) in (0.6f64..0.8, 0.03f64..0.1, 5.0f64..60.0),
        ) {
            let from = fill(LONG, &[("C", c), ("W", w), ("F", f)]);
            // Each handle alone: the other numbers as they were.
            for (name, index, to) in [
                ("deep.1.center", 0, fill(LONG, &[("C", c2), ("W", w), ("F", f)])),
                ("deep.1.width", 1, fill(LONG, &[("C", c), ("W", w2), ("F", f)])),
                ("deep.1.fov", 2, fill(LONG, &[("C", c), ("W", w), ("F", f2)])),
            ] {
                let expected = [c2, w2, f2][index];
                let n = deep_number(&from, name, place(&to, name), index);
                prop_assert!((n - expected).abs() < 1e-9, "{name}: {n} {expected}");
            }
        }
    }

    #[test]
    fn drags_past_the_valid_range_stop_at_its_ends() {
        let axonometric = fill(AXONOMETRIC, &[("AZ", 30.0), ("EL", 40.0)]);
        // Straight above and below the look-at point: +-90, clamped.
        for (y, expected) in [(5.0, 89.9), (-5.0, -89.9)] {
            let to = Place::World(DVec3::new(1.0, 0.5 + y, -2.0));
            assert_eq!(drag_to(&axonometric, "elevation", to).unwrap(), expected);
        }
        // The corner dragged past the square's corner (radius below 0) and into the eye.
        let rounded = fill(ROUNDED, &[("R", 0.3)]);
        for (k, expected) in [(70.0, 0.0), (0.0, 1.0)] {
            let to = Place::World(DVec3::new(k, 1.5, -k));
            assert_eq!(drag_to(&rounded, "corner_radius", to).unwrap(), expected);
        }
        // The mcop's angle dragged far up (past the top: over 180 degrees), far down (below
        // the look direction: negative).
        let mcop = fill(MCOP, &[("V", 50.0)]);
        let Place::World(at) = place(&mcop, "v_fov") else {
            panic!()
        };
        let to = Place::World(at + 1000.0 * DVec3::Y);
        assert_eq!(drag_to(&mcop, "v_fov", to).unwrap(), 179.9);
        let to = Place::World(at - 1000.0 * DVec3::Y);
        assert_eq!(drag_to(&mcop, "v_fov", to).unwrap(), 0.1);
        // A deep area kept a pixel (1 / 40) inside the image, its width at least a pixel.
        let long = fill(LONG, &[("C", 0.7), ("W", 0.1), ("F", 50.0)]);
        let image = |x: f64| Place::Image(DVec2::new(x, 15.0));
        let centre = deep_number(&long, "deep.1.center", image(100.0), 0);
        assert!((centre - (1.0 - 0.05 - 0.025)).abs() < 1e-15, "{centre}");
        let width = deep_number(&long, "deep.1.width", image(-100.0), 1);
        assert_eq!(width, 0.025);
        let fov = deep_number(
            &long,
            "deep.1.fov",
            Place::World(DVec3::new(-90.0, 2.5, -22.0)),
            2,
        );
        assert_eq!(fov, 0.1);
    }

    #[test]
    fn handles_sit_where_their_keys_put_them_and_refuse_degenerate_drags() {
        // Axonometric from azimuth 90 (+x), elevation 0: the eye the frame's distance d
        // along +x from the look-at point, the azimuth point half as far.
        let axonometric = fill(AXONOMETRIC, &[("AZ", 90.0), ("EL", 0.0)]);
        let look_at = DVec3::new(1.0, 0.5, -2.0);
        let d = (look_at - DVec3::new(0.0, 0.0, 20.0)).length();
        let near = |a: Place, b: DVec3| matches!(a, Place::World(a) if (a - b).length() < 1e-12);
        assert!(near(
            place(&axonometric, "elevation"),
            look_at + d * DVec3::X
        ));
        assert!(near(
            place(&axonometric, "azimuth"),
            look_at + d / 2.0 * DVec3::X
        ));
        let error = drag_to(&axonometric, "azimuth", Place::World(look_at + DVec3::Y));
        assert!(error.unwrap_err().to_string().contains("no angle"));
        let error = drag_to(&axonometric, "elevation", Place::World(look_at));
        assert!(error.unwrap_err().to_string().contains("no direction"));
        // The square's corner (radius 0) at the far clip 60: (60, 60) right-forward.
        let square = fill(ROUNDED, &[("R", 0.0)]);
        assert!(near(
            place(&square, "corner_radius"),
            DVec3::new(60.0, 1.5, -60.0)
        ));
        // 40 x 30: deep area 1 (0.7, 0.1) on the middle row, its right edge at 0.75.
        let long = fill(LONG, &[("C", 0.7), ("W", 0.1), ("F", 30.0)]);
        assert_eq!(
            place(&long, "deep.1.center"),
            Place::Image(DVec2::new(28.0, 15.0))
        );
        assert_eq!(
            place(&long, "deep.1.width"),
            Place::Image(DVec2::new(30.0, 15.0))
        );
        // Its edge on the slit at 0.25 * 100 right, widening at 15 degrees over 24 of depth.
        let reach = 25.0 + 24.0 * 15f64.to_radians().tan();
        assert!(near(
            place(&long, "deep.1.fov"),
            DVec3::new(reach, 2.5, -22.0)
        ));
        // World moves of image handles and image moves of world ones are refused.
        let (_dir, s) = session(&long);
        let list = handles(&s);
        let centre = list.iter().find(|h| h.name == "deep.1.center").unwrap();
        assert!(centre.edits(&s, Place::World(DVec3::X)).is_err());
        let fov = list.iter().find(|h| h.name == "deep.1.fov").unwrap();
        assert!(fov.edits(&s, Place::Image(DVec2::X)).is_err());
    }
}
