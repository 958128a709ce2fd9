//! Calibration: fitting projections to what a scene must show. This layer sits above
//! [`crate::projection`]: it builds projections (the projection types never call it) and is
//! used by the scene loader and the `flexcam fit` command.
//!
//! - [`grid`]: a projector grid's node projectors aimed at point correspondences by least
//!   squares, with the model of the projectors' starts chosen from the data.
//!
//! [`build`] builds any projection spec, fitting the projector grids that carry
//! correspondences (through the projection layer's [`GridFitter`] seam), and returns the
//! fits' residuals and warnings as a typed [`BuildReport`].

mod fit_memo;
pub mod grid;

use std::cell::RefCell;

pub use grid::{node_warning, FitReport, FittedStarts};

use crate::error::Result;
use crate::projection::flexible::{
    Correspondence, Flexible, FlexibleSpec, GridFitter, ProjectorGrid, Starts,
};
use crate::projection::{BuildReport, Projection, ProjectionSpec};

/// Builds `spec` for a `width` x `height` image, fitting its projector grids to their
/// correspondences. Errors: those of [`ProjectionSpec::build`] and of [`grid::fit_with`].
pub fn build(
    spec: &ProjectionSpec,
    width: u32,
    height: u32,
) -> Result<(Box<dyn Projection>, BuildReport)> {
    spec.build_fitted(width, height, &GridFit::default())
}

/// Builds a flexible projection, fitting its projector grids, with each fit's report in the
/// order the grids were fitted (a grid's base before the grid).
pub fn build_flexible(
    spec: &FlexibleSpec,
    width: u32,
    height: u32,
) -> Result<(Flexible, Vec<FitReport>)> {
    let fitter = GridFit::default();
    let flexible = Flexible::build(
        spec,
        width,
        height,
        Some(&fitter),
        &mut BuildReport::default(),
    )?;
    Ok((flexible, fitter.reports.into_inner()))
}

/// The projection layer's [`GridFitter`] by [`grid::fit_with`], keeping each fit's report.
#[derive(Default)]
struct GridFit {
    reports: RefCell<Vec<FitReport>>,
}

impl GridFitter for GridFit {
    fn fit(
        &self,
        prior: &ProjectorGrid,
        correspondences: &[Correspondence],
        starts: Starts,
    ) -> Result<(ProjectorGrid, BuildReport)> {
        let (grid, report) = fit_memo::fitted(prior, correspondences, starts, || {
            grid::fit_with(prior, correspondences, starts)
        })?;
        self.reports.borrow_mut().push(report);
        Ok((grid, build_report(&report)))
    }
}

/// A fit's residual and model as `--stats` counters, and its warning.
fn build_report(fit: &FitReport) -> BuildReport {
    let mut counters = vec![
        ("fit_correspondences", fit.correspondences as f64),
        ("fit_unconstrained_nodes", fit.unconstrained_nodes as f64),
        ("fit_max_angle_deg", fit.max_angle_deg),
        ("fit_rms_angle_deg", fit.rms_angle_deg),
        ("fit_wild_nodes", fit.wild_nodes as f64),
        ("fit_sparse_nodes", fit.sparse_nodes as f64),
    ];
    // 1 when the starts lie on projectors through a fitted eye (given next), were fitted per
    // node, or are those of one fitted pinhole camera (its eye given as well).
    let eye = match fit.starts {
        FittedStarts::Eye(eye) | FittedStarts::Pinhole(eye) => Some(eye),
        FittedStarts::Kept | FittedStarts::Free => None,
    };
    counters.push(("fit_starts_eye", f64::from(u8::from(eye.is_some()))));
    let free = fit.starts == FittedStarts::Free;
    counters.push(("fit_starts_free", f64::from(u8::from(free))));
    let pinhole = matches!(fit.starts, FittedStarts::Pinhole(_));
    counters.push(("fit_starts_pinhole", f64::from(u8::from(pinhole))));
    if fit.focal_from_prior {
        counters.push(("fit_focal_from_prior", 1.0));
    }
    if fit.square_pixel_camera {
        counters.push(("fit_square_pixel_camera", 1.0));
    }
    if fit.general_camera {
        counters.push(("fit_general_camera", 1.0));
    }
    if let Some(smoothness) = fit.smoothness {
        counters.push(("fit_smoothness", smoothness));
    }
    if let Some(iterations) = fit.curved_iterations {
        counters.push(("fit_curved_iterations", iterations as f64));
    }
    if let Some(eye) = eye {
        counters.extend([
            ("fit_eye_x", eye.x),
            ("fit_eye_y", eye.y),
            ("fit_eye_z", eye.z),
        ]);
    }
    BuildReport {
        counters,
        warnings: fit.warning().into_iter().collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example scene whose projector grid has five `fit` correspondences.
    fn fitted_example() -> ProjectionSpec {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/flexible-projector-fit.toml"
        );
        crate::scene::load(path).unwrap().projection
    }

    /// The projection layer does not fit: without the fitter a grid with correspondences is
    /// an error, never an unfitted grid; with it the fit's residual and warning come back as
    /// the typed report.
    #[test]
    fn grids_with_correspondences_are_built_only_through_calibrate() {
        let spec = fitted_example();
        let e = spec.build(64, 48).err().expect("built without the fit");
        assert!(e.message.contains("calibrate::build"), "{}", e.message);
        let (projection, report) = build(&spec, 64, 48).unwrap();
        assert_eq!(projection.kind(), "flexible");
        assert!(
            report.counters.contains(&("fit_correspondences", 5.0)),
            "{report:?}"
        );
        let rms = report
            .counters
            .iter()
            .find(|(name, _)| *name == "fit_rms_angle_deg");
        assert!(rms.is_some_and(|&(_, deg)| deg < 1e-9), "{report:?}");
        assert_eq!(report.warnings.len(), 1, "{report:?}");
        assert!(report.warnings[0].contains("not determined"), "{report:?}");
    }

    /// Projections without grids report nothing.
    #[test]
    fn explicit_projections_report_nothing() {
        let spec = ProjectionSpec::Perspective {
            frame: crate::projection::CameraFrame {
                position: glam::DVec3::Z,
                look_at: glam::DVec3::ZERO,
                up: glam::DVec3::Y,
            },
            fov: 60.0,
        };
        let (_, report) = build(&spec, 8, 8).unwrap();
        assert_eq!(report, BuildReport::default());
    }
}
