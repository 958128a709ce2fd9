use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::*;
use crate::displace::normal_distribution::tests::{bumpy_chart, noise};
use crate::displace::normal_distribution::{
    bin, distance, histogram, rotate, unit, view_angle, visible_normal_samples, visible_normals,
    Chart,
};
use crate::displace::square_map::to_square;
use crate::displace::transition::partial_view_angle;
use crate::displace::{HeightField, HeightMap};

/// Bump normals over the area of `chart`, each in the frame of a random view azimuth (as
/// the isotropic tables take them).
fn bump_normals(chart: &Chart, count: u64, seed: u64) -> Vec<DVec3> {
    (0..count)
        .map(|s| {
            let k = 3 * (s + seed * count);
            let uv = DVec2::new(unit(k), unit(k + 1));
            rotate(chart.normal(uv), unit(k + 2) * 2.0 * PI)
        })
        .collect()
}

/// The test of the dissertation: redistributed bump normals reproduce the displaced
/// surface's visible-normal distribution at each view angle, where the plain bump normals
/// do not (at grazing views they are far from it).
#[test]
fn redistributed_normals_reproduce_the_displaced_distribution() {
    let chart = bumpy_chart(0.15);
    let distribution = NormalDistribution::new(&chart, 32);
    let redistribution = Redistribution::new(&distribution);
    let normals = bump_normals(&chart, 60_000, 1);
    let plain = histogram(&normals);
    for k in [0, 10, 20, 25, VIEWS - 1] {
        let theta = view_angle(k);
        let moved: Vec<DVec3> = normals
            .iter()
            .map(|n| redistribution.map(*n, 0.0, theta))
            .collect();
        let gap = distance(&histogram(&moved), distribution.view(k));
        let noise = noise(&chart, theta, 32);
        assert!(gap < 1.3 * noise, "view {k}: {gap} against noise {noise}");
        if k >= 20 {
            let unmoved = distance(&plain, distribution.view(k));
            assert!(unmoved > 3.0 * gap, "view {k}: {unmoved} against {gap}");
        }
    }
}

/// Redistributing from a view angle to itself keeps a normal wherever that view sees
/// normals like it (a normal in an empty bin, one facing away at a grazing view, moves to
/// the nearest visible ones).
#[test]
fn from_a_view_to_itself_keeps_the_visible_normals() {
    let chart = bumpy_chart(0.15);
    let distribution = NormalDistribution::new(&chart, 16);
    let redistribution = Redistribution::new(&distribution);
    let mut kept = 0;
    for (i, n) in bump_normals(&chart, 2_000, 2).into_iter().enumerate() {
        let k = i % VIEWS;
        let theta = view_angle(k);
        let back = redistribution.map(n, theta, theta);
        if distribution.view(k)[bin(to_square(n))] > 0.0 {
            assert!((back - n).length() < 1e-9, "{n} -> {back}");
            kept += 1;
        }
    }
    assert!(kept > 1_000, "{kept}");
}

/// A flat height field maps the pole to the pole at every view angle.
#[test]
fn flat_fields_keep_the_pole() {
    let height = HeightField::Map(HeightMap::from_values(1, 1, vec![0.25]).unwrap());
    let chart = Chart::new(&height, 0.3, DVec2::ONE, 4).unwrap();
    let redistribution = Redistribution::new(&NormalDistribution::new(&chart, 4));
    for theta in [0.0, 0.4, 1.0, 1.5] {
        let n = redistribution.map(DVec3::Z, 0.0, theta);
        assert!((n - DVec3::Z).length() < 1e-12, "{n}");
    }
}

/// Partial displacement: the surface displaced by fraction `s` seen from `theta_V` shows
/// the normals the full surface shows from `theta_W = atan(s tan theta_V)`, each scaled to
/// the flatter surface ((s n_x, s n_y, n_z), normalised). The dissertation's printed form
/// with `1 - s` in place of `s`, and the inverse ratio, do not.
#[test]
fn partial_displacement_sees_the_full_surface_from_the_corrected_angle() {
    let full = bumpy_chart(0.15);
    let s = 0.4;
    let partial = bumpy_chart(0.15 * s);
    let theta_v = view_angle(27);
    let seen = visible_normals(&partial, theta_v, 32, 5);
    let flattened = |theta_w: f64| {
        let normals: Vec<DVec3> = visible_normal_samples(&full, theta_w, 32, 6)
            .into_iter()
            .map(|n| DVec3::new(s * n.x, s * n.y, n.z).normalize())
            .collect();
        histogram(&normals)
    };
    let corrected = distance(&seen, &flattened(partial_view_angle(theta_v, s)));
    let printed = distance(&seen, &flattened(partial_view_angle(theta_v, 1.0 - s)));
    let inverse = distance(&seen, &flattened((theta_v.tan() / s).atan()));
    let noise = noise(&partial, theta_v, 32);
    assert!(corrected < 1.3 * noise, "{corrected} against noise {noise}");
    assert!(printed > 2.0 * corrected, "{printed} against {corrected}");
    assert!(inverse > 2.0 * corrected, "{inverse} against {corrected}");
}
