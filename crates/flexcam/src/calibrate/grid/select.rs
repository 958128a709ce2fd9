use glam::DVec3;
use rayon::prelude::*;

use super::folds::folded;
use super::nested_models::clearly_better;
use super::{
    central, constrained_nodes, fit, free, miss_seen_from, straight_undetermined, Correspondence,
    FitReport, FittedStarts, EXACT_RMS_RAD,
};
use crate::error::Result;
use crate::projection::flexible::ProjectorGrid;

/// The central fit, its report saying which eye it found.
pub(super) fn central_fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    central::fit(prior, correspondences).map(|found| reporting_eye(found, FittedStarts::Eye))
}

/// The pinhole fit (module `central`), its report saying which eye it found.
pub(super) fn pinhole_fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    central::fit_pinhole(prior, correspondences)
        .map(|found| reporting_eye(found, FittedStarts::Pinhole))
}

/// A fit through one eye (grid, report, eye), its report's starts naming the eye as
/// `starts` does.
fn reporting_eye(
    (grid, report, eye): (ProjectorGrid, FitReport, DVec3),
    starts: fn(DVec3) -> FittedStarts,
) -> (ProjectorGrid, FitReport) {
    let report = FitReport {
        starts: starts(eye),
        ..report
    };
    (grid, report)
}

/// Whether a fit's rms miss is at most `EXACT_RMS_RAD`.
pub(super) fn exact(report: &FitReport) -> bool {
    report.rms_angle_deg.to_radians() <= EXACT_RMS_RAD
}

/// `Starts::Auto`: [`nested_fit`]'s choice where the grid is curved, or where it is exact
/// and the data determine it or no pinhole fits them (too few points, all on one line):
/// exact data keep their model, bit for bit. Inexact data: the four models (kept starts, one
/// eye, free starts, one pinhole camera) are judged by their held-out misses
/// ([`held_out_misses`]: each fitted without a fifth of the points, measured at that fifth;
/// the same fifths for every model), which the extra unknowns of a model that only fits the
/// noise raise instead of lowering; a grid that folds ([`folded`]) is taken only where every
/// model's does, and one that leaves nodes undetermined only where every unfolded one does.
/// Among models of equal flaws, simplest first (pinhole, eye, kept, free), a richer model
/// replaces the one chosen so far only where the [`trimmed_mean`] of its held-out misses is
/// lower by more than what exact fits miss (`EXACT_RMS_RAD`): a tie keeps the simpler model,
/// and the few clicks that a model's fits without them miss widely, or meet by chance, do
/// not decide. Where every model folds or leaves nodes undetermined, [`nested_fit`]'s choice
/// stands.
pub(super) fn auto_fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let nested = nested_fit(prior, correspondences);
    // An exact fit that leaves nodes undetermined meets any data (fewer equations than
    // unknowns), so it is evidence only where no pinhole can be fitted instead.
    let open = |(grid, report): &(ProjectorGrid, FitReport)| match report.starts {
        FittedStarts::Kept => straight_undetermined(grid, correspondences).map_or(true, |n| n > 0),
        _ => report.sparse_nodes > 0,
    };
    let stands = |fitted: &(ProjectorGrid, FitReport)| {
        exact(&fitted.1) && (!open(fitted) || pinhole_fit(prior, correspondences).is_err())
    };
    if prior.is_curved() || nested.as_ref().is_ok_and(stands) {
        return nested;
    }
    // Simplest first: the pinhole's 11 unknowns, the eye's, the kept starts', the free ones'.
    let models: [fn(&ProjectorGrid, &[Correspondence]) -> Fitted; 4] =
        [pinhole_fit, central_fit, fit, free_fit];
    // (held-out misses a click, flaws, the fit) of the model chosen so far.
    let mut best: Option<(Vec<f64>, Flaws, (ProjectorGrid, FitReport))> = None;
    for model in models {
        let Ok(fitted) = model(prior, correspondences) else {
            continue;
        };
        let Some(misses) = held_out_misses(prior, correspondences, model) else {
            continue;
        };
        // Flaws, worst first: a folded grid, nodes the data leave undetermined.
        let flaws = (folded(&fitted.0, correspondences), open(&fitted));
        let better = match &best {
            None => true,
            Some((chosen, chosen_flaws, _)) => {
                flaws < *chosen_flaws || (flaws == *chosen_flaws && lower_held_out(chosen, &misses))
            }
        };
        if better {
            best = Some((misses, flaws, fitted));
        }
    }
    match best {
        Some((_, (false, false), fitted)) => Ok(fitted),
        // Every model folds or leaves nodes undetermined: the held-out points lie where the
        // others do and cannot judge the nodes no point reaches; the nested choice, which
        // counts unknowns, decides, its error included (a lone correspondence at the
        // prior's eye is not taken as evidence for free starts).
        _ => nested,
    }
}

/// A fit's flaws, compared worst first: (its grid is folded, nodes the data leave
/// undetermined).
type Flaws = (bool, bool);

/// The share of the held-out misses that [`trimmed_mean`] leaves out at each end (rounded
/// down: 3 of 15 clicks, 12 of 60). Held-out misses of painting-like data are not spread as
/// noise is: a model's fits without a fifth of the clicks may miss a few of them widely
/// while imaging the rest, and the truth, best (painting-like seed 18: two held-out clicks
/// missed by the eye 0.11 and 0.28 radians more than by the pinhole); such clicks decided a
/// mean (and a paired t test of the differences, which replaced a model only where most
/// clicks gained by more than their spread). Chosen on seeds 1 to 30 of `fit_painting.rs`
/// (docs/fitting.md, "Choosing the model on clicked data"): the least mean, 10, 15, 20 to
/// 45 % trimmed means and the median, against paired t, Wilcoxon signed-rank and sign tests;
/// 20 % lies in the plateau 20 to 45 % (28 of the 30 painting-like seeds at least as good as
/// the best single model, the paired t test at 30 %: 26) and changed no pinhole or cropped
/// truth's choice.
const TRIM: f64 = 0.2;

/// The mean of `misses` without the `TRIM` share of the smallest and of the largest
/// (`floor(TRIM n)` of n each: none of fewer than 5); `None` when empty. NaN misses sort to
/// the ends (`f64::total_cmp`) and are left out with them where the trim reaches them; a
/// mean they enter is NaN, which [`lower_held_out`] never takes.
pub(super) fn trimmed_mean(misses: &[f64]) -> Option<f64> {
    if misses.is_empty() {
        return None;
    }
    let mut sorted = misses.to_vec();
    sorted.sort_by(f64::total_cmp);
    let cut = (TRIM * sorted.len() as f64) as usize;
    let middle = &sorted[cut..sorted.len() - cut];
    Some(middle.iter().sum::<f64>() / middle.len() as f64)
}

/// Whether the held-out misses `richer` (angles, one a correspondence) have a
/// [`trimmed_mean`] lower than `simpler`'s by more than `EXACT_RMS_RAD` (what exact fits
/// miss: no evidence). The misses are compared as angles, not squared: squares make one
/// badly met click dominate. No misses give no evidence.
pub(super) fn lower_held_out(simpler: &[f64], richer: &[f64]) -> bool {
    match (trimmed_mean(simpler), trimmed_mean(richer)) {
        (Some(simpler), Some(richer)) => richer < simpler - EXACT_RMS_RAD,
        _ => false,
    }
}

/// Parts the correspondences are split into for [`held_out_misses`].
const FOLDS: usize = 5;

/// The free fit (module `free`) from the kept and eye fits' grids.
pub(super) fn free_fit(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> Fitted {
    let (kept, central) = (
        fit(prior, correspondences),
        central_fit(prior, correspondences),
    );
    let guesses: Vec<_> = [&kept, &central]
        .into_iter()
        .filter_map(|r| r.as_ref().ok().map(|(g, _)| g))
        .collect();
    let (grid, report, _) = free::fit(prior, correspondences, &guesses)?;
    Ok((grid, report))
}

/// The miss ([`miss_seen_from`] the prior's starts, an angle) of every correspondence, in
/// their order, by `model` fitted without it: the correspondences are split into `FOLDS`
/// parts (every `FOLDS`-th, the same parts for every model), and each part measured against
/// the fit of the others. `None` where a part's fit fails (the model needs more points than
/// the others give). The parts are fitted in parallel.
fn held_out_misses(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    model: fn(&ProjectorGrid, &[Correspondence]) -> Fitted,
) -> Option<Vec<f64>> {
    let parts: Option<Vec<(Vec<usize>, Vec<f64>)>> = (0..FOLDS.min(correspondences.len()))
        .into_par_iter()
        .map(|part| {
            let (held, kept): (Vec<_>, Vec<_>) = correspondences
                .iter()
                .enumerate()
                .partition(|(k, _)| k % FOLDS == part);
            let kept: Vec<Correspondence> = kept.into_iter().map(|(_, c)| *c).collect();
            let (grid, _) = model(prior, &kept).ok()?;
            Some(
                held.iter()
                    .map(|(k, c)| (*k, miss_seen_from(prior, &grid, c)))
                    .unzip(),
            )
        })
        .collect();
    let mut misses = vec![0.0; correspondences.len()];
    for (indices, held) in parts? {
        for (k, miss) in indices.into_iter().zip(held) {
            misses[k] = miss;
        }
    }
    Some(misses)
}

/// The choice of the nested models, simplest first: [`fit`]'s result, bit for bit, when that meets the data exactly with the
/// data determining the free directions (rms below `EXACT_RMS_RAD`), or when the grid is
/// curved; else the central fit when it is exact, or when it beats the kept one
/// ([`clearly_better`], its 3 eye coordinates extra), or when [`fit`] fails where it does
/// not. That simpler model stands when it is exact; otherwise the free fit (module `free`)
/// replaces it where it leaves no constrained node undetermined and the simpler model does
/// ([`undetermined_nodes`]: the same criterion for both), is never taken where it leaves one
/// and the simpler model none, and otherwise replaces it when it is clearly better, counting its effective unknowns (the trace
/// of its hat matrix, `free::Shape::freedom`; at most 5 a constrained node less the scale:
/// the smoothness spends fewer where the data are sparse), or, when it is exact with node
/// values affine along every grid line (a bilinear grid: the smoothness term's own model),
/// those of the grid's four corners (19); with no
/// more unknowns than the simpler model it must only miss the data less. Misses are compared
/// as [`misses_seen_from`] the prior's starts (here and between kept and eye starts), not as
/// each model's own residual. So pinhole data keep
/// their eye, bit for bit, and bilinear non-central data from as few as 10 points may take
/// the free starts.
pub(super) fn nested_fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let (simple, central) = kept_or_eye(prior, correspondences);
    if prior.is_curved() || simple.as_ref().is_ok_and(|(_, r)| exact(r)) {
        return simple;
    }
    let kept = fit(prior, correspondences).ok();
    let guesses: Vec<&ProjectorGrid> = [kept.as_ref(), central.as_ref()]
        .into_iter()
        .flatten()
        .map(|(g, _)| g)
        .collect();
    let Ok((free_grid, free_report, shape)) = free::fit(prior, correspondences, &guesses) else {
        return simple;
    };
    let Ok((simple_grid, simple_report)) = &simple else {
        // Where the simpler models fail (a point at its projector's start, say), free starts
        // that the data leave undetermined somewhere are no evidence of anything: the
        // simpler model's error stands.
        return if free_report.sparse_nodes == 0 {
            Ok((free_grid, free_report))
        } else {
            simple
        };
    };
    // Every model is judged by the same undetermined-node criterion: a model that the data
    // leave undetermined somewhere is no evidence against one they determine, and only two
    // determined (or two undetermined) models are compared by their misses.
    let simple_open = match simple_report.starts {
        FittedStarts::Kept => straight_undetermined(simple_grid, correspondences).unwrap_or(0),
        _ => simple_report.sparse_nodes,
    } > 0;
    match (simple_open, free_report.sparse_nodes > 0) {
        (false, true) => return simple,
        (true, false) => return Ok((free_grid, free_report)),
        _ => {}
    }
    let constrained = constrained_nodes(prior, correspondences)
        .iter()
        .filter(|c| **c)
        .count();
    let simple_unknowns = match simple_report.starts {
        FittedStarts::Eye(_) => 3 * constrained + 2,
        _ => 3 * constrained - 1,
    };
    let free_unknowns = if shape.bilinear && exact(&free_report) {
        4 * 5 - 1
    } else {
        // The effective count, rounded up (finite and below the nominal one).
        let nominal = 5 * constrained - 1;
        if shape.freedom < nominal as f64 {
            shape.freedom.ceil() as usize
        } else {
            nominal
        }
    };
    let count = correspondences.len();
    let ss = |grid: &ProjectorGrid| misses_seen_from(prior, grid, correspondences);
    let (free_ss, simple_ss) = (ss(&free_grid), ss(simple_grid));
    let better = if free_unknowns <= simple_unknowns {
        2 * count > free_unknowns && free_ss < simple_ss
    } else {
        clearly_better(
            count,
            free_unknowns,
            free_unknowns - simple_unknowns,
            free_ss,
            simple_ss,
        )
    };
    if better {
        Ok((free_grid, free_report))
    } else {
        simple
    }
}

/// The sum over `correspondences` of the squared distance from each point to `grid`'s
/// straight projector at its (u, v), over the point's distance from `prior`'s start there:
/// the misses as angles seen from where the prior looks. [`auto_fit`] compares models by it,
/// not by their own residuals, which are angles at each model's own starts: a model that
/// moves its starts away from the points (an eye far behind them) shrinks those angles
/// without imaging the points any better (measured: noisy pushbroom data, an eye fit with a
/// max residual of 0.01 degrees, below the noise, and 77 to 82 % ids).
pub(super) fn misses_seen_from(
    prior: &ProjectorGrid,
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> f64 {
    correspondences
        .iter()
        .map(|c| miss_seen_from(prior, grid, c).powi(2))
        .sum()
}

/// A fit result.
pub(super) type Fitted = Result<(ProjectorGrid, FitReport)>;

/// The choice between kept starts and one eye of [`auto_fit`], with the central fit when it
/// succeeded.
pub(super) fn kept_or_eye(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> (Fitted, Option<(ProjectorGrid, FitReport)>) {
    let kept = fit(prior, correspondences);
    // Fewer equations (2 a correspondence) than free node directions (3 a constrained
    // node, less the scale): the kept fit meets the points exactly whatever lies between
    // them, so its exactness says nothing; the eye is tried as well.
    let constrained = constrained_nodes(prior, correspondences);
    let node_unknowns = 3 * constrained.iter().filter(|c| **c).count();
    let determined = 2 * correspondences.len() + 1 > node_unknowns;
    if prior.is_curved() || (determined && kept.as_ref().is_ok_and(|(_, r)| exact(r))) {
        return (kept, None);
    }
    let Ok(central) = central_fit(prior, correspondences) else {
        return (kept, None);
    };
    // An exact central fit where the kept starts are not: the data are a pinhole's (the
    // central fit's pinhole field needs six points, where the counts below are those of
    // free node directions, which sparse data leave undetermined).
    if exact(&central.1) {
        return (Ok(central.clone()), Some(central));
    }
    let Ok((kept_grid, _)) = &kept else {
        return (Ok(central.clone()), Some(central));
    };
    let count = correspondences.len();
    let ss = |grid: &ProjectorGrid| misses_seen_from(prior, grid, correspondences);
    let unknowns = node_unknowns + 3 - 1;
    if clearly_better(count, unknowns, 3, ss(&central.0), ss(kept_grid)) {
        (Ok(central.clone()), Some(central))
    } else {
        (kept, Some(central))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// 30 held-out misses of one model, spread as clicks' are.
    fn misses() -> Vec<f64> {
        (0..30).map(|k| 1.0 + 0.5 * (k as f64).sin()).collect()
    }

    #[test]
    fn trimmed_means_leave_out_a_fifth_at_each_end() {
        assert_eq!(trimmed_mean(&[]), None);
        // Below 5 misses nothing is left out.
        assert_eq!(trimmed_mean(&[4.0]), Some(4.0));
        assert_eq!(trimmed_mean(&[1.0, 2.0, 9.0, 4.0]), Some(4.0));
        // 10 misses: the 2 smallest and the 2 largest are left out, in any order.
        let ten = [100.0, 1.0, 3.0, 5.0, 0.0, 4.0, 2.0, 6.0, 7.0, -50.0];
        assert_eq!(trimmed_mean(&ten), Some(3.5));
    }

    #[test]
    fn a_clear_win_replaces_the_simpler_model() {
        let simpler = misses();
        let richer: Vec<f64> = simpler.iter().map(|m| 0.25 * m).collect();
        assert!(lower_held_out(&simpler, &richer));
        assert!(!lower_held_out(&richer, &simpler));
    }

    #[test]
    fn a_tie_keeps_the_simpler_model() {
        let simpler = misses();
        assert!(!lower_held_out(&simpler, &simpler));
        // The clicks traded between the models.
        let swapped: Vec<f64> = simpler.iter().rev().copied().collect();
        assert!(!lower_held_out(&simpler, &swapped));
        assert!(!lower_held_out(&swapped, &simpler));
    }

    #[test]
    fn a_few_widely_missed_clicks_do_not_decide() {
        // Painting-like seed 18's pattern: the richer model meets 24 of 28 held-out clicks a
        // little better, and misses 4 (its fits without them) ten times as widely. Its mean
        // is twice the simpler model's; its trimmed mean is lower, and it replaces it.
        let simpler = vec![1.0; 28];
        let richer: Vec<f64> = (0..28).map(|k| if k < 4 { 10.0 } else { 0.9 }).collect();
        let mean = |m: &[f64]| m.iter().sum::<f64>() / m.len() as f64;
        assert!(mean(&richer) > 1.5 * mean(&simpler));
        assert!(lower_held_out(&simpler, &richer));
        // Nor do a few clicks that the richer model meets by chance.
        let lucky: Vec<f64> = (0..28).map(|k| if k < 4 { 0.0 } else { 1.1 }).collect();
        assert!(mean(&lucky) < mean(&simpler));
        assert!(!lower_held_out(&simpler, &lucky));
    }

    #[test]
    fn no_clicks_or_exact_level_gains_are_no_evidence() {
        assert!(!lower_held_out(&[], &[]));
        assert!(!lower_held_out(&[1.0], &[]));
        let exact = vec![0.5 * EXACT_RMS_RAD; 10];
        assert!(!lower_held_out(&exact, &[0.0; 10]));
        assert!(lower_held_out(&[2.0; 10], &[1.0; 10]));
        // A NaN miss in the middle makes the trimmed mean NaN: never a replacement.
        let mut nan = vec![1.0; 3];
        nan[1] = f64::NAN;
        assert!(!lower_held_out(&[2.0; 3], &nan));
        assert!(!lower_held_out(&nan, &[0.5; 3]));
    }

    proptest! {
        #[test]
        fn trimmed_means_lie_between_the_kept_misses_and_ignore_order_and_ends(
            misses in prop::collection::vec(0.0f64..10.0, 1..60),
            rotate in 0usize..60,
            outlier in 10.0f64..1e6,
        ) {
            let mean = trimmed_mean(&misses).unwrap();
            let low = misses.iter().copied().fold(f64::INFINITY, f64::min);
            let high = misses.iter().copied().fold(0.0, f64::max);
            prop_assert!(low - 1e-12 <= mean && mean <= high + 1e-12);
            let mut turned = misses.clone();
            turned.rotate_left(rotate % misses.len());
            prop_assert!((trimmed_mean(&turned).unwrap() - mean).abs() <= 1e-12 * high.max(1.0));
            // From 5 misses on, the largest may grow without bound: it is left out.
            if misses.len() >= 5 {
                let mut wild = misses.clone();
                let largest = (0..wild.len()).max_by(|&a, &b| wild[a].total_cmp(&wild[b])).unwrap();
                wild[largest] = outlier;
                prop_assert!((trimmed_mean(&wild).unwrap() - mean).abs() <= 1e-12 * high.max(1.0));
            }
        }
    }
}
