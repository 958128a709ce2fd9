//! The region of a camera triangle's image where a scene triangle can appear: the pixels the
//! fragment stage is run on.
//!
//! Both bounds rest on the paper's argument (Hou et al. 2006, 2.1): a point `q` of the scene
//! triangle seen at barycentrics `b` lies on the ray from the camera plane along
//! `d(b)`, a convex combination of the corner directions `d_j`; projecting `q` along the
//! directions of that cone onto the camera plane (a central projection from `q`, as long as
//! no direction of the cone is parallel to the plane: [`Camera::one_sided`]) lands inside the
//! convex hull of its projections along the `d_j`, and the projection along one direction is
//! affine in `q`; so `b` lies in the convex hull of the nine points `p_ij`, the corners `q_i`
//! projected along the `d_j`.
//!
//! - [`Bound::Paper`]: the paper's bounding triangle of the nine points, its edges parallel
//!   to the lines `L_k` (in the plane, orthogonal to `d_k`), each pushed out to the outermost
//!   point; the camera triangle's own edges where a `d_k` is orthogonal to the plane or the
//!   three lines do not enclose a triangle. It is rasterised clipped to the camera triangle's
//!   pixel rectangle (the paper's viewport; with a projective screen map, to the camera
//!   triangle itself, where the map has no pole).
//! - [`Bound::Tight`]: the convex hull of the nine points clipped to the camera triangle, the
//!   points projected onto the camera triangle's plane along its rays through the scene
//!   triangle ([`Camera::plane_through`]: the argument holds on every plane of the points a
//!   fixed distance along the rays, and projecting onto a plane near the points moves them
//!   little, however much the rays diverge), and where that region is still large, the same on each quarter of the camera triangle
//!   (recursively): a quarter is itself a camera triangle (its corner rays are interpolated
//!   rays of the parent), so the argument holds for it, and its narrower cone of directions
//!   gives a smaller hull. The union of the quarters' regions holds every fragment.
//!
//! The argument needs only a cone of three directions holding every ray direction of the
//! (piece of the) camera triangle ([`Camera::cone`]): the corner directions for interpolated
//! rays, an enclosing cone for the per-fragment rays of a mirror ([`super::mirror_cone`],
//! projected onto the base plane only, where those rays start at their own barycentrics).
//!
//! Where the cone of directions meets the plane from both sides (or there is no plane, or no
//! cone), no hull bounds the region: the whole (sub-)triangle is the bound. Every region is dilated by
//! [`MARGIN_PX`] so that rounding never drops a pixel centre on its exact boundary.

use glam::{DVec2, DVec3};

use super::camera::{same_side, AlongDirection, Camera, CameraPlane, CORNERS};
use super::convex::{cross, Convex};
use crate::render::trilinear::plane_hit;

/// How far bound regions are pushed out, in pixels, against rounding.
pub const MARGIN_PX: f64 = 1e-4;

/// Deepest quartering of the camera triangle by the tight bound.
pub const MAX_DEPTH: u32 = 6;

/// A region of fewer pixels than this is not quartered further.
const MIN_SPLIT_PIXELS: f64 = 16.0;

/// Nor is one that exceeds the estimate of the scene triangle's image in it
/// ([`excess_pixels`]) by fewer pixels than this: the quarters' hulls and clips would cost
/// more than the few fragments they could save. (With 12, Table 1's reflection rows keep
/// their overdraw under 3, 2.66 to 2.86, with 20 to 60 % fewer regions; 16 brought the
/// 4-camera-triangle row to 2.90.)
const MIN_SPLIT_EXCESS_PX: f64 = 12.0;

/// The shallowest pieces [`MIN_SPLIT_EXCESS_PX`] stops: on the whole camera triangle and its
/// quarters the rays spread so widely that the corners' mean projections say little about
/// where the image lies (without culling, which hands the bound pieces of depth 2, Table 1's
/// 25-camera-triangle row rose to overdraw 3.35 with the rule applied from depth 0).
const EXCESS_FROM_DEPTH: u32 = 2;

/// Which bounding region is rasterised per scene triangle and camera triangle (`--bound`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Bound {
    /// The paper's bounding triangle (module doc).
    Paper,
    /// The hull of the nine projections clipped to the camera triangle, quartered where
    /// large (module doc).
    #[default]
    Tight,
}

impl std::str::FromStr for Bound {
    type Err = crate::error::Error;

    fn from_str(s: &str) -> crate::error::Result<Bound> {
        match s {
            "paper" => Ok(Bound::Paper),
            "tight" => Ok(Bound::Tight),
            _ => Err(crate::error::Error::new(format!(
                "unknown bound \"{s}\" (available: paper, tight)"
            ))),
        }
    }
}

/// Calls `emit` with each pixel-space region (convex, counter-clockwise in a y-up frame or
/// clockwise, either) of `camera`'s image where scene triangle `q` may appear by `bound`.
pub fn regions(camera: &Camera, q: &[DVec3; 3], bound: Bound, emit: &mut impl FnMut(&Convex)) {
    match bound {
        Bound::Paper => paper(camera, q, emit),
        Bound::Tight => tight_in(camera, q, tight_plane(camera, q).as_ref(), CORNERS, 0, emit),
    }
}

/// The plane the tight bound projects scene triangle `q` onto ([`Camera::plane_through`]
/// its centroid), the same for every piece of the camera triangle.
pub fn tight_plane(camera: &Camera, q: &[DVec3; 3]) -> Option<CameraPlane> {
    camera.plane_through((q[0] + q[1] + q[2]) / 3.0)
}

/// The regions of [`Bound::Tight`] for scene triangle `q` inside the sub-triangle `sub` of
/// the camera triangle, a piece of its quartering at `depth` (the whole camera triangle:
/// [`CORNERS`] at depth 0), projected onto `plane` (the triangle's [`tight_plane`]): the
/// union over the pieces of a quartering holds every fragment the whole would.
pub fn tight_in(
    camera: &Camera,
    q: &[DVec3; 3],
    plane: Option<&CameraPlane>,
    sub: [DVec2; 3],
    depth: u32,
    emit: &mut impl FnMut(&Convex),
) {
    let views = sub.map(|b| CornerView::of(camera, plane, q, b));
    let views = match &views {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        _ => None,
    };
    tight(camera, plane, q, sub, views, depth, emit)
}

/// The four quarters of `sub` (corners, then the middle one), in the order the tight bound
/// visits them.
pub fn quarters(sub: [DVec2; 3]) -> [[DVec2; 3]; 4] {
    split(sub, midpoints(sub))
}

/// The midpoints of the sides `ab`, `bc`, `ca` of `[a, b, c]`.
fn midpoints([a, b, c]: [DVec2; 3]) -> [DVec2; 3] {
    [(a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0]
}

/// The corners of the four quarters of a triangle (of [`quarters`]) from what belongs to its
/// corners and to its sides' [`midpoints`].
fn split<T: Copy>([a, b, c]: [T; 3], [ab, bc, ca]: [T; 3]) -> [[T; 3]; 4] {
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [bc, ca, ab]]
}

/// [`split`] as indices into `[a, b, c, ab, bc, ca]`: the corners of quarter `i` are
/// `SPLIT[i]`, for picking what belongs to them without building all four quarters.
const SPLIT: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [4, 5, 3]];

/// What the tight bound uses of one corner of a piece, for one scene triangle and plane,
/// where the piece's cone is its corners' directions ([`Camera::corner_direction`]): the
/// side of the plane the corner's direction crosses, and the scene triangle's corners
/// projected along it. A corner is shared by up to six pieces of a quartering (a piece's
/// quarters take its corners and its sides' midpoints), so each is computed once and
/// handed down; the values are those [`nine`] computes for each piece.
#[derive(Debug, Clone, Copy)]
struct CornerView {
    /// [`CameraPlane::side`] of the direction (`0` without a plane).
    side: i32,
    /// The projections (`None` where the direction is parallel to the plane or one is
    /// beyond [`FAR`]).
    projected: Option<[DVec2; 3]>,
}

impl CornerView {
    /// The view from corner `b` (`None` for a per-fragment mirror: its cone is per piece).
    fn of(
        camera: &Camera,
        plane: Option<&CameraPlane>,
        q: &[DVec3; 3],
        b: DVec2,
    ) -> Option<CornerView> {
        let d = camera.corner_direction(b)?;
        let Some(plane) = plane else {
            return Some(CornerView {
                side: 0,
                projected: None,
            });
        };
        let projected = plane.along(d).and_then(|a| {
            Some([
                near(a.project(q[0]))?,
                near(a.project(q[1]))?,
                near(a.project(q[2]))?,
            ])
        });
        Some(CornerView {
            side: plane.side(d),
            projected,
        })
    }

    /// The nine points of a piece with these corners (as [`nine`] orders them), `None`
    /// where its cone is not [`same_side`] or a projection failed.
    fn nine(views: [&CornerView; 3]) -> Option<[DVec2; 9]> {
        if !same_side(views.map(|v| v.side)) {
            return None;
        }
        let p = [
            views[0].projected?,
            views[1].projected?,
            views[2].projected?,
        ];
        Some(std::array::from_fn(|k| p[k % 3][k / 3]))
    }
}

/// The culling of section 2.4 for one piece `sub` of a camera triangle (the whole camera
/// triangle, [`CORNERS`], or a piece of its quartering: a piece is itself a camera
/// triangle, its corner rays the camera's rays there), for any number of point sets (a
/// box's eight corners, or a triangle): [`PieceTest::misses`]. The piece's cone of
/// directions is found once, and the projections along it onto a plane once per plane (the
/// camera plane, and the last plane near the points, which neighbouring clusters share).
pub struct PieceTest<'a> {
    camera: &'a Camera,
    sub: [DVec2; 3],
    directions: Option<[DVec3; 3]>,
    /// The projections onto the camera plane, once computed (`None` inside: the plane is
    /// crossed from both sides, or a direction is parallel to it).
    base: Option<Option<[AlongDirection; 3]>>,
    /// The last near plane used and its projections.
    near: Option<(*const CameraPlane, Option<[AlongDirection; 3]>)>,
}

impl<'a> PieceTest<'a> {
    pub fn new(camera: &'a Camera, sub: [DVec2; 3]) -> PieceTest<'a> {
        PieceTest {
            camera,
            sub,
            directions: camera.cone(sub),
            base: None,
            near: None,
        }
    }

    /// Whether the convex hull of `points` projected along the piece's directions misses
    /// the piece (so nothing inside that hull is seen by it), on the plane near the points
    /// or on the camera plane (either hull that misses proves it); `false` where no hull
    /// bounds the region.
    pub fn misses(&mut self, points: &[DVec3]) -> bool {
        let Some(directions) = self.directions else {
            return false;
        };
        let along = |plane: &CameraPlane| {
            plane
                .one_sided(&directions)
                .then(|| alongs(plane, &directions))
                .flatten()
        };
        let centre = points.iter().sum::<DVec3>() / points.len().max(1) as f64;
        if let Some(plane) = self.camera.plane_near(centre) {
            let along = match self.near {
                Some((last, along)) if std::ptr::eq(last, plane) => along,
                _ => {
                    let made = along(plane);
                    self.near = Some((plane, made));
                    made
                }
            };
            if along.is_some_and(|a| misses_along(&a, self.sub, points)) {
                return true;
            }
        }
        let Some(plane) = self.camera.plane() else {
            return false;
        };
        let along = *self.base.get_or_insert_with(|| along(plane));
        along.is_some_and(|a| misses_along(&a, self.sub, points))
    }
}

/// [`PieceTest::misses`] with the projections onto one plane. Conservative: a miss is
/// reported only where a line separates the projected points from the piece (one of its
/// edges, or an axis of its bounding box), and never where a projection is not [`near`].
fn misses_along(along: &[AlongDirection; 3], sub: [DVec2; 3], points: &[DVec3]) -> bool {
    let separation = Separation::new(sub);
    let mut outside = Separation::ALL;
    for &q in points.iter().take(8) {
        for a in along {
            match near(a.project(q)) {
                Some(p) => outside &= separation.outside(p),
                None => return false,
            }
        }
    }
    outside != 0
}

/// The lines that may separate points from a triangle: its three edges and the four sides
/// of its bounding box ([`Separation::outside`]).
struct Separation {
    t: [DVec2; 3],
    orient: f64,
    lo: DVec2,
    hi: DVec2,
}

impl Separation {
    /// Every line.
    const ALL: u8 = 0x7f;

    fn new(t: [DVec2; 3]) -> Separation {
        Separation {
            t,
            orient: cross(t[0], t[1], t[2]).signum(),
            lo: t[0].min(t[1]).min(t[2]),
            hi: t[0].max(t[1]).max(t[2]),
        }
    }

    /// The lines that finite point `p` lies strictly beyond, as bits: edge `i` of the
    /// triangle (from corner `i` to the next) is bit `i`, then `x < lo.x`, `x > hi.x`,
    /// `y < lo.y`, `y > hi.y`. Points that share a bit all lie beyond that line.
    #[inline]
    fn outside(&self, p: DVec2) -> u8 {
        let t = &self.t;
        let edge = |i: usize| u8::from(cross(t[i], t[(i + 1) % 3], p) * self.orient < 0.0) << i;
        edge(0)
            | edge(1)
            | edge(2)
            | u8::from(p.x < self.lo.x) << 3
            | u8::from(p.x > self.hi.x) << 4
            | u8::from(p.y < self.lo.y) << 5
            | u8::from(p.y > self.hi.y) << 6
    }
}

/// Whether all `points` (finite) lie strictly outside one edge of triangle `t` (either
/// orientation): then their convex hull misses `t`.
fn outside_an_edge(points: &[DVec2], t: [DVec2; 3]) -> bool {
    let orient = cross(t[0], t[1], t[2]).signum();
    (0..3).any(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        points.iter().all(|&p| cross(a, b, p) * orient < 0.0)
    })
}

/// Projections farther than this from the camera triangle (in barycentrics) make no bound:
/// their rounding error could exceed the triangle itself.
const FAR: f64 = 1e6;

/// The nine projections `p_ij` of the corners `q` along `directions` (`None` if one is
/// parallel to the plane or beyond [`FAR`]).
fn nine(plane: &CameraPlane, q: &[DVec3; 3], directions: &[DVec3; 3]) -> Option<[DVec2; 9]> {
    let along = alongs(plane, directions)?;
    let mut out = [DVec2::ZERO; 9];
    for (i, &qi) in q.iter().enumerate() {
        for (j, a) in along.iter().enumerate() {
            out[3 * i + j] = near(a.project(qi))?;
        }
    }
    Some(out)
}

/// The projections along each of `directions` (`None` if one is parallel to the plane).
fn alongs(plane: &CameraPlane, directions: &[DVec3; 3]) -> Option<[AlongDirection; 3]> {
    Some([
        plane.along(directions[0])?,
        plane.along(directions[1])?,
        plane.along(directions[2])?,
    ])
}

/// `p` unless it is beyond [`FAR`] or not finite.
fn near(p: DVec2) -> Option<DVec2> {
    (p.abs().max_element() <= FAR).then_some(p)
}

/// The paper's bound (module doc).
fn paper(camera: &Camera, q: &[DVec3; 3], emit: &mut impl FnMut(&Convex)) {
    let triangle = camera.cone(CORNERS).and_then(|directions| {
        let plane = camera
            .plane()
            .filter(|plane| plane.one_sided(&directions))?;
        let points = nine(plane, q, &directions)?;
        bounding_triangle(plane, &directions, &points)
    });
    let Some(triangle) = triangle else {
        return emit_in_camera(camera, Convex::from_points(&CORNERS), emit);
    };
    let region = Convex::from_points(&triangle);
    let region = if cross(triangle[0], triangle[1], triangle[2]) < 0.0 {
        Convex::from_points(&[triangle[0], triangle[2], triangle[1]])
    } else {
        region
    };
    if camera.map.homogeneous_weight(0.0, 0.0).is_none() {
        // Affine screen map: the triangle in pixels, clipped to the viewport.
        let (lo, hi) = camera.pixel_box;
        let pixels = region
            .map(|b| camera.map.pixel(b.x, b.y))
            .clip_to_rect(lo, hi);
        emit_pixels(pixels, emit);
    } else {
        emit_in_camera(camera, region.clip_to_triangle(CORNERS), emit);
    }
}

/// The bounding triangle of `points` with edges parallel to the lines `L_k` orthogonal to
/// `directions` (in the camera plane), or to the camera triangle's edges in the singular
/// cases; `None` for non-finite results.
fn bounding_triangle(
    plane: &CameraPlane,
    directions: &[DVec3; 3],
    points: &[DVec2; 9],
) -> Option<[DVec2; 3]> {
    let centroid = DVec2::splat(1.0 / 3.0);
    // The outward normal of the edge opposite corner k, as a covector on barycentrics:
    // m_k turned to point from the centroid towards corner k (the line L_k is then on the
    // far side of the region from the opposite edge), or the camera edge's own.
    let lines: Option<[DVec2; 3]> = (0..3)
        .map(|k| {
            let g = plane.in_plane_covector(directions[k])?;
            Some(if g.dot(CORNERS[k] - centroid) < 0.0 {
                -g
            } else {
                g
            })
        })
        .collect::<Option<Vec<_>>>()
        .map(|v| [v[0], v[1], v[2]]);
    let edges = [
        DVec2::new(1.0, 1.0),
        DVec2::new(-1.0, 0.0),
        DVec2::new(0.0, -1.0),
    ];
    let normals = match lines {
        Some(g) if encloses(g) => g,
        _ => edges,
    };
    let offsets = normals.map(|g| {
        points
            .iter()
            .map(|&p| g.dot(p))
            .fold(f64::NEG_INFINITY, f64::max)
    });
    // Corner b_k lies on the two lines other than line k.
    let corner = |i: usize, j: usize| {
        let m = glam::DMat2::from_cols(normals[i], normals[j]).transpose();
        let det = m.determinant();
        (det != 0.0).then(|| m.inverse() * DVec2::new(offsets[i], offsets[j]))
    };
    let b = [corner(1, 2)?, corner(0, 2)?, corner(0, 1)?];
    b.iter().all(|p| p.is_finite()).then_some(b)
}

/// Whether half-planes with outward normals `g` enclose a bounded triangle: the origin lies
/// strictly inside the triangle of the normals (they span the plane positively).
fn encloses(g: [DVec2; 3]) -> bool {
    let c = [
        g[0].perp_dot(g[1]),
        g[1].perp_dot(g[2]),
        g[2].perp_dot(g[0]),
    ];
    let scale = g.iter().map(|v| v.length_squared()).fold(0.0, f64::max);
    let tiny = 1e-9 * scale;
    (c.iter().all(|&x| x > tiny)) || (c.iter().all(|&x| x < -tiny))
}

/// The tight bound on the sub-triangle `sub` of the camera triangle (module doc), with the
/// [`CornerView`]s of its corners where its cone is theirs.
fn tight(
    camera: &Camera,
    plane: Option<&CameraPlane>,
    q: &[DVec3; 3],
    sub: [DVec2; 3],
    views: Option<[&CornerView; 3]>,
    depth: u32,
    emit: &mut impl FnMut(&Convex),
) {
    let points = match views {
        Some(views) => CornerView::nine(views),
        None => camera.cone(sub).and_then(|directions| {
            let plane = plane.filter(|p| p.one_sided(&directions))?;
            nine(plane, q, &directions)
        }),
    };
    if points.is_some_and(|points| outside_an_edge(&points, sub)) {
        // The hull lies beyond a line of `sub`: nothing of the piece sees the triangle.
        return;
    }
    let region = points
        .map(|points| Convex::hull(&points).clip_to_triangle(sub))
        .unwrap_or_else(|| Convex::from_points(&sub).clip_to_triangle(CORNERS));
    if region.points().len() < 3 {
        return;
    }
    let pixels = region.area() * camera.pixels_per_area;
    if depth >= MAX_DEPTH
        || pixels < MIN_SPLIT_PIXELS
        || (depth >= EXCESS_FROM_DEPTH
            && excess_pixels(points.as_ref(), sub, pixels, camera) < MIN_SPLIT_EXCESS_PX)
        || covers(camera, q, sub)
    {
        return emit_in_camera(camera, region, emit);
    }
    let mids = midpoints(sub);
    // The views of the piece's corners, then of its sides' midpoints (as [`SPLIT`] indexes
    // them).
    // (Referenced, not copied: each quarter picks three of the six.)
    let mid_views = views.map(|_| mids.map(|b| CornerView::of(camera, plane, q, b)));
    let corner_views = views
        .zip(mid_views.as_ref())
        .and_then(|(views, mid_views)| {
            Some([
                views[0],
                views[1],
                views[2],
                mid_views[0].as_ref()?,
                mid_views[1].as_ref()?,
                mid_views[2].as_ref()?,
            ])
        });
    for (quarter, corners) in split(sub, mids).into_iter().zip(SPLIT) {
        // A quarter's rays are among the piece's, so its region lies in the piece's: a
        // quarter that the region misses sees nothing of the triangle.
        if !outside_an_edge(region.points(), quarter) {
            let views = corner_views.as_ref().map(|v| corners.map(|c| v[c]));
            tight(camera, plane, q, quarter, views, depth + 1, emit);
        }
    }
}

/// How many pixels of the region `pixels` large could quartering the piece `sub` save: the
/// region's excess over an estimate of the scene triangle's image in the piece, the triangle
/// of its corners' mean projections (`points`, ordered as [`nine`] orders them) clipped to
/// the piece. The quarters' regions together still hold the image, so they cannot be
/// smaller than it; where the hull hugs the image (the rays are nearly parallel across the
/// piece at the triangle's distance, or the image fills the region), quartering only costs.
/// Without points (the region is the whole piece) or where the estimate degenerates (zero
/// area), the excess is the whole region. Only the quartering's stopping depends on it:
/// the regions hold every fragment whatever it says.
fn excess_pixels(
    points: Option<&[DVec2; 9]>,
    sub: [DVec2; 3],
    pixels: f64,
    camera: &Camera,
) -> f64 {
    let Some(p) = points else {
        return pixels;
    };
    let image = [0, 1, 2].map(|i| (p[3 * i] + p[3 * i + 1] + p[3 * i + 2]) / 3.0);
    let estimate = Convex::from_points(&image).clip_to_triangle(sub).area();
    pixels - estimate * camera.pixels_per_area
}

/// Whether the rays at the corners and centre of `sub` all hit the scene triangle `q`: then
/// it (nearly) covers the sub-triangle, and quarters would all be kept.
fn covers(camera: &Camera, q: &[DVec3; 3], sub: [DVec2; 3]) -> bool {
    let centre = (sub[0] + sub[1] + sub[2]) / 3.0;
    [sub[0], sub[1], sub[2], centre].iter().all(|&b| {
        camera
            .ray_at(b)
            .and_then(|ray| plane_hit(&ray, *q))
            .is_some_and(|(t, u, v)| t >= 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0)
    })
}

/// Emits a region given in barycentrics inside the camera triangle, in pixels.
fn emit_in_camera(camera: &Camera, region: Convex, emit: &mut impl FnMut(&Convex)) {
    emit_pixels(region.map(|b| camera.map.pixel(b.x, b.y)), emit);
}

/// Emits a pixel-space region with the rounding margin, if it has an area.
fn emit_pixels(region: Convex, emit: &mut impl FnMut(&Convex)) {
    if region.points().len() >= 3 {
        emit(&region.dilated(MARGIN_PX));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::trilinear_builders::SurfaceRays;
    use crate::projection::Trilinear;
    use crate::render::camera_triangles::tests::{load, mirror_surface};
    use crate::render::trilinear::SceneGeometry;
    use crate::scene::Scene;

    /// Every piece of the tight bound's quartering (down to depth 3) gets from the
    /// [`CornerView`]s handed down the nine points that projecting along its own cone gives,
    /// bit for bit, or none where that gives none: on trilinear scenes and on a mirror
    /// sphere's diverging rays (planes along the rays).
    #[test]
    fn corner_views_give_each_piece_its_nine_points() {
        let mut cases: Vec<(Trilinear, Scene)> = ["trilinear-fan", "trilinear-grid-cylinder"]
            .iter()
            .map(|name| {
                let scene = load(name);
                let projection = scene.projection.build(96, 72).unwrap();
                (projection.trilinear().unwrap().clone(), scene)
            })
            .collect();
        cases.push(mirror_surface(
            "reflect-sphere-cube",
            SurfaceRays::Interpolated,
        ));
        for (projection, scene) in &cases {
            let geometry = SceneGeometry::new(scene);
            let cameras = Camera::all(projection);
            let (mut pieces, mut with_points) = (0, 0);
            // About 3,000 pairs: every camera, every `step`-th triangle from an offset
            // that differs per camera.
            let step = (cameras.len() * geometry.triangles.len() / 3000).max(1);
            for (c, camera) in cameras.iter().enumerate() {
                for k in (c % step..geometry.triangles.len()).step_by(step) {
                    let q = geometry.corners(k);
                    let plane = camera.plane_near((q[0] + q[1] + q[2]) / 3.0);
                    let views = CORNERS.map(|b| CornerView::of(camera, plane, &q, b).unwrap());
                    check(
                        camera,
                        plane,
                        &q,
                        CORNERS,
                        views,
                        0,
                        &mut pieces,
                        &mut with_points,
                    );
                }
            }
            assert!(
                pieces > 10_000 && with_points > 1_000,
                "{pieces} {with_points}"
            );
        }
    }

    /// Compares the piece `sub` and its quarters down to depth 3.
    #[allow(clippy::too_many_arguments)]
    fn check(
        camera: &Camera,
        plane: Option<&CameraPlane>,
        q: &[DVec3; 3],
        sub: [DVec2; 3],
        views: [CornerView; 3],
        depth: u32,
        pieces: &mut usize,
        with_points: &mut usize,
    ) {
        let direct = camera.cone(sub).and_then(|directions| {
            let plane = plane.filter(|p| p.one_sided(&directions))?;
            nine(plane, q, &directions)
        });
        let bits = |p: Option<[DVec2; 9]>| p.map(|p| p.map(|x| (x.x.to_bits(), x.y.to_bits())));
        assert_eq!(
            bits(CornerView::nine(views.each_ref())),
            bits(direct),
            "{sub:?}"
        );
        *pieces += 1;
        *with_points += usize::from(direct.is_some());
        if depth == 3 {
            return;
        }
        let mids = midpoints(sub).map(|b| CornerView::of(camera, plane, q, b).unwrap());
        for (quarter, views) in quarters(sub).into_iter().zip(split(views, mids)) {
            check(
                camera,
                plane,
                q,
                quarter,
                views,
                depth + 1,
                pieces,
                with_points,
            );
        }
    }
}
