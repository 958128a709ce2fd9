//! Small convex polygons in the plane: the convex hull of a few points and clipping by
//! half-planes, for the bounding regions of [`super::bound`]. Fixed capacity, no allocation:
//! a hull of nine points clipped by a triangle or a rectangle has at most 13 vertices.

use glam::DVec2;

/// Most vertices a [`Convex`] holds.
const CAPACITY: usize = 16;

/// A convex polygon, counter-clockwise (in a y-up frame), possibly empty.
#[derive(Debug, Clone, Copy)]
pub struct Convex {
    points: [DVec2; CAPACITY],
    len: usize,
}

impl Convex {
    pub const EMPTY: Convex = Convex {
        points: [DVec2::ZERO; CAPACITY],
        len: 0,
    };

    /// The polygon with these vertices (convex, counter-clockwise, at most 16).
    pub fn from_points(points: &[DVec2]) -> Convex {
        let mut out = Convex::EMPTY;
        for &p in points.iter().take(CAPACITY) {
            out.push(p);
        }
        out
    }

    /// The convex hull of `points` (at most 16; Andrew's monotone chain), counter-clockwise,
    /// collinear points dropped. Non-finite points make the hull empty: no bound can be made.
    pub fn hull(points: &[DVec2]) -> Convex {
        let n = points.len().min(CAPACITY);
        if points[..n].iter().any(|p| !p.is_finite()) {
            return Convex::EMPTY;
        }
        let mut sorted = [DVec2::ZERO; CAPACITY];
        sort_lexicographic(&points[..n], &mut sorted[..n]);
        let sorted = &sorted[..n];
        if n == 1 {
            return Convex::from_points(sorted);
        }
        let mut chain = [DVec2::ZERO; 2 * CAPACITY];
        let mut k = 0;
        for &p in sorted {
            while k >= 2 && cross(chain[k - 2], chain[k - 1], p) <= 0.0 {
                k -= 1;
            }
            chain[k] = p;
            k += 1;
        }
        let lower = k + 1;
        for &p in sorted.iter().rev().skip(1) {
            while k >= lower && cross(chain[k - 2], chain[k - 1], p) <= 0.0 {
                k -= 1;
            }
            chain[k] = p;
            k += 1;
        }
        // The last point repeats the first.
        let count = k.saturating_sub(1);
        Convex::from_points(&chain[..count.min(CAPACITY)])
    }

    fn push(&mut self, p: DVec2) {
        if self.len < CAPACITY {
            self.points[self.len] = p;
            self.len += 1;
        }
    }

    pub fn points(&self) -> &[DVec2] {
        &self.points[..self.len]
    }

    /// The part on the left of the directed line `a -> b` (the line included)
    /// (Sutherland-Hodgman), in place; `scratch` is working space.
    fn clip_with(&mut self, a: DVec2, b: DVec2, scratch: &mut Convex) {
        let side = |p: DVec2| cross(a, b, p);
        if self.points().iter().all(|&p| side(p) >= 0.0) {
            // Nothing to cut: the loop below would copy every vertex and add none.
            return;
        }
        scratch.len = 0;
        for i in 0..self.len {
            let (p, q) = (self.points[i], self.points[(i + 1) % self.len]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                scratch.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                scratch.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        self.points[..scratch.len].copy_from_slice(scratch.points());
        self.len = scratch.len;
    }

    /// The part on the left of the directed line `a -> b` (the line included).
    #[cfg(test)]
    pub fn clip(&self, a: DVec2, b: DVec2) -> Convex {
        let mut out = *self;
        let mut scratch = Convex::EMPTY;
        out.clip_with(a, b, &mut scratch);
        out
    }

    /// The part inside the convex polygon with corners `corners`, counter-clockwise.
    fn clip_to_polygon(mut self, corners: &[DVec2]) -> Convex {
        let mut scratch = Convex::EMPTY;
        for (i, &a) in corners.iter().enumerate() {
            self.clip_with(a, corners[(i + 1) % corners.len()], &mut scratch);
        }
        self
    }

    /// The part inside triangle `t` (either orientation).
    pub fn clip_to_triangle(self, t: [DVec2; 3]) -> Convex {
        let t = if cross(t[0], t[1], t[2]) >= 0.0 {
            t
        } else {
            [t[0], t[2], t[1]]
        };
        self.clip_to_polygon(&t)
    }

    /// The part inside the axis-aligned rectangle `[lo, hi]`.
    pub fn clip_to_rect(self, lo: DVec2, hi: DVec2) -> Convex {
        self.clip_to_polygon(&[lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)])
    }

    /// The area (zero for fewer than three vertices).
    pub fn area(&self) -> f64 {
        let p = self.points();
        (0..p.len())
            .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
            .sum::<f64>()
            .abs()
            / 2.0
    }

    /// The same polygon with every vertex mapped by `f` (which must keep it convex: an
    /// affine or a projective map without a pole on it).
    pub fn map(mut self, f: impl Fn(DVec2) -> DVec2) -> Convex {
        for p in &mut self.points[..self.len] {
            *p = f(*p);
        }
        self
    }

    /// The polygon with each vertex moved `by` away from the vertices' mean: a margin for
    /// rounding, so that a pixel centre on the exact boundary is never lost.
    pub fn dilated(self, by: f64) -> Convex {
        if self.len == 0 {
            return self;
        }
        let centre = self.points().iter().sum::<DVec2>() / self.len as f64;
        self.map(|p| p + (p - centre).normalize_or_zero() * by)
    }
}

/// Writes `points` into `out` (as long) sorted by `x`, then `y`, in the order of
/// `f64::total_cmp` (an insertion sort on integer keys, each computed once: the hulls here
/// have at most 16 points, and the comparator of `sort_by` costs more than the sort).
fn sort_lexicographic(points: &[DVec2], out: &mut [DVec2]) {
    let mut keys = [(0i64, 0i64); CAPACITY];
    for (i, &p) in points.iter().enumerate().take(CAPACITY) {
        let k = (total_key(p.x), total_key(p.y));
        let mut j = i;
        while j > 0 && keys[j - 1] > k {
            keys[j] = keys[j - 1];
            out[j] = out[j - 1];
            j -= 1;
        }
        keys[j] = k;
        out[j] = p;
    }
}

/// An integer ordered as `f64::total_cmp` orders `x`.
#[inline]
fn total_key(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

/// Twice the signed area of `a b c` (positive counter-clockwise).
pub fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The hull's sort orders points as sorting by `total_cmp` on `x`, then `y` does
        /// (signed zeros, equal coordinates and infinities included).
        #[test]
        fn sort_matches_total_cmp(
            raw in proptest::collection::vec((0usize..6, 0usize..6), 0..16)
        ) {
            let values = [-1.5, -0.0, 0.0, 2.0, f64::INFINITY, f64::NEG_INFINITY];
            let points: Vec<DVec2> =
                raw.iter().map(|&(x, y)| DVec2::new(values[x], values[y])).collect();
            let mut ours = points.clone();
            sort_lexicographic(&points, &mut ours);
            let mut theirs = points;
            theirs.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
            let bits = |p: &[DVec2]| -> Vec<(u64, u64)> {
                p.iter().map(|q| (q.x.to_bits(), q.y.to_bits())).collect()
            };
            prop_assert_eq!(bits(&ours), bits(&theirs));
        }
    }

    /// Clipping by a line that has the whole polygon on its left keeps it as it is.
    #[test]
    fn clipping_by_a_line_outside_keeps_the_polygon() {
        let square = Convex::from_points(&[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]);
        let kept = square.clip(DVec2::new(-1.0, 0.0), DVec2::new(-1.0, -1.0));
        assert_eq!(kept.points(), square.points());
        assert!(square
            .clip(DVec2::new(-1.0, 0.0), DVec2::new(-1.0, 1.0))
            .points()
            .is_empty());
    }

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.5, 0.5),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(0.2, 0.7),
        ];
        let hull = Convex::hull(&pts);
        assert_eq!(hull.points().len(), 4);
        assert!((hull.area() - 1.0).abs() < 1e-12);
        let tri = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)];
        assert!((hull.clip_to_triangle(tri).area() - 0.5).abs() < 1e-12);
        let rect = hull.clip_to_rect(DVec2::new(0.5, -1.0), DVec2::new(2.0, 0.5));
        assert!((rect.area() - 0.25).abs() < 1e-12);
        assert!(hull
            .clip_to_triangle(tri.map(|p| p + DVec2::splat(5.0)))
            .points()
            .is_empty());
        assert!(Convex::hull(&[DVec2::NAN, DVec2::ONE]).points().is_empty());
    }
}
