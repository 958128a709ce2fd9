//! Robust real roots of real polynomials of degree at most 3, in `f64`.
//!
//! This is the numerical core of trilinear point projection (one cubic in the depth `t` per
//! scene point and projection triangle, solved millions of times per frame) and of
//! quadratic-Bezier projectors. Everything here is allocation-free: results come back in
//! [`Roots`], a sorted fixed-capacity list of at most three values.
//!
//! See [`Roots`] for the conventions (multiplicity, degree drop, identically zero polynomial)
//! and the accuracy guarantees.
//!
//! # Method
//!
//! Coefficients are first scaled by a power of two (exact) so the largest is in `[1, 2)`: the
//! result does not depend on the overall scale, and intermediate products cannot overflow.
//! A cubic with `d = 0` is factored exactly (`t = 0` is a root). Otherwise the variable is
//! rescaled by a power of two so that the monic cubic has coefficients below 1 (roots of order
//! one), a near-triple root is detected a posteriori at the inflection point, and *one* real
//! root is computed in closed form: Cardano with `cbrt` when there is one real root, the
//! trigonometric form otherwise, picking the root farthest from the other two (the simple one
//! in a near-double configuration). That root is polished by guarded Newton steps on the
//! original polynomial and deflated (forward or backward synthetic division, whichever is
//! stable, after Kahan). The remaining quadratic is solved with the cancellation-free formula
//! `q = -(b + sign(b) sqrt(disc)) / 2`, `r1 = q / a`, `r2 = c / q`, with the discriminant
//! computed using fused multiply-adds. All its roots are polished on the original cubic. When
//! the sign of the discriminant is within the error propagated from the deflated root, the
//! original cubic decides: if its extremum between the candidate pair is zero to working
//! precision, the pair is a double root there (a tangency).
//!
//! Newton polishing only accepts a step that strictly reduces `|p|`, so it never makes a root
//! worse and stops by itself at the rounding floor or where the derivative vanishes. Double
//! roots are polished as roots of `p'` instead (they are simple roots of the derivative).
//!

use std::fmt;

const EPS: f64 = f64::EPSILON;

/// Most Newton steps spent polishing one root. From a closed-form estimate one step usually
/// reaches the rounding floor and the next is below an ulp (which ends the loop); the extra
/// ones cover poor starts (small roots computed by cancellation against a large shift).
const MAX_POLISH: usize = 4;

/// Two roots closer than this (relative) are one root.
const MERGE_TOL: f64 = 4.0 * EPS;

/// A quadratic discriminant with `|disc| <= DISC_TOL * (b^2 + |4ac|)` is zero: double root.
const DISC_TOL: f64 = 2.0 * EPS;

/// Negative discriminants down to `-TANGENT_WINDOW * (b^2 + |4ac|)` are checked for a tangency
/// of the original polynomial (its extremum within rounding of zero) before being rejected.
const TANGENT_WINDOW: f64 = 64.0 * EPS;

/// `|p(r)| <= RESIDUAL_TOL * S(r)`: `p(r)` is zero to working precision. The Horner error
/// bound for degree 3 is `3 EPSILON * S(r)`.
const RESIDUAL_TOL: f64 = 4.0 * EPS;

/// Tolerance of the a-posteriori triple-root test (`p` and `p'` both zero to working precision
/// at the inflection point), with margin for coefficients that are themselves rounded.
const TRIPLE_TOL: f64 = 8.0 * EPS;

/// The real roots of a polynomial of degree at most 3: at most three distinct values, sorted
/// ascending, each with its multiplicity.
///
/// # Conventions
///
/// * **Distinct roots, with multiplicity.** Each real root is listed once, sorted ascending;
///   [`Roots::multiplicities`] says whether it is simple, double or triple. The trilinear shape
///   algorithm counts solutions modulo 2 (a point crossing the swept volume toggles the edge
///   state), and a double root is a tangency that toggles twice: callers that need the count
///   with multiplicity use [`Roots::total_multiplicity`], callers that want each distinct
///   position once iterate the roots. Two computed roots that coincide to `4 * EPSILON`
///   relative are merged and their multiplicities added.
/// * **Parity invariant.** For any finite polynomial that is not identically zero,
///   `total_multiplicity() + lost_to_infinity()` has the parity of the nominal degree (2 for
///   [`solve_quadratic`], 3 for [`solve_cubic`]): complex roots come in pairs, and when a
///   near-double pair is ambiguous (within rounding of a tangency) it is reported as a double
///   root or as two close simple roots, never as one root.
/// * **Degree drop.** A leading coefficient that is exactly zero, or whose term is below
///   rounding (`EPSILON` relative) at the magnitude of the remaining roots, is dropped: the
///   corresponding root went to infinity (for a quadratic, it would be more than `1/EPSILON`
///   times larger than the other root). It is counted by [`Roots::lost_to_infinity`] so that
///   parity-based callers can account for it (notes/trilinear.md: coplanar normals break the
///   odd-count assumption exactly this way). A root that overflows `f64` is also counted there.
/// * **Identically zero polynomial** (all coefficients zero): every `t` is a root. The result is
///   empty, [`Roots::is_identically_zero`] is `true`, and `lost_to_infinity()` is 0.
/// * **Non-finite coefficients** (NaN or infinite): the result is empty, with
///   `lost_to_infinity() == 0` and `is_identically_zero() == false`; the parity invariant does
///   not apply.
///
/// # Accuracy
///
/// A simple root `r` comes back within a few units of `EPSILON * S(r) / |p'(r)|`, where
/// `S(r) = |a||r|^3 + |b|r^2 + |c||r| + |d|`: the conditioning limit of the root with respect to
/// relative perturbations of the coefficients. For well-separated roots this is ~1e-15
/// relative. Two roots closer than about `sqrt(4 EPSILON S / |p''|)` (~1e-7 relative for roots of
/// order one) cannot be told apart from a double root: the dip of `p` between them is below the
/// rounding error of `p`. They may be reported as one double root near their midpoint or as two
/// close simple roots, and a complex pair that close to the real axis as a double root; each
/// answer is exact for coefficients perturbed by a few `EPSILON` (backward stable). Three
/// roots clustered within about `sqrt(8 EPSILON)` relative are reported as one triple root at
/// the inflection point (the triple-root conditioning limit, `EPSILON^(1/3)`, is far larger).
#[derive(Clone, Copy)]
pub struct Roots {
    values: [f64; 3],
    multiplicities: [u8; 3],
    len: u8,
    lost: u8,
    identically_zero: bool,
}

impl Roots {
    const EMPTY: Roots = Roots {
        values: [0.0; 3],
        multiplicities: [0; 3],
        len: 0,
        lost: 0,
        identically_zero: false,
    };

    /// The distinct real roots, ascending.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }

    /// The multiplicity (1, 2 or 3) of each root of [`as_slice`](Self::as_slice), same order.
    pub fn multiplicities(&self) -> &[u8] {
        &self.multiplicities[..self.len as usize]
    }

    /// Number of distinct real roots.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// `true` when there is no real root (check [`is_identically_zero`](Self::is_identically_zero)
    /// to tell "no root" from "every `t` is a root").
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The distinct real roots, ascending, by value.
    pub fn iter(&self) -> std::iter::Copied<std::slice::Iter<'_, f64>> {
        self.as_slice().iter().copied()
    }

    /// Number of real roots counted with multiplicity.
    pub fn total_multiplicity(&self) -> usize {
        self.multiplicities().iter().map(|&m| m as usize).sum()
    }

    /// Number of roots (counted with multiplicity, real or complex) that the nominal degree
    /// promises but that went to infinity: leading coefficients that are zero or negligible,
    /// or a root that overflows `f64`.
    pub fn lost_to_infinity(&self) -> usize {
        self.lost as usize
    }

    /// `true` when every coefficient was zero, so every `t` is a root (the list is empty).
    pub fn is_identically_zero(&self) -> bool {
        self.identically_zero
    }

    /// Inserts `r` with multiplicity `m`, keeping the list sorted and merging with an equal
    /// root. A non-finite `r` (overflow) is counted as lost to infinity.
    fn push(&mut self, r: f64, m: u8) {
        if !r.is_finite() {
            self.lost += m;
            return;
        }
        let r = r + 0.0; // -0.0 -> +0.0
        let n = self.len as usize;
        for i in 0..n {
            let v = self.values[i];
            if (v - r).abs() <= MERGE_TOL * v.abs().max(r.abs()) {
                self.multiplicities[i] += m;
                return;
            }
        }
        // Total multiplicity never exceeds the degree, so a fourth distinct root cannot occur.
        debug_assert!(n < 3, "more than three roots");
        if n >= 3 {
            return;
        }
        let mut i = n;
        while i > 0 && self.values[i - 1] > r {
            self.values[i] = self.values[i - 1];
            self.multiplicities[i] = self.multiplicities[i - 1];
            i -= 1;
        }
        self.values[i] = r;
        self.multiplicities[i] = m;
        self.len += 1;
    }
}

impl fmt::Debug for Roots {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Roots")
            .field("roots", &self.as_slice())
            .field("multiplicities", &self.multiplicities())
            .field("lost_to_infinity", &self.lost)
            .field("identically_zero", &self.identically_zero)
            .finish()
    }
}

impl<'a> IntoIterator for &'a Roots {
    type Item = f64;
    type IntoIter = std::iter::Copied<std::slice::Iter<'a, f64>>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl IntoIterator for Roots {
    type Item = f64;
    type IntoIter = std::iter::Take<std::array::IntoIter<f64, 3>>;

    fn into_iter(self) -> Self::IntoIter {
        self.values.into_iter().take(self.len as usize)
    }
}

/// Real roots of `a t^2 + b t + c`.
///
/// Degenerate cases: `a` zero or negligible (`|a c| <= EPSILON b^2`, the large root would exceed
/// `1/EPSILON` times the small one) -> the linear root `-c/b` refined on the full quadratic, and
/// `lost_to_infinity() == 1`; `a = b = 0, c != 0` -> no root, `lost_to_infinity() == 2`;
/// `a = b = c = 0` -> [`Roots::is_identically_zero`]; a discriminant within rounding of zero ->
/// one root of multiplicity 2; `c = 0` -> a root exactly at 0.
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> Roots {
    let mut out = Roots::EMPTY;
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return out;
    }
    let Some([a, b, c]) = normalise([a, b, c]) else {
        out.identically_zero = true;
        return out;
    };
    let target = Poly3 {
        a: 0.0,
        b: a,
        c: b,
        d: c,
    };
    quadratic_into(a, b, c, 0.0, &target, &mut out);
    out
}

/// Real roots of `a t^3 + b t^2 + c t + d`, sorted ascending, each once with its multiplicity.
///
/// Degenerate cases: `a` zero, or negligible at the scale of the other roots (the dropped root
/// went to infinity) -> the quadratic `b, c, d` with `lost_to_infinity() >= 1`, its roots
/// refined on the full cubic; `a = b = 0` -> linear; `d = 0` -> a root exactly at 0; a triple
/// root -> one root of multiplicity 3; a double root -> one root of multiplicity 2 (or two
/// simple roots closer than the conditioning limit, see [`Roots`]); all coefficients
/// zero -> [`Roots::is_identically_zero`].
pub fn solve_cubic(a: f64, b: f64, c: f64, d: f64) -> Roots {
    let mut out = Roots::EMPTY;
    if !(a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite()) {
        return out;
    }
    let Some([a, b, c, d]) = normalise([a, b, c, d]) else {
        out.identically_zero = true;
        return out;
    };
    cubic_into(&Poly3 { a, b, c, d }, &mut out);
    out
}

/// `a t^3 + b t^2 + c t + d`, the polynomial that roots are polished against.
#[derive(Clone, Copy, Debug)]
struct Poly3 {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
}

impl Poly3 {
    /// `(p(t), p'(t))` by Horner.
    #[inline]
    fn eval(&self, t: f64) -> (f64, f64) {
        let p = ((self.a * t + self.b) * t + self.c) * t + self.d;
        let dp = (3.0 * self.a * t + 2.0 * self.b) * t + self.c;
        (p, dp)
    }

    /// `(p'(t), p''(t))`.
    #[inline]
    fn eval_derivative(&self, t: f64) -> (f64, f64) {
        let dp = (3.0 * self.a * t + 2.0 * self.b) * t + self.c;
        let ddp = 6.0 * self.a * t + 2.0 * self.b;
        (dp, ddp)
    }

    /// `S(t) = |a||t|^3 + |b|t^2 + |c||t| + |d|`, the scale of the rounding error of `p(t)`.
    #[inline]
    fn magnitude(&self, t: f64) -> f64 {
        let x = t.abs();
        ((self.a.abs() * x + self.b.abs()) * x + self.c.abs()) * x + self.d.abs()
    }

    /// `3|a|t^2 + 2|b||t| + |c|`, the scale of the rounding error of `p'(t)`.
    #[inline]
    fn derivative_magnitude(&self, t: f64) -> f64 {
        let x = t.abs();
        (3.0 * self.a.abs() * x + 2.0 * self.b.abs()) * x + self.c.abs()
    }
}

/// Newton on `p` from `t`, accepting only steps that strictly reduce `|p|` (so a vanishing or
/// tiny derivative, which throws the iterate far away, is rejected rather than followed).
#[inline]
fn polish_simple(poly: &Poly3, t: f64) -> f64 {
    polish_simple_with_derivative(poly, t).0
}

/// [`polish_simple`], also returning `p'` at (or within an ulp of) the polished root. A step
/// below one ulp of `t` is taken without re-evaluating: it ends the iteration, and saves the
/// evaluation that would only confirm convergence.
#[inline]
fn polish_simple_with_derivative(poly: &Poly3, mut t: f64) -> (f64, f64) {
    let (mut p, mut dp) = poly.eval(t);
    for _ in 0..MAX_POLISH {
        if p == 0.0 || dp == 0.0 {
            break;
        }
        let step = p / dp;
        let next = t - step;
        if step.abs() <= EPS * t.abs() {
            t = next;
            break;
        }
        let (pn, dpn) = poly.eval(next);
        if pn.is_nan() || pn.abs() >= p.abs() {
            break;
        }
        t = next;
        p = pn;
        dp = dpn;
    }
    (t, dp)
}

/// Newton on `p'` from `t`: a double root of `p` is a simple root of `p'`, so this converges
/// quadratically where Newton on `p` would crawl. Accepts only steps that reduce `|p'|`.
#[inline]
fn polish_double(poly: &Poly3, mut t: f64) -> f64 {
    let (mut dp, mut ddp) = poly.eval_derivative(t);
    for _ in 0..MAX_POLISH {
        if dp == 0.0 || ddp == 0.0 {
            break;
        }
        let next = t - dp / ddp;
        let (dpn, ddpn) = poly.eval_derivative(next);
        if dpn.is_nan() || dpn.abs() >= dp.abs() {
            break;
        }
        t = next;
        dp = dpn;
        ddp = ddpn;
    }
    t
}

/// `floor(log2 |x|)` for finite non-zero `x`, subnormals included.
#[inline]
fn exponent(x: f64) -> i32 {
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i32;
    if biased == 0 {
        // Subnormal: scale into the normal range first (exact).
        exponent(x * pow2(64)) - 64
    } else {
        biased - 1023
    }
}

/// `2^n` for `n` in `[-1022, 1023]`.
#[inline]
fn pow2(n: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&n));
    f64::from_bits(((n + 1023) as u64) << 52)
}

/// `x * 2^n`, exact unless the result overflows or underflows, for any `n`.
#[inline]
fn scale2(mut x: f64, mut n: i32) -> f64 {
    for _ in 0..3 {
        if n == 0 {
            break;
        }
        let step = n.clamp(-1022, 1023);
        x *= pow2(step);
        n -= step;
    }
    x
}

/// `ceil(n / d)` for `d > 0`.
#[inline]
fn ceil_div(n: i32, d: i32) -> i32 {
    -((-n).div_euclid(d))
}

/// Scales the coefficients by a power of two (exactly: same roots) so that the largest
/// magnitude is in `[1, 2)`. `None` when all are zero.
#[inline]
fn normalise<const N: usize>(k: [f64; N]) -> Option<[f64; N]> {
    let m = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return None;
    }
    let e = exponent(m);
    Some(k.map(|x| scale2(x, -e)))
}

/// `b^2 - 4ac` with the rounding of both products compensated by fused multiply-adds
/// (Kahan): accurate to a few ulps of the result even when the products nearly cancel.
#[inline]
fn discriminant(a: f64, b: f64, c: f64) -> f64 {
    let bb = b * b;
    let bb_err = b.mul_add(b, -bb);
    let ac4 = 4.0 * a * c;
    let ac4_err = (4.0 * a).mul_add(c, -ac4);
    (bb - ac4) + (bb_err - ac4_err)
}

/// Pushes the root of `a t + b` (polished on `target`), or counts it lost if `a == 0`.
fn linear_into(a: f64, b: f64, target: &Poly3, out: &mut Roots) {
    if a == 0.0 {
        out.lost += 1;
        return;
    }
    out.push(polish_simple(target, -b / a), 1);
}

/// Pushes the real roots of `a t^2 + b t + c`, each polished on `target` (a polynomial having
/// the same roots, possibly with more).
///
/// `slack` is the uncertainty of the discriminant as a fraction of `b^2 + |4ac|` beyond its own
/// rounding: zero for exact coefficients, the propagated error of the deflated root for a
/// deflated cubic. Within that band the decision between "two roots", "double root" and "no
/// root" is taken on `target` itself: if its extremum between the candidate roots is zero to
/// working precision, the pair is a double root there (a tangency), otherwise the sign of the
/// discriminant decides.
fn quadratic_into(a: f64, b: f64, c: f64, slack: f64, target: &Poly3, out: &mut Roots) {
    if a == 0.0 {
        out.lost += 1;
        linear_into(b, c, target, out);
        return;
    }
    if c == 0.0 {
        // Exact factor t; polishing keeps 0 when it is a root of the target and moves it when
        // the zero came from cancellation in a deflation.
        out.push(polish_simple(target, 0.0), 1);
        linear_into(a, b, target, out);
        return;
    }
    let Some([a, b, c]) = normalise([a, b, c]) else {
        unreachable!("a != 0");
    };
    if b != 0.0 && (a * c).abs() <= EPS * b * b {
        // The large root -b/a is over 1/EPSILON times the small one: treat a as zero.
        out.lost += 1;
        out.push(polish_simple(target, -c / b), 1);
        return;
    }
    let scale = b * b + (4.0 * a * c).abs();
    let disc = discriminant(a, b, c);
    let two_roots = |out: &mut Roots| {
        let q = -0.5 * (b + disc.sqrt().copysign(b));
        out.push(polish_simple(target, q / a), 1);
        out.push(polish_simple(target, c / q), 1);
    };
    if disc > (DISC_TOL + slack) * scale {
        two_roots(out);
    } else if disc.abs() <= DISC_TOL * scale {
        out.push(polish_double(target, -b / (2.0 * a)), 2);
    } else if disc >= -(TANGENT_WINDOW + slack) * scale {
        let r = polish_double(target, -b / (2.0 * a));
        if target.eval(r).0.abs() <= RESIDUAL_TOL * target.magnitude(r) {
            out.push(r, 2);
        } else if disc > 0.0 {
            two_roots(out);
        }
    }
}

/// Whether the cubic term of a cubic with `d != 0` is below rounding at the magnitude `rho` of
/// the finite roots of `b t^2 + c t + d` (those of `c t + d` when `b` is negligible there too):
/// then the cubic's extra root is at least ~`1/EPSILON` times larger than the others (or
/// `1/sqrt(EPSILON)` when `b` vanishes or is negligible) and is dropped.
/// Scale-invariant in `t`, so cubics whose roots are all large are never mistaken for
/// quadratics.
#[inline]
fn cubic_term_negligible(a: f64, b: f64, c: f64, d: f64) -> bool {
    // When b is itself negligible in b t^2 + c t + d, the finite roots are those of c t + d.
    let b_negligible = c != 0.0 && (b * d).abs() <= EPS * c * c;
    let rho = if b != 0.0 && !b_negligible {
        (c / b).abs().max((d / b).abs().sqrt())
    } else if c != 0.0 {
        (d / c).abs()
    } else {
        // a t^3 + d: three roots of equal magnitude, none at infinity.
        return false;
    };
    if !(rho.is_finite() && rho > 0.0) {
        return false;
    }
    let cubic = a.abs() * rho * rho * rho;
    let rest = (b.abs() * rho * rho).max(c.abs() * rho).max(d.abs());
    cubic <= EPS * rest
}

/// Pushes the real roots of the normalised cubic `poly`.
fn cubic_into(poly: &Poly3, out: &mut Roots) {
    let Poly3 { a, b, c, d } = *poly;
    if d == 0.0 {
        out.push(0.0, 1);
        quadratic_into(a, b, c, 0.0, poly, out);
        return;
    }
    if a == 0.0 || cubic_term_negligible(a, b, c, d) {
        out.lost += 1;
        quadratic_into(b, c, d, 0.0, poly, out);
        return;
    }

    // Rescale t = 2^k v so that v^3 + bb v^2 + cc v + dd has all |coefficients| < 1: its roots
    // are then of order one and no intermediate below can overflow.
    let ea = exponent(a);
    let mut k = ceil_div(exponent(d) - ea + 1, 3);
    if c != 0.0 {
        k = k.max(ceil_div(exponent(c) - ea + 1, 2));
    }
    if b != 0.0 {
        k = k.max(exponent(b) - ea + 1);
    }
    let am = scale2(a, -ea);
    let bb = scale2(b, -k - ea) / am;
    let cc = scale2(c, -2 * k - ea) / am;
    let dd = scale2(d, -3 * k - ea) / am;

    // Depressed cubic w^3 + p w + q with v = w - s.
    let s = bb / 3.0;

    // Triple root: p and p' vanish to working precision at the inflection point.
    let inflection = scale2(-s, k);
    let (p0, p1) = poly.eval(inflection);
    if p0.abs() <= TRIPLE_TOL * poly.magnitude(inflection)
        && p1.abs() <= TRIPLE_TOL * poly.derivative_magnitude(inflection)
    {
        out.push(inflection, 3);
        return;
    }

    let p = cc - 3.0 * s * s;
    let q = dd - s * (cc - 2.0 * s * s);
    let half_q = 0.5 * q;
    let third_p = p / 3.0;
    let disc = half_q * half_q + third_p * third_p * third_p;
    let w = if disc >= 0.0 {
        // One real root (or a double root and the simple one, which this is): Cardano in the
        // cancellation-free form u = -sign(q) cbrt(|q|/2 + sqrt(disc)), w = u - p / (3u).
        let u = -(half_q.abs() + disc.sqrt()).cbrt().copysign(half_q);
        if u == 0.0 {
            0.0
        } else {
            u - third_p / u
        }
    } else {
        // Three real roots (p < 0): w_k = 2r cos((phi - 2 pi k) / 3). Take the one farthest
        // from the other two: the largest when phi < pi/2, else the smallest. In a near-double
        // configuration this is the simple root, which deflates accurately.
        let r = (-third_p).sqrt();
        let cos_phi = (-half_q / (r * r * r)).clamp(-1.0, 1.0);
        let phi = cos_phi.acos();
        let angle = if phi < std::f64::consts::FRAC_PI_2 {
            phi / 3.0
        } else {
            (phi + 2.0 * std::f64::consts::PI) / 3.0
        };
        2.0 * r * angle.cos()
    };
    let (t1, dp1) = polish_simple_with_derivative(poly, scale2(w - s, k));

    // Deflate: p(t) = (t - t1)(a t^2 + b1 t + c2). Forward synthetic division is stable when
    // t1 is small compared with the other roots, backward when it is large (Kahan's rule).
    let q0 = a * t1;
    let mut b1 = q0 + b;
    let mut c2 = b1 * t1 + c;
    let backward = t1 != 0.0 && (q0 * t1).abs() > (d / t1).abs();
    if backward {
        c2 = -d / t1;
        b1 = (c2 - c) / t1;
    }

    // Error of the quotient from the error of t1 (its conditioning EPSILON S / |p'|), carried
    // to the discriminant as a fraction of its scale.
    let dt = 4.0 * EPS * poly.magnitude(t1) / dp1.abs();
    let (db1, dc2) = if backward {
        let dc2 = c2.abs() * dt / t1.abs();
        ((dc2 + b1.abs() * dt) / t1.abs(), dc2)
    } else {
        let db1 = a.abs() * dt;
        (db1, b1.abs() * dt + t1.abs() * db1)
    };
    let slack = (2.0 * b1.abs() * db1 + 4.0 * a.abs() * dc2) / (b1 * b1 + (4.0 * a * c2).abs());
    let slack = if slack.is_nan() { f64::INFINITY } else { slack };

    out.push(t1, 1);
    quadratic_into(a, b1, c2, slack, poly, out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Coefficients of `s (t - r0)(t - r1)(t - r2)`.
    fn expand(s: f64, r: [f64; 3]) -> [f64; 4] {
        [
            s,
            -s * (r[0] + r[1] + r[2]),
            s * (r[0] * r[1] + r[0] * r[2] + r[1] * r[2]),
            -s * r[0] * r[1] * r[2],
        ]
    }

    fn cubic(k: [f64; 4]) -> Roots {
        solve_cubic(k[0], k[1], k[2], k[3])
    }

    fn eval(k: [f64; 4], t: f64) -> f64 {
        ((k[0] * t + k[1]) * t + k[2]) * t + k[3]
    }

    fn magnitude(k: [f64; 4], t: f64) -> f64 {
        Poly3 {
            a: k[0],
            b: k[1],
            c: k[2],
            d: k[3],
        }
        .magnitude(t)
    }

    /// Conditioning bound for the simple root `r[i]` of `s (t - r0)(t - r1)(t - r2)` when the
    /// coefficients are computed in floating point: `K EPSILON S(r) / |p'(r)|`, with `S` taken
    /// over the expansion terms (the coefficients themselves may have cancelled).
    fn simple_root_bound(s: f64, r: [f64; 3], i: usize) -> f64 {
        let (x, o) = (r[i], [r[(i + 1) % 3], r[(i + 2) % 3]]);
        let ax = x.abs();
        let sum1 = r[0].abs() + r[1].abs() + r[2].abs();
        let sum2 = (r[0] * r[1]).abs() + (r[0] * r[2]).abs() + (r[1] * r[2]).abs();
        let prod = (r[0] * r[1] * r[2]).abs();
        let terms = s.abs() * (((ax + sum1) * ax + sum2) * ax + prod);
        let dp = (s * (x - o[0]) * (x - o[1])).abs();
        32.0 * EPS * terms / dp
    }

    fn assert_close(got: f64, want: f64, tol: f64) {
        assert!(
            (got - want).abs() <= tol,
            "got {got:e}, want {want:e} (error {:e} > {tol:e})",
            (got - want).abs()
        );
    }

    // ---- Roots container -------------------------------------------------------------------

    #[test]
    fn roots_container_sorts_merges_and_iterates() {
        let mut r = Roots::EMPTY;
        assert!(r.is_empty());
        r.push(2.0, 1);
        r.push(-1.0, 1);
        r.push(-0.0, 1);
        assert_eq!(r.as_slice(), &[-1.0, 0.0, 2.0]);
        assert!(
            r.as_slice()[1].is_sign_positive(),
            "-0.0 normalised to +0.0"
        );
        assert_eq!(r.len(), 3);
        assert_eq!(r.iter().collect::<Vec<_>>(), vec![-1.0, 0.0, 2.0]);
        assert_eq!((&r).into_iter().sum::<f64>(), 1.0);
        assert_eq!(r.into_iter().collect::<Vec<_>>(), vec![-1.0, 0.0, 2.0]);

        let mut m = Roots::EMPTY;
        m.push(1.0, 1);
        m.push(1.0 + EPS, 2);
        assert_eq!(m.as_slice(), &[1.0]);
        assert_eq!(m.multiplicities(), &[3]);
        assert_eq!(m.total_multiplicity(), 3);

        let mut o = Roots::EMPTY;
        o.push(f64::INFINITY, 1);
        assert!(o.is_empty());
        assert_eq!(o.lost_to_infinity(), 1);
        let dbg = format!("{o:?}");
        assert!(dbg.contains("lost_to_infinity: 1"), "{dbg}");
    }

    // ---- Quadratic ---------------------------------------------------------------------------

    #[test]
    fn quadratic_two_roots_without_cancellation() {
        // (t - 1e-6)(t - 1e6): the textbook formula loses the small root to cancellation.
        let r = solve_quadratic(1.0, -(1e6 + 1e-6), 1.0);
        assert_eq!(r.len(), 2);
        assert_eq!(r.lost_to_infinity(), 0);
        assert_close(r.as_slice()[0], 1e-6, 1e-21);
        assert_close(r.as_slice()[1], 1e6, 1e-9);
        assert_eq!(r.multiplicities(), &[1, 1]);
    }

    #[test]
    fn quadratic_degenerate_cases() {
        // Linear: a = 0.
        let r = solve_quadratic(0.0, 2.0, -3.0);
        assert_eq!(r.as_slice(), &[1.5]);
        assert_eq!(r.lost_to_infinity(), 1);
        // Constant: a = b = 0, c != 0: no root, both went to infinity.
        let r = solve_quadratic(0.0, 0.0, 5.0);
        assert!(r.is_empty() && !r.is_identically_zero());
        assert_eq!(r.lost_to_infinity(), 2);
        // Identically zero.
        let r = solve_quadratic(0.0, 0.0, 0.0);
        assert!(r.is_empty() && r.is_identically_zero());
        assert_eq!(r.lost_to_infinity(), 0);
        // Double root.
        let r = solve_quadratic(2.0, -12.0, 18.0);
        assert_eq!(r.as_slice(), &[3.0]);
        assert_eq!(r.multiplicities(), &[2]);
        // Negative discriminant.
        let r = solve_quadratic(1.0, 0.0, 1.0);
        assert!(r.is_empty() && !r.is_identically_zero());
        assert_eq!(r.lost_to_infinity(), 0);
        // c = 0: exact root at 0.
        let r = solve_quadratic(3.0, -6.0, 0.0);
        assert_eq!(r.as_slice(), &[0.0, 2.0]);
        // b = c = 0: double root at 0.
        let r = solve_quadratic(3.0, 0.0, 0.0);
        assert_eq!(r.as_slice(), &[0.0]);
        assert_eq!(r.multiplicities(), &[2]);
        // b = 0: symmetric pair.
        let r = solve_quadratic(1.0, 0.0, -4.0);
        assert_eq!(r.as_slice(), &[-2.0, 2.0]);
        // Non-finite coefficients.
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let r = solve_quadratic(1.0, bad, 1.0);
            assert!(r.is_empty() && !r.is_identically_zero() && r.lost_to_infinity() == 0);
        }
    }

    #[test]
    fn quadratic_negligible_leading_coefficient_drops_the_far_root() {
        // 1e-20 t^2 + t + 1: roots ~ -1 and ~ -1e20 (beyond 1/EPSILON times -1).
        let r = solve_quadratic(1e-20, 1.0, 1.0);
        assert_eq!(r.len(), 1);
        assert_eq!(r.lost_to_infinity(), 1);
        assert_close(r.as_slice()[0], -1.0, 1e-15);
        // 1e-12 t^2 + t + 1 keeps both (ratio 1e12 < 1/EPSILON).
        let r = solve_quadratic(1e-12, 1.0, 1.0);
        assert_eq!(r.len(), 2);
        assert_eq!(r.lost_to_infinity(), 0);
        assert_close(r.as_slice()[0], -1e12 + 1.0, 1e-3);
        assert_close(r.as_slice()[1], -1.0 - 1e-12, 1e-15);
    }

    #[test]
    fn quadratic_is_scale_invariant() {
        for s in [1e-300, 1e-150, 1.0, 1e150, 1e300] {
            // 3s and 2s are rounded: allow an ulp or two.
            let r = solve_quadratic(s, -3.0 * s, 2.0 * s);
            assert_eq!(r.len(), 2, "scale {s:e}");
            assert_close(r.as_slice()[0], 1.0, 4.0 * EPS);
            assert_close(r.as_slice()[1], 2.0, 8.0 * EPS);
        }
        // Tiny discriminant of huge coefficients: b^2 overflows without normalisation.
        let r = solve_quadratic(1e300, -2e300, 1e300);
        assert_eq!(r.as_slice(), &[1.0]);
        assert_eq!(r.multiplicities(), &[2]);
    }

    // ---- Cubic: degenerate cases ------------------------------------------------------------

    #[test]
    fn cubic_identically_zero_and_constant() {
        let r = solve_cubic(0.0, 0.0, 0.0, 0.0);
        assert!(r.is_empty() && r.is_identically_zero());
        let r = solve_cubic(0.0, 0.0, 0.0, -2.0);
        assert!(r.is_empty() && !r.is_identically_zero());
        assert_eq!(r.lost_to_infinity(), 3);
    }

    #[test]
    fn cubic_with_zero_leading_coefficients() {
        // a = 0: quadratic.
        let r = solve_cubic(0.0, 1.0, -3.0, 2.0);
        assert_eq!(r.as_slice(), &[1.0, 2.0]);
        assert_eq!(r.lost_to_infinity(), 1);
        // a = b = 0: linear (orthographic trilinear case).
        let r = solve_cubic(0.0, 0.0, 4.0, -1.0);
        assert_eq!(r.as_slice(), &[0.25]);
        assert_eq!(r.lost_to_infinity(), 2);
    }

    #[test]
    fn cubic_negligible_leading_coefficient() {
        // 1e-20 (t - 1)(t - 2)(t - 1e20): the root at 1e20 is beyond 1/EPSILON times the others.
        let k = expand(1e-20, [1.0, 2.0, 1e20]);
        let r = cubic(k);
        assert_eq!(r.lost_to_infinity(), 1, "{r:?}");
        assert_eq!(r.len(), 2);
        assert_close(r.as_slice()[0], 1.0, 1e-14);
        assert_close(r.as_slice()[1], 2.0, 1e-14);
        // Rounding-level a on top of a quadratic (coplanar normals computed in floating point).
        let r = solve_cubic(3e-17, 1.0, -3.0, 2.0);
        assert_eq!(r.lost_to_infinity(), 1);
        assert_close(r.as_slice()[0], 1.0, 1e-15);
        assert_close(r.as_slice()[1], 2.0, 1e-15);
        // Small but significant a: the far root is reported.
        let r = cubic(expand(1.0, [1.0, 2.0, 1e9]));
        assert_eq!(r.lost_to_infinity(), 0);
        assert_eq!(r.len(), 3);
        assert_close(r.as_slice()[2], 1e9, 1e-6);
        // a and b both negligible: linear root, two roots lost.
        let r = solve_cubic(-1e-40, 1e-30, 1.0, -1.0);
        assert_eq!(r.lost_to_infinity(), 2, "{r:?}");
        assert_close(r.as_slice()[0], 1.0, 1e-15);
    }

    #[test]
    fn cubic_large_roots_are_not_a_degree_drop() {
        // Coefficients span 1..6e18, but the cubic term is not negligible at t ~ 1e6.
        let r = cubic(expand(1.0, [1e6, 2e6, 3e6]));
        assert_eq!(r.lost_to_infinity(), 0);
        assert_eq!(r.len(), 3);
        for (got, want) in r.iter().zip([1e6, 2e6, 3e6]) {
            assert_close(got, want, 1e-9 * want);
        }
    }

    #[test]
    fn cubic_zero_constant_term_gives_exact_zero_root() {
        let r = cubic(expand(1.0, [0.0, 0.5, -3.0]));
        assert_eq!(r.len(), 3);
        assert_eq!(r.as_slice()[1], 0.0);
        assert_close(r.as_slice()[0], -3.0, 1e-15);
        assert_close(r.as_slice()[2], 0.5, 1e-15);
        // d = c = 0: double root at zero.
        let r = solve_cubic(1.0, -2.0, 0.0, 0.0);
        assert_eq!(r.as_slice(), &[0.0, 2.0]);
        assert_eq!(r.multiplicities(), &[2, 1]);
        // d = c = b = 0: triple root at zero.
        let r = solve_cubic(5.0, 0.0, 0.0, 0.0);
        assert_eq!(r.as_slice(), &[0.0]);
        assert_eq!(r.multiplicities(), &[3]);
    }

    #[test]
    fn cubic_triple_roots() {
        for x in [1.0, -2.5, 0.3, 1e-5, 7e4] {
            for s in [1.0, -3.0, 1e-9] {
                let r = cubic(expand(s, [x, x, x]));
                assert_eq!(r.len(), 1, "x = {x}, s = {s}: {r:?}");
                assert_eq!(r.multiplicities(), &[3]);
                assert_close(r.as_slice()[0], x, 1e-14 * x.abs());
            }
        }
    }

    #[test]
    fn cubic_double_roots() {
        for (double, simple) in [
            (1.0, 2.0),
            (2.0, 1.0),
            (-1.0, 3.0),
            (0.3, -0.7),
            (1e3, 1e-3),
        ] {
            let r = cubic(expand(1.0, [double, double, simple]));
            assert_eq!(r.total_multiplicity(), 3, "{double} {simple}: {r:?}");
            let i = if double < simple { 0 } else { r.len() - 1 };
            let j = if double < simple { r.len() - 1 } else { 0 };
            assert_close(r.as_slice()[j], simple, 1e-13 * simple.abs());
            // A double root is ill-conditioned (sqrt(EPSILON)); polishing on p' usually does
            // much better.
            for &x in r.as_slice() {
                if x != r.as_slice()[j] {
                    assert_close(x, double, 1e-7 * double.abs());
                }
            }
            assert_close(r.as_slice()[i], double, 1e-7 * double.abs());
        }
        // Exactly representable: exact double root.
        let r = solve_cubic(1.0, -4.0, 5.0, -2.0); // (t - 1)^2 (t - 2)
        assert_eq!(r.as_slice(), &[1.0, 2.0]);
        assert_eq!(r.multiplicities(), &[2, 1]);
    }

    #[test]
    fn cubic_near_zero_discriminant() {
        // t^3 - 3t + 2 = (t - 1)^2 (t + 2), perturbed by +-delta in d. For delta above the
        // conditioning limit the pair splits (delta < 0) or turns complex (delta > 0); at the
        // rounding level either answer is valid but parity holds and nothing spurious appears.
        for delta in [
            0.0, 1e-17, -1e-17, 1e-15, -1e-15, 1e-10, -1e-10, 1e-6, -1e-6,
        ] {
            let r = solve_cubic(1.0, 0.0, -3.0, 2.0 + delta);
            assert_eq!(r.total_multiplicity() % 2, 1, "delta {delta:e}: {r:?}");
            // The simple root moves by delta / p'(-2) = delta / 9.
            assert_close(
                r.as_slice()[0],
                -2.0 - delta / 9.0,
                1e-14 + delta.abs() * 1e-3,
            );
            for &x in &r.as_slice()[1..] {
                // The pair sits at 1 +- sqrt(|delta| / 3).
                assert_close(x, 1.0, 2.0 * (delta.abs() / 3.0).sqrt() + 1e-7);
            }
            if delta >= 1e-10 {
                assert_eq!(r.len(), 1, "delta {delta:e}: complex pair");
            }
            if delta <= -1e-10 {
                assert_eq!(r.len(), 3, "delta {delta:e}: split pair");
                assert_eq!(r.multiplicities(), &[1, 1, 1]);
            }
        }
    }

    #[test]
    fn cubic_one_real_root() {
        // (t - 2)(t^2 + 1)
        let r = solve_cubic(1.0, -2.0, 1.0, -2.0);
        assert_eq!(r.as_slice(), &[2.0]);
        // t^3 + 1
        let r = solve_cubic(1.0, 0.0, 0.0, 1.0);
        assert_eq!(r.as_slice(), &[-1.0]);
        // Tiny root next to a complex pair: t^3 + t - 1e-300.
        let r = solve_cubic(1.0, 0.0, 1.0, -1e-300);
        assert_eq!(r.len(), 1);
        assert_close(r.as_slice()[0], 1e-300, 1e-315);
    }

    #[test]
    fn cubic_is_scale_invariant() {
        let k = expand(1.0, [-1.5, 0.25, 4.0]);
        let reference = cubic(k);
        for s in [1e-300, 1e-200, 1e-100, 1e100, 1e200, 1e300] {
            let r = cubic(k.map(|x| x * s));
            assert_eq!(r.len(), 3);
            for (got, want) in r.iter().zip(reference.iter()) {
                assert_close(got, want, 1e-14 * want.abs());
            }
        }
        // Extreme coefficient ratio with no degree drop: t^3 * 1e-200 + 1 has its root at
        // -cbrt(1e200), and the naive monic form would overflow in q^2.
        let r = solve_cubic(1e-200, 0.0, 0.0, 1.0);
        assert_eq!(r.len(), 1);
        assert_close(r.as_slice()[0], -(1e200f64.cbrt()), 1e-14 * 1e200f64.cbrt());
    }

    // ---- Cubic: known roots ------------------------------------------------------------------

    #[test]
    fn cubic_wide_range_roots() {
        let roots = [1e-6, 1.0, 1e6];
        let r = cubic(expand(1.0, roots));
        assert_eq!(r.len(), 3);
        for (got, want) in r.iter().zip(roots) {
            assert_close(got, want, 1e-12 * want);
        }
        let roots = [-1e6, -3e-6, 2e-6];
        let r = cubic(expand(-2.5, roots));
        assert_eq!(r.len(), 3);
        for (got, want) in r.iter().zip(roots) {
            assert_close(got, want, 1e-12 * want.abs());
        }
    }

    #[test]
    fn cubic_clustered_roots_reach_the_conditioning_limit() {
        // 1 and 1 + 1e-6: each is determined by the coefficients only to about
        // EPSILON S(1) / |p'(1)| = 2.2e-16 * 12 / 1e-6 ~ 2.7e-9, which is what we get (within the
        // 32x margin of simple_root_bound); the well-separated root 2 to ~1e-15 (bound 8e-15).
        let roots = [1.0, 1.0 + 1e-6, 2.0];
        let r = cubic(expand(1.0, roots));
        assert_eq!(r.len(), 3, "{r:?}");
        for (i, (got, want)) in r.iter().zip(roots).enumerate() {
            assert_close(got, want, simple_root_bound(1.0, roots, i));
        }
        assert_close(r.as_slice()[2], 2.0, 1e-14);

        // 1 and 1 + 1e-7 sit at the resolution limit sqrt(8 EPSILON S / |p''|) ~ 1e-7: the dip
        // of p between them (2.5e-15) is below the rounding bound of p (4 EPSILON S(1) ~ 1e-14),
        // so the pair may come back as one double root at the midpoint (error 5e-8, half the
        // gap) or as two roots each within the conditioning limit ~2.7e-8 of the truth.
        let roots = [1.0, 1.0 + 1e-7, 2.0];
        let r = cubic(expand(1.0, roots));
        assert_eq!(r.total_multiplicity(), 3, "{r:?}");
        assert_close(r.as_slice()[r.len() - 1], 2.0, 1e-14);
        let limit = 4.0 * EPS * magnitude(expand(1.0, roots), 1.0) / 1e-7;
        if r.len() == 3 {
            assert_close(r.as_slice()[0], 1.0, limit);
            assert_close(r.as_slice()[1], 1.0 + 1e-7, limit);
        } else {
            assert_eq!(r.multiplicities(), &[2, 1]);
            assert_close(r.as_slice()[0], 1.0 + 5e-8, limit);
        }
    }

    #[test]
    fn cubic_perspective_case() {
        // Perspective trilinear projection: (t + 1)^2 (alpha t + beta).
        for (alpha, beta) in [
            (1.0, -2.0),
            (0.37, 1.9),
            (-3.1, 0.2),
            (2.0, 2.0),
            (1e-3, 5.0),
        ] {
            let k = [alpha, beta + 2.0 * alpha, alpha + 2.0 * beta, beta];
            let r = cubic(k);
            let simple = -beta / alpha;
            assert!(r
                .iter()
                .any(|x| (x - simple).abs() <= 1e-13 * simple.abs().max(1.0)));
            if simple == -1.0 {
                assert_eq!(r.multiplicities(), &[3]);
                continue;
            }
            let near: Vec<usize> = (0..r.len())
                .filter(|&i| (r.as_slice()[i] + 1.0).abs() < 1e-6)
                .collect();
            let mult: usize = near.iter().map(|&i| r.multiplicities()[i] as usize).sum();
            assert_eq!(mult, 2, "alpha {alpha} beta {beta}: {r:?}");
            for &i in &near {
                assert_close(r.as_slice()[i], -1.0, 1e-7);
            }
        }
    }

    #[test]
    fn cubic_random_known_roots() {
        // Deterministic sample of the wide range, checked against the conditioning bound.
        let mut seed = 0x9e3779b97f4a7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let mut root = || {
                let sign = if next() < 0.5 { -1.0 } else { 1.0 };
                sign * 10f64.powf(next() * 12.0 - 6.0)
            };
            let roots = [root(), root(), root()];
            let s = 10f64.powf(next() * 20.0 - 10.0);
            let r = cubic(expand(s, roots));
            for i in 0..3 {
                let bound = simple_root_bound(s, roots, i);
                if bound > 1e-3 * roots[i].abs() {
                    continue; // clustered: not a well-conditioned simple root
                }
                assert!(
                    r.iter().any(|x| (x - roots[i]).abs() <= bound),
                    "root {:e} of {roots:?} (scale {s:e}) missing: {r:?}, bound {bound:e}",
                    roots[i]
                );
            }
        }
    }

    // ---- Properties --------------------------------------------------------------------------

    fn signed_log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
        (lo..hi, any::<bool>()).prop_map(|(e, neg)| {
            let x = 10f64.powf(e);
            if neg {
                -x
            } else {
                x
            }
        })
    }

    /// Roots with clusters: each later root is independent, equal to, or within a relative
    /// `10^-k` of the previous one.
    fn root_triples() -> impl Strategy<Value = [f64; 3]> {
        let link = prop_oneof![
            3 => Just(None),
            1 => Just(Some(0.0)),
            2 => (-14.0f64..-1.0).prop_map(|k| Some(10f64.powf(k))),
        ];
        (
            signed_log_uniform(-6.0, 6.0),
            signed_log_uniform(-6.0, 6.0),
            signed_log_uniform(-6.0, 6.0),
            link.clone(),
            link,
        )
            .prop_map(|(r0, r1, r2, l1, l2)| {
                let r1 = l1.map_or(r1, |d| r0 * (1.0 + d));
                let r2 = l2.map_or(r2, |d| r1 * (1.0 - d));
                [r0, r1, r2]
            })
    }

    fn check_invariants(k: [f64; 4], r: &Roots) -> Result<(), TestCaseError> {
        prop_assert!(!r.is_identically_zero());
        prop_assert_eq!(
            (r.total_multiplicity() + r.lost_to_infinity()) % 2,
            1,
            "parity: {:?}",
            r
        );
        prop_assert!(r.total_multiplicity() + r.lost_to_infinity() <= 3);
        prop_assert!(
            r.as_slice().windows(2).all(|w| w[0] < w[1]),
            "sorted: {:?}",
            r
        );
        for &x in r.as_slice() {
            prop_assert!(x.is_finite());
            let residual = eval(k, x).abs();
            let tol = 16.0 * EPS * magnitude(k, x);
            prop_assert!(residual <= tol, "|p({:e})| = {:e} > {:e}", x, residual, tol);
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn prop_known_roots(roots in root_triples(), s in signed_log_uniform(-30.0, 30.0)) {
            let k = expand(s, roots);
            let r = cubic(k);
            check_invariants(k, &r)?;
            // Root ratios stay below 1e12 < 1/EPSILON: nothing may be lost.
            prop_assert_eq!(r.lost_to_infinity(), 0);
            for i in 0..3 {
                let bound = simple_root_bound(s, roots, i);
                // Simple and well separated: the conditioning limit is a small fraction of
                // the root's distance to the others.
                let gap = (roots[i] - roots[(i + 1) % 3]).abs()
                    .min((roots[i] - roots[(i + 2) % 3]).abs());
                if bound < 1e-3 * gap {
                    prop_assert!(
                        r.iter().any(|x| (x - roots[i]).abs() <= bound),
                        "root {:e} missing: {:?}, bound {:e}", roots[i], r, bound
                    );
                }
            }
        }

        #[test]
        fn prop_random_coefficients(
            m in prop::array::uniform4(-1.0f64..1.0),
            e in prop::array::uniform4(-12.0f64..12.0),
            zero in prop::array::uniform4(0u8..6),
        ) {
            let mut k = [0.0; 4];
            for i in 0..4 {
                k[i] = if zero[i] == 0 { 0.0 } else { m[i] * 10f64.powf(e[i]) };
            }
            prop_assume!(k.iter().any(|&x| x != 0.0));
            let r = cubic(k);
            check_invariants(k, &r)?;
        }

        #[test]
        fn prop_quadratic(
            m in prop::array::uniform3(-1.0f64..1.0),
            e in prop::array::uniform3(-12.0f64..12.0),
        ) {
            let k = [m[0] * 10f64.powf(e[0]), m[1] * 10f64.powf(e[1]), m[2] * 10f64.powf(e[2])];
            let r = solve_quadratic(k[0], k[1], k[2]);
            let k3 = [0.0, k[0], k[1], k[2]];
            prop_assert_eq!((r.total_multiplicity() + r.lost_to_infinity()) % 2, 0);
            prop_assert!(r.as_slice().windows(2).all(|w| w[0] < w[1]));
            for &x in r.as_slice() {
                let tol = 8.0 * EPS * magnitude(k3, x);
                prop_assert!(eval(k3, x).abs() <= tol);
            }
            // The real-root count agrees with the sign of an accurate discriminant whenever
            // that sign is unambiguous.
            let disc = discriminant(k[0], k[1], k[2]);
            let scale = k[1] * k[1] + (4.0 * k[0] * k[2]).abs();
            if r.lost_to_infinity() == 0 && disc.abs() > 1e-12 * scale {
                prop_assert_eq!(r.total_multiplicity(), if disc > 0.0 { 2 } else { 0 });
            }
        }

        #[test]
        fn prop_perspective(alpha in signed_log_uniform(-3.0, 3.0), beta in signed_log_uniform(-3.0, 3.0)) {
            let k = [alpha, beta + 2.0 * alpha, alpha + 2.0 * beta, beta];
            let simple = -beta / alpha;
            prop_assume!((simple + 1.0).abs() > 1e-3);
            let r = cubic(k);
            check_invariants(k, &r)?;
            let near: usize = (0..r.len())
                .filter(|&i| (r.as_slice()[i] + 1.0).abs() < 1e-6)
                .map(|i| r.multiplicities()[i] as usize)
                .sum();
            prop_assert_eq!(near, 2, "{:?}", r);
            // Conditioning of the simple root: p'(simple) = alpha (simple + 1)^2.
            let bound = 32.0 * EPS * magnitude(k, simple) / (alpha * (simple + 1.0).powi(2)).abs();
            prop_assert!(
                r.iter().any(|x| (x - simple).abs() <= bound.max(4.0 * EPS * simple.abs())),
                "simple root {:e} missing: {:?}, bound {:e}", simple, r, bound
            );
        }
    }
}
