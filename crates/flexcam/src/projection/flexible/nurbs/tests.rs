//! NURBS against what they degenerate to (Bezier and uniform B-spline patches with unit
//! weights), the exact circle of rational weights, and every refused degenerate case.

use std::f64::consts::FRAC_1_SQRT_2;

use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::*;
use crate::projection::flexible::{BSplinePatch, BezierPatch};

/// A wavy grid: control[row][column] = (column, row, a bump), so that no evaluation is
/// trivially linear.
fn grid(rows: usize, columns: usize) -> Vec<Vec<DVec3>> {
    (0..rows)
        .map(|r| {
            (0..columns)
                .map(|c| {
                    let (x, y) = (c as f64, r as f64);
                    DVec3::new(
                        x + 0.3 * (y * 1.7).sin(),
                        y,
                        (x * 0.9).sin() * (y * 1.3).cos(),
                    )
                })
                .collect()
        })
        .collect()
}

fn spec(control: Vec<Vec<DVec3>>, degree: [usize; 2]) -> NurbsSpec {
    NurbsSpec {
        control,
        weights: None,
        degree,
        u_knots: None,
        v_knots: None,
    }
}

fn samples() -> impl Iterator<Item = DVec2> {
    (0..=8).flat_map(|i| (0..=8).map(move |j| DVec2::new(i as f64 / 8.0, j as f64 / 8.0)))
}

#[test]
fn clamped_cubic_with_unit_weights_is_the_bezier_patch() {
    let g = grid(4, 4);
    let bezier = BezierPatch {
        control: std::array::from_fn(|r| std::array::from_fn(|c| g[r][c])),
    };
    // The same with weights all 2: a common factor cancels.
    let mut weighted = spec(g.clone(), [3, 3]);
    weighted.weights = Some(vec![vec![2.0; 4]; 4]);
    let patches = [
        NurbsPatch::new(spec(g, [3, 3])).unwrap(),
        NurbsPatch::new(weighted).unwrap(),
    ];
    for uv in samples() {
        for nurbs in &patches {
            let (a, b) = (nurbs.point(uv), bezier.point(uv));
            assert!((a - b).length() < 1e-12, "{uv}: {a} vs {b}");
        }
    }
}

#[test]
fn uniform_knots_with_unit_weights_are_the_uniform_bspline() {
    let (rows, columns) = (5, 7);
    let g = grid(rows, columns);
    let bspline = BSplinePatch::new(g.clone()).unwrap();
    let mut s = spec(g, [3, 3]);
    // Uniform (unclamped) knots 0, 1, 2, ...: the valid range [3, n] has n - 3 spans.
    s.u_knots = Some((0..columns + 4).map(|k| k as f64).collect());
    s.v_knots = Some((0..rows + 4).map(|k| 10.0 + 0.5 * k as f64).collect());
    let nurbs = NurbsPatch::new(s).unwrap();
    for uv in samples() {
        let (a, b) = (nurbs.point(uv), bspline.point(uv));
        assert!((a - b).length() < 1e-12, "{uv}: {a} vs {b}");
    }
}

/// A quarter cylinder of radius `r` about the z axis: the rational quadratic quarter circle
/// (1, 0), (1, 1), (0, 1) with weights 1, 1/sqrt 2, 1 along u, z from 0 to 2 along v.
fn quarter_cylinder(r: f64) -> NurbsPatch {
    let row = |z: f64| {
        vec![
            DVec3::new(r, 0.0, z),
            DVec3::new(r, r, z),
            DVec3::new(0.0, r, z),
        ]
    };
    NurbsPatch::new(NurbsSpec {
        control: vec![row(0.0), row(2.0)],
        weights: Some(vec![vec![1.0, FRAC_1_SQRT_2, 1.0]; 2]),
        degree: [2, 1],
        u_knots: Some(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
        v_knots: None,
    })
    .unwrap()
}

#[test]
fn a_rational_quarter_circle_lies_on_the_circle() {
    let c = quarter_cylinder(1.5);
    for uv in samples() {
        let p = c.point(uv);
        let radius = p.truncate().length();
        assert!((radius - 1.5).abs() < 1e-12, "{uv}: radius {radius}");
        assert!((p.z - 2.0 * uv.y).abs() < 1e-12);
    }
    // The ends and the middle: 0, 45 and 90 degrees.
    assert!((c.point(DVec2::ZERO) - DVec3::new(1.5, 0.0, 0.0)).length() < 1e-12);
    let mid = c.point(DVec2::new(0.5, 0.0));
    assert!((mid.y.atan2(mid.x) - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    assert!((c.point(DVec2::X) - DVec3::new(0.0, 1.5, 0.0)).length() < 1e-12);
}

#[test]
fn clamped_patches_pass_through_their_corners() {
    let g = grid(6, 5);
    let mut s = spec(g.clone(), [2, 3]);
    s.weights = Some(
        (0..6)
            .map(|r| (0..5).map(|c| 0.5 + ((r * 5 + c) % 4) as f64).collect())
            .collect(),
    );
    let n = NurbsPatch::new(s).unwrap();
    for (uv, want) in [
        (DVec2::ZERO, g[0][0]),
        (DVec2::X, g[0][4]),
        (DVec2::ONE, g[5][4]),
        (DVec2::Y, g[5][0]),
    ] {
        assert!((n.point(uv) - want).length() < 1e-12, "{uv}");
    }
}

#[test]
fn the_default_knots_are_clamped_and_uniform() {
    assert_eq!(
        KnotVector::clamped(4, 3),
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]
    );
    assert_eq!(
        KnotVector::clamped(5, 2),
        vec![0.0, 0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0, 1.0]
    );
}

#[test]
fn degenerate_patches_are_refused() {
    let with = |edit: &dyn Fn(&mut NurbsSpec)| {
        let mut s = spec(grid(4, 4), [3, 3]);
        edit(&mut s);
        NurbsPatch::new(s).unwrap_err().message
    };
    let cases: Vec<(String, &str)> = vec![
        (
            with(&|s| s.degree = [0, 3]),
            "degree along u must be in 1..=7, got 0",
        ),
        (
            with(&|s| s.degree = [3, 8]),
            "degree along v must be in 1..=7, got 8",
        ),
        (
            with(&|s| s.degree = [4, 3]),
            "needs 5 to 64 control points along u",
        ),
        (with(&|s| s.control = grid(65, 4)), "got 65 rows of 4"),
        (
            with(&|s| {
                s.control[2].pop();
            }),
            "row 3 has 3 points",
        ),
        (
            with(&|s| s.weights = Some(vec![vec![1.0; 4]; 3])),
            "the control grid's shape",
        ),
        (
            with(&|s| s.weights = Some(vec![vec![1.0, 0.0, 1.0, 1.0]; 4])),
            "positive and finite, got 0",
        ),
        (
            with(&|s| s.weights = Some(vec![vec![1.0, f64::NAN, 1.0, 1.0]; 4])),
            "positive and finite, got NaN",
        ),
        (
            with(&|s| s.u_knots = Some(vec![0.0; 7])),
            "needs 8 u knots (4 control points + degree 3 + 1), got 7",
        ),
        (
            with(&|s| s.v_knots = Some(vec![0.0, 0.0, 0.0, 1.0, 0.5, 1.0, 1.0, 1.0])),
            "v knots must not decrease: knot 5 (0.5) is below knot 4 (1)",
        ),
        (
            with(&|s| s.u_knots = Some(vec![0.0, 0.0, 0.0, 0.0, f64::INFINITY, 1.0, 1.0, 1.0])),
            "u knots must be finite, not inf",
        ),
        (
            with(&|s| s.u_knots = Some(vec![0.0; 8])),
            "u knots leave an empty parameter range",
        ),
    ];
    for (message, expected) in cases {
        assert!(
            message.contains(expected),
            "{message} (expected {expected})"
        );
    }
    // An inner knot of multiplicity above the degree breaks the surface apart.
    let mut s = spec(grid(4, 7), [2, 3]);
    s.u_knots = Some(vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0]);
    let e = NurbsPatch::new(s).unwrap_err().message;
    assert!(
        e.contains("u knot 0.5 is repeated 3 times inside the range"),
        "{e}"
    );
    // Multiplicity equal to the degree is fine (a crease).
    let mut s = spec(grid(4, 6), [2, 3]);
    s.u_knots = Some(vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0]);
    assert!(NurbsPatch::new(s).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any positive weights keep a clamped patch's points in the convex hull of its control
    /// points (here: inside their bounding box), and a point of a quarter cylinder of any
    /// radius stays on it.
    #[test]
    fn points_stay_in_the_hull(
        weights in proptest::collection::vec(0.05..20.0f64, 20),
        u in 0.0..=1.0f64, v in 0.0..=1.0f64, r in 0.01..100.0f64,
    ) {
        let g = grid(4, 5);
        let mut s = spec(g.clone(), [2, 3]);
        s.weights = Some(weights.chunks(5).map(<[f64]>::to_vec).collect());
        let p = NurbsPatch::new(s).unwrap().point(DVec2::new(u, v));
        let points: Vec<DVec3> = g.into_iter().flatten().collect();
        let lo = points.iter().fold(DVec3::INFINITY, |a, b| a.min(*b));
        let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, b| a.max(*b));
        prop_assert!(p.cmpge(lo - 1e-9).all() && p.cmple(hi + 1e-9).all(), "{}", p);
        let on = quarter_cylinder(r).point(DVec2::new(u, v));
        prop_assert!((on.truncate().length() - r).abs() <= 1e-12 * r.max(1.0));
    }
}
