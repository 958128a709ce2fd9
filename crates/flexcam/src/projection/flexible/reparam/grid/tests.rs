use std::f64::consts::PI;

use proptest::prelude::*;

use super::*;

const BOTH: [SampleInterpolation; 2] =
    [SampleInterpolation::Bilinear, SampleInterpolation::Bicubic];

/// Samples of `f` at the grid positions.
fn sampled(columns: usize, rows: usize, f: impl Fn(DVec2) -> DVec2) -> Vec<DVec2> {
    (0..rows)
        .flat_map(|j| (0..columns).map(move |i| (i, j)))
        .map(|(i, j)| {
            f(DVec2::new(
                i as f64 / (columns - 1) as f64,
                j as f64 / (rows - 1) as f64,
            ))
        })
        .collect()
}

#[test]
fn the_identity_grid_is_the_linear_map_inside_and_beyond() {
    for interpolation in BOTH {
        let grid = UvGrid::new(3, 4, sampled(3, 4, |p| p), interpolation).unwrap();
        for st in [
            DVec2::new(0.3, 0.7),
            DVec2::ZERO,
            DVec2::ONE,
            DVec2::new(-0.2, 1.3),
        ] {
            assert!(
                (grid.uv(st) - st).length() < 1e-14,
                "{interpolation:?} {st}"
            );
            assert!((grid.st(st).unwrap() - st).length() < 1e-12);
        }
        let j = grid.jacobian(DVec2::new(0.4, 0.4));
        assert!((j.determinant() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn bicubic_passes_through_the_samples_and_reproduces_affine_maps() {
    let affine = |p: DVec2| DVec2::new(0.2 + 0.5 * p.x + 0.1 * p.y, 0.1 + 0.7 * p.y);
    let wavy = |p: DVec2| DVec2::new(p.x + 0.03 * (PI * p.y).sin(), p.y + 0.02 * p.x * p.x);
    let grid = UvGrid::new(5, 4, sampled(5, 4, wavy), SampleInterpolation::Bicubic).unwrap();
    for j in 0..4 {
        for i in 0..5 {
            let st = DVec2::new(i as f64 / 4.0, j as f64 / 3.0);
            assert!((grid.uv(st) - wavy(st)).length() < 1e-15);
        }
    }
    let grid = UvGrid::new(4, 3, sampled(4, 3, affine), SampleInterpolation::Bicubic).unwrap();
    let st = DVec2::new(0.37, 0.81);
    assert!((grid.uv(st) - affine(st)).length() < 1e-15);
}

#[test]
fn a_folded_or_collapsed_cell_is_named() {
    for interpolation in BOTH {
        // Swap two samples of the middle row: cells (0, 1) and (1, 1) turn over.
        let mut samples = sampled(3, 3, |p| p);
        samples.swap(3, 4);
        let e = UvGrid::new(3, 3, samples, interpolation).unwrap_err();
        assert!(e.message.contains("cell (0, 0)") || e.message.contains("cell (0, 1)"));
        assert!(e.message.contains("folds"), "{}", e.message);
        assert!(matches!(e.sample, Some(0 | 3)));
        // Two samples at one place: the cell collapses there.
        let mut samples = sampled(3, 3, |p| p);
        samples[8] = samples[7];
        let e = UvGrid::new(3, 3, samples, interpolation).unwrap_err();
        assert!(e.message.contains("cell (1, 1)"), "{}", e.message);
        assert_eq!(e.sample, Some(4));
    }
}

#[test]
fn a_border_that_crosses_itself_is_refused() {
    // A strip wound one and a half times round a circle: every cell keeps its orientation,
    // but the strip overlaps itself.
    let spiral = |p: DVec2| {
        let angle = 3.0 * PI * p.x;
        let radius = 1.0 + 0.3 * p.y + 0.05 * p.x;
        radius * DVec2::new(angle.cos(), angle.sin())
    };
    for interpolation in BOTH {
        let e = UvGrid::new(40, 2, sampled(40, 2, spiral), interpolation).unwrap_err();
        assert!(e.message.contains("border"), "{}", e.message);
    }
    // The same strip wound half way round is accepted.
    let arc = |p: DVec2| spiral(DVec2::new(p.x / 3.0, p.y));
    assert!(UvGrid::new(40, 2, sampled(40, 2, arc), SampleInterpolation::Bicubic).is_ok());
}

#[test]
fn bad_counts_and_values_are_refused() {
    let linear = SampleInterpolation::Bilinear;
    let e = UvGrid::new(1, 3, sampled(2, 3, |p| p)[..3].to_vec(), linear).unwrap_err();
    assert!(
        e.message.contains("2 to 129 columns, got 1"),
        "{}",
        e.message
    );
    let e = UvGrid::new(2, 130, vec![DVec2::ZERO; 260], linear).unwrap_err();
    assert!(e.message.contains("rows, got 130"), "{}", e.message);
    let e = UvGrid::new(2, 2, vec![DVec2::ZERO; 3], linear).unwrap_err();
    assert!(
        e.message.contains("needs 4 samples, got 3"),
        "{}",
        e.message
    );
    let mut samples = sampled(2, 2, |p| p);
    samples[2].y = f64::NAN;
    let e = UvGrid::new(2, 2, samples, linear).unwrap_err();
    assert_eq!(e.sample, Some(2));
    assert!(e.message.contains("not finite"));
}

#[test]
fn the_inverse_continues_beyond_the_image() {
    let wavy = |p: DVec2| DVec2::new(p.x + 0.03 * (PI * p.y).sin(), p.y + 0.02 * p.x * p.x);
    for interpolation in BOTH {
        let grid = UvGrid::new(5, 4, sampled(5, 4, wavy), interpolation).unwrap();
        for st in [
            DVec2::new(-0.1, 0.5),
            DVec2::new(1.1, 1.05),
            DVec2::new(0.5, -0.2),
        ] {
            let back = grid.st(grid.uv(st)).unwrap();
            assert!(
                (back - st).length() < 1e-9,
                "{interpolation:?}: {st} -> {back}"
            );
        }
    }
}

/// A (u, v) seen inside the image whose nearest sample's Newton iteration ends on the
/// border cells' continuation outside (the case proptest found: 7 x 2 samples, bent and
/// jittered): the inverse gives the root inside the image, where the grid is one-to-one.
#[test]
fn the_inverse_prefers_the_root_inside_the_image() {
    let mut jitter = vec![(0.0, 0.0); 81];
    jitter[..5].copy_from_slice(&[
        (0.0, 0.8372090379483894),
        (0.0, -0.6971345682911061),
        (0.0, 0.0),
        (0.6910219792099661, 0.44631154540554696),
        (-0.5746406867699247, -0.3556041740359952),
    ]);
    jitter[9] = (0.40268512364609627, -0.7551240366200598);
    let samples = jittered(7, 2, &jitter, 0.09025463563914304);
    let grid = UvGrid::new(7, 2, samples, SampleInterpolation::Bilinear).unwrap();
    let st = DVec2::new(0.32717856987105326, 0.533255572695756);
    let back = grid.st(grid.uv(st)).unwrap();
    assert!((back - st).length() < 1e-9, "{st} -> {back}");
}

#[test]
fn a_mirrored_grid_is_one_to_one() {
    let grid = UvGrid::new(
        3,
        3,
        sampled(3, 3, |p| DVec2::new(1.0 - p.x, p.y)),
        SampleInterpolation::Bilinear,
    )
    .unwrap();
    let st = DVec2::new(0.25, 0.6);
    assert!((grid.st(grid.uv(st)).unwrap() - st).length() < 1e-12);
}

/// A grid of `columns` x `rows` whose interior samples are moved by `jitter` (fractions of
/// a quarter of the spacing), a smooth bend added.
fn jittered(columns: usize, rows: usize, jitter: &[(f64, f64)], bend: f64) -> Vec<DVec2> {
    let spacing = DVec2::new(1.0 / (columns - 1) as f64, 1.0 / (rows - 1) as f64);
    sampled(columns, rows, |p| p)
        .into_iter()
        .zip(jitter.iter().cycle())
        .map(|(p, (a, b))| {
            let moved = p + 0.25 * spacing * DVec2::new(*a, *b);
            moved + DVec2::new(bend * (PI * moved.y).sin(), 0.5 * bend * moved.x * moved.x)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// inverse(forward(x)) = x inside the image, for both interpolations, on grids that
    /// the checks accept.
    #[test]
    fn newton_inverts_the_grid_map(
        columns in 2usize..9,
        rows in 2usize..9,
        jitter in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 81),
        bend in -0.1f64..0.1,
        bicubic in any::<bool>(),
        points in prop::collection::vec((0.0f64..=1.0, 0.0f64..=1.0), 16),
    ) {
        let interpolation = if bicubic {
            SampleInterpolation::Bicubic
        } else {
            SampleInterpolation::Bilinear
        };
        let grid = UvGrid::new(columns, rows, jittered(columns, rows, &jitter, bend), interpolation);
        prop_assume!(grid.is_ok());
        let grid = grid.unwrap();
        for (s, t) in points {
            let st = DVec2::new(s, t);
            let back = grid.st(grid.uv(st));
            prop_assert!(back.is_some(), "no inverse of {st}");
            let back = back.unwrap();
            prop_assert!((back - st).length() < 1e-9, "{st} -> {back}");
        }
    }
}
