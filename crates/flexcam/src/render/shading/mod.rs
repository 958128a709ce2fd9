//! Surface attributes at a point of a triangle: normals, texture coordinates, vertex colour
//! and base colour, shared by every renderer so that all of them shade a hit alike.
//!
//! A hit is given as an object, a triangle index within its mesh and the barycentric weights
//! `(u, v)` of the triangle's second and third vertices (the first has `1 - u - v`).

mod lanes;
pub mod trace;
pub mod triangle_color;

use glam::{Vec2, Vec3};

use crate::scene::{Material, Object, Pattern};

/// How image textures are sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureFilter {
    /// The nearest texel (`--shading flat`: no filtering).
    Nearest,
    /// Bilinear between the four nearest texel centres (`lit`).
    Bilinear,
}

/// The normals of a surface point as seen by a ray arriving along some direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normals {
    /// Unit face normal, flipped to face the incoming ray (surfaces are two-sided).
    pub geometric: Vec3,
    /// Unit shading normal (interpolated vertex normals, or the face normal), on the same side
    /// as `geometric`.
    pub shading: Vec3,
    /// Whether the ray arrives against the face normal of the triangle's winding (counter-
    /// clockwise vertices seen from the front): it enters a closed mesh wound outward.
    pub front_face: bool,
}

impl Normals {
    /// The normals of a flat face with unit normal `face` (by its winding; zero for a
    /// degenerate face) seen along `incoming`: the face normal, flipped to face the ray, as
    /// both the geometric and the shading normal (a displaced micro-triangle's).
    pub fn of_face(face: Vec3, incoming: Vec3) -> Normals {
        let front_face = face.dot(incoming) <= 0.0;
        let geometric = if front_face { face } else { -face };
        Normals {
            geometric,
            shading: geometric,
            front_face,
        }
    }
}

/// The barycentric weights of the three vertices.
fn weights(barycentric: Vec2) -> Vec3 {
    Vec3::new(
        1.0 - barycentric.x - barycentric.y,
        barycentric.x,
        barycentric.y,
    )
}

/// The vertex indices of triangle `triangle` (a valid index: meshes are validated on load).
fn corners(object: &Object, triangle: usize) -> [usize; 3] {
    let [a, b, c] = object.mesh.triangles[triangle];
    [a as usize, b as usize, c as usize]
}

/// Interpolates a per-vertex attribute at barycentric weights `w`.
fn interpolate<T>(values: &[T], [a, b, c]: [usize; 3], w: Vec3) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    values[a] * w.x + values[b] * w.y + values[c] * w.z
}

/// The world-space point at barycentrics `barycentric` of triangle `triangle` of `object`
/// (the tests' check of interpolated colours and textures).
#[cfg(test)]
pub fn position(object: &Object, triangle: usize, barycentric: Vec2) -> Vec3 {
    interpolate(
        &object.mesh.positions,
        corners(object, triangle),
        weights(barycentric),
    )
}

/// The normals of triangle `triangle` of `object` at barycentrics `barycentric`, for a ray
/// travelling along `incoming` (any length).
///
/// Degenerate cases: a zero-area triangle has no face normal, and a zero `incoming` decides
/// no side; both give a zero `geometric` normal and `front_face = true`, and then the shading
/// normal is used unflipped. A zero vertex normal means "use the face normal" (see
/// [`crate::scene::Mesh::append`]) and an interpolated normal that cancels to zero falls back
/// to the face normal.
pub fn normals(object: &Object, triangle: usize, barycentric: Vec2, incoming: Vec3) -> Normals {
    normals_of_face(
        object,
        triangle,
        face_normal(object, triangle),
        barycentric,
        incoming,
    )
}

/// The unit face normal of triangle `triangle` of `object` by its winding (counter-clockwise
/// vertices seen from the front); zero for a zero-area triangle.
pub fn face_normal(object: &Object, triangle: usize) -> Vec3 {
    let [p0, p1, p2] = corners(object, triangle).map(|i| object.mesh.positions[i]);
    (p1 - p0).cross(p2 - p0).normalize_or_zero()
}

/// [`normals`] given the triangle's [`face_normal`] `face` (kept per triangle by a caller
/// shading many hits, so that each hit does not compute it again).
pub fn normals_of_face(
    object: &Object,
    triangle: usize,
    face: Vec3,
    barycentric: Vec2,
    incoming: Vec3,
) -> Normals {
    VertexNormals::of(object, triangle).normals(face, barycentric, incoming)
}

/// The vertex normals of one triangle, looked up once for every hit on it (the pixels of a
/// 2x2 quad nearly always lie on one triangle): [`VertexNormals::normals`] of a hit is
/// [`normals_of_face`]'s, the same arithmetic on the same values.
#[derive(Debug, Clone, Copy)]
pub struct VertexNormals(
    /// The normals at the triangle's corners (zero: the face normal); `None` when the mesh
    /// has none.
    Option<[Vec3; 3]>,
);

impl VertexNormals {
    /// The vertex normals of triangle `triangle` of `object`.
    pub fn of(object: &Object, triangle: usize) -> VertexNormals {
        let normals = &object.mesh.normals;
        // Element by element: `array::map` is not inlined here (a per-pixel cost).
        VertexNormals((!normals.is_empty()).then(|| {
            let [a, b, c] = corners(object, triangle);
            [normals[a], normals[b], normals[c]]
        }))
    }

    /// The normals at barycentrics `barycentric` of the triangle, whose [`face_normal`] is
    /// `face`, for a ray travelling along `incoming` (see [`normals`] for the degenerate
    /// cases).
    #[inline]
    pub fn normals(&self, face: Vec3, barycentric: Vec2, incoming: Vec3) -> Normals {
        let Normals {
            geometric,
            front_face,
            ..
        } = Normals::of_face(face, incoming);
        let interpolated = match self.0 {
            None => Vec3::ZERO,
            Some([a, b, c]) => {
                let vertex = |n: Vec3| if n == Vec3::ZERO { face } else { n };
                let n = [vertex(a), vertex(b), vertex(c)];
                interpolate(&n, [0, 1, 2], weights(barycentric)).normalize_or_zero()
            }
        };
        let mut shading = if interpolated == Vec3::ZERO {
            face
        } else {
            interpolated
        };
        if geometric != Vec3::ZERO && shading.dot(geometric) < 0.0 {
            shading = -shading;
        }
        Normals {
            geometric,
            shading,
            front_face,
        }
    }
}

/// The base colour at barycentrics `barycentric` of triangle `triangle` of `object`:
/// `material.color * pattern * vertex colour` (see [`Material`]; no vertex colours = white),
/// with image textures sampled by `filter` (texture coordinates zero when the mesh has none).
/// Only the attributes the material needs are interpolated.
pub fn base_color(
    object: &Object,
    triangle: usize,
    barycentric: Vec2,
    filter: TextureFilter,
) -> Vec3 {
    TriangleBase::of(object, triangle, None).at(barycentric, filter)
}

/// What [`base_color`] reads of one triangle: its vertex indices and, for a checker, its
/// corners in object space, transformed or read from points kept per mesh vertex (lit
/// shading reads the prepared scene's). [`TriangleBase::at`] of a hit is `base_color`'s,
/// the same arithmetic on the same values.
#[derive(Debug, Clone, Copy)]
pub struct TriangleBase<'a> {
    object: &'a Object,
    corners: [usize; 3],
    /// The corners in object space, where the pattern is a checker.
    object_corners: Option<[Vec3; 3]>,
}

impl<'a> TriangleBase<'a> {
    /// Triangle `triangle` of `object`. `object_points`, when given, are the mesh's
    /// positions in object space (`world_to_object` applied to each, as
    /// [`object_points`] computes them), read instead of transforming the corners.
    #[inline]
    pub fn of(object: &'a Object, triangle: usize, object_points: Option<&[Vec3]>) -> Self {
        let corners = corners(object, triangle);
        let object_corners =
            matches!(object.material.pattern, Pattern::Checker { .. }).then(|| {
                let [a, b, c] = corners;
                match object_points {
                    Some(points) => [points[a], points[b], points[c]],
                    None => {
                        let local = |i: usize| {
                            object
                                .world_to_object
                                .transform_point3(object.mesh.positions[i])
                        };
                        [local(a), local(b), local(c)]
                    }
                }
            });
        TriangleBase {
            object,
            corners,
            object_corners,
        }
    }

    /// The base colour at barycentrics `barycentric`, textures sampled by `filter`.
    ///
    /// The object-space point of a checker is the object-space corners interpolated (as
    /// [`triangle_color`] does), not the interpolated world point taken to object space,
    /// whose rounding grows with the distance from the world origin: a floor at object
    /// y = 0 translated far away would otherwise flicker across the checker's cell boundary
    /// there.
    #[inline]
    pub fn at(&self, barycentric: Vec2, filter: TextureFilter) -> Vec3 {
        let (object, corners) = (self.object, self.corners);
        let mesh = &object.mesh;
        let w = weights(barycentric);
        let pattern = pattern_color(
            object,
            filter,
            // Called for a checker only, whose object-space corners were looked up.
            || interpolate(&self.object_corners.unwrap_or_default(), [0, 1, 2], w),
            || uv_at(mesh, corners, w),
        );
        if mesh.colors.is_empty() {
            pattern
        } else {
            pattern * interpolate(&mesh.colors, corners, w)
        }
    }
}

/// The positions of `object`'s mesh in object space (`world_to_object` applied to each),
/// for [`TriangleBase::of`].
pub fn object_points(object: &Object) -> Vec<Vec3> {
    (object.mesh.positions.iter())
        .map(|&p| object.world_to_object.transform_point3(p))
        .collect()
}

/// The texture coordinates at barycentrics `barycentric` of triangle `triangle` of `object`,
/// as textures are sampled there (zero when the mesh has none).
pub fn texture_coordinates(object: &Object, triangle: usize, barycentric: Vec2) -> Vec2 {
    uv_at(
        &object.mesh,
        corners(object, triangle),
        weights(barycentric),
    )
}

/// Texture coordinates at weights `w` (zero when the mesh has none).
fn uv_at(mesh: &crate::scene::Mesh, corners: [usize; 3], w: Vec3) -> Vec2 {
    if mesh.uvs.is_empty() {
        Vec2::ZERO
    } else {
        interpolate(&mesh.uvs, corners, w)
    }
}

/// `material.color` times the pattern: the checker alternates `color` and `other` by the cell
/// parity of the object-space point, textures multiply `color`. `point` and `uv` give the
/// object-space point and the texture coordinates, each computed only for the pattern that
/// needs it (the checker reads no texture coordinates, a texture no point).
#[inline]
fn pattern_color(
    object: &Object,
    filter: TextureFilter,
    point: impl Fn() -> Vec3,
    uv: impl Fn() -> Vec2,
) -> Vec3 {
    let Material { color, pattern, .. } = &object.material;
    match pattern {
        Pattern::Solid => *color,
        Pattern::Checker { other, size } => {
            if checker_parity(point(), *size) == 0 {
                *color
            } else {
                *other
            }
        }
        Pattern::Texture(texture) => {
            let uv = uv();
            *color
                * match filter {
                    TextureFilter::Nearest => texture.nearest(uv),
                    TextureFilter::Bilinear => texture.bilinear(uv),
                }
        }
    }
}

/// Parity (0 or 1) of the checker cell holding `p`: `floor(x/size) + floor(y/size) +
/// floor(z/size)` at `p` nudged by `1e-4 * size` along every axis, so a face lying on a cell
/// boundary (a floor at y = 0) falls wholly in the cell above it instead of flickering.
/// A non-positive or non-finite `size` (rejected by the scene loader) gives parity 0.
pub fn checker_parity(p: Vec3, size: f32) -> u32 {
    if !(size > 0.0 && size.is_finite()) {
        return 0;
    }
    cell_parity((p + Vec3::splat(CHECKER_NUDGE * size)) / size)
}

/// The checker's nudge along every axis, in cells (see [`checker_parity`]).
const CHECKER_NUDGE: f32 = 1e-4;

/// Parity (0 or 1) of `floor(x) + floor(y) + floor(z)`: the checker cell at cell coordinates
/// `cell` (the nudged object-space point divided by the cell size). The parity of a sum is
/// the exclusive or of the parities; each is read by [`floor_parity`] (no float-to-integer
/// conversion, the per-pixel cost of flat-shaded checkers) where all three coordinates are
/// below [`ROUNDING_RANGE`] in magnitude, which every cell of a scene within the renderers'
/// limits is. Degenerate cases: beyond that range, and for NaN or infinite coordinates, the
/// parity of the wrapping sum of the three [`floor_to_int`] (NaN counts as 0, infinities
/// as `i64::MAX` and `i64::MIN`); the result is that sum's parity for every input (tested).
#[inline]
fn cell_parity(cell: Vec3) -> u32 {
    if cell.abs().cmplt(Vec3::splat(ROUNDING_RANGE)).all() {
        floor_parity(cell.x) ^ floor_parity(cell.y) ^ floor_parity(cell.z)
    } else {
        let sum = floor_to_int(cell.x)
            .wrapping_add(floor_to_int(cell.y))
            .wrapping_add(floor_to_int(cell.z));
        (sum & 1) as u32
    }
}

/// The magnitude below which [`floor_parity`] holds: `2^22`.
const ROUNDING_RANGE: f32 = 4_194_304.0;

/// Parity (0 or 1) of `floor(x)` for `|x| <` [`ROUNDING_RANGE`]: adding `1.5 * 2^23` rounds
/// `x` to its nearest integer `r` (ties to even), exactly, because the sum lies in
/// `[2^23, 2^24]` where `f32` steps by 1 (at most 2^24, where the step becomes 2, but that
/// value is an integer); the sum's last mantissa bit is `r`'s parity, the constant being
/// even, and `floor(x)` is `r - 1` where `r > x`.
#[inline]
fn floor_parity(x: f32) -> u32 {
    const ROUNDER: f32 = 12_582_912.0;
    let sum = x + ROUNDER;
    let rounded = sum - ROUNDER;
    (sum.to_bits() & 1) ^ u32::from(rounded > x)
}

/// `x.floor() as i64` without the libm call that `f32::floor` compiles to on baseline x86-64
/// (no SSE4.1 `roundss`): truncate, then step down for negative non-integers. The same value
/// for every `x` (saturating like `as` beyond the `i64` range; NaN gives 0).
fn floor_to_int(x: f32) -> i64 {
    let truncated = x as i64;
    truncated.saturating_sub(i64::from(x < truncated as f32))
}

#[cfg(test)]
mod tests {
    #[test]
    fn floor_to_int_is_floor() {
        for x in [
            -2.5f32, -2.0, -1.0, -0.5, -1e-7, -0.0, 0.0, 1e-7, 0.5, 1.0, 2.5, 1e7, -1e7, 3e9,
        ] {
            assert_eq!(floor_to_int(x), x.floor() as i64, "{x}");
        }
        assert_eq!(floor_to_int(f32::NAN), 0);
        assert_eq!(floor_to_int(f32::INFINITY), i64::MAX);
        assert_eq!(floor_to_int(f32::NEG_INFINITY), i64::MIN);
    }

    /// The parity of the sum of the three `floor_to_int`, as `cell_parity` defines it.
    fn parity_of_floors(cell: Vec3) -> u32 {
        let sum = floor_to_int(cell.x) as i128
            + floor_to_int(cell.y) as i128
            + floor_to_int(cell.z) as i128;
        sum.rem_euclid(2) as u32
    }

    #[test]
    fn floor_parity_is_the_parity_of_floor_over_its_range() {
        // Every 61st f32 bit pattern (about 70 million values), and the values around the
        // range's ends, integers and half-integers.
        let mut checked = 0;
        for bits in (0..=u32::MAX).step_by(61) {
            let x = f32::from_bits(bits);
            if x.abs() < ROUNDING_RANGE {
                assert_eq!(
                    floor_parity(x),
                    (x.floor() as i64).rem_euclid(2) as u32,
                    "{x}"
                );
                checked += 1;
            }
        }
        assert!(checked > 30_000_000, "{checked}");
        let edge = ROUNDING_RANGE;
        let below = f32::from_bits(edge.to_bits() - 1);
        for x in [
            below,
            -below,
            edge - 0.5,
            -edge + 0.5,
            edge - 0.25,
            -edge + 0.25,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            0.999_999_94,
            -0.999_999_94,
        ] {
            assert_eq!(
                floor_parity(x),
                (x.floor() as i64).rem_euclid(2) as u32,
                "{x}"
            );
        }
    }

    #[test]
    fn cell_parity_is_the_parity_of_the_sum_of_floors_for_every_input() {
        let special = [
            0.0f32,
            -0.0,
            0.5,
            -1.5,
            ROUNDING_RANGE,
            -ROUNDING_RANGE,
            f32::from_bits(ROUNDING_RANGE.to_bits() - 1),
            3e9,
            -3e9,
            1e19,
            -1e19,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for &x in &special {
            for &y in &special {
                for &z in &special {
                    let cell = Vec3::new(x, y, z);
                    assert_eq!(cell_parity(cell), parity_of_floors(cell), "{cell}");
                }
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn cell_parity_matches_the_floors_on_random_cells(
            x in -1e7f32..1e7,
            y in -1e3f32..1e3,
            z in -10.0f32..10.0,
        ) {
            let cell = Vec3::new(x, y, z);
            proptest::prop_assert_eq!(cell_parity(cell), parity_of_floors(cell));
        }
    }

    use std::sync::Arc;

    use glam::Affine3A;

    use super::*;
    use crate::scene::{Finish, Mesh, Texture};

    fn object(mesh: Mesh, pattern: Pattern) -> Object {
        Object {
            id: 1,
            name: "t".into(),
            mesh: mesh.into(),
            material: Material {
                color: Vec3::new(1.0, 0.5, 0.25),
                pattern,
                finish: Finish::Diffuse,
            },
            world_to_object: Affine3A::IDENTITY,
            displacement: None,
        }
    }

    fn triangle() -> Mesh {
        Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        }
    }

    #[test]
    fn face_normal_flips_toward_the_ray() {
        let o = object(triangle(), Pattern::Solid);
        let b = Vec2::new(0.25, 0.25);
        let front = normals(&o, 0, b, Vec3::NEG_Z);
        assert!(front.front_face);
        assert_eq!(front.geometric, Vec3::Z);
        assert_eq!(front.shading, Vec3::Z);
        assert_eq!(position(&o, 0, b), Vec3::new(0.25, 0.25, 0.0));
        let back = normals(&o, 0, b, Vec3::new(0.0, 0.0, 3.0));
        assert!(!back.front_face);
        assert_eq!(back.geometric, Vec3::NEG_Z);
        assert_eq!(back.shading, Vec3::NEG_Z);
    }

    #[test]
    fn vertex_normals_interpolate_and_zero_means_face_normal() {
        let mut mesh = triangle();
        mesh.normals = vec![Vec3::X, Vec3::ZERO, Vec3::Z];
        let o = object(mesh, Pattern::Solid);
        // At vertex 0 the normal is +x, at vertex 1 (zero) the face normal +z.
        let at0 = normals(&o, 0, Vec2::ZERO, Vec3::NEG_Z);
        assert_eq!(at0.shading, Vec3::X);
        let at1 = normals(&o, 0, Vec2::X, Vec3::NEG_Z);
        assert_eq!(at1.shading, Vec3::Z);
        // From behind, the shading normal follows the flipped face normal.
        let behind = normals(&o, 0, Vec2::new(0.5, 0.0), Vec3::Z);
        assert!(behind.shading.z < 0.0);
        // Opposite vertex normals cancelling to zero fall back to the face normal.
        let mut mesh = triangle();
        mesh.normals = vec![Vec3::X, Vec3::NEG_X, Vec3::X];
        let o = object(mesh, Pattern::Solid);
        assert_eq!(
            normals(&o, 0, Vec2::new(0.5, 0.0), Vec3::NEG_Z).shading,
            Vec3::Z
        );
    }

    #[test]
    fn zero_area_triangle_has_no_geometric_normal() {
        let mut mesh = triangle();
        mesh.positions[2] = Vec3::X * 2.0;
        let p = normals(
            &object(mesh, Pattern::Solid),
            0,
            Vec2::new(0.3, 0.3),
            Vec3::NEG_Z,
        );
        assert_eq!(p.geometric, Vec3::ZERO);
        assert!(p.front_face);
    }

    #[test]
    fn base_color_multiplies_color_texture_and_vertex_colour() {
        let mut mesh = triangle();
        mesh.uvs = vec![
            Vec2::new(0.1, 0.5),
            Vec2::new(0.9, 0.5),
            Vec2::new(0.1, 0.5),
        ];
        mesh.colors = vec![Vec3::splat(0.5); 3];
        let texture = Texture {
            width: 2,
            height: 1,
            texels: vec![Vec3::new(0.2, 0.2, 0.2), Vec3::ONE],
        };
        let o = object(mesh, Pattern::Texture(Arc::new(texture)));
        let flat = base_color(&o, 0, Vec2::ZERO, TextureFilter::Nearest);
        assert!((flat - Vec3::new(1.0, 0.5, 0.25) * 0.2 * 0.5).length() < 1e-6);
        // Bilinear at u = 0.1 blends texel 0 with the wrapped texel 1.
        let lit = base_color(&o, 0, Vec2::ZERO, TextureFilter::Bilinear);
        assert!(lit.x > flat.x);
    }

    #[test]
    fn checker_uses_object_space_and_is_stable_on_cell_boundaries() {
        assert_eq!(checker_parity(Vec3::new(0.5, 0.0, 0.5), 1.0), 0);
        assert_eq!(checker_parity(Vec3::new(0.5, -1e-7, 0.5), 1.0), 0);
        assert_eq!(checker_parity(Vec3::new(1.5, 0.0, 0.5), 1.0), 1);
        assert_eq!(checker_parity(Vec3::new(-0.5, 0.0, 0.5), 1.0), 1);
        assert_eq!(checker_parity(Vec3::new(2.5, 0.0, 0.5), 2.0), 1);
        assert_eq!(checker_parity(Vec3::ONE, 0.0), 0);
        assert_eq!(checker_parity(Vec3::ONE, f32::NAN), 0);
        let mut o = object(
            triangle(),
            Pattern::Checker {
                other: Vec3::ZERO,
                size: 1.0,
            },
        );
        let b = Vec2::new(0.25, 0.25);
        assert_eq!(
            base_color(&o, 0, b, TextureFilter::Nearest),
            o.material.color
        );
        o.world_to_object = Affine3A::from_translation(Vec3::X);
        assert_eq!(base_color(&o, 0, b, TextureFilter::Nearest), Vec3::ZERO);
    }

    /// A triangle's base colour read through [`TriangleBase`] with the object-space points
    /// kept per vertex is `base_color`'s, bit for bit, for a moved and rotated checker, and
    /// for a textured, vertex-coloured mesh (which reads no object-space point).
    #[test]
    fn triangle_base_with_kept_points_is_base_color() {
        let mut checker = object(
            triangle(),
            Pattern::Checker {
                other: Vec3::ZERO,
                size: 0.3,
            },
        );
        checker.world_to_object =
            Affine3A::from_rotation_y(0.7) * Affine3A::from_translation(Vec3::new(0.31, -2.0, 5.5));
        let mut mesh = triangle();
        mesh.uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y];
        mesh.colors = vec![Vec3::ONE, Vec3::splat(0.5), Vec3::X];
        let texture = Texture {
            width: 2,
            height: 2,
            texels: vec![Vec3::ONE, Vec3::splat(0.2), Vec3::splat(0.7), Vec3::X],
        };
        let textured = object(mesh, Pattern::Texture(Arc::new(texture)));
        for o in [&checker, &textured] {
            let points = object_points(o);
            assert_eq!(points.len(), o.mesh.positions.len());
            let kept = TriangleBase::of(o, 0, Some(&points));
            for i in 0..20 {
                for j in 0..(20 - i) {
                    let b = Vec2::new(i as f32 / 20.0 + 0.01, j as f32 / 20.0 + 0.02);
                    for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
                        let expected = base_color(o, 0, b, filter);
                        assert_eq!(kept.at(b, filter).to_array(), expected.to_array());
                    }
                }
            }
        }
    }

    /// A floor triangle at object y = 0 (on a checker cell boundary) translated 1e4 from the
    /// origin: the interpolated world point's rounding (about 1e-3 there) exceeds the
    /// checker's nudge, the object-space corners' interpolation does not.
    #[test]
    fn checker_on_a_cell_boundary_is_stable_far_from_the_origin() {
        let offset = Vec3::new(1.0e4, -3.0e3, 2.0e4);
        let mut mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 0.9),
                Vec3::new(0.9, 0.0, 0.0),
            ],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        };
        mesh.positions.iter_mut().for_each(|p| *p += offset);
        let mut o = object(
            mesh,
            Pattern::Checker {
                other: Vec3::ZERO,
                size: 1.0,
            },
        );
        o.world_to_object = Affine3A::from_translation(-offset);
        for i in 0..50 {
            for j in 0..(50 - i) {
                let b = Vec2::new(i as f32 / 50.0 + 0.003, j as f32 / 50.0 + 0.001);
                assert_eq!(
                    base_color(&o, 0, b, TextureFilter::Nearest),
                    o.material.color,
                    "barycentrics {b}"
                );
            }
        }
    }
}
