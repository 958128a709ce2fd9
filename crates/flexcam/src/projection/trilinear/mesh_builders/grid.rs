//! A regular grid of screen cells (n x n, or columns x rows) over a base surface.

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::projection::flexible::Surface;
use crate::projection::TrilinearMesh;

/// The largest accepted number of cells along each side of a grid: 2 x 256^2 projection
/// triangles is far beyond what any surface here needs, and keeps meshes small.
pub const MAX_GRID_CELLS: u32 = 256;

/// One vertex of a projection grid: the base point (the view plane, t = 0) and the ray
/// direction (not normalised: its length is the depth scale of the trilinear projection).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridVertex {
    /// The base point, on the view plane.
    pub point: DVec3,
    /// The ray direction; its length is the depth scale.
    pub direction: DVec3,
}

/// A trilinear mesh of `n` x `n` screen cells: [`screen_grid_cells`] with `n` columns and
/// `n` rows.
pub fn screen_grid(n: u32, vertex: impl Fn(DVec2) -> GridVertex) -> Result<TrilinearMesh> {
    screen_grid_cells(n, n, vertex)
}

/// A trilinear mesh of `columns` x `rows` screen cells covering the whole image, two
/// projection triangles per cell, with `(columns + 1) (rows + 1)` shared vertices. Vertex
/// `(i, j)` (column `i` from the left, row `j` from the bottom) has index
/// `j (columns + 1) + i`, screen position `(i / columns, j / rows)` and the base point and
/// direction `vertex(screen)`. Cell `(i, j)` with lower-left vertex `a` is split along its
/// rising diagonal into `[a, a + 1, a + columns + 2]` and `[a, a + columns + 2, a + columns
/// + 1]`, both counter-clockwise on screen.
///
/// Because neighbouring triangles share vertices, the ray field is continuous across every
/// cell edge and the screen cells tile [0, 1]^2 without gaps or overlaps.
///
/// Errors (degenerate cases): `columns` or `rows` outside 1..=[`MAX_GRID_CELLS`]; a vertex
/// with a non-finite point or direction, or a zero direction (where the base's rays are
/// undefined, e.g. where the two control surfaces of [`between_surfaces`] meet); the message
/// names the vertex and its screen position.
pub fn screen_grid_cells(
    columns: u32,
    rows: u32,
    vertex: impl Fn(DVec2) -> GridVertex,
) -> Result<TrilinearMesh> {
    for n in [columns, rows] {
        if !(1..=MAX_GRID_CELLS).contains(&n) {
            return Err(Error::new(format!(
                "grid must have 1..={MAX_GRID_CELLS} cells per side, got {n}"
            )));
        }
    }
    let side = columns + 1;
    let cells = DVec2::new(f64::from(columns), f64::from(rows));
    let mut mesh = TrilinearMesh::default();
    for j in 0..=rows {
        for i in 0..side {
            let screen = DVec2::new(f64::from(i), f64::from(j)) / cells;
            let v = vertex(screen);
            if !v.point.is_finite() || !v.direction.is_finite() || v.direction == DVec3::ZERO {
                return Err(Error::new(format!(
                    "grid vertex ({i}, {j}) at screen {screen} has no ray \
                     (point {}, direction {}): the base is degenerate there",
                    v.point, v.direction
                )));
            }
            mesh.points.push(v.point);
            mesh.normals.push(v.direction);
            mesh.screen.push(screen);
        }
    }
    for j in 0..rows {
        for i in 0..columns {
            let a = j * side + i;
            mesh.triangles.push([a, a + 1, a + side + 1]);
            mesh.triangles.push([a, a + side + 1, a + side]);
        }
    }
    Ok(mesh)
}

/// The base of a flexible volume between two control surfaces (the linear volume of Brosz 2011):
/// screen position `s` is the domain point (u, v) = `s`, its base point is `near(s)` and its
/// ray runs to `far(s)`, so the trilinear grid samples the volume's projectors at the grid
/// vertices and interpolates between them. The direction is zero where the surfaces meet
/// (rejected by [`screen_grid`]).
pub fn between_surfaces<'a>(
    near: &'a Surface,
    far: &'a Surface,
) -> impl Fn(DVec2) -> GridVertex + 'a {
    move |s| {
        let point = near.point(s);
        GridVertex {
            point,
            direction: far.point(s) - point,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{AnalyticInverse, Projection, Trilinear};

    fn flat(s: DVec2) -> GridVertex {
        GridVertex {
            point: DVec3::new(s.x, s.y, 0.0),
            direction: DVec3::new(0.0, 0.0, -1.0),
        }
    }

    #[test]
    fn counts_and_shared_vertices() {
        for n in [1u32, 2, 5] {
            let mesh = screen_grid(n, flat).unwrap();
            let side = (n + 1) as usize;
            assert_eq!(mesh.points.len(), side * side);
            assert_eq!(mesh.triangles.len(), 2 * (n * n) as usize);
            // Every vertex is used; interior vertices by six triangles, corners by one or two.
            let mut uses = vec![0; side * side];
            for t in &mesh.triangles {
                for &k in t {
                    uses[k as usize] += 1;
                }
            }
            assert!(uses.iter().all(|&u| u >= 1));
            if n >= 2 {
                assert_eq!(uses[side + 1], 6, "interior vertex");
            }
            assert_eq!((uses[0], uses[side - 1]), (2, 1), "corners");
            // Each interior edge is shared by exactly two triangles, boundary edges by one.
            let mut edges = std::collections::HashMap::new();
            for t in &mesh.triangles {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            let boundary = edges.values().filter(|&&c| c == 1).count();
            assert_eq!(boundary, 4 * n as usize);
            assert!(edges.values().all(|&c| c == 1 || c == 2));
            assert_cells_tile_the_screen(&mesh);
        }
    }

    /// Asserts counter-clockwise screen triangles of total area 1.
    fn assert_cells_tile_the_screen(mesh: &TrilinearMesh) {
        let area: f64 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| mesh.screen[k as usize]);
                0.5 * (b - a).perp_dot(c - a)
            })
            .inspect(|&a| assert!(a > 0.0))
            .sum();
        assert!((area - 1.0).abs() < 1e-12);
    }

    #[test]
    fn screen_is_covered_without_gaps() {
        let mesh = screen_grid(3, flat).unwrap();
        let trilinear = Trilinear::new(&mesh, 30, 30).unwrap();
        // Pixel centres, pixel corners (on cell edges and vertices) and the image border.
        for y in 0..=60 {
            for x in 0..=60 {
                let pixel = DVec2::new(f64::from(x), f64::from(y)) * 0.5;
                let inside = pixel.x < 30.0 && pixel.y < 30.0 && pixel.y > 0.0;
                if inside {
                    let ray = trilinear.ray(pixel).expect("gap in the grid");
                    let expected = DVec3::new(pixel.x / 30.0, 1.0 - pixel.y / 30.0, 0.0);
                    assert!((ray.origin - expected).length() < 1e-12);
                }
            }
        }
    }

    /// A grid of unequal sides: its vertex layout and counts, counter-clockwise cells that
    /// tile the screen, and each side checked on its own.
    #[test]
    fn columns_and_rows_may_differ() {
        let mesh = screen_grid_cells(5, 2, flat).unwrap();
        assert_eq!(mesh.points.len(), 6 * 3);
        assert_eq!(mesh.triangles.len(), 2 * 5 * 2);
        assert_eq!(mesh.screen[6 + 5], DVec2::new(1.0, 0.5));
        assert_eq!(mesh.screen[2 * 6 + 1], DVec2::new(0.2, 1.0));
        assert_cells_tile_the_screen(&mesh);
        assert_eq!(
            screen_grid_cells(4, 4, flat).unwrap(),
            screen_grid(4, flat).unwrap()
        );
        for (columns, rows) in [(0, 3), (3, 0), (MAX_GRID_CELLS + 1, 1)] {
            let e = screen_grid_cells(columns, rows, flat).unwrap_err().message;
            assert!(e.contains("1..=256"), "{e}");
        }
    }

    #[test]
    fn degenerate_sizes_and_vertices_are_errors() {
        assert!(screen_grid(0, flat)
            .unwrap_err()
            .message
            .contains("1..=256"));
        assert!(screen_grid(MAX_GRID_CELLS + 1, flat).is_err());
        let pinched = |s: DVec2| GridVertex {
            point: DVec3::ZERO,
            direction: DVec3::new(s.x - 0.5, 0.0, 1.0) * (s.y - 0.5),
        };
        let e = screen_grid(2, pinched).unwrap_err().message;
        assert!(e.contains("grid vertex (0, 1)"), "{e}");
        let nan = |_: DVec2| GridVertex {
            point: DVec3::NAN,
            direction: DVec3::Z,
        };
        assert!(screen_grid(1, nan).is_err());
    }

    #[test]
    fn volume_base_runs_from_near_to_far() {
        let near = Surface::rectangle_centred(DVec3::ZERO, DVec3::X, DVec3::Y);
        let far = Surface::Point(DVec3::new(0.0, 0.0, 2.0));
        let mesh = screen_grid(2, between_surfaces(&near, &far)).unwrap();
        assert_eq!(mesh.points[0], DVec3::new(-1.0, -1.0, 0.0));
        assert_eq!(mesh.normals[0], DVec3::new(1.0, 1.0, 2.0));
        assert_eq!(mesh.points[4], DVec3::ZERO);
        let same = Surface::Point(DVec3::ZERO);
        assert!(
            screen_grid(2, between_surfaces(&near, &same)).is_err(),
            "centre meets"
        );
    }

    mod round_trip {
        use super::*;
        use crate::projection::flexible::{CylinderPatch, PolarFrame};
        use proptest::prelude::*;

        /// A bent base: rays outwards from a cylinder of radius 0.5 to one of radius 20,
        /// 160 degrees around and 2 (near) to 30 (far) high.
        fn bent() -> (Surface, Surface) {
            let frame = PolarFrame::new(DVec3::Y, DVec3::NEG_Z).unwrap();
            let patch = |radius: f64, half_height: f64| {
                Surface::Cylinder(CylinderPatch {
                    center: DVec3::ZERO,
                    radius,
                    frame,
                    angle: [-80f64.to_radians(), 80f64.to_radians()],
                    height: [-half_height, half_height],
                })
            };
            (patch(0.5, 1.0), patch(20.0, 15.0))
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(300))]

            /// The grid's projection inverts its rays: a point on the ray of a pixel
            /// projects back to that pixel, at that depth.
            #[test]
            fn grid_pixel_to_point_to_pixel(
                n in 1u32..7,
                (x, y) in (0.0..1.0f64, 0.0..1.0f64),
                t in 0.0..3.0f64,
            ) {
                let (near, far) = bent();
                let mesh = screen_grid(n, between_surfaces(&near, &far)).unwrap();
                let trilinear = Trilinear::new(&mesh, 320, 120).unwrap();
                let pixel = DVec2::new(x * 320.0, y * 120.0);
                let point = trilinear.ray(pixel).unwrap().at(t);
                let mut images = Vec::new();
                trilinear.project(point, &mut images);
                let found = images.iter().any(|image| {
                    (image.pixel - pixel).length() <= 1e-6 && (image.t - t).abs() <= 1e-9
                });
                prop_assert!(found, "{pixel} t {t}: {images:?}");
            }
        }
    }
}
