//! Fitting a projector grid to point correspondences: given scene points and the image
//! positions (u, v) where they must appear, aim every node projector at once and report the
//! residual. The history of measurements behind the constants here is in
//! docs/log/calibrate.md.
//!
//! # The straight fit (starts kept)
//!
//! The starts S_j of the node projectors are kept (they are the image plane); the unknowns
//! are the node directions D_j = E_j - S_j. Correspondence k says that X_k lies on the
//! projector of (u_k, v_k): D(u_k, v_k) = sum_j w_j(u_k, v_k) D_j is parallel to
//! a_k = (X_k - S(u_k, v_k)) / |...|. With P_k = I - a_k a_k^T, `P_k D(u_k, v_k) = 0` is
//! linear in the D_j, so the fit minimises
//!
//! sum_k |P_k sum_j w_kj D_j|^2 + lambda sum_j |D_j - D0_j|^2
//!
//! (D0: the prior grid's directions) subject to one scale constraint, sum_j D0_j . D_j =
//! sum_j |D0_j|^2 over the constrained nodes: the data term is homogeneous, and the
//! constraint removes the scale freedom without shrinking the solution towards zero.
//! lambda (`PRIOR_WEIGHT` of the data term's mean diagonal, unknowns scaled by the prior's
//! mean projector length so that it is dimensionless) keeps the system positive definite and
//! gives nodes no correspondence constrains the prior's projector; its bias on determined
//! directions grows with it, so it is as small as double precision allows, and a second
//! solve centred on the first removes most of what remains ([`fit`]). After the solve, when
//! some X_k would lie beyond its projector's end (t > 1), all directions are lengthened by
//! one common factor so that every X_k is in view.
//!
//! Noisy data (module `system`): one floor-weighted solve measures the noise; above rounding
//! level the fit solves again with the prior's weight set to the noise variance over
//! `PRIOR_SPREAD`^2 (the maximum a posteriori weight for a Gaussian prior around the prior
//! grid), centred on the prior, so that weakly determined node combinations do not turn
//! until projectors point away from their points.
//!
//! Inexact data: |P_k D|^2 is |D| sin(angle) squared, met as well by a projector pointing
//! away and lowered by shortening D. When the floor-weighted fit misses by more than
//! `EXACT_CHORD`, the noise-weighted linear solution is kept only where it reaches every
//! point in front of its start; otherwise the fit is refined on the chord 2 sin(angle / 2)
//! between fitted and wanted unit directions (module `angular`), from the linear solution
//! and from the prior.
//!
//! Degenerate cases: no correspondences (the prior is returned unchanged); a point at its
//! projector's start (no direction: an error naming it); (u, v) outside [0, 1]^2 or
//! non-finite values (errors); correspondences that only a projector pointing away could meet
//! (an error: the fitted projector must reach X_k at t > 0); a fitted node direction of zero
//! length (an error).
//!
//! # Starts (model selection, module `select`)
//!
//! [`fit_with`] takes the scene key `starts`: `Kept` is [`fit`]; `Eye` fits one common eye
//! with the directions, every projector through it (module `central`: a pinhole camera's
//! affine direction field where that explains the data, else free node directions); `Free`
//! fits every node's start too (module `free`: projections with no common eye, such as
//! pushbroom and crossed slits); `Pinhole` is one pinhole camera of square pixels, its
//! principal point at the image centre (focal length and pose) or off centre where the data
//! clearly support it, fitted by its reprojection error in the image (module
//! `pinhole_camera`). `Auto`, the default,
//! keeps what the nested choice (`select::nested_fit`) gives where that meets the data
//! exactly: the starts kept when they meet the data and the data determine the free
//! directions, an exact eye fit where they do not, the free starts where neither is exact
//! and the free fit is clearly better and determined. Inexact data (clicks on a painting)
//! are fitted by every model and judged by their held-out misses (each fifth of the points
//! measured against the fit of the other four fifths, the same fifths for every model): a
//! richer model replaces a simpler one only where the trimmed mean of its per-point misses
//! (a fifth of them left out at each end) is lower (`select::lower_held_out`), and a grid that
//! folds (module `folds`: projectors crossing among the points' depths) is never taken
//! where another model's does not: the residual at the points rewards models that bend to
//! the noise, the held-out misses do not.
//!
//! # Warnings (module `checks`)
//!
//! The residual is measured at the correspondences only. [`FitReport`] counts the
//! constrained nodes that left the prior by far (`wild_nodes`: a length ratio to the prior's
//! node beyond `WILD_LENGTH` times the median ratio, judged only where the lengths move the
//! projectors at the points by more than the fit's noise, or a direction more than
//! `WILD_ANGLE_DEG` off) and those the chosen model leaves undetermined (`sparse_nodes`:
//! none for a pinhole's field; for curved grids, summed grid weight below `SPARSE_WEIGHT`);
//! [`FitReport::warning`] words them for the user.
//!
//! # Curved projectors (module `curved`)
//!
//! A prior with node tangents (quadratic Bezier projectors) is fitted in two stages: the
//! straight fit above (tangents dropped, with the noise's prior weight where its residual is
//! above rounding), then the end directions, tangents and lengths (where the data determine
//! them; else the prior's) of every constrained node by nonlinear least squares. The prior's
//! tangents stay on the nodes no correspondence constrains; a fitted tangent along its chord
//! makes a straight node.

use glam::DVec3;

use crate::error::Result;
use crate::projection::flexible::{Correspondence, ProjectorGrid, Starts};

mod angular;
mod blocked_cholesky;
mod camera_matrix;
mod central;
mod cholesky;
mod curved;
mod dense_lm;
mod envelope_cholesky;
mod folds;
mod free;
mod nested_models;
mod pinhole_camera;

use checks::{
    miss_seen_from, prior_directions, report_of, straight_undetermined, thinly_weighted_nodes,
    undetermined_nodes, wild_nodes, EXACT_RMS_RAD, WILD_ANGLE_DEG, WILD_LENGTH,
};
use select::{auto_fit, central_fit, free_fit, pinhole_fit};
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
/// the truth when its weight follows the noise (module docs, "Noisy data").
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
    /// Starts on the projectors of one fitted pinhole camera with this eye.
    Pinhole(DVec3),
}

/// In words, for the written scene's header and `flexcam fit`'s output.
impl std::fmt::Display for FittedStarts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FittedStarts::Kept => write!(f, "starts kept"),
            FittedStarts::Eye(e) => write!(f, "starts on projectors through the fitted eye {e}"),
            FittedStarts::Free => write!(f, "starts fitted per node"),
            FittedStarts::Pinhole(e) => write!(f, "one pinhole camera with the fitted eye {e}"),
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
    /// The curved fit's Levenberg-Marquardt iterations, over every run of its restarts
    /// (module `curved`); `None` for the straight fits.
    pub curved_iterations: Option<usize>,
    /// Whether the pinhole model's focal length is the prior's: the data (points on a plane
    /// seen face on) leave it undetermined (module `pinhole_camera`).
    pub focal_from_prior: bool,
    /// Whether `starts = "pinhole"` fitted the general camera matrix (11 unknowns: aspect,
    /// skew and principal point free) because no square-pixel camera keeps every
    /// correspondence's point in front of it (inconsistent data).
    pub general_camera: bool,
    /// Whether `starts = "eye"` fitted the pinhole camera of square pixels because the
    /// general camera matrix the data determine keeps a correspondence's point behind its
    /// eye and the free directions find no determined eye (inconsistent data).
    pub square_pixel_camera: bool,
    /// The pinhole model's principal point as an image position (u, v) where the data put
    /// it off the image centre (a cropped painting; module `pinhole_camera`); `None` at the
    /// centre and for the other models.
    pub principal_point: Option<[f64; 2]>,
}

impl FitReport {
    /// The report of a fit whose projectors miss their points by `angles` (degrees, one per
    /// correspondence), with `unconstrained_nodes` nodes no correspondence reaches; the other
    /// fields at their defaults. No angles give a largest and RMS angle of 0.
    pub(crate) fn from_angles(angles: &[f64], unconstrained_nodes: usize) -> FitReport {
        let count = angles.len();
        FitReport {
            correspondences: count,
            unconstrained_nodes,
            max_angle_deg: angles.iter().copied().fold(0.0, f64::max),
            rms_angle_deg: if count == 0 {
                0.0
            } else {
                (angles.iter().map(|a| a * a).sum::<f64>() / count as f64).sqrt()
            },
            ..FitReport::default()
        }
    }

    /// The model in words, for `flexcam fit`'s line and the written header: the starts, for
    /// the free fit the smoothness weight the data chose, for a pinhole off centre its
    /// principal point.
    pub fn model(&self) -> String {
        match (self.smoothness, self.principal_point) {
            (Some(weight), _) => format!("{}, smoothness {weight:e}", self.starts),
            (None, Some([u, v])) => {
                format!("{}, principal point at (u, v) = ({u}, {v})", self.starts)
            }
            (None, None) => self.starts.to_string(),
        }
    }

    /// A warning for the user when some node left the prior by far or is undetermined:
    /// the residual, measured at the correspondences only, may then hide a wrong image.
    pub fn warning(&self) -> Option<String> {
        let focal = self.focal_from_prior.then(|| {
            "the correspondences (points on one plane seen nearly face on) do not determine \
             the pinhole camera's focal length: the prior's is kept, and the distance to the \
             plane follows from it"
                .to_string()
        });
        let general = self.general_camera.then(|| {
            "no pinhole camera of square pixels sees every correspondence's point in front of \
             it: the general camera matrix (aspect, skew and principal point free) is fitted \
             instead"
                .to_string()
        });
        let square = self.square_pixel_camera.then(|| {
            "the general camera matrix keeps a correspondence's point behind its eye: the \
             pinhole camera of square pixels is fitted instead"
                .to_string()
        });
        let parts: Vec<String> = [
            general,
            square,
            focal,
            node_warning(self.wild_nodes, self.sparse_nodes),
        ]
        .into_iter()
        .flatten()
        .collect();
        (!parts.is_empty()).then(|| parts.join("; "))
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
/// Noisy data (module docs of `grid`, "Noisy data") are solved once with the noise's prior weight. Exact
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
    // Inexact data (module docs of `grid`, "Inexact data"): the linear solution with the noise's
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
/// data (`auto_fit`). Then counts the wild nodes and, for kept starts, the undetermined ones
/// (the other models count their own; module section "Warnings").
pub fn fit_with(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    starts: Starts,
) -> Result<(ProjectorGrid, FitReport)> {
    let (grid, mut report) = match starts {
        Starts::Kept => fit(prior, correspondences)?,
        Starts::Eye => central_fit(prior, correspondences)?,
        Starts::Pinhole => pinhole_fit(prior, correspondences)?,
        Starts::Free => free_fit(prior, correspondences)?,
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
