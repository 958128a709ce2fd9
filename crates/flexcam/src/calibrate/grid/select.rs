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
/// replaces the one chosen so far only where its held-out misses are lower by a paired test
/// ([`significantly_better`]: each click's held-out miss under the simpler model less that
/// under the richer, the click with the largest gain left out, whose mean must exceed the
/// one-sided t quantile at `T_LEVEL` (30 %) times its standard error, and what exact fits
/// miss). Where every model folds or leaves
/// nodes undetermined, [`nested_fit`]'s choice stands.
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
                flaws < *chosen_flaws
                    || (flaws == *chosen_flaws && significantly_better(chosen, &misses))
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

/// The one-sided level of [`significantly_better`]'s paired test: the chance that a richer
/// model whose held-out misses are no lower than the simpler one's (a tie) replaces it.
/// Held-out misses already charge a model for the unknowns that fit only the noise (and the
/// eye model, which keeps the square-pixel camera unless its free directions are clearly
/// better, images pinhole truths as the pinhole does), so the test guards against the
/// comparison's own spread only. On seeds 1 to 30 of `fit_painting.rs` (docs/fitting.md)
/// the test at 10 % kept the pinhole on 6 of 30 painting-like truths where a richer model
/// imaged them better, at 30 % (the largest gain left out) on 3, at 40 % on the same 3; no
/// level changed a pinhole or cropped truth's choice. Its t quantile (0.53 to 0.54 for 15 to 60 clicks) is below 1, the t statistic
/// of a gain at one click alone, the others equal: that is why the largest gain is left out.
const T_LEVEL: f64 = 0.3;

/// The standard normal distribution's upper `T_LEVEL` quantile.
const NORMAL_QUANTILE: f64 = 0.524_400_512_708_040_7;

/// Whether the held-out misses `richer` (angles, one a correspondence, in the order of
/// `simpler`) are lower than `simpler` by a paired test: the differences d_k = simpler_k -
/// richer_k (the same click, held out of the same fifth, under both models), less the
/// largest (one click, however well the richer model meets it, is no evidence), have a mean
/// above `EXACT_RMS_RAD` (what exact fits miss: no evidence) and above the one-sided t
/// quantile at `T_LEVEL` ([`t_quantile`], m - 1 degrees of freedom for the m differences
/// kept) times their standard error s / sqrt(m). The misses are compared as angles, not
/// squared: squares make one badly met click dominate the differences' spread. Pairing
/// removes what both models miss alike (a badly clicked point), so a gain that is small but
/// shared by most clicks counts, and one carried by a single click does not, whatever the
/// others do. Fewer than 3 clicks give no evidence. Differences all equal (no spread) count
/// when their mean passes the first bound.
pub(super) fn significantly_better(simpler: &[f64], richer: &[f64]) -> bool {
    let mut d: Vec<f64> = simpler.iter().zip(richer).map(|(s, r)| s - r).collect();
    let Some(largest) = (0..d.len()).max_by(|&a, &b| d[a].total_cmp(&d[b])) else {
        return false;
    };
    d.swap_remove(largest);
    let n = d.len();
    if n < 2 {
        return false;
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let variance = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let error = (variance / n as f64).sqrt();
    mean > EXACT_RMS_RAD && mean > t_quantile(n - 1) * error
}

/// The upper `T_LEVEL` quantile of Student's t with `freedom` degrees of freedom, by the
/// Cornish-Fisher expansion about the normal quantile `NORMAL_QUANTILE` (Abramowitz and
/// Stegun 26.7.5: within 0.002 of the tables from 3 degrees of freedom); a single degree of
/// freedom, where the expansion is worst, gets its closed form tan(pi (1/2 - `T_LEVEL`)).
fn t_quantile(freedom: usize) -> f64 {
    if freedom == 1 {
        return (std::f64::consts::PI * (0.5 - T_LEVEL)).tan();
    }
    let z = NORMAL_QUANTILE;
    let v = freedom as f64;
    let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
    z + (z3 + z) / (4.0 * v)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * v * v * v)
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

    /// The rule `significantly_better` replaced: the richer model's squared held-out misses
    /// summed at least 2 % below the simpler one's.
    fn margin_rule(simpler: &[f64], richer: &[f64]) -> bool {
        let squares = |m: &[f64]| m.iter().map(|x| x * x).sum::<f64>();
        squares(richer) < (1.0 - 0.02) * squares(simpler)
    }

    /// 30 held-out misses of one model, spread as clicks' are.
    fn misses() -> Vec<f64> {
        (0..30).map(|k| 1.0 + 0.5 * (k as f64).sin()).collect()
    }

    #[test]
    fn t_quantiles_match_the_tables() {
        for (freedom, table) in [
            (1, 0.727),
            (3, 0.584),
            (14, 0.537),
            (29, 0.530),
            (59, 0.527),
        ] {
            let t = t_quantile(freedom);
            assert!((t - table).abs() < 0.002, "{freedom}: {t} against {table}");
        }
    }

    #[test]
    fn a_clear_win_replaces_the_simpler_model() {
        let simpler = misses();
        let richer: Vec<f64> = simpler.iter().map(|m| 0.25 * m).collect();
        assert!(significantly_better(&simpler, &richer));
        assert!(margin_rule(&simpler, &richer));
    }

    #[test]
    fn a_tie_keeps_the_simpler_model() {
        let simpler = misses();
        assert!(!significantly_better(&simpler, &simpler));
        // Equal means, the clicks traded between the models.
        let swapped: Vec<f64> = simpler.iter().rev().copied().collect();
        assert!(!significantly_better(&simpler, &swapped));
        assert!(!significantly_better(&swapped, &simpler));
    }

    #[test]
    fn a_gain_carried_by_one_click_among_noise_level_changes_is_no_evidence() {
        // The richer model meets click 0 better (0.5 against 3) and the others by 1 +- 0.3
        // at random: its squared misses sum 18 % lower, which the margin rule took.
        let simpler: Vec<f64> = (0..30).map(|k| if k == 0 { 3.0 } else { 1.0 }).collect();
        let richer: Vec<f64> = (0..30)
            .map(|k| {
                if k == 0 {
                    0.5
                } else {
                    1.0 + 0.3 * (-1.0_f64).powi(k)
                }
            })
            .collect();
        assert!(margin_rule(&simpler, &richer));
        assert!(!significantly_better(&simpler, &richer));
        // Nor one click alone, the others equal (its t statistic, 1, is above the quantile).
        let one: Vec<f64> = (0..30).map(|k| if k == 0 { 0.5 } else { 1.0 }).collect();
        assert!(!significantly_better(&simpler, &one));
        // Two such clicks are evidence.
        let two: Vec<f64> = (0..30).map(|k| if k < 2 { 0.5 } else { 1.0 }).collect();
        let simpler_two: Vec<f64> = (0..30).map(|k| if k < 2 { 3.0 } else { 1.0 }).collect();
        assert!(significantly_better(&simpler_two, &two));
    }

    #[test]
    fn a_small_gain_at_every_click_is_evidence() {
        // 0.5 % less at every click: below the margin, but no click says otherwise.
        let simpler = misses();
        let richer: Vec<f64> = simpler.iter().map(|m| 0.995 * m).collect();
        assert!(!margin_rule(&simpler, &richer));
        assert!(significantly_better(&simpler, &richer));
        // And the other way round: more at every click never replaces.
        assert!(!significantly_better(&richer, &simpler));
    }

    #[test]
    fn too_few_clicks_or_exact_level_gains_are_no_evidence() {
        assert!(!significantly_better(&[], &[]));
        assert!(!significantly_better(&[1.0], &[0.0]));
        let exact = vec![0.5 * EXACT_RMS_RAD; 10];
        assert!(!significantly_better(&exact, &[0.0; 10]));
        // A gain equal at every click (no spread) counts once above exact-fit level.
        assert!(significantly_better(&[2.0; 10], &[1.0; 10]));
    }
}
