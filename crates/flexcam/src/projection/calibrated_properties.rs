//! Property tests of the calibrated lens models against OpenCV's formulas written out here
//! independently, the way `cv::projectPoints` and `cv::fisheye::projectPoints` evaluate them
//! (camera frame x right, y down, z forward; pixel centres at integers):
//! - round trips: a point in the valid image maps to a pixel whose ray passes through it, to
//!   1e-9 relative;
//! - the forward map agrees with the formulas, and every pixel centre's ray images back onto
//!   that pixel centre under them.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{
    CalibratedCamera, CalibrationSize, CameraFrame, ImagePoint, Intrinsics, KannalaBrandt, Opencv,
    Projection,
};

/// OpenCV's camera frame of `frame`, written out: z towards look_at, x = z x up (right),
/// y = z x x (down).
fn opencv_axes(frame: &CameraFrame) -> [DVec3; 3] {
    let z = (frame.look_at - frame.position).normalize();
    let x = z.cross(frame.up).normalize();
    let y = z.cross(x);
    [x, y, z]
}

/// OpenCV camera coordinates of world point `point`.
fn to_camera(frame: &CameraFrame, point: DVec3) -> DVec3 {
    let [x, y, z] = opencv_axes(frame);
    let d = point - frame.position;
    DVec3::new(d.dot(x), d.dot(y), d.dot(z))
}

/// The world point with OpenCV camera coordinates `camera`.
fn to_world(frame: &CameraFrame, camera: DVec3) -> DVec3 {
    let [x, y, z] = opencv_axes(frame);
    frame.position + camera.x * x + camera.y * y + camera.z * z
}

/// `cv::projectPoints` for one point (Z > 0), distortion [k1, k2, p1, p2, k3, k4, k5, k6].
fn project_points(camera: DVec3, k: &Intrinsics, d: &[f64; 8]) -> DVec2 {
    let x = camera.x / camera.z;
    let y = camera.y / camera.z;
    let r2 = x * x + y * y;
    let r4 = r2 * r2;
    let r6 = r4 * r2;
    let cdist = 1.0 + d[0] * r2 + d[1] * r4 + d[4] * r6;
    let icdist2 = 1.0 / (1.0 + d[5] * r2 + d[6] * r4 + d[7] * r6);
    let a1 = 2.0 * x * y;
    let a2 = r2 + 2.0 * x * x;
    let a3 = r2 + 2.0 * y * y;
    let xd = x * cdist * icdist2 + d[2] * a1 + d[3] * a2;
    let yd = y * cdist * icdist2 + d[2] * a3 + d[3] * a1;
    DVec2::new(xd * k.fx + k.cx, yd * k.fy + k.cy)
}

/// `cv::fisheye::projectPoints` for one point, with theta = atan2(sqrt(X^2 + Y^2), Z) (for
/// Z > 0 OpenCV's atan(r), r = sqrt(a^2 + b^2), a = X / Z, b = Y / Z, is the same angle).
fn fisheye_project_points(camera: DVec3, k: &Intrinsics, c: &[f64; 4]) -> DVec2 {
    let rho = (camera.x * camera.x + camera.y * camera.y).sqrt();
    let theta = if camera.z > 0.0 {
        (rho / camera.z).atan()
    } else {
        rho.atan2(camera.z)
    };
    let t2 = theta * theta;
    let t4 = t2 * t2;
    let t6 = t4 * t2;
    let t8 = t4 * t4;
    let theta_d = theta * (1.0 + c[0] * t2 + c[1] * t4 + c[2] * t6 + c[3] * t8);
    let scale = if rho > 1e-8 { theta_d / rho } else { 1.0 };
    let xd = camera.x * scale;
    let yd = camera.y * scale;
    DVec2::new(k.fx * xd + k.cx, k.fy * yd + k.cy)
}

fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// Frames with a view direction and an up hint at least ~6 degrees apart.
fn frame() -> impl Strategy<Value = CameraFrame> {
    (vec3(5.0), vec3(1.0), vec3(1.0)).prop_filter_map("degenerate frame", |(position, view, up)| {
        let forward = view.try_normalize()?;
        let hint = up.try_normalize()?;
        if view.length() < 0.1 || forward.cross(hint).length() < 0.1 {
            return None;
        }
        Some(CameraFrame {
            position,
            look_at: position + view,
            up,
        })
    })
}

/// An image size and intrinsics with focal lengths between 0.3 and 1.5 image widths and the
/// principal point within a tenth of the image of its centre.
fn calibration() -> impl Strategy<Value = ((u32, u32), Intrinsics)> {
    (16u32..200, 16u32..200).prop_flat_map(|(w, h)| {
        let (wf, hf) = (f64::from(w), f64::from(h));
        (
            0.3 * wf..1.5 * wf,
            0.9..1.1,
            -0.1 * wf..0.1 * wf,
            -0.1 * hf..0.1 * hf,
        )
            .prop_map(move |(fx, aspect, dx, dy)| {
                let k = Intrinsics {
                    fx,
                    fy: fx * aspect,
                    cx: 0.5 * wf - 0.5 + dx,
                    cy: 0.5 * hf - 0.5 + dy,
                };
                ((w, h), k)
            })
    })
}

/// Radial-tangential coefficients: the 5-coefficient form, or the rational 8-coefficient one.
fn distortion() -> impl Strategy<Value = [f64; 8]> {
    (
        -0.4..0.4,
        -0.1..0.1,
        -0.01..0.01,
        -0.01..0.01,
        -0.05..0.05,
        prop::option::of((-0.2..0.2, -0.05..0.05, -0.01..0.01)),
    )
        .prop_map(|(k1, k2, p1, p2, k3, rational)| {
            let (k4, k5, k6) = rational.unwrap_or((0.0, 0.0, 0.0));
            [k1, k2, p1, p2, k3, k4, k5, k6]
        })
}

fn fisheye_coefficients() -> impl Strategy<Value = [f64; 4]> {
    (-0.05..0.05, -0.01..0.01, -0.002..0.002, -0.0002..0.0002).prop_map(|(a, b, c, d)| [a, b, c, d])
}

fn camera(frame: CameraFrame, size: (u32, u32), intrinsics: Intrinsics) -> CalibratedCamera {
    CalibratedCamera {
        frame,
        intrinsics,
        size: CalibrationSize::SceneImage([size.0, size.1]),
    }
}

/// Checks that `projection` images `point` once, at `expected` (OpenCV pixel coordinates),
/// and that the ray of that pixel passes through the point, both to 1e-9 relative.
fn check_round_trip(
    projection: &dyn Projection,
    frame: &CameraFrame,
    point: DVec3,
    expected: DVec2,
) -> Result<(), TestCaseError> {
    let mut images: Vec<ImagePoint> = Vec::new();
    projection.inverse().unwrap().project(point, &mut images);
    prop_assert_eq!(images.len(), 1, "{} images of {}", images.len(), point);
    let image = images[0];
    let opencv_pixel = image.pixel - 0.5;
    let scale = expected.length().max(1.0);
    prop_assert!(
        (opencv_pixel - expected).length() <= 1e-9 * scale,
        "pixel {} vs the formula's {}",
        opencv_pixel,
        expected
    );
    let ray = projection
        .ray(image.pixel)
        .expect("the pixel of a seen point has a ray");
    let distance = (point - frame.position).length();
    let miss = (ray.at(image.t) - point).length();
    prop_assert!(
        miss <= 1e-9 * distance,
        "misses by {} at distance {}",
        miss,
        distance
    );
    Ok(())
}

/// Every pixel centre of a grid of at most 24 x 24 over the `(w, h)` image whose ray exists
/// images back onto that centre (to 1e-9 px) under `forward`, OpenCV's formulas from camera
/// coordinates to OpenCV pixels.
fn pixel_centres_image_back(
    projection: &dyn Projection,
    frame: &CameraFrame,
    (w, h): (u32, u32),
    forward: impl Fn(DVec3) -> DVec2,
) -> Result<(), TestCaseError> {
    for y in 0..h.min(24) {
        for x in 0..w.min(24) {
            let (u, v) = (x * w / w.min(24), y * h / h.min(24));
            let centre = DVec2::new(f64::from(u), f64::from(v));
            let Some(ray) = projection.ray(centre + 0.5) else {
                continue;
            };
            let imaged = forward(to_camera(frame, ray.at(3.0)));
            prop_assert!(
                (imaged - centre).length() < 1e-9,
                "{} -> {}",
                centre,
                imaged
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// point -> pixel -> ray through the point, for points within 90 % of the valid radius.
    #[test]
    fn opencv_round_trips(
        frame in frame(),
        ((w, h), k) in calibration(),
        d in distortion(),
        p in (-1.5f64..1.5, -1.5f64..1.5),
        depth in 0.1f64..50.0,
    ) {
        let projection = Opencv::new(&camera(frame, (w, h), k), d, w, h).unwrap();
        let p = DVec2::new(p.0, p.1);
        prop_assume!(p.length() < 0.9 * projection.valid_radius());
        let point = to_world(&frame, DVec3::new(p.x, p.y, 1.0) * depth);
        let expected = project_points(to_camera(&frame, point), &k, &d);
        check_round_trip(&projection, &frame, point, expected)?;
    }

    /// The same for the Kannala-Brandt fisheye, over the whole monotone range (up to 99 % of
    /// it), behind the camera too.
    #[test]
    fn kannala_brandt_round_trips(
        frame in frame(),
        ((w, h), k) in calibration(),
        c in fisheye_coefficients(),
        direction in vec3(1.0),
        depth in 0.1f64..50.0,
    ) {
        let projection = KannalaBrandt::new(&camera(frame, (w, h), k), c, w, h).unwrap();
        let direction = direction.try_normalize();
        prop_assume!(direction.is_some());
        let camera_direction = direction.unwrap();
        let theta = camera_direction.z.acos();
        prop_assume!(theta < 0.99 * projection.theta_max() && theta > 1e-6);
        let point = to_world(&frame, camera_direction * depth);
        let expected = fisheye_project_points(to_camera(&frame, point), &k, &c);
        check_round_trip(&projection, &frame, point, expected)?;
    }

    /// Every pixel centre of a small image (up to 24 x 24 of them) with a ray: the ray,
    /// imaged by the formulas, lands back on the pixel centre (OpenCV's integer
    /// coordinates), to 1e-9 pixels. The principal point always has a ray.
    #[test]
    fn opencv_pixels_match_project_points(
        frame in frame(),
        ((w, h), k) in calibration(),
        d in distortion(),
    ) {
        let projection = Opencv::new(&camera(frame, (w, h), k), d, w, h).unwrap();
        prop_assert!(projection.ray(DVec2::new(k.cx, k.cy) + 0.5).is_some());
        pixel_centres_image_back(&projection, &frame, (w, h), |camera| {
            project_points(camera, &k, &d)
        })?;
    }

    /// The same for the fisheye: every pixel centre inside the valid image.
    #[test]
    fn kannala_brandt_pixels_match_project_points(
        frame in frame(),
        ((w, h), k) in calibration(),
        c in fisheye_coefficients(),
    ) {
        let projection = KannalaBrandt::new(&camera(frame, (w, h), k), c, w, h).unwrap();
        pixel_centres_image_back(&projection, &frame, (w, h), |camera| {
            fisheye_project_points(camera, &k, &c)
        })?;
    }
}

/// A scaled calibration images as the calibration would at its own size, scaled by the
/// pixel edges: OpenCV pixel u at W0 is u' = (u + 0.5) W / W0 - 0.5 at W.
#[test]
fn calibration_size_scales_by_pixel_edges() {
    let frame = CameraFrame {
        position: DVec3::ZERO,
        look_at: DVec3::NEG_Z,
        up: DVec3::Y,
    };
    let k = Intrinsics {
        fx: 500.0,
        fy: 480.0,
        cx: 330.2,
        cy: 241.7,
    };
    let d = [-0.2, 0.05, 0.001, 0.002, 0.0, 0.0, 0.0, 0.0];
    let scaled = CalibratedCamera {
        frame,
        intrinsics: k,
        size: CalibrationSize::Given([640, 480]),
    };
    let projection = Opencv::new(&scaled, d, 200, 120).unwrap();
    let point = DVec3::new(0.7, -0.4, -2.0);
    let mut images = Vec::new();
    projection.inverse().unwrap().project(point, &mut images);
    let full = project_points(to_camera(&frame, point), &k, &d);
    let expected = (full + 0.5) * DVec2::new(200.0 / 640.0, 120.0 / 480.0) - 0.5;
    assert!(((images[0].pixel - 0.5) - expected).length() < 1e-12);
}
