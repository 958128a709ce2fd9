//! How the trilinear renderer follows the curved edges of projected scene triangles (Vallance 2005,
//! section 4.5): the image of a straight scene edge under a trilinear projection is a curve,
//! and a shape's polygon of vertex images only approximates it.
//!
//! - [`CurveMode::Tessellate`]: cut each scene triangle into `steps^2` smaller triangles
//!   (`steps` segments per scene edge) and project those with straight edges.
//! - [`CurveMode::Slice`]: the thesis's parametric slicing: `steps` depths evenly spaced in
//!   `[max(0, t_min), t_max]` of each shape; each polygon edge gets the exact image of its
//!   scene edge at every slice depth within its own depth range.
//! - [`CurveMode::Adaptive`] (the default): each polygon edge is bisected in depth while the
//!   exact image may lie more than [`ADAPTIVE_TOLERANCE_PX`] pixels off the chord anywhere
//!   along the piece (a bound from three exact samples), up to `steps` segments per edge
//!   piece (see `edge_path::refine` for the rule).

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// Largest distance, in pixels, between the exact image of a scene edge and the chord drawn
/// for it anywhere along a segment (a bound over the whole segment, `edge_path::refine`),
/// before adaptive slicing splits the segment.
///
/// Why this value: the renderer tests every fragment exactly against its scene triangle (the
/// pixel's ray is intersected with it), so a chord that bulges *outside* the true curve costs
/// nothing, and one that cuts *inside* it loses the pixel centres in a sliver at most this
/// wide (and two triangles sharing an edge but sampling it at different depths leave a crack
/// as wide). The chord's deviation falls with the square of its length, so a tighter bound
/// costs few points: on the trilinear examples at 800 x 800, 0.02 px instead of 0.25 px
/// takes 0 to 11 % more outline points and cuts the relative RGB error against the ray
/// caster 3 to 10 times (the fan 0.000125 -> 0.000012, two views 0.000048 -> 0.000008),
/// and keeps the edges of the inverse-perspective example, lined up with rows of pixel
/// centres, as close as 32 forced segments a piece did (0.000015; at 0.25 px 0.000066).
pub const ADAPTIVE_TOLERANCE_PX: f64 = 0.02;

/// The curve-following strategy (`--curves`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CurveMode {
    /// Scene-triangle tessellation.
    Tessellate,
    /// Parametric slicing with a fixed number of slices per shape.
    Slice,
    /// Slicing refined per edge from a screen-space error bound.
    #[default]
    Adaptive,
}

impl CurveMode {
    /// Every mode with its command-line name.
    pub const ALL: [(&'static str, CurveMode); 3] = [
        ("tessellate", CurveMode::Tessellate),
        ("slice", CurveMode::Slice),
        ("adaptive", CurveMode::Adaptive),
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            CurveMode::Tessellate => "tessellate",
            CurveMode::Slice => "slice",
            CurveMode::Adaptive => "adaptive",
        }
    }

    /// The `steps` used when none is given: 8 segments per scene edge (64 sub-triangles), the
    /// thesis's smallest slicing factor of 10, and at most 256 segments per edge piece.
    pub fn default_steps(self) -> u32 {
        match self {
            CurveMode::Tessellate => 8,
            CurveMode::Slice => 10,
            CurveMode::Adaptive => 256,
        }
    }
}

impl FromStr for CurveMode {
    type Err = Error;

    fn from_str(s: &str) -> Result<CurveMode> {
        CurveMode::ALL
            .iter()
            .find(|(name, _)| *name == s)
            .map(|(_, m)| *m)
            .ok_or_else(|| {
                Error::new(format!(
                    "unknown curve mode \"{s}\" (available: tessellate, slice, adaptive)"
                ))
            })
    }
}

impl fmt::Display for CurveMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Largest accepted `steps`: tessellation makes `steps^2` triangles per scene triangle.
pub const MAX_STEPS: u32 = 1024;

/// The curve strategy and its step count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveOptions {
    /// How curved edges are followed (`--curves`).
    pub mode: CurveMode,
    /// Segments per scene edge (tessellate), slices per shape (slice) or the most segments
    /// per edge piece (adaptive); 1 to `MAX_STEPS`.
    pub steps: u32,
    /// Scene-space clipping (Vallance 2005, chapter 5; the default): outlines get exact anchors
    /// where their scene edges cross the projection triangle's edge surfaces, so images are
    /// continuous across projection edges. Without it (the thesis's cheaper variant, timed
    /// by `flexcam bench trilinear`) outlines are clipped to the screen triangle by
    /// interpolating their chords, which leaves cracks along curved projection edges.
    pub scene_clipping: bool,
}

impl CurveOptions {
    /// Adaptive slicing with its default cap.
    pub const ADAPTIVE: CurveOptions = CurveOptions {
        mode: CurveMode::Adaptive,
        steps: 256,
        scene_clipping: true,
    };

    /// `mode` with `steps`, or the mode's default steps when `None`. Errors: `steps` outside
    /// 1 to `MAX_STEPS`.
    pub fn new(mode: CurveMode, steps: Option<u32>) -> Result<CurveOptions> {
        let steps = steps.unwrap_or(mode.default_steps());
        if !(1..=MAX_STEPS).contains(&steps) {
            return Err(Error::new(format!(
                "curve steps must be between 1 and {MAX_STEPS}, got {steps}"
            )));
        }
        Ok(CurveOptions {
            mode,
            steps,
            scene_clipping: true,
        })
    }
}

impl Default for CurveOptions {
    fn default() -> Self {
        CurveOptions::ADAPTIVE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_steps_are_checked() {
        for (name, mode) in CurveMode::ALL {
            assert_eq!(name.parse::<CurveMode>().unwrap(), mode);
            assert_eq!(mode.to_string(), name);
        }
        assert!("bezier".parse::<CurveMode>().is_err());
        assert_eq!(
            CurveOptions::new(CurveMode::Adaptive, None).unwrap(),
            CurveOptions::ADAPTIVE
        );
        assert_eq!(
            CurveOptions::new(CurveMode::Slice, Some(50)).unwrap().steps,
            50
        );
        let e = CurveOptions::new(CurveMode::Slice, Some(0)).unwrap_err();
        assert!(e.to_string().contains("between 1 and 1024, got 0"), "{e}");
        assert!(CurveOptions::new(CurveMode::Tessellate, Some(MAX_STEPS + 1)).is_err());
    }
}
