//! The projective (perspective-correct) map between a screen triangle and its projection
//! triangle's barycentrics, for surfaces whose screen positions are a pinhole camera's image
//! of their base points (reflection and refraction surfaces, Vallance 2005 chapter 7).
//!
//! The thesis interpolates in screen space (7.2.2): a screen point with affine barycentrics
//! `l` in the screen triangle takes the ray at barycentrics `b = l`. When the screen
//! positions are where an eye images the base points, the eye ray through that screen point
//! meets the base triangle at the perspective-correct barycentrics instead,
//!
//! ```text
//! b_i = l_i w_i / sum_j l_j w_j,        w_i = 1 / (forward depth of base point i),
//! ```
//!
//! and the inverse is `l_i = (b_i / w_i) / sum_j (b_j / w_j)`. Both are projective maps, so
//! lines stay lines and the vertices map to themselves. The homogeneous weight
//! `W = sum_j l_j w_j = 1 / sum_j (b_j / w_j)` is affine in screen position: anything affine
//! in `b`, multiplied by `W`, is affine in screen position (what the fast renderer
//! interpolates, `render::trilinear::hit_terms`).
//!
//! Degenerate cases: weights that are zero, negative or not finite are refused
//! ([`ProjectiveMap::new`] gives `None`): with weights of different signs the map's singular
//! line `sum_j l_j w_j = 0` crosses the triangle, with a zero weight the vertex is at
//! infinity on screen, and a vertex at the eye (infinite weight) has no screen position.
//! Weights of one sign give a map that is finite on the whole closed triangle; outside it,
//! beyond the singular line, the results are not finite or meaningless (callers only
//! extrapolate by a pixel or so).

use glam::DVec2;

/// The projective map of one projection triangle: its three screen weights, scaled so that
/// the largest is 1 (the map is the same for any common positive factor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectiveMap {
    weights: [f64; 3],
}

impl ProjectiveMap {
    /// The map with vertex weights `weights`; `None` unless all three are finite and
    /// positive (module doc).
    pub fn new(weights: [f64; 3]) -> Option<ProjectiveMap> {
        if !weights.iter().all(|w| w.is_finite() && *w > 0.0) {
            return None;
        }
        let largest = weights.iter().fold(0.0_f64, |m, &w| m.max(w));
        let weights = weights.map(|w| w / largest);
        // Subnormal ratios would divide to infinity in `screen`.
        weights
            .iter()
            .all(|w| w.is_normal())
            .then_some(ProjectiveMap { weights })
    }

    /// The barycentrics `(u, v)` (of the second and third vertex) of the ray through the
    /// screen point with affine screen barycentrics `screen`.
    #[inline]
    pub fn barycentrics(&self, screen: DVec2) -> DVec2 {
        let [w0, w1, w2] = self.weights;
        let scaled = DVec2::new(screen.x * w1, screen.y * w2);
        scaled / ((1.0 - screen.x - screen.y) * w0 + scaled.x + scaled.y)
    }

    /// The affine screen barycentrics of the ray at barycentrics `b` (the inverse of
    /// [`ProjectiveMap::barycentrics`]).
    #[inline]
    pub fn screen(&self, b: DVec2) -> DVec2 {
        let [w0, w1, w2] = self.weights;
        let scaled = DVec2::new(b.x / w1, b.y / w2);
        scaled / ((1.0 - b.x - b.y) / w0 + scaled.x + scaled.y)
    }

    /// The homogeneous weight `W` at barycentrics `b` (module doc), affine in screen
    /// position.
    #[inline]
    pub fn homogeneous_weight(&self, b: DVec2) -> f64 {
        let [w0, w1, w2] = self.weights;
        1.0 / ((1.0 - b.x - b.y) / w0 + b.x / w1 + b.y / w2)
    }

    /// The weights, scaled so that the largest is 1.
    pub fn weights(&self) -> [f64; 3] {
        self.weights
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn degenerate_weights_have_no_map() {
        assert!(ProjectiveMap::new([1.0, 2.0, 3.0]).is_some());
        for bad in [
            [1.0, -2.0, 3.0],
            [0.0, 1.0, 1.0],
            [-1.0, -1.0, -1.0],
            [1.0, f64::INFINITY, 1.0],
            [1.0, f64::NAN, 1.0],
            [1.0, 1e-320, 1.0],
        ] {
            assert!(ProjectiveMap::new(bad).is_none(), "{bad:?}");
        }
    }

    #[test]
    fn equal_weights_are_the_affine_map_and_vertices_are_fixed() {
        let equal = ProjectiveMap::new([0.3; 3]).unwrap();
        let l = DVec2::new(0.2, 0.45);
        assert!((equal.barycentrics(l) - l).length() < 1e-15);
        assert!((equal.homogeneous_weight(l) - 1.0).abs() < 1e-15);
        let map = ProjectiveMap::new([1.0, 0.25, 4.0]).unwrap();
        for vertex in [DVec2::ZERO, DVec2::X, DVec2::Y] {
            assert!((map.barycentrics(vertex) - vertex).length() < 1e-15);
            assert!((map.screen(vertex) - vertex).length() < 1e-15);
        }
    }

    #[test]
    fn the_map_is_the_pinhole_image_of_the_base_triangle() {
        // An eye at the origin looking down +z images (x, y, z) at (x / z, y / z): the base
        // point at barycentrics b has the screen barycentrics `screen(b)` in the image of
        // the base triangle, with weights 1 / z.
        let base = [
            glam::DVec3::new(-1.0, 0.0, 2.0),
            glam::DVec3::new(1.0, -0.5, 5.0),
            glam::DVec3::new(0.2, 1.0, 9.0),
        ];
        let image = base.map(|p| DVec2::new(p.x / p.z, p.y / p.z));
        let map = ProjectiveMap::new(base.map(|p| 1.0 / p.z)).unwrap();
        let b = DVec2::new(0.3, 0.5);
        let point = (1.0 - b.x - b.y) * base[0] + b.x * base[1] + b.y * base[2];
        let l = map.screen(b);
        let on_screen = (1.0 - l.x - l.y) * image[0] + l.x * image[1] + l.y * image[2];
        assert!((on_screen - DVec2::new(point.x / point.z, point.y / point.z)).length() < 1e-14);
    }

    proptest! {
        #[test]
        fn screen_and_barycentrics_are_inverse(
            weights in [0.01..10.0f64, 0.01..10.0f64, 0.01..10.0f64],
            (u, v) in (0.0..1.0f64, 0.0..1.0f64),
        ) {
            let map = ProjectiveMap::new(weights).unwrap();
            // Inside the triangle (folded into it).
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let b = DVec2::new(u, v);
            let back = map.barycentrics(map.screen(b));
            prop_assert!((back - b).length() < 1e-12, "{b} -> {back}");
            // W is affine in screen position: sum_j l_j w_j at the screen point.
            let w = map.homogeneous_weight(b);
            let (l, [w0, w1, w2]) = (map.screen(b), map.weights());
            let at_screen = (1.0 - l.x - l.y) * w0 + l.x * w1 + l.y * w2;
            prop_assert!((w - at_screen).abs() < 1e-12 * w.abs().max(1.0));
        }
    }
}
