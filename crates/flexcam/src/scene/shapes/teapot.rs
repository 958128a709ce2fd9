//! The Utah teapot, tessellated from Newell's bicubic Bezier patches.

use glam::{Vec2, Vec3};

use super::grid::{push_grid, CollapsedRows, Vertex};
use super::teapot_patches::{PATCHES, POINTS};
use crate::scene::Mesh;

/// Relative size below which a patch derivative counts as vanished (a collapsed patch edge).
const VANISHED: f32 = 1e-6;

/// The Utah teapot from Newell's Bezier patches, y up, resting on y = 0, uniformly scaled by
/// `scale`; each patch is tessellated into `tessellation/4` x `tessellation/4` quads (at
/// least 1). Unscaled, it spans x in [-3, 3.434] (handle at -x, spout at +x), y in
/// [0, 3.15] and z in [-2, 2].
///
/// Normals are analytic, from the patch derivatives. The knob top and the bottom centre are
/// collapsed patch edges: quads there become single triangles (no zero-area triangles), so
/// with `n = max(tessellation/4, 1)` the mesh has `64 n^2 - 8 n` triangles. Patches are not
/// welded to each other; the teapot is not closed (the lid floats over the rim, the spout is
/// open), as in the original data. Each patch has its own `[0,1]^2` uvs. At one quad per
/// patch (tessellation below 8) the spout-tip patches, whose four corners lie on one line,
/// give zero-area triangles; from two quads per patch on there are none.
///
/// Degenerate input: a negative scale is taken by absolute value (a point reflection would
/// turn the teapot inside out); scale 0 gives a point with valid unit normals.
pub fn teapot(scale: f32, tessellation: u32) -> Mesh {
    let quads = patch_quads(tessellation);
    let scale = scale.abs();
    let mut mesh = Mesh::default();
    for patch in PATCHES.iter().map(BezierPatch::from_data) {
        // s runs along the patch's v and t along its u: with Newell's orientation,
        // dP/dv x dP/du points outward.
        push_grid(&mut mesh, quads, quads, patch.collapsed_rows(), |s, t| {
            Vertex {
                position: scale * patch.position(t, s),
                normal: patch.normal(t, s),
                uv: Vec2::new(s, t),
            }
        });
    }
    mesh
}

/// Quads along each side of a patch for a `tessellation`.
fn patch_quads(tessellation: u32) -> u32 {
    (tessellation / 4).max(1)
}

/// A bicubic Bezier patch: `points[i][j]` is control point (i, j), i along u, j along v.
struct BezierPatch {
    points: [[Vec3; 4]; 4],
}

impl BezierPatch {
    /// The patch with the given 1-based control-point indices, turned from z up to y up.
    fn from_data(indices: &[u16; 16]) -> Self {
        let point = |k: usize| {
            let [x, y, z] = POINTS[usize::from(indices[k]) - 1];
            Vec3::new(x, z, -y)
        };
        BezierPatch {
            points: std::array::from_fn(|i| std::array::from_fn(|j| point(4 * i + j))),
        }
    }

    /// Which of the rows u = 0 and u = 1 collapse to a single point.
    fn collapsed_rows(&self) -> CollapsedRows {
        let collapsed = |row: &[Vec3; 4]| row.iter().all(|&p| p == row[0]);
        CollapsedRows {
            first: collapsed(&self.points[0]),
            last: collapsed(&self.points[3]),
        }
    }

    /// `sum_ij a_i b_j P_ij` for weights `a` (along u) and `b` (along v).
    fn combine(&self, a: [f32; 4], b: [f32; 4]) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for (row, a_i) in self.points.iter().zip(a) {
            for (p, b_j) in row.iter().zip(b) {
                sum += a_i * b_j * *p;
            }
        }
        sum
    }

    fn position(&self, u: f32, v: f32) -> Vec3 {
        self.combine(bernstein(u), bernstein(v))
    }

    /// The unit outward normal `dP/dv x dP/du` at (u, v).
    ///
    /// Degenerate cases: on a collapsed edge u = u0 the derivative along v vanishes; near it
    /// `dP/dv ~ (u - u0) d2P/dudv`, so the mixed derivative, signed towards the patch
    /// interior, stands in for it (likewise for dP/du on an edge v = v0). If that also
    /// vanishes, the normal is taken a small step towards the patch centre; should even that
    /// fail (a patch collapsed to a point), the result is zero, the mesh convention for
    /// "use the face normal", never NaN.
    fn normal(&self, u: f32, v: f32) -> Vec3 {
        let normal = self.raw_normal(u, v);
        if normal != Vec3::ZERO {
            return normal;
        }
        let step = |x: f32| x + (0.5 - x) * 1e-3;
        self.raw_normal(step(u), step(v))
    }

    /// The normal with the mixed-derivative fallback, or zero.
    fn raw_normal(&self, u: f32, v: f32) -> Vec3 {
        let (bu, bv) = (bernstein(u), bernstein(v));
        let (du_basis, dv_basis) = (bernstein_derivative(u), bernstein_derivative(v));
        let mut du = self.combine(du_basis, bv);
        let mut dv = self.combine(bu, dv_basis);
        let duv = self.combine(du_basis, dv_basis);
        let toward_interior = |x: f32| if x < 0.5 { 1.0 } else { -1.0 };
        if dv.length_squared() <= VANISHED * VANISHED * du.length_squared() {
            dv = toward_interior(u) * duv;
        } else if du.length_squared() <= VANISHED * VANISHED * dv.length_squared() {
            du = toward_interior(v) * duv;
        }
        dv.cross(du).normalize_or_zero()
    }
}

/// The cubic Bernstein basis at `t`.
fn bernstein(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// Derivatives of the cubic Bernstein basis at `t`.
fn bernstein_derivative(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * (s - 2.0 * t),
        3.0 * t * (2.0 * s - t),
        3.0 * t * t,
    ]
}

#[cfg(test)]
mod tests {
    use super::super::grid::grid_triangle_count;
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn data_is_mirror_symmetric_and_complete() {
        assert_eq!(PATCHES.len(), 32);
        assert_eq!(POINTS.len(), 306);
        // Newell's teapot is symmetric about its y = 0 plane: a typo in one point breaks it.
        for [x, y, z] in POINTS {
            assert!(POINTS.contains(&[x, -y, z]), "no mirror of ({x}, {y}, {z})");
        }
        let max_index = PATCHES.iter().flatten().copied().max();
        assert_eq!(max_index, Some(306));
        assert!(PATCHES.iter().flatten().all(|&k| k >= 1));
    }

    #[test]
    fn rim_body_and_bottom_are_symmetric_under_quarter_turns() {
        // Patches 0..12 (rim and body) and 28..32 (bottom) come in rotated quadruples.
        for group in [0, 4, 8, 28] {
            let first = BezierPatch::from_data(&PATCHES[group]);
            for k in 1..4 {
                let other = BezierPatch::from_data(&PATCHES[group + k]);
                for (u, v) in [(0.2, 0.3), (0.7, 0.9)] {
                    let p = first.position(u, v);
                    let q = other.position(u, v);
                    assert!((p.y - q.y).abs() < 1e-5, "patch {} height", group + k);
                    let (r_p, r_q) = (p.x.hypot(p.z), q.x.hypot(q.z));
                    assert!((r_p - r_q).abs() < 2e-3, "patch {} radius", group + k);
                }
            }
        }
    }

    #[test]
    fn teapot_counts_and_well_formed() {
        for tessellation in [0, 4, 8, 9, 16, 40] {
            let mesh = teapot(1.0, tessellation);
            let n = patch_quads(tessellation) as usize;
            assert_eq!(
                mesh.triangle_count(),
                64 * n * n - 8 * n,
                "tessellation {tessellation}"
            );
            if n == 1 {
                // The four corners of each spout-tip patch lie on one line.
                assert!(mesh.validate().is_ok());
                assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
            } else {
                assert_well_formed(&mesh);
            }
            if n >= 10 {
                // Coarser, a triangle across the spout's tightly curled lip can face away
                // from the analytic normal at one of its corners.
                assert_winding_matches_normals(&mesh);
            }
        }
    }

    #[test]
    fn teapot_bounds_match_the_classic_data() {
        let mesh = teapot(1.0, 64);
        let (lo, hi) = mesh.bounds().unwrap();
        let expected_lo = Vec3::new(-3.0, 0.0, -2.0);
        let expected_hi = Vec3::new(3.434, 3.15, 2.0);
        assert!((lo - expected_lo).abs().max_element() < 1e-3, "{lo}");
        assert!((hi - expected_hi).abs().max_element() < 2e-3, "{hi}");
        let size = hi - lo;
        assert!((size.x - 6.434).abs() < 2e-3 && (size.y - 3.15).abs() < 1e-5);
        // Scale multiplies the whole shape; the bottom stays on y = 0.
        let (lo2, hi2) = teapot(2.0, 64).bounds().unwrap();
        assert!((lo2 - 2.0 * lo).abs().max_element() < 1e-5);
        assert!((hi2 - 2.0 * hi).abs().max_element() < 1e-5);
    }

    #[test]
    fn collapsed_edges_get_the_limit_normal() {
        // Lid knob patches (20..24) and bottom patches (28..32) collapse row u = 0.
        for (k, expected) in [
            (20, Vec3::Y),
            (23, Vec3::Y),
            (28, Vec3::NEG_Y),
            (31, Vec3::NEG_Y),
        ] {
            let patch = BezierPatch::from_data(&PATCHES[k]);
            assert!(patch.collapsed_rows().first && !patch.collapsed_rows().last);
            for v in [0.0, 0.3, 1.0] {
                let n = patch.normal(0.0, v);
                assert!((n - expected).length() < 1e-4, "patch {k} v {v}: {n}");
            }
        }
        let collapsed = PATCHES
            .iter()
            .map(BezierPatch::from_data)
            .filter(|p| p.collapsed_rows() != CollapsedRows::default())
            .count();
        assert_eq!(collapsed, 8);
    }

    #[test]
    fn degenerate_patch_falls_back_without_nan() {
        let point = BezierPatch {
            points: [[Vec3::ONE; 4]; 4],
        };
        assert_eq!(point.normal(0.0, 0.0), Vec3::ZERO);
        // A patch with a collapsed last row gets the interior-signed mixed derivative.
        let mut cone = BezierPatch::from_data(&PATCHES[20]);
        cone.points.reverse();
        for row in &mut cone.points {
            row.reverse();
        }
        assert!(cone.collapsed_rows().last);
        assert!((cone.normal(1.0, 0.4) - Vec3::Y).length() < 1e-4);
    }

    #[test]
    fn degenerate_parameters() {
        let tiny = teapot(0.0, 4);
        assert!(tiny.validate().is_ok());
        assert!(tiny.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        assert_eq!(teapot(-1.0, 8).positions, teapot(1.0, 8).positions);
    }

    /// Whether the ray `origin + t dir`, t > 0, crosses triangle `[a, b, c]`.
    fn ray_hits(origin: Vec3, dir: Vec3, [a, b, c]: [Vec3; 3]) -> bool {
        let (e1, e2) = (b - a, c - a);
        let p = dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return false;
        }
        let s = origin - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = dir.dot(q) / det;
        let t = e2.dot(q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-5
    }

    #[test]
    fn every_patch_faces_outward() {
        // From a triangle in the middle of each patch, a ray along its front side leaves the
        // teapot: it crosses the rest of the surface an even number of times (entering and
        // leaving the body, handle or spout). A patch facing inward would cross an odd number.
        let tessellation = 24;
        let mesh = teapot(1.0, tessellation);
        let quads = patch_quads(tessellation);
        let mut start = 0;
        for (k, data) in PATCHES.iter().enumerate() {
            let count =
                grid_triangle_count(quads, quads, BezierPatch::from_data(data).collapsed_rows());
            let probe = start + count / 2 + 1;
            let [a, b, c] = corners(&mesh, mesh.triangles[probe]);
            let origin = (a + b + c) / 3.0;
            let dir = (b - a).cross(c - a).normalize();
            let crossings = mesh
                .triangles
                .iter()
                .enumerate()
                .filter(|&(i, &t)| i != probe && ray_hits(origin, dir, corners(&mesh, t)))
                .count();
            assert_eq!(
                crossings % 2,
                0,
                "patch {k} faces inward ({crossings} crossings)"
            );
            start += count;
        }
        assert_eq!(start, mesh.triangle_count());
    }
}
