//! Line checks of OBJ and MTL text that tobj does not make: it drops a face's texture
//! coordinate or normal reference when the file has none of that kind (so `f 1/1 2/2 3/3`
//! in a file without `vt` loads without texture coordinates), and it reads `nan` and
//! negative colours as they are. All are errors here, at their line.

use std::path::Path;

use super::read_file;
use crate::error::{Error, Result};

/// Checks the OBJ file at `path` (`check_finite_numbers`, `check_face_references`)
/// for a reader other than the model loader (trilinear surfaces), so that its errors carry
/// the OBJ's line too.
pub fn check_obj_file(path: &Path) -> Result<()> {
    let text = read_file(path)?;
    check_finite_numbers(path, &text)?;
    check_face_references(path, &text)
}

/// Fails at the first `v`, `vn`, `vt` or `vp` line with a number that is not finite in
/// single precision (`nan`, `inf`, `1e39`), which tobj reads as it is.
pub(super) fn check_finite_numbers(path: &Path, text: &[u8]) -> Result<()> {
    for (number, line) in text.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        let Some(keyword @ ("v" | "vn" | "vt" | "vp")) = words.next() else {
            continue;
        };
        if let Some(word) = words.find(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite())) {
            return Err(Error::at(
                path,
                number + 1,
                1,
                format!("`{keyword}` value {word} is not a finite number"),
            ));
        }
    }
    Ok(())
}

/// Fails at the first face vertex whose texture coordinate or normal index names none of
/// the file's `vt` / `vn` lines (positive indices count from the file's start, negative
/// ones back from the face, as OBJ defines them). Position indices are tobj's to check.
pub(super) fn check_face_references(path: &Path, text: &[u8]) -> Result<()> {
    let lines = || text.split(|&b| b == b'\n').map(String::from_utf8_lossy);
    let count = |keyword: &str| {
        lines()
            .filter(|l| l.split_whitespace().next() == Some(keyword))
            .count()
    };
    let totals = [count("vt"), count("vn")];
    let mut seen = [0usize; 2];
    for (number, line) in lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vt") => seen[0] += 1,
            Some("vn") => seen[1] += 1,
            Some("f") => {
                for vertex in words {
                    for (kind, field) in vertex.split('/').skip(1).take(2).enumerate() {
                        let Ok(index) = field.parse::<i64>() else {
                            continue;
                        };
                        let valid = if index < 0 {
                            index.unsigned_abs() <= seen[kind] as u64
                        } else {
                            (1..=totals[kind] as i64).contains(&index)
                        };
                        if !valid {
                            let (what, keyword) =
                                [("texture coordinate", "vt"), ("normal", "vn")][kind];
                            return Err(Error::at(
                                path,
                                number + 1,
                                1,
                                format!(
                                    "face vertex `{vertex}` refers to {what} {index}, but the \
                                     file has {} `{keyword}` line(s)",
                                    totals[kind]
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// MTL statements whose numbers are colours (each component finite and not negative) or
/// other quantities that must be finite.
const COLOR_KEYWORDS: [&str; 5] = ["Ka", "Kd", "Ks", "Ke", "Tf"];
const FINITE_KEYWORDS: [&str; 4] = ["Ns", "Ni", "d", "Tr"];

/// Fails at the first MTL colour with fewer than three values (tobj unwraps three) or a
/// component that is not a finite number of at least zero, or the first `Ns`, `Ni`, `d` or
/// `Tr` that is not finite.
pub(super) fn check_mtl_values(path: &Path, text: &[u8]) -> Result<()> {
    for (number, line) in text.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let color = COLOR_KEYWORDS.contains(&keyword);
        if !color && !FINITE_KEYWORDS.contains(&keyword) {
            continue;
        }
        let values = line.split_whitespace().count() - 1;
        if matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke") && values < 3 {
            return Err(Error::at(
                path,
                number + 1,
                1,
                format!("`{keyword}` needs three values (r g b), not {values}"),
            ));
        }
        for word in words {
            let Ok(x) = word.parse::<f32>() else {
                continue;
            };
            let problem = if !x.is_finite() {
                "is not a finite number"
            } else if color && x < 0.0 {
                "is negative (colours are at least 0)"
            } else {
                continue;
            };
            return Err(Error::at(
                path,
                number + 1,
                1,
                format!("`{keyword}` value {word} {problem}"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face_error(text: &str) -> Option<String> {
        check_face_references(Path::new("m.obj"), text.as_bytes())
            .err()
            .map(|e| e.to_string())
    }

    fn mtl_error(text: &str) -> Option<String> {
        check_mtl_values(Path::new("m.mtl"), text.as_bytes())
            .err()
            .map(|e| e.to_string())
    }

    #[test]
    fn faces_must_refer_to_existing_texture_coordinates_and_normals() {
        let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert_eq!(face_error(&format!("{v}f 1 2 3\nf 1// 2// 3//\n")), None);
        assert_eq!(face_error(&format!("{v}vt 0 0\nf 1/1 2/1 3/-1\n")), None);
        assert_eq!(
            face_error(&format!("{v}f 1/1 2/2 3/3\n")).as_deref(),
            Some(
                "m.obj:4:1: face vertex `1/1` refers to texture coordinate 1, but the file \
                 has 0 `vt` line(s)"
            )
        );
        let e = face_error(&format!("{v}vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/2 3/1/1\n")).unwrap();
        assert!(e.starts_with("m.obj:6:1:") && e.contains("normal 2"), "{e}");
        let e = face_error(&format!("{v}f 1/-1 2/-1 3/-1\nvt 0 0\n")).unwrap();
        assert!(e.starts_with("m.obj:4:1:"), "{e}");
    }

    #[test]
    fn vertex_numbers_must_be_finite() {
        let check = |text: &str| {
            check_finite_numbers(Path::new("m.obj"), text.as_bytes())
                .err()
                .map(|e| e.to_string())
        };
        assert_eq!(
            check("v 0 0 0\nvn 0 0 1\nvt 0.5 0.5\nf 1/1/1 1/1/1 1/1/1\n"),
            None
        );
        assert_eq!(
            check("v 0 0 0\nvn 0 nan 1\n").as_deref(),
            Some("m.obj:2:1: `vn` value nan is not a finite number")
        );
        assert!(check("v 0 0 1e39\n")
            .unwrap()
            .starts_with("m.obj:1:1: `v` value 1e39"));
    }

    #[test]
    fn mtl_colours_must_be_finite_and_not_negative() {
        assert_eq!(mtl_error("newmtl a\nKd 0.5 0.5 0.5\nNs 10\n"), None);
        assert_eq!(
            mtl_error("newmtl a\nKd 0.5 nan 0.5\n").as_deref(),
            Some("m.mtl:2:1: `Kd` value nan is not a finite number")
        );
        let e = mtl_error("newmtl a\nKa 0 0 0\nKs -1 0 0\n").unwrap();
        assert!(e.starts_with("m.mtl:3:1: `Ks` value -1 is negative"), "{e}");
        assert_eq!(
            mtl_error("newmtl a\nKd 0.8 0.1\n").as_deref(),
            Some("m.mtl:2:1: `Kd` needs three values (r g b), not 2")
        );
        let e = mtl_error("newmtl a\nNi inf\n").unwrap();
        assert!(e.starts_with("m.mtl:2:1:"), "{e}");
    }
}
