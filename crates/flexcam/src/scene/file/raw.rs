//! The scene file as TOML gives it: flat structs of optional, span-carrying values.
//!
//! Every value keeps its byte span ([`Spanned`]) so that later checks can report a line and
//! column. The structs are deliberately flat (no tagged enums, no `flatten`, which lose spans
//! in serde); which keys a projection, shape or light type accepts is checked by hand in the
//! modules that convert them. `deny_unknown_fields` turns typos into errors.

use std::ops::Range;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use super::strict::strict;

/// A 3-vector as written in the file: `[x, y, z]`.
pub type Vec3Value = Spanned<[f64; 3]>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    pub image: Option<Spanned<RawImage>>,
    pub projection: Option<Spanned<RawProjection>>,
    #[serde(default)]
    pub object: Vec<Spanned<RawObject>>,
    #[serde(default)]
    pub light: Vec<Spanned<RawLight>>,
    pub animation: Option<Spanned<RawAnimation>>,
}

/// `[animation]`: frames over time, with a keyframed flexible camera and/or moving objects.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAnimation {
    pub frames: Spanned<u32>,
    pub fps: Option<Spanned<f64>>,
    pub interpolation: Option<Spanned<String>>,
    #[serde(default)]
    pub key: Vec<Spanned<RawKey>>,
}

/// `[[animation.key]]`: the projection at one time.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawKey {
    pub time: Spanned<f64>,
    pub projection: Spanned<RawProjection>,
}

/// `[image]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImage {
    pub width: Option<Spanned<u32>>,
    pub height: Option<Spanned<u32>>,
    #[serde(default, deserialize_with = "strict")]
    pub background: Option<Vec3Value>,
    pub spp: Option<Spanned<u32>>,
}

/// `[projection]`: the union of every projection type's parameters.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProjection {
    /// Required everywhere but in the `pieces` of a flexible projection, which are flexible.
    #[serde(rename = "type")]
    pub kind: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub position: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub look_at: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub up: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub converge: Option<Vec3Value>,
    pub fov: Option<Spanned<f64>>,
    pub width: Option<Spanned<f64>>,
    pub h_fov: Option<Spanned<f64>>,
    pub v_fov: Option<Spanned<f64>>,
    pub surface: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub points: Option<Spanned<Vec<[f64; 3]>>>,
    #[serde(default, deserialize_with = "strict")]
    pub normals: Option<Spanned<Vec<[f64; 3]>>>,
    #[serde(default, deserialize_with = "strict")]
    pub screen: Option<Spanned<Vec<[f64; 2]>>>,
    #[serde(default, deserialize_with = "strict")]
    pub triangles: Option<Spanned<Vec<[u32; 3]>>>,
    pub preset: Option<Spanned<String>>,
    pub near: Option<Spanned<RawSurface>>,
    pub far: Option<Spanned<RawSurface>>,
    pub surfaces: Option<Spanned<Vec<Spanned<RawSurface>>>>,
    pub blend: Option<Spanned<String>>,
    pub knots: Option<Spanned<Vec<f64>>>,
    pub segments: Option<Spanned<u32>>,
    pub reparam: Option<Spanned<String>>,
    pub reparam_grid: Option<Spanned<RawReparamGrid>>,
    pub interpolate: Option<Spanned<RawInterpolate>>,
    pub max_latitude: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub clip: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub shear: Option<Spanned<[f64; 2]>>,
    pub slit_distance: Option<Spanned<f64>>,
    pub grid: Option<Spanned<Numbers>>,
    pub view: Option<Spanned<String>>,
    pub camera: Option<Spanned<RawCamera>>,
    #[serde(default, deserialize_with = "strict")]
    pub focus: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub inset: Option<Spanned<[f64; 2]>>,
    pub magnification: Option<Spanned<f64>>,
    pub first: Option<Spanned<RawCamera>>,
    pub second: Option<Spanned<RawCamera>>,
    #[serde(default, deserialize_with = "strict")]
    pub band: Option<Spanned<[f64; 2]>>,
    pub focus_view: Option<Spanned<String>>,
    pub sphere: Option<Spanned<RawSphere>>,
    pub second_sphere: Option<Spanned<RawSphere>>,
    pub ior: Option<Spanned<f64>>,
    pub exact: Option<Spanned<bool>>,
    #[serde(default, deserialize_with = "strict")]
    pub shift: Option<Spanned<[f64; 2]>>,
    pub twist: Option<Spanned<f64>>,
    pub azimuth: Option<Spanned<f64>>,
    pub elevation: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub generators: Option<Spanned<Vec<[f64; 4]>>>,
    pub projectors: Option<Spanned<RawProjectors>>,
    pub transition: Option<Spanned<f64>>,
    pub transitions: Option<Spanned<Vec<f64>>>,
    pub fovs: Option<Spanned<Vec<f64>>>,
    pub style: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub pole: Option<Spanned<[f64; 2]>>,
    pub strength: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub path: Option<Spanned<Vec<[f64; 3]>>>,
    #[serde(default, deserialize_with = "strict")]
    pub directions: Option<Spanned<Vec<[f64; 3]>>>,
    #[serde(default, deserialize_with = "strict")]
    pub center: Option<Spanned<[f64; 2]>>,
    pub radius: Option<Spanned<f64>>,
    pub corner_radius: Option<Spanned<f64>>,
    pub outline: Option<Spanned<RawCurve>>,
    pub outlines: Option<Spanned<Vec<Spanned<RawCurve>>>>,
    pub profile: Option<Spanned<RawCurve>>,
    pub profiles: Option<Spanned<Vec<Spanned<RawCurve>>>>,
    #[serde(default, deserialize_with = "strict")]
    pub perspective_rect: Option<Spanned<[f64; 4]>>,
    pub fx: Option<Spanned<f64>>,
    pub fy: Option<Spanned<f64>>,
    pub cx: Option<Spanned<f64>>,
    pub cy: Option<Spanned<f64>>,
    pub distortion: Option<Spanned<Vec<f64>>>,
    pub k: Option<Spanned<Vec<f64>>>,
    #[serde(default, deserialize_with = "strict")]
    pub calibration_size: Option<Spanned<[u32; 2]>>,
    pub ipd: Option<Spanned<f64>>,
    pub pole_merge_from: Option<Spanned<f64>>,
    pub pole_merge_to: Option<Spanned<f64>>,
    pub mapping: Option<Spanned<String>>,
    pub fit: Option<Spanned<String>>,
    pub lens: Option<Spanned<f64>>,
    pub sensor_width: Option<Spanned<f64>>,
    pub sensor_height: Option<Spanned<f64>>,
    pub sensor_fit: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub pixel_aspect: Option<Spanned<[f64; 2]>>,
    pub polynomial: Option<Spanned<Vec<f64>>>,
    pub tilt: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub deep: Option<Spanned<Vec<[f64; 3]>>>,
    pub pieces: Option<Spanned<Vec<Spanned<RawProjection>>>>,
    #[serde(default, deserialize_with = "strict")]
    pub rect: Option<Spanned<[f64; 4]>>,
    pub z_near: Option<Spanned<f64>>,
    pub z_far: Option<Spanned<f64>>,
    pub map: Option<Spanned<String>>,
}

/// `[projection.interpolate]` of a flexible projection: `weight` Q1 + (1 - `weight`) Q2 of the
/// flexible projection tables `first` and `second`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInterpolate {
    pub weight: Spanned<f64>,
    pub first: Box<Spanned<RawProjection>>,
    pub second: Box<Spanned<RawProjection>>,
}

/// `reparam_grid = { ... }` of a flexible projection with `reparam = "grid"`: the samples of
/// a user-defined map, inline (`uv`) or in a text file (`file`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawReparamGrid {
    #[serde(deserialize_with = "strict")]
    pub size: Spanned<[u32; 2]>,
    #[serde(default, deserialize_with = "strict")]
    pub uv: Option<Spanned<Vec<Spanned<[f64; 2]>>>>,
    pub file: Option<Spanned<String>>,
    pub interpolation: Option<Spanned<String>>,
}

/// `outline = { ... }`, `profile`, and the entries of `outlines` / `profiles` (with `at`): a
/// panorama curve, named (`shape` with its parameter) or by `points`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCurve {
    pub at: Option<Spanned<f64>>,
    pub shape: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub points: Option<Spanned<Vec<[f64; 2]>>>,
    pub radius: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub elevation: Option<Spanned<[f64; 2]>>,
}

impl RawCurve {
    /// The keys present besides `at`, with their spans.
    pub fn present_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        [
            ("shape", self.shape.as_ref().map(Spanned::span)),
            ("points", self.points.as_ref().map(Spanned::span)),
            ("radius", self.radius.as_ref().map(Spanned::span)),
            ("elevation", self.elevation.as_ref().map(Spanned::span)),
        ]
        .into_iter()
        .filter_map(|(key, span)| Some((key, span?)))
        .collect()
    }
}

/// `projectors = { ... }` of a flexible projection: a projector grid sampled from the
/// projection's volume, with node projectors placed explicitly (`projector`), re-aimed
/// (`aim`) and fitted to correspondences (`fit`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProjectors {
    #[serde(default, deserialize_with = "strict")]
    pub size: Option<Spanned<[i64; 2]>>,
    pub interpolation: Option<Spanned<String>>,
    pub projector: Option<Vec<Spanned<RawNodeProjector>>>,
    pub aim: Option<Vec<Spanned<RawAim>>>,
    pub fit: Option<Vec<Spanned<RawCorrespondence>>>,
    pub starts: Option<Spanned<String>>,
    pub painting: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub painting_size: Option<Spanned<[i64; 2]>>,
}

/// `{ node = [column, row], start = [x, y, z], end = [x, y, z], tangent = [x, y, z] }`: one
/// node projector placed explicitly (each of start, end and tangent optional); or, the
/// thesis's form, `point = [x, y, z]` (instead of `end`) with an optional `length`: the
/// projector passes through `point`, with `tangent` its direction there.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNodeProjector {
    #[serde(deserialize_with = "strict")]
    pub node: Spanned<[i64; 2]>,
    #[serde(default, deserialize_with = "strict")]
    pub start: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub end: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub tangent: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub point: Option<Vec3Value>,
    pub length: Option<Spanned<f64>>,
}

/// `{ node = [column, row], at = [x, y, z] }`: re-aim one node projector through a point.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAim {
    #[serde(deserialize_with = "strict")]
    pub node: Spanned<[i64; 2]>,
    #[serde(deserialize_with = "strict")]
    pub at: Vec3Value,
}

/// `{ uv = [u, v], point = [x, y, z] }` or `{ pixel = [x, y], point = [x, y, z] }`: the
/// image position (in [0, 1]^2, or in the painting's pixels) that must see a scene point.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCorrespondence {
    #[serde(default, deserialize_with = "strict")]
    pub uv: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub pixel: Option<Spanned<[f64; 2]>>,
    #[serde(deserialize_with = "strict")]
    pub point: Vec3Value,
}

/// `camera = { ... }`, `first`, `second`: a camera of a trilinear grid's visualisation
/// surface; `h_fov` and `v_fov` (pinhole) or `width` and `height` (parallel).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCamera {
    #[serde(deserialize_with = "strict")]
    pub position: Vec3Value,
    #[serde(deserialize_with = "strict")]
    pub look_at: Vec3Value,
    #[serde(default, deserialize_with = "strict")]
    pub up: Option<Vec3Value>,
    pub h_fov: Option<Spanned<f64>>,
    pub v_fov: Option<Spanned<f64>>,
    pub width: Option<Spanned<f64>>,
    pub height: Option<Spanned<f64>>,
}

/// `sphere = { center = [x, y, z], radius = r }`: the ball of a trilinear grid's view
/// through a ball (`view = "sphere_mirror"` or `"sphere_glass"`), and `second_sphere`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSphere {
    #[serde(deserialize_with = "strict")]
    pub center: Vec3Value,
    pub radius: Spanned<f64>,
}

/// `near = { surface = "...", ... }` / `far`: a flexible projection's control surface, the
/// union of every surface type's parameters.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSurface {
    pub surface: Spanned<String>,
    #[serde(default, deserialize_with = "strict")]
    pub center: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub u_axis: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub v_axis: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub corner: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub u_edge: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub v_edge: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub corners: Option<Spanned<[[f64; 3]; 4]>>,
    pub radius: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub longitude: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub latitude: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub angle: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub height: Option<Spanned<[f64; 2]>>,
    #[serde(default, deserialize_with = "strict")]
    pub axis: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub front: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub point: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub start: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub end: Option<Vec3Value>,
    pub along: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub control: Option<Spanned<Vec<Vec<[f64; 3]>>>>,
    pub weights: Option<Spanned<Vec<Vec<f64>>>>,
    #[serde(default, deserialize_with = "strict")]
    pub degree: Option<Spanned<[i64; 2]>>,
    pub u_knots: Option<Spanned<Vec<f64>>>,
    pub v_knots: Option<Spanned<Vec<f64>>>,
}

impl RawSurface {
    /// The parameter keys present in the table (all but `surface`), with their spans.
    pub fn present_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        [
            ("center", self.center.as_ref().map(Spanned::span)),
            ("u_axis", self.u_axis.as_ref().map(Spanned::span)),
            ("v_axis", self.v_axis.as_ref().map(Spanned::span)),
            ("corner", self.corner.as_ref().map(Spanned::span)),
            ("u_edge", self.u_edge.as_ref().map(Spanned::span)),
            ("v_edge", self.v_edge.as_ref().map(Spanned::span)),
            ("corners", self.corners.as_ref().map(Spanned::span)),
            ("radius", self.radius.as_ref().map(Spanned::span)),
            ("longitude", self.longitude.as_ref().map(Spanned::span)),
            ("latitude", self.latitude.as_ref().map(Spanned::span)),
            ("angle", self.angle.as_ref().map(Spanned::span)),
            ("height", self.height.as_ref().map(Spanned::span)),
            ("axis", self.axis.as_ref().map(Spanned::span)),
            ("front", self.front.as_ref().map(Spanned::span)),
            ("point", self.point.as_ref().map(Spanned::span)),
            ("start", self.start.as_ref().map(Spanned::span)),
            ("end", self.end.as_ref().map(Spanned::span)),
            ("along", self.along.as_ref().map(Spanned::span)),
            ("control", self.control.as_ref().map(Spanned::span)),
            ("weights", self.weights.as_ref().map(Spanned::span)),
            ("degree", self.degree.as_ref().map(Spanned::span)),
            ("u_knots", self.u_knots.as_ref().map(Spanned::span)),
            ("v_knots", self.v_knots.as_ref().map(Spanned::span)),
        ]
        .into_iter()
        .filter_map(|(key, span)| Some((key, span?)))
        .collect()
    }
}

impl RawProjection {
    /// The parameter keys present in the table (all but `type`), with their spans.
    pub fn present_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        [
            ("position", self.position.as_ref().map(Spanned::span)),
            ("look_at", self.look_at.as_ref().map(Spanned::span)),
            ("up", self.up.as_ref().map(Spanned::span)),
            ("converge", self.converge.as_ref().map(Spanned::span)),
            ("fov", self.fov.as_ref().map(Spanned::span)),
            ("width", self.width.as_ref().map(Spanned::span)),
            ("h_fov", self.h_fov.as_ref().map(Spanned::span)),
            ("v_fov", self.v_fov.as_ref().map(Spanned::span)),
            ("surface", self.surface.as_ref().map(Spanned::span)),
            ("points", self.points.as_ref().map(Spanned::span)),
            ("normals", self.normals.as_ref().map(Spanned::span)),
            ("screen", self.screen.as_ref().map(Spanned::span)),
            ("triangles", self.triangles.as_ref().map(Spanned::span)),
            ("preset", self.preset.as_ref().map(Spanned::span)),
            ("near", self.near.as_ref().map(Spanned::span)),
            ("far", self.far.as_ref().map(Spanned::span)),
            ("surfaces", self.surfaces.as_ref().map(Spanned::span)),
            ("blend", self.blend.as_ref().map(Spanned::span)),
            ("knots", self.knots.as_ref().map(Spanned::span)),
            ("segments", self.segments.as_ref().map(Spanned::span)),
            ("reparam", self.reparam.as_ref().map(Spanned::span)),
            (
                "reparam_grid",
                self.reparam_grid.as_ref().map(Spanned::span),
            ),
            ("interpolate", self.interpolate.as_ref().map(Spanned::span)),
            (
                "max_latitude",
                self.max_latitude.as_ref().map(Spanned::span),
            ),
            ("clip", self.clip.as_ref().map(Spanned::span)),
            ("shear", self.shear.as_ref().map(Spanned::span)),
            (
                "slit_distance",
                self.slit_distance.as_ref().map(Spanned::span),
            ),
            ("grid", self.grid.as_ref().map(Spanned::span)),
            ("view", self.view.as_ref().map(Spanned::span)),
            ("camera", self.camera.as_ref().map(Spanned::span)),
            ("focus", self.focus.as_ref().map(Spanned::span)),
            ("inset", self.inset.as_ref().map(Spanned::span)),
            (
                "magnification",
                self.magnification.as_ref().map(Spanned::span),
            ),
            ("first", self.first.as_ref().map(Spanned::span)),
            ("second", self.second.as_ref().map(Spanned::span)),
            ("band", self.band.as_ref().map(Spanned::span)),
            ("focus_view", self.focus_view.as_ref().map(Spanned::span)),
            ("sphere", self.sphere.as_ref().map(Spanned::span)),
            (
                "second_sphere",
                self.second_sphere.as_ref().map(Spanned::span),
            ),
            ("ior", self.ior.as_ref().map(Spanned::span)),
            ("exact", self.exact.as_ref().map(Spanned::span)),
            ("shift", self.shift.as_ref().map(Spanned::span)),
            ("twist", self.twist.as_ref().map(Spanned::span)),
            ("azimuth", self.azimuth.as_ref().map(Spanned::span)),
            ("elevation", self.elevation.as_ref().map(Spanned::span)),
            ("generators", self.generators.as_ref().map(Spanned::span)),
            ("projectors", self.projectors.as_ref().map(Spanned::span)),
            (
                "corner_radius",
                self.corner_radius.as_ref().map(Spanned::span),
            ),
            ("outline", self.outline.as_ref().map(Spanned::span)),
            ("outlines", self.outlines.as_ref().map(Spanned::span)),
            ("profile", self.profile.as_ref().map(Spanned::span)),
            ("profiles", self.profiles.as_ref().map(Spanned::span)),
            (
                "perspective_rect",
                self.perspective_rect.as_ref().map(Spanned::span),
            ),
            ("transition", self.transition.as_ref().map(Spanned::span)),
            ("transitions", self.transitions.as_ref().map(Spanned::span)),
            ("fovs", self.fovs.as_ref().map(Spanned::span)),
            ("style", self.style.as_ref().map(Spanned::span)),
            ("pole", self.pole.as_ref().map(Spanned::span)),
            ("strength", self.strength.as_ref().map(Spanned::span)),
            ("path", self.path.as_ref().map(Spanned::span)),
            ("directions", self.directions.as_ref().map(Spanned::span)),
            ("center", self.center.as_ref().map(Spanned::span)),
            ("radius", self.radius.as_ref().map(Spanned::span)),
            ("fx", self.fx.as_ref().map(Spanned::span)),
            ("fy", self.fy.as_ref().map(Spanned::span)),
            ("cx", self.cx.as_ref().map(Spanned::span)),
            ("cy", self.cy.as_ref().map(Spanned::span)),
            ("distortion", self.distortion.as_ref().map(Spanned::span)),
            ("k", self.k.as_ref().map(Spanned::span)),
            (
                "calibration_size",
                self.calibration_size.as_ref().map(Spanned::span),
            ),
            ("ipd", self.ipd.as_ref().map(Spanned::span)),
            (
                "pole_merge_from",
                self.pole_merge_from.as_ref().map(Spanned::span),
            ),
            (
                "pole_merge_to",
                self.pole_merge_to.as_ref().map(Spanned::span),
            ),
            ("mapping", self.mapping.as_ref().map(Spanned::span)),
            ("fit", self.fit.as_ref().map(Spanned::span)),
            ("lens", self.lens.as_ref().map(Spanned::span)),
            (
                "sensor_width",
                self.sensor_width.as_ref().map(Spanned::span),
            ),
            (
                "sensor_height",
                self.sensor_height.as_ref().map(Spanned::span),
            ),
            ("sensor_fit", self.sensor_fit.as_ref().map(Spanned::span)),
            (
                "pixel_aspect",
                self.pixel_aspect.as_ref().map(Spanned::span),
            ),
            ("polynomial", self.polynomial.as_ref().map(Spanned::span)),
            ("tilt", self.tilt.as_ref().map(Spanned::span)),
            ("deep", self.deep.as_ref().map(Spanned::span)),
            ("pieces", self.pieces.as_ref().map(Spanned::span)),
            ("rect", self.rect.as_ref().map(Spanned::span)),
            ("z_near", self.z_near.as_ref().map(Spanned::span)),
            ("z_far", self.z_far.as_ref().map(Spanned::span)),
            ("map", self.map.as_ref().map(Spanned::span)),
        ]
        .into_iter()
        .filter_map(|(key, span)| Some((key, span?)))
        .collect()
    }
}

/// Only the projection type, read leniently (unknown keys allowed), to recognise projection
/// types whose parameters this parser does not know before the strict parse rejects them.
#[derive(Debug, Deserialize)]
pub struct ProjectionTypeProbe {
    pub projection: Option<ProbedProjection>,
}

/// See [`ProjectionTypeProbe`].
#[derive(Debug, Deserialize)]
pub struct ProbedProjection {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
}

/// `[[object]]`: the union of every shape's parameters.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObject {
    pub name: Option<Spanned<String>>,
    pub shape: Spanned<String>,
    pub size: Option<Spanned<Numbers>>,
    pub file: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "strict")]
    pub color: Option<Vec3Value>,
    pub checker: Option<Spanned<RawChecker>>,
    pub texture: Option<Spanned<String>>,
    pub material: Option<Spanned<String>>,
    pub ior: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub translate: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub rotate: Option<Vec3Value>,
    pub scale: Option<Spanned<Numbers>>,
    pub tessellation: Option<Spanned<u32>>,
    #[serde(default, deserialize_with = "strict")]
    pub face_colors: Option<Spanned<[[f64; 3]; 6]>>,
    pub trilinear_reflector: Option<Spanned<bool>>,
    pub trilinear_screen_map: Option<Spanned<String>>,
    pub trilinear_refine_px: Option<Spanned<f64>>,
    pub camera_triangles: Option<Spanned<u32>>,
    pub reflection: Option<Spanned<String>>,
    pub camera_rays: Option<Spanned<String>>,
    pub caustics: Option<Spanned<bool>>,
    pub caustic_map: Option<Spanned<i64>>,
    pub displacement: Option<Spanned<super::displacement::RawDisplacement>>,
    pub orbit: Option<Spanned<super::motion::RawOrbit>>,
}

/// `checker = { color = [...], size = ... }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawChecker {
    #[serde(deserialize_with = "strict")]
    pub color: Vec3Value,
    pub size: Option<Spanned<f64>>,
}

/// `[[light]]`: the union of both light types' parameters.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLight {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    #[serde(default, deserialize_with = "strict")]
    pub position: Option<Vec3Value>,
    #[serde(default, deserialize_with = "strict")]
    pub direction: Option<Vec3Value>,
    pub intensity: Option<Spanned<f64>>,
    #[serde(default, deserialize_with = "strict")]
    pub color: Option<Vec3Value>,
}

/// A value that may be one number or an array of numbers (`size`, `scale`); its meaning and
/// the length it needs depend on the key and shape, and are checked where it is used.
#[derive(Debug, Clone, PartialEq)]
pub enum Numbers {
    One(f64),
    List(Vec<f64>),
}

impl Numbers {
    /// The numbers as a slice (one element for a single number).
    pub fn as_slice(&self) -> &[f64] {
        match self {
            Numbers::One(x) => std::slice::from_ref(x),
            Numbers::List(xs) => xs,
        }
    }
}

impl<'de> Deserialize<'de> for Numbers {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NumbersVisitor;

        impl<'de> Visitor<'de> for NumbersVisitor {
            type Value = Numbers;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of numbers")
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Numbers, E> {
                Ok(Numbers::One(v))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Numbers, E> {
                Ok(Numbers::One(v as f64))
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Numbers, E> {
                Ok(Numbers::One(v as f64))
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Numbers, A::Error> {
                let mut numbers = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    numbers.push(x);
                }
                Ok(Numbers::List(numbers))
            }
        }

        deserializer.deserialize_any(NumbersVisitor)
    }
}
