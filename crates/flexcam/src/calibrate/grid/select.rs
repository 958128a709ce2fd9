use glam::DVec3;
use rayon::prelude::*;

use super::folds::folded;
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

/// Whether a model with `unknowns` and the sum of squared misses `fewer_ss` should replace
/// one with fewer (`unknowns - extra`) and `more_ss`: it must lower the sum by more than 4
/// noise variances per extra unknown, the variance estimated from its own residual and its
/// degrees of freedom (2 equations a correspondence less `unknowns`); never where it has no
/// spare equations.
pub(super) fn clearly_better(
    count: usize,
    unknowns: usize,
    extra: usize,
    ss: f64,
    simpler_ss: f64,
) -> bool {
    let freedom = 2 * count;
    if freedom <= unknowns {
        return false;
    }
    simpler_ss > ss * (1.0 + 4.0 * extra as f64 / (freedom - unknowns) as f64)
}

/// `Starts::Auto`: [`nested_fit`]'s choice where the grid is curved, or where it is exact
/// and the data determine it or no pinhole fits them (too few points, all on one line):
/// exact data keep their model, bit for bit. Inexact data: the four models (kept starts, one
/// eye, free starts, one pinhole camera) are judged by their held-out misses
/// ([`held_out_misses`]: each fitted without a fifth of the points, measured at that fifth),
/// which the extra unknowns of a model that only fits the noise raise instead of lowering;
/// a grid that folds ([`folded`]) is taken only where every model's does, and one that
/// leaves nodes undetermined only where every unfolded one does. Among the rest the least
/// held-out misses win; a model within `TIE` of a simpler one's loses to it, and so does one
/// whose gain is within what exact fits miss (`EXACT_RMS_RAD` a correspondence). Where every
/// model folds or leaves nodes undetermined, [`nested_fit`]'s choice stands.
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
    // (held-out misses, flaws, the fit) of the best model so far.
    let mut best: Option<(f64, Flaws, (ProjectorGrid, FitReport))> = None;
    // Held-out misses this small are exact fits alike: no evidence for more unknowns.
    let exact_misses = correspondences.len() as f64 * EXACT_RMS_RAD.powi(2);
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
            Some((least, best_flaws, _)) => {
                flaws < *best_flaws
                    || (flaws == *best_flaws && misses < least * (1.0 - TIE) - exact_misses)
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

/// How much lower (as a fraction) a model's held-out misses must be to beat a simpler one's.
const TIE: f64 = 0.02;

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

/// The sum of squared misses ([`miss_seen_from`] the prior's starts) of every
/// correspondence by `model` fitted without it: the correspondences are split into
/// `FOLDS` parts (every `FOLDS`-th), and each part measured against the fit of the others.
/// `None` where a part's fit fails (the model needs more points than the others give). The
/// parts are fitted in parallel and their sums added in part order (the same sum whatever
/// the thread count).
fn held_out_misses(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    model: fn(&ProjectorGrid, &[Correspondence]) -> Fitted,
) -> Option<f64> {
    let parts: Option<Vec<f64>> = (0..FOLDS.min(correspondences.len()))
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
                    .map(|(_, c)| miss_seen_from(prior, &grid, c).powi(2))
                    .sum::<f64>(),
            )
        })
        .collect();
    Some(parts?.iter().sum())
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
