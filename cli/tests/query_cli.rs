//! `ktree query` and `ktree raycast` on `.ktree` files (version 2 through the map, version 1 loaded):
//! the answers are the library's, from `.csv`, `.txt`, `.npy` and standard input, as text and JSON; bad
//! tables are one-line errors naming the file and the line or byte.

mod common;

use common::ktree;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use ktree::io::{write_ktree_file, write_ktree_v1};
use ktree::query::RayCast;
use ktree::rays::ball_rays;
use ktree::KTree;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A ball of radius 10 at level 5, written as version 2 and version 1 files.
fn ball(dir: &Path) -> (KTree<3>, std::path::PathBuf, std::path::PathBuf) {
    let tree = KTree::from_rays(&ball_rays::<3>(5, [32, 32, 32], 20).unwrap());
    let v2 = dir.join("ball.ktree");
    let v1 = dir.join("ball1.ktree");
    write_ktree_file(&v2, &tree).unwrap();
    let mut bytes = Vec::new();
    write_ktree_v1(&mut bytes, &tree).unwrap();
    std::fs::write(&v1, bytes).unwrap();
    (tree, v2, v1)
}

const POINTS: [[i64; 3]; 6] = [
    [16, 16, 16],
    [0, 0, 0],
    [31, 16, 16],
    [-4, 16, 16],
    [40, 40, 40],
    [26, 16, 16],
];

/// `.npy` bytes of an `(N, C)` array of little-endian `i8`s (dtype `<i8`) or `f8`s.
fn npy(descr: &str, shape: (usize, usize), data: &[u8]) -> Vec<u8> {
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({}, {}), }}",
        shape.0, shape.1
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// Runs `ktree` with `input` on standard input.
fn ktree_stdin(args: &[&str], input: &str) -> (bool, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ktree"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The JSON the library's answers give, as `ktree query --distance --nearest --json` prints them.
fn expected_points(tree: &KTree<3>) -> serde_json::Value {
    let rows: Vec<serde_json::Value> = POINTS
        .iter()
        .map(|&p| {
            let n = ktree::query::nearest_signed(tree, p).unwrap().unwrap();
            let inside = p.iter().all(|&v| v >= 0) && tree.contains(p.map(|v| v as u32));
            serde_json::json!({
                "point": p.to_vec(),
                "inside": inside,
                "distance": n.distance(),
                "nearest": n.voxel.to_vec(),
            })
        })
        .collect();
    serde_json::Value::Array(rows)
}

#[test]
fn query_answers_as_the_library_from_every_table_form() {
    let dir = tempfile::tempdir().unwrap();
    let (tree, v2, v1) = ball(dir.path());
    let csv = dir.path().join("points.csv");
    let text: String = POINTS
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&csv, format!("# x,y,z\n\n{text}")).unwrap();
    let txt = dir.path().join("points.txt");
    std::fs::write(&txt, text.replace(',', " ")).unwrap();
    let npy_path = dir.path().join("points.npy");
    let data: Vec<u8> = POINTS
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&npy_path, npy("<i8", (POINTS.len(), 3), &data)).unwrap();
    let expect = expected_points(&tree);
    for file in [&v2, &v1] {
        for points in [&csv, &txt, &npy_path] {
            let (ok, out, err) = ktree(&[
                "query",
                s(file),
                "--points",
                s(points),
                "--distance",
                "--nearest",
                "--json",
            ]);
            assert!(ok, "{err}");
            let got: serde_json::Value = serde_json::from_str(&out).unwrap();
            assert_eq!(got, expect, "{} {}", s(file), s(points));
        }
    }
    let (ok, out, err) = ktree_stdin(&["query", s(&v2), "--points", "-"], &text);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), POINTS.len());
    for (line, p) in lines.iter().zip(POINTS) {
        let inside = p.iter().all(|&v| v >= 0) && tree.contains(p.map(|v| v as u32));
        let word = if inside { "inside" } else { "outside" };
        assert_eq!(*line, format!("{} {} {} {word}", p[0], p[1], p[2]));
    }
    // Text with the distance and the nearest voxel.
    let (ok, out, _) = ktree(&[
        "query",
        s(&v2),
        "--points",
        s(&csv),
        "--distance",
        "--nearest",
    ]);
    assert!(ok);
    let n = tree.nearest([0, 0, 0]).unwrap();
    let v = n.voxel;
    assert_eq!(
        out.lines().nth(1).unwrap(),
        format!(
            "0 0 0 outside distance {} nearest {} {} {}",
            n.distance(),
            v[0],
            v[1],
            v[2]
        )
    );
}

#[test]
fn raycast_answers_as_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let (tree, v2, v1) = ball(dir.path());
    let rays: Vec<[f64; 6]> = vec![
        [-5.0, 16.5, 16.5, 1.0, 0.0, 0.0],
        [16.5, 16.5, 40.0, 0.0, 0.0, -1.0],
        [16.5, 16.5, 16.5, 0.3, 0.2, 0.1],
        [0.5, 0.5, 0.5, -1.0, 0.0, 0.0],
        [0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
    ];
    let csv = dir.path().join("rays.csv");
    let text: String = rays
        .iter()
        .map(|r| r.map(|v| v.to_string()).join(",") + "\n")
        .collect();
    std::fs::write(&csv, &text).unwrap();
    let npy_path = dir.path().join("rays.npy");
    let data: Vec<u8> = rays
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&npy_path, npy("<f8", (rays.len(), 6), &data)).unwrap();
    for max_t in [f64::INFINITY, 12.0] {
        let expect: Vec<serde_json::Value> = rays
            .iter()
            .map(|r| {
                let cast = RayCast::new([r[0], r[1], r[2]], [r[3], r[4], r[5]], max_t).unwrap();
                let h = ktree::query::cast_ray(&tree, &cast).unwrap();
                serde_json::json!({
                    "hit": h.is_some(),
                    "voxel": h.map(|h| h.voxel.to_vec()),
                    "t": h.map(|h| h.t),
                    "axis": h.and_then(|h| h.face).map(|f| f.axis),
                    "sign": h.and_then(|h| h.face).map(|f| f.sign),
                })
            })
            .collect();
        assert!(expect[0]["hit"].as_bool().unwrap() && !expect[3]["hit"].as_bool().unwrap());
        let max = max_t.to_string();
        for file in [&v2, &v1] {
            for r in [&csv, &npy_path] {
                let (ok, out, err) = ktree(&[
                    "raycast",
                    s(file),
                    "--rays",
                    s(r),
                    "--max-t",
                    &max,
                    "--json",
                ]);
                assert!(ok, "{err}");
                let got: serde_json::Value = serde_json::from_str(&out).unwrap();
                assert_eq!(got, serde_json::Value::Array(expect.clone()), "{max_t}");
            }
        }
    }
    let (ok, out, err) = ktree_stdin(&["raycast", s(&v2), "--rays", "-"], &text);
    assert!(ok, "{err}");
    let first = tree
        .cast_ray([-5.0, 16.5, 16.5], [1.0, 0.0, 0.0], f64::INFINITY)
        .unwrap()
        .unwrap();
    assert_eq!(
        out.lines().next().unwrap(),
        format!("hit {} 16 16 t {} face -0", first.voxel[0], first.t)
    );
    assert_eq!(out.lines().nth(3).unwrap(), "miss");
}

#[test]
fn bad_tables_and_files_are_one_line_errors_naming_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let (_, v2, _) = ball(dir.path());
    let bad = dir.path().join("bad.csv");
    let one_line = |args: &[&str], needle: &str| {
        let (ok, _, err) = ktree(args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    };
    std::fs::write(&bad, "1,2,3\n4,five,6\n").unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&bad)],
        "bad.csv:2: 'five' is not an integer",
    );
    std::fs::write(&bad, "1,2,3\n\n4,5\n").unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&bad)],
        "bad.csv:3: expected 3 numbers, found 2",
    );
    std::fs::write(&bad, "1.5,2,3\n").unwrap();
    one_line(&["query", s(&v2), "--points", s(&bad)], "bad.csv:1");
    std::fs::write(&bad, "0,0,0,1,nan,0\n").unwrap();
    one_line(
        &["raycast", s(&v2), "--rays", s(&bad)],
        "bad.csv:1: the ray's direction has NaN",
    );
    std::fs::write(&bad, "0,0,0,1,inf,0\n").unwrap();
    one_line(&["raycast", s(&v2), "--rays", s(&bad)], "bad.csv:1");
    std::fs::write(&bad, "0,0,0,1,0,0\n").unwrap();
    one_line(
        &["raycast", s(&v2), "--rays", s(&bad), "--max-t=-1"],
        "--max-t",
    );
    let npy_path = dir.path().join("bad.npy");
    std::fs::write(&npy_path, npy("<f8", (1, 3), &[0; 24])).unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&npy_path)],
        "bad.npy: byte",
    );
    std::fs::write(&npy_path, npy("<i8", (2, 3), &[0; 24])).unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&npy_path)],
        "the data ends after 24 of 48 bytes",
    );
    std::fs::write(&npy_path, npy("<i8", (2, 2), &[0; 32])).unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&npy_path)],
        "2 columns; expected 3",
    );
    std::fs::write(&npy_path, b"not an array").unwrap();
    one_line(
        &["query", s(&v2), "--points", s(&npy_path)],
        "not a .npy file",
    );
    let missing = dir.path().join("missing.csv");
    one_line(&["query", s(&v2), "--points", s(&missing)], "missing.csv");
    let not_tree = dir.path().join("junk.ktree");
    std::fs::write(&not_tree, b"junk").unwrap();
    std::fs::write(&bad, "1,2,3\n").unwrap();
    one_line(&["query", s(&not_tree), "--points", s(&bad)], "junk.ktree");
}
