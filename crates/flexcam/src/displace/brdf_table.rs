//! The isotropic diffuse BRDF of a displaced surface, tabulated from its normal distribution
//! (Becker and Max 1993; Ramsey 2005, Figure 3.3): seen from view angle `theta_V` and lit
//! from direction `L`, a surface of diffuse micro-facets reflects the mean over its visible
//! normals of `max(0, L . N)`, so
//!
//! ```text
//! B[theta_V][theta_L][phi_L] = sum over bins N of dN[theta_V][N] * max(0, L . N),
//! ```
//!
//! with `phi_L` the light's azimuth from the viewer's and `N` each bin's centre on the
//! Shirley-Chiu square. The BRDF times the albedo is the reflected fraction, as Lambert's
//! `cos theta_L` is for a flat surface (which this table reduces to). Shadowing of the light
//! by the bumps is not in it (as in the dissertation). Light angles are [`LIGHTS`] nodes
//! over `[0, pi]` (a light below the base plane still lights facets turned towards it) and
//! [`LIGHT_AZIMUTHS`] over a full turn; lookups are trilinear in view angle, light angle and
//! light azimuth.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::normal_distribution::{view_node, NormalDistribution, BINS, VIEWS};
use super::square_map::to_hemisphere;

/// Light-angle nodes over `[0, pi]`.
pub const LIGHTS: usize = 33;
/// Light-azimuth nodes over `[0, 2 pi)`.
pub const LIGHT_AZIMUTHS: usize = 32;

/// The tabulated diffuse BRDF (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfTable {
    /// `[view][light angle][light azimuth]`.
    values: Vec<f64>,
}

impl BrdfTable {
    /// Tabulates the BRDF of micro-surfaces whose normals follow `distribution`.
    pub fn new(distribution: &NormalDistribution) -> BrdfTable {
        let centres: Vec<DVec3> = (0..BINS * BINS)
            .map(|k| {
                let cell = DVec2::new((k % BINS) as f64 + 0.5, (k / BINS) as f64 + 0.5);
                to_hemisphere(cell / BINS as f64)
            })
            .collect();
        let mut values = Vec::with_capacity(VIEWS * LIGHTS * LIGHT_AZIMUTHS);
        for view in 0..VIEWS {
            let bins = distribution.view(view);
            let visible: Vec<(f64, DVec3)> = bins
                .iter()
                .zip(&centres)
                .filter(|(p, _)| **p > 0.0)
                .map(|(p, n)| (*p, *n))
                .collect();
            for i in 0..LIGHTS {
                for j in 0..LIGHT_AZIMUTHS {
                    let light = light_direction(i, j);
                    values.push(
                        visible
                            .iter()
                            .map(|(p, n)| p * light.dot(*n).max(0.0))
                            .sum(),
                    );
                }
            }
        }
        BrdfTable { values }
    }

    fn at(&self, view: usize, light: usize, azimuth: usize) -> f64 {
        self.values[(view * LIGHTS + light) * LIGHT_AZIMUTHS + azimuth % LIGHT_AZIMUTHS]
    }

    /// The BRDF (times pi: the reflected fraction) for view angle `theta_v` and unit light
    /// direction `light` in the view's frame (surface normal `+z`, viewer towards `+x`).
    pub fn lookup(&self, theta_v: f64, light: DVec3) -> f64 {
        let (v, wv) = view_node(theta_v);
        let theta = light.z.clamp(-1.0, 1.0).acos();
        let x = (theta / PI * (LIGHTS - 1) as f64).clamp(0.0, (LIGHTS - 1) as f64);
        let l = (x.floor() as usize).min(LIGHTS - 2);
        let wl = x - l as f64;
        let phi = light.y.atan2(light.x).rem_euclid(2.0 * PI);
        let y = phi / (2.0 * PI) * LIGHT_AZIMUTHS as f64;
        let a = (y.floor() as usize).min(LIGHT_AZIMUTHS - 1);
        let wa = y - a as f64;
        let plane = |v: usize| {
            let row = |l: usize| self.at(v, l, a) * (1.0 - wa) + self.at(v, l, a + 1) * wa;
            row(l) * (1.0 - wl) + row(l + 1) * wl
        };
        plane(v) * (1.0 - wv) + plane(v + 1) * wv
    }
}

/// The light direction at light node `i`, azimuth node `j`.
fn light_direction(i: usize, j: usize) -> DVec3 {
    let theta = i as f64 * PI / (LIGHTS - 1) as f64;
    let phi = j as f64 * 2.0 * PI / LIGHT_AZIMUTHS as f64;
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

#[cfg(test)]
mod tests;
