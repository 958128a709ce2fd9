//! The central fit (`starts = "eye"`): one common eye E found together with the node
//! directions, every projector a line through E, for correspondences taken from a pinhole
//! camera whose eye is not where the prior's starts are (module section "Starts" of `grid`).
//!
//! With the starts kept off the camera's eye no grid meets such data: a projector from a
//! start off the eye through two points at different depths at nearby (u, v) disagrees, and
//! where the data are sparse the kept-starts fit bends between the points (docs/flexible.md,
//! "A small residual is not a faithful image"). Here every node starts on its own projector
//! at S_j = E + s D_j, with one s for all nodes: then S(u, v) = E + s D(u, v) for any
//! weights that sum to 1, so every projector of the grid, not only the nodes', passes
//! through E, and a bilinear grid is any pinhole camera exactly (its direction field is
//! affine in (u, v)).
//!
//! Two direction fields are fitted: the pinhole's affine field
//! D(u, v) = A (u - 1/2) + B (v - 1/2) + C, with its eye, of the square-pixel camera (module
//! `pinhole_camera`) unless the 3 x 4 camera matrix of least reprojection error in the image
//! (module `camera_matrix`) meets the data clearly better in the image
//! (`Setup::general_clearly_better`), tried first and kept when
//! it is exact or explains the data nearly as well as the free field ([`pinhole_suffices`]),
//! and the free node directions (3 a node) at an eye found as below. Free directions meet
//! sparse data exactly in many ways, most of them bent between the points, so six points
//! determine the pinhole where the free field needs points enough for every node.
//! `starts = "pinhole"` is the field of a pinhole camera of square pixels, its principal
//! point at the image centre (module `pinhole_camera`: 7 unknowns, determined by points on
//! one plane too), alone ([`fit_pinhole`]).
//!
//! The free field's E is found by variable projection: for a given E the directions are the
//! linear fit's of module `grid` (starts at E, solved twice, the second centred on the
//! first), and Levenberg-Marquardt moves E to minimise the chords 2 sin(angle / 2) between
//! the blended directions and the points seen from E, with central-difference derivatives
//! in E (three unknowns; each residual is two small linear solves). It starts from the
//! point nearest to the prior's node projectors (the prior's own eye, for a perspective
//! prior) and from the pinhole's eye (the square-pixel camera's where the camera matrix is
//! undetermined), and keeps the better. The grid at the found eye is
//! then fitted by `fit` with its starts at E. The starts are moved along their projectors to
//! the prior's near distance s (the prior's mean start parameter seen from its own eye, 0
//! when the prior has none), less where a point lies nearer the eye than that.
//!
//! Degenerate cases (each an error naming the cause, which `starts = "auto"` answers by
//! keeping the prior's starts): a prior with tangents (curved projectors have no common
//! eye); fewer than `MIN_POINTS` correspondences; points that all coincide; an eye the data
//! do not determine (for the pinhole, a second camera matrix meets the data: points all on
//! one plane; for the free directions, the misses change by less than `FLAT` of the data's
//! extent when E moves in some direction: so few points that they absorb any move of E);
//! image positions all on one line (points on one line through the eye among them); no
//! pinhole and no eye at which the free directions solve. Data that are merely
//! inconsistent (two eyes' points mixed) get the pinhole's least-squares fit: the general
//! camera matrix's, or where that keeps a point behind its eye (nearly coplanar noisy points
//! with one off the plane put its eye in the plane) the square-pixel camera's
//! ([`FitReport::square_pixel_camera`]). The
//! square-pixel camera of `starts = "pinhole"` has its own degenerate cases (module
//! `pinhole_camera`): points on one line, a plane seen edge-on; a plane seen face on leaves
//! only its focal length free (the prior's is kept, [`FitReport::focal_from_prior`]); data
//! that keep a point behind every square-pixel camera reached, or behind the fitted one's
//! starts (inconsistent data, such as a point behind the eye), get the general camera
//! matrix's fit instead
//! ([`FitReport::general_camera`]).

use std::cell::OnceCell;

use glam::{DMat3, DVec2, DVec3};
use nalgebra::{Matrix3, SymmetricEigen};

use super::camera_matrix::CameraMatrix;
use super::nested_models::clearly_better;
use super::pinhole_camera::{ImageShape, PinholeCamera, Undetermined};
use super::{blended, prior_directions, targets, Correspondence, FitReport, System};
use crate::error::{Error, Result};
use crate::projection::flexible::projector_grid::ProjectorGrid;

/// The fewest correspondences an eye is fitted from: the direct linear transform's 11
/// unknowns need six points.
pub(super) const MIN_POINTS: usize = 6;

/// Levenberg-Marquardt iterations at most per starting eye.
const MAX_ITERATIONS: usize = 40;

/// The eye is taken as undetermined when moving it by the data's extent in some direction
/// changes the misses (rad, root sum of squares) by less than this, or by less than this
/// fraction of the most that any direction changes them.
const FLAT: f64 = 1e-6;

/// The central-difference step in E, as a fraction of the data's extent.
const STEP: f64 = 1e-5;

/// Fits `prior`'s node directions and one common eye to `correspondences` (module docs);
/// returns the grid, its residual and the eye.
pub(super) fn fit(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport, DVec3)> {
    let setup = Setup::new(prior, correspondences)?;
    let (pinhole_fit, square_pixels) = match setup.pinhole_fit() {
        // The square-pixel camera (7 unknowns) unless the general one (11) is clearly better:
        // nearly coplanar points leave the general camera matrix nearly free, and its
        // least-squares eye may lie in their plane, far off the square-pixel camera's.
        Some(general) => match setup.square_pixel_fit() {
            Ok((square, camera)) if !setup.general_clearly_better(&camera) => (Some(square), false),
            _ => (Some(general), false),
        },
        // Merely inconsistent data (the general camera the data determine keeps a point
        // behind its eye, as mixed eyes or one noisy point off a plane do): the square-pixel
        // camera's least-squares fit, which `fit_pinhole` would give, and the report says so.
        None if setup.camera().is_some() => {
            (setup.square_pixel_fit().ok().map(|(found, _)| found), true)
        }
        None => (None, false),
    };
    let finish_pinhole = |grid: &ProjectorGrid, eye: DVec3| {
        let (grid, report, eye) = finish(grid, correspondences, eye, prior, true)?;
        let report = FitReport {
            square_pixel_camera: square_pixels,
            ..report
        };
        Ok((grid, report, eye))
    };
    if let Some(((grid, report), eye)) = &pinhole_fit {
        if report.rms_angle_deg.to_radians() <= PINHOLE_EXACT {
            return finish_pinhole(grid, *eye);
        }
    }
    let (free, extent) = (setup.problem(), setup.extent);
    let free_fit = setup
        .best(&free)
        .ok_or_else(|| {
            Error::new(
                "projector grid fit: no eye found at which the node directions can be fitted",
            )
        })
        .and_then(|eye| {
            free.check_determined(eye, extent)?;
            let at_eye = free.grid_at(eye, &prior_directions(prior))?;
            Ok((super::fit(&at_eye, correspondences)?, eye))
        });
    match (pinhole_fit, free_fit) {
        (Some(((grid, report), eye)), Ok(((_, free_report), _)))
            if pinhole_suffices(&report, &free_report, prior.starts().len()) =>
        {
            finish_pinhole(&grid, eye)
        }
        (_, Ok(((grid, _), eye))) => finish(&grid, correspondences, eye, prior, false),
        (Some(((grid, _), eye)), Err(_)) => finish_pinhole(&grid, eye),
        (None, Err(e)) => Err(e),
    }
}

/// The pinhole model alone (`starts = "pinhole"`): the eye and the affine direction field
/// of one pinhole camera that best meet `correspondences`, with its residual however large
/// (module docs). Errors: those of [`fit`]'s degenerate cases, and no eye at which the field
/// keeps every point in front.
pub(super) fn fit_pinhole(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
) -> Result<(ProjectorGrid, FitReport, DVec3)> {
    let setup = Setup::new(prior, correspondences)?;
    match setup.square_pixel_fit() {
        Ok((((grid, _), eye), camera)) => {
            // A camera reached only from starts moved back (every start kept a point behind
            // it) where the general camera matrix has a grid: inconsistent data (a point
            // behind the eye), whose square-pixel descent may end with its eye on that
            // point; the general camera's fit moves the eye until every point is in front.
            if camera.moved_start() {
                if let Some(general) = setup.pinhole_fit() {
                    return general_camera_fit(general, correspondences, prior);
                }
            }
            let (grid, report, eye) = finish(&grid, correspondences, eye, prior, true)?;
            let report = FitReport {
                focal_from_prior: camera.focal_from_prior(),
                principal_point: camera.principal_point().map(|uv| uv.to_array()),
                ..report
            };
            Ok((grid, report, eye))
        }
        // Merely inconsistent data (a point behind every square-pixel camera the starts
        // reach, or behind the fitted one's starts).
        Err(NoSquarePixelGrid::Inconsistent) => {
            let general = setup.pinhole_fit().ok_or_else(undetermined)?;
            general_camera_fit(general, correspondences, prior)
        }
        Err(NoSquarePixelGrid::Undetermined(why)) => {
            Err(Error::new(format!("projector grid fit: {why}")))
        }
    }
}

/// The general camera matrix's least-squares fit `general` (its grid and eye) finished for
/// `fit_pinhole` on inconsistent data: the descent may move the eye until every point is in
/// front, and the report says the general camera was taken.
fn general_camera_fit(
    ((grid, _), eye): CameraFit,
    correspondences: &[Correspondence],
    prior: &ProjectorGrid,
) -> Result<(ProjectorGrid, FitReport, DVec3)> {
    let (grid, report, eye) = finish(&grid, correspondences, eye, prior, true)?;
    let report = FitReport {
        general_camera: true,
        ..report
    };
    Ok((grid, report, eye))
}

/// A camera's grid with its report, and its eye.
type CameraFit = ((ProjectorGrid, FitReport), DVec3);

/// Why the square-pixel camera gave no grid: the data are merely inconsistent with it (a
/// point stays behind), or they do not determine it (the reason).
enum NoSquarePixelGrid {
    Inconsistent,
    Undetermined(Undetermined),
}

/// What both direction fields of a central fit share: the checked data, their extent and
/// the general camera matrix of the correspondences, fitted once when first asked for.
struct Setup<'a> {
    prior: &'a ProjectorGrid,
    correspondences: &'a [Correspondence],
    extent: f64,
    camera: OnceCell<Option<CameraMatrix>>,
}

impl<'a> Setup<'a> {
    /// The setup of fitting `prior` to `correspondences` through one eye; errors for the
    /// degenerate cases of the module docs that the data show before any fit.
    fn new(prior: &'a ProjectorGrid, correspondences: &'a [Correspondence]) -> Result<Self> {
        if prior.is_curved() {
            return Err(Error::new(
                "projector grid fit: `starts = \"eye\"` fits straight projectors through one \
                 eye; this grid has tangents",
            ));
        }
        if correspondences.len() < MIN_POINTS {
            return Err(Error::new(format!(
                "projector grid fit: an eye needs at least {MIN_POINTS} correspondences, not {}",
                correspondences.len()
            )));
        }
        let extent = extent(correspondences);
        if extent <= 0.0 || !extent.is_finite() {
            return Err(Error::new(
                "projector grid fit: the correspondences' points all coincide; they determine \
                 no eye",
            ));
        }
        if on_one_image_line(correspondences) {
            return Err(undetermined());
        }
        Ok(Setup {
            prior,
            correspondences,
            extent,
            camera: OnceCell::new(),
        })
    }

    /// The general camera matrix of the correspondences (module `camera_matrix`), `None`
    /// where they determine none.
    fn camera(&self) -> Option<&CameraMatrix> {
        self.camera
            .get_or_init(|| CameraMatrix::fit(self.correspondences))
            .as_ref()
    }

    /// The variable-projection problem of the free directions.
    fn problem(&self) -> Problem<'a> {
        Problem {
            prior: self.prior,
            correspondences: self.correspondences,
            step: STEP * self.extent,
        }
    }

    /// The eye of least cost descended to from either starting eye: the prior's centre and
    /// the camera matrix's eye (the square-pixel camera's where the camera matrix has none).
    fn best(&self, problem: &Problem) -> Option<DVec3> {
        let pinhole_eye = || {
            self.camera().and_then(|c| c.eye()).or_else(|| {
                PinholeCamera::fit(self.correspondences, ImageShape::of_prior(self.prior))
                    .ok()
                    .map(|c| c.eye())
            })
        };
        [prior_centre(self.prior), pinhole_eye()]
            .into_iter()
            .flatten()
            .filter_map(|start| problem.descend(start))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(eye, _)| eye)
    }

    /// The square-pixel camera's grid (module `pinhole_camera`: 7 unknowns, determined by
    /// points on one plane too), lengthened into view, with its eye and the camera.
    fn square_pixel_fit(
        &self,
    ) -> std::result::Result<(CameraFit, PinholeCamera), NoSquarePixelGrid> {
        let camera =
            match PinholeCamera::fit(self.correspondences, ImageShape::of_prior(self.prior)) {
                Ok(camera) => camera,
                Err(Undetermined::NotInFront) => return Err(NoSquarePixelGrid::Inconsistent),
                Err(why) => return Err(NoSquarePixelGrid::Undetermined(why)),
            };
        let found = self
            .camera_grid(camera.eye(), |uv| camera.direction(uv))
            .ok_or(NoSquarePixelGrid::Inconsistent)?;
        Ok((found, camera))
    }

    /// Whether the general camera matrix (11 unknowns) should replace the square-pixel
    /// camera `square` (7): the nested least-squares rule of module `nested_models` on their
    /// reprojection errors in the image, where click noise is the same for every point (as
    /// angles at the eye, a wrong eye's misses shrink: nearly coplanar points seen from an
    /// eye in their plane all lie near one plane of directions). False where the general
    /// camera keeps a point behind it.
    fn general_clearly_better(&self, square: &PinholeCamera) -> bool {
        let Some(general) = self.camera() else {
            return false;
        };
        let misses = |project: &dyn Fn(DVec3) -> Option<DVec2>| {
            self.correspondences
                .iter()
                .map(|c| project(c.point).map(|uv| (uv - c.uv).length_squared()))
                .sum::<Option<f64>>()
        };
        match (
            misses(&|p| general.project(p)),
            misses(&|p| square.project(p)),
        ) {
            (Some(general), Some(square)) => {
                clearly_better(self.correspondences.len(), 11, 4, general, square)
            }
            (general, _) => general.is_some(),
        }
    }

    /// The pinhole's grid (module `camera_matrix`: 11 unknowns, which six points in general
    /// position determine, where the free directions need points enough for every node),
    /// lengthened into view, with its eye; `None` where the data determine no camera.
    fn pinhole_fit(&self) -> Option<((ProjectorGrid, FitReport), DVec3)> {
        let camera = self.camera()?;
        self.camera_grid(camera.eye()?, |uv| camera.direction(uv))
    }

    /// The grid of the camera at `eye` whose projector through (u, v) has the direction
    /// `direction(uv)`, its node directions scaled to the prior's mean length and
    /// lengthened into view, with the eye; `None` where a point stays behind.
    fn camera_grid(
        &self,
        eye: DVec3,
        direction: impl Fn(DVec2) -> DVec3,
    ) -> Option<((ProjectorGrid, FitReport), DVec3)> {
        let (cols, rows) = self.prior.size();
        let mut dirs: Vec<DVec3> = (0..rows)
            .flat_map(|row| (0..cols).map(move |col| (col, row)))
            .map(|(col, row)| direction(self.prior.node_uv(col, row)))
            .collect();
        let mean = |d: &[DVec3]| d.iter().map(|v| v.length()).sum::<f64>() / d.len() as f64;
        let scale = mean(&prior_directions(self.prior)) / mean(&dirs);
        if !(scale.is_finite() && scale > 0.0) {
            return None;
        }
        dirs.iter_mut().for_each(|d| *d *= scale);
        let at_eye = self.problem().grid_at(eye, &dirs).ok()?;
        let targets = targets(&at_eye, self.correspondences).ok()?;
        let fitted = super::in_view(&at_eye, self.correspondences, &targets, dirs).ok()?;
        Some((fitted, eye))
    }
}

/// `fitted` (every start at `eye`) with its starts moved to the prior's near distance, its
/// report and the eye. The report's `sparse_nodes` counts the nodes the data leave
/// undetermined: none under the `pinhole` field (its eye and 8 unknowns were found
/// determined), else those of the free directions at the eye.
fn finish(
    fitted: &ProjectorGrid,
    correspondences: &[Correspondence],
    eye: DVec3,
    prior: &ProjectorGrid,
    pinhole: bool,
) -> Result<(ProjectorGrid, FitReport, DVec3)> {
    let grid = starts_moved(fitted, correspondences, eye, near_fraction(prior))?;
    let report = super::report_of(&grid, correspondences)?;
    let sparse_nodes = if pinhole {
        0
    } else {
        super::straight_undetermined(&grid, correspondences)?
    };
    Ok((
        grid,
        FitReport {
            sparse_nodes,
            ..report
        },
        eye,
    ))
}

/// The error of an eye the correspondences do not determine.
fn undetermined() -> Error {
    Error::new(
        "projector grid fit: the correspondences do not determine an eye (they are met as \
         well from other eyes: image positions on one line, points all on one plane, or too \
         few points for the grid's nodes); use `starts = \"kept\"` or add points off that \
         plane or line",
    )
}

/// Whether the image positions all lie on one line (or at one position): a pinhole's points
/// then lie in one plane through its eye, and every eye in that plane sees them in one plane
/// of directions too, which the node directions can follow.
fn on_one_image_line(correspondences: &[Correspondence]) -> bool {
    let n = correspondences.len() as f64;
    let mean = correspondences.iter().map(|c| c.uv).sum::<glam::DVec2>() / n;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for c in correspondences {
        let d = c.uv - mean;
        (xx, xy, yy) = (xx + d.x * d.x, xy + d.x * d.y, yy + d.y * d.y);
    }
    // The covariance's least eigenvalue, against a spread of 1e-6 in the image.
    let (half_trace, det) = (0.5 * (xx + yy) / n, (xx * yy - xy * xy) / (n * n));
    let least = half_trace - (half_trace * half_trace - det).max(0.0).sqrt();
    least < 1e-12
}

/// The root mean square distance of the correspondences' points from their centroid.
fn extent(correspondences: &[Correspondence]) -> f64 {
    let n = correspondences.len() as f64;
    let centroid = correspondences.iter().map(|c| c.point).sum::<DVec3>() / n;
    let spread: f64 = correspondences
        .iter()
        .map(|c| (c.point - centroid).length_squared())
        .sum();
    (spread / n).sqrt()
}

/// The point nearest (least squares) to the lines of `grid`'s node projectors: the eye of a
/// perspective grid. `None` when the lines are (nearly) parallel.
fn prior_centre(grid: &ProjectorGrid) -> Option<DVec3> {
    let mut matrix = DMat3::ZERO;
    let mut rhs = DVec3::ZERO;
    for (s, e) in grid.starts().iter().zip(grid.ends()) {
        let d = (*e - *s).try_normalize()?;
        let off = DMat3::IDENTITY - DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        matrix += off;
        rhs += off * *s;
    }
    let scale = matrix.x_axis.x + matrix.y_axis.y + matrix.z_axis.z;
    let det = matrix.determinant();
    (det.abs() > 1e-9 * scale.powi(3))
        .then(|| matrix.inverse() * rhs)
        .filter(|c| c.is_finite())
}

/// The start parameter s of the prior's nodes seen from its own eye ([`prior_centre`]):
/// the mean of (S_j - E0) . D_j / |D_j|^2, at least 0; 0 when the prior has no eye.
fn near_fraction(prior: &ProjectorGrid) -> f64 {
    let Some(eye) = prior_centre(prior) else {
        return 0.0;
    };
    let n = prior.starts().len() as f64;
    let sum: f64 = prior
        .starts()
        .iter()
        .zip(prior.ends())
        .map(|(s, e)| (*s - eye).dot(*e - *s) / (*e - *s).length_squared())
        .sum();
    (sum / n).max(0.0)
}

/// Rms miss (radians) at or below which the pinhole's direction field is taken as exact.
const PINHOLE_EXACT: f64 = 1e-6;

/// Whether the pinhole's direction field (8 unknowns) explains the data as well as the
/// free directions of `nodes` nodes (3 a node less 1) do: its misses are at rounding level, or the
/// free fit lowers the sum of squared misses by no more than 4 noise variances per extra
/// unknown, the variance estimated from the pinhole's own misses (the simpler model's
/// estimate, so that sparse data, where the free fit has few or no spare equations, keep
/// the pinhole). The same rule as `starts = "auto"`'s between kept starts and the eye.
fn pinhole_suffices(pinhole: &FitReport, free: &FitReport, nodes: usize) -> bool {
    let rad = |deg: f64| deg.to_radians();
    if rad(pinhole.rms_angle_deg) <= PINHOLE_EXACT {
        return true;
    }
    let n = pinhole.correspondences as f64;
    let sse = |r: &FitReport| n * rad(r.rms_angle_deg).powi(2);
    let free_unknowns = 3.0 * nodes as f64 - 1.0;
    let extra = free_unknowns - 8.0;
    let spare = 2.0 * n - 8.0;
    if spare <= 0.0 || extra <= 0.0 {
        return true;
    }
    let variance = sse(pinhole) / spare;
    sse(pinhole) - sse(free) <= 4.0 * extra * variance
}

/// The variable-projection problem in the eye E.
struct Problem<'a> {
    prior: &'a ProjectorGrid,
    correspondences: &'a [Correspondence],
    /// The central-difference step in E.
    step: f64,
}

impl Problem<'_> {
    /// The prior's grid with every start at `eye` and the node directions `dirs`.
    fn grid_at(&self, eye: DVec3, dirs: &[DVec3]) -> Result<ProjectorGrid> {
        let starts = vec![eye; dirs.len()];
        let ends = dirs.iter().map(|d| eye + *d).collect();
        ProjectorGrid::new(self.prior.size(), starts, ends, self.prior.interpolation())
    }

    /// The chords n_k - a_k (3 per correspondence) between the blended directions of the
    /// model's field at `eye` (the linear fit with every start at `eye`, or the pinhole's)
    /// and the unit directions from `eye` to the points; `None` where that fit fails (a point
    /// at the eye, a zero-length node, a pinhole field turning a point behind).
    fn misses(&self, eye: DVec3) -> Option<Vec<f64>> {
        let first = self.grid_at(eye, &prior_directions(self.prior)).ok()?;
        let targets = targets(&first, self.correspondences).ok()?;
        let dirs = System::new(&first, self.correspondences, &targets)
            .solve(0.0)
            .ok()?;
        // Centred on the first solve: the prior's pull acts on its small residual only.
        let second = self.grid_at(eye, &dirs).ok()?;
        let dirs = System::new(&second, self.correspondences, &targets)
            .solve(0.0)
            .ok()?;
        self.chords(&second, &targets, &dirs)
    }

    /// The chords n_k - a_k between the blended unit directions of `grid`'s nodes `dirs`
    /// and the unit directions `targets` from the starts to the points.
    fn chords(&self, grid: &ProjectorGrid, targets: &[DVec3], dirs: &[DVec3]) -> Option<Vec<f64>> {
        let mut out = Vec::with_capacity(3 * self.correspondences.len());
        for (c, a) in self.correspondences.iter().zip(targets) {
            let n = blended(grid, c, dirs).try_normalize()?;
            out.extend((n - *a).to_array());
        }
        Some(out)
    }

    /// The derivative of [`Problem::misses`] in E by central differences: 3 columns.
    fn jacobian(&self, eye: DVec3) -> Option<Vec<[f64; 3]>> {
        let mut rows = vec![[0.0; 3]; 3 * self.correspondences.len()];
        for axis in 0..3 {
            let mut h = DVec3::ZERO;
            h[axis] = self.step;
            let (plus, minus) = (self.misses(eye + h)?, self.misses(eye - h)?);
            for (row, (p, m)) in rows.iter_mut().zip(plus.iter().zip(&minus)) {
                row[axis] = (p - m) / (2.0 * self.step);
            }
        }
        Some(rows)
    }

    /// J^T J and J^T r at `eye`.
    fn normal(&self, eye: DVec3, r: &[f64]) -> Option<(DMat3, DVec3)> {
        let jacobian = self.jacobian(eye)?;
        let mut jtj = DMat3::ZERO;
        let mut jtr = DVec3::ZERO;
        for (row, value) in jacobian.iter().zip(r) {
            let j = DVec3::from_array(*row);
            jtj += DMat3::from_cols(j * j.x, j * j.y, j * j.z);
            jtr += j * *value;
        }
        Some((jtj, jtr))
    }

    /// Levenberg-Marquardt on the sum of squared misses from the eye `start`: the eye found
    /// and its cost, or `None` where the misses cannot be evaluated at `start`.
    fn descend(&self, start: DVec3) -> Option<(DVec3, f64)> {
        let cost_of = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
        let mut eye = start;
        let mut r = self.misses(eye)?;
        let mut cost = cost_of(&r);
        let mut damping = 1e-3;
        for _ in 0..MAX_ITERATIONS {
            if cost < 1e-30 {
                break;
            }
            let Some((jtj, jtr)) = self.normal(eye, &r) else {
                break;
            };
            let mut improved = false;
            for _ in 0..12 {
                let diagonal = DVec3::new(jtj.x_axis.x, jtj.y_axis.y, jtj.z_axis.z);
                let damped =
                    jtj + DMat3::from_diagonal(damping * diagonal.max(DVec3::splat(1e-30)));
                let step = -(damped.inverse() * jtr);
                let next = eye + step;
                if let Some(r_next) = step.is_finite().then(|| self.misses(next)).flatten() {
                    let next_cost = cost_of(&r_next);
                    if next_cost < cost {
                        let decrease = cost - next_cost;
                        (eye, r, cost) = (next, r_next, next_cost);
                        damping = (damping * 0.1).max(1e-12);
                        improved = decrease > 1e-14 * cost;
                        break;
                    }
                }
                damping *= 10.0;
            }
            if !improved {
                break;
            }
        }
        Some((eye, cost))
    }

    /// An error when the misses at `eye` hardly change as E moves in some direction (module
    /// docs, degenerate cases): the eye is then not determined by the data.
    fn check_determined(&self, eye: DVec3, extent: f64) -> Result<()> {
        let r = self.misses(eye).ok_or_else(undetermined)?;
        let (jtj, _) = self.normal(eye, &r).ok_or_else(undetermined)?;
        let symmetric = Matrix3::from_fn(|i, j| jtj.col(j)[i]);
        let eigenvalues = SymmetricEigen::new(symmetric).eigenvalues;
        let (least, most) = (eigenvalues.min().max(0.0).sqrt(), eigenvalues.max().sqrt());
        if least * extent < FLAT || least < FLAT * most {
            return Err(undetermined());
        }
        Ok(())
    }
}

/// `fitted` (every start at `eye`) with its starts moved along their projectors to
/// S_j = E + s D_j, the end D_j beyond, for the near fraction `s` less where a point lies
/// nearer the eye than that (then half the nearest point's parameter).
fn starts_moved(
    fitted: &ProjectorGrid,
    correspondences: &[Correspondence],
    eye: DVec3,
    near: f64,
) -> Result<ProjectorGrid> {
    let dirs = prior_directions(fitted);
    let nearest = correspondences
        .iter()
        .map(|c| {
            let d = blended(fitted, c, &dirs);
            (c.point - eye).dot(d) / d.length_squared()
        })
        .fold(f64::INFINITY, f64::min);
    let s = near.min(0.5 * nearest);
    if s <= 0.0 {
        return Ok(fitted.clone());
    }
    let starts = dirs.iter().map(|d| eye + s * *d).collect();
    let ends = dirs.iter().map(|d| eye + (1.0 + s) * *d).collect();
    ProjectorGrid::new(fitted.size(), starts, ends, fitted.interpolation())
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::{fit_with, FittedStarts, Starts};
    use super::*;
    use crate::calibrate::grid::tests::lcg_uniform;
    use crate::projection::flexible::projector_grid::tests::perspective_volume as perspective;
    use crate::projection::flexible::projector_grid::GridInterpolation;

    /// The fixture camera's eye (`projector_grid::tests::preset_volume`).
    const EYE: DVec3 = DVec3::new(0.0, 1.0, 5.0);

    /// A 3 x 3 bilinear grid of a `fov`-degree perspective camera with near clip 1, every
    /// point moved by `offset`.
    fn camera_grid(fov: f64, offset: DVec3) -> ProjectorGrid {
        let grid = ProjectorGrid::sample(
            &perspective(fov, [1.0, 40.0]),
            (3, 3),
            GridInterpolation::Bilinear,
        )
        .unwrap();
        let starts = grid.starts().iter().map(|s| *s + offset).collect();
        let ends = grid.ends().iter().map(|e| *e + offset).collect();
        ProjectorGrid::new((3, 3), starts, ends, GridInterpolation::Bilinear).unwrap()
    }

    /// `count` points seen by `truth` at seeded image positions and depths t in (0.1, 0.6).
    fn seen_by(truth: &ProjectorGrid, count: usize, seed: u64) -> Vec<Correspondence> {
        let mut next = lcg_uniform(seed);
        (0..count)
            .map(|_| {
                let uv = DVec2::new(next(), next());
                let t = 0.1 + 0.5 * next();
                Correspondence {
                    uv,
                    point: truth.point(uv, t),
                }
            })
            .collect()
    }

    /// The largest distance from `eye` to a projector line of `grid` over a 9 x 9 grid of
    /// (u, v).
    fn farthest_line(grid: &ProjectorGrid, eye: DVec3) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..=8 {
            for j in 0..=8 {
                let uv = DVec2::new(f64::from(i), f64::from(j)) / 8.0;
                let (s, e) = grid.start_end(uv);
                let d = (e - s).normalize();
                worst = worst.max((eye - s).cross(d).length());
            }
        }
        worst
    }

    #[test]
    fn recovers_a_pinhole_eye_from_a_prior_whose_starts_are_off_it() {
        let truth = camera_grid(50.0, DVec3::ZERO);
        // The prior: a wider camera 1.2 away, its starts on its own near plane.
        let prior = camera_grid(70.0, DVec3::new(0.8, -0.5, 0.7));
        let data = seen_by(&truth, 16, 3);
        let (fitted, report, eye) = fit(&prior, &data).unwrap();
        assert!((eye - EYE).length() < 1e-9, "{eye}");
        assert!(report.max_angle_deg < 1e-6, "{report:?}");
        assert!(farthest_line(&fitted, EYE) < 1e-8);
        // The starts moved to the prior's near fraction 1 / 39 along the projectors.
        let d = fitted.ends()[4] - fitted.starts()[4];
        assert!((fitted.starts()[4] - (EYE + d / 39.0)).length() < 1e-8 * d.length());
        // `auto` takes it (the kept starts miss by degrees), and says so.
        let (kept, kept_report) = fit_with(&prior, &data, Starts::Kept).unwrap();
        assert!(kept_report.max_angle_deg > 0.1, "{kept_report:?}");
        assert_eq!(kept_report.starts, FittedStarts::Kept);
        let (auto, auto_report) = fit_with(&prior, &data, Starts::Auto).unwrap();
        assert_eq!(auto, fitted);
        assert!(matches!(auto_report.starts, FittedStarts::Eye(e) if e == eye));
        assert_ne!(kept, fitted);
    }

    #[test]
    fn auto_keeps_exact_kept_starts_bit_for_bit() {
        let truth = camera_grid(50.0, DVec3::ZERO);
        // The prior has the truth's starts: the kept fit is exact, and `auto` is that fit.
        let prior = truth
            .with_ends(camera_grid(80.0, DVec3::ZERO).ends().to_vec())
            .unwrap();
        let data = seen_by(&truth, 30, 5);
        let kept = super::super::fit(&prior, &data).unwrap();
        assert!(kept.1.max_angle_deg < 1e-6);
        let (grid, report) = fit_with(&prior, &data, Starts::Auto).unwrap();
        assert_eq!(grid, kept.0);
        assert_eq!(report.starts, FittedStarts::Kept);
        assert_eq!(
            (report.max_angle_deg, report.rms_angle_deg),
            (kept.1.max_angle_deg, kept.1.rms_angle_deg)
        );
    }

    #[test]
    fn too_few_points_curved_priors_and_undetermined_eyes_are_refused() {
        let truth = camera_grid(50.0, DVec3::ZERO);
        let prior = camera_grid(70.0, DVec3::new(0.8, -0.5, 0.7));
        let five = seen_by(&truth, 5, 3);
        let e = fit(&prior, &five).unwrap_err();
        assert!(e.message.contains("at least 6 correspondences"), "{e}");
        // Eight points on one line through the eye, at one (u, v): any eye on that line
        // meets them.
        let uv = DVec2::new(0.3, 0.6);
        let line: Vec<_> = (0..8)
            .map(|k| Correspondence {
                uv,
                point: truth.point(uv, 0.1 + 0.1 * f64::from(k)),
            })
            .collect();
        let e = fit(&prior, &line).unwrap_err();
        assert!(e.message.contains("do not determine an eye"), "{e}");
        // Six and twelve points, fewer equations than a 3 x 3 grid's 27 free direction
        // unknowns (the free directions absorb any move of the eye): the pinhole field's
        // 8 unknowns still determine it, and every projector, not only the points', is the
        // camera's.
        for count in [6, 12] {
            let (fitted, _, eye) = fit(&prior, &seen_by(&truth, count, 3)).unwrap();
            assert!((eye - EYE).length() < 1e-8, "{count}: {eye}");
            assert!(farthest_line(&fitted, EYE) < 1e-7, "{count}");
            for uv in [
                DVec2::new(0.9, 0.1),
                DVec2::new(0.05, 0.95),
                DVec2::splat(0.5),
            ] {
                let along = |g: &ProjectorGrid| {
                    let (s, e) = g.start_end(uv);
                    (e - s).normalize()
                };
                assert!(
                    (along(&fitted) - along(&truth)).length() < 1e-8,
                    "{count} {uv}"
                );
            }
        }
        // Twenty points on one plane (z = -5, across the view): from any eye the plane's
        // points are affine in (u, v), which a bilinear grid meets exactly.
        let plane: Vec<_> = seen_by(&truth, 20, 4)
            .into_iter()
            .map(|c| {
                let (s, e) = truth.start_end(c.uv);
                let t = (-5.0 - s.z) / (e.z - s.z);
                Correspondence {
                    point: s + t * (e - s),
                    ..c
                }
            })
            .collect();
        let e = fit(&prior, &plane).unwrap_err();
        assert!(e.message.contains("do not determine an eye"), "{e}");
        // `auto` then keeps the prior's starts.
        let (_, report) = fit_with(&prior, &line, Starts::Auto).unwrap();
        assert_eq!(report.starts, FittedStarts::Kept);
        // A curved prior has no common eye.
        let mut curved = prior.clone();
        let (s, end) = (curved.starts()[4], curved.ends()[4]);
        curved
            .set_projector((1, 1), s, end, Some((end - s).normalize() + DVec3::X * 0.1))
            .unwrap();
        let e = fit(&curved, &seen_by(&truth, 16, 3)).unwrap_err();
        assert!(e.message.contains("has tangents"), "{e}");
        // All points at one place.
        let same = vec![five[0]; 8];
        assert!(fit(&prior, &same).unwrap_err().message.contains("coincide"));
    }

    #[test]
    fn wild_nodes_are_counted_and_undetermined_ones_only_where_the_model_leaves_them_open() {
        let prior = camera_grid(60.0, DVec3::ZERO);
        let data = seen_by(&prior, 40, 9);
        let (grid, report) = fit_with(&prior, &data, Starts::Kept).unwrap();
        assert_eq!(
            (report.wild_nodes, report.sparse_nodes),
            (0, 0),
            "{report:?}"
        );
        assert!(report.warning().is_none());
        // Node 0 ten times as long, node 8 turned by 90 degrees: both wild.
        let mut ends = grid.ends().to_vec();
        ends[0] = grid.starts()[0] + 10.0 * (ends[0] - grid.starts()[0]);
        let d = ends[8] - grid.starts()[8];
        ends[8] = grid.starts()[8] + d.cross(DVec3::Y).normalize() * d.length();
        let wild = grid.with_ends(ends).unwrap();
        assert_eq!(super::super::wild_nodes(&prior, &wild, &data), 2);
        // Kept starts, three points in the lower left cell: its four nodes' 12 direction
        // unknowns against 6 equations are undetermined, and the user is told.
        let cell: Vec<_> = data
            .iter()
            .filter(|c| c.uv.max_element() < 0.5)
            .take(3)
            .copied()
            .collect();
        assert_eq!(cell.len(), 3);
        let (_, report) = fit_with(&prior, &cell, Starts::Kept).unwrap();
        assert_eq!(report.sparse_nodes, 4, "{report:?}");
        assert!(report.warning().unwrap().contains("not determined"));
        // A pinhole off the prior's eye recovered exactly from 8 points: some nodes carry
        // little weight (the old summed-weight rule warned of them), but the pinhole's field
        // determines every node: no warning.
        let truth = camera_grid(50.0, DVec3::ZERO);
        let off = camera_grid(70.0, DVec3::new(0.8, -0.5, 0.7));
        let eight = seen_by(&truth, 8, 3);
        assert!(super::super::thinly_weighted_nodes(&off, &eight) > 0);
        let (fitted, report) = fit_with(&off, &eight, Starts::Auto).unwrap();
        assert!(matches!(report.starts, FittedStarts::Eye(_)), "{report:?}");
        assert!(farthest_line(&fitted, EYE) < 1e-7);
        assert_eq!(report.sparse_nodes, 0, "{report:?}");
        assert!(report.warning().is_none());
    }

    /// A 5 x 5 bilinear grid of a `fov`-degree perspective camera (near 1, far 40).
    fn grid_of(fov: f64) -> ProjectorGrid {
        ProjectorGrid::sample(
            &perspective(fov, [1.0, 40.0]),
            (5, 5),
            GridInterpolation::Bilinear,
        )
        .unwrap()
    }

    /// `count` points on the floor (y = 0) seen by `truth`, their image positions moved by up
    /// to 0.005 (seeded) within the image, and one point off the floor.
    fn nearly_coplanar(truth: &ProjectorGrid, count: usize, seed: u64) -> Vec<Correspondence> {
        let mut data: Vec<_> = seen_by(truth, 3 * count, seed)
            .into_iter()
            .filter_map(|c| {
                let (s, e) = truth.start_end(c.uv);
                let t = -s.y / (e.y - s.y);
                (t > 0.0 && t < 1.0).then(|| Correspondence {
                    point: s + t * (e - s),
                    ..c
                })
            })
            .take(count)
            .collect();
        let mut draw = lcg_uniform(seed);
        let mut next = || draw() - 0.5;
        for c in &mut data {
            // Kept in the image, as clicks are.
            c.uv = (c.uv + DVec2::new(next(), next()) * 0.01).clamp(DVec2::ZERO, DVec2::ONE);
        }
        data.push(seen_by(truth, 1, seed + 100)[0]);
        data
    }

    #[test]
    fn nearly_coplanar_noisy_points_get_the_square_pixel_camera() {
        // The general camera matrix these data determine keeps a point behind its eye, and
        // 22 or 42 equations leave the free directions' 75 unknowns no determined eye. The
        // eye model fits the square-pixel camera instead of erroring, and says so.
        let (truth, prior) = (grid_of(50.0), grid_of(70.0));
        for (seed, count) in [(0u64, 10usize), (10, 20)] {
            let data = nearly_coplanar(&truth, count, seed);
            let setup = Setup::new(&prior, &data).unwrap();
            assert!(setup.camera().is_some() && setup.pinhole_fit().is_none());
            let (_, report, _) = fit(&prior, &data).unwrap();
            assert!(report.square_pixel_camera, "{seed}: {report:?}");
            assert!(report.warning().unwrap().contains("square pixels"));
            assert!(report.rms_angle_deg < 0.3, "{seed}: {report:?}");
        }
    }

    #[test]
    fn nearly_coplanar_noisy_points_give_the_true_eye() {
        // 10 to 20 floor points with click noise and one point off the floor leave the
        // general camera matrix nearly free: its least-squares eye lies in the floor, and
        // seen from there every floor point lies near one plane of directions, so its misses
        // as angles are smaller than the true camera's. Every one of the 36 cases fits
        // (the square-pixel camera's starts moved back where a point lies behind them), with
        // the eye within 0.1 of the truth's at a distance of 5 and the misses of the click
        // noise (0.005 of the image, about 0.25 degrees at most).
        let (truth, prior) = (grid_of(50.0), grid_of(70.0));
        for seed in 0u64..12 {
            for count in [10usize, 14, 20] {
                let data = nearly_coplanar(&truth, count, seed);
                let (_, report, eye) = fit(&prior, &data)
                    .unwrap_or_else(|e| panic!("seed {seed}, {count} points: {e}"));
                assert!(
                    (eye - EYE).length() < 0.1 && report.rms_angle_deg < 0.3,
                    "seed {seed}, {count} points: eye {eye}, {report:?}"
                );
            }
        }
    }

    #[test]
    fn a_square_pixel_camera_from_a_nearly_degenerate_camera_matrix_is_rigid() {
        // Nearly coplanar points make the camera matrix's rows nearly dependent; its split
        // into K R still gives a rotation, so that the fitted camera's projector through a
        // pixel comes back to that pixel (a skewed frame would not).
        let (truth, prior) = (grid_of(50.0), grid_of(70.0));
        for seed in 0u64..12 {
            let data = nearly_coplanar(&truth, 10, seed);
            let camera = PinholeCamera::fit(&data, ImageShape::of_prior(&prior)).unwrap();
            for c in &data {
                let back = camera
                    .project(camera.eye() + camera.direction(c.uv))
                    .unwrap();
                assert!(
                    (back - c.uv).length() < 1e-9,
                    "seed {seed}: {back} {}",
                    c.uv
                );
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// The central fit inverts a pinhole camera: its eye comes back from any 16 of its
        /// points, whatever the prior's position.
        #[test]
        fn the_eye_of_any_pinhole_camera_comes_back(
            fov in 20.0f64..120.0,
            offset in prop::array::uniform3(-2.0f64..2.0),
            moved in prop::array::uniform3(-1.5f64..1.5),
            seed in 0u64..1000,
        ) {
            let truth = camera_grid(fov, DVec3::from(offset));
            let prior = camera_grid(60.0, DVec3::from(moved));
            let data = seen_by(&truth, 16, seed);
            let (_, report, eye) = fit(&prior, &data).unwrap();
            prop_assert!((eye - (EYE + DVec3::from(offset))).length() < 1e-7, "{eye}");
            prop_assert!(report.max_angle_deg < 1e-5, "{report:?}");
        }
    }
}
