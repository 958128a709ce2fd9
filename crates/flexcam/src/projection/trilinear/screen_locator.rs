//! Point location among screen triangles: which triangle covers a screen point, and where.
//!
//! A uniform grid of bins over the triangles' bounding box lists, per bin, the triangles
//! whose bounding boxes overlap it, in index order; a query tests only its bin's list.
//!
//! Tie rule, so that a mesh partitions the screen without cracks or double coverage: a point
//! counts as inside a triangle when it would be strictly inside after an infinitesimal shift
//! by (+e, -e^2) (right, then down). A point on an edge thus belongs to the triangle on the
//! right of that edge (for horizontal edges, the one below it), and a shared vertex to exactly
//! one triangle of its fan. With screen (s, t) = (x / W, 1 - y / H), a mesh covering
//! [0,1]^2 covers exactly the pixel positions [0, W) x [0, H): its left and top boundaries
//! are inside, its right and bottom ones outside.
//!
//! Each edge function is evaluated with the edge's endpoints in a canonical (lexicographic)
//! order, so two triangles sharing an edge see exactly opposite values: whatever the
//! rounding, no point is lost or doubled across a shared edge. Only within rounding distance
//! of a vertex where several edges meet could the rounded signs disagree; on dyadic screen
//! grids (such as k / 2^n) pixel positions are evaluated exactly.

use std::ops::Range;

use glam::DVec2;

/// Most bins along one axis: bounds the grid's memory for very large meshes.
const MAX_BINS_PER_AXIS: usize = 256;

/// A screen triangle covering a point, and the point's barycentrics there: `u` weighs the
/// triangle's second vertex, `v` its third.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScreenHit {
    pub triangle: usize,
    pub u: f64,
    pub v: f64,
}

/// Screen triangles (each of non-zero area, either orientation) with a bin grid.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ScreenLocator {
    triangles: Vec<[DVec2; 3]>,
    min: DVec2,
    bin_size: DVec2,
    bins_per_axis: usize,
    /// Bin `b` holds `bin_triangles[bin_start[b]..bin_start[b + 1]]`, ascending.
    bin_start: Vec<usize>,
    bin_triangles: Vec<u32>,
}

impl ScreenLocator {
    /// Builds the grid. Every triangle must have non-zero area (validated by the caller), so
    /// the bounding box of a non-empty list has positive extent on both axes.
    pub fn new(triangles: Vec<[DVec2; 3]>) -> Self {
        let (min, max) = triangles.iter().flatten().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let bins_per_axis =
            ((triangles.len() as f64).sqrt().ceil() as usize * 2).clamp(1, MAX_BINS_PER_AXIS);
        let mut locator = ScreenLocator {
            min,
            bin_size: (max - min) / bins_per_axis as f64,
            bins_per_axis,
            bin_start: Vec::new(),
            bin_triangles: Vec::new(),
            triangles: Vec::new(),
        };
        // A counting sort into the bins (how many per bin, where each bin starts, then the
        // triangles in index order): no list per bin to grow, which cost more than the
        // queries on meshes of a thousand triangles.
        let bins = bins_per_axis * bins_per_axis;
        let mut bin_start = vec![0; bins + 1];
        for tri in &triangles {
            locator.for_each_bin(tri, |bin| bin_start[bin + 1] += 1);
        }
        for bin in 0..bins {
            bin_start[bin + 1] += bin_start[bin];
        }
        let mut next = bin_start[..bins].to_vec();
        let mut bin_triangles = vec![0; bin_start[bins]];
        for (index, tri) in triangles.iter().enumerate() {
            locator.for_each_bin(tri, |bin| {
                bin_triangles[next[bin]] = index as u32;
                next[bin] += 1;
            });
        }
        locator.bin_start = bin_start;
        locator.bin_triangles = bin_triangles;
        locator.triangles = triangles;
        locator
    }

    /// Calls `f` with every bin that the bounding box of `tri` overlaps, row by row.
    fn for_each_bin(&self, tri: &[DVec2; 3], mut f: impl FnMut(usize)) {
        let lo = tri[0].min(tri[1]).min(tri[2]);
        let hi = tri[0].max(tri[1]).max(tri[2]);
        for by in self.bin(lo.y, 1)..=self.bin(hi.y, 1) {
            for bx in self.bin(lo.x, 0)..=self.bin(hi.x, 0) {
                f(by * self.bins_per_axis + bx);
            }
        }
    }

    /// The bin index of coordinate `c` along `axis`, clamped to the grid. Monotone in `c`,
    /// so a point inside a triangle's bounding box falls in one of the triangle's bins.
    fn bin(&self, c: f64, axis: usize) -> usize {
        let cell = ((c - self.min[axis]) / self.bin_size[axis]).floor();
        (cell.max(0.0) as usize).min(self.bins_per_axis - 1)
    }

    /// The upper corner of the grid: [`ScreenLocator::locate`] finds nothing beyond it.
    fn max(&self) -> DVec2 {
        self.min + self.bin_size * self.bins_per_axis as f64
    }

    /// The lowest-index triangle covering `p` under the tie rule, or `None`.
    pub fn locate(&self, p: DVec2) -> Option<ScreenHit> {
        let max = self.max();
        if !(p.cmpge(self.min).all() && p.cmple(max).all()) {
            return None;
        }
        let bin = self.bin(p.y, 1) * self.bins_per_axis + self.bin(p.x, 0);
        self.bin_triangles[self.bin_start[bin]..self.bin_start[bin + 1]]
            .iter()
            .find_map(|&index| {
                let (u, v) = barycentrics(&self.triangles[index as usize], p)?;
                Some(ScreenHit {
                    triangle: index as usize,
                    u,
                    v,
                })
            })
    }

    /// The points of a grid where [`ScreenLocator::locate`] finds a triangle, as runs along
    /// its rows: the grid's point `(x, y)` is `(columns[x], rows[y])`, each list monotone
    /// (ascending or descending), and `run(y, xs)` is called with runs of columns whose union
    /// over all calls is exactly the covered points of row `y` (the runs of different
    /// triangles may overlap). Per triangle, every condition `locate` puts on a point (the
    /// grid's bounds, the triangle's bins, each edge's side) holds on a half-line of a row or
    /// a column of the grid (each is monotone in one coordinate while the other is fixed), so
    /// the triangle's points in a row are one interval, found by binary searches: no test per
    /// point, and the same rounded tests as `locate`, so the same points.
    pub fn covered_runs(
        &self,
        columns: &[f64],
        rows: &[f64],
        mut run: impl FnMut(usize, Range<usize>),
    ) {
        let max = self.max();
        // The points within the grid's bounds along `axis`.
        let bounded = |coords: &[f64], axis: usize| {
            let from = monotone_part(0..coords.len(), |k| coords[k] >= self.min[axis]);
            monotone_part(from, |k| coords[k] <= max[axis])
        };
        let (inside_x, inside_y) = (bounded(columns, 0), bounded(rows, 1));
        // The points of `inside` whose bin along `axis` is one of those of `lo..=hi`.
        let in_bins = |coords: &[f64], inside: Range<usize>, axis: usize, lo: f64, hi: f64| {
            let (first, last) = (self.bin(lo, axis), self.bin(hi, axis));
            let from = monotone_part(inside, |k| self.bin(coords[k], axis) >= first);
            monotone_part(from, |k| self.bin(coords[k], axis) <= last)
        };
        for tri in &self.triangles {
            let lo = tri[0].min(tri[1]).min(tri[2]);
            let hi = tri[0].max(tri[1]).max(tri[2]);
            let xs = in_bins(columns, inside_x.clone(), 0, lo.x, hi.x);
            if xs.is_empty() {
                continue;
            }
            let orientation = orientation(tri);
            for y in in_bins(rows, inside_y.clone(), 1, lo.y, hi.y) {
                let mut span = xs.clone();
                for k in 0..3 {
                    span = monotone_part(span, |x| {
                        edge_weight(tri, orientation, k, DVec2::new(columns[x], rows[y])).is_some()
                    });
                }
                if !span.is_empty() {
                    run(y, span);
                }
            }
        }
    }
}

/// Twice the signed area of (a, b, p), computed with a and b in lexicographic order so that
/// `edge_function(a, b, p) == -edge_function(b, a, p)` exactly.
fn edge_function(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    let ordered = (a.x, a.y) <= (b.x, b.y);
    let (from, to) = if ordered { (a, b) } else { (b, a) };
    let w = (to - from).perp_dot(p - from);
    if ordered {
        w
    } else {
        -w
    }
}

/// Whether a point exactly on an edge traversed counter-clockwise along `direction` belongs
/// to the triangle: whether the shift (+e, -e^2) moves it into the triangle, to the left of
/// the edge (the sign of `direction x (e, -e^2)`).
fn owns_edge_point(direction: DVec2) -> bool {
    direction.y < 0.0 || (direction.y == 0.0 && direction.x < 0.0)
}

/// The sign of `tri`'s signed area: 1 counter-clockwise, -1 clockwise.
fn orientation(tri: &[DVec2; 3]) -> f64 {
    (tri[1] - tri[0]).perp_dot(tri[2] - tri[0]).signum()
}

/// The weight of `p` for the edge of `tri` opposite vertex `k` (twice the signed area of the
/// edge and `p`, positive inside), or `None` when `p` lies outside that edge under the tie
/// rule. `orientation` is `tri`'s ([`orientation`]). Along a line of points whose one
/// coordinate is fixed, the weight is monotone in the other coordinate even as rounded (each
/// difference, product and sum of the edge function is monotone in it), so the points inside
/// one edge form a half-line, and those inside the triangle an interval
/// ([`ScreenLocator::covered_runs`]).
fn edge_weight(tri: &[DVec2; 3], orientation: f64, k: usize, p: DVec2) -> Option<f64> {
    let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
    let w = orientation * edge_function(a, b, p);
    if w < 0.0 || (w == 0.0 && !owns_edge_point(orientation * (b - a))) {
        None
    } else {
        Some(w)
    }
}

/// Barycentrics (u, v) of `p` in `tri` if `p` is inside under the tie rule. `tri` must have
/// non-zero area; either orientation works.
pub(crate) fn barycentrics(tri: &[DVec2; 3], p: DVec2) -> Option<(f64, f64)> {
    let orientation = orientation(tri);
    // weights[k] belongs to the edge opposite vertex k.
    let mut weights = [0.0; 3];
    for (k, weight) in weights.iter_mut().enumerate() {
        *weight = edge_weight(tri, orientation, k, p)?;
    }
    let total = weights[0] + weights[1] + weights[2];
    Some((weights[1] / total, weights[2] / total))
}

/// The indices of `range` where `holds` is true, for a `holds` monotone along `range` (false
/// then true, or true then false, either part possibly empty): a binary search for the
/// switch, at most `2 + log2(len)` calls. The result is a part of `range`.
fn monotone_part(range: Range<usize>, holds: impl Fn(usize) -> bool) -> Range<usize> {
    if range.is_empty() {
        return range;
    }
    let first = holds(range.start);
    if first == holds(range.end - 1) {
        return if first {
            range
        } else {
            range.start..range.start
        };
    }
    // holds(lo) == first, holds(hi) != first.
    let (mut lo, mut hi) = (range.start, range.end - 1);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if holds(mid) == first {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if first {
        range.start..hi
    } else {
        hi..range.end
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n x n grid of unit-square quads over [0,1]^2, each split along one diagonal.
    fn grid(n: usize) -> Vec<[DVec2; 3]> {
        let at = |i: usize, j: usize| DVec2::new(i as f64, j as f64) / n as f64;
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if (i + j) % 2 == 0 {
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                } else {
                    tris.push([a, b, d]);
                    tris.push([d, c, b]); // clockwise: both orientations occur
                }
            }
        }
        tris
    }

    /// `n` counter-clockwise triangles scattered over the unit square, overlapping, of
    /// `steps` sizes `smallest + k step`.
    fn scattered(n: usize, smallest: f64, steps: usize, step: f64) -> Vec<[DVec2; 3]> {
        (0..n)
            .map(|k| {
                let (x, y) = ((k * 37 % 101) as f64 / 101.0, (k * 53 % 97) as f64 / 97.0);
                let size = smallest + (k % steps) as f64 * step;
                [
                    DVec2::new(x, y),
                    DVec2::new(x + size, y + 0.3 * size),
                    DVec2::new(x - 0.5 * size, y + size),
                ]
            })
            .collect()
    }

    #[test]
    fn barycentrics_reproduce_the_point() {
        let tri = [
            DVec2::new(0.1, 0.2),
            DVec2::new(0.9, 0.3),
            DVec2::new(0.4, 0.8),
        ];
        let p = DVec2::new(0.45, 0.4);
        let (u, v) = barycentrics(&tri, p).unwrap();
        let q = (1.0 - u - v) * tri[0] + u * tri[1] + v * tri[2];
        assert!((q - p).length() < 1e-15);
        let reversed = [tri[0], tri[2], tri[1]];
        assert_eq!(barycentrics(&reversed, p), Some((v, u)));
        assert_eq!(barycentrics(&tri, DVec2::new(0.9, 0.9)), None);
    }

    #[test]
    fn grid_points_and_edge_points_are_covered_exactly_once() {
        // Sample a lattice that hits every edge and vertex of the grid exactly (dyadic
        // coordinates), plus interior points.
        let n = 4;
        let tris = grid(n);
        let locator = ScreenLocator::new(tris.clone());
        let samples = 64;
        for j in 0..=samples {
            for i in 0..=samples {
                let p = DVec2::new(i as f64, j as f64) / samples as f64;
                let owners: Vec<usize> = (0..tris.len())
                    .filter(|&k| barycentrics(&tris[k], p).is_some())
                    .collect();
                let hit = locator.locate(p);
                if i == samples || j == 0 {
                    // The rule gives the mesh's right and bottom boundaries to the outside.
                    assert!(owners.is_empty(), "point {p} owned by {owners:?}");
                    assert!(hit.is_none());
                    continue;
                }
                assert_eq!(owners.len(), 1, "point {p} owned by {owners:?}");
                assert_eq!(hit.map(|h| h.triangle), Some(owners[0]), "point {p}");
            }
        }
    }

    #[test]
    fn interior_shared_edges_are_owned_by_one_side() {
        let a = DVec2::new(0.0, 0.0);
        let b = DVec2::new(1.0, 0.0);
        let c = DVec2::new(1.0, 1.0);
        let d = DVec2::new(0.0, 1.0);
        let lower = [a, b, c];
        let upper = [a, c, d];
        let on_diagonal = DVec2::new(0.25, 0.25);
        let lower_has = barycentrics(&lower, on_diagonal).is_some();
        let upper_has = barycentrics(&upper, on_diagonal).is_some();
        assert!(lower_has != upper_has);
        // The shared vertex in the middle of a fan of four belongs to exactly one triangle.
        let m = DVec2::new(0.5, 0.5);
        let fan = [[a, b, m], [b, c, m], [c, d, m], [d, a, m]];
        assert_eq!(
            fan.iter().filter(|t| barycentrics(t, m).is_some()).count(),
            1
        );
    }

    #[test]
    fn overlapping_triangles_lowest_index_wins() {
        let big = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)];
        let small = [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.3, 0.1),
            DVec2::new(0.1, 0.3),
        ];
        let p = DVec2::new(0.15, 0.15);
        assert_eq!(
            ScreenLocator::new(vec![big, small])
                .locate(p)
                .unwrap()
                .triangle,
            0
        );
        assert_eq!(
            ScreenLocator::new(vec![small, big])
                .locate(p)
                .unwrap()
                .triangle,
            0
        );
    }

    #[test]
    fn points_outside_every_triangle_are_none() {
        let locator = ScreenLocator::new(vec![[
            DVec2::new(0.2, 0.2),
            DVec2::new(0.8, 0.2),
            DVec2::new(0.5, 0.8),
        ]]);
        assert!(locator.locate(DVec2::new(0.5, 0.1)).is_none()); // outside the bounds
        assert!(locator.locate(DVec2::new(0.25, 0.7)).is_none()); // inside bounds, outside
        assert!(locator.locate(DVec2::new(0.5, 0.4)).is_some());
        assert!(locator.locate(DVec2::new(f64::NAN, 0.4)).is_none());
    }

    /// The runs of covered grid points are exactly the points where `locate` finds a
    /// triangle: on the grid mesh sampled on a lattice through its edges and vertices (the
    /// tie rule decides every point there), on scattered overlapping triangles of both
    /// orientations and on a fan, each on grids of pixel centres ascending and descending in
    /// both axes, wider than the triangles' bounds (points outside them) and of one row or
    /// column; no point is reported covered twice by one triangle.
    #[test]
    fn covered_runs_are_the_points_locate_finds() {
        let scattered: Vec<[DVec2; 3]> = scattered(60, 0.02, 5, 0.09)
            .into_iter()
            .enumerate()
            .map(|(k, t)| if k % 2 == 0 { t } else { [t[0], t[2], t[1]] })
            .collect();
        let m = DVec2::new(0.5, 0.5);
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let fan: Vec<[DVec2; 3]> = (0..4)
            .map(|k| [corners[k], corners[(k + 1) % 4], m])
            .collect();
        // Lattices: through the grid's edges and vertices (k / 64), pixel centres over a wider
        // range, and single lines.
        let lattice = |n: usize, from: f64, to: f64, centres: bool| -> Vec<f64> {
            let offset = if centres { 0.5 } else { 0.0 };
            (0..n)
                .map(|k| from + (to - from) * (k as f64 + offset) / n as f64)
                .collect()
        };
        let grids = [
            (
                lattice(65, 0.0, 65.0 / 64.0, false),
                lattice(65, 0.0, 65.0 / 64.0, false),
            ),
            (lattice(90, -0.2, 1.3, true), lattice(70, -0.1, 1.2, true)),
            (lattice(37, 0.0, 1.0, true), vec![0.5]),
            (vec![0.25], lattice(41, 0.0, 1.0, true)),
        ];
        for tris in [grid(4), scattered, fan] {
            let locator = ScreenLocator::new(tris.clone());
            for (columns, rows) in &grids {
                for (columns, rows) in [
                    (columns.clone(), rows.clone()),
                    (
                        columns.iter().rev().copied().collect(),
                        rows.iter().rev().copied().collect(),
                    ),
                ] {
                    let mut count = vec![0usize; columns.len() * rows.len()];
                    let mut runs = 0;
                    locator.covered_runs(&columns, &rows, |y, xs| {
                        runs += 1;
                        for x in xs {
                            count[y * columns.len() + x] += 1;
                        }
                    });
                    assert!(runs > 0);
                    let mut covered = 0;
                    for (y, &py) in rows.iter().enumerate() {
                        for (x, &px) in columns.iter().enumerate() {
                            let p = DVec2::new(px, py);
                            let found = locator.locate(p).is_some();
                            let c = count[y * columns.len() + x];
                            let owners =
                                tris.iter().filter(|t| barycentrics(t, p).is_some()).count();
                            assert_eq!(c > 0, found, "point {p}");
                            assert!(c <= owners, "point {p}: {c} runs, {owners} triangles");
                            covered += usize::from(found);
                        }
                    }
                    assert!(covered > 0);
                }
            }
        }
    }

    /// Each bin lists exactly the triangles whose bounding boxes overlap it (by the bin
    /// indices of their corners' extremes), in ascending order, and the bins follow each
    /// other without gaps: the counting sort against the definition, on the grid mesh and
    /// on overlapping triangles of many sizes (some covering many bins, some one).
    #[test]
    fn bins_list_the_overlapping_triangles_in_index_order() {
        for tris in [grid(6), scattered(200, 0.01, 7, 0.06)] {
            let locator = ScreenLocator::new(tris.clone());
            let n = locator.bins_per_axis;
            assert_eq!(locator.bin_start.len(), n * n + 1);
            assert_eq!(locator.bin_start[0], 0);
            assert_eq!(locator.bin_start[n * n], locator.bin_triangles.len());
            for by in 0..n {
                for bx in 0..n {
                    let expected: Vec<u32> = (0..tris.len())
                        .filter(|&k| {
                            let t = &tris[k];
                            let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                            (locator.bin(lo.x, 0)..=locator.bin(hi.x, 0)).contains(&bx)
                                && (locator.bin(lo.y, 1)..=locator.bin(hi.y, 1)).contains(&by)
                        })
                        .map(|k| k as u32)
                        .collect();
                    let b = by * n + bx;
                    let listed =
                        &locator.bin_triangles[locator.bin_start[b]..locator.bin_start[b + 1]];
                    assert_eq!(listed, &expected[..], "bin ({bx}, {by})");
                }
            }
        }
        assert!(ScreenLocator::new(Vec::new()).locate(DVec2::ZERO).is_none());
    }
}
