//! A view plane for projection triangles whose base collapses (Vallance 2005, 4.6).
//!
//! View-plane clipping cuts every shape at `t = 0`, the plane of the base triangle, through
//! the exact crossing of each scene edge with that plane. When the base points coincide (a
//! pinhole: every ray starts at the eye) or lie on one line, that plane is undefined: the
//! crossings cannot be computed, the clip falls back to cutting chords by interpolation,
//! and a scene triangle running from in front of the eye to behind it (a floor under and
//! behind the camera, a room around it) was drawn with wrong outlines (a pinhole over one
//! floor quad: ids 64 %, relative RGB error 0.66 against the ray caster).
//!
//! Moving each base point `p_i` along its own ray to `p_i + s n_i` changes no ray: the ray
//! at `(u, v)` becomes `p(u, v) + (t + s) n(u, v)`, the same line with its depth counted
//! from `s` on. The moved base is the rays' own cross-section at depth `s`, a proper
//! triangle when the rays diverge, so clipping there is exact again; what is lost is the
//! part of the scene nearer than depth `s`, and depths are measured from the moved base
//! (shorter by `s |n|`). `s` is `SHIFT` times `1 + |p| / |n|` (coordinates over direction
//! lengths): far above the rounding of the coordinates, far below any scene feature.
//!
//! Degenerate cases: a base that does not collapse is returned unchanged (bit for bit:
//! the renderer's output for every other mesh is untouched); rays that do not diverge
//! either (parallel rays from one point or line) sweep no volume and are ray cast by the
//! renderer whatever their base; a zero direction leaves its base point where it is.

use glam::DVec3;

/// Depth of the moved base, relative to `1 + |p| / |n|` (see the module doc).
const SHIFT: f64 = 1e-6;

/// The base points to clip against for the projection triangle with base points `p` and
/// directions `n`: `p` itself unless its area is below that of the rays' cross-section at
/// the depth `s` of the module doc, then the cross-section at `s`.
pub fn clipping_base(p: [DVec3; 3], n: [DVec3; 3]) -> [DVec3; 3] {
    let base_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let spread_area = (n[1] - n[0]).cross(n[2] - n[0]).length();
    let coordinates = p.iter().map(|q| q.abs().max_element()).fold(0.0, f64::max);
    let direction = n.iter().map(|d| d.length()).fold(0.0, f64::max);
    if !(direction > 0.0 && coordinates.is_finite()) {
        return p;
    }
    let s = SHIFT * (1.0 + coordinates / direction);
    if base_area > s * s * spread_area {
        return p;
    }
    [0, 1, 2].map(|i| p[i] + s * n[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: [DVec3; 3] = [
        DVec3::new(-1.0, -0.7, -0.3),
        DVec3::new(-0.1, -0.7, -1.0),
        DVec3::new(-0.3, 0.1, -1.2),
    ];

    #[test]
    fn a_pinhole_base_moves_along_its_rays() {
        let eye = DVec3::new(0.0, 1.0, 0.2);
        let moved = clipping_base([eye; 3], N);
        let longest = N.iter().map(|d| d.length()).fold(0.0, f64::max);
        let s = SHIFT * (1.0 + 1.0 / longest);
        for i in 0..3 {
            // On its own ray, at the stated depth.
            assert!((moved[i] - (eye + s * N[i])).length() <= 1e-15, "{moved:?}");
        }
        // The moved base is a proper triangle.
        let area = (moved[1] - moved[0]).cross(moved[2] - moved[0]).length();
        assert!(area > 0.0);
    }

    #[test]
    fn a_base_on_one_line_moves_too() {
        let a = DVec3::new(1.0, 2.0, 3.0);
        let b = DVec3::new(2.0, 2.0, 3.0);
        let on_line = [a, b, a];
        assert_ne!(clipping_base(on_line, N), on_line);
    }

    #[test]
    fn proper_bases_are_unchanged_bit_for_bit() {
        let p = [
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(clipping_base(p, N), p);
        // Tiny but proper (the rays' cross-section at depth 1e-3): unchanged, at any scale.
        for scale in [1e-3, 1.0, 1e3] {
            let q = [0, 1, 2].map(|i| DVec3::splat(scale) + 1e-3 * scale * N[i]);
            let n = N.map(|d| d * scale);
            assert_eq!(clipping_base(q, n), q, "{scale}");
        }
    }

    #[test]
    fn parallel_rays_and_zero_directions_keep_their_base() {
        let eye = DVec3::new(0.0, 1.0, 0.2);
        // Parallel rays from one point: the spread is zero, the base collapsed; moving it
        // along the common direction leaves it collapsed (the renderer ray casts these).
        let d = DVec3::new(0.0, 0.0, -1.0);
        let moved = clipping_base([eye; 3], [d; 3]);
        assert!(moved[0] == moved[1] && moved[1] == moved[2], "{moved:?}");
        assert_eq!(clipping_base([eye; 3], [DVec3::ZERO; 3]), [eye; 3]);
        let far = DVec3::splat(f64::INFINITY);
        assert_eq!(clipping_base([far; 3], N), [far; 3]);
    }
}
