//! One pinhole camera fitted to point correspondences by its 3 x 4 camera matrix P, with
//! (u, v, 1) ~ P (X, 1): the direct linear transform on normalised coordinates, then
//! Levenberg-Marquardt on the reprojection error in the image (the "gold standard" of
//! Hartley and Zisserman 2004, 7.2). The error is measured in the image because there click
//! noise is the same for every point; measured as angles at the eye, as the other central
//! fits measure it, the error of a wrong eye shrinks as the eye moves away, and noisy data
//! drive the eye off to infinity.
//!
//! Degenerate data (the points all on one plane, or the image positions on one line) leave
//! the matrix undetermined: [`CameraMatrix::fit`] answers `None`, and the caller names the
//! cause. The central fit's pinhole field is this camera's; `starts = "pinhole"` is the
//! square-pixel camera of module `pinhole_camera`, which this one starts where it exists.

use glam::{DMat3, DVec2, DVec3};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::{dense_lm, Correspondence};

/// The data are taken as degenerate when the direct linear transform's second least
/// eigenvalue is below this fraction of its largest (a second camera matrix meets them).
const DEGENERATE: f64 = 1e-12;

/// Levenberg-Marquardt iterations at most.
const MAX_ITERATIONS: usize = 60;

/// A fitted pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CameraMatrix {
    /// P, row by row, in the correspondences' own coordinates.
    rows: [[f64; 4]; 3],
    /// +1 or -1: the sign of P's third row at the points (their depth's sign).
    facing: f64,
}

/// A similarity taking points to their centroid at the origin and a mean distance of
/// sqrt(dimension) (Hartley's normalisation).
pub(super) fn normalisation<const N: usize>(points: &[[f64; N]]) -> ([f64; N], f64) {
    let n = points.len() as f64;
    let mut centre = [0.0; N];
    for p in points {
        for i in 0..N {
            centre[i] += p[i] / n;
        }
    }
    let mean = points
        .iter()
        .map(|p| {
            (0..N)
                .map(|i| (p[i] - centre[i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum::<f64>()
        / n;
    (centre, (N as f64).sqrt() / mean)
}

impl CameraMatrix {
    /// The camera of least reprojection error over `correspondences` (at least six), or
    /// `None` where the data do not determine one (module docs) or the descent leaves the
    /// numbers finite nowhere.
    pub(super) fn fit(correspondences: &[Correspondence]) -> Option<CameraMatrix> {
        if correspondences.len() < 6 {
            return None;
        }
        let image: Vec<[f64; 2]> = correspondences.iter().map(|c| c.uv.to_array()).collect();
        let world: Vec<[f64; 3]> = correspondences.iter().map(|c| c.point.to_array()).collect();
        let ((ic, is), (wc, ws)) = (normalisation(&image), normalisation(&world));
        if !(is.is_finite() && ws.is_finite()) {
            return None;
        }
        let uv: Vec<[f64; 2]> = image
            .iter()
            .map(|p| [(p[0] - ic[0]) * is, (p[1] - ic[1]) * is])
            .collect();
        let x: Vec<[f64; 4]> = world
            .iter()
            .map(|p| {
                [
                    (p[0] - wc[0]) * ws,
                    (p[1] - wc[1]) * ws,
                    (p[2] - wc[2]) * ws,
                    1.0,
                ]
            })
            .collect();
        let start = direct_linear_transform(&uv, &x)?;
        let p = refine(start, &uv, &x);
        // P = T^-1 P_n U: T takes (u, v, 1) to the normalised image, U (X, 1) to the
        // normalised points.
        let mut rows = [[0.0; 4]; 3];
        for (r, row) in rows.iter_mut().enumerate() {
            for c in 0..3 {
                row[c] = p[4 * r + c] * ws;
            }
            row[3] = p[4 * r + 3] - (0..3).map(|c| p[4 * r + c] * ws * wc[c]).sum::<f64>();
        }
        let [r0, r1, r2] = &mut rows;
        for ((a, b), &w) in r0.iter_mut().zip(r1.iter_mut()).zip(r2.iter()) {
            *a = *a / is + ic[0] * w;
            *b = *b / is + ic[1] * w;
        }
        let depth_sum: f64 = world
            .iter()
            .map(|p| rows[2][0] * p[0] + rows[2][1] * p[1] + rows[2][2] * p[2] + rows[2][3])
            .sum();
        let camera = CameraMatrix {
            rows,
            facing: if depth_sum < 0.0 { -1.0 } else { 1.0 },
        };
        rows.iter()
            .flatten()
            .all(|v| v.is_finite())
            .then_some(camera)
    }

    /// The left 3 x 3 block M of P.
    fn m(&self) -> DMat3 {
        let r = &self.rows;
        DMat3::from_cols(
            DVec3::new(r[0][0], r[1][0], r[2][0]),
            DVec3::new(r[0][1], r[1][1], r[2][1]),
            DVec3::new(r[0][2], r[1][2], r[2][2]),
        )
    }

    /// The eye: -M^-1 p4, `None` where M is singular (a camera at infinity).
    pub(super) fn eye(&self) -> Option<DVec3> {
        let m = self.m();
        let det = m.determinant();
        let p4 = DVec3::new(self.rows[0][3], self.rows[1][3], self.rows[2][3]);
        let eye = -(m.inverse() * p4);
        (det.abs() > 0.0 && eye.is_finite()).then_some(eye)
    }

    /// P, row by row, its sign such that the points lie at positive depth (the third row's
    /// value at them): P = lambda K R [I | -E] with lambda > 0 where the camera is a pinhole.
    pub(super) fn rows_facing(&self) -> [[f64; 4]; 3] {
        self.rows.map(|row| row.map(|v| v * self.facing))
    }

    /// The image position (u, v) of `point`, `None` where it is not in front of the camera
    /// (at zero or negative depth, the points' side being the front).
    pub(super) fn project(&self, point: DVec3) -> Option<DVec2> {
        let h = point.extend(1.0).to_array();
        let row = |i: usize| (0..4).map(|c| self.rows[i][c] * h[c]).sum::<f64>();
        let w = row(2);
        (w * self.facing > 0.0).then(|| DVec2::new(row(0) / w, row(1) / w))
    }

    /// The direction from the eye of the projector of image position `uv`, towards the
    /// points (unnormalised; affine in (u, v)).
    pub(super) fn direction(&self, uv: DVec2) -> DVec3 {
        self.facing * (self.m().inverse() * DVec3::new(uv.x, uv.y, 1.0))
    }
}

/// The direct linear transform: P (12 numbers, unit length) as the eigenvector of A^T A of
/// least eigenvalue; `None` where the second least is at rounding level too.
fn direct_linear_transform(uv: &[[f64; 2]], x: &[[f64; 4]]) -> Option<DVector<f64>> {
    let mut a = DMatrix::<f64>::zeros(2 * uv.len(), 12);
    for (k, (p, h)) in uv.iter().zip(x).enumerate() {
        for i in 0..4 {
            a[(2 * k, i)] = -h[i];
            a[(2 * k, 8 + i)] = p[0] * h[i];
            a[(2 * k + 1, 4 + i)] = -h[i];
            a[(2 * k + 1, 8 + i)] = p[1] * h[i];
        }
    }
    let eigen = SymmetricEigen::new(a.transpose() * &a);
    let mut order: Vec<usize> = (0..12).collect();
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let largest = eigen.eigenvalues[order[11]];
    // Also degenerate where an eigenvalue is NaN (no ordering).
    let second = eigen.eigenvalues[order[1]];
    if second.partial_cmp(&(DEGENERATE * largest)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some(eigen.eigenvectors.column(order[0]).into_owned())
}

/// The reprojection residuals (2 a point) of P `p` and the sum of their squares; `None`
/// where a point lies on the camera's focal plane.
fn residuals(p: &DVector<f64>, uv: &[[f64; 2]], x: &[[f64; 4]]) -> Option<(Vec<f64>, f64)> {
    let mut r = Vec::with_capacity(2 * uv.len());
    for (q, h) in uv.iter().zip(x) {
        let row = |i: usize| (0..4).map(|c| p[4 * i + c] * h[c]).sum::<f64>();
        let w = row(2);
        if w == 0.0 {
            return None;
        }
        r.push(row(0) / w - q[0]);
        r.push(row(1) / w - q[1]);
    }
    let cost: f64 = r.iter().map(|v| v * v).sum();
    cost.is_finite().then_some((r, cost))
}

/// Levenberg-Marquardt on the reprojection error from `start` (module `dense_lm`), P kept
/// at unit length (the scale is no unknown: the damping holds the step off it).
fn refine(start: DVector<f64>, uv: &[[f64; 2]], x: &[[f64; 4]]) -> DVector<f64> {
    let jacobian = |p: &DVector<f64>| {
        let mut j = DMatrix::<f64>::zeros(2 * x.len(), 12);
        for (k, h) in x.iter().enumerate() {
            let row = |i: usize| (0..4).map(|c| p[4 * i + c] * h[c]).sum::<f64>();
            let w = row(2);
            let (pu, pv) = (row(0) / w, row(1) / w);
            for c in 0..4 {
                j[(2 * k, c)] = h[c] / w;
                j[(2 * k, 8 + c)] = -pu * h[c] / w;
                j[(2 * k + 1, 4 + c)] = h[c] / w;
                j[(2 * k + 1, 8 + c)] = -pv * h[c] / w;
            }
        }
        j
    };
    let fitted = dense_lm::minimise(
        start.clone(),
        MAX_ITERATIONS,
        |p| residuals(p, uv, x).map(|(r, _)| r),
        jacobian,
        |p, step| Some((p - step).normalize()),
    );
    fitted.map_or(start, |(p, _)| p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points seen by a camera at `eye` looking down -z (focal length 1.5, principal point at
    /// the image centre), 4 to 9 in front of it.
    fn seen(eye: DVec3, count: usize, planar: bool) -> Vec<Correspondence> {
        (0..count)
            .map(|k| {
                let (a, b) = ((k * 7 % 11) as f64 / 10.0, (k * 5 % 13) as f64 / 12.0);
                let depth = if planar {
                    6.0
                } else {
                    4.0 + 5.0 * ((k * 3 % 7) as f64 / 6.0)
                };
                let local = DVec3::new((a - 0.5) * depth / 1.5, (b - 0.5) * depth / 1.5, -depth);
                Correspondence {
                    uv: DVec2::new(a, b),
                    point: eye + local,
                }
            })
            .collect()
    }

    #[test]
    fn a_pinhole_comes_back_and_planar_points_determine_none() {
        let eye = DVec3::new(1.0, 2.0, 3.0);
        let camera = CameraMatrix::fit(&seen(eye, 20, false)).unwrap();
        assert!((camera.eye().unwrap() - eye).length() < 1e-9);
        for c in seen(eye, 20, false) {
            let d = camera.direction(c.uv).normalize();
            assert!(d.dot((c.point - eye).normalize()) > 1.0 - 1e-12, "{c:?}");
        }
        assert!(CameraMatrix::fit(&seen(eye, 20, true)).is_none());
        assert!(CameraMatrix::fit(&seen(eye, 5, false)).is_none());
    }
}
