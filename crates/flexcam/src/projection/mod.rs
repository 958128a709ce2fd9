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
mod fisheye;
pub mod flexible;
mod image_coords;
mod inverse;
#[cfg(test)]
mod inverse_properties;
mod kannala_brandt;
mod linear;
mod opencv;
mod panoramic;
mod params;
pub mod projector;
mod radial_tangential;
pub mod ray_map;
mod trilinear;

pub use build_report::BuildReport;
pub use calibrated::{CalibratedCamera, CalibrationSize, Intrinsics};
pub use camera_basis::CameraBasis;
pub use chart::{HalfSpace, InverseChart, Pole};
pub use fisheye::Fisheye;
pub use flexible::{Flexible, FlexibleSpec};
pub use image_coords::Resolution;
pub use inverse::{
    AnalyticInverse, BranchImage, Charted, ContinuousInverse, NoInverse, SingleImage,
};
pub use kannala_brandt::KannalaBrandt;
pub use linear::{Orthographic, Perspective};
pub use opencv::Opencv;
pub use panoramic::{Cylindrical, Equirectangular};
pub use projector::{Projector, ProjectorHull};
pub use trilinear::mesh_builders as trilinear_builders;
pub use trilinear::{
    project_solved_triangle, project_triangle, ProjectionTriangleCache, ProjectiveMap, SceneEdge,
    Shape, ShapeVertex, Solutions, TriangleShapes, TriangleSolution, Trilinear, Unprojectable,
};

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

/// A projection bound to an image size.
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
    /// this projection has none.
    fn inverse(&self) -> Result<&dyn AnalyticInverse, NoInverse>;

    /// This projection as a trilinear mesh, for the renderers that need its triangles
    /// (`--method trilinear`); `None` for every other kind.
    fn trilinear(&self) -> Option<&Trilinear>;
}

/// A camera placement shared by the single-viewpoint projections: an eye position, a point
/// it looks at, and an up hint (need not be perpendicular to the view direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraFrame {
    pub position: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
}

/// The vertices of a trilinear projection mesh (Vallance 2005). Vertex `k` has a base point
/// `points[k]`, a ray direction `normals[k]` (not normalised: its length is the depth scale)
/// and a screen position `screen[k]` in \[0,1\]^2 with (0,0) the bottom-left of the image.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrilinearMesh {
    pub points: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub screen: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
}

/// A parsed projection description; angles in degrees as in scene files.
#[derive(Debug, Clone, PartialEq)]
pub enum ProjectionSpec {
    /// Pinhole; `fov` is the horizontal angle.
    Perspective { frame: CameraFrame, fov: f64 },
    /// Parallel rays; `width` is the horizontal extent in world units.
    Orthographic { frame: CameraFrame, width: f64 },
    /// Angular (equidistant) fisheye; `fov` is the angle across the inscribed image circle.
    Fisheye { frame: CameraFrame, fov: f64 },
    /// Longitude linear in x, latitude linear in y.
    Equirectangular {
        frame: CameraFrame,
        h_fov: f64,
        v_fov: f64,
    },
    /// Longitude linear in x, tan(latitude) linear in y.
    Cylindrical {
        frame: CameraFrame,
        h_fov: f64,
        v_fov: f64,
    },
    /// A calibrated pinhole with OpenCV's radial-tangential distortion, coefficients in
    /// OpenCV's order [k1, k2, p1, p2, k3, k4, k5, k6] (zeros for the shorter forms).
    Opencv {
        camera: CalibratedCamera,
        distortion: [f64; 8],
    },
    /// A calibrated Kannala-Brandt fisheye (OpenCV's `cv::fisheye`), `k` = [k1, k2, k3, k4].
    OpencvFisheye {
        camera: CalibratedCamera,
        k: [f64; 4],
    },
    /// A mesh of trilinear projection triangles.
    Trilinear(TrilinearMesh),
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
            ProjectionSpec::Fisheye { .. } => "fisheye",
            ProjectionSpec::Equirectangular { .. } => "equirectangular",
            ProjectionSpec::Cylindrical { .. } => "cylindrical",
            ProjectionSpec::Opencv { .. } => "opencv",
            ProjectionSpec::OpencvFisheye { .. } => "opencv_fisheye",
            ProjectionSpec::Trilinear(_) => "trilinear",
            ProjectionSpec::Flexible(_) => "flexible",
        }
    }
}
