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

use glam::DVec3;

use crate::error::Result;
use crate::projection::flexible::{Correspondence, ProjectorGrid, Starts};

mod angular;
mod central;
mod curved;
mod free;

use checks::{
    miss_seen_from, prior_directions, report_of, straight_undetermined, thinly_weighted_nodes,
    undetermined_nodes, wild_nodes, EXACT_RMS_RAD, WILD_ANGLE_DEG, WILD_LENGTH,
};
use select::{auto_fit, central_fit};
use system::{
    add_block, all_in_front, blended, constrained_nodes, fit_once, in_view, nearly_exact,
    noise_weight, projector_off, residual, straight_start, targets, System,
};

mod checks;
mod select;
mod system;
#[cfg(test)]
mod tests;

/// The prior's least weight, relative to the data term's mean diagonal (see the module docs).
const PRIOR_WEIGHT: f64 = 1e-11;

/// How far, as a fraction of their length, the prior's node directions are taken to be off
/// the truth when its weight follows the noise (module section "Noise").
const PRIOR_SPREAD: f64 = 1.0;

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
