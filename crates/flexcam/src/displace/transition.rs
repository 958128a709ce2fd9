//! The transition function of Becker and Max 1993 (Ramsey 2005, section 7.3) that chooses,
//! per ray, between the BRDF, redistributed bump mapping and displacement, with blends
//! between them, and partial displacement's corrected view angle.
//!
//! The dissertation's `T(d, theta_V) = (1/d - D) / cos(theta_V)` measures detail by the
//! inverse distance `1/d` from a single eye point, against `D = c f S` (a user constant
//! times the bump map's frequency times its repeats over the surface). Under a nonlinear
//! projection there is no such point and no `1/d` law, so here detail is measured against
//! the ray's own footprint `w`: the width of the pixel's ray at the hit (the distance to the
//! neighbouring pixels' rays, found through the projection). Two lengths of the height
//! field are compared with it, each for the boundary it decides:
//!
//! ```text
//! T_relief  = (R / w - D) / cos(theta_V)
//! T_pattern = (lambda / w - (NYQUIST + 1)) / cos(theta_V)
//! T = max(T_relief, min(T_pattern, -0.3))
//! ```
//!
//! `R` the relief (highest minus lowest displacement) and `lambda` the bumps' mean
//! wavelength, both in world units; `D` a user constant; `theta_V` the angle between the ray
//! and the undisplaced surface's normal. The thresholds are the dissertation's `-1, -0.3,
//! 0.3, 1`: below -1 the BRDF, up to -0.3 a blend of BRDF and bump intensities, up to 0.3
//! redistributed bump mapping, up to 1 partial displacement by `s` rising from 0 to 1, then
//! full displacement.
//!
//! Why two lengths: bump mapping and displacement differ by where the surface is (its
//! silhouette, what hides what, its shadows, the shift of the pattern seen obliquely), by at
//! most the relief: `R / w` is how many pixel footprints tall the bumps are, and where it is
//! above `D` displacement is needed. The BRDF and bump mapping differ by whether the pattern
//! is drawn at all, which is the pattern's frequency against the pixels' (Becker and Max's
//! `f S`): the dissertation's rule is that "when the spatial frequency of a feature exceeds
//! the Nyquist limit (one half cycle per pixel), the BRDF should be used". `lambda / w` is
//! how many footprints one bump spans; at [`NYQUIST`] (2) footprints or fewer `T_pattern` is
//! at most -1 (the BRDF, the pattern's average), from 2.7 on it is above -0.3 (bump mapping
//! draws the pattern); it is capped at -0.3, since the pattern's width alone never asks for
//! displacement. Under a perspective camera `w` grows as `d` times the pixel's angle, so both
//! ratios fall as the dissertation's `1/d`, scaled by the image's resolution. Every weight is
//! continuous in `T`, and `T` in its inputs, so no method switches abruptly.
//!
//! Degenerate cases: at grazing incidence (`cos(theta_V) = 0`) each term is `+inf` where its
//! ratio is at least its constant and `-inf` otherwise; a flat surface (`R = 0`, `lambda =
//! 0`) or an infinite footprint gives the BRDF wherever `D > 0`; NaN inputs give the BRDF.

/// The four thresholds of `T`.
pub const THRESHOLDS: [f64; 4] = [-1.0, -0.3, 0.3, 1.0];

/// Footprints per bump wavelength at and below which the pattern is not drawn: the Nyquist
/// limit, two samples per period (module docs).
pub const NYQUIST: f64 = 2.0;

/// `T` for relief `relief` and mean wavelength `wavelength` over footprint `footprint` (all
/// three in world units), user constant `d` and the cosine of the view angle (module docs).
pub fn value(relief: f64, wavelength: f64, footprint: f64, d: f64, cos_view: f64) -> f64 {
    let by_relief = over_cos(relief / footprint - d, cos_view);
    let by_pattern = over_cos(wavelength / footprint - (NYQUIST + 1.0), cos_view);
    if by_relief.is_nan() || by_pattern.is_nan() {
        return f64::NEG_INFINITY;
    }
    by_relief.max(by_pattern.min(THRESHOLDS[1]))
}

/// `detail / |cos|`: `+-inf` at `cos = 0` by the sign of `detail` (`+inf` at 0), NaN where
/// either is NaN.
fn over_cos(detail: f64, cos_view: f64) -> f64 {
    let cos = cos_view.abs();
    if detail.is_nan() || cos.is_nan() {
        return f64::NAN;
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
        // No pattern term (a wavelength of 0): the relief alone.
        // Three footprints of relief, D = 2, seen head on: T = 1.
        assert!((value(0.3, 0.0, 0.1, 2.0, 1.0) - 1.0).abs() < 1e-12);
        // A wider footprint (further away) lowers T; grazing pushes it to the extremes.
        assert!(value(0.3, 0.0, 0.2, 2.0, 1.0) < value(0.3, 0.0, 0.1, 2.0, 1.0));
        assert!(value(0.3, 0.0, 0.1, 2.0, 0.1) > value(0.3, 0.0, 0.1, 2.0, 1.0));
        assert!(value(0.1, 0.0, 0.1, 2.0, 0.1) < value(0.1, 0.0, 0.1, 2.0, 1.0));
        assert_eq!(value(0.3, 0.0, 0.1, 2.0, 0.0), f64::INFINITY);
        assert_eq!(value(0.1, 0.0, 0.1, 2.0, 0.0), f64::NEG_INFINITY);
        // Flat, an infinite footprint, NaN: the BRDF.
        assert!(blend(value(0.0, 0.0, 0.1, 2.0, 1.0)).brdf == 1.0);
        assert!(blend(value(0.3, 0.5, f64::INFINITY, 2.0, 1.0)).brdf == 1.0);
        assert_eq!(value(f64::NAN, 0.5, 0.1, 2.0, 1.0), f64::NEG_INFINITY);
        assert_eq!(value(0.3, f64::NAN, 0.1, 2.0, 1.0), f64::NEG_INFINITY);
    }

    /// The pattern term: low relief whose bumps span more than 2.7 footprints is bump
    /// mapped, at the Nyquist limit (2 footprints) and below it gets the BRDF, in between
    /// the blend; it never asks for displacement, and where the relief asks for more it
    /// gives way.
    #[test]
    fn resolved_patterns_are_bump_mapped() {
        let low = 0.01;
        let at = |wavelength: f64, cos: f64| blend(value(low, wavelength, 0.1, 2.0, cos));
        assert_eq!(at(0.5, 1.0).bump, 1.0);
        assert_eq!(at(0.28, 1.0).bump, 1.0);
        assert_eq!(at(0.2, 1.0).brdf, 1.0);
        assert_eq!(at(0.1, 1.0).brdf, 1.0);
        let mid = at(0.235, 1.0);
        assert!((mid.brdf - 0.5).abs() < 1e-9 && (mid.bump - 0.5).abs() < 1e-9);
        // Grazing: a resolved pattern stays bump mapped, an unresolved one goes to the BRDF.
        assert_eq!(at(0.5, 0.0).bump, 1.0);
        assert_eq!(at(0.1, 0.0).brdf, 1.0);
        assert_eq!(at(100.0, 1.0).displacement, 0.0);
        // Tall relief displaces whatever the pattern.
        assert_eq!(blend(value(0.5, 0.01, 0.1, 2.0, 1.0)).displacement, 1.0);
        assert_eq!(blend(value(0.5, 100.0, 0.1, 2.0, 1.0)).displacement, 1.0);
        // Continuous in the wavelength across the blend.
        let mut last = at(0.15, 0.8);
        let mut wavelength = 0.15;
        while wavelength < 0.35 {
            wavelength += 1e-5;
            let b = at(wavelength, 0.8);
            assert!((b.bump - last.bump).abs() < 1e-3, "jump at {wavelength}");
            last = b;
        }
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
