use std::path::Path;

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{finish, nearest_image};
use crate::geometry::Ray;
use crate::projection::inverse_properties::frame;
use crate::projection::{ImagePoint, Projection, ProjectionSpec};

/// Projections with an analytic inverse that image every point of their view once.
fn injective_spec() -> impl Strategy<Value = ProjectionSpec> {
    frame().prop_flat_map(|frame| {
        prop_oneof![
            (20.0..150.0).prop_map(move |fov| ProjectionSpec::Perspective { frame, fov }),
            (0.5..20.0).prop_map(move |width| ProjectionSpec::Orthographic { frame, width }),
            (30.0..300.0).prop_map(move |fov| ProjectionSpec::Fisheye { frame, fov }),
        ]
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The point on the projector of pixel p is found at p (the search inverts the
    /// projection), and where the projection has a closed-form inverse the two agree.
    #[test]
    fn finds_the_pixel_whose_projector_holds_the_point(
        spec in injective_spec(),
        (w, h) in (16u32..400, 16u32..400),
        (fx, fy, t) in (0.05..0.95, 0.05..0.95, 0.5..20.0),
    ) {
        let projection = spec.build(w, h).unwrap();
        let pixel = DVec2::new(fx * f64::from(w), fy * f64::from(h));
        let Some(ray) = projection.ray(pixel) else {
            return Ok(()); // outside a fisheye's image circle
        };
        let point = ray.at(t);
        let found = nearest_image(projection.as_ref(), point).unwrap();
        prop_assert!((found.pixel - pixel).length() < 1e-5, "{found:?} for {pixel}");
        prop_assert!(found.miss < 1e-9 && found.miss_pixels < 1e-4, "{found:?}");
        let mut images: Vec<ImagePoint> = Vec::new();
        projection.inverse().unwrap().project(point, &mut images);
        let closed = images.iter().map(|i| (i.pixel - found.pixel).length()).fold(f64::INFINITY, f64::min);
        prop_assert!(closed < 1e-5, "closed form {images:?}, found {found:?}");
    }
}

#[test]
fn curved_projectors_are_searched_along_their_curves() {
    // A projector grid with tangents (quadratic projectors, no analytic inverse).
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/flexible-projector-tangents.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let scene = crate::scene::file::parse(&text, &path).unwrap();
    let projection = scene.projection.build(160, 120).unwrap();
    for (pixel, s) in [
        (DVec2::new(20.5, 30.5), 0.3),
        (DVec2::new(80.0, 60.0), 0.7),
        (DVec2::new(150.25, 100.75), 0.5),
    ] {
        let Some(super::Projector::QuadraticBezier(c)) = projection.projector(pixel) else {
            panic!("the quadratic scene has curved projectors");
        };
        let point = super::quadratic_point(&c, s);
        let found = nearest_image(projection.as_ref(), point).unwrap();
        assert!((found.pixel - pixel).length() < 1e-5, "{found:?} {pixel}");
        assert!(found.miss_pixels < 1e-4, "{found:?}");
    }
}

#[test]
fn points_out_of_view_have_a_large_miss_in_pixels() {
    let spec = ProjectionSpec::Perspective {
        frame: crate::projection::CameraFrame {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
        },
        fov: 60.0,
    };
    let projection = spec.build(64, 48).unwrap();
    // Behind the eye, and in front but far outside the image on the right.
    for point in [DVec3::new(0.1, 0.2, 3.0), DVec3::new(10.0, 0.0, -1.0)] {
        let found = nearest_image(projection.as_ref(), point).unwrap();
        assert!(found.miss_pixels > 5.0, "{point}: {found:?}");
    }
    // Off the right edge: the nearest projector is on that edge.
    let right = nearest_image(projection.as_ref(), DVec3::new(10.0, 0.0, -1.0)).unwrap();
    assert!(right.pixel.x == 64.0, "{right:?}");
    // The eye is every projector's start: on all of them, with no miss.
    let eye = nearest_image(projection.as_ref(), DVec3::ZERO).unwrap();
    assert_eq!((eye.miss, eye.miss_pixels), (0.0, 0.0));
}

#[test]
fn coinciding_projectors_give_an_infinite_miss_in_pixels() {
    let flat = finish(DVec2::ONE, DVec3::X, (DVec3::ZERO, DVec3::ZERO));
    assert_eq!(flat.miss_pixels, f64::INFINITY);
    let on = finish(DVec2::ONE, DVec3::ZERO, (DVec3::ZERO, DVec3::ZERO));
    assert_eq!(on.miss_pixels, 0.0);
}

/// A projection that sees nothing anywhere.
struct Blind;

impl Projection for Blind {
    fn kind(&self) -> &'static str {
        "blind"
    }
    fn resolution(&self) -> (u32, u32) {
        (8, 8)
    }
    fn ray(&self, _: DVec2) -> Option<Ray> {
        None
    }
}

#[test]
fn a_projection_without_projectors_images_nothing() {
    assert_eq!(nearest_image(&Blind, DVec3::ONE), None);
}
