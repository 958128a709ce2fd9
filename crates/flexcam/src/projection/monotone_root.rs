//! Solving an increasing function for a value by Newton's method kept inside a bracket, as
//! the lens models' inverses do (Kannala-Brandt's theta from theta_d, Cycles' lens
//! polynomial's radius from theta).

/// The x in [`low`, `high`] with `value(x) = target`, for `value` strictly increasing there
/// with derivative `slope` and `value(low) <= target <= value(high)`. Newton steps from
/// `start`; every step shrinks the bracket to the side that keeps the root, and a step that
/// would leave it bisects instead, so it converges for every such function. Stops at an
/// exact hit, at a step below 1e-16 max(x, 1), or after 100 steps (bisection alone then has
/// halved the bracket 100 times).
pub(super) fn solve_increasing(
    value: impl Fn(f64) -> f64,
    slope: impl Fn(f64) -> f64,
    target: f64,
    (mut low, mut high): (f64, f64),
    start: f64,
) -> f64 {
    let mut x = start;
    for _ in 0..100 {
        let f = value(x) - target;
        if f == 0.0 {
            break;
        }
        if f < 0.0 {
            low = x;
        } else {
            high = x;
        }
        let newton = x - f / slope(x);
        let next = if newton > low && newton < high {
            newton
        } else {
            0.5 * (low + high)
        };
        if (next - x).abs() <= 1e-16 * x.max(1.0) {
            x = next;
            break;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_where_newton_alone_would_overshoot() {
        // x^3 from a start where Newton's first step leaves [0, 2].
        let x = solve_increasing(|x| x * x * x, |x| 3.0 * x * x, 1.0, (0.0, 2.0), 1e-3);
        assert!((x - 1.0).abs() < 1e-15, "{x}");
        // A flat end: tanh saturates, the bracket still closes in.
        let x = solve_increasing(
            f64::tanh,
            |x| 1.0 / x.cosh().powi(2),
            0.999,
            (0.0, 20.0),
            20.0,
        );
        assert!((x.tanh() - 0.999).abs() < 1e-15, "{x}");
        // The ends themselves.
        assert_eq!(solve_increasing(|x| x, |_| 1.0, 0.0, (0.0, 1.0), 0.0), 0.0);
    }
}
