//! The projector hulls of blended volumes: every projector of a (u, v) rectangle lies in
//! the padded box of its corners' control points, and the degenerate cases have no hull.

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::{BezierVolume, PiecewiseVolume};
use crate::projection::flexible::control_surface::{PolarFrame, SpherePatch, Surface};
use crate::projection::{Projector, ProjectorHull};

/// The control points of a projector (polyline vertices or Bezier control points).
fn points(p: &Projector) -> Vec<DVec3> {
    match p {
        Projector::Polyline(v) => v.clone(),
        Projector::QuadraticBezier(q) => q.to_vec(),
        Projector::Straight(r) => panic!("a blended volume has no straight projector: {r:?}"),
    }
}

/// Asserts that each control point of `inside` lies in the box of the corners'
/// corresponding control points enlarged by the hull's pad.
fn assert_in_hull(hull: &ProjectorHull, inside: &Projector) {
    let corners = hull.corners.each_ref().map(points);
    let inside = points(inside);
    for (k, p) in inside.iter().enumerate() {
        let lo = corners.iter().fold(DVec3::INFINITY, |m, c| m.min(c[k]));
        let hi = corners.iter().fold(DVec3::NEG_INFINITY, |m, c| m.max(c[k]));
        let pad = DVec3::splat(hull.pad);
        assert!(
            p.cmpge(lo - pad).all() && p.cmple(hi + pad).all(),
            "control point {k} {p} outside [{lo}, {hi}] + {}",
            hull.pad
        );
    }
}

fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    [-range..range, -range..range, -range..range].prop_map(DVec3::from_array)
}

/// A rectangle or a bilinear patch around depth `z`, small enough to stay within 4 of it.
fn surface(z: f64) -> impl Strategy<Value = Surface> {
    let rectangle =
        (vec3(1.0), vec3(1.5), vec3(1.5)).prop_map(move |(c, u, v)| Surface::Rectangle {
            corner: c + DVec3::Z * z,
            u_edge: u,
            v_edge: v,
        });
    let bilinear =
        [vec3(2.0), vec3(2.0), vec3(2.0), vec3(2.0)].prop_map(move |corners| Surface::Bilinear {
            corners: corners.map(|c| c + DVec3::Z * z),
        });
    prop_oneof![rectangle, bilinear]
}

/// A (u, v) rectangle in [0, 1]^2 and a point of it given by weights in [0, 1].
fn rectangle_and_point() -> impl Strategy<Value = (DVec2, DVec2, DVec2)> {
    (
        0.0..1.0f64,
        0.0..1.0f64,
        0.0..0.2f64,
        0.0..0.2f64,
        0.0..=1.0f64,
        0.0..=1.0f64,
    )
        .prop_map(|(u, v, du, dv, a, b)| {
            let (lo, hi) = (DVec2::new(u, v), DVec2::new(u + du, v + dv));
            (lo, hi, lo + DVec2::new(a, b) * (hi - lo))
        })
}

proptest! {
    #[test]
    fn every_projector_of_a_rectangle_lies_in_its_hull(
        near in surface(0.0),
        middle in surface(10.0),
        far in surface(20.0),
        extra in surface(30.0),
        segments in 1u32..7,
        (lo, hi, uv) in rectangle_and_point(),
    ) {
        // Depths 10 apart and surfaces within 4 of theirs: the surfaces never meet, so
        // every volume has a hull.
        let three = vec![near.clone(), middle.clone(), far.clone()];
        let four = vec![near, middle, far, extra];
        let quadratic = BezierVolume::new(three.clone(), None).unwrap();
        let polyline = BezierVolume::new(three.clone(), Some(segments)).unwrap();
        let cubic = BezierVolume::new(four.clone(), Some(segments)).unwrap();
        let piecewise = PiecewiseVolume::new(four, None).unwrap();
        for (hull, inside) in [
            (quadratic.projector_hull(lo, hi), quadratic.projector(uv)),
            (polyline.projector_hull(lo, hi), polyline.projector(uv)),
            (cubic.projector_hull(lo, hi), cubic.projector(uv)),
            (piecewise.projector_hull(lo, hi), piecewise.projector(uv)),
        ] {
            let hull = hull.expect("surfaces that never meet have a hull");
            assert_in_hull(&hull, &inside.expect("every (u, v) of a hull has a projector"));
        }
    }
}

fn square(centre: DVec3, u: DVec3, v: DVec3) -> Surface {
    Surface::rectangle_centred(centre, u, v)
}

#[test]
fn a_curved_surface_has_no_hull() {
    let frame = PolarFrame::new(DVec3::Y, -DVec3::Z).unwrap();
    let sphere = Surface::Sphere(SpherePatch {
        center: DVec3::ZERO,
        radius: 10.0,
        frame,
        longitude: [-1.0, 1.0],
        latitude: [-0.5, 0.5],
    });
    let near = square(DVec3::Z, DVec3::X, DVec3::Y);
    let mid = square(DVec3::ZERO, DVec3::X, DVec3::Y);
    let v = BezierVolume::new(vec![near, mid, sphere], None).unwrap();
    assert_eq!(v.projector_hull(DVec2::ZERO, DVec2::splat(0.1)), None);
}

#[test]
fn surfaces_that_may_meet_inside_the_rectangle_give_no_hull() {
    // Both surfaces differ by (2v - 1)(Z - Y): they meet along v = 1/2.
    let a = square(DVec3::ZERO, DVec3::X, DVec3::Y);
    let b = square(DVec3::ZERO, DVec3::X, DVec3::Z);
    let v = PiecewiseVolume::new(vec![a, b], None).unwrap();
    let across = v.projector_hull(DVec2::new(0.2, 0.4), DVec2::new(0.3, 0.6));
    assert_eq!(across, None);
    // The projector at v = 1/2 has zero length indeed.
    assert_eq!(v.projector(DVec2::new(0.25, 0.5)), None);
    // Away from the line the rectangle has a hull.
    let below = v.projector_hull(DVec2::new(0.2, 0.1), DVec2::new(0.3, 0.3));
    assert!(below.is_some());
}

#[test]
fn coefficients_that_could_overflow_give_no_hull() {
    let huge = f64::MAX / 8.0;
    let a = square(DVec3::ZERO, DVec3::X, DVec3::Y);
    let b = square(DVec3::Z * huge, DVec3::X, DVec3::Y);
    let v = PiecewiseVolume::new(vec![a.clone(), b], None).unwrap();
    assert_eq!(v.projector_hull(DVec2::ZERO, DVec2::splat(0.1)), None);
    let c = square(DVec3::Z, DVec3::X, DVec3::Y);
    let v = PiecewiseVolume::new(vec![a, c], None).unwrap();
    assert!(v.projector_hull(DVec2::ZERO, DVec2::splat(0.1)).is_some());
}
