//! Polygon meshes in Wavefront OBJ: reading faces of any number of corners, and writing.
//!
//! One surface per file: every `f` statement indexes the file's one list of `v` statements,
//! whatever `o` and `g` groups say (tobj would split them into separately indexed models
//! and cut the surface along group borders). `vt` and `vn` are kept when they are per
//! vertex, each position always paired with the same one; otherwise that attribute is left
//! out and named in [`ObjPolygons::dropped`]. Colours after a `v` position are kept. Lines,
//! points, materials and smoothing groups are ignored. Errors name the file and line, and
//! [`ObjPolygons::defect_error`] turns a [`Defect`] of the mesh into one naming the face or
//! vertex as the file numbers it (1-based) with its line.

use std::io::Write;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{Defect, PolyMesh};
use crate::error::{Error, Result};

/// A polygon mesh read from an OBJ file, with where its elements came from.
#[derive(Debug, Clone)]
pub struct ObjPolygons {
    /// The polygons, vertices in file order.
    pub mesh: PolyMesh,
    /// The line of each face's `f` statement and of each vertex's `v` statement.
    pub face_lines: Vec<usize>,
    /// The line of each vertex's `v` statement.
    pub vertex_lines: Vec<usize>,
    /// Attributes left out because they were given per face corner, not per vertex.
    pub dropped: Vec<&'static str>,
}

impl ObjPolygons {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<ObjPolygons> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::in_file(path, format!("cannot read the OBJ file: {e}")))?;
        parse(&text).map_err(|(line, message)| Error::at(path, line, 1, message))
    }

    /// The error for a defect of the mesh read from `path`: faces and vertices numbered
    /// from 1 in file order, at the line of the first element named.
    pub fn defect_error(&self, path: &Path, defect: &Defect) -> Error {
        let face = |f: u32| format!("face {} (line {})", f + 1, self.face_lines[f as usize]);
        let vertex = |v: u32| match self.vertex_lines.get(v as usize) {
            Some(line) => format!("vertex {} (line {line})", v + 1),
            None => format!("vertex {}", v as i64 + 1),
        };
        let line = match defect {
            Defect::TooFewVertices { face }
            | Defect::IndexOutOfRange { face, .. }
            | Defect::RepeatedVertex { face, .. } => self.face_lines[*face as usize],
            Defect::Orientation { faces, .. } => self.face_lines[faces[1] as usize],
            Defect::NonManifoldEdge { faces, .. } => self.face_lines[faces[2] as usize],
            Defect::NonFinite { vertex } | Defect::NonManifoldVertex { vertex } => {
                self.vertex_lines[*vertex as usize]
            }
            Defect::AttributeCount { .. } => 0,
        };
        let message = defect.describe(&face, &vertex);
        if line == 0 {
            Error::in_file(path, message)
        } else {
            Error::at(path, line, 1, message)
        }
    }
}

/// Parses OBJ text; an error is its 1-based line and message.
fn parse(text: &str) -> std::result::Result<ObjPolygons, (usize, String)> {
    let mut positions = Vec::new();
    let mut colors = Vec::new();
    let mut uvs = Vec::new();
    let mut normals = Vec::new();
    let mut corners: Vec<Vec<[Option<usize>; 3]>> = Vec::new();
    let mut face_lines = Vec::new();
    let mut vertex_lines = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let mut words = raw.split('#').next().unwrap_or("").split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let numbers =
            |words: std::str::SplitWhitespace| -> std::result::Result<Vec<f32>, (usize, String)> {
                words
                    .map(|w| {
                        w.parse::<f32>()
                            .map_err(|_| (line, format!("`{w}` is not a number")))
                    })
                    .collect()
            };
        match keyword {
            "v" => {
                let n = numbers(words)?;
                if n.len() < 3 {
                    return Err((line, "a vertex needs three coordinates".into()));
                }
                positions.push(Vec3::new(n[0], n[1], n[2]));
                if n.len() >= 6 {
                    colors.push(Vec3::new(n[3], n[4], n[5]));
                }
                vertex_lines.push(line);
            }
            "vt" => {
                let n = numbers(words)?;
                if n.is_empty() {
                    return Err((line, "a texture coordinate needs a value".into()));
                }
                uvs.push(Vec2::new(n[0], n.get(1).copied().unwrap_or(0.0)));
            }
            "vn" => {
                let n = numbers(words)?;
                if n.len() < 3 {
                    return Err((line, "a normal needs three coordinates".into()));
                }
                normals.push(Vec3::new(n[0], n[1], n[2]));
            }
            "f" => {
                let counts = [positions.len(), uvs.len(), normals.len()];
                let face = words
                    .map(|w| corner(w, counts).map_err(|m| (line, m)))
                    .collect::<std::result::Result<Vec<_>, _>>()?;
                corners.push(face);
                face_lines.push(line);
            }
            _ => {}
        }
    }
    if !colors.is_empty() && colors.len() != positions.len() {
        return Err((
            vertex_lines.last().copied().unwrap_or(1),
            "some vertices have colours and some do not".into(),
        ));
    }
    let mut dropped = Vec::new();
    let uvs = per_vertex(
        &corners,
        1,
        &uvs,
        positions.len(),
        "texture coordinates",
        &mut dropped,
    );
    let normals = per_vertex(
        &corners,
        2,
        &normals,
        positions.len(),
        "normals",
        &mut dropped,
    );
    let faces = corners
        .iter()
        .map(|face| face.iter().map(|c| c[0].unwrap_or(0) as u32).collect())
        .collect();
    Ok(ObjPolygons {
        mesh: PolyMesh {
            positions,
            normals,
            uvs,
            colors,
            faces,
        },
        face_lines,
        vertex_lines,
        dropped,
    })
}

/// One face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` as 0-based indices; negative indices
/// count back from the last element read.
fn corner(word: &str, counts: [usize; 3]) -> std::result::Result<[Option<usize>; 3], String> {
    let mut out = [None; 3];
    for (k, part) in word.split('/').enumerate() {
        if k > 2 {
            return Err(format!("`{word}` is not a face corner"));
        }
        if part.is_empty() {
            if k == 0 {
                return Err(format!("`{word}` has no vertex index"));
            }
            continue;
        }
        let i: i64 = part
            .parse()
            .map_err(|_| format!("`{word}` is not a face corner"))?;
        let n = counts[k] as i64;
        let index = if i > 0 { i - 1 } else { n + i };
        if i == 0 || index < 0 || index >= n {
            let what = ["vertex", "texture coordinate", "normal"][k];
            return Err(format!("{what} index {i} is out of range (1 to {n})"));
        }
        out[k] = Some(index as usize);
    }
    Ok(out)
}

/// The attribute `values` of slot `k` of the corners as one per vertex, or nothing (and its
/// name in `dropped`) when some corner lacks it or a vertex is paired with two of them.
fn per_vertex<T: Copy + Default + PartialEq>(
    corners: &[Vec<[Option<usize>; 3]>],
    k: usize,
    values: &[T],
    vertex_count: usize,
    name: &'static str,
    dropped: &mut Vec<&'static str>,
) -> Vec<T> {
    if values.is_empty() {
        return Vec::new();
    }
    let mut paired: Vec<Option<usize>> = vec![None; vertex_count];
    for c in corners.iter().flatten() {
        let (Some(v), Some(a)) = (c[0], c[k]) else {
            dropped.push(name);
            return Vec::new();
        };
        match paired[v] {
            Some(b) if values[b] != values[a] => {
                dropped.push(name);
                return Vec::new();
            }
            _ => paired[v] = Some(a),
        }
    }
    paired
        .iter()
        .map(|a| a.map_or(T::default(), |a| values[a]))
        .collect()
}

/// Writes `mesh` as OBJ text: `v` (with colours if any), `vt`, `vn`, then one `f` per face
/// with as many corners as it has. Floats are written in their shortest exact form, so
/// reading the file back gives the same numbers.
pub fn write_obj(mesh: &PolyMesh, out: &mut impl Write) -> std::io::Result<()> {
    for (i, p) in mesh.positions.iter().enumerate() {
        match mesh.colors.get(i) {
            Some(c) => writeln!(out, "v {} {} {} {} {} {}", p.x, p.y, p.z, c.x, c.y, c.z)?,
            None => writeln!(out, "v {} {} {}", p.x, p.y, p.z)?,
        }
    }
    for t in &mesh.uvs {
        writeln!(out, "vt {} {}", t.x, t.y)?;
    }
    for n in &mesh.normals {
        writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    let (has_uv, has_normal) = (!mesh.uvs.is_empty(), !mesh.normals.is_empty());
    for face in &mesh.faces {
        write!(out, "f")?;
        for &v in face {
            let v = v + 1;
            match (has_uv, has_normal) {
                (false, false) => write!(out, " {v}")?,
                (true, false) => write!(out, " {v}/{v}")?,
                (false, true) => write!(out, " {v}//{v}")?,
                (true, true) => write!(out, " {v}/{v}/{v}")?,
            }
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_groups_and_negative_indices_read_and_write_back() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 1 0.5\n\
                    o a\nf 1/1 2/2 3/3 4/4\ng b\nf -4/-4 5/5 -3/-3 # a triangle\n";
        let obj = parse(text).unwrap();
        assert_eq!(obj.mesh.faces, vec![vec![0, 1, 2, 3], vec![1, 4, 2]]);
        assert_eq!(obj.face_lines, vec![12, 14]);
        assert_eq!(obj.mesh.uvs[4], Vec2::new(1.0, 0.5));
        assert!(obj.dropped.is_empty());
        let mut bytes = Vec::new();
        write_obj(&obj.mesh, &mut bytes).unwrap();
        let back = parse(std::str::from_utf8(&bytes).unwrap()).unwrap();
        assert_eq!(back.mesh, obj.mesh);
    }

    #[test]
    fn per_corner_normals_are_dropped_and_bad_lines_named() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 -1\n\
                    f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n";
        let obj = parse(text).unwrap();
        assert_eq!(obj.dropped, vec!["normals"]);
        assert!(obj.mesh.normals.is_empty());
        assert_eq!(parse("v 0 0 0\nf 1 2 x\n").unwrap_err().0, 2);
        let (line, message) = parse("v 0 0 0\nv 1 1 1\n\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            (line, message.as_str()),
            (4, "vertex index 3 is out of range (1 to 2)")
        );
        assert_eq!(
            parse("v 0 zero 0\n").unwrap_err().1,
            "`zero` is not a number"
        );
    }
}
