use glam::{DVec2, DVec3};
use proptest::prelude::*;

use super::*;
use crate::displace::{HeightMap, Procedural, Wave};
use crate::geometry::{BilinearPatch, Ray};

/// Crossed waves, the usual test surface: slopes up to about 45 degrees, steep enough for
/// strong occlusion at grazing views, and no flat areas (a flat area's normals are all the
/// pole, one point that no redistribution can spread).
pub(crate) fn bumpy_chart(scale: f64) -> Chart {
    let waves = [([3, 0], 1.0), ([0, 3], 1.0), ([2, 2], 0.5)]
        .map(|(frequency, amplitude)| Wave {
            amplitude,
            frequency,
            phase: 0.0,
        })
        .to_vec();
    let height = HeightField::Procedural(Procedural::waves(waves).unwrap());
    Chart::new(&height, scale, DVec2::new(1.0, 1.0), 48).unwrap()
}

fn flat_chart() -> Chart {
    let height = HeightField::Map(HeightMap::from_values(2, 2, vec![0.5; 4]).unwrap());
    Chart::new(&height, 0.2, DVec2::new(2.0, 1.0), 8).unwrap()
}

#[test]
fn refuses_bad_charts() {
    let height = HeightField::Procedural(Procedural::bumps([3, 3], 0.45).unwrap());
    for (cells, size, scale) in [
        (1, DVec2::ONE, 0.1),
        (8, DVec2::new(0.0, 1.0), 0.1),
        (8, DVec2::new(1.0, f64::NAN), 0.1),
        (8, DVec2::ONE, f64::INFINITY),
    ] {
        assert!(Chart::new(&height, scale, size, cells).is_err());
    }
}

/// A single wave's wavelength is found in either direction at any world size and scale;
/// crossed equal waves keep it; a finer wave shortens it (by the root mean square of the
/// wavenumbers; the forward differences flatten a wave of 8 cells per period by 2.5 %);
/// a flat chart has none.
#[test]
fn wavelength_of_waves() {
    let chart = |waves: &[([i32; 2], f64)], size: DVec2, scale: f64| {
        let waves = waves
            .iter()
            .map(|&(frequency, amplitude)| Wave {
                amplitude,
                frequency,
                phase: 0.3,
            })
            .collect();
        let height = HeightField::Procedural(Procedural::waves(waves).unwrap());
        Chart::new(&height, scale, size, 128).unwrap()
    };
    let size = DVec2::new(2.0, 0.5);
    for (waves, expected) in [
        (vec![([4, 0], 1.0)], 0.5),
        (vec![([0, 4], 1.0)], 0.125),
        (
            vec![([4, 0], 1.0), ([16, 0], 1.0)],
            0.5 * (2.0_f64 / 17.0).sqrt(),
        ),
    ] {
        for scale in [0.01, 3.0] {
            let found = chart(&waves, size, scale).wavelength();
            assert!(
                (found / expected - 1.0).abs() < 0.03,
                "{waves:?} at scale {scale}: {found}, not {expected}"
            );
        }
    }
    let square = DVec2::ONE;
    let one = chart(&[([5, 0], 1.0)], square, 0.1).wavelength();
    let crossed = chart(&[([5, 0], 1.0), ([0, 5], 1.0)], square, 0.1).wavelength();
    assert!((crossed / one - 1.0).abs() < 1e-6 && (one - 0.2).abs() < 0.001);
    assert_eq!(flat_chart().wavelength(), 0.0);
}

/// Every view's histogram is normalised; a flat field (and a zero scale) puts all of it in
/// the middle bin, the pole.
#[test]
fn flat_fields_see_only_the_pole() {
    let pole = bin(DVec2::splat(0.5));
    assert_eq!(pole, (BINS / 2) * BINS + BINS / 2);
    let zero_scale = Chart::new(
        &HeightField::Procedural(Procedural::bumps([3, 3], 0.45).unwrap()),
        0.0,
        DVec2::ONE,
        16,
    )
    .unwrap();
    for chart in [flat_chart(), zero_scale] {
        assert_eq!(chart.relief(), 0.0);
        let d = NormalDistribution::new(&chart, 6);
        for k in 0..VIEWS {
            assert_eq!(d.view(k)[pole], 1.0, "view {k}");
        }
    }
}

#[test]
fn views_are_normalised_and_grazing_views_see_the_fronts_of_bumps() {
    let d = NormalDistribution::new(&bumpy_chart(0.15), 16);
    let centres: Vec<DVec3> = (0..BINS * BINS)
        .map(|k| {
            let c = DVec2::new((k % BINS) as f64 + 0.5, (k / BINS) as f64 + 0.5);
            crate::displace::square_map::to_hemisphere(c / BINS as f64)
        })
        .collect();
    let mean_x = |k: usize| -> f64 { d.view(k).iter().zip(&centres).map(|(p, n)| p * n.x).sum() };
    for k in 0..VIEWS {
        let total: f64 = d.view(k).iter().sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
    // Straight down the bumps' slopes balance; from the side the faces turned towards the
    // viewer (+x) dominate, and more so the lower the view.
    assert!(mean_x(0).abs() < 0.02, "{}", mean_x(0));
    assert!(mean_x(VIEWS / 2) > 0.05, "{}", mean_x(VIEWS / 2));
    assert!(mean_x(VIEWS - 1) > mean_x(VIEWS / 2));
}

/// The distance between two independent samplings of the same view's histogram (`rays`
/// per side, different jitters): the sampling noise that comparisons of histograms allow.
pub(crate) fn noise(chart: &Chart, theta: f64, rays: usize) -> f64 {
    distance(
        &visible_normals(chart, theta, rays, 101),
        &visible_normals(chart, theta, rays, 202),
    )
}

/// From straight above every point is visible: view 0 is the distribution of the normals
/// over the area (what a bump map shows), sampled independently here (five times as many
/// samples: their distance is below the noise between two samplings of view 0).
#[test]
fn the_top_view_is_the_area_distribution() {
    let chart = bumpy_chart(0.15);
    let d = NormalDistribution::new(&chart, 32);
    let normals: Vec<DVec3> = (0..40_000u64)
        .map(|s| {
            let uv = DVec2::new(unit(3 * s + 11), unit(3 * s + 12));
            rotate(chart.normal(uv), unit(3 * s + 13) * 2.0 * PI)
        })
        .collect();
    let area = histogram(&normals);
    let gap = distance(d.view(0), &area);
    let noise = noise(&chart, 0.0, 32);
    assert!(gap < noise, "{gap} against noise {noise}");
    // And it is not the grazing view's.
    assert!(distance(d.view(VIEWS - 1), &area) > 3.0 * noise);
}

/// The brute-force reference of [`Chart::trace`]: every cell's patch within reach of the
/// ray, the nearest hit's normal.
fn brute_force(chart: &Chart, entry: DVec2, direction: DVec3) -> Option<DVec3> {
    let cell = chart.cell();
    let origin = DVec3::new(entry.x, entry.y, chart.hi);
    let reach =
        (chart.relief() / -direction.z) * direction.truncate().length() + 2.0 * cell.max_element();
    let lo = ((entry - DVec2::splat(reach)) / cell).floor();
    let hi = ((entry + DVec2::splat(reach)) / cell).ceil();
    let ray = Ray::new(origin, direction);
    let mut best: Option<(f64, DVec3)> = None;
    for i in lo.x as i64..=hi.x as i64 {
        for j in lo.y as i64..=hi.y as i64 {
            let at = |di: i64, dj: i64| {
                DVec3::new(
                    (i + di) as f64 * cell.x,
                    (j + dj) as f64 * cell.y,
                    chart.z(i + di, j + dj),
                )
            };
            let patch = BilinearPatch {
                p00: at(0, 0),
                p10: at(1, 0),
                p01: at(0, 1),
                p11: at(1, 1),
            };
            if let Some(hit) = patch.intersect(&ray) {
                if best.is_none_or(|(t, _)| hit.t < t) {
                    let point = ray.at(hit.t).truncate() / chart.size();
                    best = Some((hit.t, chart.normal(point)));
                }
            }
        }
    }
    best.map(|(_, n)| n)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The grid walk finds the patch brute force finds (its normal), away from patch
    /// boundaries where either side's normal is right.
    #[test]
    fn trace_matches_brute_force(
        x in 0.0..1.0f64,
        y in 0.0..1.0f64,
        theta in 0.0..1.5f64,
        phi in 0.0..6.3f64,
        m in 1i32..4,
        n in -3i32..4,
    ) {
        let height = HeightField::Procedural(Procedural::waves(vec![
            Wave { amplitude: 1.0, frequency: [m, n], phase: 0.0 },
            Wave { amplitude: 0.5, frequency: [2, 1], phase: 0.0 },
        ]).unwrap());
        let chart = Chart::new(&height, 0.12, DVec2::new(1.0, 0.7), 24).unwrap();
        let direction = -DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
        let entry = DVec2::new(x, y * 0.7);
        let walked = chart.trace(entry, direction).unwrap();
        let reference = brute_force(&chart, entry, direction).unwrap();
        prop_assert!((walked - reference).length() < 1e-6, "{} {}", walked, reference);
    }
}
