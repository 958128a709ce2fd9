//! `flexcam simplify`: an n-gon OBJ in, a coarser OBJ out with its statistics; bad input
//! refused in one line naming the file and element, with no output written.

mod common;

use std::fmt::Write;
use std::fs;

use common::{run, run_json, run_ok};
use tempfile::TempDir;

/// A flat `n` x `n` grid of quads with one hexagon (two cells merged), as OBJ text.
fn grid_obj(n: u32) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            writeln!(s, "v {i} {j} 0").unwrap();
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i + 1;
    writeln!(
        s,
        "f {} {} {} {} {} {}",
        at(0, 0),
        at(1, 0),
        at(2, 0),
        at(2, 1),
        at(1, 1),
        at(0, 1)
    )
    .unwrap();
    for j in 0..n {
        for i in 0..n {
            if j == 0 && i < 2 {
                continue;
            }
            writeln!(
                s,
                "f {} {} {} {}",
                at(i, j),
                at(i + 1, j),
                at(i + 1, j + 1),
                at(i, j + 1)
            )
            .unwrap();
        }
    }
    s
}

#[test]
fn simplifies_an_n_gon_obj_and_reports() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("grid.obj"), grid_obj(10)).unwrap();
    let stats = run_json(
        &dir,
        &[
            "simplify",
            "grid.obj",
            "-o",
            "out/coarse.obj",
            "--faces",
            "20",
            "--stats",
            "-",
        ],
    );
    assert_eq!(stats["faces_in"], 99);
    let faces_out = stats["faces_out"].as_u64().unwrap();
    assert!(faces_out <= 20, "{stats}");
    assert!(stats["splits"].as_u64().unwrap() > 0);
    assert!(stats["simplify_ms"].as_f64().unwrap() >= 0.0);
    let text = fs::read_to_string(dir.path().join("out/coarse.obj")).unwrap();
    let faces = text.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!(faces as u64, faces_out);
    // The output reads back as input, and the same seed gives the same file.
    run_ok(
        &dir,
        &[
            "simplify",
            "out/coarse.obj",
            "-o",
            "again.obj",
            "--ratio",
            "1",
        ],
    );
    run_ok(
        &dir,
        &["simplify", "grid.obj", "-o", "second.obj", "--faces", "20"],
    );
    assert_eq!(
        fs::read(dir.path().join("second.obj")).unwrap(),
        text.as_bytes()
    );
    let help = run_ok(&dir, &["--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("simplify"));
}

#[test]
fn non_manifold_input_is_refused_in_one_line_with_no_output() {
    let dir = TempDir::new().unwrap();
    // A fin: three quads on the edge from vertex 1 to vertex 2.
    let fin = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 1 0 1\nv 1 1 1\n\
               f 1 2 3 4\nf 2 5 6 3\nf 2 3 8 7\n";
    fs::write(dir.path().join("fin.obj"), fin).unwrap();
    let flipped = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 3 5\n";
    fs::write(dir.path().join("flipped.obj"), flipped).unwrap();
    fs::write(dir.path().join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    for (file, expected) in [
        (
            "fin.obj",
            "fin.obj:11:1: the edge from vertex 2 (line 2) to vertex 3 (line 3) is shared by 3 \
             faces (face 1 (line 9), face 2 (line 10), face 3 (line 11)): non-manifold edge",
        ),
        (
            "flipped.obj",
            "flipped.obj:7:1: face 1 (line 6) and face 2 (line 7) both run from vertex 2 \
             (line 2) to vertex 3 (line 3): inconsistent orientation",
        ),
        (
            "bad.obj",
            "bad.obj:2:1: vertex index 2 is out of range (1 to 1)",
        ),
    ] {
        let out = run(
            &dir,
            &["simplify", file, "-o", "out.obj", "--stats", "stats.json"],
        );
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert_eq!(stderr.trim_end(), format!("flexcam: {expected}"));
        assert!(!dir.path().join("out.obj").exists());
        assert!(!dir.path().join("stats.json").exists());
    }
    let out = run(&dir, &["simplify", "missing.obj", "-o", "out.obj"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("flexcam: missing.obj: "));
    let out = run(&dir, &["simplify", "fin.obj", "-o", "fin.obj"]);
    assert!(!out.status.success());
    assert_eq!(fs::read_to_string(dir.path().join("fin.obj")).unwrap(), fin);
}
