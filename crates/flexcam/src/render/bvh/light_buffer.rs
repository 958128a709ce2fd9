//! A light buffer (Haines and Greenberg, 1986) over a [`Bvh`]: for one light, the tree's
//! leaves binned by the cells of the directions in which the light sees them, so that a
//! shadow ray towards the light opens only its cell's leaves instead of walking the tree.
//!
//! A point light's cells are those of a cube around it: 6 faces of [`CELLS`] x [`CELLS`]
//! cells, a direction `w` falling on the face of its largest coordinate and there in the cell
//! of its two others divided by that one. A directional light's are a grid of
//! [`CELLS`] x [`CELLS`] cells across its beam: a ray parallel to it falls in the cell of its
//! origin projected onto a plane perpendicular to the beam.
//!
//! Exactness: [`LightBuffer::occluded`] answers as [`Bvh::occluded`] does, because it opens
//! every leaf the tree's walk would open with a hit and only such leaves. A leaf is opened when
//! the slab test of its box, the very box and arithmetic of the walk (`box_entry`), enters it
//! within the ray's interval, and then its triangles are tested with the same f32 test and
//! mask: a leaf entered this way is entered by the walk too, since every box above it in the
//! tree contains its box and the slab test's entry and exit are monotone in the planes. And
//! every leaf the walk enters is in the ray's cell: the walk enters a box only where the f32
//! ray passes within its f32 rounding (about 2^-21 of the scene's size) of it, and the f32 ray
//! stays that close to the f64 segment from its origin to the light (for a point light the
//! segment's far end is checked to lie within an eighth of [`LightBuffer`]'s margin of the
//! light: `shadow_ray` ends it one secondary-ray offset, 2^-16 of the scene's size, off the
//! light); so the box enlarged by the margin (2^-12 of the size) meets that segment, whose
//! points other than the light all lie in the direction of the ray's origin. Each box is
//! binned into every cell whose directions its enlarged box can show, its cell coordinates
//! widened by far more than their rounding (`ROUNDING`), and a box whose enlargement holds
//! the light into every cell. A ray that is not such a shadow ray towards this light (another
//! end or interval, a non-finite origin) and a ray whose cell holds more than
//! [`MAX_CELL_LEAVES`] leaves (where the walk's pruning beats testing them all) are answered
//! by the walk itself.

use glam::{DVec3, Vec4};

use super::traverse::{box_entry, same_signs, Packet};
use super::triangle::FastRay;
use super::{Bvh, Keep};
use crate::geometry::{Aabb, Ray};

/// Cells per side of a cube face or of a directional light's grid.
const CELLS: usize = 64;
/// A cell holding more leaves than this is answered by the tree's walk.
const MAX_CELL_LEAVES: usize = 24;
/// How far a box's cell coordinates are widened against the rounding of the cells'
/// arithmetic (relative to a face's [-1, 1]; to the margin on a directional light's grid),
/// far above it (a few units of 2^-53, over distances from the light of at least the
/// margin) and far below a cell.
const ROUNDING: f64 = 1e-9;
/// Marks a cell answered by the tree's walk in [`LightBuffer::cells`].
const WALK: u32 = u32::MAX;

/// How a light's rays are mapped to cells.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// A point light at `position`.
    Point { position: DVec3 },
    /// A directional light whose shadow rays all have direction `direction`; `axes` span a
    /// plane across it, on which the grid's corner is `low` and a cell measures `cell`
    /// (`per_cell` is its reciprocal).
    Parallel {
        direction: DVec3,
        axes: [DVec3; 2],
        low: [f64; 2],
        cell: [f64; 2],
        per_cell: [f64; 2],
    },
}

/// A leaf of the tree: its box as the walk tests it and its stored triangles.
#[derive(Debug, Clone, Copy)]
struct Leaf {
    bounds: Aabb,
    first: u32,
    count: u32,
}

/// The leaves of a [`Bvh`] binned by the direction cells of one light (see the module
/// documentation).
#[derive(Debug, Clone)]
pub(in crate::render) struct LightBuffer {
    source: Source,
    /// How far each box is enlarged before binning: 2^-12 of the scene's size.
    margin: f64,
    leaves: Vec<Leaf>,
    /// Cell `k`'s leaves are `cell_leaves[cells[k].0..cells[k].1]`; `cells[k].0 == WALK`
    /// for a cell answered by the walk.
    cells: Vec<(u32, u32)>,
    cell_leaves: Vec<u32>,
}

impl LightBuffer {
    /// The buffer of a point light at `position`; `None` for a non-finite position.
    pub fn point(bvh: &Bvh, position: DVec3) -> Option<LightBuffer> {
        if !position.is_finite() {
            return None;
        }
        let scale = bvh.root_scale.max(position.abs().max_element());
        Some(LightBuffer::binned(
            bvh,
            Source::Point { position },
            scale,
            6,
        ))
    }

    /// The buffer of a directional light whose shadow rays have direction `direction`
    /// (towards the light); `None` for a zero or non-finite direction.
    pub fn parallel(bvh: &Bvh, direction: DVec3) -> Option<LightBuffer> {
        let unit = direction.try_normalize()?;
        let helper = if unit.x.abs() < 0.5 {
            DVec3::X
        } else {
            DVec3::Y
        };
        let a = helper.cross(unit).normalize();
        let axes = [a, unit.cross(a)];
        let margin = margin_of(bvh.root_scale);
        let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for leaf in leaves_of(bvh) {
            for (k, axis) in axes.iter().enumerate() {
                let (lo, hi) = projected(&leaf.bounds, margin, *axis);
                low[k] = low[k].min(lo);
                high[k] = high[k].max(hi);
            }
        }
        let cell = |k: usize| {
            let size = (high[k] - low[k]) / CELLS as f64;
            if size > 0.0 && size.is_finite() {
                size
            } else {
                1.0
            }
        };
        // The grid's corner at the leaves' low corner (0 when there are none).
        let source = Source::Parallel {
            direction,
            axes,
            low: low.map(|l| if l.is_finite() { l } else { 0.0 }),
            cell: [cell(0), cell(1)],
            per_cell: [1.0 / cell(0), 1.0 / cell(1)],
        };
        Some(LightBuffer::binned(bvh, source, bvh.root_scale, 1))
    }

    /// Bins the leaves of `bvh` into the `faces` x [`CELLS`] x [`CELLS`] cells of `source`.
    fn binned(bvh: &Bvh, source: Source, scale: f64, faces: usize) -> LightBuffer {
        let margin = margin_of(scale);
        let leaves = leaves_of(bvh);
        let count = faces * CELLS * CELLS;
        let mut cells: Vec<Vec<u32>> = vec![Vec::new(); count];
        for (index, leaf) in leaves.iter().enumerate() {
            let lo = leaf.bounds.min.as_dvec3() - margin;
            let hi = leaf.bounds.max.as_dvec3() + margin;
            let mut add = |cell: usize| cells[cell].push(index as u32);
            match source {
                Source::Point { position } => {
                    if lo.cmple(position).all() && position.cmple(hi).all() {
                        (0..count).for_each(&mut add);
                        continue;
                    }
                    for face in 0..6 {
                        if let Some([us, vs]) = face_cells(face, lo - position, hi - position) {
                            for i in us.0..=us.1 {
                                for j in vs.0..=vs.1 {
                                    add(face * CELLS * CELLS + i * CELLS + j);
                                }
                            }
                        }
                    }
                }
                Source::Parallel {
                    axes,
                    low,
                    cell,
                    per_cell,
                    ..
                } => {
                    let range = |k: usize| {
                        let (a, b) = projected(&leaf.bounds, margin, axes[k]);
                        let pad = margin * ROUNDING + cell[k] * ROUNDING;
                        (
                            grid_index(a - pad, low[k], per_cell[k]),
                            grid_index(b + pad, low[k], per_cell[k]),
                        )
                    };
                    let (us, vs) = (range(0), range(1));
                    for i in us.0..=us.1 {
                        for j in vs.0..=vs.1 {
                            add(i * CELLS + j);
                        }
                    }
                }
            }
        }
        let mut cell_leaves = Vec::new();
        let cells = (cells.iter())
            .map(|cell| {
                if cell.len() > MAX_CELL_LEAVES {
                    return (WALK, WALK);
                }
                let start = cell_leaves.len() as u32;
                cell_leaves.extend_from_slice(cell);
                (start, cell_leaves.len() as u32)
            })
            .collect();
        LightBuffer {
            source,
            margin,
            leaves,
            cells,
            cell_leaves,
        }
    }

    /// The cell of shadow ray `ray` towards this buffer's light, or `None` for a ray that is
    /// not one (see the module documentation), or whose origin has no cell.
    #[inline]
    fn cell_of(&self, ray: &Ray) -> Option<usize> {
        match self.source {
            Source::Point { position } => {
                let end = ray.origin + ray.direction - position;
                let ends_at_light = end.abs().max_element() <= self.margin / 8.0;
                if ray.t_max != 1.0 || !ends_at_light {
                    return None;
                }
                let w = ray.origin - position;
                let a = w.abs();
                let (axis, b, c) = if a.x >= a.y && a.x >= a.z {
                    (0, w.y, w.z)
                } else if a.y >= a.z {
                    (1, w.z, w.x)
                } else {
                    (2, w.x, w.y)
                };
                let major = a[axis];
                if !(major >= self.margin && major.is_finite()) {
                    return None;
                }
                let face = 2 * axis + usize::from(w[axis] < 0.0);
                // One division: the ratios' rounding stays far below `ROUNDING`.
                let inverse = 1.0 / major;
                let (i, j) = (face_index(b * inverse), face_index(c * inverse));
                Some(face * CELLS * CELLS + i * CELLS + j)
            }
            Source::Parallel {
                direction,
                axes,
                low,
                per_cell,
                ..
            } => {
                if ray.t_max != f64::INFINITY || ray.direction != direction {
                    return None;
                }
                let (x, y) = (ray.origin.dot(axes[0]), ray.origin.dot(axes[1]));
                if !(x.is_finite() && y.is_finite()) {
                    return None;
                }
                Some(
                    grid_index(x, low[0], per_cell[0]) * CELLS + grid_index(y, low[1], per_cell[1]),
                )
            }
        }
    }

    /// Whether each of four shadow rays (each with its f32 form; `None`: no ray, answered
    /// `false`) towards this buffer's light hits a triangle `keep` keeps, exactly as
    /// [`Bvh::occluded4`] answers: the rays that fall in a cell of leaves by those leaves
    /// (four rays in one cell, as a 2x2 quad's nearly always are, by one box test of each
    /// leaf for the four), the others (see the module documentation) by the tree's walk.
    pub fn occluded4<K: Keep>(
        &self,
        bvh: &Bvh,
        rays: [Option<(&Ray, &FastRay)>; 4],
        keep: &K,
    ) -> [bool; 4] {
        let mut cells = [None; 4];
        for lane in 0..4 {
            if let Some((ray, _)) = rays[lane] {
                cells[lane] = self.cell_of(ray);
            }
        }
        if let ([Some(a), Some(b), Some(c), Some(d)], [Some(k), ..]) = (rays, cells) {
            let fast = [a.1, b.1, c.1, d.1];
            if cells.iter().all(|&c| c == Some(k)) && same_signs(fast) {
                if let Some(leaves) = self.leaves_in(k) {
                    return self.blocks4(bvh, leaves, fast, keep);
                }
            }
        }
        let mut blocked = [false; 4];
        let mut walked: [Option<&FastRay>; 4] = [None; 4];
        let mut walks = false;
        for lane in 0..4 {
            let Some((_, fast)) = rays[lane] else {
                continue;
            };
            match cells[lane].and_then(|k| self.leaves_in(k)) {
                Some(leaves) => blocked[lane] = self.blocks(bvh, leaves, fast, keep),
                None => {
                    walked[lane] = Some(fast);
                    walks = true;
                }
            }
        }
        if walks {
            let by_walk = bvh.occluded4(walked, keep);
            for lane in 0..4 {
                if walked[lane].is_some() {
                    blocked[lane] = by_walk[lane];
                }
            }
        }
        blocked
    }

    /// [`LightBuffer::occluded4`] of one ray: [`Bvh::occluded`]'s answer.
    pub fn occluded<K: Keep>(&self, bvh: &Bvh, ray: &Ray, fast: &FastRay, keep: &K) -> bool {
        match self.leaves_for(ray) {
            Some(leaves) => self.blocks(bvh, leaves, fast, keep),
            None => bvh.occluded(fast, keep),
        }
    }

    /// The leaves of `ray`'s cell, or `None` where the walk answers it.
    #[inline]
    fn leaves_for(&self, ray: &Ray) -> Option<&[u32]> {
        self.leaves_in(self.cell_of(ray)?)
    }

    /// The leaves of cell `cell`, or `None` for a cell the walk answers.
    #[inline]
    fn leaves_in(&self, cell: usize) -> Option<&[u32]> {
        let (start, end) = self.cells[cell];
        (start != WALK).then(|| &self.cell_leaves[start as usize..end as usize])
    }

    /// Whether `ray` hits a kept triangle of one of `leaves` whose box the walk's slab test
    /// enters within the ray's interval.
    #[inline]
    fn blocks<K: Keep>(&self, bvh: &Bvh, leaves: &[u32], ray: &FastRay, keep: &K) -> bool {
        leaves.iter().any(|&index| {
            let leaf = &self.leaves[index as usize];
            // Entered: a finite entry (infinity for a box missed) within the interval.
            let entry = box_entry(&leaf.bounds, ray, ray.t_max);
            let entered = entry < f32::INFINITY && entry <= ray.t_max;
            if !entered {
                return false;
            }
            let first = leaf.first as usize;
            let triangles = &bvh.triangles[first..first + leaf.count as usize];
            (triangles.iter().enumerate())
                .any(|(i, tri)| tri.intersect(ray, ray.t_max).is_some() && keep.keeps(first + i))
        })
    }

    /// [`LightBuffer::blocks`] of four rays whose direction signs agree, each leaf's box
    /// tested for the four at once (bit for bit each ray's `box_entry`); a ray stops at its
    /// first hit, the test when all four have one.
    #[inline]
    fn blocks4<K: Keep>(
        &self,
        bvh: &Bvh,
        leaves: &[u32],
        rays: [&FastRay; 4],
        keep: &K,
    ) -> [bool; 4] {
        let packet = Packet::new(rays);
        let t_max = Vec4::new(rays[0].t_max, rays[1].t_max, rays[2].t_max, rays[3].t_max);
        let mut blocked = [false; 4];
        let mut open = 0b1111u32;
        for &index in leaves {
            let leaf = &self.leaves[index as usize];
            let entry = packet.box_entries(leaf.bounds.min, leaf.bounds.max, t_max);
            let entered = entry.cmplt(Vec4::INFINITY) & entry.cmple(t_max);
            let mut active = entered.bitmask() & open;
            let first = leaf.first as usize;
            let triangles = &bvh.triangles[first..first + leaf.count as usize];
            while active != 0 {
                let lane = active.trailing_zeros() as usize;
                active &= active - 1;
                let ray = rays[lane];
                if (triangles.iter().enumerate()).any(|(i, tri)| {
                    tri.intersect(ray, ray.t_max).is_some() && keep.keeps(first + i)
                }) {
                    blocked[lane] = true;
                    open &= !(1 << lane);
                }
            }
            if open == 0 {
                break;
            }
        }
        blocked
    }
}

/// The binning margin for a scene whose largest coordinate magnitude is `scale`.
fn margin_of(scale: f64) -> f64 {
    (scale * (1.0 / 4096.0)).max(f64::MIN_POSITIVE)
}

/// Every leaf of `bvh` with the box the walk tests it by: the box its parent stores for it,
/// or the root's padded box for a tree that is one leaf.
fn leaves_of(bvh: &Bvh) -> Vec<Leaf> {
    if bvh.triangles.is_empty() {
        return Vec::new();
    }
    let leaf = |bounds: Aabb, child: super::Child| Leaf {
        bounds,
        first: child.index,
        count: child.count,
    };
    if bvh.root.count > 0 {
        return vec![leaf(bvh.root_bounds, bvh.root)];
    }
    let mut leaves = Vec::new();
    for node in &bvh.nodes {
        for (k, child) in node.children.iter().enumerate() {
            if child.count > 0 {
                let (min, max) = node.child_box(k);
                leaves.push(leaf(Aabb { min, max }, *child));
            }
        }
    }
    leaves
}

/// The range of `axis . p` over the points `p` of `bounds` enlarged by `margin`.
fn projected(bounds: &Aabb, margin: f64, axis: DVec3) -> (f64, f64) {
    let (lo, hi) = (
        bounds.min.as_dvec3() - margin,
        bounds.max.as_dvec3() + margin,
    );
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for corner in 0..8 {
        let pick = |k: usize| if corner >> k & 1 == 0 { lo[k] } else { hi[k] };
        let d = axis.dot(DVec3::new(pick(0), pick(1), pick(2)));
        low = low.min(d);
        high = high.max(d);
    }
    (low, high)
}

/// The cell of coordinate `x` on a grid axis starting at `low` with `per_cell` cells a
/// unit, clamped to the grid.
#[inline]
fn grid_index(x: f64, low: f64, per_cell: f64) -> usize {
    // Truncation is the floor for the non-negative values it is applied to.
    let i = (x - low) * per_cell;
    if i >= (CELLS - 1) as f64 {
        CELLS - 1
    } else if i >= 0.0 {
        i as usize
    } else {
        0
    }
}

/// The cell of a face coordinate `u` (in [-1, 1] for a direction on that face).
#[inline]
fn face_index(u: f64) -> usize {
    grid_index(u, -1.0, CELLS as f64 / 2.0)
}

/// The cells of cube face `face` (axis `face / 2`, positive for an even face) that the
/// directions of the points of the box `[lo, hi]` (relative to the light, which it does not
/// hold) can fall in, as ranges of the face's two coordinates; `None` when none.
fn face_cells(face: usize, lo: DVec3, hi: DVec3) -> Option<[(usize, usize); 2]> {
    let axis = face / 2;
    let (major_lo, major_hi) = if face % 2 == 0 {
        (lo[axis], hi[axis])
    } else {
        (-hi[axis], -lo[axis])
    };
    if major_hi <= 0.0 {
        return None;
    }
    // The face's points have a positive major coordinate; the ratios over the box's part
    // with one, the least major coordinate 0 where the box reaches the plane through the
    // light (ratios then unbounded).
    let least = major_lo.max(0.0);
    let ratio_range = |minor_lo: f64, minor_hi: f64| {
        let low = if minor_lo >= 0.0 {
            minor_lo / major_hi
        } else if least > 0.0 {
            minor_lo / least
        } else {
            f64::NEG_INFINITY
        };
        let high = if minor_hi <= 0.0 {
            minor_hi / major_hi
        } else if least > 0.0 {
            minor_hi / least
        } else {
            f64::INFINITY
        };
        (low <= 1.0 && high >= -1.0)
            .then(|| (face_index(low - ROUNDING), face_index(high + ROUNDING)))
    };
    let (b, c) = [(1, 2), (2, 0), (0, 1)][axis];
    Some([ratio_range(lo[b], hi[b])?, ratio_range(lo[c], hi[c])?])
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::tests::{soup, Rng};
    use super::super::TriangleMask;
    use super::*;
    use crate::render::bvh::AllTriangles;

    /// A tessellated floor (a grid of quads in y = 0) and a box of triangles over it: the
    /// shape of cube-floor, where shadow rays leave one triangle and pass near others.
    fn floor_and_box(rng: &mut Rng) -> Vec<[Vec3; 3]> {
        let mut triangles = Vec::new();
        let n = 12;
        let at = |i: usize, j: usize| Vec3::new(i as f32 - 6.0, 0.0, j as f32 - 6.0);
        for i in 0..n {
            for j in 0..n {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        for _ in 0..40 {
            let c = Vec3::new(0.0, 1.5, 0.0) + rng.vec(1.0);
            triangles.push([c + rng.vec(0.6), c + rng.vec(0.6), c + rng.vec(0.6)]);
        }
        triangles
    }

    /// A point on triangle `t` (barycentrics from -0.05 to 1.05: on and just past its
    /// edges) moved `offset` along its normal.
    fn on_triangle(rng: &mut Rng, t: &[Vec3; 3], offset: f64) -> DVec3 {
        let (u, v) = (rng.next() * 1.1 - 0.05, rng.next() * 1.1 - 0.05);
        let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        p.as_dvec3() + n.as_dvec3() * offset
    }

    /// Shadow rays as lit shading builds them (from points on and near the triangles and
    /// anywhere in the scene, to a point light or along a directional light's beam), in
    /// 2x2 quads: a light buffer answers each exactly as the BVH's walk does, unmasked and
    /// masked, one by one and four at a time, for lights outside the scene, among its
    /// triangles and on a vertex; most rays through a cell's leaves, both answers common.
    #[test]
    fn light_buffers_answer_as_the_walk() {
        let mut rng = Rng(47);
        let (mut blocked, mut free, mut by_cells, mut walked) = (0, 0, 0, 0);
        let scenes = [
            floor_and_box(&mut rng),
            soup(&mut rng, 5),
            soup(&mut rng, 300),
            soup(&mut rng, 5000),
        ];
        for (s, triangles) in scenes.iter().enumerate() {
            let bvh = Bvh::build(triangles);
            let mask = TriangleMask::by_id(&bvh, |id| id % 3 != 1);
            let offset = 10.0 / 65536.0;
            for l in 0..12 {
                let point = match l % 4 {
                    0 => rng.vec(4.0).as_dvec3() + DVec3::new(0.0, 9.0, 0.0),
                    1 => rng.vec(12.0).as_dvec3(),
                    2 => triangles[l % triangles.len()][0].as_dvec3(),
                    _ => rng.vec(30.0).as_dvec3(),
                };
                let direction = rng.vec(1.0).as_dvec3() + DVec3::new(0.0, 0.5, 0.0);
                let buffers = [
                    (LightBuffer::point(&bvh, point).unwrap(), true),
                    (LightBuffer::parallel(&bvh, direction).unwrap(), false),
                ];
                for (buffer, is_point) in &buffers {
                    for k in 0..300 {
                        let corner = if k % 3 == 0 {
                            rng.vec(12.0).as_dvec3()
                        } else {
                            let t = &triangles
                                [(rng.next() * triangles.len() as f32) as usize % triangles.len()];
                            on_triangle(&mut rng, t, [offset, -offset, 0.0][k % 3])
                        };
                        let step = [1e-3, 0.05, 0.4][k % 3];
                        let rays =
                            [(0.0, 0.0), (step, 0.0), (0.0, step), (step, step)].map(|(x, z)| {
                                let from = corner + DVec3::new(x, 0.0, z);
                                if *is_point {
                                    Ray {
                                        t_max: 1.0,
                                        ..Ray::new(from, point - from)
                                    }
                                } else {
                                    Ray::new(from, direction)
                                }
                            });
                        let fast = rays.each_ref().map(FastRay::new);
                        let lanes = [0, 1, 2, 3].map(|i| Some((&rays[i], fast[i].as_ref()?)));
                        let got = buffer.occluded4(&bvh, lanes, &AllTriangles);
                        let masked = buffer.occluded4(&bvh, lanes, &mask);
                        for i in 0..4 {
                            let (ray, fast) = (&rays[i], fast[i].as_ref().unwrap());
                            let expected = bvh.occluded(fast, &AllTriangles);
                            let what = format!("scene {s}, light {l}, quad {k}, ray {i}");
                            assert_eq!(got[i], expected, "{what}");
                            assert_eq!(masked[i], bvh.occluded(fast, &mask), "{what}, masked");
                            assert_eq!(buffer.occluded(&bvh, ray, fast, &AllTriangles), expected);
                            if expected {
                                blocked += 1;
                            } else {
                                free += 1;
                            }
                            if buffer.leaves_for(ray).is_some() {
                                by_cells += 1;
                            } else {
                                walked += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(
            blocked > 5000 && free > 5000 && by_cells > 50_000 && walked > 1000,
            "{blocked} blocked, {free} free, {by_cells} by cells, {walked} walked"
        );
    }

    /// Rays that are not the buffer's shadow rays (another interval, another end, another
    /// direction, a non-finite origin) are answered by the walk.
    #[test]
    fn other_rays_are_walked() {
        let mut rng = Rng(5);
        let bvh = Bvh::build(&soup(&mut rng, 50));
        let light = DVec3::new(1.0, 20.0, 2.0);
        let point = LightBuffer::point(&bvh, light).unwrap();
        let from = DVec3::new(0.5, -1.0, 0.25);
        let to_light = Ray {
            t_max: 1.0,
            ..Ray::new(from, light - from)
        };
        assert!(point.leaves_for(&to_light).is_some());
        let half = Ray {
            t_max: 0.5,
            ..to_light
        };
        let past = Ray::new(from, light - from);
        let elsewhere = Ray {
            t_max: 1.0,
            ..Ray::new(from, light - from + DVec3::X)
        };
        let at_light = Ray {
            t_max: 1.0,
            ..Ray::new(light, DVec3::ZERO)
        };
        for ray in [half, past, elsewhere, at_light] {
            assert!(point.leaves_for(&ray).is_none(), "{ray:?}");
        }
        let direction = DVec3::new(0.3, 1.0, 0.5);
        let parallel = LightBuffer::parallel(&bvh, direction).unwrap();
        assert!(parallel.leaves_for(&Ray::new(from, direction)).is_some());
        for ray in [
            Ray::new(from, direction * 2.0),
            Ray {
                t_max: 1.0,
                ..Ray::new(from, direction)
            },
            Ray::new(DVec3::new(f64::NAN, 0.0, 0.0), direction),
        ] {
            assert!(parallel.leaves_for(&ray).is_none(), "{ray:?}");
        }
        assert!(LightBuffer::point(&bvh, DVec3::NAN).is_none());
        assert!(LightBuffer::parallel(&bvh, DVec3::ZERO).is_none());
    }

    /// An empty tree: every ray is free, through an empty cell.
    #[test]
    fn an_empty_tree_blocks_nothing() {
        let bvh = Bvh::build(&[]);
        let buffer = LightBuffer::point(&bvh, DVec3::Y).unwrap();
        let ray = Ray {
            t_max: 1.0,
            ..Ray::new(DVec3::ZERO, DVec3::Y)
        };
        let fast = FastRay::new(&ray).unwrap();
        assert!(!buffer.occluded(&bvh, &ray, &fast, &AllTriangles));
        assert!(buffer.leaves_for(&ray).is_some());
    }
}
