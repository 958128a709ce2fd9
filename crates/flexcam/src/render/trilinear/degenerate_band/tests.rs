use glam::DVec3;
use proptest::prelude::*;

use super::*;
use crate::projection::project_triangle;

const V: fn(f64, f64, f64) -> DVec3 = DVec3::new;

/// Base points in the plane z = 0 and directions with z components all 1: the parametric
/// triangle stays parallel to the base (its plane at depth `t` is z = t), and the first two
/// vertex rays cross at `t = 1 / 0.6`, where it degenerates to a segment (the directions
/// are not coplanar: every scene point has three roots).
fn crossing() -> ProjectionTriangleCache {
    let p = [V(0.0, 0.0, 0.0), V(1.0, 0.0, 0.0), V(0.0, 1.0, 0.0)];
    let n = [V(0.3, 0.0, 1.0), V(-0.3, 0.0, 1.0), V(0.1, 0.2, 1.0)];
    ProjectionTriangleCache::new(p, n)
}

fn band() -> DegenerateBand {
    let cache = crossing();
    DegenerateBand::around(cache.degenerate_depths().expect("degenerates"))
}

/// The winding number of the closed polygon `outline` (in barycentrics) about `(u, v)`.
fn winding(outline: &[OutlinePoint], (u, v): (f64, f64)) -> i32 {
    let mut w = 0;
    for (i, a) in outline.iter().enumerate() {
        let b = outline[(i + 1) % outline.len()];
        let cross = (b.u - a.u) * (v - a.v) - (u - a.u) * (b.v - a.v);
        if a.v <= v && b.v > v && cross > 0.0 {
            w += 1;
        } else if a.v > v && b.v <= v && cross < 0.0 {
            w -= 1;
        }
    }
    w
}

/// The outlines of the band of `scene` in the crossing triangle.
fn band_outlines(scene: [DVec3; 3]) -> Vec<Vec<OutlinePoint>> {
    let (mut outline, mut scratch, mut found) = (Vec::new(), Vec::new(), Vec::new());
    let cache = crossing();
    band().outlines(&cache, scene, (&mut outline, &mut scratch), |o| {
        found.push(o.to_vec())
    });
    found
}

#[test]
fn the_band_surrounds_the_degenerate_depths() {
    let b = band();
    let t0 = 1.0 / 0.6;
    assert!((b.degenerate.0 - t0).abs() < 1e-9 && b.degenerate.0 == b.degenerate.1);
    assert!(b.lo < b.degenerate.0 && b.hi > b.degenerate.1 && b.lo > 0.0);
    assert!((b.lo - t0 * (1.0 - BAND_MARGIN)).abs() < 1e-9);
}

proptest! {
    /// The band's outlines cover a pixel exactly where its projector meets the scene
    /// triangle's plane at a depth in the band (points within 1e-9 of a boundary passed
    /// over), and only inside the domain; every outline point's depth is in the band.
    #[test]
    fn band_outlines_hold_the_pixels_seeing_the_plane_in_the_band(
        corners in proptest::array::uniform3((-3.0..3.0f64, -3.0..3.0f64, 0.2..3.5f64)),
    ) {
        let scene = corners.map(|(x, y, z)| V(x, y, z));
        let normal = (scene[1] - scene[0]).cross(scene[2] - scene[0]);
        prop_assume!(normal.length() > 1e-3);
        let (b, cache) = (band(), crossing());
        let outlines = band_outlines(scene);
        for o in &outlines {
            prop_assert!(o.len() >= 3);
            for p in o {
                prop_assert!(p.t == b.lo, "{p:?}");
            }
        }
        for i in 0..=40 {
            for j in 0..=(40 - i) {
                let (u, v) = (f64::from(i) / 40.0, f64::from(j) / 40.0);
                let n = normal.dot(scene[0] - cache.tripoint(u, v));
                let d = normal.dot(cache.trinorm(u, v));
                let t = n / d;
                // Far enough from the band's lines (N - lo D = 0, N - hi D = 0) to be sure.
                let scale = normal.length() * 10.0;
                if (n - b.lo * d).abs() < 1e-9 * scale || (n - b.hi * d).abs() < 1e-9 * scale {
                    continue;
                }
                let inside: i32 = outlines.iter().map(|o| winding(o, (u, v))).sum();
                let expected = d != 0.0 && b.lo <= t && t <= b.hi;
                prop_assert_eq!(inside != 0, expected, "({}, {}) at t = {}", u, v, t);
            }
        }
    }
}

/// A scene triangle without a plane has no band, nor has a plane seen only beyond the band
/// (z = 10: every projector meets it at t = 10) or only before it.
#[test]
fn planes_not_seen_in_the_band_have_no_outline() {
    let line = [V(0.0, 0.0, 1.0), V(1.0, 0.0, 1.5), V(2.0, 0.0, 2.0)];
    assert!(band_outlines(line).is_empty());
    let far = [V(-5.0, -5.0, 10.0), V(5.0, -5.0, 10.0), V(0.0, 5.0, 10.0)];
    assert!(band_outlines(far).is_empty());
    let near = far.map(|x| V(x.x, x.y, 0.5));
    assert!(band_outlines(near).is_empty());
}

/// A scene triangle lying in the plane of the degenerate depth (z = 1 / 0.6) is seen there
/// by every pixel whose projector passes through it: the band holds the whole domain.
#[test]
fn a_triangle_in_the_degenerate_plane_has_the_whole_domain_in_its_band() {
    let z = 1.0 / 0.6;
    let flat = [V(-5.0, -5.0, z), V(5.0, -5.0, z), V(0.0, 5.0, z)];
    let outlines = band_outlines(flat);
    assert_eq!(outlines.len(), 1, "{outlines:?}");
    for (u, v) in [(0.01, 0.01), (0.98, 0.01), (0.01, 0.98), (0.3, 0.3)] {
        assert_eq!(
            winding(&outlines[0], (u, v)).abs(),
            1,
            "({u}, {v}) {outlines:?}"
        );
    }
    assert_eq!(winding(&outlines[0], (0.6, 0.6)), 0, "outside the domain");
}

/// Shapes whose vertex depths reach across the degenerate depths, or touch them, are cut;
/// shapes wholly before or beyond them are not.
#[test]
fn shapes_reaching_the_degenerate_depth_are_cut() {
    let cache = crossing();
    let b = band();
    let t0 = 1.0 / 0.6;
    let reached = |scene: [DVec3; 3]| {
        let shapes = project_triangle(&cache, scene);
        let shapes = shapes.unwrap_or_else(|e| panic!("{scene:?}: {e:?}"));
        b.is_reached_by_any(&shapes)
    };
    // Tilted across z = t0 (the plane at the degenerate depth), wholly before, wholly beyond.
    assert!(reached([
        V(0.2, 0.2, 1.0),
        V(0.8, 0.1, 2.5),
        V(0.1, 0.7, 2.0)
    ]));
    assert!(!reached([
        V(0.2, 0.2, 0.5),
        V(0.8, 0.1, 1.0),
        V(0.1, 0.7, 0.8)
    ]));
    assert!(!reached([
        V(0.2, 0.2, 2.0),
        V(0.8, 0.1, 3.0),
        V(0.1, 0.7, 2.5)
    ]));
    // Touching it at a vertex: that vertex's genuine root is rejected with the spurious
    // one, and no shapes are formed (drawn pixel tested at every depth instead).
    let touching = [V(0.2, 0.2, t0), V(0.8, 0.1, 2.5), V(0.1, 0.7, 2.0)];
    assert!(matches!(
        project_triangle(&cache, touching),
        Err(crate::projection::Unprojectable::OpenShape { .. })
    ));
}

/// Every depth: the band holds the pixels that see the plane in front of the view plane
/// (z = 2: all of the domain), none that see it behind (z = -1).
#[test]
fn everywhere_holds_the_plane_in_front() {
    let (cache, b) = (crossing(), DegenerateBand::everywhere());
    let (mut outline, mut scratch) = (Vec::new(), Vec::new());
    let mut found = Vec::new();
    let front = [V(-5.0, -5.0, 2.0), V(5.0, -5.0, 2.0), V(0.0, 5.0, 2.0)];
    b.outlines(&cache, front, (&mut outline, &mut scratch), |o| {
        found.push(o.to_vec())
    });
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(winding(&found[0], (0.3, 0.3)).abs(), 1);
    let behind = front.map(|x| V(x.x, x.y, -1.0));
    found.clear();
    b.outlines(&cache, behind, (&mut outline, &mut scratch), |o| {
        found.push(o.to_vec())
    });
    assert!(found.is_empty(), "{found:?}");
}

/// The cut keeps the parts of an outline before and beyond the band, passing through its
/// anchors at the band's ends, and drops what lies between.
#[test]
fn the_cut_keeps_both_sides_through_the_anchors() {
    let b = band();
    let p = |u: f64, v: f64, t: f64| OutlinePoint { u, v, t };
    // An outline from t = 1 to t = 2.5 and back, with anchors at lo and hi, and wild points
    // between them (the outline through infinity).
    let traced = [
        p(0.1, 0.1, 1.0),
        p(0.2, 0.1, b.lo),
        p(40.0, -7.0, 1.6),
        p(-50.0, 9.0, 1.7),
        p(0.3, 0.1, b.hi),
        p(0.4, 0.1, 2.5),
        p(0.4, 0.4, 2.5),
        p(0.3, 0.3, b.hi),
        p(1e6, 1e6, 1.65),
        p(0.2, 0.3, b.lo),
        p(0.1, 0.4, 1.0),
    ];
    let (mut outline, mut scratch, mut parts) = (Vec::new(), Vec::new(), Vec::new());
    b.cut(&traced, (&mut outline, &mut scratch), |part| {
        parts.push(part.to_vec())
    });
    assert_eq!(parts.len(), 2, "{parts:?}");
    assert_eq!(
        parts[0],
        [
            p(0.1, 0.1, 1.0),
            p(0.2, 0.1, b.lo),
            p(0.2, 0.3, b.lo),
            p(0.1, 0.4, 1.0)
        ]
    );
    assert_eq!(
        parts[1],
        [
            p(0.3, 0.1, b.hi),
            p(0.4, 0.1, 2.5),
            p(0.4, 0.4, 2.5),
            p(0.3, 0.3, b.hi)
        ]
    );
}
