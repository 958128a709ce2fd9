//! The fan of faces around one vertex, read from the faces' vertex lists: what the simplifier
//! checks around every vertex a collapse touches, so that the mesh stays a manifold.

/// The faces around a vertex, if they form one fan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fan {
    /// Number of faces.
    pub faces: usize,
    /// For a vertex on the boundary, its two boundary neighbours: the vertex before it on the
    /// first face of the fan and the vertex after it on the last; `None` for a closed fan.
    pub boundary: Option<(u32, u32)>,
}

/// The fan of `v` over `faces` (each a vertex list containing `v` once), or `None` when they
/// are not one fan: a directed edge at `v` used twice, or faces falling into separate fans.
/// No faces give an empty open fan with `boundary` `None` and `faces` 0.
pub fn fan<'a>(v: u32, faces: impl Iterator<Item = &'a [u32]>) -> Option<Fan> {
    // Each face meets v in a wedge p -> v -> s; a neighbouring face across the edge v-s runs
    // s -> v, so its wedge starts at p = s.
    let mut wedges: Vec<(u32, u32)> = Vec::new();
    for face in faces {
        let n = face.len();
        let i = face.iter().position(|&x| x == v)?;
        let wedge = (face[(i + n - 1) % n], face[(i + 1) % n]);
        if wedges.iter().any(|w| w.0 == wedge.0 || w.1 == wedge.1) {
            return None;
        }
        wedges.push(wedge);
    }
    if wedges.is_empty() {
        return Some(Fan {
            faces: 0,
            boundary: None,
        });
    }
    let open_start = wedges
        .iter()
        .position(|w| !wedges.iter().any(|u| u.1 == w.0));
    let start = open_start.unwrap_or(0);
    let mut at = start;
    let mut seen = 1;
    while let Some(next) = wedges.iter().position(|w| w.0 == wedges[at].1) {
        if next == start {
            break;
        }
        at = next;
        seen += 1;
        if seen > wedges.len() {
            return None;
        }
    }
    (seen == wedges.len()).then(|| Fan {
        faces: wedges.len(),
        boundary: open_start.map(|s| (wedges[s].0, wedges[at].1)),
    })
}
