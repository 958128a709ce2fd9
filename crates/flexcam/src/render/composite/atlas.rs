//! The joint texture atlas of camera triangles (Hou, Wei, Shum and Guo 2006, section 2.3;
//! scene key `reflection = "atlas"`): every camera triangle of a reflector's surface is given a
//! right triangle of the same size in one texture, the scene without the reflector is rendered
//! through that atlas projection (each atlas triangle a projection triangle with the camera
//! triangle's three vertex rays, so the renderer, camera triangles or any other, works on it
//! unchanged), and a final pass texture-maps the reflector of the main view from the atlas.
//!
//! The final pass follows the paper's correspondence: at each main-image pixel that sees the
//! reflector, the main camera's ray meets the original (fine) reflector at a point `P` with
//! shading normal `N` (exactly, as [`super::FresnelSplit`] intersects it), and the line
//! `P + s N` is shot at the camera mesh; the nearest camera triangle it meets, and the
//! barycentrics there, name the atlas point whose colour the pixel takes (bilinear, a
//! sample point within one and a half texels of its triangle's edge moved in to that
//! distance, so that no tap reads a neighbour or the gap). Unlike the screen-space lookup of the default compositing, this covers the whole
//! original reflector, also where its silhouette reaches beyond the coarse camera mesh's.
//!
//! Layout: camera triangles in pairs, each pair a square cell of `S + 3` texels holding two
//! right triangles with legs of `S` texels, one texel apart along their hypotenuses and from
//! the cell's edges; cells in rows, as square an arrangement as the count allows. `S` is
//! [`DENSITY`] times `sqrt(2 A)` for the 90th percentile of the camera triangles' screen
//! areas `A` in main-image pixels (an atlas triangle then has four texels for each pixel of
//! nine in ten camera triangles: resampling the atlas blurs what the main image shows less),
//! between [`MIN_CELL`] and [`MAX_CELL`], and smaller where the atlas would exceed
//! [`MAX_SIDE`] texels a side.
//!
//! Degenerate cases: a pixel whose ray misses the reflector (a grazing edge the exact test
//! rejects), whose point has no usable normal, or whose normal line meets no camera triangle
//! (a camera triangle the surface left out, or a point beyond the camera mesh's rim along
//! its normal) is returned as missed, for the caller to ray cast exactly. A surface without
//! triangles has no atlas (the caller renders nothing through it). The per-fragment rays of
//! `camera_rays = "per-fragment"` are not used: the atlas interpolates the vertex rays.

use std::sync::Arc;

use glam::{Affine3A, DVec2, DVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::{only, pixel_centre};
use crate::error::{Error, Result};
use crate::geometry::Ray;
use crate::projection::{Perspective, Projection, Trilinear, TrilinearMesh};
use crate::render::prepared::PreparedScene;
use crate::render::shading::normals;
use crate::render::{Counter, Frame, RenderOptions, Stats};
use crate::scene::{Material, Mesh, Object};

/// The smallest leg of an atlas triangle, texels.
pub const MIN_CELL: u32 = 8;
/// The largest leg of an atlas triangle, texels.
pub const MAX_CELL: u32 = 256;
/// The largest side of the atlas, texels.
pub const MAX_SIDE: u32 = 4096;

/// The atlas triangles' legs over `sqrt(2 A)` of the camera triangles' screen areas `A`:
/// four texels per main-image pixel. Measured on `camtri-convex.toml` (flat, 320 x 240, mean
/// absolute 8-bit difference from the exact mirror): 3.7 at one texel per pixel, 2.0 at
/// four, 1.2 at sixteen; the screen-space compositing 0.64.
const DENSITY: f64 = 2.0;

/// Texels between a cell's triangles and around them (1 each side, 1 between).
const CELL_MARGIN: u32 = 3;

/// How far inside its triangle a sample point is kept, texels.
const SAMPLE_INSET: f64 = 1.5;

/// The atlas's layout: `columns` x `rows` cells of legs `cell` texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub cell: u32,
    pub columns: u32,
    pub rows: u32,
}

impl Layout {
    /// The layout of `triangles` camera triangles in cells of legs `leg_px` texels, clamped
    /// to [`MIN_CELL`, `MAX_CELL`] (module doc). Errors: more triangles than an atlas of
    /// [`MAX_SIDE`] texels holds at [`MIN_CELL`].
    pub fn new(triangles: usize, leg_px: f64) -> Result<Layout> {
        let cells = triangles.div_ceil(2).max(1) as u64;
        let columns = (cells as f64).sqrt().ceil() as u64;
        let rows = cells.div_ceil(columns);
        let fits = u64::from(MAX_SIDE) / columns.max(rows);
        let wanted = if leg_px.is_finite() {
            leg_px
                .ceil()
                .clamp(f64::from(MIN_CELL), f64::from(MAX_CELL)) as u64
        } else {
            u64::from(MIN_CELL)
        };
        let cell = wanted.min(fits.saturating_sub(u64::from(CELL_MARGIN)));
        if cell < u64::from(MIN_CELL) {
            return Err(Error::new(format!(
                "a texture atlas of {triangles} camera triangles would need more than \
                 {MAX_SIDE} x {MAX_SIDE} texels; give the reflector fewer camera triangles"
            )));
        }
        Ok(Layout {
            cell: cell as u32,
            columns: columns as u32,
            rows: rows as u32,
        })
    }

    /// The atlas's size in texels.
    pub fn size(&self) -> (u32, u32) {
        let side = self.cell + CELL_MARGIN;
        (self.columns * side, self.rows * side)
    }

    /// The corners of atlas triangle `k` (texel coordinates, y down), the right angle first:
    /// the upper-left triangle of cell `k / 2` for even `k`, the lower-right for odd.
    pub fn corners(&self, k: usize) -> [DVec2; 3] {
        let side = f64::from(self.cell + CELL_MARGIN);
        let cell = k / 2;
        let origin = DVec2::new(
            (cell % self.columns as usize) as f64 * side,
            (cell / self.columns as usize) as f64 * side,
        );
        let s = f64::from(self.cell);
        if k % 2 == 0 {
            let a = origin + DVec2::splat(1.0);
            [a, a + DVec2::new(s, 0.0), a + DVec2::new(0.0, s)]
        } else {
            let a = origin + DVec2::splat(2.0 + s);
            [a, a - DVec2::new(s, 0.0), a - DVec2::new(0.0, s)]
        }
    }
}

/// A reflector's atlas: the layout, and per camera triangle (surface triangle order) its
/// three corners in vertex order.
pub struct Atlas {
    pub layout: Layout,
    corners: Vec<[DVec2; 3]>,
}

impl Atlas {
    /// The atlas of `surface` (a reflector surface in main-image pixels): its layout, and
    /// the projection of the atlas with each camera triangle's vertex rays at its atlas
    /// triangle, wound as the triangle is on the screen. `None` without triangles. Errors:
    /// those of [`Layout::new`] and [`Trilinear::new`].
    pub fn new(surface: &Trilinear) -> Result<Option<(Atlas, Trilinear)>> {
        let mesh = surface.mesh();
        if mesh.triangles.is_empty() {
            return Ok(None);
        }
        let (width, height) = surface.resolution();
        let size = DVec2::new(f64::from(width), f64::from(height));
        let on_screen = |v: u32| mesh.screen[v as usize] * size;
        // The leg that gives a triangle as many texels as it has pixels on the screen
        // (sqrt(2 area)) at the 90th percentile, doubled ([`DENSITY`]).
        let mut legs: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(on_screen);
                (b - a).perp_dot(c - a).abs().sqrt()
            })
            .collect();
        legs.sort_by(f64::total_cmp);
        let leg = legs[(legs.len() * 9 / 10).min(legs.len() - 1)];
        let layout = Layout::new(mesh.triangles.len(), DENSITY * leg)?;
        let (atlas_width, atlas_height) = layout.size();
        let texels = DVec2::new(f64::from(atlas_width), f64::from(atlas_height));
        let mut atlas_mesh = TrilinearMesh::default();
        let mut corners = Vec::with_capacity(mesh.triangles.len());
        for (k, t) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = t.map(on_screen);
            let mut cell = layout.corners(k);
            // Screen y points up, texel y down: a counter-clockwise screen triangle is
            // clockwise in texels. Keep the screen's winding.
            let screen_turn = (b - a).perp_dot(c - a);
            let atlas_turn = -(cell[1] - cell[0]).perp_dot(cell[2] - cell[0]);
            if screen_turn * atlas_turn < 0.0 {
                cell.swap(1, 2);
            }
            for (&v, corner) in t.iter().zip(cell) {
                atlas_mesh.points.push(mesh.points[v as usize]);
                atlas_mesh.normals.push(mesh.normals[v as usize]);
                atlas_mesh
                    .screen
                    .push(DVec2::new(corner.x / texels.x, 1.0 - corner.y / texels.y));
            }
            let first = (3 * k) as u32;
            atlas_mesh.triangles.push([first, first + 1, first + 2]);
            corners.push(cell);
        }
        let projection = Trilinear::new(&atlas_mesh, atlas_width, atlas_height)?;
        Ok(Some((Atlas { layout, corners }, projection)))
    }

    /// The colour of `image` (the atlas rendered) at barycentrics `(u, v)` of camera triangle
    /// `triangle`: bilinear, a point nearer than [`SAMPLE_INSET`] texels to an edge of its
    /// atlas triangle moved in to that distance.
    fn sample(&self, image: &Frame, triangle: usize, (u, v): (f64, f64)) -> Vec3 {
        let [a, b, c] = self.corners[triangle];
        // Barycentric distances that keep the point SAMPLE_INSET texels off the legs
        // (weights u, v) and off the hypotenuse (weight w, across which the triangle's
        // height is S / sqrt 2); points farther inside are not moved.
        let leg = (SAMPLE_INSET / f64::from(self.layout.cell)).min(0.2);
        let hypotenuse = (leg * std::f64::consts::SQRT_2).min(0.2);
        let (mut u, mut v) = (u.max(leg), v.max(leg));
        let room = 1.0 - hypotenuse;
        if u + v > room {
            let excess = u + v - room;
            // Take the excess from the weights above the leg bound, in proportion.
            let (su, sv) = (u - leg, v - leg);
            let share = excess / (su + sv).max(f64::MIN_POSITIVE);
            u -= su * share.min(1.0);
            v -= sv * share.min(1.0);
        }
        let w = 1.0 - u - v;
        let p = a * w + b * u + c * v - DVec2::splat(0.5);
        let base = p.floor();
        let f = (p - base).as_vec2();
        let texel = |dx: i64, dy: i64| {
            let x = (base.x as i64 + dx).clamp(0, i64::from(image.width) - 1) as usize;
            let y = (base.y as i64 + dy).clamp(0, i64::from(image.height) - 1) as usize;
            image.color[y * image.width as usize + x]
        };
        let top = texel(0, 0).lerp(texel(1, 0), f.x);
        let bottom = texel(0, 1).lerp(texel(1, 1), f.x);
        top.lerp(bottom, f.y)
    }
}

/// What the final pass of one reflector sees: the whole scene (`prepared`), the scene
/// without the reflector (`others`, rendered through the atlas), the reflector's id and the
/// main view (its ids) with its camera.
pub struct View<'a> {
    pub prepared: &'a PreparedScene,
    pub others: &'a PreparedScene,
    pub id: u32,
    pub main: &'a Frame,
    pub camera: &'a Perspective,
}

impl View<'_> {
    /// The reflection (refraction) of the reflector through `surface` by way of its atlas:
    /// `others` rendered through the atlas projection with `render`, and every pixel of the
    /// main view that sees the reflector texture-mapped from it (module doc). Returns the
    /// image in main-image pixels (other pixels hold the background), the atlas render's
    /// stats with `atlas_width`, `atlas_height`, `atlas_cell_px` and
    /// `atlas_missed_pixels`, the pixels missed (for the caller to ray cast), and the atlas
    /// as rendered (none for a surface without triangles).
    pub fn image(
        &self,
        surface: &Trilinear,
        options: &RenderOptions,
        render: &super::Renderer,
    ) -> Result<Mapped> {
        let (main, id) = (self.main, self.id);
        let background = self.others.scene().image.background;
        let mut frame = Frame::try_new(main.width, main.height, background)?;
        let Some((atlas, projection)) = Atlas::new(surface)? else {
            let all = (0..main.ids.len()).filter(|&k| main.ids[k] == id).collect();
            return Ok(Mapped {
                image: frame,
                stats: Stats::new(),
                missed: all,
                atlas: None,
            });
        };
        let (atlas_image, mut stats) = render(self.others, &projection, options)?;
        let reflector = self
            .prepared
            .view(only(self.prepared.scene(), |o| o.id == id));
        let camera_mesh = camera_mesh_scene(self.others, surface);
        let width = main.width as usize;
        let found: Vec<Option<Vec3>> = (0..main.ids.len())
            .into_par_iter()
            .map(|k| {
                if main.ids[k] != id {
                    return Some(background);
                }
                let ray = self.camera.ray(pixel_centre(k, width))?;
                let hit = reflector.intersect(&ray)?;
                let part = &reflector.scene().objects[hit.object];
                let direction = ray.direction.as_vec3();
                let seen = normals(part, hit.triangle, hit.barycentric, direction);
                let normal = seen.shading.as_dvec3().try_normalize()?;
                let (triangle, u, v) = shoot_normal(&camera_mesh, ray.at(hit.t), normal)?;
                Some(atlas.sample(&atlas_image, triangle, (u, v)))
            })
            .collect();
        let mut missed = Vec::new();
        for (k, colour) in found.into_iter().enumerate() {
            match colour {
                Some(colour) => frame.color[k] = colour,
                None => missed.push(k),
            }
        }
        let (atlas_width, atlas_height) = atlas.layout.size();
        for (name, value) in [
            ("atlas_width", atlas_width),
            ("atlas_height", atlas_height),
            ("atlas_cell_px", atlas.layout.cell),
        ] {
            stats.insert(name, Counter::Count(u64::from(value)));
        }
        stats.insert("atlas_missed_pixels", Counter::Count(missed.len() as u64));
        Ok(Mapped {
            image: frame,
            stats,
            missed,
            atlas: Some(atlas_image),
        })
    }
}

/// What [`View::image`] makes of one reflector.
pub struct Mapped {
    /// The reflector's pixels texture-mapped from the atlas, in main-image pixels.
    pub image: Frame,
    /// The atlas render's stats and the atlas counters.
    pub stats: Stats,
    /// The reflector's pixels the final pass missed (row-major indices).
    pub missed: Vec<usize>,
    /// The atlas as rendered.
    pub atlas: Option<Frame>,
}

/// The surface's camera mesh (its vertex points and triangles) as a prepared scene of one
/// object, for the normal lines of [`shoot_normal`].
fn camera_mesh_scene(others: &PreparedScene, surface: &Trilinear) -> PreparedScene {
    let mesh = surface.mesh();
    let mut scene = others.scene().clone();
    scene.objects = vec![Object {
        id: 1,
        name: "camera mesh".to_string(),
        mesh: Arc::new(Mesh {
            positions: mesh.points.iter().map(|p| p.as_vec3()).collect(),
            triangles: mesh.triangles.clone(),
            ..Mesh::default()
        }),
        material: Material::default(),
        world_to_object: Affine3A::IDENTITY,
        displacement: None,
    }];
    scene.lights.clear();
    scene.trilinear_reflectors.clear();
    scene.caustics.clear();
    scene.motions.clear();
    PreparedScene::new(&scene)
}

/// The camera triangle the line through `point` along `normal` meets nearest `point`, on
/// either side, with the barycentrics `(u, v)` of the meeting point; `None` if it meets none.
fn shoot_normal(
    camera_mesh: &PreparedScene,
    point: DVec3,
    normal: DVec3,
) -> Option<(usize, f64, f64)> {
    [normal, -normal]
        .into_iter()
        .filter_map(|direction| camera_mesh.intersect(&Ray::new(point, direction)))
        .min_by(|a, b| a.t.total_cmp(&b.t))
        .map(|hit| {
            let Vec2 { x: u, y: v } = hit.barycentric;
            (hit.triangle, f64::from(u), f64::from(v))
        })
}

#[cfg(test)]
mod tests;
