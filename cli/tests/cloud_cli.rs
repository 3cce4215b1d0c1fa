//! `ktree voxelize CLOUD --voxel-size S …` from the outside: the tree written holds the voxels that numpy's
//! `floor((p − origin) / s)` gives with at least `--min-points` points (brute force here), for a PLY without
//! faces, a PCD, an XYZ and a CSV; points outside a given level fail or are cropped; bad files are one-line
//! errors naming the file and line.

mod common;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use common::ktree;
use ktree::io::read_ktree_file;
use ktree::{AnyTree, KTree, Universe};

/// Points on a helix, on a grid of 1/64 (exact in every text format).
fn helix() -> Vec<[f64; 3]> {
    (0..400)
        .map(|i| {
            let t = f64::from(i) * 0.21;
            [t.cos() * 3.0 + 1.0, t.sin() * 3.0 - 2.0, t * 0.05].map(|c| (c * 64.0).round() / 64.0)
        })
        .collect()
}

/// The tree of the voxels with at least `min` points, by brute force; voxel `floor((p − origin) / s)`.
fn reference(points: &[[f64; 3]], s: f64, origin: [f64; 3], min: u64, level: u32) -> KTree<3> {
    let mut counts = BTreeMap::new();
    for p in points {
        let k: [i64; 3] = std::array::from_fn(|a| ((p[a] - origin[a]) / s).floor() as i64);
        *counts.entry(k).or_insert(0u64) += 1;
    }
    let u = Universe::<3>::new(level).unwrap();
    let cells: Vec<_> = counts
        .iter()
        .filter(|(k, &c)| c >= min && k.iter().all(|&v| v >= 0 && v < 1 << level))
        .map(|(k, _)| u.cell(k.map(|v| v as u32), level).unwrap())
        .collect();
    KTree::from_cells(u, &cells).unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn files(dir: &Path, points: &[[f64; 3]]) -> Vec<String> {
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        points.len()
    );
    let mut pcd = format!(
        "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA ascii\n",
        n = points.len()
    );
    let mut xyz = String::new();
    let mut csv = String::from("X;Y;Z\n");
    for p in points {
        writeln!(ply, "{} {} {}", p[0], p[1], p[2]).unwrap();
        writeln!(pcd, "{} {} {}", p[0], p[1], p[2]).unwrap();
        writeln!(xyz, "{} {} {} 1 2 3", p[0], p[1], p[2]).unwrap();
        writeln!(csv, "{};{};{}", p[0], p[1], p[2]).unwrap();
    }
    vec![
        write(dir, "c.ply", &ply),
        write(dir, "c.pcd", &pcd),
        write(dir, "c.xyz", &xyz),
        write(dir, "c.csv", &csv),
    ]
}

fn tree(path: &Path) -> KTree<3> {
    match read_ktree_file(path).unwrap() {
        AnyTree::K3(t) => t,
        _ => panic!("not an octree"),
    }
}

#[test]
fn clouds_voxelize_to_the_floored_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let points = helix();
    let lo = points.iter().fold([f64::INFINITY; 3], |m, p| {
        std::array::from_fn(|a| m[a].min(p[a]))
    });
    let out = dir.path().join("o.ktree");
    let o = out.to_str().unwrap();
    for f in files(dir.path(), &points) {
        // Default origin and level.
        let (ok, stdout, err) = ktree(&[
            "voxelize",
            &f,
            "--voxel-size",
            "0.25",
            "--min-points",
            "2",
            "--out",
            o,
        ]);
        assert!(ok, "{f}: {err}");
        assert!(
            stdout.contains("(the minimum corner of the points)"),
            "{stdout}"
        );
        let got = tree(&out);
        assert_eq!(got, reference(&points, 0.25, lo, 2, got.level()), "{f}");
        // A given origin and level, every point inside.
        let (ok, _, err) = ktree(&[
            "voxelize",
            &f,
            "--voxel-size",
            "0.5",
            "--origin=-3,-6,-1",
            "--level",
            "5",
            "--out",
            o,
        ]);
        assert!(ok, "{f}: {err}");
        assert_eq!(
            tree(&out),
            reference(&points, 0.5, [-3.0, -6.0, -1.0], 1, 5)
        );
        // Points outside the universe: an error naming how many, or dropped with --crop.
        let args = [
            "voxelize",
            &f,
            "--voxel-size",
            "0.5",
            "--origin",
            "0,0,0",
            "--level",
            "3",
            "--out",
            o,
        ];
        let (ok, _, err) = ktree(&args);
        assert!(!ok);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.contains("points lie outside the universe of level 3"),
            "{err}"
        );
        let (ok, stdout, err) = ktree(&[&args[..], &["--crop"]].concat());
        assert!(ok, "{err}");
        assert!(
            stdout.contains("points outside the universe dropped"),
            "{stdout}"
        );
        assert_eq!(tree(&out), reference(&points, 0.5, [0.0; 3], 1, 3));
    }
}

#[test]
fn bad_clouds_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.ktree");
    let o = out.to_str().unwrap();
    let bad = write(dir.path(), "bad.xyz", "1 2 3\n4 5\n");
    let good = write(dir.path(), "good.xyz", "1 2 3\n");
    for (args, want) in [
        (
            vec!["voxelize", &bad, "--voxel-size", "1", "--out", o],
            "bad.xyz:2: expected 3 numbers",
        ),
        (vec!["voxelize", &good, "--out", o], "needs --voxel-size"),
        (
            vec!["voxelize", &good, "--voxel-size", "0", "--out", o],
            "voxel size",
        ),
        (
            vec![
                "voxelize",
                &good,
                "--voxel-size",
                "1",
                "--origin",
                "1,2",
                "--out",
                o,
            ],
            "--origin",
        ),
        (
            vec!["voxelize", &good, "--voxel-size", "1", "--crop", "--out", o],
            "--crop needs --level",
        ),
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{err} (wanted {want})");
    }
    // A PLY with faces is still a mesh.
    let mesh = write(
        dir.path(),
        "m.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    );
    let (ok, _, err) = ktree(&["voxelize", &mesh, "--voxel-size", "1", "--out", o]);
    assert!(!ok && err.contains("are for point clouds"), "{err}");
    let (ok, _, err) = ktree(&["voxelize", &mesh, "--level", "3", "--fit", "--out", o]);
    assert!(ok, "{err}");
}

/// A `.ply` whose header is broken is neither a cloud nor a mesh: the header's fault is said, naming the
/// file once and the line (it was reported as a cloud needing --voxel-size); a mesh's error names the file
/// once; points outside the universe get the command's hint.
#[test]
fn broken_files_are_said_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.ktree");
    let o = out.to_str().unwrap();
    let broken = write(
        dir.path(),
        "broken.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
    );
    let bad_index = write(
        dir.path(),
        "bad.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5.5\n",
    );
    let good = write(dir.path(), "good.xyz", "1 2 3\n9 2 3\n");
    for (args, want) in [
        (
            vec!["voxelize", &broken, "--level", "3", "--fit", "--out", o],
            format!("ktree: {broken}:5: unexpected PLY header line 'property float'"),
        ),
        (
            vec!["voxelize", &broken, "--voxel-size", "1", "--out", o],
            format!("ktree: {broken}:5: unexpected PLY header line 'property float'"),
        ),
        (
            vec!["voxelize", &bad_index, "--level", "3", "--fit", "--out", o],
            format!("ktree: {bad_index}:13: PLY face 0: '5.5' is not a vertex index"),
        ),
        (
            vec!["voxelize", &good, "--voxel-size", "1", "--origin", "0,0,0", "--level", "2", "--out", o],
            format!("ktree: {good}: 1 points lie outside the universe of level 2 (side 4 voxels); the first is point 1 [9.0, 2.0, 3.0] in voxel [9.0, 2.0, 3.0]: use a larger --level or --voxel-size, another --origin, or --crop to drop them"),
        ),
        (
            vec!["voxelize", &good, "--voxel-size", "1", "--origin", "2,0,0", "--out", o],
            format!("ktree: {good}: point 0 [1.0, 2.0, 3.0] lies below the origin [2.0, 0.0, 0.0] along axis 0: give --level and --crop to drop such points, or another --origin"),
        ),
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?}");
        assert_eq!(err.trim(), want);
    }
}

/// LAZ whose point count was raised by one: refused in one line naming the file and the byte, within a
/// small address space (it once asked for 3.7 GB and aborted); PCL's `binary_compressed` PCD voxelizes as
/// PCL's own conversion of it to `binary`.
#[test]
fn real_clouds_read_or_are_refused_with_bounded_memory() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/clouds");
    let dir = tempfile::tempdir().unwrap();
    let mut copc = std::fs::read(data.join("simple.copc.laz")).unwrap();
    copc[107..111].copy_from_slice(&1066u32.to_le_bytes());
    copc[247..255].copy_from_slice(&1066u64.to_le_bytes());
    let bad = dir.path().join("bad.laz");
    std::fs::write(&bad, &copc).unwrap();
    let out = dir.path().join("o.ktree");
    let command = format!(
        "ulimit -v 1000000; exec {} voxelize {} --voxel-size 0.5 --out {}",
        env!("CARGO_BIN_EXE_ktree"),
        bad.display(),
        out.display()
    );
    let run = std::process::Command::new("sh")
        .arg("-c")
        .arg(&command)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.trim().starts_with(&format!(
            "ktree: {}: byte 107: LAZ: the header declares 1066 points, but the chunk table",
            bad.display()
        )),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let mut trees = Vec::new();
    for name in [
        "pcl_brisk_keypoints_gt.pcd",
        "pcl_brisk_keypoints_gt_binary.pcd",
    ] {
        let input = data.join(name);
        let (ok, stdout, err) = ktree(&[
            "voxelize",
            input.to_str().unwrap(),
            "--voxel-size",
            "0.01",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        assert!(stdout.contains(": 1860 points, "), "{stdout}");
        trees.push(tree(&out));
    }
    assert_eq!(trees[0], trees[1]);
}

/// A closed mesh whose every face has its own vertices is not warned about.
#[test]
fn closed_meshes_with_repeated_vertices_give_no_warning() {
    let dir = tempfile::tempdir().unwrap();
    // A cube [0, 1]³ with four vertices a face, as PLY exporters write it for per-face attributes.
    let faces = [
        [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]],
        [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
        [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]],
        [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]],
        [[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0]],
        [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]],
    ];
    let mut ply = String::from("ply\nformat ascii 1.0\nelement vertex 24\nproperty float x\nproperty float y\nproperty float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n");
    for f in &faces {
        for v in f {
            ply += &format!("{} {} {}\n", v[0], v[1], v[2]);
        }
    }
    for i in 0..6 {
        ply += &format!("4 {} {} {} {}\n", 4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3);
    }
    let cube = write(dir.path(), "cube.ply", &ply);
    let out = dir.path().join("o.ktree");
    let (ok, _, err) = ktree(&[
        "voxelize",
        &cube,
        "--level",
        "4",
        "--fit",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(!err.contains("not closed"), "{err}");
    assert_eq!(tree(&out).voxel_count(), 14 * 14 * 14);
}

/// The README's example as written, `--origin -1,-1,0` with a space: a vector beginning with a minus is the
/// flag's value, not another flag.
#[test]
fn a_negative_origin_is_taken_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let points = helix();
    let out = dir.path().join("o.ktree");
    let o = out.to_str().unwrap();
    let f = &files(dir.path(), &points)[1];
    let (ok, stdout, err) = ktree(&[
        "voxelize",
        f,
        "--voxel-size",
        "0.05",
        "--origin",
        "-3,-6,-1",
        "--out",
        o,
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("origin -3,-6,-1,"), "{stdout}");
    let got = tree(&out);
    assert_eq!(
        got,
        reference(&points, 0.05, [-3.0, -6.0, -1.0], 1, got.level())
    );
    // A vector that is not three numbers is still refused, naming the flag.
    for bad in ["-1,-1", "-1,a,0"] {
        let (ok, _, err) = ktree(&[
            "voxelize",
            f,
            "--voxel-size",
            "0.05",
            "--origin",
            bad,
            "--out",
            o,
        ]);
        assert!(!ok, "{bad}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.starts_with("ktree: ") && err.contains("--origin"),
            "{err}"
        );
    }
}
