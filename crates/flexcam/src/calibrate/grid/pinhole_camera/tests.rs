use proptest::prelude::*;

use super::*;
use crate::projection::flexible::projector_grid::tests::perspective_volume as perspective;
use crate::projection::flexible::projector_grid::GridInterpolation;

/// A 4:3 image, v up in a right-handed world, the prior's focal length 0.9.
const SHAPE: ImageShape = ImageShape {
    aspect: 4.0 / 3.0,
    handedness: 1.0,
    focal: 0.9,
};

/// A camera of `SHAPE`'s image at `eye` looking at `target` (world up +y), turned by `roll`
/// radians about its view, with the focal length `focal` and the handedness `handedness`.
fn camera(eye: DVec3, target: DVec3, roll: f64, focal: f64, handedness: f64) -> PinholeCamera {
    let forward = (target - eye).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let down = forward.cross(right);
    let turn = DMat3::from_axis_angle(forward, roll);
    let (right, down) = (turn * right, turn * down);
    PinholeCamera {
        focal,
        rotation: DMat3::from_cols(right, down, forward).transpose(),
        eye,
        principal: DVec2::ZERO,
        aspect: SHAPE.aspect,
        handedness,
        focal_from_prior: false,
        moved_start: false,
    }
}

/// The unit direction of the ray of `truth` through `uv`.
fn ray(truth: &PinholeCamera, uv: DVec2) -> DVec3 {
    truth.direction(uv).normalize()
}

/// Correspondences of `truth` at the image positions `uvs`, each point on the ray at the
/// distance `distance(k, ray)`.
fn seen(
    truth: &PinholeCamera,
    uvs: &[DVec2],
    mut distance: impl FnMut(usize, DVec3) -> f64,
) -> Vec<Correspondence> {
    uvs.iter()
        .enumerate()
        .map(|(k, uv)| {
            let d = ray(truth, *uv);
            Correspondence {
                uv: *uv,
                point: truth.eye + distance(k, d) * d,
            }
        })
        .collect()
}

/// Points of `truth` on the plane through `on_plane` with normal `normal`.
fn on_plane(
    truth: &PinholeCamera,
    uvs: &[DVec2],
    on_plane: DVec3,
    normal: DVec3,
) -> Vec<Correspondence> {
    seen(truth, uvs, |_, d| {
        (on_plane - truth.eye).dot(normal) / d.dot(normal)
    })
}

/// Image positions on a 5 x 4 lattice inside [0.2, 0.8]^2, slightly jittered.
fn lattice() -> Vec<DVec2> {
    (0..20)
        .map(|k| {
            let (i, j) = ((k % 5) as f64, (k / 5) as f64);
            let jitter = 0.01 * ((k * 7 % 5) as f64 - 2.0);
            DVec2::new(0.2 + 0.15 * i + jitter, 0.2 + 0.2 * j - jitter)
        })
        .collect()
}

/// The largest distance in the image (image widths) between where `fitted` sees the points
/// and their positions.
fn worst_reprojection(fitted: &PinholeCamera, data: &[Correspondence]) -> f64 {
    data.iter()
        .map(|c| {
            let uv = fitted.project(c.point).expect("a point behind the camera");
            let d = uv - c.uv;
            DVec2::new(d.x, d.y / SHAPE.aspect).length()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_tilted_plane_determines_focal_length_and_pose() {
    let truth = camera(DVec3::new(1.0, 4.0, 8.0), DVec3::ZERO, 0.1, 1.3, 1.0);
    // The floor, seen from 26 degrees above it.
    let data = on_plane(&truth, &lattice(), DVec3::ZERO, DVec3::Y);
    let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
    assert!(!fitted.focal_from_prior());
    assert!((fitted.focal() - 1.3).abs() < 1e-9, "{fitted:?}");
    assert!((fitted.eye() - truth.eye).length() < 1e-8, "{fitted:?}");
    assert!(worst_reprojection(&fitted, &data) < 1e-12);
}

#[test]
fn a_plane_seen_face_on_keeps_the_priors_focal_length() {
    let truth = camera(DVec3::new(0.0, 0.0, 6.0), DVec3::ZERO, 0.3, 1.3, 1.0);
    let data = on_plane(&truth, &lattice(), DVec3::ZERO, DVec3::Z);
    let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
    assert!(fitted.focal_from_prior(), "{fitted:?}");
    assert_eq!(fitted.focal(), SHAPE.focal);
    // The image is the plane's, scaled: the eye on the view axis, nearer by 0.9 / 1.3.
    let eye = DVec3::new(0.0, 0.0, 6.0 * 0.9 / 1.3);
    assert!((fitted.eye() - eye).length() < 1e-8, "{fitted:?}");
    assert!(worst_reprojection(&fitted, &data) < 1e-12);
}

#[test]
fn points_on_one_line_determine_no_camera() {
    let uvs: Vec<DVec2> = (0..12)
        .map(|k| DVec2::splat(0.2 + 0.05 * k as f64))
        .collect();
    // Points along one world line (and, below, all at one point).
    let a = DVec3::new(-1.0, 0.0, 0.0);
    let data: Vec<Correspondence> = (0..12)
        .map(|k| Correspondence {
            uv: uvs[k],
            point: a + DVec3::new(0.2 * k as f64, 0.05 * k as f64, 0.0),
        })
        .collect();
    assert_eq!(
        PinholeCamera::fit(&data, SHAPE),
        Err(Undetermined::PointsOnOneLine)
    );
    let same: Vec<Correspondence> = data
        .iter()
        .map(|c| Correspondence { point: a, ..*c })
        .collect();
    assert_eq!(
        PinholeCamera::fit(&same, SHAPE),
        Err(Undetermined::PointsOnOneLine)
    );
}

#[test]
fn a_plane_seen_edge_on_determines_no_camera() {
    let truth = camera(DVec3::new(1.0, 4.0, 8.0), DVec3::ZERO, 0.0, 1.0, 1.0);
    // The plane through the eye and the image's horizontal centre line.
    let uvs: Vec<DVec2> = (0..12)
        .map(|k| DVec2::new(0.1 + 0.07 * k as f64, 0.5))
        .collect();
    let data = seen(&truth, &uvs, |k, _| 3.0 + (k % 4) as f64);
    assert_eq!(
        PinholeCamera::fit(&data, SHAPE),
        Err(Undetermined::ImageOnOneLine)
    );
}

#[test]
fn three_points_are_too_few() {
    let truth = camera(DVec3::new(1.0, 4.0, 8.0), DVec3::ZERO, 0.0, 1.0, 1.0);
    let data = on_plane(&truth, &lattice()[..3], DVec3::ZERO, DVec3::Y);
    assert_eq!(PinholeCamera::fit(&data, SHAPE), Err(Undetermined::TooFew));
}

#[test]
fn mirrored_points_off_a_plane_get_the_mirrored_camera() {
    let truth = camera(DVec3::new(-2.0, 3.0, 7.0), DVec3::ZERO, -0.2, 1.1, -1.0);
    let data = seen(&truth, &lattice(), |k, _| 5.0 + (k * 3 % 7) as f64);
    let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
    assert_eq!(fitted.handedness, -1.0);
    assert!((fitted.eye() - truth.eye).length() < 1e-8, "{fitted:?}");
    assert!(worst_reprojection(&fitted, &data) < 1e-12);
}

#[test]
fn a_perspective_priors_shape_is_its_aspect_and_field_of_view() {
    // 60 degrees across, aspect 3:4 (height over width).
    let prior = ProjectorGrid::sample(
        &perspective(60.0, [1.0, 40.0]),
        (5, 5),
        GridInterpolation::Bilinear,
    )
    .unwrap();
    let shape = ImageShape::of_prior(&prior);
    assert!((shape.aspect - 4.0 / 3.0).abs() < 1e-12, "{shape:?}");
    assert_eq!(shape.handedness, 1.0);
    let focal = 1.0 / (2.0 * 30f64.to_radians().tan());
    assert!((shape.focal - focal).abs() < 1e-12, "{shape:?}");
}

/// A random camera and image positions: eye 4 to 12 from the origin in any direction above
/// the floor's side, looking near the origin, 30 to 80 degrees across, any roll.
fn camera_and_uvs() -> impl Strategy<Value = (PinholeCamera, Vec<DVec2>)> {
    (
        (0.0..std::f64::consts::TAU, 0.1f64..1.4, 4.0f64..12.0),
        (-0.5f64..0.5, -0.5f64..0.5, -0.5f64..0.5),
        (-3.0f64..3.0, 30.0f64..80.0),
        prop::collection::vec((0.2f64..0.8, 0.2f64..0.8), 6..40),
    )
        .prop_map(
            |((azimuth, elevation, distance), (x, y, z), (roll, fov), uvs)| {
                let eye = distance
                    * DVec3::new(
                        azimuth.sin() * elevation.cos(),
                        elevation.sin(),
                        azimuth.cos() * elevation.cos(),
                    );
                let focal = 1.0 / (2.0 * (0.5 * fov).to_radians().tan());
                let truth = camera(eye, DVec3::new(x, y, z), roll, focal, 1.0);
                (
                    truth,
                    uvs.into_iter().map(|(u, v)| DVec2::new(u, v)).collect(),
                )
            },
        )
}

/// Whether `fitted` is `truth` (eye to 1e-6 of its distance, focal length to 1e-7) and
/// meets `data` to 1e-9 image widths.
fn recovered(fitted: &PinholeCamera, truth: &PinholeCamera, data: &[Correspondence]) -> bool {
    let distance = truth.eye.length();
    (fitted.eye() - truth.eye).length() < 1e-6 * distance
        && (fitted.focal() / truth.focal - 1.0).abs() < 1e-7
        && !fitted.focal_from_prior()
        && worst_reprojection(fitted, data) < 1e-9
}

/// Unit vectors at 15 to 55 degrees from `axis`.
fn tilted_from(axis: DVec3, tilt: f64, turn: f64) -> DVec3 {
    let side = axis.any_orthonormal_vector();
    let towards = DMat3::from_axis_angle(axis, turn) * side;
    (axis * tilt.cos() + towards * tilt.sin()).normalize()
}

/// A non-collinear check of the generated image positions: the random ones may fall on a
/// line (rarely), and then no camera is determined.
fn spread(uvs: &[DVec2]) -> bool {
    let n = uvs.len() as f64;
    let mean = uvs.iter().copied().sum::<DVec2>() / n;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for p in uvs {
        let d = *p - mean;
        (xx, xy, yy) = (xx + d.x * d.x, xy + d.x * d.y, yy + d.y * d.y);
    }
    (xx * yy - xy * xy) / (n * n) > 1e-4
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn a_camera_comes_back_from_exact_points_on_a_tilted_plane(
        (truth, uvs) in camera_and_uvs(),
        tilt in 15f64..55.0,
        turn in 0.0..std::f64::consts::TAU,
        depth in 0.5f64..1.5,
    ) {
        prop_assume!(uvs.len() >= 4 && spread(&uvs));
        let forward = truth.rotation.row(2);
        let normal = tilted_from(-forward, tilt.to_radians(), turn);
        let centre = truth.eye + depth * truth.eye.length() * forward;
        let data = on_plane(&truth, &uvs, centre, normal);
        let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
        prop_assert!(recovered(&fitted, &truth, &data), "{fitted:?}\n{truth:?}");
    }

    #[test]
    fn a_camera_comes_back_from_exact_points_off_a_plane(
        (truth, uvs) in camera_and_uvs(),
        depths in prop::collection::vec(0.3f64..1.5, 40),
    ) {
        prop_assume!(spread(&uvs));
        let distance = truth.eye.length();
        let data = seen(&truth, &uvs, |k, _| depths[k] * distance);
        let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
        prop_assert!(recovered(&fitted, &truth, &data), "{fitted:?}\n{truth:?}");
    }
}

/// `truth` cropped off centre: its principal point moved by `offset` (fractions of the
/// image's width and height, each 10 to 25 % either way).
fn cropped(truth: PinholeCamera, offset: DVec2) -> PinholeCamera {
    PinholeCamera {
        principal: DVec2::new(offset.x, -offset.y / SHAPE.aspect),
        ..truth
    }
}

/// Offsets of 10 to 25 % of the image's width and height, each either way.
fn offsets() -> impl Strategy<Value = DVec2> {
    (0.1f64..0.25, 0.1f64..0.25, any::<bool>(), any::<bool>()).prop_map(|(x, y, left, down)| {
        DVec2::new(if left { -x } else { x }, if down { -y } else { y })
    })
}

#[test]
fn a_centred_camera_has_no_principal_point_to_report() {
    let truth = camera(DVec3::new(-2.0, 3.0, 7.0), DVec3::ZERO, -0.2, 1.1, 1.0);
    let data = seen(&truth, &lattice(), |k, _| 5.0 + (k * 3 % 7) as f64);
    let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
    assert_eq!(fitted.principal_point(), None);
    let off = cropped(truth, DVec2::new(0.2, -0.15));
    let data = seen(&off, &lattice(), |k, _| 5.0 + (k * 3 % 7) as f64);
    let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
    let uv = fitted.principal_point().unwrap();
    assert!((uv - DVec2::new(0.7, 0.35)).length() < 1e-9, "{uv}");
}

/// Below `PRINCIPAL_MIN_POINTS` exact points of a cropped camera the principal point is not
/// fitted (the centred camera's residual shows the crop); at it, it is recovered.
#[test]
fn a_principal_point_needs_nine_points() {
    let off = cropped(
        camera(DVec3::new(-2.0, 3.0, 7.0), DVec3::ZERO, -0.2, 1.1, 1.0),
        DVec2::new(0.2, -0.15),
    );
    let all = seen(&off, &lattice(), |k, _| 5.0 + (k * 3 % 7) as f64);
    assert!(all.len() > super::PRINCIPAL_MIN_POINTS);
    let few = &all[..super::PRINCIPAL_MIN_POINTS - 1];
    assert_eq!(
        PinholeCamera::fit(few, SHAPE).unwrap().principal_point(),
        None
    );
    let enough = &all[..super::PRINCIPAL_MIN_POINTS];
    let uv = PinholeCamera::fit(enough, SHAPE)
        .unwrap()
        .principal_point()
        .unwrap();
    assert!((uv - DVec2::new(0.7, 0.35)).length() < 1e-9, "{uv}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn a_cropped_camera_comes_back_from_exact_points_off_a_plane(
        (truth, uvs) in camera_and_uvs(),
        offset in offsets(),
        depths in prop::collection::vec(0.3f64..1.5, 40),
    ) {
        prop_assume!(spread(&uvs) && uvs.len() >= super::PRINCIPAL_MIN_POINTS);
        let truth = cropped(truth, offset);
        let distance = truth.eye.length();
        let data = seen(&truth, &uvs, |k, _| depths[k] * distance);
        let fitted = PinholeCamera::fit(&data, SHAPE).unwrap();
        prop_assert!(recovered(&fitted, &truth, &data), "{fitted:?}\n{truth:?}");
        let uv = fitted.principal_point().unwrap();
        let wanted = DVec2::new(0.5 + offset.x, 0.5 + offset.y);
        prop_assert!((uv - wanted).length() < 1e-7, "{uv} against {wanted}");
    }
}

#[test]
fn the_fit_says_when_it_keeps_the_priors_focal_length() {
    let prior = ProjectorGrid::sample(
        &perspective(60.0, [1.0, 40.0]),
        (3, 3),
        GridInterpolation::Bilinear,
    )
    .unwrap();
    let truth = camera(DVec3::new(0.0, 0.0, 6.0), DVec3::ZERO, 0.3, 1.3, 1.0);
    let face_on = on_plane(&truth, &lattice(), DVec3::ZERO, DVec3::Z);
    let (_, report) = super::super::fit_with(
        &prior,
        &face_on,
        crate::projection::flexible::Starts::Pinhole,
    )
    .unwrap();
    assert!(report.focal_from_prior, "{report:?}");
    assert!(report.rms_angle_deg < 1e-6, "{report:?}");
    let warning = report.warning().unwrap();
    assert!(warning.contains("focal length"), "{warning}");
    // Tilted, the plane determines it, and there is nothing to say.
    let floor = on_plane(
        &truth,
        &lattice(),
        DVec3::new(0.0, -1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.6).normalize(),
    );
    let (_, report) =
        super::super::fit_with(&prior, &floor, crate::projection::flexible::Starts::Pinhole)
            .unwrap();
    assert!(
        !report.focal_from_prior && report.warning().is_none(),
        "{report:?}"
    );
    assert!(report.rms_angle_deg < 1e-6, "{report:?}");
}
