//! One pinhole camera as a photograph or a perspective painting has it: square pixels and no
//! skew, the principal point at the image centre, so that its focal length and pose (a
//! rotation and the eye) are its 7 unknowns, or off centre (a painting or photograph cropped
//! off-centre) where the data support it, 9 unknowns; fitted to point correspondences by
//! the reprojection error in the image (click noise is the same for every point there).
//!
//! Positions are measured in square image coordinates q = (u - 1/2, -h (v - 1/2) / a), in
//! image widths: a is the image's aspect (width over height) and h its handedness (+1 where
//! v runs up in a right-handed world, as in the presets), both read from the prior grid
//! ([`ImageShape::of_prior`]: the flexible projection's fitter is not told the image size).
//! The camera sees the point X at q = f (c_x, c_y) / c_z + p, c = R (X - E), with f > 0, R a
//! rotation, p the principal point (zero at the image centre), and c_z > 0 for every point
//! in front of it.
//!
//! Starts, each refined by Levenberg-Marquardt (rotation updates as rotation vectors) and the
//! one of least error kept: the general 3 x 4 camera matrix of module `camera_matrix` where
//! the points are not coplanar, split into K R (Gram-Schmidt from its third row) with f the
//! mean of its two focal lengths; and the homography from the points' best plane to the
//! image (Zhang 2000): with K = diag(f, f, 1), the columns h1, h2 of H ~ K (r1 r2 t) give
//! r1 . r2 = 0 and |r1| = |r2|, two equations linear in 1 / f^2, solved by least squares
//! (the prior's focal length where they give none within `FOCAL_RANGE` of it); the pose
//! then from K^-1 H's columns, (r1, r2) made orthonormal. Where every start keeps a point
//! behind it (the best plane of nearly coplanar points tilted by one point off it), the
//! starts are moved back along their viewing axes until every point is in front.
//!
//! The principal point: where there are at least `PRINCIPAL_MIN_POINTS` (9) points, not
//! coplanar (the camera matrix exists), and the focal length is determined, the 9-unknown
//! camera is fitted as well, from the camera
//! matrix's K R split with its own principal point (K's third column) and from the centred
//! camera, and kept where it is clearly better by the nested least-squares rule of module
//! `nested_models` (`clearly_better`: its sum of squares lower by more than 4 noise variances per
//! extra unknown, about a 2 % chance on data of a centred camera) and its normal matrix is
//! regular (the principal point trades against the rotation, so its spread may be large
//! while the image is well met). One plane does not
//! determine focal length and principal point together (Zhang's two equations for three
//! unknowns), so coplanar points keep the centred camera.
//!
//! Degenerate cases ([`Undetermined`], each tested): fewer than 4 points (7 unknowns, 2
//! equations a point); the points all on one line or at one position (no plane: the camera
//! may turn about the line); the image positions all on one line (the points lie in one
//! plane through the eye: a plane seen edge-on, met from any eye in it); no start that keeps
//! the points in front. The focal length alone is unobservable when the points lie on a
//! plane seen face on (fronto-parallel: a larger f and a farther eye give the same image);
//! where its standard error exceeds `FOCAL_SPREAD` of its value (or the normal matrix is
//! singular), the fit keeps the prior's focal length, fits the pose alone (from the best
//! pose, its eye's distance from the points' centre scaled by the focal lengths' ratio, and
//! from the homography with the prior's focal length) and says so
//! ([`PinholeCamera::focal_from_prior`]).

use std::cmp::Ordering;

use glam::{DMat3, DVec2, DVec3};
use nalgebra::{DMatrix, Matrix3, SymmetricEigen};

use super::camera_matrix::{normalisation, CameraMatrix};
use super::nested_models::clearly_better;
use super::{dense_lm, Correspondence};
use crate::projection::flexible::ProjectorGrid;

/// The fewest correspondences: 7 unknowns, 2 equations a point.
pub(super) const MIN_POINTS: usize = 4;

/// A spread (an eigenvalue of the points' or image positions' covariance) below this
/// fraction of the largest is taken as none: the points on one line, the image positions
/// on one line.
const FLAT: f64 = 1e-12;

/// Levenberg-Marquardt iterations at most.
const MAX_ITERATIONS: usize = 100;

/// The focal length is taken as undetermined when its standard error exceeds this fraction
/// of its value.
const FOCAL_SPREAD: f64 = 0.25;

/// The homography's focal length is taken as a start only within this factor of the
/// prior's: beyond it the data (a plane seen nearly face on) hardly determine it, and a far
/// start (a focal length of thousands of image widths, an eye as far) is where the descent
/// would stay.
const FOCAL_RANGE: f64 = 100.0;

/// The least depth (in the points' spread) of every point in front of a start
/// ([`Data::in_front`]).
const FRONT_MARGIN: f64 = 0.25;

/// The least noise (image widths) the focal length's standard error is computed with: exact
/// data miss by rounding only, and a focal length they leave free must still show as free.
const NOISE_FLOOR: f64 = 1e-7;

/// The image the prior grid draws: its aspect, its handedness and, seen as a pinhole, its
/// focal length (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ImageShape {
    /// Width over height.
    pub(super) aspect: f64,
    /// +1 where v runs up in a right-handed world (square image y runs down), -1 mirrored.
    pub(super) handedness: f64,
    /// The focal length in image widths: 1 / (2 tan(horizontal field of view / 2)).
    pub(super) focal: f64,
}

impl ImageShape {
    /// The shape of `prior`'s image seen as a pinhole: its straight projectors' directions
    /// at u = 1/4 and 3/4 (and v so) taken to the plane one unit along the centre's direction;
    /// their spans give the focal length and the aspect, their cross product's side the
    /// handedness. A prior seen from no such plane (its directions at those positions
    /// turned 90 degrees or more from the centre's) is taken as square, right-handed, with a
    /// focal length of 1 (a 53-degree field of view).
    pub(super) fn of_prior(prior: &ProjectorGrid) -> ImageShape {
        let direction = |u: f64, v: f64| {
            let (start, end) = prior.start_end(DVec2::new(u, v));
            end - start
        };
        let axis = direction(0.5, 0.5).normalize_or_zero();
        let on_plane = |u: f64, v: f64| {
            let d = direction(u, v);
            let depth = d.dot(axis);
            (depth > 0.0).then(|| d / depth)
        };
        let measured = || {
            let across = 2.0 * (on_plane(0.75, 0.5)? - on_plane(0.25, 0.5)?);
            let up = 2.0 * (on_plane(0.5, 0.75)? - on_plane(0.5, 0.25)?);
            let shape = ImageShape {
                aspect: across.length() / up.length(),
                handedness: if across.cross(up).dot(axis) > 0.0 {
                    -1.0
                } else {
                    1.0
                },
                focal: 1.0 / across.length(),
            };
            let usable = |x: f64| x.is_finite() && x > 0.0;
            (usable(shape.aspect) && usable(shape.focal)).then_some(shape)
        };
        measured().unwrap_or(ImageShape {
            aspect: 1.0,
            handedness: 1.0,
            focal: 1.0,
        })
    }

    /// The square image coordinates of `uv` with the handedness `handedness`.
    fn square(&self, uv: DVec2, handedness: f64) -> DVec2 {
        DVec2::new(uv.x - 0.5, -handedness * (uv.y - 0.5) / self.aspect)
    }
}

/// Why the data determine no camera (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Undetermined {
    /// Fewer than [`MIN_POINTS`] correspondences.
    TooFew,
    /// The points all lie on one line (or coincide).
    PointsOnOneLine,
    /// The image positions all lie on one line: the points lie in one plane through the eye.
    ImageOnOneLine,
    /// No start keeps the points in front of the camera.
    NotInFront,
}

impl std::fmt::Display for Undetermined {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Undetermined::TooFew => write!(
                f,
                "a pinhole camera needs at least {MIN_POINTS} correspondences"
            ),
            Undetermined::PointsOnOneLine => write!(
                f,
                "the correspondences' points all lie on one line, about which the camera may \
                 turn; add points off that line"
            ),
            Undetermined::ImageOnOneLine => write!(
                f,
                "the correspondences' image positions all lie on one line (their points lie \
                 in one plane through the eye, seen edge-on from any eye in it); add points \
                 off that plane"
            ),
            Undetermined::NotInFront => write!(
                f,
                "no pinhole camera sees every correspondence's point in front of it"
            ),
        }
    }
}

/// A fitted pinhole camera of square pixels (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PinholeCamera {
    /// In image widths.
    focal: f64,
    /// World to camera: rows right, down (in square image coordinates) and forward.
    rotation: DMat3,
    eye: DVec3,
    /// The principal point in square image coordinates of the camera's handedness (zero at
    /// the image centre).
    principal: DVec2,
    aspect: f64,
    handedness: f64,
    /// Whether the focal length is the prior's, the data leaving it undetermined.
    focal_from_prior: bool,
    /// Whether the descent began from starts moved back ([`PinholeCamera::moved_start`]).
    moved_start: bool,
}

impl PinholeCamera {
    /// The camera of least reprojection error over `correspondences`, in the image of
    /// `shape` (module docs); the reason where the data determine none.
    pub(super) fn fit(
        correspondences: &[Correspondence],
        shape: ImageShape,
    ) -> Result<PinholeCamera, Undetermined> {
        let data = Data::new(correspondences, shape)?;
        let general = CameraMatrix::fit(correspondences)
            .and_then(|camera| data.start_of_camera_matrix(&camera));
        let centred = |pose: Pose| Pose {
            principal: DVec2::ZERO,
            ..pose
        };
        let starts = [general.map(centred), data.start_of_homography(None)];
        let (best, best_ss, moved) = data.refine_best(&starts, Unknowns::Focal)?;
        let chosen = general
            .and_then(|start| data.off_centre(start, best, best_ss))
            .unwrap_or(best);
        if !data.focal_undetermined(&chosen) {
            return Ok(data.camera(chosen, false, moved));
        }
        // The prior's focal length, from the best pose with its distance scaled by the
        // focal lengths' ratio (the same image of a plane seen face on through the points'
        // centre), and from the homography with that focal length.
        let rescaled = Pose {
            focal: shape.focal,
            eye: best.eye * (shape.focal / best.focal),
            ..best
        };
        let (pose, _, moved) = data.refine_best(
            &[Some(rescaled), data.start_of_homography(Some(shape.focal))],
            Unknowns::Pose,
        )?;
        Ok(data.camera(pose, true, moved))
    }

    /// The eye.
    pub(super) fn eye(&self) -> DVec3 {
        self.eye
    }

    /// The focal length in image widths.
    #[cfg(test)]
    pub(super) fn focal(&self) -> f64 {
        self.focal
    }

    /// Whether the focal length is the prior's, the data (a plane seen face on) leaving it
    /// undetermined.
    pub(super) fn focal_from_prior(&self) -> bool {
        self.focal_from_prior
    }

    /// Whether the descent began only from starts moved back to keep every point in front
    /// (every start the data give kept a point behind it: [`Data::refine_best`]).
    pub(super) fn moved_start(&self) -> bool {
        self.moved_start
    }

    /// The principal point's image position (u, v), `None` where it is the image centre.
    pub(super) fn principal_point(&self) -> Option<DVec2> {
        (self.principal != DVec2::ZERO).then(|| self.uv_of(self.principal))
    }

    /// The direction from the eye of the projector of image position `uv`, towards the
    /// points (unnormalised; affine in (u, v)).
    pub(super) fn direction(&self, uv: DVec2) -> DVec3 {
        let q =
            DVec2::new(uv.x - 0.5, -self.handedness * (uv.y - 0.5) / self.aspect) - self.principal;
        self.rotation.transpose() * DVec3::new(q.x / self.focal, q.y / self.focal, 1.0)
    }

    /// The image position (u, v) of the square image coordinates `q`.
    fn uv_of(&self, q: DVec2) -> DVec2 {
        DVec2::new(q.x + 0.5, 0.5 - self.handedness * self.aspect * q.y)
    }

    /// The image position of `point`, `None` where it is not in front of the camera.
    pub(super) fn project(&self, point: DVec3) -> Option<DVec2> {
        let c = self.rotation * (point - self.eye);
        (c.z > 0.0).then(|| self.uv_of(self.focal * DVec2::new(c.x, c.y) / c.z + self.principal))
    }
}

/// A camera in the normalised world coordinates of [`Data`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pose {
    focal: f64,
    rotation: DMat3,
    eye: DVec3,
    /// In square image coordinates of the handedness `handedness`.
    principal: DVec2,
    handedness: f64,
}

/// The unknowns a refinement fits: the pose (rotation, eye; 6), the focal length too (7), or
/// the principal point too (9). Columns of [`Data::jacobian`]: focal length, rotation
/// vector, eye, principal point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Unknowns {
    Pose,
    Focal,
    Principal,
}

impl Unknowns {
    /// The Jacobian's columns fitted.
    fn columns(self) -> std::ops::Range<usize> {
        match self {
            Unknowns::Pose => 1..7,
            Unknowns::Focal => 0..7,
            Unknowns::Principal => 0..9,
        }
    }
}

/// The correspondences in normalised world coordinates (centroid at the origin, root mean
/// square distance 1) and image positions as (u - 1/2, -(v - 1/2) / a): the square image
/// coordinates of handedness +1.
struct Data {
    shape: ImageShape,
    centre: DVec3,
    scale: f64,
    points: Vec<DVec3>,
    image: Vec<DVec2>,
    /// The points' covariance, axes of largest spread first.
    axes: [DVec3; 3],
}

impl Data {
    fn new(correspondences: &[Correspondence], shape: ImageShape) -> Result<Data, Undetermined> {
        if correspondences.len() < MIN_POINTS {
            return Err(Undetermined::TooFew);
        }
        let n = correspondences.len() as f64;
        let centre = correspondences.iter().map(|c| c.point).sum::<DVec3>() / n;
        let spread = correspondences
            .iter()
            .map(|c| (c.point - centre).length_squared())
            .sum::<f64>()
            / n;
        let scale = spread.sqrt();
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(Undetermined::PointsOnOneLine);
        }
        let points: Vec<DVec3> = correspondences
            .iter()
            .map(|c| (c.point - centre) / scale)
            .collect();
        let (spreads, axes) = principal_axes(&points);
        if spreads[1] <= FLAT * spreads[0] {
            return Err(Undetermined::PointsOnOneLine);
        }
        let image: Vec<DVec2> = correspondences
            .iter()
            .map(|c| shape.square(c.uv, 1.0))
            .collect();
        let mean = image.iter().copied().sum::<DVec2>() / n;
        let flat: Vec<DVec3> = image.iter().map(|q| (*q - mean).extend(0.0)).collect();
        let (image_spreads, _) = principal_axes(&flat);
        if image_spreads[1].partial_cmp(&(FLAT * image_spreads[0])) != Some(Ordering::Greater) {
            return Err(Undetermined::ImageOnOneLine);
        }
        Ok(Data {
            shape,
            centre,
            scale,
            points,
            image,
            axes,
        })
    }

    /// The image position of point `k` for the handedness `handedness`.
    fn seen(&self, k: usize, handedness: f64) -> DVec2 {
        DVec2::new(self.image[k].x, handedness * self.image[k].y)
    }

    /// The fitted camera of `pose` in world coordinates.
    fn camera(&self, pose: Pose, focal_from_prior: bool, moved_start: bool) -> PinholeCamera {
        PinholeCamera {
            focal: pose.focal,
            rotation: pose.rotation,
            eye: self.centre + self.scale * pose.eye,
            principal: pose.principal,
            aspect: self.shape.aspect,
            handedness: pose.handedness,
            focal_from_prior,
            moved_start,
        }
    }

    /// The start from the general camera matrix `camera` (module docs), its handedness the
    /// prior's unless its rotation would then be a reflection, with the principal point of
    /// its K R split; `None` where it is no camera (a singular left block).
    fn start_of_camera_matrix(&self, camera: &CameraMatrix) -> Option<Pose> {
        let rows = camera.rows_facing();
        let eye = (camera.eye()? - self.centre) / self.scale;
        let handedness = self.shape.handedness;
        // Rows of M in square image coordinates of the prior's handedness, on normalised
        // world coordinates (the scale only; the eye carries the offset).
        let m = |r: usize| DVec3::new(rows[r][0], rows[r][1], rows[r][2]) * self.scale;
        let (m0, m1, m2) = (m(0), m(1), m(2));
        let row_x = m0 - 0.5 * m2;
        let row_y = -handedness * (m1 - 0.5 * m2) / self.shape.aspect;
        let r3 = m2.try_normalize()?;
        let lambda = 1.0 / m2.length();
        let principal = DVec2::new((lambda * row_x).dot(r3), (lambda * row_y).dot(r3));
        let q2 = lambda * row_y - (lambda * row_y).dot(r3) * r3;
        let fy = q2.length();
        let r2 = q2 / fy;
        // The first row is the unit vector across r2 and r3, so that the rotation is one to
        // rounding even where the camera matrix is nearly degenerate (nearly coplanar points:
        // its rows nearly dependent, where subtracting their projections would leave a
        // first row of rounding error, not orthogonal to the others); fx is the row's
        // component along it.
        let across = r2.cross(r3);
        let along = (lambda * row_x).dot(across);
        let fx = along.abs();
        // A reflection (the row runs against r2 x r3): the data are of the other handedness
        // (square image y flipped).
        let (r1, r2, principal, handedness) = if along < 0.0 {
            (
                -across,
                -r2,
                DVec2::new(principal.x, -principal.y),
                -handedness,
            )
        } else {
            (across, r2, principal, handedness)
        };
        let pose = Pose {
            focal: 0.5 * (fx + fy),
            rotation: DMat3::from_cols(r1, r2, r3).transpose(),
            eye,
            principal,
            handedness,
        };
        (pose.focal.is_finite() && pose.focal > 0.0 && pose.rotation.is_finite()).then_some(pose)
    }

    /// The start from the homography between the points' best plane and the image (module
    /// docs) with the focal length `focal`, or where `None` the one the homography gives:
    /// the prior's where the two equations give no positive 1 / f^2 or one more than
    /// `FOCAL_RANGE` times the prior's or less than its inverse (a plane seen face on, or
    /// noise); `None` where the homography is undetermined.
    fn start_of_homography(&self, focal: Option<f64>) -> Option<Pose> {
        let handedness = self.shape.handedness;
        let [e1, e2, _] = self.axes;
        let plane: Vec<DVec2> = self
            .points
            .iter()
            .map(|p| DVec2::new(p.dot(e1), p.dot(e2)))
            .collect();
        let image: Vec<DVec2> = (0..self.points.len())
            .map(|k| self.seen(k, handedness))
            .collect();
        let h = homography(&plane, &image)?;
        let col = |c: usize| DVec3::new(h[(0, c)], h[(1, c)], h[(2, c)]);
        let (h1, h2, h3) = (col(0), col(1), col(2));
        // (a_i / f^2 + b_i = 0): r1 . r2 = 0 and |r1|^2 - |r2|^2 = 0.
        let a = [
            h1.x * h2.x + h1.y * h2.y,
            h1.x * h1.x + h1.y * h1.y - h2.x * h2.x - h2.y * h2.y,
        ];
        let b = [h1.z * h2.z, h1.z * h1.z - h2.z * h2.z];
        let w = -(a[0] * b[0] + a[1] * b[1]) / (a[0] * a[0] + a[1] * a[1]);
        let ratio = 1.0 / (w.sqrt() * self.shape.focal);
        let focal = focal.unwrap_or(if (1.0 / FOCAL_RANGE..=FOCAL_RANGE).contains(&ratio) {
            1.0 / w.sqrt()
        } else {
            self.shape.focal
        });
        let unscaled = |v: DVec3| DVec3::new(v.x / focal, v.y / focal, v.z);
        let (a1, a2, a3) = (unscaled(h1), unscaled(h2), unscaled(h3));
        // The plane's centre (the origin) in front: c_z = lambda a3.z > 0.
        let lambda = 2.0 / (a1.length() + a2.length()) * a3.z.signum();
        let b1 = (lambda * a1).try_normalize()?;
        let b2 = (lambda * a2 - (lambda * a2).dot(b1) * b1).try_normalize()?;
        let columns = DMat3::from_cols(b1, b2, b1.cross(b2));
        let plane_axes = DMat3::from_cols(e1, e2, e1.cross(e2));
        let rotation = columns * plane_axes.transpose();
        let eye = -(rotation.transpose() * (lambda * a3));
        let pose = Pose {
            focal,
            rotation,
            eye,
            principal: DVec2::ZERO,
            handedness,
        };
        (rotation.is_finite() && eye.is_finite()).then_some(pose)
    }

    /// The reprojection residuals (2 a point, image widths) of `pose`; `None` where a point
    /// is not in front of it.
    fn residuals(&self, pose: &Pose) -> Option<Vec<f64>> {
        let mut r = Vec::with_capacity(2 * self.points.len());
        for (k, p) in self.points.iter().enumerate() {
            let c = pose.rotation * (*p - pose.eye);
            if c.z.partial_cmp(&0.0) != Some(Ordering::Greater) {
                return None;
            }
            let q = self.seen(k, pose.handedness);
            r.push(pose.focal * c.x / c.z + pose.principal.x - q.x);
            r.push(pose.focal * c.y / c.z + pose.principal.y - q.y);
        }
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    /// The derivative of [`Data::residuals`] in (f, rotation vector, eye, principal point):
    /// 9 columns, the rotation vector turning the camera frame as R <- exp([w]x) R.
    fn jacobian(&self, pose: &Pose) -> DMatrix<f64> {
        let mut j = DMatrix::<f64>::zeros(2 * self.points.len(), 9);
        for (k, p) in self.points.iter().enumerate() {
            let c = pose.rotation * (*p - pose.eye);
            let f = pose.focal;
            let dx = DVec3::new(f / c.z, 0.0, -f * c.x / (c.z * c.z));
            let dy = DVec3::new(0.0, f / c.z, -f * c.y / (c.z * c.z));
            j[(2 * k, 0)] = c.x / c.z;
            j[(2 * k + 1, 0)] = c.y / c.z;
            j[(2 * k, 7)] = 1.0;
            j[(2 * k + 1, 8)] = 1.0;
            for axis in 0..3 {
                let mut e = DVec3::ZERO;
                e[axis] = 1.0;
                let turned = e.cross(c);
                j[(2 * k, 1 + axis)] = dx.dot(turned);
                j[(2 * k + 1, 1 + axis)] = dy.dot(turned);
                // dc / dE = -R: column `axis` of -R.
                let moved = -pose.rotation.col(axis);
                j[(2 * k, 4 + axis)] = dx.dot(moved);
                j[(2 * k + 1, 4 + axis)] = dy.dot(moved);
            }
        }
        j
    }

    /// Levenberg-Marquardt on the reprojection error from `start`, fitting `unknowns` (the
    /// others kept); the pose reached and its sum of squared residuals, or `None` where
    /// `start` has a point behind it.
    fn refine(&self, start: Pose, unknowns: Unknowns) -> Option<(Pose, f64)> {
        let columns = unknowns.columns();
        dense_lm::minimise(
            start,
            MAX_ITERATIONS,
            |pose| self.residuals(pose),
            |pose| {
                self.jacobian(pose)
                    .columns(columns.start, columns.len())
                    .into_owned()
            },
            |pose, step| {
                let mut full = [0.0; 9];
                full[columns.clone()].copy_from_slice(step.as_slice());
                let turn = DVec3::new(-full[1], -full[2], -full[3]);
                let next = Pose {
                    focal: pose.focal - full[0],
                    rotation: rotation_of(turn) * pose.rotation,
                    eye: pose.eye - DVec3::new(full[4], full[5], full[6]),
                    principal: pose.principal - DVec2::new(full[7], full[8]),
                    handedness: pose.handedness,
                };
                (next.focal > 0.0).then_some(next)
            },
        )
    }

    /// The least-error refinement of `unknowns` from any of `starts`; where every start keeps
    /// a point behind it (inconsistent or nearly coplanar data with a point off the plane),
    /// from the starts moved back until every point is in front ([`Data::in_front`]), and
    /// then whether they were moved. `NotInFront` where no refinement can begin even so.
    fn refine_best(
        &self,
        starts: &[Option<Pose>],
        unknowns: Unknowns,
    ) -> Result<(Pose, f64, bool), Undetermined> {
        let best = |moved: bool| {
            starts
                .iter()
                .flatten()
                .filter_map(|start| match moved {
                    false => Some(*start),
                    true => self.in_front(*start),
                })
                .filter_map(|start| self.refine(start, unknowns))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        best(false)
            .map(|(pose, ss)| (pose, ss, false))
            .or_else(|| best(true).map(|(pose, ss)| (pose, ss, true)))
            .ok_or(Undetermined::NotInFront)
    }

    /// `pose` with its eye moved back along its viewing axis until every point lies in front
    /// of it by at least `FRONT_MARGIN` (the points' spread is 1): a start from the points'
    /// best plane (the homography's) or from a camera matrix whose eye lies among nearly
    /// coplanar points may keep a point off that plane behind it, where the descent cannot
    /// begin; moving back keeps the view's direction, and the descent then fits focal length
    /// and eye. `pose` unchanged where every point is in front; `None` for a non-finite pose.
    fn in_front(&self, pose: Pose) -> Option<Pose> {
        let forward = pose.rotation.row(2);
        let nearest = self
            .points
            .iter()
            .map(|p| forward.dot(*p - pose.eye))
            .fold(f64::INFINITY, f64::min);
        if !nearest.is_finite() {
            return None;
        }
        if nearest >= FRONT_MARGIN {
            return Some(pose);
        }
        Some(Pose {
            eye: pose.eye - (FRONT_MARGIN - nearest) * forward,
            ..pose
        })
    }

    /// Whether the data leave `pose`'s focal length undetermined: its standard error (the
    /// noise variance, at least `NOISE_FLOOR` squared, times the inverse normal matrix's
    /// entry, the focal length measured relative to its value) above `FOCAL_SPREAD`, or a
    /// singular normal matrix.
    fn focal_undetermined(&self, pose: &Pose) -> bool {
        self.standard_errors(pose, Unknowns::Focal)
            .is_none_or(|errors| !within(errors[0], FOCAL_SPREAD))
    }

    /// The standard errors of `pose`'s `unknowns` (the noise variance, at least
    /// `NOISE_FLOOR` squared, times the inverse normal matrix's diagonal; the focal length
    /// relative to its value), in the order of [`Data::jacobian`]'s columns from the first
    /// fitted; `None` where the normal matrix is singular.
    fn standard_errors(&self, pose: &Pose, unknowns: Unknowns) -> Option<Vec<f64>> {
        let columns = unknowns.columns();
        let mut j = self.jacobian(pose);
        j.column_mut(0).scale_mut(pose.focal);
        let j = j.columns(columns.start, columns.len()).into_owned();
        let inverse = (j.transpose() * &j).cholesky()?.inverse();
        let r = self.residuals(pose).unwrap_or_default();
        let spare = r.len().saturating_sub(columns.len()).max(1) as f64;
        let variance = (r.iter().map(|v| v * v).sum::<f64>() / spare).max(NOISE_FLOOR.powi(2));
        Some(
            (0..columns.len())
                .map(|i| (variance * inverse[(i, i)]).sqrt())
                .collect(),
        )
    }

    /// The camera with its principal point fitted too (module docs), from the camera
    /// matrix's start `general` and from the centred camera `centred` (its sum of squares
    /// `centred_ss`), where the centred camera misses by more than `NOISE_FLOOR` (rms) and the
    /// other is clearly better with a regular normal matrix; `None` where not.
    fn off_centre(&self, general: Pose, centred: Pose, centred_ss: f64) -> Option<Pose> {
        let count = self.points.len();
        if count < PRINCIPAL_MIN_POINTS {
            // Too few equations to tell a principal point from a far, narrow camera.
            return None;
        }
        if centred_ss <= 2.0 * count as f64 * NOISE_FLOOR.powi(2) {
            // The centred camera meets the data: nothing for a principal point to explain.
            return None;
        }
        let (pose, ss) = [general, centred]
            .into_iter()
            .filter_map(|start| self.refine(start, Unknowns::Principal))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let better = clearly_better(count, 9, 2, ss, centred_ss);
        // A singular normal matrix: the data determine no principal point. A large but
        // finite spread is no reason to refuse it: the principal point trades against the
        // rotation, which the image of the points hardly tells apart.
        let determined = self.standard_errors(&pose, Unknowns::Principal).is_some();
        (better && determined).then_some(pose)
    }
}

/// The fewest correspondences whose equations (two each) are at least twice the
/// off-centre camera's 9 unknowns: below it the principal point is not fitted. With fewer,
/// a point the centred camera cannot keep in front (data contradicting each other) is met
/// almost exactly by an eye moved far away along the contradiction with its principal point
/// shifted, a silent and wrong fit, where the centred camera shows the contradiction in its
/// residual.
pub(super) const PRINCIPAL_MIN_POINTS: usize = 9;

/// Whether `spread` is a number at most `bound`.
fn within(spread: f64, bound: f64) -> bool {
    matches!(
        spread.partial_cmp(&bound),
        Some(Ordering::Less | Ordering::Equal)
    )
}

/// The eigenvalues of the covariance of `points` (about the origin), largest first, and
/// their unit eigenvectors.
fn principal_axes(points: &[DVec3]) -> ([f64; 3], [DVec3; 3]) {
    let mut covariance = Matrix3::<f64>::zeros();
    for p in points {
        let v = nalgebra::Vector3::new(p.x, p.y, p.z);
        covariance += v * v.transpose();
    }
    let eigen = SymmetricEigen::new(covariance);
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[j].total_cmp(&eigen.eigenvalues[i]));
    let axis = |i: usize| {
        let c = eigen.eigenvectors.column(order[i]);
        DVec3::new(c[0], c[1], c[2])
    };
    (
        order.map(|i| eigen.eigenvalues[i]),
        [axis(0), axis(1), axis(2)],
    )
}

/// The rotation by the rotation vector `turn` (its length the angle).
fn rotation_of(turn: DVec3) -> DMat3 {
    let angle = turn.length();
    if angle == 0.0 {
        return DMat3::IDENTITY;
    }
    DMat3::from_axis_angle(turn / angle, angle)
}

/// The homography H (3 x 3, unit length) with (image, 1) ~ H (plane, 1) of least algebraic
/// error, by the direct linear transform on normalised coordinates; `None` where the
/// second least eigenvalue is at rounding level too (the positions do not determine it).
fn homography(plane: &[DVec2], image: &[DVec2]) -> Option<Matrix3<f64>> {
    // Hartley's normalisation: centroids at the origin, mean distance sqrt(2).
    let similarity = |points: &[DVec2]| {
        let arrays: Vec<[f64; 2]> = points.iter().map(|p| p.to_array()).collect();
        let (centre, scale) = normalisation(&arrays);
        (scale.is_finite() && scale > 0.0).then_some((DVec2::from_array(centre), scale))
    };
    let (pc, ps) = similarity(plane)?;
    let (ic, is) = similarity(image)?;
    let mut a = DMatrix::<f64>::zeros(2 * plane.len(), 9);
    for (k, (p, q)) in plane.iter().zip(image).enumerate() {
        let (p, q) = ((*p - pc) * ps, (*q - ic) * is);
        let h = [p.x, p.y, 1.0];
        for i in 0..3 {
            a[(2 * k, i)] = -h[i];
            a[(2 * k, 6 + i)] = q.x * h[i];
            a[(2 * k + 1, 3 + i)] = -h[i];
            a[(2 * k + 1, 6 + i)] = q.y * h[i];
        }
    }
    let eigen = SymmetricEigen::new(a.transpose() * &a);
    let mut order: Vec<usize> = (0..9).collect();
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let second = eigen.eigenvalues[order[1]];
    if second.partial_cmp(&(FLAT * eigen.eigenvalues[order[8]])) != Some(Ordering::Greater) {
        return None;
    }
    let v = eigen.eigenvectors.column(order[0]);
    let normalised = Matrix3::new(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
    // H = T_image^-1 H_n T_plane.
    let t_plane = Matrix3::new(ps, 0.0, -ps * pc.x, 0.0, ps, -ps * pc.y, 0.0, 0.0, 1.0);
    let t_image_inverse = Matrix3::new(1.0 / is, 0.0, ic.x, 0.0, 1.0 / is, ic.y, 0.0, 0.0, 1.0);
    let h = t_image_inverse * normalised * t_plane;
    let norm = h.norm();
    (norm > 0.0 && norm.is_finite()).then(|| h / norm)
}

#[cfg(test)]
mod tests;
