//! The analytic inverse of a projection, an optional capability: [`super::Projection::inverse`]
//! gives it as an [`AnalyticInverse`] or says why there is none ([`NoInverse`]).
//!
//! An inverse that is one continuous map a rasteriser can fill triangles by is reached
//! further through [`AnalyticInverse::charted`]: its [`InverseChart`] and the map itself
//! ([`ContinuousInverse`]). Renderers look a capability up once per render and call through
//! the returned object per point, one dynamic call as for any projection method.

use glam::DVec3;

use super::{ImagePoint, InverseChart};

/// Why a projection has no analytic inverse.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoInverse {
    /// The reason, where the projection's kind may have an inverse but this one has not (a
    /// panorama shape outside the lookup's class), for error messages; `None` where the
    /// kind has none at all (a volume between curved control surfaces).
    pub reason: Option<String>,
}

/// The inverse of a projection: every image position of a scene point.
pub trait AnalyticInverse: Send + Sync {
    /// Appends to `out` every image position of scene point `point`, each with the ray
    /// parameter that reaches it: zero, one or several (a trilinear mesh can fold).
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>);

    /// The inverse as a continuous map with its chart (see [`super::chart`]); `None` where it
    /// folds or jumps in ways a chart cannot describe.
    fn charted(&self) -> Option<Charted<'_>>;
}

/// A continuous inverse and the chart that describes where it is continuous.
#[derive(Clone)]
pub struct Charted<'a> {
    pub chart: InverseChart,
    pub map: &'a dyn ContinuousInverse,
}

impl std::fmt::Debug for Charted<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Charted")
            .field("chart", &self.chart)
            .finish_non_exhaustive()
    }
}

/// The continuous branch of an inverse described by an [`InverseChart`].
pub trait ContinuousInverse: Send + Sync {
    /// The image of `point` on the continuous branch: unclipped to the image and to the
    /// visible domain. `None` on the singular set (an eye, a pole).
    fn project_continuous(&self, point: DVec3) -> Option<ImagePoint>;
}

/// An image on the continuous branch of a [`SingleImage`] projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchImage {
    pub image: ImagePoint,
    /// Whether the projection sees the point there: the point is on the ray (orthographic
    /// rays start at `t = 0`) and inside the visible domain (a fisheye's field of view).
    pub seen: bool,
}

/// A projection whose inverse is one continuous branch over all of space, imaging each
/// point at most once: the inverse appends the branch's image where the projection sees it,
/// and the chart is the projection's own. Implementing this gives [`AnalyticInverse`] and
/// [`ContinuousInverse`], so the two never disagree.
pub trait SingleImage: Send + Sync {
    /// The image of `point` on the branch, `None` on the singular set.
    fn branch_image(&self, point: DVec3) -> Option<BranchImage>;

    /// Where the branch is continuous.
    fn chart(&self) -> InverseChart;
}

impl<T: SingleImage> ContinuousInverse for T {
    fn project_continuous(&self, point: DVec3) -> Option<ImagePoint> {
        self.branch_image(point).map(|b| b.image)
    }
}

impl<T: SingleImage> AnalyticInverse for T {
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>) {
        out.extend(self.branch_image(point).filter(|b| b.seen).map(|b| b.image));
    }

    fn charted(&self) -> Option<Charted<'_>> {
        Some(Charted {
            chart: self.chart(),
            map: self,
        })
    }
}
