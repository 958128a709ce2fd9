//! Fitting a projector grid to point correspondences by linear least squares: given scene
//! points and the image positions where they must appear, aim every node projector at once.
//! The thesis placed its 25 projectors by hand, about three hours per attempt, with no error
//! measure (8.3); this does it in milliseconds and reports the residual.
//!
//! # The problem
//!
//! The starts S_j of the node projectors are kept (they are the image plane: where each part of
//! the image begins); the unknowns are the node directions D_j = E_j - S_j. Correspondence k
//! says that scene point X_k lies on the projector of (u_k, v_k), i.e. that
//! D(u_k, v_k) = sum_j w_j(u_k, v_k) D_j is parallel to a_k = (X_k - S(u_k, v_k)) / |...|.
//! With P_k = I - a_k a_k^T (the projection off a_k), `P_k D(u_k, v_k) = 0` is linear in the
//! D_j, so the fit minimises
//!
//! sum_k |P_k sum_j w_kj D_j|^2 + lambda sum_j |D_j - D0_j|^2
//!
//! where D0 are the prior grid's directions, subject to one linear constraint that fixes the
//! overall scale: sum_j D0_j . D_j = sum_j |D0_j|^2 over the nodes that some correspondence
//! constrains. The data term alone is homogeneous (D = 0 and any overall scale fit it): the
//! constraint removes that freedom without shrinking the solution towards zero (a pure prior
//! term would shrink it, badly so when the data are noisy), and the small prior term gives
//! nodes that no correspondence constrains (no weight at any (u_k, v_k)) the prior's
//! projector and settles directions the data leave open. lambda is 1e-11 of the data term's
//! mean diagonal: it keeps the system positive definite, and the bias it adds to directions
//! the data determine grows with it (measured: 1e-6 rad at 1e-8, 2e-9 rad at 1e-11 on
//! exact data), so it is as small as double precision allows; a second solve centred on the
//! first removes most of what bias remains (see [`fit`]).
//!
//! Unknowns are scaled by the prior's mean projector length, so lambda is dimensionless. After
//! the solve, when some X_k would lie beyond its projector's end (t > 1), all directions are
//! lengthened by one common factor (which changes no direction) so that every X_k is in view.
//!
//! # Noise
//!
//! The floor weight holds only against exact data: a Bezier grid's inner control nodes are
//! weakly determined by scattered points, and with 1e-3 rad of noise the floor-weighted fit
//! turned such node combinations until projectors pointed away from their points (21 of 100
//! random fits from 144 points and 89 of 100 from 64 were refused, two more turned a
//! projector by 3.1 rad). [`fit`] therefore first measures the data's noise with one
//! floor-weighted solve and, where it is above rounding level, solves once more with the
//! prior's weight set to the estimated noise variance over `PRIOR_SPREAD`^2 (the maximum a
//! posteriori weight for a Gaussian prior around the prior grid), centred on the prior. Exact
//! data take the floor weight and the two solves as before, unchanged.
//!
//! # Inexact data
//!
//! |P_k D|^2 is |D| sin(angle) squared: a projector pointing away meets it as well as one
//! pointing towards X_k, and shortening D lowers it. Where no grid with the kept starts meets
//! the data (a near surface off the camera's eye), the linear optimum shrank the nodes the
//! residual gathers on to 1e-9 to 2e-7 of the longest and past zero, and consistent data were
//! refused as contradictory. When the floor-weighted linear fit misses the data by more than
//! `EXACT_CHORD`, the fit keeps the noise-weighted linear solution only where it reaches every
//! point in front of its start; otherwise (no noise weight, or some point behind) it refines
//! on the chord 2 sin(angle / 2) between fitted and wanted unit directions, which no length
//! changes and a reversed projector maximises, from the linear solution and from the prior
//! (module `angular`). Refining noisy Bezier fits as well was measured worse (see
//! docs/flexible.md) and is not done.
//!
//! Degenerate cases: no correspondences (the prior is returned unchanged); a point at its
//! projector's start (no direction: an error naming it); (u, v) outside [0, 1]^2 or
//! non-finite values (errors); correspondences that only a projector pointing away could meet
//! (an error: the fitted projector must reach X_k at t > 0); a fitted node direction of zero
//! length (an error).
//!
//! # Starts
//!
//! Kept starts off a pinhole camera's eye meet no grid to its correspondences, and sparse
//! data then bend the fit between the points (a small residual, a wrong image). [`fit_with`]
//! takes the scene key `starts`: `Kept` is [`fit`]; `Eye` fits one common eye with the
//! directions, every projector through it (module `central`: a pinhole camera's affine
//! direction field where that explains the data, else free node directions); `Auto`, the
//! default, keeps the starts when they meet the data exactly and the data determine the
//! free directions (bit for bit the old result), takes an exact eye fit where they do not
//! (sparse data met exactly by many bent grids), and otherwise the eye where it meets the
//! data clearly better. `Free` fits every node's start too (module `free`: projections with
//! no common eye, such as pushbroom and crossed slits); `Auto` takes it where neither simpler
//! model is exact and it is clearly better and determined ([`auto_fit`]).
//!
//! # Warnings
//!
//! The residual is measured at the correspondences only. [`FitReport`] counts the
//! constrained nodes that left the prior by far (`wild_nodes`: a length ratio to the prior's
//! node beyond `WILD_LENGTH` times the median ratio, judged only where the lengths move the
//! projectors at the points by more than the fit's noise ([`lengths_move_lines`]), or a
//! direction more than `WILD_ANGLE_DEG` off) and those whose projectors the chosen model leaves undetermined
//! (`sparse_nodes`, [`undetermined_nodes`]: none for a pinhole's field; for curved grids,
//! summed grid weight below `SPARSE_WEIGHT`); [`FitReport::warning`] words them for the user.
//!
//! # Curved projectors
//!
//! A prior with node tangents (quadratic Bezier projectors) is fitted in two stages: the
//! straight fit above (its tangents dropped; with the noise's prior weight where its residual
//! is above rounding, as it always is for curved data), then the end directions, tangents and
//! lengths (where the data determine them; else the prior's) of every node that some
//! correspondence constrains by nonlinear least squares from there (module `curved`).
//! The prior's tangents mark the grid as curved and stay on the nodes no correspondence
//! constrains; a fitted tangent along its chord makes a straight node.

use glam::{DVec2, DVec3};
use nalgebra::{DMatrix, DVector};

use super::projector_grid::ProjectorGrid;
use crate::error::{Error, Result};

mod angular;
mod central;
mod curved;
mod free;

/// The prior's least weight, relative to the data term's mean diagonal (see the module docs).
const PRIOR_WEIGHT: f64 = 1e-11;

/// How far, as a fraction of their length, the prior's node directions are taken to be off
/// the truth when its weight follows the noise (module section "Noise").
const PRIOR_SPREAD: f64 = 1.0;

/// A scene point and the image position (u, v) in [0, 1]^2 (u right, v up) that must see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    pub uv: DVec2,
    pub point: DVec3,
}

/// Where the fitted grid's projectors start: the scene key `starts` (module section
/// "Starts").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Starts {
    /// The prior's starts are kept; only the node directions are fitted.
    Kept,
    /// One common eye is fitted with the directions; every projector passes through it.
    Eye,
    /// Every node's start is fitted with the directions (module `free`).
    Free,
    /// The kept starts where they meet the data exactly and determine the directions, else
    /// the eye where it meets the data exactly or clearly better, else the free starts where
    /// they meet the data clearly better (see [`fit_with`]).
    #[default]
    Auto,
}

impl Starts {
    /// The scene file's names, in the order of the error message.
    pub const NAMES: [&'static str; 4] = ["auto", "kept", "eye", "free"];

    /// The model of a scene file name (`None` for any other).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Starts::Auto),
            "kept" => Some(Starts::Kept),
            "eye" => Some(Starts::Eye),
            "free" => Some(Starts::Free),
            _ => None,
        }
    }
}

/// The starts a fit used.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FittedStarts {
    /// The prior's starts.
    #[default]
    Kept,
    /// Starts on projectors through this fitted eye.
    Eye(DVec3),
    /// Starts fitted per node (module `free`).
    Free,
}

/// In words, for the written scene's header and `flexcam fit`'s output.
impl std::fmt::Display for FittedStarts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FittedStarts::Kept => write!(f, "starts kept"),
            FittedStarts::Eye(e) => write!(f, "starts on projectors through the fitted eye {e}"),
            FittedStarts::Free => write!(f, "starts fitted per node"),
        }
    }
}

/// How well a fitted grid meets the correspondences.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FitReport {
    /// Correspondences used.
    pub correspondences: usize,
    /// Nodes no correspondence constrains (they keep the prior's projector).
    pub unconstrained_nodes: usize,
    /// Largest angle, in degrees, between a fitted projector and the direction from its start
    /// to its scene point.
    pub max_angle_deg: f64,
    /// Root mean square of those angles, in degrees.
    pub rms_angle_deg: f64,
    /// The starts the fit used.
    pub starts: FittedStarts,
    /// Constrained nodes that left the prior by far (module section "Warnings").
    pub wild_nodes: usize,
    /// Constrained nodes that the data leave undetermined under the fitted model (module
    /// section "Warnings").
    pub sparse_nodes: usize,
    /// The free fit's smoothness weight, relative to its data term's mean diagonal, as the
    /// data chose it (module `free::weight`); `None` for the other models.
    pub smoothness: Option<f64>,
}

impl FitReport {
    /// The model in words, for `flexcam fit`'s line and the written header: the starts, and
    /// for the free fit the smoothness weight the data chose.
    pub fn model(&self) -> String {
        match self.smoothness {
            Some(weight) => format!("{}, smoothness {weight:e}", self.starts),
            None => self.starts.to_string(),
        }
    }

    /// A warning for the user when some node left the prior by far or is undetermined:
    /// the residual, measured at the correspondences only, may then hide a wrong image.
    pub fn warning(&self) -> Option<String> {
        node_warning(self.wild_nodes, self.sparse_nodes)
    }
}

/// [`FitReport::warning`] from its two counts (as `flexcam render`'s statistics carry them:
/// `fit_wild_nodes`, `fit_sparse_nodes`).
pub fn node_warning(wild_nodes: usize, sparse_nodes: usize) -> Option<String> {
    let mut parts = Vec::new();
    if wild_nodes > 0 {
        parts.push(format!(
            "{wild_nodes} fitted node(s) left the prior by far (length over {WILD_LENGTH} \
                 times or under 1/{WILD_LENGTH} of the median length ratio, or direction over \
                 {WILD_ANGLE_DEG} degrees off)"
        ));
    }
    if sparse_nodes > 0 {
        parts.push(format!(
            "{sparse_nodes} node(s) are not determined by the correspondences under the \
                 fitted model (too few points near them)"
        ));
    }
    (!parts.is_empty()).then(|| {
        format!(
            "{}: the residual is measured at the correspondences only; check the fitted \
                 image",
            parts.join(" and ")
        )
    })
}

/// Fits the node directions of `prior` to `correspondences` (see the module docs); returns the
/// fitted grid, with the prior's starts and interpolation, and its residual. A prior with
/// tangents is fitted with curved projectors (section "Curved projectors").
///
/// Noisy data (module section "Noise") are solved once with the noise's prior weight. Exact
/// data: the solve runs twice, the second time with the first fit as its prior: the prior term pulls
/// every direction towards the prior by about `PRIOR_WEIGHT` times their difference, which for
/// a prior far from the answer (a 90-degree frustum fitted to a 20-degree camera) leaves
/// errors near 2e-7 rad; centred on the first fit, the pull acts on that small residual only.
pub fn fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    if prior.is_curved() {
        targets(prior, correspondences)?;
        // Only a start: where curved data make the straight fit shrink a node to nothing,
        // the prior's own straight projectors start the curved fit instead.
        let start = straight_start(prior, correspondences).unwrap_or_else(|_| prior.straightened());
        return curved::fit(prior, &start, correspondences);
    }
    let targets = targets(prior, correspondences)?;
    let system = System::new(prior, correspondences, &targets);
    let floor_dirs = system.solve(0.0)?;
    if nearly_exact(prior, correspondences, &targets, &floor_dirs) {
        let (first, _) = in_view(prior, correspondences, &targets, floor_dirs)?;
        return fit_once(&first, correspondences);
    }
    // Inexact data (module section "Inexact data"): the linear solution with the noise's
    // prior weight is kept where it reaches every point in front of its start; otherwise
    // (no weight, or a node shrunk past zero) it and the prior start the angular refinement.
    let weight = noise_weight(&system, correspondences, &targets, &floor_dirs);
    let linear = match weight {
        Some(weight) => system.solve(weight)?,
        None => floor_dirs,
    };
    if weight.is_some() && all_in_front(prior, correspondences, &targets, &linear) {
        return in_view(prior, correspondences, &targets, linear);
    }
    let prior_dirs = prior
        .starts()
        .iter()
        .zip(prior.ends())
        .map(|(s, e)| *e - *s)
        .collect();
    let dirs = angular::refine(
        &system,
        correspondences,
        &targets,
        &[linear, prior_dirs],
        weight.unwrap_or(0.0),
    );
    in_view(prior, correspondences, &targets, dirs)
}

/// Fits `prior` to `correspondences` with the starts model `starts` (module section
/// "Starts"): `Kept` is [`fit`]; `Eye` the central fit (module `central`, its errors
/// included); `Free` the free fit (module `free`); `Auto` the simplest model that explains the
/// data ([`auto_fit`]). Then counts the wild nodes and, for kept starts, the undetermined ones
/// (the other models count their own; module section "Warnings").
pub fn fit_with(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    starts: Starts,
) -> Result<(ProjectorGrid, FitReport)> {
    let (grid, mut report) = match starts {
        Starts::Kept => fit(prior, correspondences)?,
        Starts::Eye => central_fit(prior, correspondences)?,
        Starts::Free => {
            let (kept, central) = (
                fit(prior, correspondences),
                central_fit(prior, correspondences),
            );
            let guesses: Vec<_> = [&kept, &central]
                .into_iter()
                .filter_map(|r| r.as_ref().ok().map(|(g, _)| g))
                .collect();
            let (grid, report, _) = free::fit(prior, correspondences, &guesses)?;
            (grid, report)
        }
        Starts::Auto => auto_fit(prior, correspondences)?,
    };
    report.wild_nodes = wild_nodes(prior, &grid, correspondences);
    if report.starts == FittedStarts::Kept {
        report.sparse_nodes = if grid.is_curved() {
            thinly_weighted_nodes(prior, correspondences)
        } else {
            straight_undetermined(&grid, correspondences)?
        };
    }
    Ok((grid, report))
}

/// Largest rms angle, in radians, of a fit that `Starts::Auto` takes as meeting the data
/// exactly (the rms miss `EXACT_CHORD` allows).
const EXACT_RMS_RAD: f64 = 1e-6;

/// The central fit, its report saying which eye it found.
fn central_fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let (grid, report, eye) = central::fit(prior, correspondences)?;
    Ok((
        grid,
        FitReport {
            starts: FittedStarts::Eye(eye),
            ..report
        },
    ))
}

/// Whether a fit's rms miss is at most `EXACT_RMS_RAD`.
fn exact(report: &FitReport) -> bool {
    report.rms_angle_deg.to_radians() <= EXACT_RMS_RAD
}

/// Whether a model with `unknowns` and the sum of squared misses `fewer_ss` should replace
/// one with fewer (`unknowns - extra`) and `more_ss`: it must lower the sum by more than 4
/// noise variances per extra unknown, the variance estimated from its own residual and its
/// degrees of freedom (2 equations a correspondence less `unknowns`); never where it has no
/// spare equations.
fn clearly_better(count: usize, unknowns: usize, extra: usize, ss: f64, simpler_ss: f64) -> bool {
    let freedom = 2 * count;
    if freedom <= unknowns {
        return false;
    }
    simpler_ss > ss * (1.0 + 4.0 * extra as f64 / (freedom - unknowns) as f64)
}

/// `Starts::Auto`: [`fit`]'s result, bit for bit, when that meets the data exactly with the
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
fn auto_fit(
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
fn misses_seen_from(
    prior: &ProjectorGrid,
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> f64 {
    correspondences
        .iter()
        .map(|c| miss_seen_from(prior, grid, c).powi(2))
        .sum()
}

/// The distance from `c`'s point to `grid`'s straight projector at its (u, v), over the
/// point's distance from `prior`'s start there (one term of [`misses_seen_from`]).
fn miss_seen_from(prior: &ProjectorGrid, grid: &ProjectorGrid, c: &Correspondence) -> f64 {
    (c.point - foot(grid, c)).length() / reach(prior, c)
}

/// The point's distance from `prior`'s start at its (u, v), the unit of
/// [`miss_seen_from`].
fn reach(prior: &ProjectorGrid, c: &Correspondence) -> f64 {
    // A point at the prior's start is an error of every fit (`targets`).
    (c.point - prior.start_end(c.uv).0)
        .length()
        .max(f64::MIN_POSITIVE)
}

/// The point of `grid`'s straight projector line at `c`'s (u, v) nearest `c`'s point (the
/// start where the projector has no direction).
fn foot(grid: &ProjectorGrid, c: &Correspondence) -> DVec3 {
    let (s, e) = grid.start_end(c.uv);
    match (e - s).try_normalize() {
        Some(d) => s + d * (c.point - s).dot(d),
        None => s,
    }
}

/// A fit result.
type Fitted = Result<(ProjectorGrid, FitReport)>;

/// The choice between kept starts and one eye of [`auto_fit`], with the central fit when it
/// succeeded.
fn kept_or_eye(
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

/// A fitted node is wild when its length ratio to the prior's node is more than this many
/// times the median ratio of the constrained nodes, or less than its inverse.
const WILD_LENGTH: f64 = 4.0;

/// Node lengths are judged when giving them the median ratio moves the projectors at the
/// points by more than this many times the fit's noise (root mean squares, see
/// [`lengths_move_lines`]): moves of a few noise deviations change the image by about the
/// noise's size (measured: a noisy pushbroom fit's length pattern, 2.4 times), a wild node
/// moves them by far more (its cell's angular spread).
const LENGTH_MOVE: f64 = 4.0;

/// A fitted node is wild when its direction is more than this many degrees off the prior's.
const WILD_ANGLE_DEG: f64 = 60.0;

/// A constrained node of a curved grid has little data when the grid weights on it, summed
/// over the correspondences, are below this: less than one correspondence's two equations
/// for the node's three unknowns.
const SPARSE_WEIGHT: f64 = 1.0;

/// The node weights summed over the correspondences.
fn node_weights(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> Vec<f64> {
    let mut weight = vec![0.0; prior.starts().len()];
    for c in correspondences {
        prior.for_each_weight(c.uv, |j, w| weight[j] += w);
    }
    weight
}

/// The number of wild constrained nodes of `fitted` against `prior` (module section
/// "Warnings").
fn wild_nodes(
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
fn lengths_move_lines(
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
fn median_squared_miss(
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
fn thinly_weighted_nodes(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> usize {
    node_weights(prior, correspondences)
        .iter()
        .filter(|w| **w > 0.0 && **w < SPARSE_WEIGHT)
        .count()
}

/// A node is undetermined when the variance of some projector at or around it under the
/// model, relative to the inverse mean diagonal of the model's matrix, exceeds this: the data
/// (and the model's own terms) leave it free, and only the prior's weak pull settles it.
const UNDETERMINED_VARIANCE: f64 = 1e6;

/// The constrained nodes (`constrained`) of the fitted `grid` whose projectors the model
/// leaves undetermined (module section "Warnings"). `matrix` is the model's Gauss-Newton
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
fn undetermined_nodes(
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
fn straight_undetermined(
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
fn prior_directions(grid: &ProjectorGrid) -> Vec<DVec3> {
    grid.starts()
        .iter()
        .zip(grid.ends())
        .map(|(s, e)| *e - *s)
        .collect()
}

/// The residual of `grid` (straight) at `correspondences`, seen from its own starts.
fn report_of(grid: &ProjectorGrid, correspondences: &[Correspondence]) -> Result<FitReport> {
    let targets = targets(grid, correspondences)?;
    let constrained = constrained_nodes(grid, correspondences);
    Ok(residual(grid, correspondences, &targets, &constrained))
}

/// The direction of correspondence `c`'s projector in `prior`'s grid with node directions
/// `dirs`: the nodes' directions blended with the grid's weights at its image position.
fn blended(prior: &ProjectorGrid, c: &Correspondence, dirs: &[DVec3]) -> DVec3 {
    let mut d = DVec3::ZERO;
    prior.for_each_weight(c.uv, |j, w| d += w * dirs[j]);
    d
}

/// Whether every correspondence's blended direction in `dirs` points towards its target
/// (positive dot product: its point is reached at t > 0).
fn all_in_front(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    dirs: &[DVec3],
) -> bool {
    correspondences
        .iter()
        .zip(targets)
        .all(|(c, a)| blended(prior, c, dirs).dot(*a) > 0.0)
}

/// Largest mean squared chord (2 sin(angle / 2)) per correspondence, in rad^2, at which the
/// linear fit is taken as meeting the data (rms miss 1e-6 rad): below it the linear optimum
/// cannot have shrunk or reversed a node (module section "Inexact data").
const EXACT_CHORD: f64 = 1e-12;

/// Whether the floor-weighted linear directions `dirs` meet every correspondence to within
/// `EXACT_CHORD` on average (each in front of its start).
fn nearly_exact(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    dirs: &[DVec3],
) -> bool {
    let sum: f64 = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = blended(prior, c, dirs);
            d.try_normalize().map_or(4.0, |n| (n - *a).length_squared())
        })
        .sum();
    sum <= EXACT_CHORD * correspondences.len() as f64
}

/// The straight fit's first solve, its node directions before any lengthening.
enum FirstSolve {
    /// Noisy data: the one solve with the noise's prior weight ([`noise_weight`]).
    Noisy(Vec<DVec3>),
    /// Exact data: the floor-weighted solve, the first of two (see [`fit`]).
    Exact(Vec<DVec3>),
}

/// The first solve of the straight fit of `prior` to `correspondences` (`targets`: their
/// unit directions from their projectors' starts): the floor-weighted solve both measures
/// the noise and, for exact data, is the first of the two solves.
fn first_solve(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
) -> Result<FirstSolve> {
    let system = System::new(prior, correspondences, targets);
    let floor_dirs = system.solve(0.0)?;
    Ok(
        match noise_weight(&system, correspondences, targets, &floor_dirs) {
            Some(weight) => FirstSolve::Noisy(system.solve(weight)?),
            None => FirstSolve::Exact(floor_dirs),
        },
    )
}

/// The prior's weight for noisy correspondences, or `None` when the data show no noise above
/// what the floor weight `PRIOR_WEIGHT` handles (see the module section "Noise").
///
/// The solve at the floor weight, `floor_dirs`, measures the data term's residual sum of squares; divided by
/// the degrees of freedom (two equations per correspondence less the unknowns of the
/// constrained nodes, plus one for the scale constraint) it estimates the noise variance
/// sigma^2 per equation, in the unknowns' scaled units (about radians squared). The weight is
/// then sigma^2 / `PRIOR_SPREAD`^2: the maximum a posteriori weight for a prior whose node
/// directions may be off by about `PRIOR_SPREAD` of their length.
///
/// Degenerate cases: exact data (the estimate is at rounding level, below the floor: `None`,
/// so that exact data are fitted as before); no more equations than unknowns (say one
/// correspondence, or 30 points for a Bezier grid's 75 unknowns: the data can be met exactly,
/// noise cannot be told from signal: `None`).
fn noise_weight(
    system: &System<'_>,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    floor_dirs: &[DVec3],
) -> Option<f64> {
    let prior = system.prior;
    let constrained = constrained_nodes(prior, correspondences);
    let unknowns = 3 * constrained.iter().filter(|c| **c).count();
    let equations = 2 * correspondences.len() + 1;
    if equations <= unknowns {
        return None;
    }
    let sum_of_squares: f64 = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = blended(prior, c, floor_dirs) / system.scale;
            (d - d.dot(*a) * *a).length_squared()
        })
        .sum();
    let variance = sum_of_squares / (equations - unknowns) as f64;
    let weight = variance / (PRIOR_SPREAD * PRIOR_SPREAD);
    (weight > system.floor).then_some(weight)
}

/// The start of the curved fit: the straight fit of `prior` without its tangents (the
/// noise's prior weight where the straight residual exceeds rounding, else the two solves of
/// exact data), without the check that every point is reached (a straight projector may
/// point away from a point that the curved one reaches).
fn straight_start(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<ProjectorGrid> {
    let straight = prior.straightened();
    let targets = targets(&straight, correspondences)?;
    match first_solve(&straight, correspondences, &targets)? {
        FirstSolve::Noisy(dirs) => with_directions(&straight, &dirs),
        FirstSolve::Exact(dirs) => {
            let first = with_directions(&straight, &dirs)?;
            with_directions(&first, &solve_directions(&first, correspondences)?)
        }
    }
}

/// One least-squares solve around `prior` at the floor weight (see [`fit`]), its projectors
/// lengthened so that every point is in view.
fn fit_once(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport)> {
    let targets = targets(prior, correspondences)?;
    let dirs = solve_directions(prior, correspondences)?;
    in_view(prior, correspondences, &targets, dirs)
}

/// The grid of `prior` with the solved node directions `dirs`, all lengthened by one common
/// factor where some point would lie beyond its projector's end (module docs), and its
/// residual; `targets` are the correspondences' unit directions from their projectors' starts.
fn in_view(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    mut dirs: Vec<DVec3>,
) -> Result<(ProjectorGrid, FitReport)> {
    let fitted = with_directions(prior, &dirs)?;
    let reach = farthest_reach(&fitted, correspondences)?;
    if reach > 1.0 {
        for d in &mut dirs {
            *d *= 1.01 * reach;
        }
    }
    let fitted = with_directions(prior, &dirs)?;
    let constrained = constrained_nodes(prior, correspondences);
    let report = residual(&fitted, correspondences, targets, &constrained);
    Ok((fitted, report))
}

/// Whether some correspondence weights each node of `grid`.
fn constrained_nodes(grid: &ProjectorGrid, correspondences: &[Correspondence]) -> Vec<bool> {
    let mut constrained = vec![false; grid.starts().len()];
    for c in correspondences {
        grid.for_each_weight(c.uv, |j, _| constrained[j] = true);
    }
    constrained
}

/// The node directions of one least-squares solve around `prior` at the floor weight.
fn solve_directions(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<Vec<DVec3>> {
    let targets = targets(prior, correspondences)?;
    System::new(prior, correspondences, &targets).solve(0.0)
}

/// The least-squares system of one fit: the data term's normal matrix and the prior, in
/// unknowns scaled by the prior's mean projector length.
struct System<'a> {
    prior: &'a ProjectorGrid,
    /// The data term's normal matrix (3 rows per node).
    normal: DMatrix<f64>,
    /// The prior's node directions over `scale`.
    prior_dirs: DVector<f64>,
    /// The scale constraint's row: the prior over the constrained nodes, zero elsewhere.
    scale_row: DVector<f64>,
    /// The prior's mean projector length.
    scale: f64,
    /// The least prior weight: `PRIOR_WEIGHT` of the normal matrix's mean diagonal.
    floor: f64,
}

impl<'a> System<'a> {
    fn new(
        prior: &'a ProjectorGrid,
        correspondences: &[Correspondence],
        targets: &[DVec3],
    ) -> Self {
        let nodes = prior.starts().len();
        let dirs: Vec<DVec3> = prior
            .starts()
            .iter()
            .zip(prior.ends())
            .map(|(s, e)| *e - *s)
            .collect();
        let scale = dirs.iter().map(|d| d.length()).sum::<f64>() / nodes as f64;
        let n = 3 * nodes;
        let mut normal = DMatrix::<f64>::zeros(n, n);
        let mut weights = Vec::new();
        for (c, a) in correspondences.iter().zip(targets) {
            weights.clear();
            prior.for_each_weight(c.uv, |j, w| weights.push((j, w)));
            let p = projector_off(*a);
            for &(j, wj) in &weights {
                for &(l, wl) in &weights {
                    add_block(&mut normal, j, l, wj * wl, &p);
                }
            }
        }
        let constrained = constrained_nodes(prior, correspondences);
        let prior_dirs =
            DVector::from_iterator(n, dirs.iter().flat_map(|d| (*d / scale).to_array()));
        let scale_row = DVector::from_iterator(
            n,
            (0..n).map(|i| {
                if constrained[i / 3] {
                    prior_dirs[i]
                } else {
                    0.0
                }
            }),
        );
        let mean_diagonal = normal.trace() / n as f64;
        let floor = PRIOR_WEIGHT
            * if mean_diagonal > 0.0 {
                mean_diagonal
            } else {
                1.0
            };
        Self {
            prior,
            normal,
            prior_dirs,
            scale_row,
            scale,
            floor,
        }
    }

    /// The node directions minimising the data term plus `weight` (at least the floor) times
    /// the squared distance to the prior, under the scale constraint.
    fn solve(&self, weight: f64) -> Result<Vec<DVec3>> {
        let lambda = weight.max(self.floor);
        let mut matrix = self.normal.clone();
        for i in 0..matrix.nrows() {
            matrix[(i, i)] += lambda;
        }
        let factor = matrix.cholesky().ok_or_else(|| {
            Error::new("projector grid fit: the least-squares system is singular")
        })?;
        // The scale constraint g^T y = |g|^2 (g: the prior over the constrained nodes) through
        // a Lagrange multiplier: y = y_a + mu y_b with (A + lambda I) y_a = lambda y0 and
        // (A + lambda I) y_b = g.
        let mut solution = factor.solve(&(lambda * &self.prior_dirs));
        let wanted = self.scale_row.norm_squared();
        if wanted > 0.0 {
            let along = factor.solve(&self.scale_row);
            let mu = (wanted - self.scale_row.dot(&solution)) / self.scale_row.dot(&along);
            solution += mu * along;
        }
        let dirs: Vec<DVec3> = solution
            .as_slice()
            .chunks_exact(3)
            .map(|y| self.scale * DVec3::new(y[0], y[1], y[2]))
            .collect();
        if let Some(j) = dirs.iter().position(|d| d.length() <= 1e-12 * self.scale) {
            return Err(Error::new(format!(
                "projector grid fit: node ({}, {}) got a zero-length projector",
                j % self.prior.size().0,
                j / self.prior.size().0
            )));
        }
        Ok(dirs)
    }
}

/// The unit direction a_k from the start of each correspondence's projector to its point.
fn targets(prior: &ProjectorGrid, correspondences: &[Correspondence]) -> Result<Vec<DVec3>> {
    correspondences
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let inside = c.uv.cmpge(DVec2::ZERO).all() && c.uv.cmple(DVec2::ONE).all();
            if !inside || !c.point.is_finite() {
                return Err(Error::new(format!(
                    "correspondence {}: the image position must be in [0, 1] x [0, 1] and the \
                     point finite (got uv {} and point {})",
                    k + 1,
                    c.uv,
                    c.point
                )));
            }
            let (start, _) = prior.start_end(c.uv);
            (c.point - start).try_normalize().ok_or_else(|| {
                Error::new(format!(
                    "correspondence {}: the point {} is the start of its own projector",
                    k + 1,
                    c.point
                ))
            })
        })
        .collect()
}

/// I - a a^T for unit a, row-major.
fn projector_off(a: DVec3) -> [[f64; 3]; 3] {
    let mut p = [[0.0; 3]; 3];
    for (r, row) in p.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value = f64::from(u8::from(r == c)) - a[r] * a[c];
        }
    }
    p
}

/// normal[block (j, l)] += w * p.
fn add_block(normal: &mut DMatrix<f64>, j: usize, l: usize, w: f64, p: &[[f64; 3]; 3]) {
    for (r, row) in p.iter().enumerate() {
        for (c, value) in row.iter().enumerate() {
            normal[(3 * j + r, 3 * l + c)] += w * value;
        }
    }
}

fn with_directions(prior: &ProjectorGrid, dirs: &[DVec3]) -> Result<ProjectorGrid> {
    let ends = prior
        .starts()
        .iter()
        .zip(dirs)
        .map(|(s, d)| *s + *d)
        .collect();
    prior.with_ends(ends)
}

/// The largest projector parameter t at which a correspondence's point is reached (its
/// projection onto the fitted projector). Errors when a point is reached only at t <= 0.
fn farthest_reach(grid: &ProjectorGrid, correspondences: &[Correspondence]) -> Result<f64> {
    let mut reach = 0.0f64;
    for (k, c) in correspondences.iter().enumerate() {
        let (start, end) = grid.start_end(c.uv);
        let d = end - start;
        let t = (c.point - start).dot(d) / d.length_squared();
        if t.is_nan() || t <= 0.0 {
            return Err(Error::new(format!(
                "correspondence {}: no projector of the grid can reach {} at {} (the fitted \
                 projector points away from it; the correspondences contradict each other)",
                k + 1,
                c.point,
                c.uv
            )));
        }
        reach = reach.max(t);
    }
    Ok(reach)
}

fn residual(
    grid: &ProjectorGrid,
    correspondences: &[Correspondence],
    targets: &[DVec3],
    constrained: &[bool],
) -> FitReport {
    let angles: Vec<f64> = correspondences
        .iter()
        .zip(targets)
        .map(|(c, a)| {
            let d = grid.tangent(c.uv, 0.0).normalize();
            // atan2 of |cross| and dot: accurate for tiny angles, unlike acos.
            d.cross(*a).length().atan2(d.dot(*a)).to_degrees()
        })
        .collect();
    let count = angles.len();
    FitReport {
        correspondences: count,
        unconstrained_nodes: constrained.iter().filter(|c| !**c).count(),
        max_angle_deg: angles.iter().copied().fold(0.0, f64::max),
        rms_angle_deg: if count == 0 {
            0.0
        } else {
            (angles.iter().map(|a| a * a).sum::<f64>() / count as f64).sqrt()
        },
        ..FitReport::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::flexible::presets::Preset;
    use crate::projection::flexible::projector_grid::tests::perspective_volume as perspective;
    use crate::projection::flexible::projector_grid::tests::preset_volume;
    use crate::projection::flexible::projector_grid::GridInterpolation;
    use crate::projection::flexible::volume::LinearVolume;
    use crate::projection::projector::quadratic_point;
    use proptest::prelude::*;

    /// Correspondences seen by `truth`: one per cell of a `per_side x per_side` jittered
    /// grid of image positions (so every region of the image has data), each on its projector
    /// at a depth t in (0.05, 0.9).
    fn correspondences_of(
        truth: &ProjectorGrid,
        per_side: usize,
        seed: u64,
    ) -> Vec<Correspondence> {
        correspondences_from(|uv, t| truth.point(uv, t), per_side, seed)
    }

    /// [`correspondences_of`] any volume, given as Q(u, v, t).
    fn correspondences_from(
        volume: impl Fn(DVec2, f64) -> DVec3,
        per_side: usize,
        seed: u64,
    ) -> Vec<Correspondence> {
        let mut next = uniform(seed);
        let n = per_side as f64;
        let mut out = Vec::new();
        for i in 0..per_side {
            for j in 0..per_side {
                let uv = DVec2::new((i as f64 + next()) / n, (j as f64 + next()) / n);
                let t = 0.05 + 0.85 * next();
                out.push(Correspondence {
                    uv,
                    point: volume(uv, t),
                });
            }
        }
        out
    }

    /// Deterministic uniform numbers in [0, 1) from `seed` (SplitMix64).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            (z ^ (z >> 31)) as f64 / u64::MAX as f64
        }
    }

    /// The largest angle, in radians, between the two grids' projectors over a grid of (u, v).
    fn max_direction_error(a: &ProjectorGrid, b: &ProjectorGrid) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..=16 {
            for j in 0..=16 {
                let uv = DVec2::new(f64::from(i), f64::from(j)) / 16.0;
                let (da, db) = (
                    a.tangent(uv, 0.0).normalize(),
                    b.tangent(uv, 0.0).normalize(),
                );
                worst = worst.max(da.cross(db).length().atan2(da.dot(db)));
            }
        }
        worst
    }

    #[test]
    fn recovers_a_perspective_camera_from_a_different_prior() {
        let bilinear = GridInterpolation::Bilinear;
        let truth =
            ProjectorGrid::sample(&perspective(50.0, [1.0, 40.0]), (5, 5), bilinear).unwrap();
        // The prior: the truth's image plane with the directions of a much wider camera.
        let wide =
            ProjectorGrid::sample(&perspective(100.0, [1.0, 300.0]), (5, 5), bilinear).unwrap();
        let prior = truth.with_ends(
            truth
                .starts()
                .iter()
                .zip(wide.ends())
                .map(|(s, e)| *s + (*e - *s))
                .collect(),
        );
        let prior = prior.unwrap();
        assert!(
            max_direction_error(&prior, &truth) > 0.2,
            "the prior is far off"
        );
        let data = correspondences_of(&truth, 12, 7);
        let (fitted, report) = fit(&prior, &data).unwrap();
        assert_eq!(
            (report.correspondences, report.unconstrained_nodes),
            (144, 0)
        );
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(max_direction_error(&fitted, &truth) < 1e-7);
        // Every point is in view: reached at t in (0, 1].
        let reach = farthest_reach(&fitted, &data).unwrap();
        assert!(reach > 0.0 && reach <= 1.0, "{reach}");
    }

    /// Fits a 5 x 5 bilinear grid to `per_side`^2 correspondences seen by `truth` (a volume
    /// whose surfaces are bilinear in (u, v), so that the grid can be it exactly), from a prior
    /// with the truth's starts and a 90-degree perspective camera's directions; returns the
    /// largest angle, in radians, between a fitted projector and the truth's over a 17 x 17
    /// grid of (u, v), and the fit's residual.
    fn recover(truth: &LinearVolume, per_side: usize, seed: u64) -> (f64, FitReport) {
        let bilinear = GridInterpolation::Bilinear;
        let sampled = ProjectorGrid::sample(truth, (5, 5), bilinear).unwrap();
        let other =
            ProjectorGrid::sample(&perspective(90.0, [1.0, 40.0]), (5, 5), bilinear).unwrap();
        let prior = sampled
            .with_ends(
                (sampled.starts().iter())
                    .zip(other.starts().iter().zip(other.ends()))
                    .map(|(s, (os, oe))| *s + (*oe - *os))
                    .collect(),
            )
            .unwrap();
        let data = correspondences_from(|uv, t| truth.point(uv, t), per_side, seed);
        let (fitted, report) = fit(&prior, &data).unwrap();
        let mut worst = 0.0f64;
        for i in 0..=16 {
            for j in 0..=16 {
                let uv = DVec2::new(f64::from(i), f64::from(j)) / 16.0;
                let (a, b) = (
                    fitted.tangent(uv, 0.0).normalize(),
                    truth.tangent(uv).normalize(),
                );
                worst = worst.max(a.cross(b).length().atan2(a.dot(b)));
            }
        }
        (worst, report)
    }

    #[test]
    fn recovers_pushbroom_and_crossed_slits_cameras_from_their_own_correspondences() {
        // Neither has a single centre of projection, and both have near and far rectangles:
        // bilinear in (u, v), so a bilinear grid is each exactly.
        let pushbroom = Preset::Pushbroom {
            width: 6.0,
            v_fov: 50.0,
        };
        let crossed_slits = Preset::CrossedSlits {
            fov: 60.0,
            v_fov: None,
            slit_distance: -2.0,
        };
        for preset in [pushbroom, crossed_slits] {
            let truth = preset_volume(preset.clone(), [1.0, 30.0]);
            let (error, report) = recover(&truth, 12, 5);
            assert!(error < 1e-7, "{preset:?}: {error} rad");
            assert!(report.max_angle_deg < 1e-6, "{preset:?}: {report:?}");
        }
    }

    #[test]
    fn recovers_a_curved_bezier_grid_from_its_own_correspondences() {
        let bezier = GridInterpolation::Bezier;
        let base = ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bezier).unwrap();
        // A known non-perspective projection: every node direction bent differently.
        let ends = base
            .ends()
            .iter()
            .enumerate()
            .map(|(j, e)| {
                *e + DVec3::new((j as f64 * 0.7).sin(), (j as f64 * 1.3).cos(), 0.0) * 4.0
            })
            .collect();
        let truth = base.with_ends(ends).unwrap();
        let data = correspondences_of(&truth, 12, 11);
        let (fitted, report) = fit(&base, &data).unwrap();
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(max_direction_error(&fitted, &truth) < 1e-7);
    }

    #[test]
    fn nodes_without_data_keep_the_prior_and_no_data_changes_nothing() {
        let bilinear = GridInterpolation::Bilinear;
        let prior =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (3, 3), bilinear).unwrap();
        let (same, report) = fit(&prior, &[]).unwrap();
        assert_eq!(report.unconstrained_nodes, 9);
        for (a, b) in same.ends().iter().zip(prior.ends()) {
            assert!((*a - *b).length() < 1e-9 * b.length());
        }
        // Points in the bottom-left cell only: the top-right node is never weighted.
        let uv = DVec2::new(0.2, 0.3);
        let (start, end) = prior.start_end(uv);
        let point = start + 0.5 * (end - start) + DVec3::new(2.0, 0.0, 0.0);
        let (fitted, report) = fit(&prior, &[Correspondence { uv, point }]).unwrap();
        assert_eq!(report.unconstrained_nodes, 5);
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        let top_right = 8;
        let (pd, fd) = (
            prior.ends()[top_right] - prior.starts()[top_right],
            fitted.ends()[top_right] - fitted.starts()[top_right],
        );
        assert!(pd.normalize().dot(fd.normalize()) > 1.0 - 1e-12);
    }

    #[test]
    fn noisy_correspondences_leave_a_reported_residual() {
        let bilinear = GridInterpolation::Bilinear;
        let truth =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bilinear).unwrap();
        let mut data = correspondences_of(&truth, 20, 3);
        for (k, c) in data.iter_mut().enumerate() {
            // Alternating sideways offsets: no grid meets them all.
            let side = if k % 2 == 0 { 0.05 } else { -0.05 };
            c.point += DVec3::new(side, -side, 0.0);
        }
        let (fitted, report) = fit(&truth, &data).unwrap();
        assert!(report.rms_angle_deg > 1e-3, "{report:?}");
        assert!(report.max_angle_deg < 5.0, "{report:?}");
        assert!(max_direction_error(&fitted, &truth) < 0.02);

        // Noisy data over the bottom-left quarter only, from a prior that is far off: the
        // covered cells follow the data, and the fitted node projectors keep lengths like the
        // prior's (a fit that let noisy solutions shrink towards zero would leave them
        // vanishingly short next to the unconstrained prior nodes, so that the cells between
        // the two regions would take the prior's directions).
        let wide =
            ProjectorGrid::sample(&perspective(100.0, [1.0, 300.0]), (5, 5), bilinear).unwrap();
        let prior = truth
            .with_ends(
                (truth
                    .starts()
                    .iter()
                    .zip(wide.starts().iter().zip(wide.ends())))
                .map(|(s, (ws, we))| *s + (*we - *ws))
                .collect(),
            )
            .unwrap();
        let quarter: Vec<_> = data
            .into_iter()
            .filter(|c| c.uv.x < 0.5 && c.uv.y < 0.5)
            .collect();
        let (fitted, report) = fit(&prior, &quarter).unwrap();
        assert_eq!(report.unconstrained_nodes, 25 - 9);
        for uv in [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.3, 0.2),
            DVec2::new(0.2, 0.4),
        ] {
            let (a, b) = (
                fitted.tangent(uv, 0.0).normalize(),
                truth.tangent(uv, 0.0).normalize(),
            );
            assert!(a.dot(b) > (0.02f64).cos(), "{uv}: {a} vs {b}");
        }
        for j in [0, 1, 2, 5, 6, 7, 10, 11, 12] {
            let fitted_length = (fitted.ends()[j] - fitted.starts()[j]).length();
            let prior_length = (prior.ends()[j] - prior.starts()[j]).length();
            let ratio = fitted_length / prior_length;
            assert!(
                (0.3..3.0).contains(&ratio),
                "node {j}: length ratio {ratio}"
            );
        }
    }

    #[test]
    fn bad_correspondences_are_named() {
        let bilinear = GridInterpolation::Bilinear;
        let prior =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (3, 3), bilinear).unwrap();
        let ok = Correspondence {
            uv: DVec2::splat(0.5),
            point: prior.point(DVec2::splat(0.5), 0.5),
        };
        for bad in [
            Correspondence {
                uv: DVec2::new(1.5, 0.5),
                ..ok
            },
            Correspondence {
                uv: DVec2::new(f64::NAN, 0.5),
                ..ok
            },
            Correspondence {
                point: DVec3::INFINITY,
                ..ok
            },
        ] {
            let e = fit(&prior, &[ok, bad]).unwrap_err();
            assert!(
                e.message
                    .starts_with("correspondence 2: the image position"),
                "{e}"
            );
        }
        let at_start = Correspondence {
            point: prior.point(ok.uv, 0.0),
            ..ok
        };
        let e = fit(&prior, &[at_start]).unwrap_err();
        assert!(
            e.message.contains("is the start of its own projector"),
            "{e}"
        );
        // The same image position asked to see a point behind the image plane as well as one
        // in front: the fitted projector cannot point both ways.
        let behind = Correspondence {
            point: prior.point(ok.uv, -0.5),
            ..ok
        };
        let e = fit(&prior, &[ok, behind, behind]).unwrap_err();
        assert!(e.message.contains("points away from it"), "{e}");
    }

    /// A 5 x 5 grid of `interpolation` sampled from a 60-degree perspective camera, then every
    /// node's end turned by up to about 6 degrees (its length kept) and its projector curved:
    /// it leaves its
    /// start at 60 to 100 % of `bend` radians off its chord, turned about the chord by a
    /// random angle (seeded).
    fn curved_truth(interpolation: GridInterpolation, bend: f64, seed: u64) -> ProjectorGrid {
        let base =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), interpolation).unwrap();
        let mut next = uniform(seed);
        let mut grid = base.clone();
        for j in 0..25 {
            let start = base.starts()[j];
            let length = (base.ends()[j] - start).length();
            let turned = (base.ends()[j] - start) / length
                + 0.2 * (DVec3::new(next(), next(), next()) - 0.5);
            let chord = turned.normalize();
            let end = start + length * chord;
            let (a, b) = chord.any_orthonormal_pair();
            let (turn, off) = (std::f64::consts::TAU * next(), bend * (0.6 + 0.4 * next()));
            let tangent = off.cos() * chord + off.sin() * (turn.cos() * a + turn.sin() * b);
            grid.set_projector((j % 5, j / 5), start, end, Some(tangent))
                .unwrap();
        }
        grid
    }

    /// Fits `truth` (curved) from `per_side`^2 of its own correspondences, starting from the
    /// straight 60-degree perspective grid with one tangent (which marks it as curved).
    /// Returns the fit's report and [`max_node_errors`].
    fn recover_curved(
        truth: &ProjectorGrid,
        per_side: usize,
        seed: u64,
    ) -> Result<(FitReport, [f64; 4])> {
        let interpolation = truth.interpolation();
        let mut prior =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), interpolation).unwrap();
        let (s, e) = (prior.starts()[12], prior.ends()[12]);
        prior.set_projector((2, 2), s, e, Some(DVec3::X)).unwrap();
        let data = correspondences_of(truth, per_side, seed);
        let (fitted, report) = fit(&prior, &data)?;
        Ok((report, max_node_errors(&fitted, truth)))
    }

    /// `grid` with every node's projector lengthened by its own random factor in `factors`
    /// (seeded), its start, direction and tangent kept: the grid of a camera with other clip
    /// distances, node by node.
    fn with_random_lengths(
        grid: &ProjectorGrid,
        factors: std::ops::Range<f64>,
        seed: u64,
    ) -> ProjectorGrid {
        let mut next = uniform(seed);
        let mut out = grid.clone();
        let cols = grid.size().0;
        for (j, (start, end)) in grid.starts().iter().zip(grid.ends()).enumerate() {
            let factor = factors.start + (factors.end - factors.start) * next();
            let end = *start + factor * (*end - *start);
            out.set_projector((j % cols, j / cols), *start, end, grid.tangents()[j])
                .unwrap();
        }
        out
    }

    /// The random curved grid of `seed` of the length tests: bent 0.03 to 0.43 rad, every
    /// node's length 0.5 to 3 times the prior's.
    fn random_curved_truth(interpolation: GridInterpolation, seed: u64) -> ProjectorGrid {
        let bend = 0.03 + 0.4 * uniform(1000 + seed)();
        let truth = curved_truth(interpolation, bend, seed);
        with_random_lengths(&truth, 0.5..3.0, 2000 + seed)
    }

    /// The largest relative error of a node end of `fitted` against `truth` (over the
    /// node's projector length), of a node tangent (radians; a straight node's tangent is its
    /// chord), of Q(u, v, t) over a 17 x 17 x 5 sample (over the projector length there) and
    /// of a node's length (relative).
    fn max_node_errors(fitted: &ProjectorGrid, truth: &ProjectorGrid) -> [f64; 4] {
        let mut worst = [0.0f64; 4];
        for j in 0..25 {
            let (start, end) = (truth.starts()[j], truth.ends()[j]);
            let length = (end - start).length();
            worst[0] = worst[0].max((fitted.ends()[j] - end).length() / length);
            let fitted_length = (fitted.ends()[j] - fitted.starts()[j]).length();
            worst[3] = worst[3].max((fitted_length / length - 1.0).abs());
            let chord = (fitted.ends()[j] - fitted.starts()[j]).normalize();
            let truth_chord = (end - start).normalize();
            let (a, b) = (
                fitted.tangents()[j].unwrap_or(chord),
                truth.tangents()[j].unwrap_or(truth_chord),
            );
            worst[1] = worst[1].max(a.cross(b).length().atan2(a.dot(b)));
        }
        for i in 0..=16 {
            for k in 0..=16 {
                let uv = DVec2::new(f64::from(i), f64::from(k)) / 16.0;
                let (start, end) = truth.start_end(uv);
                for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
                    let gap = (fitted.point(uv, t) - truth.point(uv, t)).length();
                    worst[2] = worst[2].max(gap / (end - start).length());
                }
            }
        }
        worst
    }

    #[test]
    fn recovers_curved_projector_grids_from_their_own_correspondences() {
        // One grid, with tight bounds (random ones, with random lengths:
        // recovers_random_bilinear_curved_grids_with_their_own_lengths).
        let truth = curved_truth(GridInterpolation::Bilinear, 0.3, 3);
        let (report, [end, tangent, point, _]) = recover_curved(&truth, 12, 13).unwrap();
        eprintln!("{report:?}, errors end {end:e}, tangent {tangent:e} rad, Q {point:e}");
        assert_eq!(
            (report.correspondences, report.unconstrained_nodes),
            (144, 0)
        );
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(end < 1e-7, "end error {end}");
        assert!(tangent < 1e-7, "tangent error {tangent} rad");
        assert!(point < 1e-7, "Q error {point}");
    }

    /// Moves every point of `data` sideways, off the line from its projector's start in
    /// `grid`, by up to `sigma` radians in each of two perpendicular directions (seeded).
    fn with_noise(
        grid: &ProjectorGrid,
        data: &[Correspondence],
        sigma: f64,
        seed: u64,
    ) -> Vec<Correspondence> {
        let mut next = uniform(seed);
        data.iter()
            .map(|c| {
                let (start, _) = grid.start_end(c.uv);
                let (a, b) = (c.point - start).normalize().any_orthonormal_pair();
                let off = sigma * (c.point - start).length();
                let (x, y) = (2.0 * next() - 1.0, 2.0 * next() - 1.0);
                Correspondence {
                    point: c.point + off * (x * a + y * b),
                    ..*c
                }
            })
            .collect()
    }

    #[test]
    fn recovers_random_straight_grids_and_reports_noise() {
        // 24 random grids of each interpolation (every node's end turned up to about 6
        // degrees), fitted from the untouched 60-degree camera: all recovered from exact
        // data. Noise is checked here on bilinear grids (Bezier grids with noise:
        // noisy_bezier_fits_stay_near_their_grid).
        let sigma: f64 = 1e-3;
        for interpolation in [GridInterpolation::Bilinear, GridInterpolation::Bezier] {
            let prior =
                ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), interpolation)
                    .unwrap();
            let (mut exact_worst, mut noisy_worst) = (0.0f64, 0.0f64);
            let mut rms_range = (f64::INFINITY, 0.0f64);
            for seed in 0..24 {
                let truth = curved_truth(interpolation, 0.0, seed).straightened();
                let data = correspondences_of(&truth, 12, 200 + seed);
                let (fitted, report) = fit(&prior, &data).unwrap();
                assert!(report.max_angle_deg < 1e-6, "seed {seed}: {report:?}");
                exact_worst = exact_worst.max(max_direction_error(&fitted, &truth));
                if interpolation == GridInterpolation::Bezier {
                    continue;
                }
                // Noise: a residual of about its size is reported, no error.
                let noisy = with_noise(&truth, &data, sigma, 300 + seed);
                let (fitted, report) = fit(&prior, &noisy).unwrap();
                noisy_worst = noisy_worst.max(max_direction_error(&fitted, &truth));
                let rms = report.rms_angle_deg.to_radians();
                rms_range = (rms_range.0.min(rms), rms_range.1.max(rms));
            }
            eprintln!("{interpolation:?}: exact {exact_worst:e} rad");
            assert!(exact_worst < 1e-7, "{interpolation:?}: {exact_worst}");
            if interpolation == GridInterpolation::Bezier {
                continue;
            }
            eprintln!(
                "noise {sigma}: direction error {noisy_worst:e} rad, rms residual {rms_range:?} rad"
            );
            // Noise of up to sigma per axis has an rms angle of sigma * sqrt(2 / 3); the fit
            // absorbs a part of it (75 unknowns for 288 equations).
            assert!(
                rms_range.0 > 0.4 * sigma && rms_range.1 < sigma,
                "{interpolation:?}: {rms_range:?}"
            );
            assert!(
                noisy_worst < 10.0 * sigma,
                "{interpolation:?}: {noisy_worst}"
            );
        }
    }

    #[test]
    fn noisy_bezier_fits_stay_near_their_grid() {
        // 24 random straight Bezier grids, each fitted from 64 and from 144 correspondences
        // with 1e-3 rad of noise, from the untouched 60-degree camera: every fit succeeds,
        // its rms residual is about the noise's, and its projectors stay near the truth's
        // over the whole image (figures: docs/flexible.md).
        let sigma: f64 = 1e-3;
        let bezier = GridInterpolation::Bezier;
        let prior = ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bezier).unwrap();
        for per_side in [8, 12] {
            let mut worst = 0.0f64;
            let mut rms_range = (f64::INFINITY, 0.0f64);
            let mut refused = 0;
            for seed in 0..24 {
                let truth = curved_truth(bezier, 0.0, seed).straightened();
                let data = correspondences_of(&truth, per_side, 200 + seed);
                let noisy = with_noise(&truth, &data, sigma, 300 + seed);
                let (fitted, report) = match fit(&prior, &noisy) {
                    Ok(fit) => fit,
                    Err(e) => {
                        eprintln!("{per_side}^2 seed {seed}: {e}");
                        refused += 1;
                        continue;
                    }
                };
                worst = worst.max(max_direction_error(&fitted, &truth));
                let rms = report.rms_angle_deg.to_radians();
                rms_range = (rms_range.0.min(rms), rms_range.1.max(rms));
            }
            eprintln!(
                "{per_side}^2 points, noise {sigma}: {refused} refused, direction error \
                 {worst:e} rad, rms residual {rms_range:?} rad"
            );
            assert_eq!(refused, 0, "{per_side}^2");
            assert!(
                rms_range.0 > 0.3 * sigma && rms_range.1 < sigma,
                "{per_side}^2: {rms_range:?}"
            );
            assert!(worst < 0.08, "{per_side}^2: {worst}");
        }
    }

    /// [`noise_weight`] of `data` for `prior`, from the floor-weighted solve that [`fit`]
    /// makes first.
    fn noise_weight_of(prior: &ProjectorGrid, data: &[Correspondence]) -> Result<Option<f64>> {
        let targets = targets(prior, data)?;
        let system = System::new(prior, data, &targets);
        let floor_dirs = system.solve(0.0)?;
        Ok(noise_weight(&system, data, &targets, &floor_dirs))
    }

    #[test]
    fn the_noise_weight_follows_the_data() {
        let bezier = GridInterpolation::Bezier;
        let prior = ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bezier).unwrap();
        let truth = curved_truth(bezier, 0.0, 3).straightened();
        let data = correspondences_of(&truth, 12, 5);
        // No noise: no noise weight (exact data take the exact path).
        assert_eq!(noise_weight_of(&prior, &data).unwrap(), None);
        let noisy = with_noise(&truth, &data, 1e-3, 6);
        // Too few points: 37 give 75 equations for 75 unknowns, met exactly.
        assert_eq!(noise_weight_of(&prior, &noisy[..37]).unwrap(), None);
        // Uniform noise of up to 1e-3 on each of two axes: variance 1e-6 / 3 per equation.
        let weight = noise_weight_of(&prior, &noisy).unwrap().unwrap();
        assert!((1e-7..1e-6).contains(&weight), "{weight}");

        // All noisy points in the bottom-left cell of a bilinear grid: that cell follows
        // them, the 21 other nodes keep the prior's directions.
        let bilinear = GridInterpolation::Bilinear;
        let grid =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bilinear).unwrap();
        let cell: Vec<_> = correspondences_from(|uv, t| grid.point(0.25 * uv, t), 6, 8)
            .into_iter()
            .map(|c| Correspondence {
                uv: 0.25 * c.uv,
                ..c
            })
            .collect();
        let cell = with_noise(&grid, &cell, 1e-3, 9);
        assert!(noise_weight_of(&grid, &cell).unwrap().is_some());
        let (fitted, report) = fit(&grid, &cell).unwrap();
        assert_eq!(report.unconstrained_nodes, 21);
        assert!(report.rms_angle_deg.to_radians() < 1e-3, "{report:?}");
        assert!(max_direction_error(&fitted, &grid) < 0.08);
        let (pd, fd) = (
            grid.ends()[24] - grid.starts()[24],
            fitted.ends()[24] - fitted.starts()[24],
        );
        assert!(pd.normalize().dot(fd.normalize()) > 1.0 - 1e-12);
    }

    #[test]
    fn a_point_behind_the_image_plane_is_named() {
        // 144 exact correspondences and one more whose point lies behind its projector's
        // start (t = -0.5): straight and curved fits refuse it by number.
        let curved = curved_truth(GridInterpolation::Bilinear, 0.3, 3);
        for truth in [curved.straightened(), curved] {
            let mut data = correspondences_of(&truth, 12, 13);
            let uv = DVec2::new(0.4, 0.7);
            let (start, end) = truth.start_end(uv);
            data.push(Correspondence {
                uv,
                point: start - 0.5 * (end - start),
            });
            let e = fit(&truth, &data).unwrap_err();
            assert!(e.message.starts_with("correspondence 145: "), "{e}");
        }
    }

    #[test]
    fn curved_fits_with_too_few_or_uninformative_correspondences_are_refused() {
        let truth = curved_truth(GridInterpolation::Bilinear, 0.3, 7);
        let mut prior = ProjectorGrid::sample(
            &perspective(60.0, [1.0, 30.0]),
            (5, 5),
            truth.interpolation(),
        )
        .unwrap();
        let (s, e) = (prior.starts()[12], prior.ends()[12]);
        prior.set_projector((2, 2), s, e, Some(DVec3::X)).unwrap();
        // 25 nodes need 50 correspondences.
        let few = correspondences_of(&truth, 7, 1);
        let e = fit(&prior, &few).unwrap_err();
        assert!(
            e.message.contains("need at least 50 correspondences"),
            "{e}"
        );
        assert!(e.message.contains("got 49, add 1 more"), "{e}");
        // Points at the node positions only (each weights one node): three depths along
        // every node's projector determine it, three copies of one point do not (a curve
        // through one point can leave its start in any direction near it).
        let at_nodes = |depths: [f64; 3]| -> Vec<Correspondence> {
            (0..25)
                .flat_map(|j| {
                    let uv = truth.node_uv(j % 5, j / 5);
                    depths.map(|t| Correspondence {
                        uv,
                        point: truth.point(uv, t),
                    })
                })
                .collect()
        };
        let (fitted, report) = fit(&prior, &at_nodes([0.25, 0.55, 0.85])).unwrap();
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(max_node_errors(&fitted, &truth).iter().all(|e| *e < 1e-7));
        let mut one_depth = at_nodes([0.25, 0.55, 0.85]);
        let j = 3 * 17;
        one_depth[j + 1] = one_depth[j];
        one_depth[j + 2] = one_depth[j];
        let e = fit(&prior, &one_depth).unwrap_err();
        assert!(
            e.message
                .contains("do not determine the end and tangent of node (2, 3)"),
            "{e}"
        );
    }

    /// Fits random curved grids of `interpolation` (seeds `seeds`; bend 0.03 to 0.43 rad,
    /// every node's length 0.5 to 3 times the prior's, 144 exact correspondences) and checks
    /// that every fit either recovers its grid (every error of [`max_node_errors`] below
    /// `tolerance`) or reports a residual above 1e-3 degrees (a wrong local minimum is never
    /// silent); returns how many were recovered.
    fn recover_random_curved(
        interpolation: GridInterpolation,
        seeds: std::ops::Range<u64>,
        tolerance: f64,
    ) -> usize {
        let mut recovered = 0;
        let mut worst = [0.0f64; 4];
        for seed in seeds {
            let truth = random_curved_truth(interpolation, seed);
            match recover_curved(&truth, 12, 100 + seed) {
                Ok((report, errors)) if errors.iter().all(|e| *e < tolerance) => {
                    eprintln!("{interpolation:?} seed {seed}: {report:?} {errors:?}");
                    recovered += 1;
                    for (w, e) in worst.iter_mut().zip(errors) {
                        *w = w.max(e);
                    }
                }
                Ok((report, errors)) => {
                    eprintln!("{interpolation:?} seed {seed} missed: {report:?} {errors:?}");
                    assert!(
                        report.max_angle_deg > 1e-3,
                        "{interpolation:?} seed {seed}: {report:?} {errors:?}"
                    );
                }
                Err(e) => eprintln!("{interpolation:?} seed {seed}: {e}"),
            }
        }
        eprintln!(
            "{interpolation:?}: {recovered} recovered, worst end {:e}, tangent {:e} rad, Q {:e}, \
             length {:e}",
            worst[0], worst[1], worst[2], worst[3]
        );
        recovered
    }

    #[test]
    fn recovers_random_bilinear_curved_grids_with_their_own_lengths() {
        // The counts are the measured ones (docs/flexible.md).
        let bilinear = GridInterpolation::Bilinear;
        assert_eq!(recover_random_curved(bilinear, 0..24, 1e-7), 23);
    }

    #[test]
    fn recovers_random_bezier_curved_grids_with_their_own_lengths() {
        let bezier = GridInterpolation::Bezier;
        // Every point weights every node of a Bezier patch, and a weakly bent node's length
        // is weakly determined: recovered to 1e-6 (figures: docs/flexible.md).
        assert_eq!(recover_random_curved(bezier, 0..16, 1e-6), 15);
    }

    #[test]
    fn open_lengths_keep_the_prior_length() {
        let bilinear = GridInterpolation::Bilinear;
        let mut prior =
            ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), bilinear).unwrap();
        let (s, e) = (prior.starts()[12], prior.ends()[12]);
        prior.set_projector((2, 2), s, e, Some(DVec3::X)).unwrap();
        let length = |g: &ProjectorGrid, j: usize| (g.ends()[j] - g.starts()[j]).length();

        // Points at the node positions only (each weights one node), three depths per node:
        // a curved node's length is fixed by them, a straight node (1, 3) can slide along
        // itself and keeps the prior's length.
        let mut truth = with_random_lengths(&curved_truth(bilinear, 0.3, 5), 0.5..3.0, 7);
        let j = 3 * 5 + 1;
        let (start, end) = (
            truth.starts()[j],
            truth.starts()[j] + 0.6 * (prior.ends()[j] - prior.starts()[j]),
        );
        truth.set_projector((1, 3), start, end, None).unwrap();
        let at_nodes: Vec<Correspondence> = (0..25)
            .flat_map(|j| {
                let uv = truth.node_uv(j % 5, j / 5);
                [0.25, 0.55, 0.85].map(|t| Correspondence {
                    uv,
                    point: truth.point(uv, t),
                })
            })
            .collect();
        let (fitted, report) = fit(&prior, &at_nodes).unwrap();
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!((length(&fitted, j) / length(&prior, j) - 1.0).abs() < 1e-14);
        let direction = |g: &ProjectorGrid| (g.ends()[j] - g.starts()[j]).normalize();
        assert!(direction(&fitted).angle_between(direction(&truth)) < 1e-7);
        for other in (0..25).filter(|k| *k != j) {
            let error =
                (fitted.ends()[other] - truth.ends()[other]).length() / length(&truth, other);
            assert!(error < 1e-7, "node {other}: end error {error}");
        }

        // A straight grid seen through a curved prior: the directions and the lengths'
        // ratios are fixed by the blended points, their common scale is not (it only
        // rescales the depths), so one length keeps the prior's and the rest follow it. (The
        // truth's projectors are shorter than the prior's, so that every point stays in view
        // at the prior's scale: a fit started shorter than its points stretches until its
        // farthest point is at t = 1, where the bound, not the prior, fixes the scale.)
        let straight = with_random_lengths(&curved_truth(bilinear, 0.0, 9), 0.3..0.9, 11);
        assert!(!straight.is_curved());
        let (fitted, report) = fit(&prior, &correspondences_of(&straight, 12, 13)).unwrap();
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(max_direction_error(&fitted, &straight) < 1e-7);
        let ratios: Vec<f64> = (0..25)
            .map(|j| length(&fitted, j) / length(&straight, j))
            .collect();
        for r in &ratios {
            assert!((r / ratios[0] - 1.0).abs() < 1e-7, "{ratios:?}");
        }
        let kept = (0..25)
            .filter(|j| (length(&fitted, *j) / length(&prior, *j) - 1.0).abs() < 1e-14)
            .count();
        assert_eq!(kept, 1, "{ratios:?}");
    }

    /// The largest angle, seen from the fitted projector's start, between a scene point of
    /// `truth` (over a 17 x 17 grid of (u, v) at depths 0.25, 0.5, 0.75) and the nearest point
    /// of `fitted`'s projector of the same (u, v): how far off the fitted grid sees the
    /// truth's scene, whatever its depths (a length off along a barely bent curve moves the
    /// depths, not what is seen).
    fn max_sight_error(fitted: &ProjectorGrid, truth: &ProjectorGrid) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..=16 {
            for k in 0..=16 {
                let uv = DVec2::new(f64::from(i), f64::from(k)) / 16.0;
                let p = fitted.control_points(uv);
                for t in [0.25, 0.5, 0.75] {
                    let x = truth.point(uv, t);
                    let on = quadratic_point(&p, curved::closest_depth(&p, x));
                    worst = worst.max((x - on).length().atan2((x - p[0]).length()));
                }
            }
        }
        worst
    }

    #[test]
    fn noisy_curved_fits_stay_near_their_grid() {
        // Random curved grids (as in recover_random_curved) seen with 1e-3 rad of noise per
        // axis, from 144 correspondences: each fit either sees the truth's scene to within
        // `bound` rad ([`max_sight_error`]; the bounds are about 1.3 times the measured worst,
        // the Bezier patch's edge amplifying noise as in the straight fit), with an rms
        // residual about the noise's, or is refused with an error (figures:
        // docs/flexible.md). The node lengths themselves are poorly determined by noisy data
        // (off by up to 37 % on bilinear grids here): a weakly bent curve barely changes shape
        // when its end slides along it.
        let sigma: f64 = 1e-3;
        for (interpolation, seeds, bound) in [
            (GridInterpolation::Bilinear, 0..8, 0.015),
            (GridInterpolation::Bezier, 0..4, 0.1),
        ] {
            let mut worst = [0.0f64; 4];
            let mut rms_range = (f64::INFINITY, 0.0f64);
            let mut refused = 0;
            let mut worst_sight = 0.0f64;
            for seed in seeds {
                let truth = random_curved_truth(interpolation, seed);
                let data = correspondences_of(&truth, 12, 100 + seed);
                let noisy = with_noise(&truth, &data, sigma, 300 + seed);
                let mut prior =
                    ProjectorGrid::sample(&perspective(60.0, [1.0, 30.0]), (5, 5), interpolation)
                        .unwrap();
                let (s, e) = (prior.starts()[12], prior.ends()[12]);
                prior.set_projector((2, 2), s, e, Some(DVec3::X)).unwrap();
                let (fitted, report) = match fit(&prior, &noisy) {
                    Ok(fit) => fit,
                    Err(e) => {
                        eprintln!("{interpolation:?} seed {seed}: {e}");
                        refused += 1;
                        continue;
                    }
                };
                let errors = max_node_errors(&fitted, &truth);
                let sight = max_sight_error(&fitted, &truth);
                eprintln!("{interpolation:?} seed {seed}: {report:?} {errors:?} sight {sight:e}");
                worst_sight = worst_sight.max(sight);
                for (w, e) in worst.iter_mut().zip(errors) {
                    *w = w.max(e);
                }
                let rms = report.rms_angle_deg.to_radians();
                rms_range = (rms_range.0.min(rms), rms_range.1.max(rms));
            }
            eprintln!(
                "{interpolation:?} noise {sigma}: {refused} refused, sight {worst_sight:e} rad, \
                 worst end {:e}, tangent {:e} rad, Q {:e}, length {:e}; rms residual \
                 {rms_range:?} rad",
                worst[0], worst[1], worst[2], worst[3]
            );
            assert!(rms_range.1 < sigma, "{interpolation:?}: {rms_range:?}");
            assert!(worst_sight < bound, "{interpolation:?}: {worst_sight}");
        }
    }

    /// The example scene's 25 correspondences of a known curved 3 x 3 grid: the fit meets
    /// them and recovers the grid's tangents.
    #[test]
    fn the_curved_fit_example_recovers_its_grid() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/flexible-projector-fit-curved.toml"
        );
        let scene = crate::scene::load(path).unwrap();
        let crate::projection::ProjectionSpec::Flexible(spec) = &scene.projection else {
            panic!("not flexible");
        };
        let flexible = crate::projection::flexible::Flexible::new(spec, 32, 24).unwrap();
        let crate::projection::flexible::Volume::Grid(grid) = flexible.volume() else {
            panic!("not a grid");
        };
        let report = grid.fit.unwrap();
        eprintln!("{report:?}");
        assert!(report.max_angle_deg < 1e-5, "{report:?}");
        let known = [
            (6, DVec3::new(-0.47, -0.35, -0.86)),
            (7, DVec3::new(0.0, -0.37, -0.98)),
            (8, DVec3::new(0.47, -0.35, -0.86)),
            (4, DVec3::new(0.15, -0.59, -0.81)),
        ];
        for (j, tangent) in known {
            let fitted = grid.grid.tangents()[j].unwrap();
            let angle = fitted.cross(tangent.normalize()).length();
            assert!(angle < 1e-5, "node {j}: {fitted} vs {tangent}");
        }
    }

    #[test]
    fn a_curved_prior_without_data_is_kept() {
        let truth = curved_truth(GridInterpolation::Bilinear, 0.3, 1);
        let (same, report) = fit(&truth, &[]).unwrap();
        assert_eq!(same, truth);
        assert_eq!(report.unconstrained_nodes, 25);
    }

    /// The audit's camera: the fitting scene's eye (0, 5.5, 7) looking at (0.8, 0, 0.5),
    /// horizontal field of view 52 degrees, aspect 3:4; and the scene's own camera (looking
    /// at (0, 0.4, 0), 60 degrees) sampled as an `n` x `n` bilinear grid with its near surface
    /// at `near` (far 40): the prior of `scenes/flexible-projector-fit.toml`.
    fn audit_truth_and_prior(n: usize, near: f64) -> (LinearVolume, ProjectorGrid) {
        use crate::projection::flexible::presets::PresetSpec;
        use crate::projection::CameraFrame;
        let camera = |look_at: DVec3, fov: f64, clip: [f64; 2]| {
            let spec = PresetSpec {
                preset: Preset::Perspective { fov },
                frame: CameraFrame {
                    position: DVec3::new(0.0, 5.5, 7.0),
                    look_at,
                    up: DVec3::Y,
                },
                clip: Some(clip),
            };
            let (near, far) = spec.surfaces(0.75).unwrap();
            LinearVolume::new(near, far).unwrap()
        };
        let truth = camera(DVec3::new(0.8, 0.0, 0.5), 52.0, [0.0, 40.0]);
        let scene = camera(DVec3::new(0.0, 0.4, 0.0), 60.0, [near, 40.0]);
        let prior = ProjectorGrid::sample(&scene, (n, n), GridInterpolation::Bilinear).unwrap();
        (truth, prior)
    }

    /// `count` correspondences of `truth` (a camera whose near surface is at its eye): (u, v)
    /// uniform in the image, points 4 to 12 units from the eye along the pixel's ray, rounded
    /// to 6 decimals as a scene file would hold them (the audit's generator).
    fn camera_correspondences(
        truth: &LinearVolume,
        count: usize,
        seed: u64,
    ) -> Vec<Correspondence> {
        let mut next = uniform(seed);
        let round = |x: DVec3| (x * 1e6).round() / 1e6;
        (0..count)
            .map(|_| {
                let uv = round(DVec3::new(next(), next(), 0.0)).truncate();
                let eye = truth.point(uv, 0.0);
                let depth = 4.0 + 8.0 * next();
                Correspondence {
                    uv,
                    point: round(eye + depth * truth.tangent(uv).normalize()),
                }
            })
            .collect()
    }

    /// The audit's 12 points (docs/robustness.md): refused before, with the starts 0.5 off
    /// the eye, as "the fitted projector points away".
    fn audit_points() -> Vec<Correspondence> {
        [
            ([0.956034, 0.947827], [2.496893, 3.753678, 2.926832]),
            ([0.308136, 0.605944], [-0.762563, 0.331184, -0.370187]),
            ([0.430670, 0.393532], [0.198629, -1.375848, -0.030679]),
            ([0.268241, 0.035924], [-0.664618, 1.689302, 4.590871]),
            ([0.380015, 0.891789], [-0.000852, 2.023814, -0.855560]),
            ([0.136697, 0.510224], [-3.088537, -2.141873, -2.688734]),
            ([0.893572, 0.796760], [4.855044, 0.790971, -1.410929]),
            ([0.980977, 0.961901], [3.098326, 3.467070, 2.142023]),
            ([0.461407, 0.530356], [0.458760, 0.541191, 0.831714]),
            ([0.882851, 0.899701], [3.745460, 2.277288, 0.072491]),
            ([0.723773, 0.486609], [1.786751, 1.743047, 2.801248]),
            ([0.268138, 0.911378], [-0.694885, 2.827536, 0.654512]),
        ]
        .map(|(uv, point)| Correspondence {
            uv: DVec2::from_array(uv),
            point: DVec3::from_array(point),
        })
        .to_vec()
    }

    #[test]
    fn the_audit_points_fit_from_every_near_plane() {
        for near in [0.0, 0.1, 0.5, 2.0] {
            let (_, prior) = audit_truth_and_prior(3, near);
            let (fitted, report) = fit(&prior, &audit_points()).unwrap();
            eprintln!("audit near {near}: {report:?}");
            let reach = farthest_reach(&fitted, &audit_points()).unwrap();
            assert!(reach > 0.0 && reach <= 1.0, "{reach}");
            // Measured: 9.3e-6, 0.019, 0.14, 1.35 degrees (docs/flexible.md).
            assert!(report.max_angle_deg < 3.0, "near {near}: {report:?}");
        }
    }

    #[test]
    fn camera_data_fit_without_refusal_from_any_near_plane() {
        // Correspondences of a real camera (the audit's generator), 5 seeds per grid size and
        // near surface: starts off the camera's eye leave every grid a residual, which must
        // be reported, not turned into a refusal. Bounds: about twice the worst measured
        // (docs/flexible.md, "Inexact data").
        for (n, count) in [(3, 12), (5, 30), (9, 200)] {
            for (near, bound) in [(0.0, 1e-4), (0.1, 0.3), (0.5, 1.5), (2.0, 8.0)] {
                let (truth, prior) = audit_truth_and_prior(n, near);
                let mut worst = (0.0f64, 0.0f64);
                for seed in 0..5 {
                    let data = camera_correspondences(&truth, count, 1000 * n as u64 + seed);
                    let (_, report) = fit(&prior, &data)
                        .unwrap_or_else(|e| panic!("{n} x {n}, near {near}, seed {seed}: {e}"));
                    worst = (
                        worst.0.max(report.max_angle_deg),
                        worst.1.max(report.rms_angle_deg),
                    );
                }
                eprintln!(
                    "{n} x {n}, {count} points, near {near}: worst max {:e}, rms {:e} deg",
                    worst.0, worst.1
                );
                assert!(worst.0 < bound, "{n} x {n}, near {near}: {worst:?}");
            }
        }
    }

    #[test]
    fn correspondences_in_opposite_directions_are_still_refused() {
        // Two points at one image position on opposite sides of its start: no projector
        // reaches both in front of it, whatever the rest of the data.
        let (truth, prior) = audit_truth_and_prior(3, 0.5);
        let mut data = camera_correspondences(&truth, 12, 3);
        let uv = DVec2::new(0.4, 0.6);
        let (start, end) = prior.start_end(uv);
        let away = (end - start).normalize() * 6.0;
        data.push(Correspondence {
            uv,
            point: start + away,
        });
        data.push(Correspondence {
            uv,
            point: start - away,
        });
        let e = fit(&prior, &data).unwrap_err();
        assert!(e.message.contains("points away from it"), "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]

        /// Crossed-slits cameras of any field of view and slit distance (the horizontal slit
        /// in front of or behind the vertical one) are recovered from 64 of their own
        /// correspondences.
        #[test]
        fn crossed_slits_round_trip(
            fov in 20.0f64..140.0,
            slit_distance in prop_oneof![-8.0f64..-0.3, 0.3f64..0.9],
            seed in 0u64..1000,
        ) {
            let preset = Preset::CrossedSlits { fov, v_fov: None, slit_distance };
            let (error, _) = recover(&preset_volume(preset, [1.0, 30.0]), 8, seed);
            prop_assert!(error < 1e-7, "direction error {error}");
        }

        /// A perspective camera of any field of view is recovered from 64 of its own
        /// correspondences, starting from a 90-degree prior.
        #[test]
        fn perspective_round_trip(fov in 20.0f64..150.0, seed in 0u64..1000) {
            let bilinear = GridInterpolation::Bilinear;
            let truth =
                ProjectorGrid::sample(&perspective(fov, [1.0, 40.0]), (5, 5), bilinear).unwrap();
            let other =
                ProjectorGrid::sample(&perspective(90.0, [1.0, 40.0]), (5, 5), bilinear).unwrap();
            let prior = truth.with_ends(
                truth.starts().iter().zip(other.starts().iter().zip(other.ends()))
                    .map(|(s, (os, oe))| *s + (*oe - *os))
                    .collect(),
            ).unwrap();
            let data = correspondences_of(&truth, 8, seed);
            let (fitted, _) = fit(&prior, &data).unwrap();
            let error = max_direction_error(&fitted, &truth);
            prop_assert!(error < 1e-7, "direction error {error}");
            // Casting the fitted projector through each correspondence's image position gives
            // back its scene point.
            for c in &data {
                let ray = fitted.ray(c.uv).unwrap();
                let t = (c.point - ray.origin).dot(ray.direction) / ray.direction.length_squared();
                prop_assert!((ray.at(t) - c.point).length() < 1e-5 * c.point.length().max(1.0));
            }
        }
    }
}
