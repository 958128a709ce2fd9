//! What rasterisation by the analytic inverse needs from a projection beyond
//! [`super::AnalyticInverse::project`]: where the image of a scene point is a continuous
//! function of the point, so that a triangle can be drawn from the images of its corners (and
//! of its edge midpoints, when it is subdivided).
//!
//! [`super::ContinuousInverse::project_continuous`] gives the image on the continuous branch,
//! also outside the image rectangle and outside the projection's visible domain (a fisheye point
//! beyond its field of view, a flexible point with t or (u, v) outside [0, 1]), so that a
//! triangle reaching out of the view is cut by the screen clip instead of being lost. The
//! [`InverseChart`] says where that branch stops being continuous:
//! - [`HalfSpace`]s: triangles are clipped to them in 3D before projection (the plane through
//!   a perspective eye, beyond which images flip; the near and far ends of a flexible volume
//!   between planes);
//! - a horizontal `period`: panoramas whose longitude is linear in x repeat every `period`
//!   pixels, and an image position is only known up to a multiple of it (the seam);
//! - [`Pole`]s: rays from a centre along which the longitude is undefined; a triangle they
//!   cross has no image that a polygon can describe, but the part of it within the pole's
//!   `clearance` maps beyond every pixel centre and can be left out.

use glam::DVec3;

/// The points `p` with `normal . p >= offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// The boundary plane's normal, pointing inside (any length: it scales `offset`).
    pub normal: DVec3,
    /// `normal . p` on the boundary plane.
    pub offset: f64,
}

impl HalfSpace {
    /// `normal . p - offset`: zero on the boundary, positive inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// A singular ray of a panorama: the points `origin + s direction`, s > 0, have no single
/// image (a pole of an equirectangular image: a whole row; the axis behind a fisheye: the
/// whole image circle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pole {
    /// Where the singular ray starts (the panorama's centre).
    pub origin: DVec3,
    /// Unit length.
    pub direction: DVec3,
    /// Radians: every pixel centre's projector keeps at least this angle from `direction` as
    /// seen from `origin`, so a part of a triangle lying within this angle of the pole covers
    /// no pixel centre.
    pub clearance: f64,
}

/// How the continuous inverse of a projection may be used by a rasteriser.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InverseChart {
    /// Triangles are clipped to the intersection of these before projection.
    pub clip: Vec<HalfSpace>,
    /// The horizontal period of the image in pixels, for panoramas (`None`: no wrap).
    pub period: Option<f64>,
    /// The singular rays triangles must not cross, each with its clearance.
    pub poles: Vec<Pole>,
}

/// How far in front of a perspective eye triangles are clipped (world units): the plane
/// through the eye maps to infinity, so it cannot be reached; what lies closer than this to
/// the eye plane is not drawn.
pub const EYE_CLEARANCE: f64 = 1e-6;

/// The two poles `origin +- axis` of a panorama whose pixel centres lie between latitudes
/// `lowest` and `highest` (radians, measured from the plane perpendicular to `axis`).
pub fn axis_poles(origin: DVec3, axis: DVec3, lowest: f64, highest: f64) -> Vec<Pole> {
    let quarter = std::f64::consts::FRAC_PI_2;
    vec![
        Pole {
            origin,
            direction: axis,
            clearance: (quarter - highest).max(0.0),
        },
        Pole {
            origin,
            direction: -axis,
            clearance: (quarter + lowest).max(0.0),
        },
    ]
}
