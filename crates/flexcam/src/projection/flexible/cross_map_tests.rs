//! Blends of volumes on different re-parameterisations (thesis fig. 6.16: a perspective and
//! a fisheye): every pixel's projector is the mix of the two volumes' projectors at that
//! pixel, each through its own map.

use glam::DVec2;

use super::tests::{blend_of, preset};
use super::*;

const SIZE: (u32, u32) = (40, 30);

fn perspective() -> FlexibleSpec {
    preset(Preset::Perspective { fov: 80.0 }, Some([0.5, 20.0]))
}

fn fisheye() -> FlexibleSpec {
    preset(Preset::Fisheye { fov: 180.0 }, Some([0.5, 20.0]))
}

fn build(spec: &FlexibleSpec) -> Flexible {
    Flexible::new(spec, SIZE.0, SIZE.1).unwrap_or_else(|e| panic!("{e}"))
}

/// Pixel centres on a coarse lattice over the image.
fn pixels() -> impl Iterator<Item = DVec2> {
    (0..SIZE.1)
        .step_by(3)
        .flat_map(|y| (0..SIZE.0).step_by(3).map(move |x| (x, y)))
        .map(|(x, y)| DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5))
}

/// The straight projector of `f` at `pixel` through its map continued beyond its domain, as
/// (origin, end).
fn continued(f: &Flexible, pixel: DVec2) -> (DVec3, DVec3) {
    let uv = f.reparam().to_uv_continued(&f.resolution, pixel);
    let ray = f.volume().ray(uv).expect("a straight projector");
    (ray.at(0.0), ray.at(1.0))
}

#[test]
fn each_pixel_mixes_the_two_projectors_it_has_in_its_own_maps() {
    let (a, b) = (build(&perspective()), build(&fisheye()));
    for weight in [0.25, 0.5, 0.75, 1.5, -0.5] {
        let mix = build(&blend_of(weight, perspective(), fisheye()));
        assert_eq!(*mix.reparam(), Reparam::Linear);
        assert!(matches!(mix.volume(), Volume::Interpolated(_)));
        for pixel in pixels() {
            let ray = mix.ray(pixel).expect("the perspective sees every pixel");
            let (pa, pb) = (continued(&a, pixel), continued(&b, pixel));
            let want = (
                weight * pa.0 + (1.0 - weight) * pb.0,
                weight * pa.1 + (1.0 - weight) * pb.1,
            );
            let scale = 1.0 + pa.1.length() + pb.1.length();
            assert!(
                (ray.at(0.0) - want.0).length() < 1e-9 * scale
                    && (ray.at(1.0) - want.1).length() < 1e-9 * scale,
                "{weight} at {pixel}: {} {} against {} {}",
                ray.at(0.0),
                ray.at(1.0),
                want.0,
                want.1
            );
            // Inside the fisheye's circle its continuation is the fisheye itself.
            if let Some(own) = b.ray(pixel) {
                assert!((own.at(1.0) - pb.1).length() < 1e-9 * scale);
            }
        }
    }
}

#[test]
fn the_blend_sees_where_either_volume_does_and_the_ends_are_the_volumes() {
    let corner = DVec2::new(1.5, 1.5);
    let centre = DVec2::new(20.5, 15.5);
    let fish = build(&fisheye());
    assert!(fish.ray(corner).is_none() && fish.ray(centre).is_some());
    for weight in [0.01, 0.5, 0.99, -0.5] {
        let mix = build(&blend_of(weight, perspective(), fisheye()));
        assert!(mix.ray(corner).is_some(), "{weight}");
    }
    // Weights 0 and 1 are the volumes themselves, each on its own map.
    let at_zero = build(&blend_of(0.0, perspective(), fisheye()));
    assert!(at_zero.ray(corner).is_none());
    let persp = build(&perspective());
    let at_one = build(&blend_of(1.0, perspective(), fisheye()));
    for pixel in pixels() {
        let (p, q) = (persp.ray(pixel).unwrap(), at_one.ray(pixel).unwrap());
        assert!((p.at(0.0) - q.at(0.0)).length() < 1e-12);
        assert!((p.at(1.0) - q.at(1.0)).length() < 1e-12);
    }
    // Two fisheyes on different maps: neither sees the corners, so their blend does not.
    let lens = FlexibleSpec {
        reparam: Some(Reparam::Lens),
        ..fisheye()
    };
    let both = build(&blend_of(0.5, fisheye(), lens));
    assert!(both.ray(corner).is_none() && both.ray(centre).is_some());
}

#[test]
fn blends_across_maps_have_no_analytic_inverse_and_say_why() {
    let mix = build(&blend_of(0.5, perspective(), fisheye()));
    let reason = mix.inverse().err().and_then(|none| none.reason).unwrap();
    assert!(
        reason.contains("different re-parameterisations"),
        "{reason}"
    );
}
