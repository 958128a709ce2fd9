//! Procedural height functions: small, parameterised patterns a scene can name instead of a
//! height map, each with an exact h_max and interval bounds over uv rectangles.
//!
//! Both are periodic with period 1 in u and v, so they tile seamlessly over a mesh whose
//! texture coordinates wrap (a torus parameterised by two angles over [0, 1]^2):
//! * **waves**: `h = sum_k a_k (1 + cos(2 pi (m_k u + n_k v) + phi_k)) / (2 sum_k a_k)`, with
//!   amplitudes `a_k > 0` and integer frequencies `(m_k, n_k)`;
//! * **bumps**: a grid of `nu x nv` cells over the unit square, each with a round bump
//!   `h = (1 - r^2)^2` for `r < 1`, 0 outside, `r` the distance from the cell centre in cell
//!   units over `radius` (`0 < radius <= 1/2`, so a bump stays inside its cell and h is
//!   continuous, with a continuous gradient).

use std::f64::consts::{PI, TAU};

use glam::DVec2;

use crate::error::Result;
use crate::scene::displacement::ProceduralSpec;
pub use crate::scene::displacement::Wave;

/// A procedural height function; build it with [`Procedural::waves`] or
/// [`Procedural::bumps`].
#[derive(Debug, Clone, PartialEq)]
pub struct Procedural {
    kind: Kind,
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    /// The waves and the sum of their amplitudes.
    Waves(Vec<Wave>, f64),
    Bumps {
        cells: [u32; 2],
        radius: f64,
    },
}

/// Largest slope of `(1 - r^2)^2` over `r` in [0, 1]: `8 / (3 sqrt 3)`, at `r = 1 / sqrt 3`.
const BUMP_SLOPE: f64 = 1.539_600_717_839_002;

/// Absolute allowance for the rounding of `cos` and of the sums in a bound.
const ROUNDING: f64 = 1e-12;

impl Procedural {
    /// The function `spec` describes (already validated by its constructors).
    pub fn new(spec: &ProceduralSpec) -> Procedural {
        let kind = match spec {
            ProceduralSpec::Waves(waves) => {
                Kind::Waves(waves.clone(), waves.iter().map(|w| w.amplitude).sum())
            }
            &ProceduralSpec::Bumps { cells, radius } => Kind::Bumps { cells, radius },
        };
        Procedural { kind }
    }

    /// A sum of waves. Errors: those of [`ProceduralSpec::waves`].
    pub fn waves(waves: Vec<Wave>) -> Result<Procedural> {
        ProceduralSpec::waves(waves).map(|spec| Procedural::new(&spec))
    }

    /// A grid of round bumps. Errors: those of [`ProceduralSpec::bumps`].
    pub fn bumps(cells: [u32; 2], radius: f64) -> Result<Procedural> {
        ProceduralSpec::bumps(cells, radius).map(|spec| Procedural::new(&spec))
    }

    /// h at `uv`, in [0, 1].
    pub fn sample(&self, uv: DVec2) -> f64 {
        match &self.kind {
            Kind::Waves(waves, sum) => {
                let total: f64 = waves
                    .iter()
                    .map(|w| w.amplitude * (1.0 + wave_angle(w, uv).cos()))
                    .sum();
                total / (2.0 * sum)
            }
            Kind::Bumps { cells, radius } => {
                let local = |x: f64, n: u32| {
                    let s = x * n as f64;
                    s - s.floor() - 0.5
                };
                let r2 = DVec2::new(local(uv.x, cells[0]), local(uv.y, cells[1])).length_squared()
                    / (radius * radius);
                if r2 < 1.0 {
                    (1.0 - r2) * (1.0 - r2)
                } else {
                    0.0
                }
            }
        }
    }

    /// h_max = 1. Exact for bumps (attained at every cell centre) and for waves whose phases
    /// are all zero (attained at `uv = (0, 0)`); with non-zero phases the waves need not peak
    /// together and 1 is an upper bound (the undisplaced surface is still an outer hull).
    pub fn max(&self) -> f64 {
        1.0
    }

    /// `[lo, hi]` bounding h over the uv rectangle `[min, max]`. Waves: each cosine's exact
    /// range over the interval its angle sweeps (1 if it contains a multiple of 2 pi, -1 if it
    /// contains an odd multiple of pi, else its end values). Bumps: the value at the centre
    /// plus or minus the slope bound times the centre-to-corner distance in cell units.
    /// Both are widened by a rounding allowance and clamped to [0, 1].
    pub fn range(&self, min: DVec2, max: DVec2) -> [f64; 2] {
        let centre = (min + max) * 0.5;
        let half = (max - min) * 0.5;
        let [lo, hi] = match &self.kind {
            Kind::Waves(waves, sum) => {
                let mut out = [0.0, 0.0];
                for w in waves {
                    let theta = wave_angle(w, centre);
                    let spread = TAU
                        * (w.frequency[0].unsigned_abs() as f64 * half.x
                            + w.frequency[1].unsigned_abs() as f64 * half.y);
                    let [c_lo, c_hi] = cos_range(theta - spread, theta + spread);
                    let slack = ROUNDING * (1.0 + theta.abs() + spread);
                    out[0] += w.amplitude * (1.0 + c_lo - slack);
                    out[1] += w.amplitude * (1.0 + c_hi + slack);
                }
                [out[0] / (2.0 * sum), out[1] / (2.0 * sum)]
            }
            Kind::Bumps { cells, radius } => {
                let reach = DVec2::new(half.x * cells[0] as f64, half.y * cells[1] as f64);
                let spread = BUMP_SLOPE / radius * reach.length();
                let h = self.sample(centre);
                [h - spread - ROUNDING, h + spread + ROUNDING]
            }
        };
        [lo.max(0.0), hi.min(1.0)]
    }
}

/// `2 pi (m u + n v) + phi`.
fn wave_angle(w: &Wave, uv: DVec2) -> f64 {
    TAU * (w.frequency[0] as f64 * uv.x + w.frequency[1] as f64 * uv.y) + w.phase
}

/// The range of `cos` over `[a, b]`.
fn cos_range(a: f64, b: f64) -> [f64; 2] {
    if (b - a).is_nan() || b - a >= TAU {
        return [-1.0, 1.0];
    }
    let (ca, cb) = (a.cos(), b.cos());
    let contains = |offset: f64| ((a - offset) / TAU).ceil() <= ((b - offset) / TAU).floor();
    let hi = if contains(0.0) { 1.0 } else { ca.max(cb) };
    let lo = if contains(PI) { -1.0 } else { ca.min(cb) };
    [lo, hi]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(min: DVec2, max: DVec2, n: usize) -> impl Iterator<Item = DVec2> {
        (0..=n).flat_map(move |i| {
            (0..=n).map(move |j| {
                min + (max - min) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64)
            })
        })
    }

    fn functions() -> Vec<Procedural> {
        let wave = |amplitude, frequency, phase| Wave {
            amplitude,
            frequency,
            phase,
        };
        vec![
            Procedural::waves(vec![wave(1.0, [3, 0], 0.0), wave(0.5, [2, -5], 0.0)]).unwrap(),
            Procedural::waves(vec![wave(2.0, [1, 1], 1.0), wave(0.25, [0, 7], -2.0)]).unwrap(),
            Procedural::bumps([4, 3], 0.4).unwrap(),
            Procedural::bumps([1, 1], 0.5).unwrap(),
        ]
    }

    #[test]
    fn values_stay_in_unit_interval_and_peak_at_max() {
        for (i, f) in functions().into_iter().enumerate() {
            for uv in grid(DVec2::splat(-1.0), DVec2::splat(2.0), 90) {
                let h = f.sample(uv);
                assert!((0.0..=f.max()).contains(&h), "function {i}: {h} at {uv}");
            }
        }
        // Zero phases peak at the origin, bumps at their cell centres: h_max is attained.
        let f = functions();
        assert_eq!(f[0].sample(DVec2::ZERO), f[0].max());
        assert_eq!(f[2].sample(DVec2::new(0.375, 0.5)), f[2].max());
        assert_eq!(f[3].sample(DVec2::new(0.5, 0.5)), f[3].max());
    }

    #[test]
    fn periodic_in_u_and_v() {
        for f in functions() {
            for uv in grid(DVec2::ZERO, DVec2::ONE, 7) {
                let shifted = f.sample(uv + DVec2::new(1.0, -2.0));
                assert!((f.sample(uv) - shifted).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn ranges_bound_dense_samples_and_shrink_with_the_box() {
        for f in functions() {
            for (k, corner) in grid(DVec2::splat(-0.3), DVec2::splat(1.1), 6).enumerate() {
                let size = 0.5f64.powi(k as i32 % 8);
                let max = corner + DVec2::new(size, 0.7 * size);
                let [lo, hi] = f.range(corner, max);
                for uv in grid(corner, max, 20) {
                    let h = f.sample(uv);
                    assert!(lo <= h && h <= hi, "{h} outside [{lo}, {hi}]");
                }
                if size < 0.01 {
                    assert!(hi - lo < 0.2, "[{lo}, {hi}] for a box of {size}");
                }
            }
        }
    }

    #[test]
    fn cos_range_cases() {
        assert_eq!(cos_range(-0.1, 0.1)[1], 1.0);
        assert_eq!(cos_range(3.0, 3.5)[0], -1.0);
        let [lo, hi] = cos_range(0.5, 1.0);
        assert_eq!([lo, hi], [1.0f64.cos(), 0.5f64.cos()]);
        assert_eq!(cos_range(0.0, 7.0), [-1.0, 1.0]);
        assert_eq!(cos_range(0.0, f64::NAN), [-1.0, 1.0]);
        assert_eq!(cos_range(TAU * 3.0 - 0.1, TAU * 3.0 + 0.1)[1], 1.0);
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(Procedural::waves(vec![]).is_err());
        let bad = Wave {
            amplitude: 0.0,
            frequency: [1, 0],
            phase: 0.0,
        };
        assert!(Procedural::waves(vec![bad]).is_err());
        assert!(Procedural::bumps([0, 3], 0.3).is_err());
        assert!(Procedural::bumps([2, 3], 0.6).is_err());
        assert!(Procedural::bumps([2, 3], f64::NAN).is_err());
    }
}
