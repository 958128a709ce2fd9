//! NURBS control surfaces (non-uniform rational B-splines; Brosz 2011, 5.1 and 6.1.1, after
//! Glassner's Digital Cubism, whose projectors run straight from one NURBS surface to
//! another).
//!
//! A patch of degree (p, q) over a grid of `rows x columns` control points P_ij with weights
//! w_ij > 0 and knot vectors U (columns + p + 1 knots, along u) and V (rows + q + 1, along v):
//!
//!   S(s, r) = sum_ij N_j,p(s) N_i,q(r) w_ij P_ij / sum_ij N_j,p(s) N_i,q(r) w_ij
//!
//! with the Cox-de Boor basis N. The shared domain u in [0, 1] maps linearly onto the valid
//! parameter range [U_p, U_columns] (v likewise), so a patch covers the whole image whatever
//! its knots. Unit weights give the polynomial B-spline; clamped knots (p + 1 equal knots at
//! each end) make the patch pass through its corner control points, and a clamped patch with
//! as many control points as one more than its degree is a Bezier patch. Rational weights
//! give conics exactly: a circular arc, a cylinder, a sphere.
//!
//! Degenerate cases, all refused when the patch is made: degree 0 or above [`MAX_DEGREE`],
//! fewer control points than degree + 1 along a side, more than [`MAX_CONTROL`] along a side,
//! rows of different lengths, a knot count other than control points + degree + 1, knots that
//! decrease or are not finite, an empty valid range (U_p = U_columns), an inner knot repeated
//! more than the degree (the surface would break apart there), weights that are not positive
//! and finite or do not match the control grid's shape.

use glam::{DVec2, DVec3, DVec4};

use crate::error::{Error, Result};

/// The highest degree along either parameter.
pub const MAX_DEGREE: usize = 7;

/// The most control points along either side of the grid.
pub const MAX_CONTROL: usize = 64;

/// The knot vector of one parameter with its degree.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    knots: Vec<f64>,
    degree: usize,
    /// The number of control points (basis functions) along this parameter.
    count: usize,
}

impl KnotVector {
    /// Checks `knots` for `count` control points of `degree` (see the module doc); `which`
    /// names the parameter in messages ("u" or "v").
    pub fn new(knots: Vec<f64>, count: usize, degree: usize, which: &str) -> Result<Self> {
        let want = count + degree + 1;
        if knots.len() != want {
            return Err(Error::new(format!(
                "nurbs surface needs {want} {which} knots ({count} control points + degree \
                 {degree} + 1), got {}",
                knots.len()
            )));
        }
        if let Some(bad) = knots.iter().find(|k| !k.is_finite()) {
            return Err(Error::new(format!(
                "nurbs surface {which} knots must be finite, not {bad}"
            )));
        }
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(Error::new(format!(
                "nurbs surface {which} knots must not decrease: knot {} ({}) is below knot {} \
                 ({})",
                i + 2,
                knots[i + 1],
                i + 1,
                knots[i]
            )));
        }
        let (lo, hi) = (knots[degree], knots[count]);
        if hi <= lo {
            return Err(Error::new(format!(
                "nurbs surface {which} knots leave an empty parameter range: knots {} and {} \
                 (degree + 1 from each end) are both {lo}",
                degree + 1,
                count + 1
            )));
        }
        // Inner knots (strictly inside the valid range) of multiplicity above the degree.
        let mut i = degree + 1;
        while i < count {
            let run = knots[i..count]
                .iter()
                .take_while(|&&k| k == knots[i])
                .count();
            if run > degree {
                return Err(Error::new(format!(
                    "nurbs surface {which} knot {} is repeated {run} times inside the range: at \
                     most the degree ({degree}), or the surface breaks apart there",
                    knots[i]
                )));
            }
            i += run;
        }
        Ok(KnotVector {
            knots,
            degree,
            count,
        })
    }

    /// Clamped uniform knots for `count` control points of `degree`: degree + 1 zeros,
    /// equally spaced inner knots, degree + 1 ones (the curve passes through its end control
    /// points; with count = degree + 1 it is a Bezier curve).
    pub fn clamped(count: usize, degree: usize) -> Vec<f64> {
        let inner = count - degree;
        (0..count + degree + 1)
            .map(|i| (i.saturating_sub(degree).min(inner)) as f64 / inner as f64)
            .collect()
    }

    /// The knot span index k (degree <= k < count) with knots[k] <= t < knots[k + 1], the
    /// last span for t at (or beyond) the range's end, the first before its start.
    fn span(&self, t: f64) -> usize {
        let (p, n) = (self.degree, self.count);
        if t >= self.knots[n] {
            // The last non-empty span.
            return (p..n)
                .rev()
                .find(|&k| self.knots[k] < self.knots[k + 1])
                .unwrap_or(p);
        }
        if t <= self.knots[p] {
            return (p..n)
                .find(|&k| self.knots[k] < self.knots[k + 1])
                .unwrap_or(p);
        }
        // knots[p] < t < knots[n]: the last k with knots[k] <= t.
        let upper = self.knots[p..=n].partition_point(|&k| k <= t);
        p + upper - 1
    }

    /// The degree + 1 basis functions N_{span - degree .. span} at t (The NURBS Book, A2.2).
    fn basis(&self, span: usize, t: f64) -> [f64; MAX_DEGREE + 1] {
        let p = self.degree;
        let mut n = [0.0; MAX_DEGREE + 1];
        let mut left = [0.0; MAX_DEGREE + 1];
        let mut right = [0.0; MAX_DEGREE + 1];
        n[0] = 1.0;
        for j in 1..=p {
            left[j] = t - self.knots[span + 1 - j];
            right[j] = self.knots[span + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = n[r] / (right[r + 1] + left[j - r]);
                n[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            n[j] = saved;
        }
        n
    }

    /// The knot parameter of domain coordinate `x` in [0, 1] (linear onto the valid range).
    fn parameter(&self, x: f64) -> f64 {
        let (lo, hi) = (self.knots[self.degree], self.knots[self.count]);
        lo + x * (hi - lo)
    }
}

/// A NURBS patch over the shared (u, v) domain.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsPatch {
    columns: usize,
    u: KnotVector,
    v: KnotVector,
    /// (w P, w) per control point, row-major (rows along v).
    homogeneous: Vec<DVec4>,
}

/// What a NURBS patch is made of, as a scene file gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSpec {
    /// `control[row][column]`: rows along v (row 0 at v = 0), columns along u.
    pub control: Vec<Vec<DVec3>>,
    /// One weight per control point, the same shape; `None`: all 1.
    pub weights: Option<Vec<Vec<f64>>>,
    /// Degree along u and along v.
    pub degree: [usize; 2],
    /// Knots along u; `None`: clamped uniform.
    pub u_knots: Option<Vec<f64>>,
    /// Knots along v; `None`: clamped uniform.
    pub v_knots: Option<Vec<f64>>,
}

impl NurbsPatch {
    /// Makes the patch. Errors: the degenerate cases of the module doc.
    pub fn new(spec: NurbsSpec) -> Result<NurbsPatch> {
        let rows = spec.control.len();
        let columns = spec.control.first().map_or(0, Vec::len);
        for (which, degree) in ["u", "v"].into_iter().zip(spec.degree) {
            if !(1..=MAX_DEGREE).contains(&degree) {
                return Err(Error::new(format!(
                    "nurbs surface degree along {which} must be in 1..={MAX_DEGREE}, got {degree}"
                )));
            }
        }
        let [p, q] = spec.degree;
        if columns <= p || rows <= q || columns > MAX_CONTROL || rows > MAX_CONTROL {
            return Err(Error::new(format!(
                "nurbs surface of degree [{p}, {q}] needs {} to {MAX_CONTROL} control points \
                 along u and {} to {MAX_CONTROL} along v, got {rows} rows of {columns}",
                p + 1,
                q + 1
            )));
        }
        if let Some(bad) = spec.control.iter().position(|row| row.len() != columns) {
            return Err(Error::new(format!(
                "nurbs surface rows must have equal lengths: row {} has {} points, row 1 has \
                 {columns}",
                bad + 1,
                spec.control[bad].len()
            )));
        }
        let weights = match spec.weights {
            None => vec![vec![1.0; columns]; rows],
            Some(w) => {
                let shape_ok = w.len() == rows && w.iter().all(|row| row.len() == columns);
                if !shape_ok {
                    return Err(Error::new(format!(
                        "nurbs surface weights must have the control grid's shape ({rows} rows \
                         of {columns}), got {} rows of {}",
                        w.len(),
                        w.iter().map(Vec::len).max().unwrap_or(0)
                    )));
                }
                if let Some(bad) = w.iter().flatten().find(|x| !(x.is_finite() && **x > 0.0)) {
                    return Err(Error::new(format!(
                        "nurbs surface weights must be positive and finite, got {bad}"
                    )));
                }
                w
            }
        };
        let u = KnotVector::new(
            spec.u_knots
                .unwrap_or_else(|| KnotVector::clamped(columns, p)),
            columns,
            p,
            "u",
        )?;
        let v = KnotVector::new(
            spec.v_knots.unwrap_or_else(|| KnotVector::clamped(rows, q)),
            rows,
            q,
            "v",
        )?;
        let homogeneous = spec
            .control
            .iter()
            .flatten()
            .zip(weights.iter().flatten())
            .map(|(point, &w)| (*point * w).extend(w))
            .collect();
        Ok(NurbsPatch {
            columns,
            u,
            v,
            homogeneous,
        })
    }

    /// Whether every control point is finite.
    pub fn is_finite(&self) -> bool {
        self.homogeneous.iter().all(|h| h.is_finite())
    }

    /// The patch point at (u, v) in [0, 1]^2 (outside it the end spans extrapolate).
    pub fn point(&self, uv: DVec2) -> DVec3 {
        let (s, r) = (self.u.parameter(uv.x), self.v.parameter(uv.y));
        let (su, sv) = (self.u.span(s), self.v.span(r));
        let (nu, nv) = (self.u.basis(su, s), self.v.basis(sv, r));
        let (p, q) = (self.u.degree, self.v.degree);
        let mut sum = DVec4::ZERO;
        for (i, wv) in nv.iter().take(q + 1).enumerate() {
            let row = (sv - q + i) * self.columns;
            for (j, wu) in nu.iter().take(p + 1).enumerate() {
                sum += (wv * wu) * self.homogeneous[row + su - p + j];
            }
        }
        sum.truncate() / sum.w
    }
}

#[cfg(test)]
mod tests;
