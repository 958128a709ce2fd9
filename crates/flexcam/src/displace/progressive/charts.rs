//! Charts of a triangle mesh for the progressive mesh (Ramsey 2005, section 6.2, after
//! Sander et al. 2001): greedy merging of neighbouring charts by planarity and compactness,
//! each chart kept a topological disc, then chart boundaries straightened by shortest paths.
//!
//! Merging starts from one chart per triangle and repeatedly merges the neighbouring pair of
//! least cost: planarity `sum A_i (1 - N . N_i)` over the merged chart's triangles (area
//! `A_i`, normal `N_i`, `N` the area-weighted mean normal of the pair) plus compactness
//! `P^2 / (4 pi)` (`P` the merged perimeter; the area of the circle of that perimeter, so
//! both terms are areas). A merge is refused when the result would not be a disc (one
//! boundary loop, no handle, no pinched vertex) or would have fewer than three corners
//! (vertices of more than two charts, the mesh's outside counting as one). Merging stops at
//! the target number of charts or when no merge is allowed.
//!
//! Straightening: each run of boundary between two charts from one corner to the next is
//! replaced by the shortest path (Dijkstra over mesh edges, by length) between the same
//! corners through the inside of the two charts, and the two charts' triangles are divided
//! again along it; a run is left as it is where the division would not give two discs.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

use glam::DVec3;

use super::topology::{key, Topology, NONE};

/// The chart of each face after merging down to `target` charts (or as far as allowed) and
/// straightening; charts are numbered from 0 in the order of their first face.
pub fn build_charts(topology: &Topology, target: usize) -> Vec<u32> {
    let mut chart_of = merge(topology, target);
    straighten(topology, &mut chart_of);
    renumber(&mut chart_of);
    chart_of
}

/// A chart while merging.
struct Chart {
    faces: Vec<u32>,
    /// Area-weighted normal sum (its direction is the chart's normal).
    normal: DVec3,
    /// Its triangles' total area.
    area: f64,
    perimeter: f64,
    version: u32,
}

fn merge(topology: &Topology, target: usize) -> Vec<u32> {
    let n = topology.triangles.len();
    let mut chart_of: Vec<u32> = (0..n as u32).collect();
    let mut charts: Vec<Chart> = (0..n)
        .map(|f| Chart {
            faces: vec![f as u32],
            normal: topology.normals[f] * topology.areas[f],
            area: topology.areas[f],
            perimeter: topology
                .edges(f as u32)
                .iter()
                .map(|&(v, w)| topology.length(v, w))
                .sum(),
            version: 0,
        })
        .collect();
    let mut live = n;
    // (cost bits, chart a, chart b, version a, version b), cheapest first. Whether the
    // merged chart is a disc depends on the two charts alone, so it is asked only of the
    // pair popped (their versions unchanged since the push), not of every pair pushed.
    let mut heap = BinaryHeap::new();
    let push = |heap: &mut BinaryHeap<_>, charts: &[Chart], chart_of: &[u32], a: u32, b: u32| {
        if let Some(c) = merge_cost(topology, charts, chart_of, a, b) {
            let (x, y) = (a.min(b), a.max(b));
            heap.push(Reverse((
                c.to_bits(),
                x,
                y,
                charts[x as usize].version,
                charts[y as usize].version,
            )));
        }
    };
    for &[f, g] in topology.edge_faces.values() {
        if f != NONE && g != NONE && f < g {
            push(&mut heap, &charts, &chart_of, f, g);
        }
    }
    while live > target.max(1) {
        let Some(Reverse((_, a, b, va, vb))) = heap.pop() else {
            break;
        };
        if charts[a as usize].version != va || charts[b as usize].version != vb {
            continue;
        }
        let faces = charts[a as usize]
            .faces
            .iter()
            .chain(&charts[b as usize].faces);
        let inside = |f: u32| f != NONE && (chart_of[f as usize] == a || chart_of[f as usize] == b);
        if !is_disc(topology, faces.copied(), inside) {
            continue;
        }
        // Merge b into a.
        let moved = std::mem::take(&mut charts[b as usize].faces);
        let shared = shared_length(topology, &chart_of, &moved, a);
        for &f in &moved {
            chart_of[f as usize] = a;
        }
        let b_chart = &charts[b as usize];
        let (nb, ab, pb) = (b_chart.normal, b_chart.area, b_chart.perimeter);
        let chart = &mut charts[a as usize];
        chart.faces.extend(moved);
        chart.normal += nb;
        chart.area += ab;
        chart.perimeter += pb - 2.0 * shared;
        chart.version += 1;
        charts[b as usize].version += 1;
        live -= 1;
        for c in neighbours(topology, &chart_of, &charts[a as usize].faces) {
            push(&mut heap, &charts, &chart_of, a, c);
        }
    }
    chart_of
}

/// The length of the boundary between `faces` (one chart) and chart `other`.
fn shared_length(topology: &Topology, chart_of: &[u32], faces: &[u32], other: u32) -> f64 {
    let mut length = 0.0;
    for &f in faces {
        for (v, w) in topology.edges(f) {
            let g = topology.across(f, v, w);
            if g != NONE && chart_of[g as usize] == other {
                length += topology.length(v, w);
            }
        }
    }
    length
}

/// The charts next to `faces` (one chart) across an edge.
fn neighbours(topology: &Topology, chart_of: &[u32], faces: &[u32]) -> Vec<u32> {
    let own = chart_of[faces[0] as usize];
    let mut out: Vec<u32> = faces
        .iter()
        .flat_map(|&f| topology.edges(f).map(|(v, w)| topology.across(f, v, w)))
        .filter(|&g| g != NONE && chart_of[g as usize] != own)
        .map(|g| chart_of[g as usize])
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The cost of merging charts `a` and `b` (module documentation), or `None` when the merged
/// chart would have fewer than three corners (whether it is a disc is asked when the pair
/// is popped). The planarity `sum A_i (1 - N . N_i)` is `A - |S|`, `A` the pair's area and
/// `S = sum A_i N_i` (so `N = S / |S|`): both are kept per chart.
fn merge_cost(
    topology: &Topology,
    charts: &[Chart],
    chart_of: &[u32],
    a: u32,
    b: u32,
) -> Option<f64> {
    let (ca, cb) = (&charts[a as usize], &charts[b as usize]);
    let faces = ca.faces.iter().chain(&cb.faces).copied();
    if corner_count(topology, chart_of, faces, a, b) < 3 {
        return None;
    }
    let planarity = ca.area + cb.area - (ca.normal + cb.normal).length();
    let perimeter =
        ca.perimeter + cb.perimeter - 2.0 * shared_length(topology, chart_of, &cb.faces, a);
    Some(planarity.max(0.0) + perimeter * perimeter / (4.0 * std::f64::consts::PI))
}

/// Whether `faces` (those `inside` says are in) form a topological disc: Euler
/// characteristic 1 and every vertex on at most one boundary run (0 or 2 boundary edges),
/// which together leave one boundary loop, no handle and no pinched vertex.
pub fn is_disc(
    topology: &Topology,
    faces: impl IntoIterator<Item = u32>,
    inside: impl Fn(u32) -> bool,
) -> bool {
    let mut edges: HashSet<(u32, u32)> = HashSet::new();
    let mut vertices: HashMap<u32, u32> = HashMap::new();
    let mut count = 0i64;
    for f in faces {
        count += 1;
        for (v, w) in topology.edges(f) {
            edges.insert(key(v, w));
            vertices.entry(v).or_insert(0);
            if !inside(topology.across(f, v, w)) {
                *vertices.entry(v).or_insert(0) += 1;
                *vertices.entry(w).or_insert(0) += 1;
            }
        }
    }
    let euler = vertices.len() as i64 - edges.len() as i64 + count;
    count > 0 && euler == 1 && vertices.values().all(|&c| c == 0 || c == 2)
}

/// The corners of charts `a` and `b` merged (`faces` their faces): boundary vertices whose
/// faces belong to three or more charts, the outside counting as one.
fn corner_count(
    topology: &Topology,
    chart_of: &[u32],
    faces: impl IntoIterator<Item = u32>,
    a: u32,
    b: u32,
) -> usize {
    let label = |f: u32| match f {
        NONE => NONE - 1,
        f if chart_of[f as usize] == b => a,
        f => chart_of[f as usize],
    };
    let mut seen: HashSet<u32> = HashSet::new();
    let mut count = 0;
    for f in faces {
        for v in topology.triangles[f as usize] {
            if !seen.insert(v) {
                continue;
            }
            if labels_at(topology, v, label) >= 3 {
                count += 1;
            }
        }
    }
    count
}

/// How many different labels the faces around `v` have (`label(NONE)` for the outside, when
/// `v` is on the mesh's boundary).
fn labels_at(topology: &Topology, v: u32, label: impl Fn(u32) -> u32) -> usize {
    let mut labels: Vec<u32> = topology.vertex_faces[v as usize]
        .iter()
        .map(|&f| label(f))
        .collect();
    if topology.on_boundary(v) {
        labels.push(label(NONE));
    }
    labels.sort_unstable();
    labels.dedup();
    labels.len()
}

/// Whether `v` is a chart corner: its faces belong to three or more charts (the mesh's
/// outside counting as one).
pub fn is_corner(topology: &Topology, chart_of: &[u32], v: u32) -> bool {
    labels_at(topology, v, |f| {
        if f == NONE {
            NONE
        } else {
            chart_of[f as usize]
        }
    }) >= 3
}

/// Straightens every boundary run between two charts (module documentation).
fn straighten(topology: &Topology, chart_of: &mut [u32]) {
    let mut pairs: Vec<(u32, u32)> = topology
        .edge_faces
        .values()
        .filter(|[f, g]| *f != NONE && *g != NONE)
        .map(|&[f, g]| (chart_of[f as usize], chart_of[g as usize]))
        .filter(|(x, y)| x != y)
        .map(|(x, y)| key(x, y))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    for (a, b) in pairs {
        for (start, end) in runs(topology, chart_of, a, b) {
            straighten_run(topology, chart_of, a, b, start, end);
        }
    }
}

/// The runs of boundary between charts `a` and `b`, by their end corners.
fn runs(topology: &Topology, chart_of: &[u32], a: u32, b: u32) -> Vec<(u32, u32)> {
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    for (&(v, w), &[f, g]) in &topology.edge_faces {
        if f == NONE || g == NONE {
            continue;
        }
        let (x, y) = (chart_of[f as usize], chart_of[g as usize]);
        if key(x, y) == (a, b) && x != y {
            next.entry(v).or_default().push(w);
            next.entry(w).or_default().push(v);
        }
    }
    for list in next.values_mut() {
        list.sort_unstable();
    }
    let mut out = Vec::new();
    let mut used: HashSet<(u32, u32)> = HashSet::new();
    let mut starts: Vec<u32> = next
        .keys()
        .copied()
        .filter(|&v| is_corner(topology, chart_of, v))
        .collect();
    starts.sort_unstable();
    for start in starts {
        for &first in &next[&start] {
            if used.contains(&key(start, first)) {
                continue;
            }
            let (mut previous, mut at) = (start, first);
            used.insert(key(start, first));
            while !is_corner(topology, chart_of, at) {
                let Some(&step) = next[&at].iter().find(|&&w| w != previous) else {
                    break;
                };
                if !used.insert(key(at, step)) {
                    break;
                }
                (previous, at) = (at, step);
            }
            if is_corner(topology, chart_of, at) && at != start {
                out.push((start, at));
            }
        }
    }
    out
}

/// Replaces the run between corners `start` and `end` of the boundary of charts `a` and `b`
/// by the shortest path through their inside, if the division along it gives two discs.
fn straighten_run(topology: &Topology, chart_of: &mut [u32], a: u32, b: u32, start: u32, end: u32) {
    let in_pair = |f: u32| f != NONE && (chart_of[f as usize] == a || chart_of[f as usize] == b);
    // Vertices on the outer boundary of the pair stay put: the path may only end there.
    let on_outer = |v: u32| {
        topology.on_boundary(v)
            || topology.vertex_faces[v as usize]
                .iter()
                .any(|&f| !in_pair(f))
    };
    let Some(path) = shortest_path(topology, start, end, |v, w| {
        let [f, g] = topology.faces_of(v, w);
        in_pair(f) && in_pair(g) && (w == end || !on_outer(w))
    }) else {
        return;
    };
    let cut: HashSet<(u32, u32)> = path.windows(2).map(|p| key(p[0], p[1])).collect();
    let faces: Vec<u32> = (0..chart_of.len() as u32).filter(|&f| in_pair(f)).collect();
    // Components of the pair's faces with the path as a wall.
    let mut component: HashMap<u32, u32> = HashMap::new();
    let mut count = 0;
    for &seed in &faces {
        if component.contains_key(&seed) {
            continue;
        }
        let mut stack = vec![seed];
        component.insert(seed, count);
        while let Some(f) = stack.pop() {
            for (v, w) in topology.edges(f) {
                let g = topology.across(f, v, w);
                if in_pair(g) && !cut.contains(&key(v, w)) && !component.contains_key(&g) {
                    component.insert(g, count);
                    stack.push(g);
                }
            }
        }
        count += 1;
    }
    if count != 2 {
        return;
    }
    let from_a = faces
        .iter()
        .filter(|&&f| chart_of[f as usize] == a && component[&f] == 0)
        .count();
    let a_side =
        u32::from(2 * from_a < faces.iter().filter(|&&f| chart_of[f as usize] == a).count());
    let new_label = |f: u32| if component[&f] == a_side { a } else { b };
    for label in [a, b] {
        let side: Vec<u32> = faces
            .iter()
            .copied()
            .filter(|&f| new_label(f) == label)
            .collect();
        let inside = |g: u32| g != NONE && component.get(&g).is_some_and(|_| new_label(g) == label);
        if !is_disc(topology, side.iter().copied(), inside) {
            return;
        }
    }
    for &f in &faces {
        chart_of[f as usize] = new_label(f);
    }
}

/// The shortest path by edge length from `start` to `end` along edges `allowed(v, w)` lets
/// the path take from `v` to `w`.
fn shortest_path(
    topology: &Topology,
    start: u32,
    end: u32,
    allowed: impl Fn(u32, u32) -> bool,
) -> Option<Vec<u32>> {
    let mut distance: HashMap<u32, f64> = HashMap::from([(start, 0.0)]);
    let mut previous: HashMap<u32, u32> = HashMap::new();
    let mut heap = BinaryHeap::from([Reverse((0u64, start))]);
    while let Some(Reverse((bits, v))) = heap.pop() {
        let d = f64::from_bits(bits);
        if d > distance[&v] {
            continue;
        }
        if v == end {
            let mut path = vec![end];
            while let Some(&p) = previous.get(path.last()?) {
                path.push(p);
            }
            path.reverse();
            return Some(path);
        }
        for &f in &topology.vertex_faces[v as usize] {
            for w in topology.triangles[f as usize] {
                if w == v || !allowed(v, w) {
                    continue;
                }
                let next = d + topology.length(v, w);
                if distance.get(&w).is_none_or(|&old| next < old) {
                    distance.insert(w, next);
                    previous.insert(w, v);
                    heap.push(Reverse((next.to_bits(), w)));
                }
            }
        }
    }
    None
}

/// Numbers charts from 0 in the order of their first face.
fn renumber(chart_of: &mut [u32]) {
    let mut map: HashMap<u32, u32> = HashMap::new();
    for c in chart_of.iter_mut() {
        let next = map.len() as u32;
        *c = *map.entry(*c).or_insert(next);
    }
}
