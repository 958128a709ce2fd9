//! The free fit's smoothness weight, chosen from the data by cross-validation.
//!
//! # Why
//!
//! The second-difference term (module `free`) must be strong where few points leave many
//! grids exact (16 points of a pushbroom come out bilinear only with mu = 1e-3 of the data
//! term's mean diagonal), and weak where many points determine a grid that is not bilinear
//! across its nodes (a 3 x 3 grid with starts off any eye: 99.2 to 99.4 % ids at 50 points
//! with 1e-3, 99.99 % with 1e-6; docs/flexible.md, "Free starts"). No one weight serves both,
//! so the data choose it.
//!
//! # Rule
//!
//! The full data are fitted with each weight of `LADDER`, largest first (the first from the
//! given starting grids, each next from the previous rung's fit). A rung is eligible when it
//! leaves no more constrained nodes undetermined than the largest weight does (a smaller
//! weight must not buy its fit with lines that nothing settles). Each eligible rung is then
//! scored by `FOLDS`-fold cross-validation: correspondence k is held out in fold k mod
//! `FOLDS`, the rung's problem is refitted to the rest (from the rung's full fit), and the
//! held-out point's squared chord (module `free`'s residual, about its squared angle) is
//! taken under that refit. Each rung's mean held-out square is floored at `EXACT_RMS_RAD`
//! squared (misses below it are rounding, not evidence). The chosen rung is the largest
//! weight whose mean is within one standard error of the smallest mean (the standard error
//! of the best rung's held-out squares): the one-standard-error rule of cross-validation,
//! which prefers the smoother grid unless the data show that a weaker one predicts unseen
//! points better, so noise is not fitted as bends.
//!
//! # Degenerate cases
//!
//! - Fewer than `FOLDS * MIN_HELD_OUT` correspondences: too few to hold any out and still
//!   rank the rungs; the largest weight (1e-3).
//! - A node that no correspondence weighs (all points in one cell, say): the smoothness
//!   carries the fit to it, which no held-out point can check; the largest weight.
//! - Exact data that every weight meets (a bilinear truth, where no rung bends the grid):
//!   every mean is at the floor, the rungs tie, and the largest weight is chosen, so such
//!   fits are those of the fixed weight, bit for bit.
//! - A fold whose refit has no usable start (no positive scale along the constraint): its
//!   held-out points count as reversed projectors (squared chord 4), which rules the rung
//!   out unless all rungs share it.

use nalgebra::DVector;

use super::super::{constrained_nodes, Correspondence, EXACT_RMS_RAD};
use super::{Problem, REVERSED};
use crate::error::{Error, Result};
use crate::projection::flexible::projector_grid::ProjectorGrid;

/// The smoothness weights tried, relative to the data term's mean diagonal, largest first.
pub(super) const LADDER: [f64; 4] = [1e-3, 1e-4, 1e-5, 1e-6];

/// Cross-validation folds.
const FOLDS: usize = 5;

/// Fewest correspondences each fold must hold out for the rungs to be ranked.
const MIN_HELD_OUT: usize = 4;

/// One rung of the ladder: its problem, the fit's unknowns and grid, and the constrained
/// nodes it leaves undetermined.
pub(super) struct Rung<'a> {
    pub(super) problem: Problem<'a>,
    pub(super) y: DVector<f64>,
    pub(super) grid: ProjectorGrid,
    pub(super) sparse_nodes: usize,
}

/// Whether the data allow cross-validation (module section "Degenerate cases").
fn cross_validates(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> bool {
    correspondences.len() >= FOLDS * MIN_HELD_OUT
        && constrained_nodes(prior, correspondences).iter().all(|c| *c)
}

/// The full data's fit with every weight of the ladder the data allow (only the largest
/// where they do not cross-validate), largest first: the first from `guesses` and the prior,
/// each next from the previous rung's grid.
pub(super) fn fit_ladder<'a>(
    prior: &'a ProjectorGrid,
    correspondences: &'a [Correspondence],
    guesses: &[&ProjectorGrid],
) -> Result<Vec<Rung<'a>>> {
    let weights = if cross_validates(prior, correspondences) {
        &LADDER[..]
    } else {
        &LADDER[..1]
    };
    let mut rungs: Vec<Rung<'a>> = Vec::new();
    for &weight in weights {
        let problem = Problem::new(prior, correspondences, weight);
        let starts: Vec<&ProjectorGrid> = match rungs.last() {
            Some(previous) => vec![&previous.grid],
            None => guesses.iter().copied().chain([prior]).collect(),
        };
        let Some(y) = problem.solve(&starts) else {
            if rungs.is_empty() {
                return Err(Error::new(
                    "projector grid fit: no starting grid for the free fit points at its data",
                ));
            }
            break;
        };
        let grid = problem.grid_of(&y)?;
        let sparse_nodes = problem.undetermined(&y, &grid);
        rungs.push(Rung {
            problem,
            y,
            grid,
            sparse_nodes,
        });
    }
    Ok(rungs)
}

/// The index of the chosen rung (module section "Rule"): 0 when there is only one.
pub(super) fn choose(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    rungs: &[Rung<'_>],
) -> usize {
    if rungs.len() < 2 {
        return 0;
    }
    let floor = EXACT_RMS_RAD * EXACT_RMS_RAD;
    // (rung, mean held-out square, its standard error) of the eligible rungs.
    let scores: Vec<(usize, f64, f64)> = rungs
        .iter()
        .enumerate()
        .filter(|(_, rung)| rung.sparse_nodes <= rungs[0].sparse_nodes)
        .map(|(i, rung)| {
            let held = held_out_squares(prior, correspondences, rung);
            let n = held.len() as f64;
            let mean = held.iter().sum::<f64>() / n;
            let spread = held.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (i, mean.max(floor), (spread / n).sqrt())
        })
        .collect();
    let Some(&(_, best, error)) = scores.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
        return 0;
    };
    scores
        .iter()
        .find(|(_, mean, _)| *mean <= best + error)
        .map_or(0, |(i, _, _)| *i)
}

/// The squared chord of each correspondence under the rung's refit without its fold.
fn held_out_squares(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    rung: &Rung<'_>,
) -> Vec<f64> {
    let mut squares = vec![REVERSED; correspondences.len()];
    let mut weights = Vec::new();
    for fold in 0..FOLDS {
        let training: Vec<Correspondence> = correspondences
            .iter()
            .enumerate()
            .filter(|(k, _)| k % FOLDS != fold)
            .map(|(_, c)| *c)
            .collect();
        let problem = Problem::new(prior, &training, rung.problem.smoothness);
        let Some(y) = problem.solve(&[&rung.grid]) else {
            continue;
        };
        for (k, c) in correspondences.iter().enumerate() {
            if k % FOLDS != fold {
                continue;
            }
            weights.clear();
            prior.for_each_weight(c.uv, |j, w| weights.push((j, w)));
            squares[k] = problem.miss_squared(c, &weights, &y);
        }
    }
    squares
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::super::super::{fit_with, FittedStarts, Starts};
    use super::super::tests::{farthest_miss, prior, seen_by, truths, uniform};
    use super::*;
    use crate::projection::flexible::projector_grid::tests::perspective_volume;

    /// The weight the free fit of `data` chose.
    fn chosen(data: &[Correspondence]) -> f64 {
        let (_, report) = fit_with(&prior(), data, Starts::Free).unwrap();
        assert_eq!(report.starts, FittedStarts::Free);
        report.smoothness.unwrap()
    }

    /// A 3 x 3 grid truth whose starts and ends are the prior's moved by up to 0.3 and 3
    /// (seeded): not bilinear across its nodes, no common eye.
    fn bent_truth(seed: u64) -> ProjectorGrid {
        let prior = prior();
        let mut next = uniform(seed);
        let mut jitter = |size: f64| DVec3::new(next(), next(), next()) * 2.0 * size - size;
        let starts = prior.starts().iter().map(|s| *s + jitter(0.3)).collect();
        let ends = prior.ends().iter().map(|e| *e + jitter(3.0)).collect();
        ProjectorGrid::new(prior.size(), starts, ends, prior.interpolation()).unwrap()
    }

    #[test]
    fn too_few_points_or_a_node_without_data_keep_the_largest_weight() {
        let bent = bent_truth(5);
        // 16 points: folds of 3 or 4 held-out points cannot rank the rungs.
        assert_eq!(chosen(&seen_by(&bent, 16, 3, 0.0, 1.0)), LADDER[0]);
        // 60 points in one cell: five nodes have no data; what the smoothness carries to
        // them no held-out point checks.
        let cell = seen_by(&bent, 60, 3, 0.0, 0.5);
        assert!(!cross_validates(&prior(), &cell));
        assert_eq!(chosen(&cell), LADDER[0]);
    }

    #[test]
    fn exact_bilinear_data_tie_and_keep_the_largest_weight() {
        for truth in truths() {
            let data = seen_by(&truth, 50, 3, 0.0, 1.0);
            let prior = prior();
            let rungs = fit_ladder(&prior, &data, &[]).unwrap();
            assert_eq!(rungs.len(), LADDER.len());
            assert_eq!(choose(&prior, &data, &rungs), 0);
            assert_eq!(chosen(&data), LADDER[0]);
        }
    }

    #[test]
    fn a_grid_bent_across_its_nodes_takes_a_weaker_weight_and_comes_closer() {
        for seed in [5, 6] {
            let truth = bent_truth(seed);
            let data = seen_by(&truth, 50, seed, 0.0, 1.0);
            let prior = prior();
            let rungs = fit_ladder(&prior, &data, &[]).unwrap();
            let index = choose(&prior, &data, &rungs);
            assert!(index > 0, "seed {seed}");
            let fixed = farthest_miss(&rungs[0].grid, &truth, 0.0, 1.0);
            let (fitted, report) = fit_with(&prior, &data, Starts::Free).unwrap();
            assert_eq!(report.smoothness, Some(LADDER[index]));
            let miss = farthest_miss(&fitted, &truth, 0.0, 1.0);
            assert!(miss < 0.5 * fixed, "seed {seed}: {miss} against {fixed}");
        }
    }

    #[test]
    fn a_fine_grid_from_few_points_is_judged_by_its_effective_unknowns() {
        // A 5 x 5 prior (150 unknowns) and 64 points (128 equations) of the bent 3 x 3 truth,
        // which the 5 x 5 grid holds exactly: only the effective count of the cross-validated
        // fit leaves `auto` spare equations to judge free starts by.
        let fine = ProjectorGrid::sample(
            &perspective_volume(60.0, [1.0, 40.0]),
            (5, 5),
            prior().interpolation(),
        )
        .unwrap();
        for seed in [6, 7, 8] {
            let truth = bent_truth(seed);
            let data = seen_by(&truth, 64, seed, 0.0, 1.0);
            let (fitted, report) = fit_with(&fine, &data, Starts::Auto).unwrap();
            let (kept, _) = fit_with(&fine, &data, Starts::Kept).unwrap();
            let miss = farthest_miss(&fitted, &truth, 0.0, 1.0);
            let kept_miss = farthest_miss(&kept, &truth, 0.0, 1.0);
            // Every node has data, so the weight was cross-validated and the count is the
            // effective one (measured: lines within 0.08 to 0.34 of the truth's points,
            // kept starts 2.5 to 4.4).
            assert_eq!(report.unconstrained_nodes, 0, "seed {seed}: {report:?}");
            assert_eq!(report.starts, FittedStarts::Free, "seed {seed}: {report:?}");
            assert!(
                miss < 0.5 * kept_miss,
                "seed {seed}: {miss} against {kept_miss}"
            );
        }
    }
}
