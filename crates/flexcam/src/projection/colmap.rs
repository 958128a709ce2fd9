//! COLMAP's `cameras.txt` (one camera per line: `CAMERA_ID MODEL WIDTH HEIGHT PARAMS...`,
//! `#` comments) read into calibrated lens projections, and written back out as scene
//! projection tables.
//!
//! COLMAP puts the centre of the top-left pixel at (0.5, 0.5), OpenCV at (0, 0): a COLMAP
//! principal point c is OpenCV's c - 0.5. The distortion models are OpenCV's: SIMPLE_RADIAL
//! (k) and RADIAL (k1, k2) are radial-tangential with the other coefficients zero, OPENCV
//! has [k1, k2, p1, p2], FULL_OPENCV the rational [k1, k2, p1, p2, k3, k4, k5, k6], and
//! OPENCV_FISHEYE is Kannala-Brandt [k1, k2, k3, k4].

use std::fmt::Write as _;
use std::path::Path;

use super::Intrinsics;
use crate::error::{Error, Result};

/// The lens model of a camera as flexcam's calibrated projection types have it.
#[derive(Debug, Clone, PartialEq)]
pub enum Lens {
    /// `type = "opencv"`: `distortion` in OpenCV's order, its first `count` given by the
    /// camera (0, 4 or 8; written out as such).
    Opencv {
        /// [k1, k2, p1, p2, k3, k4, k5, k6], zeros past `count`.
        distortion: [f64; 8],
        /// How many coefficients the camera's model gives.
        count: usize,
    },
    /// `type = "opencv_fisheye"`.
    Fisheye {
        /// Kannala-Brandt [k1, k2, k3, k4].
        k: [f64; 4],
    },
}

/// One camera of a `cameras.txt`.
#[derive(Debug, Clone, PartialEq)]
pub struct ColmapCamera {
    /// COLMAP's CAMERA_ID.
    pub id: u64,
    /// 1-based line in the file.
    pub line: usize,
    /// COLMAP's model name (`OPENCV`, `OPENCV_FISHEYE`, ...).
    pub model: String,
    /// The calibration's image width, pixels.
    pub width: u32,
    /// The calibration's image height, pixels.
    pub height: u32,
    /// In OpenCV's pixel convention.
    pub intrinsics: Intrinsics,
    /// The lens model and its distortion coefficients.
    pub lens: Lens,
}

/// The models read, with their parameter counts.
const MODELS: [(&str, usize); 7] = [
    ("SIMPLE_PINHOLE", 3),
    ("PINHOLE", 4),
    ("SIMPLE_RADIAL", 4),
    ("RADIAL", 5),
    ("OPENCV", 8),
    ("FULL_OPENCV", 12),
    ("OPENCV_FISHEYE", 8),
];

/// Reads the cameras of `text` (the contents of `path`, named in errors). Errors, one line
/// with the file and line: a line with too few fields, a number that does not parse or is
/// not finite, a size of zero, a model other than `MODELS`, the wrong number of parameters
/// for the model, a focal length <= 0, a camera id given twice, no camera at all.
pub fn read_cameras(text: &str, path: &Path) -> Result<Vec<ColmapCamera>> {
    let mut cameras: Vec<ColmapCamera> = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let fields: Vec<&str> = raw.split_whitespace().collect();
        if fields.is_empty() || fields[0].starts_with('#') {
            continue;
        }
        let camera = camera(&fields, line).map_err(|message| Error::at(path, line, 1, message))?;
        if let Some(first) = cameras.iter().find(|c| c.id == camera.id) {
            return Err(Error::at(
                path,
                line,
                1,
                format!(
                    "camera {} is already defined on line {}",
                    camera.id, first.line
                ),
            ));
        }
        cameras.push(camera);
    }
    if cameras.is_empty() {
        return Err(Error::in_file(path, "no camera in the file"));
    }
    Ok(cameras)
}

/// One camera from the fields of its line, or the message of what is wrong with it.
fn camera(fields: &[&str], line: usize) -> std::result::Result<ColmapCamera, String> {
    let [id, model, width, height, params @ ..] = fields else {
        return Err(format!(
            "a camera line needs CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., got {} fields",
            fields.len()
        ));
    };
    let id: u64 = id
        .parse()
        .map_err(|_| format!("camera id {id:?} is not a non-negative integer"))?;
    let size = |name: &str, value: &str| match value.parse::<u32>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!("{name} {value:?} is not a positive integer")),
    };
    let (width, height) = (size("width", width)?, size("height", height)?);
    let Some(&(_, count)) = MODELS.iter().find(|(name, _)| name == model) else {
        let known: Vec<&str> = MODELS.iter().map(|(name, _)| *name).collect();
        return Err(format!(
            "camera model {model:?} is not supported (supported: {})",
            known.join(", ")
        ));
    };
    if params.len() != count {
        return Err(format!(
            "{model} needs {count} parameters, got {}",
            params.len()
        ));
    }
    let p = params
        .iter()
        .map(|s| match s.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("parameter {s:?} is not a finite number")),
        })
        .collect::<std::result::Result<Vec<f64>, String>>()?;
    // Focal lengths, principal point (COLMAP's), the distortion parameters.
    let (fx, fy, cx, cy, rest) = match *model {
        "SIMPLE_PINHOLE" | "SIMPLE_RADIAL" | "RADIAL" => (p[0], p[0], p[1], p[2], &p[3..]),
        _ => (p[0], p[1], p[2], p[3], &p[4..]),
    };
    if fx <= 0.0 || fy <= 0.0 {
        return Err(format!("focal lengths must be positive, got {fx}, {fy}"));
    }
    let mut coefficients = [0.0; 8];
    let lens = match *model {
        "OPENCV_FISHEYE" => Lens::Fisheye {
            k: [rest[0], rest[1], rest[2], rest[3]],
        },
        // k1 (SIMPLE_RADIAL), k1 k2 (RADIAL): radial-tangential with p1 = p2 = 0, so four
        // coefficients [k1, k2, 0, 0].
        "SIMPLE_RADIAL" | "RADIAL" => {
            coefficients[..rest.len()].copy_from_slice(rest);
            Lens::Opencv {
                distortion: coefficients,
                count: 4,
            }
        }
        _ => {
            coefficients[..rest.len()].copy_from_slice(rest);
            Lens::Opencv {
                distortion: coefficients,
                count: rest.len(),
            }
        }
    };
    Ok(ColmapCamera {
        id,
        line,
        model: (*model).to_string(),
        width,
        height,
        intrinsics: Intrinsics {
            fx,
            fy,
            cx: cx - 0.5,
            cy: cy - 0.5,
        },
        lens,
    })
}

/// The cameras as TOML: per camera a comment naming it and a table `[camera_ID]` with the
/// keys of a `[projection]` table (a placeholder placement the user replaces, the type, the
/// intrinsics, the coefficients and `calibration_size`), so that a table renamed
/// `[projection]` in a scene renders that camera at any image size. Numbers are written
/// with Rust's shortest round-trip formatting, so they read back exactly.
pub fn projection_tables(cameras: &[ColmapCamera], source: &str) -> String {
    let mut out = format!(
        "# Cameras of {source}, one table per camera: rename a table to [projection] in a scene\n\
         # and set position / look_at / up (COLMAP's cameras.txt has no placement).\n"
    );
    for camera in cameras {
        let Intrinsics { fx, fy, cx, cy } = camera.intrinsics;
        let (kind, coefficients) = match &camera.lens {
            Lens::Opencv { distortion, count } => (
                "opencv",
                (*count > 0).then(|| ("distortion", &distortion[..*count])),
            ),
            Lens::Fisheye { k } => ("opencv_fisheye", Some(("k", &k[..]))),
        };
        let _ = write!(
            out,
            "\n# COLMAP camera {} (line {}): {} {} x {}\n[camera_{}]\ntype = \"{kind}\"\n\
             position = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, -1.0]\nup = [0.0, 1.0, 0.0]\n\
             fx = {}\nfy = {}\ncx = {}\ncy = {}\n",
            camera.id,
            camera.line,
            camera.model,
            camera.width,
            camera.height,
            camera.id,
            number(fx),
            number(fy),
            number(cx),
            number(cy),
        );
        if let Some((key, values)) = coefficients {
            let list: Vec<String> = values.iter().map(|&v| number(v)).collect();
            let _ = writeln!(out, "{key} = [{}]", list.join(", "));
        }
        let _ = writeln!(
            out,
            "calibration_size = [{}, {}]",
            camera.width, camera.height
        );
    }
    out
}

/// A TOML float: shortest round-trip digits, with a decimal point.
fn number(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) {
        s
    } else {
        format!("{s}.0")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERAS: &str = "# Camera list with one line of data per camera:
#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]
# Number of cameras: 4
1 SIMPLE_PINHOLE 3072 2304 2559.81 1536 1152
2 OPENCV 640 480 500.5 501.25 320 240 -0.1 0.01 0.001 -0.002

3 FULL_OPENCV 640 480 500 500 319.5 239.5 -0.1 0.01 0.001 -0.002 0.003 0.1 0.02 0.003
7 OPENCV_FISHEYE 1024 1024 300 300 512 512 0.02 -0.004 0.0005 -0.00002
";

    fn read(text: &str) -> Result<Vec<ColmapCamera>> {
        read_cameras(text, Path::new("cams/cameras.txt"))
    }

    #[test]
    fn reads_every_model_with_opencv_pixel_centres() {
        let cameras = read(CAMERAS).unwrap();
        assert_eq!(cameras.len(), 4);
        let first = &cameras[0];
        assert_eq!((first.id, first.line, first.width), (1, 4, 3072));
        assert_eq!(
            first.intrinsics,
            Intrinsics {
                fx: 2559.81,
                fy: 2559.81,
                cx: 1535.5,
                cy: 1151.5
            }
        );
        assert_eq!(
            first.lens,
            Lens::Opencv {
                distortion: [0.0; 8],
                count: 0
            }
        );
        assert_eq!(
            cameras[2].lens,
            Lens::Opencv {
                distortion: [-0.1, 0.01, 0.001, -0.002, 0.003, 0.1, 0.02, 0.003],
                count: 8
            }
        );
        assert_eq!(
            cameras[3].lens,
            Lens::Fisheye {
                k: [0.02, -0.004, 0.0005, -0.00002]
            }
        );
        let radial = read("5 RADIAL 10 10 8 5 5 -0.2 0.03").unwrap();
        assert_eq!(
            radial[0].lens,
            Lens::Opencv {
                distortion: [-0.2, 0.03, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                count: 4
            }
        );
    }

    #[test]
    fn bad_lines_are_refused_with_file_and_line() {
        for (text, line, needle) in [
            (
                "1 PINHOLE 10 10 5 5 5",
                1,
                "PINHOLE needs 4 parameters, got 3",
            ),
            (
                "# c\n1 THIN_PRISM_FISHEYE 10 10 1 2 3",
                2,
                "\"THIN_PRISM_FISHEYE\" is not supported",
            ),
            (
                "1 PINHOLE 0 10 5 5 5 5",
                1,
                "width \"0\" is not a positive integer",
            ),
            (
                "1 PINHOLE 10 10 5 nan 5 5",
                1,
                "\"nan\" is not a finite number",
            ),
            (
                "1 PINHOLE 10 10 -5 5 5 5",
                1,
                "focal lengths must be positive",
            ),
            ("x PINHOLE 10 10 5 5 5 5", 1, "camera id \"x\""),
            ("1 PINHOLE 10", 1, "got 3 fields"),
            (
                "1 PINHOLE 10 10 5 5 5 5\n\n1 PINHOLE 10 10 5 5 5 5",
                3,
                "already defined on line 1",
            ),
        ] {
            let e = read(text).unwrap_err().to_string();
            let prefix = format!("cams/cameras.txt:{line}:1: ");
            assert!(e.starts_with(&prefix) && e.contains(needle), "{e}");
        }
        let e = read("# nothing\n").unwrap_err().to_string();
        assert_eq!(e, "cams/cameras.txt: no camera in the file");
    }

    #[test]
    fn tables_are_toml_with_the_projection_keys() {
        let cameras = read(CAMERAS).unwrap();
        let text = projection_tables(&cameras, "cameras.txt");
        let parsed: toml::Table = text.parse().unwrap();
        assert_eq!(parsed.len(), 4);
        let opencv = parsed["camera_2"].as_table().unwrap();
        assert_eq!(opencv["type"].as_str(), Some("opencv"));
        assert_eq!(opencv["cx"].as_float(), Some(319.5));
        assert_eq!(opencv["fy"].as_float(), Some(501.25));
        assert_eq!(opencv["distortion"].as_array().unwrap().len(), 4);
        assert_eq!(
            opencv["calibration_size"].as_array().unwrap()[0].as_integer(),
            Some(640)
        );
        assert!(!parsed["camera_1"]
            .as_table()
            .unwrap()
            .contains_key("distortion"));
        let fisheye = parsed["camera_7"].as_table().unwrap();
        assert_eq!(fisheye["type"].as_str(), Some("opencv_fisheye"));
        assert_eq!(
            fisheye["k"].as_array().unwrap()[3].as_float(),
            Some(-0.00002)
        );
    }
}
