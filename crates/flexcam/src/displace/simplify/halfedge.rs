//! The half-edge structure of a [`PolyMesh`], built only for meshes the simplifier supports:
//! oriented 2-manifolds, with or without boundary, of arbitrary n-gons.
//!
//! Every face of `n` vertices owns `n` consecutive half-edges, one per side, in face order;
//! the half-edge of side `i` starts at vertex `i` of the face. Each half-edge knows its twin
//! (the same side seen from the neighbouring face) unless it lies on the boundary. Building
//! refuses, naming the element ([`Defect`]): faces of fewer than three vertices or repeating a
//! vertex, indices out of range, non-finite positions, an edge used twice in one direction
//! (inconsistent orientation) or by three or more faces, and a vertex whose faces do not form
//! a single fan (two cones touching at a point).

use std::collections::HashMap;

use super::fan::fan;
use super::PolyMesh;
use crate::error::Error;

/// No half-edge: the twin of a boundary half-edge.
pub const NONE: u32 = u32::MAX;

/// Why a mesh is not a supported manifold, with the offending element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Defect {
    /// A face with fewer than three vertices.
    TooFewVertices {
        /// The face's index.
        face: u32,
    },
    /// A face naming a vertex the mesh does not have.
    IndexOutOfRange {
        /// The face's index.
        face: u32,
        /// The vertex index it names.
        vertex: u32,
    },
    /// A face naming one vertex twice.
    RepeatedVertex {
        /// The face's index.
        face: u32,
        /// The vertex it names twice.
        vertex: u32,
    },
    /// A vertex at infinity or NaN.
    NonFinite {
        /// The vertex's index.
        vertex: u32,
    },
    /// An attribute list neither empty nor one per vertex.
    AttributeCount {
        /// The attribute list (`normals`, `uvs`, `colors`).
        name: &'static str,
        /// Its length.
        len: usize,
    },
    /// Two faces that both run from `from` to `to`: their orientations disagree.
    Orientation {
        /// The edge's first vertex.
        from: u32,
        /// The edge's second vertex.
        to: u32,
        /// The two faces running from `from` to `to`.
        faces: [u32; 2],
    },
    /// An edge shared by three or more faces.
    NonManifoldEdge {
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
        /// Every face using the edge.
        faces: Vec<u32>,
    },
    /// A vertex whose faces do not form one fan (two cones meeting at a point).
    NonManifoldVertex {
        /// The vertex's index.
        vertex: u32,
    },
}

impl Defect {
    /// The message, with faces and vertices named by `face` and `vertex` (a file reader names
    /// them as its file numbers them).
    pub fn describe(&self, face: &dyn Fn(u32) -> String, vertex: &dyn Fn(u32) -> String) -> String {
        match self {
            Defect::TooFewVertices { face: f } => {
                format!("{} has fewer than three vertices", face(*f))
            }
            Defect::IndexOutOfRange { face: f, vertex: v } => {
                format!(
                    "{} refers to {}, which does not exist",
                    face(*f),
                    vertex(*v)
                )
            }
            Defect::RepeatedVertex { face: f, vertex: v } => {
                format!("{} uses {} twice (degenerate face)", face(*f), vertex(*v))
            }
            Defect::NonFinite { vertex: v } => format!("{} has a non-finite position", vertex(*v)),
            Defect::AttributeCount { name, len } => {
                format!("the mesh has {len} {name}, neither none nor one per vertex")
            }
            Defect::Orientation { from, to, faces } => format!(
                "{} and {} both run from {} to {}: inconsistent orientation",
                face(faces[0]),
                face(faces[1]),
                vertex(*from),
                vertex(*to)
            ),
            Defect::NonManifoldEdge { a, b, faces } => format!(
                "the edge from {} to {} is shared by {} faces ({}): non-manifold edge",
                vertex(*a),
                vertex(*b),
                faces.len(),
                faces
                    .iter()
                    .map(|&f| face(f))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Defect::NonManifoldVertex { vertex: v } => format!(
                "the faces around {} do not form one fan: non-manifold vertex",
                vertex(*v)
            ),
        }
    }
}

impl From<Defect> for Error {
    /// The message with 0-based face and vertex indices.
    fn from(defect: Defect) -> Error {
        Error::new(defect.describe(&|f| format!("face {f}"), &|v| format!("vertex {v}")))
    }
}

/// One side of a face, directed as the face runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HalfEdge {
    /// The vertex it starts at.
    pub origin: u32,
    /// The face it belongs to.
    pub face: u32,
    /// The next half-edge around the same face.
    pub next: u32,
    /// The opposite half-edge of the neighbouring face, or [`NONE`] on the boundary.
    pub twin: u32,
}

/// The half-edges of a checked [`PolyMesh`].
#[derive(Debug, Clone)]
pub struct HalfEdgeMesh {
    /// Every half-edge of the mesh; face f's start at `face_start[f]`.
    pub half_edges: Vec<HalfEdge>,
    /// The first half-edge of each face.
    pub face_start: Vec<u32>,
    /// Whether each vertex lies on the boundary (or is used by no face).
    boundary: Vec<bool>,
}

impl HalfEdgeMesh {
    /// Checks `mesh` and builds its half-edges; see the module documentation.
    pub fn build(mesh: &PolyMesh) -> Result<HalfEdgeMesh, Defect> {
        let n = mesh.vertex_count();
        for (name, len) in [
            ("normals", mesh.normals.len()),
            ("texture coordinates", mesh.uvs.len()),
            ("colours", mesh.colors.len()),
        ] {
            if len != 0 && len != n {
                return Err(Defect::AttributeCount { name, len });
            }
        }
        if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(Defect::NonFinite { vertex: v as u32 });
        }
        let mut half_edges: Vec<HalfEdge> = Vec::new();
        let mut face_start = Vec::with_capacity(mesh.face_count());
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            let f = f as u32;
            check_face(f, face, n)?;
            let start = half_edges.len() as u32;
            face_start.push(start);
            for (i, &v) in face.iter().enumerate() {
                let w = face[(i + 1) % face.len()];
                let h = start + i as u32;
                if let Some(&other) = directed.get(&(v, w)) {
                    let g = half_edges[other as usize].face;
                    return Err(edge_defect(mesh, v, w, [g, f]));
                }
                directed.insert((v, w), h);
                half_edges.push(HalfEdge {
                    origin: v,
                    face: f,
                    next: start + ((i + 1) % face.len()) as u32,
                    twin: NONE,
                });
            }
        }
        for h in 0..half_edges.len() {
            let e = half_edges[h];
            let to = half_edges[e.next as usize].origin;
            if let Some(&t) = directed.get(&(to, e.origin)) {
                half_edges[h].twin = t;
            }
        }
        let mut he = HalfEdgeMesh {
            half_edges,
            face_start,
            boundary: vec![true; n],
        };
        he.check_fans(mesh)?;
        Ok(he)
    }

    /// Whether a vertex lies on the boundary (or is used by no face).
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.boundary[v as usize]
    }

    /// Each edge once: the half-edge with the smaller index of each twin pair, and every
    /// boundary half-edge.
    pub fn edges(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.half_edges.len() as u32).filter(|&h| {
            let t = self.half_edges[h as usize].twin;
            t == NONE || h < t
        })
    }

    /// Checks that the faces around every vertex form one fan, and records which vertices
    /// lie on the boundary.
    fn check_fans(&mut self, mesh: &PolyMesh) -> Result<(), Defect> {
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertex_count()];
        for (f, face) in mesh.faces.iter().enumerate() {
            for &v in face {
                around[v as usize].push(f as u32);
            }
        }
        for (v, faces) in around.iter().enumerate() {
            let faces = faces.iter().map(|&f| mesh.faces[f as usize].as_slice());
            match fan(v as u32, faces) {
                Some(fan) => self.boundary[v] = fan.faces == 0 || fan.boundary.is_some(),
                None => return Err(Defect::NonManifoldVertex { vertex: v as u32 }),
            }
        }
        Ok(())
    }
}

/// Face-local checks: size, index range, repeated vertices.
fn check_face(f: u32, face: &[u32], n: usize) -> Result<(), Defect> {
    if face.len() < 3 {
        return Err(Defect::TooFewVertices { face: f });
    }
    if let Some(&v) = face.iter().find(|&&v| v as usize >= n) {
        return Err(Defect::IndexOutOfRange { face: f, vertex: v });
    }
    for (i, &v) in face.iter().enumerate() {
        if face[..i].contains(&v) {
            return Err(Defect::RepeatedVertex { face: f, vertex: v });
        }
    }
    Ok(())
}

/// The defect of an edge `v -> w` found twice: a non-manifold edge if three or more faces
/// use it in either direction, otherwise inconsistent orientation of the two `faces`.
fn edge_defect(mesh: &PolyMesh, v: u32, w: u32, faces: [u32; 2]) -> Defect {
    let users: Vec<u32> = (0..mesh.faces.len() as u32)
        .filter(|&f| has_edge(&mesh.faces[f as usize], v, w))
        .collect();
    if users.len() >= 3 {
        Defect::NonManifoldEdge {
            a: v,
            b: w,
            faces: users,
        }
    } else {
        Defect::Orientation {
            from: v,
            to: w,
            faces,
        }
    }
}

/// Whether `v` and `w` are consecutive in `face`, in either order.
pub fn has_edge(face: &[u32], v: u32, w: u32) -> bool {
    let n = face.len();
    (0..n).any(|i| {
        let (a, b) = (face[i], face[(i + 1) % n]);
        (a, b) == (v, w) || (a, b) == (w, v)
    })
}
