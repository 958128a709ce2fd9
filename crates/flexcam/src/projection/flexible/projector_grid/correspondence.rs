//! What a projector grid is to be fitted to: point correspondences and the model of the
//! projectors' starts (scene keys `fit` and `starts`), and the seam through which the fit,
//! which lives above the projection layer (`crate::calibrate`), is handed to the build.
//!
//! The projection layer describes and builds grids; it does not fit them. A grid spec with
//! correspondences is built by [`GridVolume::build`](super::GridVolume::build) with a
//! [`GridFitter`]; without one such a spec is an error, never an unfitted grid.

use glam::{DVec2, DVec3};

use super::ProjectorGrid;
use crate::error::Result;
use crate::projection::BuildReport;

/// A scene point and the image position (u, v) in [0, 1]^2 (u right, v up) that must see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    /// The image position, in [0, 1]^2, u right, v up.
    pub uv: DVec2,
    /// The scene point it must see.
    pub point: DVec3,
}

/// Where the fitted grid's projectors start: the scene key `starts` (see `crate::calibrate`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Starts {
    /// The prior's starts are kept; only the node directions are fitted.
    Kept,
    /// One common eye is fitted with the directions; every projector passes through it.
    Eye,
    /// Every node's start is fitted with the directions.
    Free,
    /// One pinhole camera of square pixels, its principal point at the image centre (focal
    /// length and pose, 7 unknowns) or, where the data clearly support it, off centre (a
    /// cropped painting, 9 unknowns): the model of a painting drawn in true perspective.
    Pinhole,
    /// Exact data: the kept starts where they meet the data and determine the directions,
    /// else the eye where it meets the data exactly or clearly better, else the free starts
    /// where they meet the data clearly better. Inexact data: the simplest model (pinhole,
    /// eye, kept, free) that no richer one beats by the trimmed mean of their held-out misses
    /// (a fifth left out at each end), never a folded grid where another is not.
    #[default]
    Auto,
}

impl Starts {
    /// The scene file's names, in the order of the error message.
    pub const NAMES: [&'static str; 5] = ["auto", "kept", "eye", "free", "pinhole"];

    /// The model of a scene file name (`None` for any other).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Starts::Auto),
            "kept" => Some(Starts::Kept),
            "eye" => Some(Starts::Eye),
            "free" => Some(Starts::Free),
            "pinhole" => Some(Starts::Pinhole),
            _ => None,
        }
    }
}

/// Aims a projector grid at point correspondences: implemented by `crate::calibrate`, which
/// passes itself to the build of a projection whose grids have correspondences.
pub trait GridFitter {
    /// The grid fitted from the prior `prior` to `correspondences` with the starts model
    /// `starts`, and what the fit reports (its residual as counters, its warnings).
    fn fit(
        &self,
        prior: &ProjectorGrid,
        correspondences: &[Correspondence],
        starts: Starts,
    ) -> Result<(ProjectorGrid, BuildReport)>;
}
