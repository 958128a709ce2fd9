use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::*;
use crate::displace::bump::Redistribution;
use crate::displace::normal_distribution::tests::bumpy_chart;
use crate::displace::normal_distribution::{rotate, unit, view_angle, Chart};
use crate::displace::{HeightField, HeightMap};

fn light(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// A flat surface's BRDF is Lambert's cosine (to the interpolation between light nodes).
#[test]
fn flat_fields_are_lambertian() {
    let height = HeightField::Map(HeightMap::from_values(1, 1, vec![0.7]).unwrap());
    let chart = Chart::new(&height, 0.1, DVec2::ONE, 4).unwrap();
    let table = BrdfTable::new(&NormalDistribution::new(&chart, 4));
    for i in 0..40 {
        let theta_l = i as f64 * PI / 39.0;
        let phi = i as f64 * 0.7;
        let b = table.lookup(0.3 + 0.02 * i as f64, light(theta_l, phi));
        assert!((b - theta_l.cos().max(0.0)).abs() < 3e-3, "{theta_l}: {b}");
    }
}

/// The BRDF is the mean Lambert term of the redistributed bump normals: what the bump
/// method shows on average, so that blending the two keeps the intensity.
#[test]
fn brdf_matches_the_mean_of_redistributed_bump_shading() {
    let chart = bumpy_chart(0.15);
    let distribution = NormalDistribution::new(&chart, 32);
    let table = BrdfTable::new(&distribution);
    let redistribution = Redistribution::new(&distribution);
    for (k, theta_l, phi_l) in [(0, 0.3, 0.0), (15, 0.8, 2.0), (25, 1.2, 0.0), (25, 1.2, PI)] {
        let theta_v = view_angle(k);
        let l = light(theta_l, phi_l);
        let count = 20_000;
        let mean: f64 = (0..count)
            .map(|s| {
                let uv = DVec2::new(unit(3 * s), unit(3 * s + 1));
                let n = rotate(chart.normal(uv), unit(3 * s + 2) * 2.0 * PI);
                redistribution.map(n, 0.0, theta_v).dot(l).max(0.0)
            })
            .sum::<f64>()
            / count as f64;
        let b = table.lookup(theta_v, l);
        let seen =
            crate::displace::normal_distribution::visible_normal_samples(&chart, theta_v, 32, 9);
        let direct: f64 = seen.iter().map(|n| n.dot(l).max(0.0)).sum::<f64>() / seen.len() as f64;
        assert!(
            (b - mean).abs() < 0.03,
            "view {k}: table {b}, bumps {mean}, displaced {direct}"
        );
    }
    // Lit from behind the viewer, a grazing view sees lit fronts: brighter than lit from
    // beyond the bumps.
    let theta_v = view_angle(25);
    assert!(table.lookup(theta_v, light(1.2, 0.0)) > table.lookup(theta_v, light(1.2, PI)));
    // Never more than all the light.
    for k in 0..VIEWS {
        for i in 0..LIGHTS {
            assert!(table.at(k, i, 0) <= 1.0 + 1e-12);
        }
    }
}
