//! The valid ranges of a projection's angle keys, as the scene loader checks them, for the
//! parameter panel's drag values and the angle handles' clamps (docs/viewer.md, "Handles").
//!
//! The loader wants an angle in (0, 180), (0, 180], (0, 360) or (0, 360] degrees by
//! projection type and preset; an open end is moved in by a tenth of a degree here, so
//! every number of a range builds.

/// (0, 180) in the loader: a perspective's angle of view, tan(fov / 2) finite.
pub const BELOW_HALF_TURN: [f64; 2] = [0.1, 179.9];

/// (0, 180] in the loader: an equirectangular's vertical angle, pole to pole.
pub const HALF_TURN: [f64; 2] = [0.1, 180.0];

/// (0, 360) in the loader: the stereographic fisheye (its radius is infinite straight
/// behind).
pub const BELOW_TURN: [f64; 2] = [0.1, 359.9];

/// (0, 360] in the loader: a full turn around the eye.
pub const TURN: [f64; 2] = [0.1, 360.0];

/// The range of angle key `key` (`fov`, `h_fov`, `v_fov`, an entry of `fovs`) of projection
/// type `kind`, where `variant` is a flexible projection's `preset` or a fisheye's `mapping`
/// (`None` where the table has none); `None` for the other keys.
pub fn angle(kind: &str, variant: Option<&str>, key: &str) -> Option<[f64; 2]> {
    Some(match (kind, variant, key) {
        ("flexible", Some("fisheye"), "fov") => TURN,
        ("flexible", Some("cylindrical" | "equirectangular"), "h_fov") => TURN,
        ("flexible", Some("equirectangular"), "v_fov") => HALF_TURN,
        ("flexible", _, "fov" | "v_fov" | "fovs") => BELOW_HALF_TURN,
        ("fisheye", Some("stereographic"), "fov") => BELOW_TURN,
        ("fisheye", Some("orthographic"), "fov") => HALF_TURN,
        ("equirectangular", _, "v_fov") => HALF_TURN,
        ("perspective" | "cylindrical", _, "fov" | "v_fov") => BELOW_HALF_TURN,
        (_, _, "fov" | "h_fov") => TURN,
        (_, _, "v_fov") => HALF_TURN,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::scratch;

    /// The projection table's text of `kind` (a flexible `preset`, or a single-viewpoint
    /// type) with `key` (the preset's other keys at their scene-file values) set to `value`.
    fn table(kind: &str, variant: Option<&str>, key: &str, value: f64) -> String {
        let frame = "position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n";
        let number = |k: &str, default: f64| {
            let v = if k == key { value } else { default };
            format!("{k} = {v:?}\n")
        };
        match (kind, variant) {
            ("flexible", Some(preset)) => {
                let keys: &[(&str, f64)] = match preset {
                    "fisheye" | "perspective" => &[("fov", 90.0)],
                    "cylindrical" | "equirectangular" => &[("h_fov", 180.0), ("v_fov", 90.0)],
                    "pushbroom" => &[("width", 2.0), ("v_fov", 60.0)],
                    "depth_transition" => &[],
                    _ => &[("fov", 60.0), ("v_fov", 40.0), ("slit_distance", 1.0)],
                };
                let mut text = format!("type = \"flexible\"\npreset = \"{preset}\"\n{frame}");
                for &(k, d) in keys {
                    text += &number(k, d);
                }
                if preset == "depth_transition" {
                    text += &format!("fovs = [{value:?}, 40.0]\ntransitions = [2.0]\n");
                }
                text + "clip = [0.5, 10.0]\n"
            }
            _ => {
                let mut text = format!("type = \"{kind}\"\n{frame}");
                if let Some(mapping) = variant {
                    text += &format!("mapping = \"{mapping}\"\n");
                }
                let keys: &[(&str, f64)] = match kind {
                    "equirectangular" | "cylindrical" => &[("h_fov", 180.0), ("v_fov", 90.0)],
                    _ => &[("fov", 90.0)],
                };
                for &(k, d) in keys {
                    text += &number(k, d);
                }
                text
            }
        }
    }

    /// Whether the scene loader builds `kind` with `key` = `value`.
    fn builds(kind: &str, variant: Option<&str>, key: &str, value: f64) -> bool {
        let text = table(kind, variant, key, value);
        let dir = tempfile::TempDir::new().unwrap();
        let path = dir.path().join("scene.toml");
        std::fs::write(
            &path,
            format!("[image]\nwidth = 40\nheight = 30\n\n[projection]\n{text}"),
        )
        .unwrap();
        crate::Session::open(&path).is_ok()
    }

    #[test]
    fn every_range_is_what_the_loader_accepts() {
        let cases: &[(&str, Option<&str>, &str)] = &[
            ("flexible", Some("perspective"), "fov"),
            ("flexible", Some("fisheye"), "fov"),
            ("flexible", Some("cylindrical"), "h_fov"),
            ("flexible", Some("cylindrical"), "v_fov"),
            ("flexible", Some("equirectangular"), "h_fov"),
            ("flexible", Some("equirectangular"), "v_fov"),
            ("flexible", Some("crossed_slits"), "fov"),
            ("flexible", Some("crossed_slits"), "v_fov"),
            ("flexible", Some("pushbroom"), "v_fov"),
            ("flexible", Some("depth_transition"), "fovs"),
            ("perspective", None, "fov"),
            ("fisheye", None, "fov"),
            ("fisheye", Some("stereographic"), "fov"),
            ("fisheye", Some("orthographic"), "fov"),
            ("equirectangular", None, "h_fov"),
            ("equirectangular", None, "v_fov"),
            ("cylindrical", None, "h_fov"),
            ("cylindrical", None, "v_fov"),
        ];
        for &(kind, variant, key) in cases {
            let [low, high] = angle(kind, variant, key).unwrap();
            let case = format!("{kind} {variant:?} {key}");
            assert!(builds(kind, variant, key, low), "{case}: {low}");
            assert!(builds(kind, variant, key, high), "{case}: {high}");
            assert!(!builds(kind, variant, key, 0.0), "{case}: 0");
            // Past the top: the loader's bound itself where the range stops short of it.
            let past = if high.fract() == 0.0 {
                high + 0.1
            } else {
                high.ceil()
            };
            assert!(!builds(kind, variant, key, past), "{case}: {past}");
        }
        // The session helper builds the same text.
        let (_dir, session) = scratch(&table("flexible", Some("perspective"), "fov", 179.9));
        assert_eq!(session.spec().kind(), "flexible");
    }

    #[test]
    fn keys_without_an_angle_range() {
        assert_eq!(angle("flexible", Some("perspective"), "width"), None);
        assert_eq!(angle("perspective", None, "clip"), None);
    }
}
