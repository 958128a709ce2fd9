//! The projection: the object at the centre of flexcam.
//!
//! A projection maps a continuous image position to a ray (its projector) and, where it has an
//! inverse (an optional capability, see [`AnalyticInverse`]), maps a scene point back to every image position that sees it, with depth. A
//! projection may image a point zero, one or several times (a trilinear mesh can fold; a
//! panorama can wrap), so the inverse appends to a list.
//!
//! [`ProjectionSpec`] is the parsed description (from a scene file); [`ProjectionSpec::build`]
//! turns it into a [`Projection`] for a given image size, validating it on the way.

mod build;
mod build_report;
mod calibrated;
#[cfg(test)]
mod calibrated_properties;
mod camera_basis;
pub mod chart;
pub mod colmap;
mod dome_master;
mod fisheye;
mod fisheye_circle;
mod fisheye_mapping;
#[cfg(test)]
mod fisheye_properties;
pub mod flexible;
mod image_coords;
mod inverse;
#[cfg(test)]
mod inverse_properties;
mod kannala_brandt;
mod linear;
mod monotone_root;
pub mod nearest_image;
mod ods;
mod opencv;
mod panoramic;
mod params;
pub mod projector;
mod radial_tangential;
pub mod ray_map;
mod stereo;
#[cfg(test)]
mod stereo_properties;
mod trilinear;
pub mod volume_geometry;
mod vr180;

pub use build_report::BuildReport;
pub use calibrated::{CalibratedCamera, CalibrationSize, Intrinsics};
pub use camera_basis::CameraBasis;
pub use chart::{HalfSpace, InverseChart, Pole};
pub use fisheye::{Fisheye, FisheyeLens};
pub use fisheye_circle::{FisheyeFit, Sensor, SensorFit, SENSOR_FIT_NAMES};
pub use fisheye_mapping::{FisheyeMapping, MAPPING_NAMES};
pub use flexible::{Flexible, FlexibleSpec};
pub use image_coords::Resolution;
pub use inverse::{
    AnalyticInverse, BranchImage, Charted, ContinuousInverse, NoInverse, SingleImage, StageKey,
    StagedInverse,
};
pub use kannala_brandt::KannalaBrandt;
pub use linear::{Orthographic, Perspective};
pub use ods::{ods, Ods, OdsEye};
pub use opencv::Opencv;
pub use panoramic::{Cylindrical, Equirectangular};
pub use projector::{Projector, ProjectorHull};
pub use stereo::{KeepClear, Layout, StereoPair, View};
pub use trilinear::mesh_builders as trilinear_builders;
pub use trilinear::ray_fan as trilinear_fan;
pub use trilinear::{
    project_solved_triangle, project_triangle, FanSolution, FragmentMirror,
    ProjectionTriangleCache, ProjectiveMap, RayFan, SceneEdge, Shape, ShapeVertex, Solutions,
    TriangleMirror, TriangleShapes, TriangleSolution, Trilinear, Unprojectable,
};
pub use vr180::{vr180, Vr180};

use glam::{DVec2, DVec3};

use crate::geometry::Ray;

/// One image of a scene point under a projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImagePoint {
    /// Continuous pixel position (pixel (x, y) covers [x, x+1) x [y, y+1); y grows down).
    /// It may lie outside the image: callers clip.
    pub pixel: DVec2,
    /// The ray parameter at which `ray(pixel)` reaches the point: `ray(pixel).at(t) == point`.
    pub t: f64,
}

/// Images of one scene point closer than this (in pixels) are one image: a point on an
/// edge or vertex shared by several pieces of a projection is found by each of them.
pub const SAME_IMAGE_PIXELS: f64 = 1e-6;

/// An image of a scene point that is a whole segment of image positions, each seeing the
/// point along one and the same ray (a trilinear projection triangle whose rays form a fan,
/// [`RayFan`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageSegment {
    /// The segment's ends, as [`ImagePoint::pixel`] (outside the image possibly: callers
    /// clip).
    pub ends: [DVec2; 2],
    /// The ray parameter at which the ray of every position on the segment reaches the point.
    pub t: f64,
}

/// A projection bound to an image size.
///
/// Ray generation and the inverse of a projection built from its description:
///
/// ```
/// use flexcam::glam::{DVec2, DVec3};
/// use flexcam::projection::{CameraFrame, ProjectionSpec};
///
/// let frame = CameraFrame { position: DVec3::ZERO, look_at: -DVec3::Z, up: DVec3::Y };
/// let projection = ProjectionSpec::Fisheye { frame, fov: 180.0 }.build(200, 100)?;
/// // The image centre looks along the view direction.
/// let ray = projection.ray(DVec2::new(100.0, 50.0)).unwrap();
/// assert!((ray.direction.normalize() - (-DVec3::Z)).length() < 1e-12);
/// // Outside the fisheye's image circle there is no ray.
/// assert!(projection.ray(DVec2::new(1.0, 1.0)).is_none());
/// // The inverse gives every image of a scene point with its ray parameter.
/// let point = DVec3::new(1.0, 0.5, -2.0);
/// let mut images = Vec::new();
/// projection.inverse().expect("a fisheye has one").project(point, &mut images);
/// assert_eq!(images.len(), 1);
/// let back = projection.ray(images[0].pixel).unwrap().at(images[0].t);
/// assert!((back - point).length() < 1e-9);
/// # Ok::<(), flexcam::Error>(())
/// ```
///
/// A projection of one's own implements [`Projection::kind`], [`Projection::resolution`] and
/// [`Projection::ray`]; it renders by ray casting, and also by `--method raster` when it gives
/// an [`AnalyticInverse`] (implementing [`SingleImage`] gives one). See the example
/// `crates/flexcam/examples/custom_projection`.
pub trait Projection: Send + Sync {
    /// The projection's type name as in scene files (`perspective`, `fisheye`, ...).
    fn kind(&self) -> &'static str;

    /// Image width and height in pixels.
    fn resolution(&self) -> (u32, u32);

    /// The ray through continuous pixel position `pixel` (a pixel's centre is at +0.5), or
    /// `None` where that image position sees nothing (outside a fisheye's image circle,
    /// outside every screen triangle of a trilinear mesh). The direction need not be unit
    /// length; see [`Ray`].
    fn ray(&self, pixel: DVec2) -> Option<Ray>;

    /// The projector through continuous pixel position `pixel`, straight or curved; `None`
    /// where the position sees nothing. Projections with straight projectors keep the
    /// default, [`Projection::ray`] as a [`Projector::Straight`].
    fn projector(&self, pixel: DVec2) -> Option<Projector> {
        self.ray(pixel).map(Projector::Straight)
    }

    /// Sets `out` to [`Projection::projector`] of `pixel`, reusing what `out` holds where the
    /// projection can: a polyline refills the vertex buffer of a polyline already in `out`
    /// instead of allocating one. Renderers that generate a projector per sample keep one
    /// `out` per lane of their inner loop, so that loop allocates nothing. The default
    /// replaces `out`.
    fn projector_into(&self, pixel: DVec2, out: &mut Option<Projector>) {
        *out = self.projector(pixel);
    }

    /// Sets `out[j * stride + i]` to [`Projection::projector`] of pixel position
    /// `(columns[i], rows[j])`, for every column `i` and row `j` (`out` holds at least
    /// `(rows.len() - 1) * stride + columns.len()` entries; the others are left alone). The
    /// same projectors as one [`Projection::projector_into`] call per position, which the
    /// default makes; a projection whose projector is separable in x and y (longitude by
    /// column, latitude by row) computes its trigonometry once per column and per row
    /// instead of per pixel: the raster's pixel projectors for a whole tile come from here.
    fn projector_grid_into(
        &self,
        columns: &[f64],
        rows: &[f64],
        stride: usize,
        out: &mut [Option<Projector>],
    ) {
        for (j, &y) in rows.iter().enumerate() {
            for (i, &x) in columns.iter().enumerate() {
                self.projector_into(DVec2::new(x, y), &mut out[j * stride + i]);
            }
        }
    }

    /// A bound on the projectors of every sample position in the closed pixel-space
    /// rectangle `[lo, hi]`, each of which has a projector (see [`ProjectorHull`]): lets a
    /// renderer cull a whole tile at once. `None` (the default) where the projection cannot
    /// promise that. This is an honest answer for every projection, not a missing
    /// capability: a renderer without a hull searches projector by projector, so `None`
    /// only costs time, and whether a bound exists can depend on the rectangle.
    fn projector_hull(&self, _lo: DVec2, _hi: DVec2) -> Option<ProjectorHull> {
        None
    }

    /// The analytic inverse (every image of a scene point, see [`AnalyticInverse`]), or why
    /// this projection has none. The default has none (`reason: None`): such a projection
    /// renders by ray casting alone, and `--method raster` refuses it with one line.
    fn inverse(&self) -> Result<&dyn AnalyticInverse, NoInverse> {
        Err(NoInverse { reason: None })
    }

    /// The projection as separate views tiled in its image (the two eyes of a stereo pair,
    /// see [`StereoPair`]), for renderers that draw one continuous view at a time
    /// (`--method raster`); empty (the default) for a projection that is a single view.
    fn views(&self) -> Vec<View<'_>> {
        Vec::new()
    }

    /// This projection as a trilinear mesh, for the renderers that need its triangles
    /// (`--method trilinear`); `None` for every other kind, the default.
    fn trilinear(&self) -> Option<&Trilinear> {
        None
    }

    /// This projection as a flexible viewing volume, for what needs its control surfaces
    /// (the volume's geometry, [`volume_geometry`]); `None` for every other kind, the
    /// default.
    fn flexible(&self) -> Option<&Flexible> {
        None
    }
}

/// A camera placement shared by the single-viewpoint projections: an eye position, a point
/// it looks at, and an up hint (need not be perpendicular to the view direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraFrame {
    /// The eye: where every ray of the projection starts (world units).
    pub position: DVec3,
    /// A point the view direction passes through (the image centre's ray).
    pub look_at: DVec3,
    /// Which way is up in the image; only its component perpendicular to the view direction
    /// counts.
    pub up: DVec3,
}

/// The vertices of a trilinear projection mesh (Vallance 2005). Vertex `k` has a base point
/// `points[k]`, a ray direction `normals[k]` (not normalised: its length is the depth scale)
/// and a screen position `screen[k]` in \[0,1\]^2 with (0,0) the bottom-left of the image.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrilinearMesh {
    /// Base point of each vertex's ray (world units).
    pub points: Vec<DVec3>,
    /// Ray direction of each vertex; its length scales depth.
    pub normals: Vec<DVec3>,
    /// Image position of each vertex, (0, 0) bottom-left and (1, 1) top-right.
    pub screen: Vec<DVec2>,
    /// Vertex indices of each projection triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// A parsed projection description; angles in degrees as in scene files.
#[derive(Debug, Clone, PartialEq)]
pub enum ProjectionSpec {
    /// Pinhole; `fov` is the horizontal angle.
    Perspective {
        /// Eye, view direction and up.
        frame: CameraFrame,
        /// Horizontal angle of view, degrees.
        fov: f64,
    },
    /// Parallel rays; `width` is the horizontal extent in world units.
    Orthographic {
        /// The image centre's ray start, view direction and up.
        frame: CameraFrame,
        /// Horizontal extent of the view, world units.
        width: f64,
    },
    /// Angular (equidistant) fisheye; `fov` is the angle across the inscribed image circle.
    Fisheye {
        /// Eye, view axis and up.
        frame: CameraFrame,
        /// Angle across the image circle, degrees, up to 360.
        fov: f64,
    },
    /// A fisheye with another mapping or image-circle placement than the angular one
    /// (`type = "fisheye"` with `mapping`, `fit` or sensor keys); `fov` is the angle across
    /// the outline, or where a lens polynomial is cut.
    MappedFisheye {
        /// Eye, view axis and up.
        frame: CameraFrame,
        /// Angle across the outline (or where the lens polynomial is cut), degrees.
        fov: f64,
        /// The mapping and the image circle's placement.
        lens: FisheyeLens,
    },
    /// A fulldome master: `frame.up` is the zenith, `frame.look_at` the front, the dome
    /// tilted forward by `tilt` degrees; `fov` across the circle (180 for a hemisphere).
    DomeMaster {
        /// The dome's centre (the eye), its front (`look_at`) and zenith (`up`).
        frame: CameraFrame,
        /// Angle across the dome's circle, degrees.
        fov: f64,
        /// Forward tilt of the dome, degrees.
        tilt: f64,
    },
    /// Longitude linear in x, latitude linear in y.
    Equirectangular {
        /// Eye, the image centre's direction and up (the poles' axis).
        frame: CameraFrame,
        /// Longitude range across the image, degrees.
        h_fov: f64,
        /// Latitude range down the image, degrees.
        v_fov: f64,
    },
    /// Longitude linear in x, tan(latitude) linear in y.
    Cylindrical {
        /// Eye, the image centre's direction and up (the cylinder's axis).
        frame: CameraFrame,
        /// Longitude range across the image, degrees.
        h_fov: f64,
        /// Vertical angle at the image centre, degrees.
        v_fov: f64,
    },
    /// A calibrated pinhole with OpenCV's radial-tangential distortion, coefficients in
    /// OpenCV's order [k1, k2, p1, p2, k3, k4, k5, k6] (zeros for the shorter forms).
    Opencv {
        /// Placement and intrinsics (focal lengths, principal point, calibration size).
        camera: CalibratedCamera,
        /// [k1, k2, p1, p2, k3, k4, k5, k6].
        distortion: [f64; 8],
    },
    /// A calibrated Kannala-Brandt fisheye (OpenCV's `cv::fisheye`), `k` = [k1, k2, k3, k4].
    OpencvFisheye {
        /// Placement and intrinsics (focal lengths, principal point, calibration size).
        camera: CalibratedCamera,
        /// [k1, k2, k3, k4] of theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8).
        k: [f64; 4],
    },
    /// Omni-directional stereo: 360 x 180 equirectangular per eye, left eye on top, rays
    /// tangent to the circle of radius `ipd`/2; `pole_merge` = [from, to] latitudes in
    /// degrees between which the eye offset fades to zero (Cycles' pole merging).
    Ods {
        /// The centre of the eye circle, the image centre's direction and up (the poles' axis).
        frame: CameraFrame,
        /// Interpupillary distance, world units: the eye circle's diameter.
        ipd: f64,
        /// Latitudes from and to which the eye offset fades to zero, degrees; `None`: no
        /// merging.
        pole_merge: Option<[f64; 2]>,
    },
    /// VR180: two 180 x 180 equirectangular halves side by side, left eye on the left, eyes
    /// `ipd` apart along the camera's right axis.
    Vr180 {
        /// The point midway between the eyes, the common view direction and up.
        frame: CameraFrame,
        /// Interpupillary distance, world units: the eyes' separation.
        ipd: f64,
    },
    /// A mesh of trilinear projection triangles.
    Trilinear(TrilinearMesh),
    /// The exact view through a ball that a trilinear grid `view = "sphere_mirror"` or
    /// `"sphere_glass"` samples (scene key `exact = true`): every pixel's ray from the ball
    /// itself, ray cast only.
    ExactBall(trilinear_builders::BallView),
    /// A parametric viewing volume between control surfaces (Brosz 2011); boxed, as it is
    /// much larger than the other variants.
    Flexible(Box<FlexibleSpec>),
}

impl ProjectionSpec {
    /// The scene-file type name.
    pub fn kind(&self) -> &'static str {
        match self {
            ProjectionSpec::Perspective { .. } => "perspective",
            ProjectionSpec::Orthographic { .. } => "orthographic",
            ProjectionSpec::Fisheye { .. } | ProjectionSpec::MappedFisheye { .. } => "fisheye",
            ProjectionSpec::DomeMaster { .. } => "dome_master",
            ProjectionSpec::Equirectangular { .. } => "equirectangular",
            ProjectionSpec::Cylindrical { .. } => "cylindrical",
            ProjectionSpec::Opencv { .. } => "opencv",
            ProjectionSpec::OpencvFisheye { .. } => "opencv_fisheye",
            ProjectionSpec::Ods { .. } => "ods",
            ProjectionSpec::Vr180 { .. } => "vr180",
            ProjectionSpec::Trilinear(_) | ProjectionSpec::ExactBall(_) => "trilinear",
            ProjectionSpec::Flexible(_) => "flexible",
        }
    }
}
