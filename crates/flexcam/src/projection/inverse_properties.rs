//! Property tests of the inverses: for random frames, parameters and image sizes, every
//! projection with an inverse is consistent with its rays both ways.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{CameraFrame, ImagePoint, Projection, ProjectionSpec};

pub(super) fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// Frames with a view direction of length >= 0.1 and an up hint at least ~6 degrees away
/// from it.
pub(super) fn frame() -> impl Strategy<Value = CameraFrame> {
    (vec3(5.0), vec3(1.0), vec3(1.0)).prop_filter_map("degenerate frame", |(position, view, up)| {
        let forward = view.try_normalize()?;
        let up_hint = up.try_normalize()?;
        if view.length() < 0.1 || forward.cross(up_hint).length() < 0.1 {
            return None;
        }
        Some(CameraFrame {
            position,
            look_at: position + 3.0 * view,
            up,
        })
    })
}

/// Every projection kind with an inverse, away from the extreme angles where tan blows up
/// (perspective fov and cylindrical v_fov up to 170 degrees).
fn invertible_spec() -> impl Strategy<Value = ProjectionSpec> {
    frame().prop_flat_map(|frame| {
        prop_oneof![
            (1.0..170.0).prop_map(move |fov| ProjectionSpec::Perspective { frame, fov }),
            (0.1..20.0).prop_map(move |width| ProjectionSpec::Orthographic { frame, width }),
            (1.0..=360.0).prop_map(move |fov| ProjectionSpec::Fisheye { frame, fov }),
            (1.0..=360.0, 1.0..=180.0).prop_map(move |(h_fov, v_fov)| {
                ProjectionSpec::Equirectangular {
                    frame,
                    h_fov,
                    v_fov,
                }
            }),
            (1.0..=360.0, 1.0..170.0).prop_map(move |(h_fov, v_fov)| {
                ProjectionSpec::Cylindrical {
                    frame,
                    h_fov,
                    v_fov,
                }
            }),
        ]
    })
}

fn frame_of(spec: &ProjectionSpec) -> CameraFrame {
    match spec {
        ProjectionSpec::Perspective { frame, .. }
        | ProjectionSpec::Orthographic { frame, .. }
        | ProjectionSpec::Fisheye { frame, .. }
        | ProjectionSpec::Equirectangular { frame, .. }
        | ProjectionSpec::Cylindrical { frame, .. } => *frame,
        ProjectionSpec::Opencv { .. }
        | ProjectionSpec::OpencvFisheye { .. }
        | ProjectionSpec::Ods { .. }
        | ProjectionSpec::Vr180 { .. }
        | ProjectionSpec::MappedFisheye { .. }
        | ProjectionSpec::DomeMaster { .. }
        | ProjectionSpec::Trilinear(_)
        | ProjectionSpec::ExactBall(_)
        | ProjectionSpec::Flexible(_) => {
            unreachable!(
                "not generated (calibrated_properties, stereo_properties, fisheye_properties)"
            )
        }
    }
}

/// Whether `point` is in the domain where `spec` must image it, decided from the frame alone
/// (independently of the implementation), with a margin around the excluded sets.
fn must_be_imaged(spec: &ProjectionSpec, point: DVec3) -> bool {
    let frame = frame_of(spec);
    let forward = (frame.look_at - frame.position).normalize();
    let offset = point - frame.position;
    let distance = offset.length();
    match spec {
        ProjectionSpec::Perspective { .. } => offset.dot(forward) > 1e-6 * distance,
        ProjectionSpec::Orthographic { .. } => offset.dot(forward) >= 0.0,
        ProjectionSpec::Fisheye { fov, .. } => {
            let off_axis = offset.angle_between(forward).to_degrees();
            distance > 1e-6 && off_axis < 0.5 * fov - 1e-6 && off_axis < 180.0 - 1e-6
        }
        ProjectionSpec::Equirectangular { .. } => distance > 1e-6,
        ProjectionSpec::Cylindrical { .. } => {
            let true_up = forward.cross(frame.up).normalize().cross(forward);
            let vertical = offset.dot(true_up);
            (distance * distance - vertical * vertical).sqrt() > 1e-6 * distance
        }
        ProjectionSpec::Opencv { .. }
        | ProjectionSpec::OpencvFisheye { .. }
        | ProjectionSpec::Ods { .. }
        | ProjectionSpec::Vr180 { .. }
        | ProjectionSpec::MappedFisheye { .. }
        | ProjectionSpec::DomeMaster { .. }
        | ProjectionSpec::Trilinear(_)
        | ProjectionSpec::ExactBall(_)
        | ProjectionSpec::Flexible(_) => false,
    }
}

fn scale(projection: &dyn Projection, point: DVec3, image: &ImagePoint) -> f64 {
    let origin = projection
        .ray(image.pixel)
        .map_or(DVec3::ZERO, |r| r.origin);
    1.0 + point.length() + origin.length()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Random points: every point in the visible domain has an image, and every image's ray
    /// reaches the point at the reported t.
    #[test]
    fn projected_points_lie_on_their_rays(
        spec in invertible_spec(),
        size in (1u32..400, 1u32..400),
        point in vec3(20.0),
    ) {
        let projection = spec.build(size.0, size.1).unwrap();
        let mut images = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        if must_be_imaged(&spec, point) {
            prop_assert!(!images.is_empty(), "{} lost {point}", spec.kind());
        }
        for image in &images {
            let ray = projection.ray(image.pixel);
            prop_assert!(ray.is_some(), "{}: no ray at {}", spec.kind(), image.pixel);
            let ray = ray.unwrap();
            prop_assert!(image.t >= 0.0);
            let error = (ray.at(image.t) - point).length();
            let tolerance = 1e-9 * scale(projection.as_ref(), point, image);
            prop_assert!(error <= tolerance, "{}: {point} missed by {error}", spec.kind());
        }
    }

    /// Random pixels: the point at a random t of a pixel's ray projects back to that pixel
    /// and that t. Pixels keep 0.5% away from the image border (the 360-degree seam) and, for
    /// fisheyes, 1% inside the image circle (near it a 360 fisheye approaches its ambiguous
    /// point); equirectangular poles at v_fov = 180 are thus avoided too.
    #[test]
    fn rays_project_back_to_their_pixels(
        spec in invertible_spec(),
        size in (1u32..400, 1u32..400),
        fraction in (0.005..0.995, 0.005..0.995),
        t in 0.0..100.0,
    ) {
        let projection = spec.build(size.0, size.1).unwrap();
        let image_size = DVec2::new(f64::from(size.0), f64::from(size.1));
        let pixel = DVec2::new(fraction.0, fraction.1) * image_size;
        if let ProjectionSpec::Fisheye { .. } = spec {
            let radius = (pixel - 0.5 * image_size).length() / (0.5 * image_size.min_element());
            prop_assume!(radius <= 0.99);
        }
        let ray = projection.ray(pixel).unwrap();
        prop_assume!(t > 0.0 || matches!(spec, ProjectionSpec::Orthographic { .. }));
        let point = ray.at(t);
        let mut images = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        let back = images.iter().find(|image| {
            (image.pixel - pixel).length() <= 1e-9 * (1.0 + image_size.max_element())
        });
        prop_assert!(back.is_some(), "{}: {pixel} came back as {images:?}", spec.kind());
        let back_t = back.unwrap().t;
        let kind = spec.kind();
        prop_assert!((back_t - t).abs() <= 1e-9 * (1.0 + t), "{kind}: t {t} became {back_t}");
    }
}
