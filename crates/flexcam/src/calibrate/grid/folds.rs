//! Whether a fitted grid folds: projectors that cross among the scene's points image the
//! same surface twice (a folded copy of the floor in the sky), whatever the residual at the
//! correspondences says.
//!
//! A straight grid's projectors are F(u, v, s) = S(u, v) + s D(u, v) (S the start, D the
//! direction, s the parameter along it). Neighbouring projectors cross where the Jacobian
//! det [F_u, F_v, F_s] = det [S_u + s D_u, S_v + s D_v, D] is zero; a grid that does not fold
//! keeps one sign of it over the image and the depths of the scene. [`folded`] samples it
//! inside every cell (the bilinear interpolation is smooth there) at depths spanning the
//! correspondences' parameters, and calls the grid folded where the sign changes at more
//! than rounding level.

use glam::DVec2;

use super::Correspondence;
use crate::projection::flexible::ProjectorGrid;

/// Samples per cell and axis.
const PER_CELL: usize = 4;

/// Depths sampled between the nearest and the farthest correspondence.
const DEPTHS: usize = 5;

/// The finite-difference step in (u, v).
const STEP: f64 = 1e-6;

/// Whether `grid`'s straight projectors cross between the depths of `correspondences`
/// (module docs). A grid with no correspondence in front of its starts does not fold.
pub(super) fn folded(grid: &ProjectorGrid, correspondences: &[Correspondence]) -> bool {
    let parameters: Vec<f64> = correspondences
        .iter()
        .filter_map(|c| {
            let (s, e) = grid.start_end(c.uv);
            let d = e - s;
            let t = (c.point - s).dot(d) / d.length_squared();
            t.is_finite().then_some(t.max(0.0))
        })
        .collect();
    let Some(near) = parameters.iter().copied().reduce(f64::min) else {
        return false;
    };
    let far = parameters.iter().copied().fold(near, f64::max);
    let (cols, rows) = grid.size();
    let (across, up) = (PER_CELL * (cols - 1), PER_CELL * (rows - 1));
    let (mut positive, mut negative, mut largest) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..up {
        for i in 0..across {
            let uv = DVec2::new(
                (i as f64 + 0.5) / across as f64,
                (j as f64 + 0.5) / up as f64,
            );
            let at = |uv: DVec2| {
                let (s, e) = grid.start_end(uv);
                (s, e - s)
            };
            let (_, d) = at(uv);
            let derivative = |h: DVec2| {
                let ((s1, d1), (s0, d0)) = (at(uv + h), at(uv - h));
                ((s1 - s0) / (2.0 * STEP), (d1 - d0) / (2.0 * STEP))
            };
            let (s_u, d_u) = derivative(DVec2::new(STEP, 0.0));
            let (s_v, d_v) = derivative(DVec2::new(0.0, STEP));
            for k in 0..DEPTHS {
                let t = near + (far - near) * k as f64 / (DEPTHS - 1) as f64;
                let det = (s_u + t * d_u).cross(s_v + t * d_v).dot(d);
                largest = largest.max(det.abs());
                if det > 0.0 {
                    positive = positive.max(det);
                } else {
                    negative = negative.max(-det);
                }
            }
        }
    }
    // Rounding of the finite differences: relative to the largest magnitude.
    let level = 1e-6 * largest;
    positive > level && negative > level
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::projection::flexible::projector_grid::tests::perspective_volume as perspective;
    use crate::projection::flexible::projector_grid::GridInterpolation;

    /// A 60-degree camera's 3 x 3 grid and points at depths 0.1 to 0.6 of its projectors.
    fn camera() -> (ProjectorGrid, Vec<Correspondence>) {
        let grid = ProjectorGrid::sample(
            &perspective(60.0, [1.0, 40.0]),
            (3, 3),
            GridInterpolation::Bilinear,
        )
        .unwrap();
        let points = (0..20)
            .map(|k| {
                let uv = DVec2::new((k % 5) as f64 / 4.0, (k / 5) as f64 / 3.0);
                Correspondence {
                    uv,
                    point: grid.point(uv, 0.1 + 0.025 * k as f64),
                }
            })
            .collect();
        (grid, points)
    }

    #[test]
    fn a_camera_does_not_fold_and_crossed_projectors_do() {
        let (grid, points) = camera();
        assert!(!folded(&grid, &points));
        // The middle node's projector swung past its right neighbour's: the two cross.
        let mut ends = grid.ends().to_vec();
        ends[4] = ends[5] + (ends[5] - ends[4]);
        let crossed = ProjectorGrid::new(
            (3, 3),
            grid.starts().to_vec(),
            ends,
            GridInterpolation::Bilinear,
        )
        .unwrap();
        assert!(folded(&crossed, &points));
        // Moved sideways by the same amount everywhere: no fold.
        let shifted: Vec<DVec3> = grid.ends().iter().map(|e| *e + DVec3::X).collect();
        let shifted = ProjectorGrid::new(
            (3, 3),
            grid.starts().to_vec(),
            shifted,
            GridInterpolation::Bilinear,
        )
        .unwrap();
        assert!(!folded(&shifted, &points));
    }
}
