//! The base colour of one triangle as a function of its barycentrics, prepared once per
//! triangle: a renderer that shades many pixels of the same triangle (a rasteriser) pays a
//! few multiply-adds per pixel instead of [`super::base_color`]'s vertex lookups,
//! world-space interpolation, world-to-object transform and divisions.
//!
//! Everything `base_color` interpolates is affine in the barycentrics `(u, v)`: the world
//! point, so the object-space point and the checker's cell coordinates `(p + nudge) / size`
//! too, the texture coordinates and the vertex colour. Each is kept as its value at the first
//! corner plus its change per unit `u` and `v` (`Affine`). Where a triangle lies inside one
//! checker cell and its vertex colours agree, the colour is one constant.
//!
//! The colours are [`super::base_color`]'s up to `f32` rounding: the same affine values
//! evaluated in another order, so a point within rounding (about `1e-6` cells) of a checker
//! cell boundary or a texel boundary may land on the other side, and interpolated vertex
//! colours may differ in their last bits.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{cell_parity, corners, TextureFilter};
use crate::scene::{Material, Object, Pattern, Texture};

/// A value affine in the barycentrics `(u, v)`: `origin + u du + v dv`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Affine<T> {
    origin: T,
    du: T,
    dv: T,
}

impl<T> Affine<T>
where
    T: Copy
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<f32, Output = T>,
{
    /// The affine function taking the values `[a, b, c]` at the corners `(0, 0)`, `(1, 0)`
    /// and `(0, 1)`.
    fn through([a, b, c]: [T; 3]) -> Self {
        Affine {
            origin: a,
            du: b - a,
            dv: c - a,
        }
    }

    #[inline(always)]
    fn at(&self, barycentric: Vec2) -> T {
        self.origin + self.du * barycentric.x + self.dv * barycentric.y
    }
}

/// The pattern's colour (material colour included) over the triangle.
#[derive(Debug, Clone)]
enum PatternMap {
    /// The same colour everywhere.
    Uniform(Vec3),
    /// The checker's cell coordinates, and the colours of even and odd cells.
    Checker {
        cell: Affine<Vec3>,
        colors: [Vec3; 2],
    },
    /// An image texture at the interpolated texture coordinates, times `color`.
    Texture {
        color: Vec3,
        uv: Affine<Vec2>,
        texture: Arc<Texture>,
        filter: TextureFilter,
    },
}

impl PatternMap {
    /// The pattern multiplied by the constant `tint`.
    fn tinted(self, tint: Vec3) -> PatternMap {
        match self {
            PatternMap::Uniform(c) => PatternMap::Uniform(c * tint),
            PatternMap::Checker { cell, colors } => PatternMap::Checker {
                cell,
                colors: colors.map(|c| c * tint),
            },
            PatternMap::Texture {
                color,
                uv,
                texture,
                filter,
            } => PatternMap::Texture {
                color: color * tint,
                uv,
                texture,
                filter,
            },
        }
    }

    #[inline(always)]
    fn at(&self, barycentric: Vec2) -> Vec3 {
        match self {
            PatternMap::Uniform(c) => *c,
            PatternMap::Checker { cell, colors } => {
                colors[cell_parity(cell.at(barycentric)) as usize]
            }
            PatternMap::Texture {
                color,
                uv,
                texture,
                filter,
            } => {
                let uv = uv.at(barycentric);
                *color
                    * match filter {
                        TextureFilter::Nearest => texture.nearest(uv),
                        TextureFilter::Bilinear => texture.bilinear(uv),
                    }
            }
        }
    }
}

/// One triangle's base colour at any barycentrics (module doc).
#[derive(Debug, Clone)]
pub struct TriangleColor {
    pattern: PatternMap,
    /// The interpolated vertex colour; `None` where the mesh has none or the three agree
    /// (then folded into `pattern`).
    vertex: Option<Affine<Vec3>>,
}

impl TriangleColor {
    /// The base colour of triangle `triangle` (a valid index) of `object`, image textures
    /// sampled by `filter`: what [`super::base_color`] gives at every point of it (module
    /// doc).
    pub fn new(object: &Object, triangle: usize, filter: TextureFilter) -> TriangleColor {
        let mesh = &object.mesh;
        let corners = corners(object, triangle);
        let Material { color, pattern, .. } = &object.material;
        let pattern = match pattern {
            Pattern::Solid => PatternMap::Uniform(*color),
            Pattern::Checker { other, size } => checker(object, corners, [*color, *other], *size),
            Pattern::Texture(texture) => PatternMap::Texture {
                color: *color,
                uv: Affine::through(if mesh.uvs.is_empty() {
                    [Vec2::ZERO; 3]
                } else {
                    corners.map(|i| mesh.uvs[i])
                }),
                texture: Arc::clone(texture),
                filter,
            },
        };
        if mesh.colors.is_empty() {
            return TriangleColor {
                pattern,
                vertex: None,
            };
        }
        match corners.map(|i| mesh.colors[i]) {
            [a, b, c] if a == b && b == c => TriangleColor {
                pattern: pattern.tinted(a),
                vertex: None,
            },
            colors => TriangleColor {
                pattern,
                vertex: Some(Affine::through(colors)),
            },
        }
    }

    /// The base colour at barycentrics `barycentric` (weights of the second and third
    /// corners), a point of the triangle. Outside it the affine parts extrapolate, except
    /// where the triangle was found to have one colour: that colour.
    #[inline(always)]
    pub fn at(&self, barycentric: Vec2) -> Vec3 {
        let pattern = self.pattern.at(barycentric);
        match &self.vertex {
            None => pattern,
            Some(vertex) => pattern * vertex.at(barycentric),
        }
    }

    /// [`TriangleColor::at`] of every barycentrics of `barycentrics`, into `out` (as many
    /// colours as there are barycentrics; extra entries of `out` are left as they are), bit
    /// for bit: for a rasteriser's run of pixels of one triangle. A checker without vertex
    /// colours is evaluated several pixels at a time (`checker_lanes`).
    pub fn fill(&self, barycentrics: &[[f32; 2]], out: &mut [Vec3]) {
        match (&self.pattern, &self.vertex) {
            (PatternMap::Uniform(color), None) => out[..barycentrics.len()].fill(*color),
            (PatternMap::Checker { cell, colors }, None) => {
                for (b, o) in barycentrics.chunks(LANES).zip(out.chunks_mut(LANES)) {
                    checker_lanes(cell, colors, b, o);
                }
            }
            _ => {
                for (b, o) in barycentrics.iter().zip(out) {
                    *o = self.at(Vec2::from(*b));
                }
            }
        }
    }

    /// Whether the colour is the same at every point of the triangle (checked by the tests).
    #[cfg(test)]
    pub fn is_uniform(&self) -> bool {
        matches!(self.pattern, PatternMap::Uniform(_)) && self.vertex.is_none()
    }
}

/// Pixels whose checker colours [`checker_lanes`] computes together.
const LANES: usize = 8;

/// `colors[parity]` of the checker cell holding `cell.at(b)` for each of (at most [`LANES`])
/// barycentrics `b`, into `out`: [`PatternMap::at`]'s values, bit for bit. Each axis's cell
/// coordinate is `origin + du u + dv v`, the operations of [`Affine::at`] in its order, and
/// its floor's parity is [`super::floor_parity`]'s, over all lanes at once (loops the
/// compiler turns into vector instructions). Degenerate cases: a lane with a coordinate
/// outside [`super::ROUNDING_RANGE`], or NaN, takes [`cell_parity`] of its point (the same
/// function, whose slow path then decides); unused lanes compute from zeros and are
/// dropped.
#[inline]
fn checker_lanes(cell: &Affine<Vec3>, colors: &[Vec3; 2], b: &[[f32; 2]], out: &mut [Vec3]) {
    let (mut u, mut v) = ([0.0f32; LANES], [0.0f32; LANES]);
    for ((u, v), b) in u.iter_mut().zip(&mut v).zip(b) {
        (*u, *v) = (b[0], b[1]);
    }
    let mut parity = [0u32; LANES];
    let mut in_range = [true; LANES];
    for axis in 0..3 {
        let (origin, du, dv) = (cell.origin[axis], cell.du[axis], cell.dv[axis]);
        for k in 0..LANES {
            let x = origin + du * u[k] + dv * v[k];
            in_range[k] &= x.abs() < super::ROUNDING_RANGE;
            parity[k] ^= super::floor_parity(x);
        }
    }
    for (k, (o, b)) in out.iter_mut().zip(b).enumerate() {
        let parity = if in_range[k] {
            parity[k]
        } else {
            cell_parity(cell.at(Vec2::from(*b)))
        };
        *o = if parity == 0 { colors[0] } else { colors[1] };
    }
}

/// The checker over the triangle with corners `corners` of `object`, cells `size` wide
/// coloured `colors` (even, odd): [`PatternMap::Uniform`] where the whole triangle lies in
/// one cell with a margin that covers the rounding of [`Affine::at`].
///
/// Degenerate case: a non-positive or non-finite `size` (refused by the scene loader) gives
/// parity 0 everywhere, as [`super::checker_parity`] does.
fn checker(object: &Object, corners: [usize; 3], colors: [Vec3; 2], size: f32) -> PatternMap {
    if !(size > 0.0 && size.is_finite()) {
        return PatternMap::Uniform(colors[0]);
    }
    let nudge = Vec3::splat(super::CHECKER_NUDGE * size);
    let cell = Affine::through(corners.map(|i| {
        (object
            .world_to_object
            .transform_point3(object.mesh.positions[i])
            + nudge)
            / size
    }));
    match uniform_cell(&cell) {
        Some(c) => PatternMap::Uniform(colors[cell_parity(c) as usize]),
        None => PatternMap::Checker { cell, colors },
    }
}

/// A point of the cell that `cell.at(b)` falls in for every `b` of the triangle
/// (`u, v >= 0`, `u + v <= 1`, in `f32`), or `None` when two points of it may fall in
/// different cells.
///
/// `at` adds three products in `f32`: its result is within `2 eps S` of the exact affine
/// value, `S = |origin| + |du| + |dv|` per axis, and the exact values over the triangle lie
/// between those at its corners, themselves computed within `2 eps S`; barycentrics rounded
/// to `f32` may overshoot the triangle by `eps / 2`. A margin of `8 eps S` covers all three.
fn uniform_cell(cell: &Affine<Vec3>) -> Option<Vec3> {
    let values = [Vec2::ZERO, Vec2::X, Vec2::Y].map(|b| cell.at(b));
    let (lo, hi) = values
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let scale = cell.origin.abs() + cell.du.abs() + cell.dv.abs();
    let margin = 8.0 * f32::EPSILON * scale;
    let (lo, hi) = (lo - margin, hi + margin);
    let same = (0..3).all(|axis| {
        lo[axis].is_finite() && hi[axis].is_finite() && lo[axis].floor() == hi[axis].floor()
    });
    same.then_some(lo)
}

#[cfg(test)]
mod tests {
    use glam::Affine3A;
    use proptest::prelude::*;

    use super::*;
    use crate::render::shading::base_color;
    use crate::scene::{Finish, Mesh};

    fn object(positions: [Vec3; 3], colors: Option<[Vec3; 3]>, pattern: Pattern) -> Object {
        Object {
            id: 1,
            name: "t".into(),
            mesh: Arc::new(Mesh {
                positions: positions.to_vec(),
                triangles: vec![[0, 1, 2]],
                colors: colors.map_or(Vec::new(), |c| c.to_vec()),
                ..Default::default()
            }),
            material: Material {
                color: Vec3::new(0.9, 0.5, 0.25),
                pattern,
                finish: Finish::Diffuse,
            },
            world_to_object: Affine3A::from_rotation_y(0.5)
                * Affine3A::from_translation(Vec3::new(0.3, -1.0, 0.2)),
            displacement: None,
        }
    }

    const CHECKER: Pattern = Pattern::Checker {
        other: Vec3::new(0.1, 0.2, 0.3),
        size: 0.7,
    };

    /// How far (in cells) the object-space point at `b` lies from the nearest cell boundary.
    fn boundary_distance(o: &Object, b: Vec2) -> f32 {
        let Pattern::Checker { size, .. } = o.material.pattern else {
            return f32::INFINITY;
        };
        let p = super::super::position(o, 0, b);
        let cell = (o.world_to_object.transform_point3(p) + Vec3::splat(1e-4 * size)) / size;
        (0..3)
            .map(|i| (cell[i] - cell[i].round()).abs())
            .fold(f32::INFINITY, f32::min)
    }

    fn vec3() -> impl Strategy<Value = Vec3> {
        (-4.0..4.0f32, -4.0..4.0f32, -4.0..4.0f32).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn color() -> impl Strategy<Value = Vec3> {
        (0.0..1.0f32, 0.0..1.0f32, 0.0..1.0f32).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    /// A barycentric coordinate: mostly around the triangle, sometimes any `f32` bits (NaN,
    /// infinities, huge values).
    fn coordinate() -> impl Strategy<Value = f32> {
        prop_oneof![
            3 => -0.5..1.5f32,
            1 => any::<u32>().prop_map(f32::from_bits),
        ]
    }

    proptest! {
        /// `fill` writes `at` of every barycentrics, bit for bit, and nothing past them: solid
        /// and checker, with and without vertex colours, cell coordinates inside and beyond
        /// the parity's fast range (corners scaled by 1e7), runs of 0 to 20 pixels (whole and
        /// partial lanes).
        #[test]
        fn fill_is_at_bit_for_bit(
            corners in [vec3(), vec3(), vec3()],
            scale in prop_oneof![Just(1.0f32), Just(1e7f32)],
            colors in proptest::option::of([color(), color(), color()]),
            checker in any::<bool>(),
            barycentrics in proptest::collection::vec([coordinate(), coordinate()], 0..20),
        ) {
            let pattern = if checker { CHECKER } else { Pattern::Solid };
            let o = object(corners.map(|c| c * scale), colors, pattern);
            let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
            let sentinel = Vec3::splat(-7.0);
            let mut out = vec![sentinel; barycentrics.len() + 3];
            map.fill(&barycentrics, &mut out);
            let bits = |c: Vec3| c.to_array().map(f32::to_bits);
            for (b, o) in barycentrics.iter().zip(&out) {
                prop_assert_eq!(bits(*o), bits(map.at(Vec2::from(*b))), "{:?}", b);
            }
            prop_assert!(out[barycentrics.len()..].iter().all(|&c| c == sentinel));
        }

        /// Away from cell boundaries the map gives `base_color`'s checker colour, times the
        /// interpolated vertex colour within rounding.
        #[test]
        fn matches_base_color(
            corners in [vec3(), vec3(), vec3()],
            colors in proptest::option::of([color(), color(), color()]),
            u in 0.0..1.0f32,
            v in 0.0..1.0f32,
        ) {
            let o = object(corners, colors, CHECKER);
            let b = if u + v > 1.0 { Vec2::new(1.0 - u, 1.0 - v) } else { Vec2::new(u, v) };
            prop_assume!(boundary_distance(&o, b) > 1e-4);
            let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
            let expected = base_color(&o, 0, b, TextureFilter::Nearest);
            prop_assert!((map.at(b) - expected).abs().max_element() < 1e-5, "{map:?} {b}");
        }

        /// A triangle found uniform gives the colour the general map computes anywhere on it.
        #[test]
        fn uniform_triangles_agree_with_the_general_map(
            origin in vec3(),
            du in vec3(),
            dv in vec3(),
            scale in 0.001..1.0f32,
            u in 0.0..1.0f32,
            v in 0.0..1.0f32,
        ) {
            let cell = Affine { origin, du: du * scale, dv: dv * scale };
            let b = if u + v > 1.0 { Vec2::new(1.0 - u, 1.0 - v) } else { Vec2::new(u, v) };
            if let Some(inside) = uniform_cell(&cell) {
                prop_assert_eq!(cell_parity(cell.at(b)), cell_parity(inside));
                prop_assert_eq!(cell.at(b).floor(), inside.floor());
            }
        }
    }

    #[test]
    fn one_cell_and_equal_vertex_colours_make_a_uniform_colour() {
        // Object space = world space: cell coordinates (p + 0.7e-4) / 0.7 in [0.28, 0.43].
        let small = [
            Vec3::splat(0.2),
            Vec3::new(0.3, 0.2, 0.2),
            Vec3::new(0.2, 0.2, 0.3),
        ];
        let tint = Vec3::new(0.5, 1.0, 0.25);
        let mut o = object(small, Some([tint; 3]), CHECKER);
        o.world_to_object = Affine3A::IDENTITY;
        let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
        assert!(map.is_uniform(), "{map:?}");
        let b = Vec2::new(0.3, 0.3);
        let expected = base_color(&o, 0, b, TextureFilter::Nearest);
        assert!((map.at(b) - expected).abs().max_element() < 1e-6);
        // A triangle across cells is not uniform, nor one whose vertex colours differ.
        let large = [
            Vec3::ZERO,
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 3.0),
        ];
        assert!(
            !TriangleColor::new(&object(large, None, CHECKER), 0, TextureFilter::Nearest)
                .is_uniform()
        );
        Arc::make_mut(&mut o.mesh).colors[1] = Vec3::ONE;
        assert!(!TriangleColor::new(&o, 0, TextureFilter::Nearest).is_uniform());
    }

    #[test]
    fn a_floor_on_a_cell_boundary_takes_the_cell_above() {
        // The nudge: a face at y = 0 in object space lies in the cell above, as in
        // `checker_parity`, on every point of it.
        let mut o = object(
            [
                Vec3::new(0.1, 0.0, 0.1),
                Vec3::new(3.9, 0.0, 0.2),
                Vec3::new(0.2, 0.0, 3.9),
            ],
            None,
            Pattern::Checker {
                other: Vec3::ZERO,
                size: 1.0,
            },
        );
        o.world_to_object = Affine3A::IDENTITY;
        let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
        for (u, v) in [(0.0, 0.0), (0.5, 0.2), (0.9, 0.05), (0.0, 1.0), (0.3, 0.6)] {
            let b = Vec2::new(u, v);
            assert_eq!(
                map.at(b),
                base_color(&o, 0, b, TextureFilter::Nearest),
                "{b}"
            );
        }
    }

    #[test]
    fn solid_and_texture_patterns() {
        let corners = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let colors = [Vec3::X, Vec3::Y, Vec3::Z];
        let o = object(corners, Some(colors), Pattern::Solid);
        let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
        let b = Vec2::new(0.25, 0.5);
        let expected = base_color(&o, 0, b, TextureFilter::Nearest);
        assert!((map.at(b) - expected).abs().max_element() < 1e-6);
        assert!(TriangleColor::new(
            &object(corners, None, Pattern::Solid),
            0,
            TextureFilter::Nearest
        )
        .is_uniform());

        let texture = Texture {
            width: 2,
            height: 1,
            texels: vec![Vec3::splat(0.2), Vec3::ONE],
        };
        let mut o = object(corners, None, Pattern::Texture(Arc::new(texture)));
        Arc::make_mut(&mut o.mesh).uvs = vec![
            Vec2::new(0.1, 0.5),
            Vec2::new(0.9, 0.5),
            Vec2::new(0.1, 0.5),
        ];
        for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
            let map = TriangleColor::new(&o, 0, filter);
            for b in [Vec2::ZERO, Vec2::new(0.8, 0.1), Vec2::new(0.2, 0.3)] {
                let expected = base_color(&o, 0, b, filter);
                assert!(
                    (map.at(b) - expected).abs().max_element() < 1e-6,
                    "{filter:?} {b}"
                );
            }
        }
    }

    #[test]
    fn non_positive_checker_size_is_parity_zero() {
        for size in [0.0, -1.0, f32::NAN] {
            let o = object(
                [Vec3::ZERO, Vec3::splat(5.0), Vec3::Y],
                None,
                Pattern::Checker {
                    other: Vec3::ZERO,
                    size,
                },
            );
            let map = TriangleColor::new(&o, 0, TextureFilter::Nearest);
            assert!(map.is_uniform());
            assert_eq!(map.at(Vec2::new(0.3, 0.3)), o.material.color);
        }
    }
}
