//! [`RenderWarning`]: what a render found that its caller should tell the user. The frame is
//! made, but something asked of it did not fully hold.

use std::fmt;

/// A render-level warning, reported in [`crate::render::Rendered::warnings`]. Its
/// [`fmt::Display`] is one line, without a trailing full stop, for a user (the CLI prints it
/// on stderr after `warning:` and lists it in `--stats`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum RenderWarning {
    /// Refining the mesh of the trilinear reflector with object id `id` stopped (at its
    /// depth cap, or at edges shorter than a pixel) with `edges` edges whose interpolated
    /// rays still displace the reflected image by more than the reflector's tolerance
    /// `tolerance_px` (scene key `trilinear_refine_px`): the reflection may be off by more
    /// than that there.
    ReflectorOverTolerance {
        /// The reflector object's id.
        id: u32,
        /// The mesh edges still over the tolerance.
        edges: u64,
        /// The tolerance asked for, main-image pixels.
        tolerance_px: f64,
    },
}

impl fmt::Display for RenderWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderWarning::ReflectorOverTolerance {
                id,
                edges,
                tolerance_px,
            } => write!(
                f,
                "trilinear reflector {id}: {edges} edges of its surface still displace the \
                 reflection by more than trilinear_refine_px = {tolerance_px} pixels \
                 (refinement stopped at its depth cap or at sub-pixel edges)"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warning_is_one_line_naming_the_reflector_and_tolerance() {
        let line = RenderWarning::ReflectorOverTolerance {
            id: 3,
            edges: 12,
            tolerance_px: 0.5,
        }
        .to_string();
        assert_eq!(line.lines().count(), 1);
        assert!(
            line.starts_with("trilinear reflector 3: 12 edges"),
            "{line}"
        );
        assert!(line.contains("trilinear_refine_px = 0.5 pixels"), "{line}");
    }
}
