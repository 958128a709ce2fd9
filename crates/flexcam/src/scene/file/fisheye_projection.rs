//! The keys of `type = "fisheye"` (`fov`, `mapping`, `polynomial`, `fit` and the Cycles-style
//! sensor: `lens`, `sensor_width`, `sensor_height`, `sensor_fit`, `pixel_aspect`) and of
//! `type = "dome_master"` (`fov`, `tilt`).

use toml::Spanned;

use super::projection_table::{camera_frame, Required};
use crate::error::Result;
use crate::projection::{
    FisheyeFit, FisheyeLens, FisheyeMapping, ProjectionSpec, Sensor, SensorFit, MAPPING_NAMES,
    SENSOR_FIT_NAMES,
};

/// Keys of a `fisheye` table besides the camera frame.
pub(super) const FISHEYE_KEYS: [&str; 9] = [
    "fov",
    "mapping",
    "polynomial",
    "fit",
    "lens",
    "sensor_width",
    "sensor_height",
    "sensor_fit",
    "pixel_aspect",
];

/// Keys of a `dome_master` table besides the camera frame.
pub(super) const DOME_KEYS: [&str; 2] = ["fov", "tilt"];

/// `fit` names as written in scene files.
const FIT_NAMES: [&str; 3] = ["inscribed", "fill", "diagonal"];

/// Blender's default sensor, millimetres.
const SENSOR_WIDTH: f64 = 36.0;
const SENSOR_HEIGHT: f64 = 24.0;

/// `type = "fisheye"`. Without `mapping`, `fit` or sensor keys it is the angular fisheye
/// ([`ProjectionSpec::Fisheye`]). A classic mapping is placed by `fit` or, with `lens`, on
/// the sensor; the polynomial always on the sensor. `fov` is required.
pub(super) fn fisheye(required: &Required) -> Result<ProjectionSpec> {
    let src = required.src;
    let raw = required.raw();
    let frame = camera_frame(src, required)?;
    let fov = src.number(required.get(&raw.fov, "fov")?, "fov")?;
    let mapping = match &raw.mapping {
        None => FisheyeMapping::Equidistant,
        Some(name) => match name.get_ref().as_str() {
            "equidistant" => FisheyeMapping::Equidistant,
            "equisolid" => FisheyeMapping::Equisolid,
            "stereographic" => FisheyeMapping::Stereographic,
            "orthographic" => FisheyeMapping::Orthographic,
            "polynomial" => FisheyeMapping::Polynomial(polynomial(required)?),
            other => {
                return Err(src.unknown(&name.span(), "fisheye mapping", other, &MAPPING_NAMES))
            }
        },
    };
    if let (Some(given), false) = (
        &raw.polynomial,
        matches!(mapping, FisheyeMapping::Polynomial(_)),
    ) {
        return Err(src.error(
            &given.span(),
            "`polynomial` belongs to `mapping = \"polynomial\"`",
        ));
    }
    let on_sensor = matches!(mapping, FisheyeMapping::Polynomial(_)) || raw.lens.is_some();
    let fit = if on_sensor {
        if let Some(fit) = &raw.fit {
            return Err(src.error(
                &fit.span(),
                "`fit` places a fisheye circle by its fov; on a sensor (`lens` or the polynomial) the millimetres place it",
            ));
        }
        if let (Some(lens), FisheyeMapping::Polynomial(_)) = (&raw.lens, mapping) {
            return Err(src.error(
                &lens.span(),
                "`lens` (focal length) belongs to the classic mappings: the polynomial maps millimetres to angles itself",
            ));
        }
        FisheyeFit::Sensor(sensor(required)?)
    } else {
        let sensor_key = [
            ("sensor_width", raw.sensor_width.as_ref().map(Spanned::span)),
            (
                "sensor_height",
                raw.sensor_height.as_ref().map(Spanned::span),
            ),
            ("sensor_fit", raw.sensor_fit.as_ref().map(Spanned::span)),
            ("pixel_aspect", raw.pixel_aspect.as_ref().map(Spanned::span)),
        ]
        .into_iter()
        .find_map(|(key, span)| Some((key, span?)));
        if let Some((key, span)) = sensor_key {
            return Err(src.error(
                &span,
                format!(
                    "`{key}` needs `lens` (the focal length in mm) for mapping \"{}\"",
                    mapping.name()
                ),
            ));
        }
        match &raw.fit {
            None => FisheyeFit::Inscribed,
            Some(name) => match name.get_ref().as_str() {
                "inscribed" => FisheyeFit::Inscribed,
                "fill" => FisheyeFit::Fill,
                "diagonal" => FisheyeFit::Diagonal,
                other => return Err(src.unknown(&name.span(), "fisheye fit", other, &FIT_NAMES)),
            },
        }
    };
    let lens = FisheyeLens { mapping, fit };
    Ok(if lens == FisheyeLens::default() {
        ProjectionSpec::Fisheye { frame, fov }
    } else {
        ProjectionSpec::MappedFisheye { frame, fov, lens }
    })
}

/// `polynomial = [k0, k1, k2, k3, k4]` (required with the polynomial mapping).
fn polynomial(required: &Required) -> Result<[f64; 5]> {
    let src = required.src;
    let given = required.get(&required.raw().polynomial, "polynomial")?;
    let values = given.get_ref();
    if values.len() != 5 {
        return Err(src.error(
            &given.span(),
            format!(
                "`polynomial` needs 5 coefficients [k0, k1, k2, k3, k4] (Cycles' fisheye_polynomial_k0..k4), got {}",
                values.len()
            ),
        ));
    }
    src.all_finite(values, given, "polynomial")?;
    let mut k = [0.0; 5];
    k.copy_from_slice(values);
    Ok(k)
}

/// The sensor keys, Blender's defaults where absent (36 x 24 mm, fit `auto`, square pixels).
fn sensor(required: &Required) -> Result<Sensor> {
    let src = required.src;
    let raw = required.raw();
    let length = |value: &Option<Spanned<f64>>, key: &str, default: f64| {
        value.as_ref().map_or(Ok(default), |v| src.positive(v, key))
    };
    let fit = match &raw.sensor_fit {
        None => SensorFit::Auto,
        Some(name) => SensorFit::parse(name.get_ref()).ok_or_else(|| {
            src.unknown(
                &name.span(),
                "sensor_fit",
                name.get_ref(),
                &SENSOR_FIT_NAMES,
            )
        })?,
    };
    let pixel_aspect = match &raw.pixel_aspect {
        None => [1.0, 1.0],
        Some(given) => {
            let [x, y] = *given.get_ref();
            if !(x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0) {
                return Err(src.error(
                    &given.span(),
                    format!("`pixel_aspect` must be two positive numbers [x, y], got [{x}, {y}]"),
                ));
            }
            [x, y]
        }
    };
    Ok(Sensor {
        width: length(&raw.sensor_width, "sensor_width", SENSOR_WIDTH)?,
        height: length(&raw.sensor_height, "sensor_height", SENSOR_HEIGHT)?,
        fit,
        pixel_aspect,
        lens: raw
            .lens
            .as_ref()
            .map(|v| src.positive(v, "lens"))
            .transpose()?,
    })
}

/// `type = "dome_master"`: `fov` (default 180) and `tilt` (default 0), degrees.
pub(super) fn dome_master(required: &Required) -> Result<ProjectionSpec> {
    let src = required.src;
    let raw = required.raw();
    let angle = |value: &Option<Spanned<f64>>, key: &str, default: f64| {
        value.as_ref().map_or(Ok(default), |v| src.number(v, key))
    };
    Ok(ProjectionSpec::DomeMaster {
        frame: camera_frame(src, required)?,
        fov: angle(&raw.fov, "fov", 180.0)?,
        tilt: angle(&raw.tilt, "tilt", 0.0)?,
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::super::parse;
    use super::super::tests::assert_error_at;
    use crate::projection::{FisheyeFit, FisheyeMapping, ProjectionSpec};

    fn scene(keys: &str) -> String {
        format!(
            "[image]\nwidth = 64\nheight = 48\n[projection]\ntype = \"fisheye\"\n\
             position = [0, 1, 5]\nlook_at = [0, 1, 0]\nfov = 180\n{keys}"
        )
    }

    #[test]
    fn plain_fisheye_stays_the_angular_one() {
        for keys in ["", "mapping = \"equidistant\"\nfit = \"inscribed\"\n"] {
            let parsed = parse(&scene(keys), Path::new("s.toml")).unwrap();
            assert!(
                matches!(parsed.projection, ProjectionSpec::Fisheye { fov, .. } if fov == 180.0),
                "{:?}",
                parsed.projection
            );
        }
    }

    #[test]
    fn mapped_fisheye_keys() {
        let text = scene("mapping = \"polynomial\"\npolynomial = [0, -0.02, 0, 0, 0]\nsensor_fit = \"vertical\"\nsensor_height = 20\n");
        let parsed = parse(&text, Path::new("s.toml")).unwrap();
        let ProjectionSpec::MappedFisheye { lens, .. } = parsed.projection else {
            panic!("{:?}", parsed.projection)
        };
        assert_eq!(
            lens.mapping,
            FisheyeMapping::Polynomial([0.0, -0.02, 0.0, 0.0, 0.0])
        );
        let FisheyeFit::Sensor(sensor) = lens.fit else {
            panic!("{lens:?}")
        };
        assert_eq!(
            (sensor.width, sensor.height, sensor.lens),
            (36.0, 20.0, None)
        );
        let parsed = parse(
            &scene("mapping = \"equisolid\"\nlens = 10.5\n"),
            Path::new("s.toml"),
        )
        .unwrap();
        let ProjectionSpec::MappedFisheye { lens, .. } = parsed.projection else {
            panic!()
        };
        assert!(matches!(lens.fit, FisheyeFit::Sensor(s) if s.lens == Some(10.5)));
        let parsed = parse(&scene("fit = \"fill\"\n"), Path::new("s.toml")).unwrap();
        assert!(matches!(
            parsed.projection,
            ProjectionSpec::MappedFisheye { lens, .. } if lens.fit == FisheyeFit::Fill
        ));
    }

    #[test]
    fn bad_fisheye_keys_are_refused_at_their_place() {
        assert_error_at(
            &scene("mapping = \"fishy\"\n"),
            9,
            11,
            "unknown fisheye mapping \"fishy\"; expected one of: equidistant, equisolid",
        );
        assert_error_at(
            &scene("mapping = \"polynomial\"\npolynomial = [1, 2]\n"),
            10,
            14,
            "`polynomial` needs 5 coefficients",
        );
        assert_error_at(
            &scene("mapping = \"polynomial\"\n"),
            4,
            1,
            "fisheye projection needs `polynomial`",
        );
        assert_error_at(
            &scene("polynomial = [0, -0.02, 0, 0, 0]\n"),
            9,
            14,
            "`polynomial` belongs to `mapping = \"polynomial\"`",
        );
        assert_error_at(
            &scene("sensor_width = 30\n"),
            9,
            16,
            "`sensor_width` needs `lens`",
        );
        assert_error_at(
            &scene("lens = 8\nfit = \"fill\"\n"),
            10,
            7,
            "`fit` places a fisheye circle by its fov",
        );
        assert_error_at(
            &scene("fit = \"cover\"\n"),
            9,
            7,
            "unknown fisheye fit \"cover\"",
        );
        assert_error_at(
            &scene("lens = 8\nsensor_fit = \"diagonal\"\n"),
            10,
            14,
            "unknown sensor_fit \"diagonal\"",
        );
        assert_error_at(&scene("lens = -8\n"), 9, 8, "`lens` must be positive");
        assert_error_at(
            &scene("tilt = 10\n"),
            9,
            8,
            "`tilt` is not a parameter of fisheye projections",
        );
    }

    #[test]
    fn dome_master_defaults() {
        let text =
            "[projection]\ntype = \"dome_master\"\nposition = [0, 1, 0]\nlook_at = [0, 1, -1]\n";
        let parsed = parse(text, Path::new("s.toml")).unwrap();
        assert!(matches!(
            parsed.projection,
            ProjectionSpec::DomeMaster { fov, tilt, .. } if fov == 180.0 && tilt == 0.0
        ));
    }
}
