//! The transition function of Becker and Max 1993 (Ramsey 2005, section 7.3) that chooses,
//! per ray, between the BRDF, redistributed bump mapping and displacement, with blends
//! between them, and partial displacement's corrected view angle.
//!
//! The dissertation's `T(d, theta_V) = (1/d - D) / cos(theta_V)` measures detail by the
//! inverse distance `1/d` from a single eye point. Under a nonlinear projection there is no
//! such point and no `1/d` law, so here the measure is the ray's own footprint: `w`, the
//! width of the pixel's ray at the hit (the distance to the neighbouring pixels' rays,
//! found through the projection), against the surface's relief `R` (highest minus lowest
//! displacement, world units):
//!
//! ```text
//! T = (R / w - D) / cos(theta_V),
//! ```
//!
//! `R / w` being how many pixel footprints tall the bumps are, `D` a user constant in the
//! same unit, `theta_V` the angle between the ray and the undisplaced surface's normal.
//! Under a perspective camera `w` grows as `d` times the pixel's angle, so `R / w` is the
//! dissertation's `1/d` scaled by the image's resolution: finer images keep displacement
//! further away. The thresholds are the dissertation's `-1, -0.3, 0.3, 1`: below -1 the
//! BRDF, up to -0.3 a blend of BRDF and bump intensities, up to 0.3 redistributed bump
//! mapping, up to 1 partial displacement by `s` rising from 0 to 1, then full displacement.
//! Every weight is continuous in `T`, so no method switches abruptly.
//!
//! Degenerate cases: at grazing incidence (`cos(theta_V) = 0`) `T` is `+inf` where the
//! relief is at least `D` footprints and `-inf` otherwise; a flat surface (`R = 0`) or an
//! infinite footprint gives the BRDF wherever `D > 0`; NaN inputs give the BRDF.

/// The four thresholds of `T`.
pub const THRESHOLDS: [f64; 4] = [-1.0, -0.3, 0.3, 1.0];

/// `T` for relief `relief` over footprint `footprint` (same unit), user constant `d` and the
/// cosine of the view angle (module docs).
pub fn value(relief: f64, footprint: f64, d: f64, cos_view: f64) -> f64 {
    let detail = relief / footprint - d;
    let cos = cos_view.abs();
    if detail.is_nan() || cos.is_nan() {
        return f64::NEG_INFINITY;
    }
    if cos == 0.0 {
        return if detail >= 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
    }
    detail / cos
}

/// How a ray with transition value `T` is shaded: weights of the three methods (summing to
/// 1) and the fraction of the displacement its geometry takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blend {
    /// Weight of the BRDF shading.
    pub brdf: f64,
    /// Weight of the redistributed bump shading.
    pub bump: f64,
    /// Weight of the displaced geometry's shading.
    pub displacement: f64,
    /// `s`: 0 (the undisplaced surface, shaded by bump or BRDF) to 1 (full displacement).
    pub fraction: f64,
}

/// The blend at transition value `t`: linear ramps across the blend intervals.
pub fn blend(t: f64) -> Blend {
    let [e1, e2, e3, e4] = THRESHOLDS;
    let ramp = |a: f64, b: f64| ((t - a) / (b - a)).clamp(0.0, 1.0);
    if t.is_nan() || t < e2 {
        let bump = if t.is_nan() { 0.0 } else { ramp(e1, e2) };
        Blend {
            brdf: 1.0 - bump,
            bump,
            displacement: 0.0,
            fraction: 0.0,
        }
    } else {
        let s = ramp(e3, e4);
        Blend {
            brdf: 0.0,
            bump: 1.0 - s,
            displacement: s,
            fraction: s,
        }
    }
}

/// The view angle `theta_W = atan(s tan(theta_V))` from which the fully displaced surface
/// shows the same points as the surface displaced by fraction `s` shows from `theta_V`:
/// scaling heights by `s` maps rays of slope `tan(theta_W)` to rays of slope
/// `tan(theta_W) / s`. (The dissertation's `t` is `1 - s`.) `s = 1` keeps the angle, `s = 0`
/// looks straight down.
pub fn partial_view_angle(theta_v: f64, s: f64) -> f64 {
    (s * theta_v.tan()).atan()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_choose_the_dissertation_methods() {
        let at = |t: f64| {
            let b = blend(t);
            (b.brdf, b.bump, b.displacement, b.fraction)
        };
        assert_eq!(at(-5.0), (1.0, 0.0, 0.0, 0.0));
        assert_eq!(at(-1.0), (1.0, 0.0, 0.0, 0.0));
        assert_eq!(at(-0.3), (0.0, 1.0, 0.0, 0.0));
        assert_eq!(at(0.0), (0.0, 1.0, 0.0, 0.0));
        assert_eq!(at(0.3), (0.0, 1.0, 0.0, 0.0));
        assert_eq!(at(1.0), (0.0, 0.0, 1.0, 1.0));
        assert_eq!(at(f64::INFINITY), (0.0, 0.0, 1.0, 1.0));
        assert_eq!(at(f64::NEG_INFINITY), (1.0, 0.0, 0.0, 0.0));
        assert_eq!(at(f64::NAN), (1.0, 0.0, 0.0, 0.0));
        let mid = blend(-0.65);
        assert!((mid.brdf - 0.5).abs() < 1e-12 && (mid.bump - 0.5).abs() < 1e-12);
        let mid = blend(0.65);
        assert!((mid.fraction - 0.5).abs() < 1e-12 && (mid.displacement - 0.5).abs() < 1e-12);
    }

    /// No jumps: over a fine sweep of T the weights move by at most the sweep step over the
    /// narrowest ramp, and always sum to 1.
    #[test]
    fn weights_are_continuous_and_sum_to_one() {
        let step = 1e-4;
        let mut last = blend(-3.0);
        let mut t = -3.0;
        while t < 3.0 {
            t += step;
            let b = blend(t);
            assert!((b.brdf + b.bump + b.displacement - 1.0).abs() < 1e-12);
            for (x, y) in [
                (b.brdf, last.brdf),
                (b.bump, last.bump),
                (b.displacement, last.displacement),
                (b.fraction, last.fraction),
            ] {
                assert!((x - y).abs() <= step / 0.7 + 1e-12, "jump at T = {t}");
            }
            last = b;
        }
    }

    #[test]
    fn value_follows_relief_footprint_and_angle() {
        // Three footprints of relief, D = 2, seen head on: T = 1.
        assert!((value(0.3, 0.1, 2.0, 1.0) - 1.0).abs() < 1e-12);
        // A wider footprint (further away) lowers T; grazing pushes it to the extremes.
        assert!(value(0.3, 0.2, 2.0, 1.0) < value(0.3, 0.1, 2.0, 1.0));
        assert!(value(0.3, 0.1, 2.0, 0.1) > value(0.3, 0.1, 2.0, 1.0));
        assert!(value(0.1, 0.1, 2.0, 0.1) < value(0.1, 0.1, 2.0, 1.0));
        assert_eq!(value(0.3, 0.1, 2.0, 0.0), f64::INFINITY);
        assert_eq!(value(0.1, 0.1, 2.0, 0.0), f64::NEG_INFINITY);
        // Flat, an infinite footprint, NaN: the BRDF.
        assert!(blend(value(0.0, 0.1, 2.0, 1.0)).brdf == 1.0);
        assert!(blend(value(0.3, f64::INFINITY, 2.0, 1.0)).brdf == 1.0);
        assert_eq!(value(f64::NAN, 0.1, 2.0, 1.0), f64::NEG_INFINITY);
    }

    #[test]
    fn partial_angle_ends() {
        let theta = 1.2;
        assert!((partial_view_angle(theta, 1.0) - theta).abs() < 1e-12);
        assert_eq!(partial_view_angle(theta, 0.0), 0.0);
        assert!(partial_view_angle(theta, 0.5) < theta);
        assert!(partial_view_angle(theta, 0.5) > partial_view_angle(theta, 0.25));
    }
}
