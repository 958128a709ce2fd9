//! Property tests of the fisheye mappings, the sensor ellipse and the dome master against
//! their closed forms written out here independently: a pixel's direction from the mapping
//! formulas (Cycles' sensor convention for `lens` and the polynomial, the fulldome axes for
//! the dome master), and the round trips point -> pixel -> ray through the point (1e-9
//! relative) and pixel -> ray -> pixel.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::inverse_properties::{frame, vec3};
use super::{
    CameraFrame, FisheyeFit, FisheyeLens, FisheyeMapping, Projection, ProjectionSpec, Sensor,
    SensorFit,
};

/// Image radius of angle `theta` under a classic mapping, unit focal length.
fn classic(mapping: FisheyeMapping, theta: f64) -> f64 {
    match mapping {
        FisheyeMapping::Equidistant => theta,
        FisheyeMapping::Equisolid => 2.0 * (theta / 2.0).sin(),
        FisheyeMapping::Stereographic => 2.0 * (theta / 2.0).tan(),
        FisheyeMapping::Orthographic => theta.sin(),
        FisheyeMapping::Polynomial(_) => unreachable!(),
    }
}

/// Angle of image radius `rho` under a classic mapping, unit focal length.
fn classic_inverse(mapping: FisheyeMapping, rho: f64) -> f64 {
    match mapping {
        FisheyeMapping::Equidistant => rho,
        FisheyeMapping::Equisolid => 2.0 * (rho / 2.0).asin(),
        FisheyeMapping::Stereographic => 2.0 * (rho / 2.0).atan(),
        FisheyeMapping::Orthographic => rho.asin(),
        FisheyeMapping::Polynomial(_) => unreachable!(),
    }
}

/// Cycles' `fisheye_lens_polynomial_to_direction` angle: -(k0 + k1 r + ... + k4 r^4).
fn cycles_theta(k: &[f64; 5], r: f64) -> f64 {
    -(k[0] + k[1] * r + k[2] * r.powi(2) + k[3] * r.powi(3) + k[4] * r.powi(4))
}

/// Millimetres per pixel in x and y, Blender's `blender_camera_sync` written out: the
/// fitted side is `sensor_size` mm, the other follows the aspect-weighted image size.
fn sensor_mm(sensor: &Sensor, w: f64, h: f64) -> DVec2 {
    let (xr, yr) = (w * sensor.pixel_aspect[0], h * sensor.pixel_aspect[1]);
    let (horizontal, size) = match sensor.fit {
        SensorFit::Auto => (xr > yr, sensor.width),
        SensorFit::Horizontal => (true, sensor.width),
        SensorFit::Vertical => (false, sensor.height),
    };
    let (sw, sh) = if horizontal {
        (size, size * yr / xr)
    } else {
        (size * xr / yr, size)
    };
    DVec2::new(sw / w, sh / h)
}

/// Camera axes (right, image up, forward) of a spec.
fn axes(spec: &ProjectionSpec) -> (DVec3, [DVec3; 3]) {
    let (frame, tilt) = match spec {
        ProjectionSpec::MappedFisheye { frame, .. } => (frame, None),
        ProjectionSpec::DomeMaster { frame, tilt, .. } => (frame, Some(*tilt)),
        _ => unreachable!(),
    };
    let Some(tilt) = tilt else {
        let z = (frame.look_at - frame.position).normalize();
        let x = z.cross(frame.up).normalize();
        return (frame.position, [x, x.cross(z), z]);
    };
    let zenith = frame.up.normalize();
    let v = frame.look_at - frame.position;
    let front = (v - v.dot(zenith) * zenith).normalize();
    let right = front.cross(zenith);
    let (s, c) = tilt.to_radians().sin_cos();
    (
        frame.position,
        [right, s * zenith - c * front, c * zenith + s * front],
    )
}

/// The direction pixel `pixel` of a `w` x `h` image sees, from the closed forms; `None`
/// outside the image circle.
fn expected_direction(spec: &ProjectionSpec, w: f64, h: f64, pixel: DVec2) -> Option<DVec3> {
    let c = DVec2::new(pixel.x - w / 2.0, h / 2.0 - pixel.y);
    let (fov, lens) = match spec {
        ProjectionSpec::MappedFisheye { fov, lens, .. } => (*fov, *lens),
        ProjectionSpec::DomeMaster { fov, .. } => (*fov, FisheyeLens::default()),
        _ => unreachable!(),
    };
    let half = (fov / 2.0).to_radians();
    let (theta, azimuth) = match (lens.mapping, lens.fit) {
        (FisheyeMapping::Polynomial(k), FisheyeFit::Sensor(sensor)) => {
            let p = c * sensor_mm(&sensor, w, h);
            let theta = cycles_theta(&k, p.length());
            if theta.abs() > half {
                return None;
            }
            (theta, p)
        }
        (mapping, FisheyeFit::Sensor(sensor)) => {
            let p = c * sensor_mm(&sensor, w, h);
            let f = sensor.lens.unwrap();
            if p.length() > f * classic(mapping, half) {
                return None;
            }
            (classic_inverse(mapping, p.length() / f), p)
        }
        (mapping, fit) => {
            let radii = match fit {
                FisheyeFit::Inscribed => DVec2::splat(w.min(h) / 2.0),
                FisheyeFit::Fill => DVec2::new(w / 2.0, h / 2.0),
                FisheyeFit::Diagonal => DVec2::splat((w * w + h * h).sqrt() / 2.0),
                FisheyeFit::Sensor(_) => unreachable!(),
            };
            let s = c / radii;
            if s.length() > 1.0 {
                return None;
            }
            (
                classic_inverse(mapping, s.length() * classic(mapping, half)),
                s,
            )
        }
    };
    let phi = azimuth.y.atan2(azimuth.x);
    let (_, [x, y, z]) = axes(spec);
    Some(theta.sin() * (phi.cos() * x + phi.sin() * y) + theta.cos() * z)
}

fn classic_mapping() -> impl Strategy<Value = (FisheyeMapping, f64)> {
    prop_oneof![
        (1.0..=360.0).prop_map(|fov| (FisheyeMapping::Equidistant, fov)),
        (1.0..=360.0).prop_map(|fov| (FisheyeMapping::Equisolid, fov)),
        (1.0..350.0).prop_map(|fov| (FisheyeMapping::Stereographic, fov)),
        (1.0..=180.0).prop_map(|fov| (FisheyeMapping::Orthographic, fov)),
    ]
}

fn sensor(lens: Option<f64>) -> impl Strategy<Value = Sensor> {
    (
        5.0..50.0,
        5.0..50.0,
        0usize..3,
        prop_oneof![
            Just([1.0, 1.0]),
            (0.5..2.0, 0.5..2.0).prop_map(|(a, b)| [a, b])
        ],
    )
        .prop_map(move |(width, height, fit, pixel_aspect)| Sensor {
            width,
            height,
            fit: [SensorFit::Auto, SensorFit::Horizontal, SensorFit::Vertical][fit],
            pixel_aspect,
            lens,
        })
}

/// Fisheyes of every mapping and fit, and dome masters.
fn fisheye_spec() -> impl Strategy<Value = ProjectionSpec> {
    let fit = prop_oneof![
        Just(FisheyeFit::Inscribed),
        Just(FisheyeFit::Fill),
        Just(FisheyeFit::Diagonal),
        (2.0..30.0)
            .prop_flat_map(|lens| sensor(Some(lens)))
            .prop_map(FisheyeFit::Sensor),
    ];
    let classic = (frame(), classic_mapping(), fit).prop_map(|(frame, (mapping, fov), fit)| {
        ProjectionSpec::MappedFisheye {
            frame,
            fov,
            lens: FisheyeLens { mapping, fit },
        }
    });
    // theta(r) = -(k0 + k1 r + ...): k1 sets about 2 to 8 degrees per mm, small higher terms.
    let k = (
        -0.01..=0.0,
        -0.15..-0.03,
        -1e-3..1e-3,
        -1e-4..1e-4,
        -1e-6..1e-6,
    )
        .prop_map(|(a, b, c, d, e)| [a, b, c, d, e]);
    let polynomial = (frame(), 10.0..=360.0, k, sensor(None)).prop_map(|(frame, fov, k, s)| {
        ProjectionSpec::MappedFisheye {
            frame,
            fov,
            lens: FisheyeLens {
                mapping: FisheyeMapping::Polynomial(k),
                fit: FisheyeFit::Sensor(s),
            },
        }
    });
    let dome = (frame(), 10.0..=360.0, -90.0..=90.0)
        .prop_map(|(frame, fov, tilt)| ProjectionSpec::DomeMaster { frame, fov, tilt });
    prop_oneof![classic, polynomial, dome]
}

/// Builds `spec`, skipping polynomials that are refused as non-monotone over the image.
fn build(spec: &ProjectionSpec, size: (u32, u32)) -> Option<Box<dyn Projection>> {
    match spec.build(size.0, size.1) {
        Ok(projection) => Some(projection),
        Err(e) if e.message.starts_with("fisheye polynomial") => None,
        Err(e) => panic!("{spec:?}: {e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    /// A pixel's ray is the closed form's direction (1e-12), from the eye, and the closed
    /// form sees nothing exactly where the projection sees nothing (away from the edge).
    #[test]
    fn rays_follow_the_closed_forms(
        spec in fisheye_spec(),
        size in (1u32..300, 1u32..300),
        fraction in (0.0..1.0, 0.0..1.0),
    ) {
        let Some(projection) = build(&spec, size) else { return Ok(()); };
        let (w, h) = (f64::from(size.0), f64::from(size.1));
        let pixel = DVec2::new(fraction.0 * w, fraction.1 * h);
        let expected = expected_direction(&spec, w, h, pixel);
        let ray = projection.ray(pixel);
        match (ray, expected) {
            (Some(ray), Some(d)) => {
                prop_assert!((ray.direction - d).length() < 1e-9, "{spec:?} {pixel}: {} vs {d}", ray.direction);
                prop_assert_eq!(ray.origin, axes(&spec).0);
            }
            (None, None) => {}
            (ray, expected) => {
                // Only on the outline itself may the two roundings differ.
                let nudged = [0.999, 1.001].map(|s| {
                    let c = DVec2::new(w, h) / 2.0;
                    expected_direction(&spec, w, h, c + (pixel - c) * s).is_some()
                });
                prop_assert!(nudged[0] != nudged[1], "{spec:?} {pixel}: {ray:?} vs {expected:?}");
            }
        }
    }

    /// Point -> pixel -> ray through the point (1e-9 relative, and the closed form's ray
    /// there points at it); a point at most one image, and one wherever it is within fov/2
    /// of the axis (the classic mappings and the dome master).
    #[test]
    fn projected_points_lie_on_their_rays(
        spec in fisheye_spec(),
        size in (1u32..300, 1u32..300),
        point in vec3(20.0),
    ) {
        let Some(projection) = build(&spec, size) else { return Ok(()); };
        let mut images = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        prop_assert!(images.len() <= 1);
        for image in &images {
            let ray = projection.ray(image.pixel);
            prop_assert!(ray.is_some(), "{spec:?}: no ray at {}", image.pixel);
            let error = (ray.unwrap().at(image.t) - point).length();
            prop_assert!(error <= 1e-9 * (1.0 + point.length() + axes(&spec).0.length()),
                "{spec:?}: {point} missed by {error}");
        }
        // Seen by the closed form, well inside: the direction to the point must have an image.
        let (origin, [_, _, z]) = axes(&spec);
        let offset = point - origin;
        prop_assume!(offset.length() > 1e-6 && offset.angle_between(z) < PI - 1e-3);
        let half_fov = match &spec {
            ProjectionSpec::MappedFisheye { fov, lens, .. } => {
                (!matches!(lens.mapping, FisheyeMapping::Polynomial(_))).then_some(*fov)
            }
            ProjectionSpec::DomeMaster { fov, .. } => Some(*fov),
            _ => None,
        }
        .map(|fov| (fov / 2.0).to_radians());
        if let Some(half_fov) = half_fov {
            if offset.angle_between(z) < half_fov - 1e-6 {
                prop_assert_eq!(images.len(), 1, "{:?} lost {}", spec, point);
            }
        }
        if let Some(image) = images.first() {
            let (w, h) = (f64::from(size.0), f64::from(size.1));
            let d = expected_direction(&spec, w, h, image.pixel);
            prop_assert!(d.is_some());
            let (d, to_point) = (d.unwrap(), offset.normalize());
            prop_assert!(d.dot(to_point) > 0.0 && d.cross(to_point).length() < 1e-9, "{spec:?}: {d} vs {to_point}");
        }
    }

    /// Pixel -> ray -> pixel: a point on the ray of a pixel inside the circle (its angle
    /// short of 180 degrees, where a 360-degree fisheye is ambiguous) projects back there.
    #[test]
    fn rays_project_back_to_their_pixels(
        spec in fisheye_spec(),
        size in (1u32..300, 1u32..300),
        fraction in (0.0..1.0, 0.0..1.0),
        t in 0.01..100.0,
    ) {
        let Some(projection) = build(&spec, size) else { return Ok(()); };
        let (w, h) = (f64::from(size.0), f64::from(size.1));
        let pixel = DVec2::new(fraction.0 * w, fraction.1 * h);
        let Some(ray) = projection.ray(pixel) else { return Ok(()); };
        let (_, [_, _, z]) = axes(&spec);
        prop_assume!(ray.direction.angle_between(z) < PI - 0.02);
        let mut images = Vec::new();
        projection.inverse().unwrap().project(ray.at(t), &mut images);
        prop_assert_eq!(images.len(), 1, "{:?} {}", spec, pixel);
        let back = images[0];
        prop_assert!((back.pixel - pixel).length() <= 1e-9 * (1.0 + w.max(h)), "{spec:?}: {pixel} -> {}", back.pixel);
        prop_assert!((back.t - t).abs() <= 1e-9 * (1.0 + t));
    }
}

/// Closed forms at chosen angles, written out: a point theta off the axis of a 180-degree
/// fisheye on a 400 x 400 image lands at radius 200 g(theta) / g(90 degrees).
#[test]
fn classic_radii_at_fov_180() {
    let frame = CameraFrame {
        position: DVec3::ZERO,
        look_at: DVec3::NEG_Z,
        up: DVec3::Y,
    };
    /// A mapping's image radius over the circle's, as a function of theta.
    type Normalised = fn(f64) -> f64;
    let cases: [(FisheyeMapping, Normalised); 4] = [
        (FisheyeMapping::Equidistant, |t| t / (PI / 2.0)),
        (FisheyeMapping::Equisolid, |t| {
            2.0 * (t / 2.0).sin() / (2.0 * (PI / 4.0).sin())
        }),
        (FisheyeMapping::Stereographic, |t| (t / 2.0).tan()),
        (FisheyeMapping::Orthographic, f64::sin),
    ];
    for (mapping, normalised) in cases {
        let spec = ProjectionSpec::MappedFisheye {
            frame,
            fov: 180.0,
            lens: FisheyeLens {
                mapping,
                fit: FisheyeFit::Inscribed,
            },
        };
        let projection = spec.build(400, 400).unwrap();
        for degrees in [10.0f64, 45.0, 80.0] {
            let theta = degrees.to_radians();
            // theta to the right of the axis, 3 units away.
            let point = 3.0 * DVec3::new(theta.sin(), 0.0, -theta.cos());
            let mut out = Vec::new();
            projection.inverse().unwrap().project(point, &mut out);
            let expected = DVec2::new(200.0 + 200.0 * normalised(theta), 200.0);
            assert!(
                (out[0].pixel - expected).length() < 1e-10,
                "{mapping:?} {degrees}: {} vs {expected}",
                out[0].pixel
            );
        }
    }
}

/// Cycles' default lens polynomial on its default 36 mm sensor at 360 x 240: a pixel d
/// pixels right of the centre is 0.1 d mm out and sees theta(0.1 d) to the right.
#[test]
fn cycles_polynomial_on_its_sensor() {
    let k = [
        -1.1735143712967577e-05,
        -0.019988736953434998,
        -3.3525322965709175e-06,
        3.099275275886036e-06,
        -2.6064646454854524e-08,
    ];
    let spec = ProjectionSpec::MappedFisheye {
        frame: CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        },
        fov: 180.0,
        lens: FisheyeLens {
            mapping: FisheyeMapping::Polynomial(k),
            fit: FisheyeFit::Sensor(Sensor {
                width: 36.0,
                height: 24.0,
                fit: SensorFit::Auto,
                pixel_aspect: [1.0, 1.0],
                lens: None,
            }),
        },
    };
    let projection = spec.build(360, 240).unwrap();
    for d in [7.0, 60.0, 179.0] {
        let theta = cycles_theta(&k, 0.1 * d);
        let ray = projection.ray(DVec2::new(180.0 + d, 120.0)).unwrap();
        let expected = DVec3::new(theta.sin(), 0.0, -theta.cos());
        assert!((ray.direction - expected).length() < 1e-12, "{d}");
    }
    // Its 50 mm-like view is about 40 degrees across the width.
    let edge = cycles_theta(&k, 18.0).to_degrees();
    assert!((edge - 20.0).abs() < 0.5, "{edge}");
}
