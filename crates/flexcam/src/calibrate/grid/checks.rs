use glam::{DVec2, DVec3};
use nalgebra::{DMatrix, DVector};

use super::{
    constrained_nodes, projector_off, residual, targets, Correspondence, FitReport, System,
};
use crate::error::Result;
use crate::projection::flexible::ProjectorGrid;

/// A fitted node is wild when its length ratio to the prior's node is more than this many
/// times the median ratio of the constrained nodes, or less than its inverse.
pub(super) const WILD_LENGTH: f64 = 4.0;

/// Node lengths are judged when giving them the median ratio moves the projectors at the
/// points by more than this many times the fit's noise (root mean squares, see
/// [`lengths_move_lines`]): moves of a few noise deviations change the image by about the
/// noise's size (measured: a noisy pushbroom fit's length pattern, 2.4 times), a wild node
/// moves them by far more (its cell's angular spread).
pub(super) const LENGTH_MOVE: f64 = 4.0;

/// A fitted node is wild when its direction is more than this many degrees off the prior's.
pub(super) const WILD_ANGLE_DEG: f64 = 60.0;

/// A constrained node of a curved grid has little data when the grid weights on it, summed
/// over the correspondences, are below this: less than one correspondence's two equations
/// for the node's three unknowns.
pub(super) const SPARSE_WEIGHT: f64 = 1.0;

/// The node weights summed over the correspondences.
pub(super) fn node_weights(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> Vec<f64> {
    let mut weight = vec![0.0; prior.starts().len()];
    for c in correspondences {
        prior.for_each_weight(c.uv, |j, w| weight[j] += w);
    }
    weight
}

/// The number of wild constrained nodes of `fitted` against `prior` (module section
/// "Warnings").
pub(super) fn wild_nodes(
    prior: &ProjectorGrid,
    fitted: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> usize {
    let weight = node_weights(prior, correspondences);
    let direction = |g: &ProjectorGrid, j: usize| g.ends()[j] - g.starts()[j];
    let constrained: Vec<usize> = (0..weight.len()).filter(|j| weight[*j] > 0.0).collect();
    let ratios: Vec<f64> = constrained
        .iter()
        .map(|&j| direction(fitted, j).length() / direction(prior, j).length())
        .collect();
    let mut sorted = ratios.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
    let lengths_judged = lengths_move_lines(prior, fitted, correspondences, &constrained, median);
    constrained
        .iter()
        .zip(&ratios)
        .filter(|(&j, &ratio)| {
            let (a, b) = (direction(fitted, j), direction(prior, j));
            let angle = a.cross(b).length().atan2(a.dot(b)).to_degrees();
            let relative = ratio / median;
            angle > WILD_ANGLE_DEG
                || (lengths_judged && !(1.0 / WILD_LENGTH..=WILD_LENGTH).contains(&relative))
        })
        .count()
}

/// Whether the fitted node lengths shape the projectors the data see: whether giving every
/// constrained node of `fitted` the length ratio `median` to its `prior` node (starts and
/// unit directions kept) moves the projectors at the correspondences by more than the
/// noise. A length pattern that moves no line is a freedom the model leaves, not a claim of
/// the fit: a pushbroom's nodes along a row share one direction, so lengths affine in u
/// change no blended line, and noisy data pick any of them (measured: noisy pushbroom fits
/// with node lengths 2.3 to 205, 97.8 to 99.98 % ids, warned of 3 wild nodes; the noise also
/// turns the row's directions apart by about its own size, so that the lengths move the
/// lines a little). The move is each projector's at its point (its nearest point to the
/// point, over the point's distance from the prior's start), squared and averaged over the
/// correspondences; the lengths shape the lines when its root exceeds `LENGTH_MOVE` times
/// the noise, the root of the median squared miss ([`miss_seen_from`]) of the better of the
/// two length patterns (the median and the better pattern, so that a wild node's own misses
/// do not raise the bar that judges it), at least `EXACT_RMS_RAD`. Degenerate cases: no
/// correspondences or a length that cannot be set (a zero direction): judged.
pub(super) fn lengths_move_lines(
    prior: &ProjectorGrid,
    fitted: &ProjectorGrid,
    correspondences: &[Correspondence],
    constrained: &[usize],
    median: f64,
) -> bool {
    let mut ends = fitted.ends().to_vec();
    for &j in constrained {
        let (s, prior_length) = (
            fitted.starts()[j],
            (prior.ends()[j] - prior.starts()[j]).length(),
        );
        let Some(unit) = (ends[j] - s).try_normalize() else {
            return true;
        };
        ends[j] = s + unit * (median * prior_length);
    }
    let Ok(even) = fitted.with_ends(ends) else {
        return true;
    };
    if correspondences.is_empty() {
        return true;
    }
    let typical = median_squared_miss(prior, fitted, correspondences)
        .min(median_squared_miss(prior, &even, correspondences))
        .max(EXACT_RMS_RAD.powi(2));
    let moved = correspondences
        .iter()
        .map(|c| ((foot(&even, c) - foot(fitted, c)).length() / reach(prior, c)).powi(2))
        .sum::<f64>()
        / correspondences.len() as f64;
    moved > LENGTH_MOVE.powi(2) * typical
}

/// The median over `correspondences` (not empty) of [`miss_seen_from`] squared.
pub(super) fn median_squared_miss(
    prior: &ProjectorGrid,
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> f64 {
    let mut misses: Vec<f64> = correspondences
        .iter()
        .map(|c| miss_seen_from(prior, grid, c).powi(2))
        .collect();
    misses.sort_by(f64::total_cmp);
    misses[misses.len() / 2]
}

/// The constrained nodes of a curved grid whose summed weight is below `SPARSE_WEIGHT`.
pub(super) fn thinly_weighted_nodes(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> usize {
    node_weights(prior, correspondences)
        .iter()
        .filter(|w| **w > 0.0 && **w < SPARSE_WEIGHT)
        .count()
}

/// A node is undetermined when the variance of some projector at or around it under the
/// model, relative to the inverse mean diagonal of the model's matrix, exceeds this: the data
/// (and the model's own terms) leave it free, and only the prior's weak pull settles it.
pub(super) const UNDETERMINED_VARIANCE: f64 = 1e6;

/// The constrained nodes (`constrained`) of the fitted `grid` whose projectors the model
/// leaves undetermined (module docs of `grid`, "Warnings"). `matrix` is the model's Gauss-Newton
/// matrix without the pull to the prior, in `per_node` unknowns a node: 3 (the direction over
/// `scale`) or 6 (the start over a length near the points' distance, then the direction over
/// `scale`); `grid` has the directions the unknowns describe; `gauge` is the
/// scale constraint's row. The covariance is the inverse of matrix + g g^T (scaled to the
/// mean diagonal) + 1e-10 of the mean diagonal; what is judged is the projectors' lines, not
/// the unknowns: at the node's (u, v) and at the centres of its cells, the blended start's
/// and direction's moves across the projector (about radians: the start in its units, the
/// direction over its own length). A move that changes no line (a start sliding along its
/// projector, a direction's length; a pushbroom's starts and lengths may change by any
/// amount affine in u that way, its directions being the same along a row) is no doubt.
pub(super) fn undetermined_nodes(
    grid: &ProjectorGrid,
    matrix: &DMatrix<f64>,
    per_node: usize,
    gauge: &DVector<f64>,
    constrained: &[bool],
    scale: f64,
) -> usize {
    let n = matrix.nrows();
    let mean = matrix.trace() / n as f64;
    let all = constrained.iter().filter(|c| **c).count();
    if mean <= 0.0 || !mean.is_finite() {
        return all;
    }
    let mut fixed = matrix.clone();
    let g2 = gauge.norm_squared();
    if g2 > 0.0 {
        fixed += (mean / g2) * gauge * gauge.transpose();
    }
    for i in 0..n {
        fixed[(i, i)] += 1e-10 * mean;
    }
    let Some(covariance) = fixed.cholesky().map(|f| f.inverse()) else {
        return all;
    };
    let dirs = prior_directions(grid);
    let (cols, rows) = grid.size();
    let doubtful = |uv: DVec2| {
        let mut weights = Vec::new();
        grid.for_each_weight(uv, |j, w| weights.push((j, w)));
        let d: DVec3 = weights.iter().map(|&(j, w)| w * dirs[j]).sum();
        let Some(unit) = d.try_normalize() else {
            return true;
        };
        let off = projector_off(unit);
        // Rows: the start's move across the projector (if fitted), then the direction's.
        let parts = per_node / 3;
        let mut jacobian = DMatrix::<f64>::zeros(3 * parts, n);
        for &(j, w) in &weights {
            for part in 0..parts {
                let factor = if part + 1 == parts {
                    w * scale / d.length()
                } else {
                    w
                };
                for r in 0..3 {
                    for c in 0..3 {
                        jacobian[(3 * part + r, per_node * j + 3 * part + c)] += factor * off[r][c];
                    }
                }
            }
        }
        let variance = &jacobian * &covariance * jacobian.transpose();
        (0..variance.nrows()).any(|i| variance[(i, i)] * mean > UNDETERMINED_VARIANCE)
    };
    (0..constrained.len())
        .filter(|&j| {
            let (col, row) = (j % cols, j / cols);
            let here = grid.node_uv(col, row);
            let mut samples = vec![here];
            for (dc, dr) in [(-1, -1), (-1, 1), (1, -1), (1, 1)] {
                let (c, r) = (col as isize + dc, row as isize + dr);
                if (0..cols as isize).contains(&c) && (0..rows as isize).contains(&r) {
                    samples.push(0.5 * (here + grid.node_uv(c as usize, r as usize)));
                }
            }
            constrained[j] && samples.into_iter().any(&doubtful)
        })
        .count()
}

/// The constrained nodes of the straight `grid` whose directions (its starts kept) the data
/// leave undetermined ([`undetermined_nodes`] of the linear fit's normal matrix).
pub(super) fn straight_undetermined(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<usize> {
    let targets = targets(grid, correspondences)?;
    let system = System::new(grid, correspondences, &targets);
    let constrained = constrained_nodes(grid, correspondences);
    Ok(undetermined_nodes(
        grid,
        &system.normal,
        3,
        &system.scale_row,
        &constrained,
        system.scale,
    ))
}

/// The node directions E_j - S_j of `grid`.
pub(super) fn prior_directions(grid: &ProjectorGrid) -> Vec<DVec3> {
    grid.starts()
        .iter()
        .zip(grid.ends())
        .map(|(s, e)| *e - *s)
        .collect()
}

/// The residual of `grid` (straight) at `correspondences`, seen from its own starts.
pub(super) fn report_of(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<FitReport> {
    let targets = targets(grid, correspondences)?;
    let constrained = constrained_nodes(grid, correspondences);
    Ok(residual(grid, correspondences, &targets, &constrained))
}

/// Largest rms angle, in radians, of a fit that `Starts::Auto` takes as meeting the data
/// exactly (the rms miss `EXACT_CHORD` allows).
pub(super) const EXACT_RMS_RAD: f64 = 1e-6;

/// The distance from `c`'s point to `grid`'s straight projector at its (u, v), over the
/// point's distance from `prior`'s start there (one term of [`misses_seen_from`]).
pub(super) fn miss_seen_from(
    prior: &ProjectorGrid,
    grid: &ProjectorGrid,
    c: &Correspondence,
) -> f64 {
    (c.point - foot(grid, c)).length() / reach(prior, c)
}

/// The point's distance from `prior`'s start at its (u, v), the unit of
/// [`miss_seen_from`].
pub(super) fn reach(prior: &ProjectorGrid, c: &Correspondence) -> f64 {
    // A point at the prior's start is an error of every fit (`targets`).
    (c.point - prior.start_end(c.uv).0)
        .length()
        .max(f64::MIN_POSITIVE)
}

/// The point of `grid`'s straight projector line at `c`'s (u, v) nearest `c`'s point (the
/// start where the projector has no direction).
pub(super) fn foot(grid: &ProjectorGrid, c: &Correspondence) -> DVec3 {
    let (s, e) = grid.start_end(c.uv);
    match (e - s).try_normalize() {
        Some(d) => s + d * (c.point - s).dot(d),
        None => s,
    }
}
