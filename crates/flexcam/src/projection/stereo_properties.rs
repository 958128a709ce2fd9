//! Property tests of the stereo inverses (ods with and without pole merging, vr180): for
//! random frames, eye distances, merge latitudes, image sizes and points, every image's ray
//! passes through the point at the reported t, and each eye that must see a point (decided
//! here from the geometry alone) does; random pixels' points project back to their pixels.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::inverse_properties::{frame, vec3};
use super::{CameraBasis, CameraFrame, ProjectionSpec};

fn stereo_spec() -> impl Strategy<Value = ProjectionSpec> {
    (frame(), 0.001..2.0f64).prop_flat_map(|(frame, ipd)| {
        prop_oneof![
            Just(ProjectionSpec::Ods {
                frame,
                ipd,
                pole_merge: None
            }),
            (0.0..89.0f64, 0.5..1.0f64).prop_map(move |(from, f)| ProjectionSpec::Ods {
                frame,
                ipd,
                pole_merge: Some([from, from + f * (90.0 - from)]),
            }),
            Just(ProjectionSpec::Vr180 { frame, ipd }),
        ]
    })
}

fn parts(spec: &ProjectionSpec) -> (CameraFrame, f64) {
    match spec {
        ProjectionSpec::Ods { frame, ipd, .. } | ProjectionSpec::Vr180 { frame, ipd } => {
            (*frame, *ipd)
        }
        _ => unreachable!("not generated"),
    }
}

/// How many images `point` must have, from the geometry alone with margins: ods, two where
/// the point is off the eye circle's disc (merging) or outside its cylinder (none); vr180,
/// one per eye that has the point more than 1e-6 radians inside its front half space.
fn must_have(spec: &ProjectionSpec, point: DVec3) -> usize {
    let (frame, ipd) = parts(spec);
    let basis = CameraBasis::new(&frame).unwrap();
    let local = basis.to_local(point - frame.position);
    let horizontal = DVec2::new(local.x, local.z).length();
    let r = 0.5 * ipd;
    match spec {
        ProjectionSpec::Ods { pole_merge, .. } => {
            let clear = match pole_merge {
                Some(_) => local.y.abs() > 1e-6 || horizontal > r * (1.0 + 1e-6),
                None => horizontal > r * (1.0 + 1e-6),
            };
            2 * usize::from(clear)
        }
        _ => [-r, r]
            .into_iter()
            .filter(|&side| {
                let q = local - DVec3::new(side, 0.0, 0.0);
                q.length() > 1e-6 && q.z > 1e-6 * q.length()
            })
            .count(),
    }
}

/// Sizes with an even side along each layout's split.
fn even_size() -> impl Strategy<Value = (u32, u32)> {
    (1u32..200, 1u32..200).prop_map(|(w, h)| (2 * w, 2 * h))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn projected_points_lie_on_their_rays(
        spec in stereo_spec(),
        size in even_size(),
        point in vec3(20.0),
    ) {
        let projection = spec.build(size.0, size.1).unwrap();
        let mut images = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        let kind = spec.kind();
        prop_assert!(images.len() >= must_have(&spec, point), "{kind} lost {point}: {images:?}");
        prop_assert!(images.len() <= 2);
        for image in &images {
            let ray = projection.ray(image.pixel).unwrap();
            prop_assert!(image.t >= 0.0);
            let error = (ray.at(image.t) - point).length();
            let tolerance = 1e-9 * (1.0 + point.length() + ray.origin.length());
            prop_assert!(error <= tolerance, "{kind}: {point} missed by {error} at {image:?}");
        }
        if images.len() == 2 {
            let (w, h) = (f64::from(size.0), f64::from(size.1));
            let [a, b] = [images[0].pixel, images[1].pixel];
            match spec {
                ProjectionSpec::Vr180 { .. } => prop_assert!(a.x < 0.5 * w && b.x >= 0.5 * w),
                _ => prop_assert!(a.y < 0.5 * h && b.y >= 0.5 * h),
            }
        }
    }

    /// The point at a random t on a random pixel's ray (pixels 0.5% away from each tile's
    /// border: the seam, the poles, a vr180 half's edges) projects back to that pixel.
    #[test]
    fn rays_project_back_to_their_pixels(
        spec in stereo_spec(),
        size in even_size(),
        fraction in (0.005..0.995, 0.005..0.995),
        right_eye in any::<bool>(),
        t in 0.01..50.0f64,
    ) {
        let projection = spec.build(size.0, size.1).unwrap();
        let (w, h) = (f64::from(size.0), f64::from(size.1));
        let pixel = match spec {
            ProjectionSpec::Vr180 { .. } => {
                DVec2::new((fraction.0 + f64::from(u8::from(right_eye))) * 0.5 * w, fraction.1 * h)
            }
            _ => DVec2::new(fraction.0 * w, (fraction.1 + f64::from(u8::from(right_eye))) * 0.5 * h),
        };
        let ray = projection.ray(pixel).unwrap();
        let point = ray.at(t);
        let mut images = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        let back = images.iter().find(|i| (i.pixel - pixel).length() < 1e-6 * (1.0 + w));
        prop_assert!(back.is_some(), "{}: {pixel} -> {point} -> {images:?}", spec.kind());
        prop_assert!((back.unwrap().t - t).abs() <= 1e-9 * (1.0 + t));
    }
}
