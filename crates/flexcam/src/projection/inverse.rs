//! The analytic inverse of a projection, an optional capability: [`super::Projection::inverse`]
//! gives it as an [`AnalyticInverse`] or says why there is none ([`NoInverse`]).
//!
//! An inverse that is one continuous map a rasteriser can fill triangles by is reached
//! further through [`AnalyticInverse::charted`]: its [`InverseChart`] and the map itself
//! ([`ContinuousInverse`]). Renderers look a capability up once per render and call through
//! the returned object per point, one dynamic call as for any projection method.

use glam::{DVec2, DVec3};

use super::{CameraBasis, ImagePoint, ImageSegment, InverseChart};

/// Why a projection has no analytic inverse.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoInverse {
    /// The reason, where the projection's kind may have an inverse but this one has not (a
    /// panorama shape outside the lookup's class, a flexible volume with curved projectors),
    /// for error messages; `None` where the kind has none at all.
    pub reason: Option<String>,
}

/// The inverse of a projection: every image position of a scene point.
pub trait AnalyticInverse: Send + Sync {
    /// Appends to `out` every image position of scene point `point`, each with the ray
    /// parameter that reaches it: zero, one or several (a trilinear mesh can fold).
    fn project(&self, point: DVec3, out: &mut Vec<ImagePoint>);

    /// Appends to `out` every image of `point` that is a whole segment of image positions
    /// (each seeing the point along the same ray), where a projection has such images: a
    /// trilinear mesh's triangles whose rays form a fan. None by default.
    fn project_segments(&self, point: DVec3, out: &mut Vec<ImageSegment>) {
        let _ = (point, out);
    }

    /// The inverse as a continuous map with its chart (see [`super::chart`]); `None` where it
    /// folds or jumps in ways a chart cannot describe.
    fn charted(&self) -> Option<Charted<'_>>;
}

/// A continuous inverse and the chart that describes where it is continuous.
#[derive(Clone)]
pub struct Charted<'a> {
    /// Where `map` is continuous.
    pub chart: InverseChart,
    /// The continuous branch of the inverse.
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

    /// The branch's pixels in two stages, where it has them ([`StagedInverse`]); `None` by
    /// default.
    fn staged(&self) -> Option<&dyn StagedInverse> {
        None
    }
}

/// A continuous inverse whose pixel is computed in two stages: coordinates of the point
/// that depend only on what [`StagedInverse::key`] names (a panorama's longitude and
/// latitude: the eye and its frame), then the pixel from those coordinates (dividing by
/// the angle per pixel: the fields of view and image size). A renderer of many frames keeps
/// the first stage's results while the key stays the same (a field-of-view slider dragged
/// in a viewer) and redoes only the second.
pub trait StagedInverse: Send + Sync {
    /// Everything [`StagedInverse::coordinates`] reads: which first stage (the projection's
    /// kind) and the bits of the camera basis it uses. Equal keys give equal coordinates.
    fn key(&self) -> StageKey;

    /// The first stage: `None` exactly where [`ContinuousInverse::project_continuous`] is
    /// `None` (the singular set).
    fn coordinates(&self, point: DVec3) -> Option<DVec2>;

    /// The second stage: from `coordinates` of a point, the pixel
    /// [`ContinuousInverse::project_continuous`] gives it, the same bits.
    fn pixel(&self, coordinates: DVec2) -> DVec2;
}

/// What the first stage of a [`StagedInverse`] depends on: its kind and the bits of the
/// camera basis (origin, right, up, forward).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StageKey {
    /// The first stage's name (the projection's kind).
    pub kind: &'static str,
    /// The basis's components as bits.
    pub basis: [u64; 12],
}

impl StageKey {
    /// The key of first stage `kind` reading `basis`.
    pub fn new(kind: &'static str, basis: &CameraBasis) -> Self {
        let mut bits = [0; 12];
        let vectors = [basis.origin, basis.right, basis.up, basis.forward];
        for (k, v) in vectors.iter().enumerate() {
            for (i, c) in v.to_array().into_iter().enumerate() {
                bits[3 * k + i] = c.to_bits();
            }
        }
        StageKey { kind, basis: bits }
    }
}

/// An image on the continuous branch of a [`SingleImage`] projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchImage {
    /// The point's position on the branch, and its ray parameter.
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

    /// The branch's pixels in two stages, where it has them; `None` by default.
    fn staged(&self) -> Option<&dyn StagedInverse> {
        None
    }
}

impl<T: SingleImage> ContinuousInverse for T {
    fn project_continuous(&self, point: DVec3) -> Option<ImagePoint> {
        self.branch_image(point).map(|b| b.image)
    }

    fn staged(&self) -> Option<&dyn StagedInverse> {
        SingleImage::staged(self)
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

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_4;
    use std::sync::Arc;

    use glam::{DVec2, DVec3};

    use crate::projection::flexible::panorama::{OutlineShape, ProfileShape};
    use crate::projection::flexible::{
        FlexibleSpec, PanoramaShape, PanoramaSpec, Reparam, Surface, VolumeSource,
    };
    use crate::projection::{CameraFrame, ProjectionSpec, TrilinearMesh};

    fn frame() -> CameraFrame {
        CameraFrame {
            position: DVec3::new(0.5, 1.0, 4.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
        }
    }

    fn panorama(profile: ProfileShape, reparam: Option<Reparam>) -> ProjectionSpec {
        let shape = PanoramaShape::single(
            OutlineShape::Circle.curve().unwrap(),
            profile.curve().unwrap(),
        )
        .unwrap();
        ProjectionSpec::Flexible(Box::new(FlexibleSpec {
            source: VolumeSource::Panorama(PanoramaSpec {
                shape: Arc::new(shape),
                frame: frame(),
                clip: None,
            }),
            reparam,
        }))
    }

    /// A projection and what it answers: an inverse with a chart or without (`Ok`), or none
    /// and a part of the reason's text (`Err`); whether it is a trilinear mesh.
    type Case = (ProjectionSpec, Result<bool, &'static str>, bool);

    /// What each kind answers: an inverse, the reason for none, a chart, the trilinear
    /// structure.
    #[test]
    fn every_kind_reports_its_capabilities() {
        let frame = frame();
        let segment = || ProfileShape::Segment {
            elevation: [-FRAC_PI_4, FRAC_PI_4],
        };
        let folded = ProfileShape::Points(
            [[1.0, 0.0], [1.0, 2.0], [3.0, 1.0]]
                .map(DVec2::from_array)
                .to_vec(),
        );
        let twisted = Surface::Bilinear {
            corners: [
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(1.0, -1.0, 0.5),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 1.0, 0.0),
            ],
        };
        let surfaces = ProjectionSpec::Flexible(Box::new(FlexibleSpec {
            source: VolumeSource::Surfaces {
                near: twisted,
                far: Surface::rectangle_centred(DVec3::Z * 2.0, DVec3::X, DVec3::Y),
            },
            reparam: None,
        }));
        let trilinear = ProjectionSpec::Trilinear(TrilinearMesh {
            points: vec![DVec3::ZERO; 3],
            normals: vec![DVec3::Z; 3],
            screen: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            triangles: vec![[0, 1, 2]],
        });
        let single = |spec: ProjectionSpec| (spec, Ok(true), false);
        let cases: Vec<Case> = vec![
            single(ProjectionSpec::Perspective { frame, fov: 60.0 }),
            single(ProjectionSpec::Orthographic { frame, width: 3.0 }),
            single(ProjectionSpec::Fisheye { frame, fov: 180.0 }),
            single(ProjectionSpec::Equirectangular {
                frame,
                h_fov: 360.0,
                v_fov: 180.0,
            }),
            single(ProjectionSpec::Cylindrical {
                frame,
                h_fov: 360.0,
                v_fov: 90.0,
            }),
            // The stereo pairs: an image per eye, two branches without a chart.
            (
                ProjectionSpec::Ods {
                    frame,
                    ipd: 0.064,
                    pole_merge: Some([60.0, 75.0]),
                },
                Ok(false),
                false,
            ),
            (
                ProjectionSpec::Vr180 { frame, ipd: 0.064 },
                Ok(false),
                false,
            ),
            // The mesh folds: an inverse without a chart.
            (trilinear, Ok(false), true),
            // A panorama in the lookup's class, with a chart under the linear map only.
            (panorama(segment(), None), Ok(true), false),
            (panorama(segment(), Some(Reparam::Polar)), Ok(false), false),
            // Outside the lookup's class, or the scanline class of curved projectors: the
            // reason.
            (
                panorama(folded, None),
                Err("profile does not rise strictly"),
                false,
            ),
            (surfaces, Err("outside the scanline class"), false),
        ];
        for (spec, inverse, trilinear) in cases {
            let projection = spec.build(32, 16).unwrap();
            let kind = projection.kind();
            assert_eq!(kind, spec.kind());
            match (projection.inverse(), inverse) {
                (Ok(found), Ok(charted)) => {
                    assert_eq!(found.charted().is_some(), charted, "{kind}");
                }
                (Err(none), Err(reason)) => {
                    let why = none.reason.unwrap();
                    assert!(why.contains(reason), "{kind}: {why}");
                }
                (found, expected) => panic!(
                    "{kind}: inverse {:?}, expected {expected:?}",
                    found.map(|_| ())
                ),
            }
            assert_eq!(projection.trilinear().is_some(), trilinear, "{kind}");
        }
    }
}
