//! Adaptive refinement of a reflector mesh before its trilinear surface is built (Vallance 2005,
//! 7.2.2 leaves open "when and how much to tessellate").
//!
//! Between its vertices a reflection or refraction surface interpolates the vertex rays,
//! while the ray caster's true mirror reflects (refracts) about the shading normal
//! interpolated at the hit; on a curved reflector the two differ. [`refine`] splits the
//! reflector's triangles where they differ by more than a tolerance measured in main-image
//! pixels, so that the surface converges to the exact mirror:
//!
//! - **New vertices** lie on the flat reflector triangle (edge midpoints), with the shading
//!   normal the ray caster interpolates there (the raw vertex normals averaged, normalised
//!   only when used), so a new vertex's ray *is* the ray caster's mirror (refraction) ray at
//!   that point of the reflector.
//! - **The error of an edge** is measured at its midpoint `m`, where the surface's ray at the
//!   main-image pixel that sees `m` (barycentrics `(1/2, 1/2)` with the projective screen
//!   map; with the affine map, the screen-space fraction along the edge's image, and unit
//!   vertex rays, as [`SurfaceScreenMap`] interpolates) is compared with the exact ray from
//!   `m`, in main-image pixels of displacement of the reflected (refracted) image, the sum of
//!   two terms:
//!   - the angle `delta` between the two directions over the rate `sigma` at which the ray
//!     turns per main-image pixel along the edge (the angle between its end rays over its
//!     length in pixels, at least the main camera's own pixel angle at `m`): the displacement
//!     of distant content, independent of its distance (the error and the spread of the
//!     pixel's rays both grow with it). A convex mirror spreads its rays `sigma` many pixel
//!     angles apart, so it tolerates larger angular errors than a flat one; the floor at the
//!     pixel angle keeps a focusing lens (rays that converge: `sigma` near 0) from demanding
//!     unbounded refinement;
//!   - the offset of the surface ray's base point across the exact ray (zero with the
//!     projective map; with the affine map the base point is the screen-space blend, not
//!     `m`) over the pixel's footprint at the reflector (`|m - eye|` times the pixel angle):
//!     the displacement of content right behind the reflector, the worst case, since the
//!     pixel's beam only widens beyond it.
//! - **The bound**: an edge is split when its midpoint error exceeds `3/4` of the tolerance.
//!   For a ray field that is quadratic over a triangle (a smooth reflector, small triangles)
//!   the interpolation error inside is at most `4/3` of the largest edge-midpoint error
//!   (it peaks at the centroid when the three edge errors have the same sign: `(1/6) q`
//!   against `(1/8) q` at each midpoint), so every triangle's error stays within the
//!   tolerance without a separate centroid test.
//! - **Crack-free**: the decision is a function of the edge alone (its two end vertices and
//!   its level), made once and shared by the triangles on both sides, which split it at the
//!   same new vertex. A triangle with one, two or three split edges becomes two, three or four
//!   triangles (red-green refinement), so no vertex ever lies inside another triangle's edge
//!   (no T-junction, which would open a crack in the surface image).
//! - **Back-facing triangles stay whole** (mirrors): a triangle whose vertex normals all
//!   point clearly away from the eye (the far side of a sphere) is dropped by the surface,
//!   and so would every piece of it be ([`Refiner::back_facing`]), so it is not split; an
//!   edge it shares with a split neighbour leaves a T-junction only on its side, which the
//!   surface drops. The surface is the same as when every triangle is refined.
//!
//! Degenerate cases:
//! - **parallel vertex rays** (a triangle whose rays are all parallel, e.g. a flat mirror
//!   seen by a parallel eye, or straight rays at ior 1 meeting at a focus): the exact ray at
//!   the midpoint is the interpolated one (`delta = 0`), so nothing is split; the floor on
//!   `sigma` avoids dividing by the zero spread;
//! - **a grazing vertex ray** (incidence at 90 degrees): [`vertex_ray`]'s continuation, as the
//!   ray caster; such edges are short on screen and stop at [`MIN_EDGE_PX`];
//! - **total internal reflection** at a new vertex: its ray is the mirror reflection, as the
//!   ray caster's (and [`vertex_ray`]'s) fallback; the edge error is measured against it;
//! - **an edge end or midpoint without a ray** (on or behind the eye's plane, not imaged by
//!   the main camera), **an edge beyond one side of the main image** (both ends left of it,
//!   right of it, above or below it: no pixel sees it, and a large reflector reaching far
//!   outside the view is not refined there) or **an edge shorter than [`MIN_EDGE_PX`] on
//!   screen**: not split. A triangle that covers the image while all its edges lie outside
//!   it on different sides therefore stays whole (the thesis's surface there);
//! - **the depth cap** [`MAX_LEVEL`]: an edge of the input mesh is split into at most
//!   `2^MAX_LEVEL` pieces and a triangle into at most `4^MAX_LEVEL` (a pathological mesh, or
//!   a tolerance far below a pixel, cannot explode: at most 4,096 triangles per reflector
//!   triangle); edges still over the tolerance at the cap (or below [`MIN_EDGE_PX`]) are
//!   left as they are and counted ([`Refinement::unsplit`]);
//! - **a glass's silhouette**: where the eye's ray enters the glass at one end of an edge
//!   (or its midpoint) and leaves it at another ([`across_silhouette`]), the exact image itself
//!   jumps (the grazing ray refracted to the critical angle on one side, a ray going on
//!   nearly straight on the other), so the edge's error stays over any tolerance however
//!   short it gets; such edges are split down to [`MIN_EDGE_PX`], which confines the jump to
//!   a band under a pixel wide, and counted apart ([`Refinement::silhouette`]), not as over
//!   the tolerance;
//! - **a mesh without vertex normals, or a zero normal**: the area-weighted face normal, as
//!   [`reflector_surface`](crate::projection::trilinear_builders::reflector_surface) uses at the
//!   original vertices; the refined surface then converges to that smooth mirror, not to the
//!   ray caster's faceted one (which uses each face's own normal);
//! - **a tolerance of 0**: no refinement, the mesh as it is (the thesis's surface).

use std::collections::HashMap;

use glam::{DVec2, DVec3, Vec3};

use crate::projection::trilinear_builders::{
    enters, vertex_normals, vertex_ray, Optic, SurfaceScreenMap,
};
use crate::projection::{ContinuousInverse, Perspective, Projection};
use crate::scene::Mesh;

/// The deepest edge level: an input edge is split into at most `2^MAX_LEVEL` pieces.
pub const MAX_LEVEL: u32 = 6;

/// Edges shorter than this on screen (main-image pixels) are not split: below a pixel the
/// composite samples too few pixel centres for a split to matter.
pub const MIN_EDGE_PX: f64 = 1.0;

/// How clearly a triangle must face away for [`Refiner::back_facing`]: the cosines between
/// its face normal and each vertex normal, and between its face normal and the direction to
/// the eye, at least this far from zero. Far above the rounding of the `f32` midpoints (its
/// descendants' planes and normals are the parent's up to about `1e-4` of a cosine even at
/// the depth cap), so the surface's test on every descendant has the parent's sign.
const BACK_FACING_COSINE: f64 = 1e-2;

/// The edge-midpoint bound as a fraction of the tolerance (see the module docs: the error
/// inside a triangle is at most 4/3 of its largest edge-midpoint error).
const MIDPOINT_FRACTION: f64 = 0.75;

/// A refined reflector mesh.
#[derive(Debug, Clone)]
pub struct Refinement {
    /// Positions, shading normals (explicit at every vertex) and triangles; no texture
    /// coordinates or colours (a surface uses neither).
    pub mesh: Mesh,
    /// Edges still over the tolerance, left unsplit at the depth cap [`MAX_LEVEL`] or
    /// because they are shorter than [`MIN_EDGE_PX`] on screen, silhouette edges aside.
    pub unsplit: usize,
    /// Edges across a glass's silhouette ([`across_silhouette`]) split down to
    /// shorter than [`MIN_EDGE_PX`]: the exact image jumps inside them, so no split
    /// brings their error within a tolerance; the jump is confined to under a pixel.
    pub silhouette: usize,
}

/// Refines `reflector` (a world-space mesh) for the surface of `optic` seen by the main
/// camera `camera` with screen map `map`, until every edge's error is within
/// `tolerance_px` main-image pixels (see the module docs); a tolerance of 0 (or NaN) returns
/// the mesh unchanged. Triangles keep their winding.
pub fn refine(
    reflector: &Mesh,
    camera: &Perspective,
    optic: Optic,
    map: SurfaceScreenMap,
    tolerance_px: f64,
) -> Refinement {
    if tolerance_px.is_nan() || tolerance_px <= 0.0 {
        return Refinement {
            mesh: reflector.clone(),
            unsplit: 0,
            silhouette: 0,
        };
    }
    refine_where(
        reflector,
        Refiner::new(reflector, camera, optic, map, tolerance_px),
        |refiner, triangle| refiner.back_facing(triangle),
    )
}

/// The refinement loop of [`refine`] with `refiner`, leaving whole the triangles `whole`
/// holds for (their edges are decided only where a neighbour needs them).
fn refine_where(
    reflector: &Mesh,
    mut refiner: Refiner<'_>,
    whole: impl Fn(&Refiner<'_>, [u32; 3]) -> bool,
) -> Refinement {
    let mut stack: Vec<[u32; 3]> = reflector.triangles.iter().rev().copied().collect();
    let mut triangles = Vec::with_capacity(reflector.triangles.len());
    while let Some(triangle) = stack.pop() {
        let split = if whole(&refiner, triangle) {
            None
        } else {
            refiner.split_triangle(triangle)
        };
        match split {
            None => triangles.push(triangle),
            // Reversed so that the children come out in order.
            Some(children) => stack.extend(children.into_iter().rev()),
        }
    }
    Refinement {
        mesh: Mesh {
            positions: refiner.positions,
            normals: refiner.normals,
            triangles,
            ..Mesh::default()
        },
        unsplit: refiner.unsplit,
        silhouette: refiner.silhouette,
    }
}

/// A vertex as the surface sees it: its exact unit ray, the ray the map interpolates, and
/// its main-image pixel.
#[derive(Debug, Clone, Copy)]
struct Sample {
    point: DVec3,
    unit: DVec3,
    /// `unit` times the vertex's distance from the eye (projective map), or `unit` (affine).
    interpolated: DVec3,
    pixel: DVec2,
    /// Whether the eye's ray enters the reflector there ([`enters`]).
    entering: bool,
}

/// An edge's level and, once decided, its midpoint vertex (`Some(None)`: not split).
#[derive(Debug, Clone, Copy, Default)]
struct Edge {
    level: u32,
    midpoint: Option<Option<u32>>,
}

struct Refiner<'a> {
    camera: &'a Perspective,
    optic: Optic,
    map: SurfaceScreenMap,
    tolerance_px: f64,
    positions: Vec<Vec3>,
    /// Raw (not normalised) shading normals: averaging them is the ray caster's linear
    /// interpolation.
    normals: Vec<Vec3>,
    /// Face normals (area-weighted sums), for the side a ray arrives from.
    faces: Vec<DVec3>,
    samples: Vec<Option<Sample>>,
    /// Each vertex's first copy (same position and shading normal): edges are keyed by these,
    /// so that a seam of duplicated vertices splits at one shared midpoint on both sides.
    canonical: Vec<u32>,
    edges: HashMap<(u32, u32), Edge>,
    unsplit: usize,
    silhouette: usize,
}

impl<'a> Refiner<'a> {
    fn new(
        reflector: &Mesh,
        camera: &'a Perspective,
        optic: Optic,
        map: SurfaceScreenMap,
        tolerance_px: f64,
    ) -> Self {
        let (normals, faces): (Vec<Vec3>, Vec<DVec3>) = vertex_normals(reflector)
            .into_iter()
            .map(|(shading, face)| (shading.as_vec3(), face))
            .unzip();
        let canonical = canonical_vertices(&reflector.positions, &normals);
        let mut refiner = Refiner {
            camera,
            optic,
            map,
            tolerance_px,
            positions: reflector.positions.clone(),
            normals,
            faces,
            samples: Vec::new(),
            canonical,
            edges: HashMap::new(),
            unsplit: 0,
            silhouette: 0,
        };
        refiner.samples = (0..refiner.positions.len())
            .map(|k| refiner.sample_at(refiner.positions[k], refiner.normals[k], refiner.faces[k]))
            .collect();
        refiner
    }

    /// The sample of a vertex at `position` with raw shading normal `normal` and face normal
    /// `face`, as [`crate::projection::trilinear_builders::reflector_surface`] computes its ray; `None`
    /// where it has no ray.
    fn sample_at(&self, position: Vec3, normal: Vec3, face: DVec3) -> Option<Sample> {
        let point = position.as_dvec3();
        let eye = self.camera.basis().origin;
        let incident = (point - eye).try_normalize()?;
        let normal = normal.as_dvec3().try_normalize()?;
        let pixel = self.camera.project_continuous(point)?.pixel;
        let unit = vertex_ray(incident, normal, face, self.optic);
        let entering = enters(incident, normal, face);
        let interpolated = match self.map {
            SurfaceScreenMap::Projective => point.distance(eye) * unit,
            SurfaceScreenMap::Affine => unit,
        };
        Some(Sample {
            point,
            unit,
            interpolated,
            pixel,
            entering,
        })
    }

    /// Whether the surface ([`reflector_surface`](crate::projection::trilinear_builders::reflector_surface))
    /// drops `[a, b, c]` and every triangle its refinement could make, so that splitting
    /// it is wasted: its vertex normals all lie clearly on the side of its plane away from
    /// the eye ([`BACK_FACING_COSINE`]). Its descendants lie in its plane with its winding,
    /// and their vertices' raw normals are averages of its own (midpoints), so each has
    /// every vertex normal on that side too, and the surface's test (the face normal
    /// against the sum of the vertex normals, times the eye's side) drops it. On the
    /// example sphere about half the refined triangles were such (the far hemisphere).
    ///
    /// Mirrors only: a glass surface's vertex ray depends on whether the ray enters or
    /// leaves, which it decides by the face normals of the triangles around the vertex,
    /// weighted by their areas (`vertex_normals`), so a whole back-facing triangle next to a
    /// split front-facing one could turn a silhouette vertex's ray; a mirror's ray is the
    /// same for either side.
    fn back_facing(&self, corners: [u32; 3]) -> bool {
        if self.optic != Optic::Reflect {
            return false;
        }
        let [a, b, c] = corners.map(|k| self.positions[k as usize].as_dvec3());
        let face = (b - a).cross(c - a);
        let to_eye = self.camera.basis().origin - a;
        let eye_side = face.dot(to_eye);
        let clear = BACK_FACING_COSINE * face.length();
        // False for NaN too: such a triangle is refined as before.
        let off_the_plane = eye_side.abs() > clear * to_eye.length();
        if !off_the_plane {
            return false;
        }
        corners.iter().all(|&k| {
            let normal = self.normals[k as usize].as_dvec3();
            face.dot(normal) * eye_side.signum() < -clear * normal.length()
        })
    }

    /// The children of `[a, b, c]` by the decisions of its three edges, or `None` when no
    /// edge is split. Children keep the winding.
    fn split_triangle(&mut self, [a, b, c]: [u32; 3]) -> Option<Vec<[u32; 3]>> {
        let corners = [a, b, c];
        let mids = [
            self.midpoint(a, b),
            self.midpoint(b, c),
            self.midpoint(c, a),
        ];
        let children = match mids {
            [None, None, None] => return None,
            [Some(m0), Some(m1), Some(m2)] => {
                vec![[a, m0, m2], [m0, b, m1], [m2, m1, c], [m0, m1, m2]]
            }
            _ if mids.iter().flatten().count() == 1 => {
                // Rotate so that the split edge is (a, b).
                let r = mids.iter().position(Option::is_some)?;
                let [a, b, c] = rotate(corners, r);
                let m = mids[r]?;
                vec![[a, m, c], [m, b, c]]
            }
            _ => {
                // Rotate so that the unsplit edge is (c, a): (a, b) and (b, c) are split.
                let r = (mids.iter().position(Option::is_none)? + 1) % 3;
                let [a, b, c] = rotate(corners, r);
                let (m0, m1) = (mids[r]?, mids[(r + 1) % 3]?);
                // The quad a, m0, m1, c along its shorter diagonal.
                let length = |p: u32, q: u32| {
                    self.positions[p as usize].distance(self.positions[q as usize])
                };
                if length(a, m1) <= length(m0, c) {
                    vec![[m0, b, m1], [a, m0, m1], [a, m1, c]]
                } else {
                    vec![[m0, b, m1], [a, m0, c], [m0, m1, c]]
                }
            }
        };
        // The new interior edges get the level after the triangle's deepest edge (the split
        // edges' halves already have theirs).
        let level = 1 + [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(p, q)| self.edge(p, q).level)
            .max()
            .unwrap_or(0);
        for child in &children {
            for (p, q) in [
                (child[0], child[1]),
                (child[1], child[2]),
                (child[2], child[0]),
            ] {
                let key = self.key(p, q);
                self.edges.entry(key).or_insert(Edge {
                    level,
                    midpoint: None,
                });
            }
        }
        Some(children)
    }

    /// The edge record of `(p, q)`: level 0 for an edge of the input mesh.
    fn edge(&self, p: u32, q: u32) -> Edge {
        self.edges.get(&self.key(p, q)).copied().unwrap_or_default()
    }

    /// An edge's key: its canonical end vertices, the same for both directions.
    fn key(&self, p: u32, q: u32) -> (u32, u32) {
        let (p, q) = (self.canonical[p as usize], self.canonical[q as usize]);
        (p.min(q), p.max(q))
    }

    /// The midpoint vertex of edge `(p, q)` if it is split, deciding (once) whether it is.
    fn midpoint(&mut self, p: u32, q: u32) -> Option<u32> {
        let edge = self.edge(p, q);
        if let Some(decided) = edge.midpoint {
            return decided;
        }
        let decided = self.decide(p, q, edge.level);
        let key = self.key(p, q);
        self.edges.insert(
            key,
            Edge {
                level: edge.level,
                midpoint: Some(decided),
            },
        );
        if let Some(m) = decided {
            for end in [p, q] {
                let key = self.key(end, m);
                self.edges.insert(
                    key,
                    Edge {
                        level: edge.level + 1,
                        midpoint: None,
                    },
                );
            }
        }
        decided
    }

    /// Adds the midpoint of `(p, q)` if the edge's error exceeds the bound (module docs);
    /// returns it, or `None` when the edge stays whole.
    fn decide(&mut self, p: u32, q: u32, level: u32) -> Option<u32> {
        let (sp, sq) = (self.samples[p as usize]?, self.samples[q as usize]?);
        let (p, q) = (p as usize, q as usize);
        let position = (self.positions[p] + self.positions[q]) * 0.5;
        let normal = (self.normals[p] + self.normals[q]) * 0.5;
        let face = self.faces[p] + self.faces[q];
        let sm = self.sample_at(position, normal, face)?;
        if self.error_px(&sp, &sq, &sm) <= MIDPOINT_FRACTION * self.tolerance_px {
            return None;
        }
        if self.off_image(sp.pixel, sq.pixel) {
            return None;
        }
        let short = sp.pixel.distance(sq.pixel) < MIN_EDGE_PX;
        if short && across_silhouette(self.optic, [&sp, &sq, &sm]) {
            self.silhouette += 1;
            return None;
        }
        if level >= MAX_LEVEL || short {
            self.unsplit += 1;
            return None;
        }
        let m = self.positions.len() as u32;
        self.positions.push(position);
        self.normals.push(normal);
        self.faces.push(face);
        self.samples.push(Some(sm));
        self.canonical.push(m);
        Some(m)
    }

    /// The displacement, in main-image pixels, of the image seen at midpoint sample `sm` of
    /// the edge `(sp, sq)` by the surface's interpolated ray (module docs).
    fn error_px(&self, sp: &Sample, sq: &Sample, sm: &Sample) -> f64 {
        let along = sq.pixel - sp.pixel;
        let length_sq = along.length_squared();
        // The surface's barycentric weight of `sq` at `sm`'s pixel.
        let t = match self.map {
            SurfaceScreenMap::Projective => 0.5,
            SurfaceScreenMap::Affine if length_sq > 0.0 => {
                ((sm.pixel - sp.pixel).dot(along) / length_sq).clamp(0.0, 1.0)
            }
            SurfaceScreenMap::Affine => 0.5,
        };
        let pixel_angle = self.pixel_angle(sm.pixel);
        // The direction's error, against the spread of the rays per pixel.
        let direction = (1.0 - t) * sp.interpolated + t * sq.interpolated;
        let delta = angle(direction, sm.unit);
        let spread = angle(sp.unit, sq.unit) / length_sq.sqrt();
        let sigma = if spread.is_finite() {
            spread.max(pixel_angle)
        } else {
            pixel_angle
        };
        // The base point's offset across the exact ray, against the pixel's footprint at the
        // reflector (the narrowest the pixel's beam is after it).
        let offset = (1.0 - t) * sp.point + t * sq.point - sm.point;
        let across = (offset - offset.dot(sm.unit) * sm.unit).length();
        let footprint = sm.point.distance(self.camera.basis().origin) * pixel_angle;
        if sigma > 0.0 && footprint > 0.0 {
            delta / sigma + across / footprint
        } else {
            0.0
        }
    }

    /// Whether the screen segment from `a` to `b` lies beyond one side of the main image
    /// (both ends left of it, right of it, above or below it): no pixel sees it.
    fn off_image(&self, a: DVec2, b: DVec2) -> bool {
        let (width, height) = self.camera.resolution();
        let size = DVec2::new(f64::from(width), f64::from(height));
        (a.x < 0.0 && b.x < 0.0)
            || (a.y < 0.0 && b.y < 0.0)
            || (a.x > size.x && b.x > size.x)
            || (a.y > size.y && b.y > size.y)
    }

    /// The angle between the main camera's rays through `pixel` and its horizontal
    /// neighbour.
    fn pixel_angle(&self, pixel: DVec2) -> f64 {
        let ray = |x: DVec2| self.camera.ray(x).map(|r| r.direction);
        match (ray(pixel), ray(pixel + DVec2::X)) {
            (Some(a), Some(b)) => angle(a, b),
            _ => 0.0,
        }
    }
}

/// Whether the eye's ray enters a glass (`optic`) at one of an edge's `samples` (its ends
/// and its midpoint) and leaves it at another: the edge crosses the glass's silhouette,
/// where the exact image jumps (a ray grazing the front is bent to the critical angle, one
/// just past it goes on nearly straight). Mirrors have no such jump (a grazing reflection
/// is the incident ray on either side).
fn across_silhouette(optic: Optic, samples: [&Sample; 3]) -> bool {
    matches!(optic, Optic::Refract { .. })
        && samples.iter().any(|s| s.entering != samples[0].entering)
}

/// The angle between `a` and `b` (any lengths), accurate for small angles; 0 if either is
/// zero.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// For each vertex, the first vertex with the same position and normal (bit for bit).
fn canonical_vertices(positions: &[Vec3], normals: &[Vec3]) -> Vec<u32> {
    let mut first = HashMap::new();
    positions
        .iter()
        .zip(normals)
        .enumerate()
        .map(|(k, (p, n))| {
            let bits = [p.x, p.y, p.z, n.x, n.y, n.z].map(f32::to_bits);
            *first.entry(bits).or_insert(k as u32)
        })
        .collect()
}

/// `[a, b, c]` rotated left by `r` (the winding is kept).
fn rotate(corners: [u32; 3], r: usize) -> [u32; 3] {
    [corners[r % 3], corners[(r + 1) % 3], corners[(r + 2) % 3]]
}

#[cfg(test)]
mod tests;
