//! Redistributed bump mapping (Becker and Max 1993; Ramsey 2005, chapter 4): a bump normal is
//! moved so that, over the surface, the normals a viewer sees are distributed as the visible
//! normals of the displaced surface from the same view angle, not as the bump map's own.
//! Seen at a grazing angle, bumps then show the faces turned towards the viewer, as the
//! displaced surface does, instead of their backs.
//!
//! The redistribution from distribution `F` to `G` is `q = G^-1(F(n))` with the
//! two-dimensional cumulative distributions taken one axis after the other on the
//! Shirley-Chiu square ([`super::square_map`]): the marginal over rows of bins, then the
//! conditional within the row. Each view node stores these as prefix sums (a row table of
//! `BINS + 1` and a `BINS x (BINS + 1)` table); a lookup is a bin index forwards and a
//! binary search backwards, linear within a bin (the histogram's density is uniform over
//! each bin), so the tables are exact for the histograms and need no finer resampling than
//! the histograms themselves.
//!
//! The bump map's own distribution `F` is the displaced surface's seen from straight above
//! (view node 0): from there every point of a height field is visible, so the visible
//! normals are the normals over the area, which is what a bump-mapped flat surface shows
//! from any view. The same tables then serve partial displacement ([`super::transition`]):
//! a surface displaced by a fraction `s` of its height, seen from `theta_V`, shows the
//! points the fully displaced one shows from `theta_W = atan(s tan theta_V)`, so its
//! normals are redistributed from `theta_W` to `theta_V` ([`Redistribution::map`] with
//! `from = theta_W`); `from = 0` is plain redistributed bump mapping, `from = to` keeps the
//! normal (up to the within-bin interpolation between view nodes).
//!
//! Degenerate cases: a flat height field has all its mass in the middle bin (module
//! [`super::normal_distribution`]), whose centre the map keeps fixed; an empty histogram (no
//! ray hit) counts as uniform.

use glam::{DVec2, DVec3};

use super::normal_distribution::{view_node, NormalDistribution, BINS, VIEWS};
use super::square_map::{to_hemisphere, to_square};

/// The prefix-sum tables of one view node's distribution.
#[derive(Debug, Clone, PartialEq)]
struct Cdf {
    /// `rows[r]`: the mass of rows `0..r` (`BINS + 1` entries, from 0 to 1).
    rows: Vec<f64>,
    /// `within[r * (BINS + 1) + a]`: the mass of bins `0..a` of row `r` over the row's
    /// (uniform for an empty row).
    within: Vec<f64>,
}

impl Cdf {
    fn new(bins: &[f64]) -> Cdf {
        let total: f64 = bins.iter().sum();
        let mass = |k: usize| if total > 0.0 { bins[k] / total } else { 1.0 };
        let mut rows = vec![0.0; BINS + 1];
        let mut within = vec![0.0; BINS * (BINS + 1)];
        for r in 0..BINS {
            let row_mass: f64 = (0..BINS).map(|a| mass(r * BINS + a)).sum();
            rows[r + 1] = rows[r] + row_mass;
            let line = &mut within[r * (BINS + 1)..(r + 1) * (BINS + 1)];
            for a in 0..BINS {
                let m = if row_mass > 0.0 {
                    mass(r * BINS + a) / row_mass
                } else {
                    1.0 / BINS as f64
                };
                line[a + 1] = line[a] + m;
            }
        }
        let end = rows[BINS];
        rows.iter_mut().for_each(|x| *x /= end);
        for r in 0..BINS {
            let line = &mut within[r * (BINS + 1)..(r + 1) * (BINS + 1)];
            let end = line[BINS];
            line.iter_mut().for_each(|x| *x /= end);
        }
        Cdf { rows, within }
    }

    fn row(&self, r: usize) -> &[f64] {
        &self.within[r * (BINS + 1)..(r + 1) * (BINS + 1)]
    }

    /// The cumulative masses `(row CDF, within-row CDF)` at square point `p`.
    fn forward(&self, p: DVec2) -> DVec2 {
        let (r, fy) = split(p.y);
        let (a, fx) = split(p.x);
        let line = self.row(r);
        DVec2::new(
            lerp(self.rows[r], self.rows[r + 1], fy),
            lerp(line[a], line[a + 1], fx),
        )
    }

    /// The square point whose cumulative masses are `u` (the inverse of [`Cdf::forward`]
    /// where the density is positive).
    fn inverse(&self, u: DVec2) -> DVec2 {
        let (r, fy) = invert(&self.rows, u.x.clamp(0.0, 1.0));
        let (a, fx) = invert(self.row(r), u.y.clamp(0.0, 1.0));
        DVec2::new((a as f64 + fx) / BINS as f64, (r as f64 + fy) / BINS as f64)
    }
}

/// The bin of coordinate `x` in `[0, 1]` and the fraction across it.
fn split(x: f64) -> (usize, f64) {
    let g = (x * BINS as f64).clamp(0.0, BINS as f64);
    let k = (g.floor() as usize).min(BINS - 1);
    (k, g - k as f64)
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// The bin `k` of prefix sums `cdf` (non-decreasing, from 0 to 1) holding mass `u`, skipping
/// empty bins, and the fraction across it.
fn invert(cdf: &[f64], u: f64) -> (usize, f64) {
    let bins = cdf.len() - 1;
    let mut k = cdf[1..].partition_point(|&c| c < u).min(bins - 1);
    while k + 1 < bins && cdf[k + 1] <= cdf[k] {
        k += 1;
    }
    let width = cdf[k + 1] - cdf[k];
    let f = if width > 0.0 {
        ((u - cdf[k]) / width).clamp(0.0, 1.0)
    } else {
        0.5
    };
    (k, f)
}

/// The redistribution tables of a normal distribution, per view node (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Redistribution {
    views: Vec<Cdf>,
}

impl Redistribution {
    /// The redistribution tables of `distribution`, one per view node.
    pub fn new(distribution: &NormalDistribution) -> Redistribution {
        Redistribution {
            views: (0..VIEWS).map(|k| Cdf::new(distribution.view(k))).collect(),
        }
    }

    /// Bump normal `n` (unit, in the view's frame: surface normal `+z`, viewer towards
    /// `+x`) as a normal distributed like the visible normals from view angle `to`, taking
    /// it as distributed like those from view angle `from` (0 for a bump map). Between view
    /// nodes the cumulative masses and the points they give are interpolated linearly.
    pub fn map(&self, n: DVec3, from: f64, to: f64) -> DVec3 {
        let p = to_square(n);
        let (k, w) = view_node(from);
        let u = self.views[k]
            .forward(p)
            .lerp(self.views[k + 1].forward(p), w);
        let (k, w) = view_node(to);
        let q = self.views[k]
            .inverse(u)
            .lerp(self.views[k + 1].inverse(u), w);
        to_hemisphere(q)
    }
}

#[cfg(test)]
mod tests;
