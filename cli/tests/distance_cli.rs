//! `ktree distance`: the narrow band written as an OpenVDB level set, checked against OpenVDB itself —
//! Debian's `pyopenvdb` reads it as a `FloatGrid` of class level set with the band's values, and OpenVDB's
//! `tools::sdfInteriorMask` (C++, `vdb_level_set_check.cpp` here built against `libopenvdb-dev`) gives back
//! the tree's voxels — and level sets read back: ktree's own, and OpenVDB's (written by `pyopenvdb` and
//! rewritten by the C++ check with each compression) as their interior. A test whose tool is missing (Debian's
//! `python3-openvdb`, or `g++` and `libopenvdb-dev`) prints a visible `SKIPPED:` line and passes, or fails
//! under `KTREE_REQUIRE_TOOLS=1`, as `.ci/run` sets it (`common::tools`).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use common::{ktree, run_openvdb, tools};
use ktree::io::{write_tree, WriteOptions};
use ktree::rays::ball_rays;
use ktree::{AnyTree, KTree, Ray, RaySet};

/// Octrees with a surface: a ball, a ball with a box cut out touching the universe's border, two voxels.
fn objects() -> Vec<(&'static str, KTree<3>)> {
    let ball = KTree::from_rays(&ball_rays::<3>(5, [32, 30, 34], 22).unwrap());
    let slab: Vec<Ray<3>> = (0..32u32)
        .flat_map(|x| (20..32u32).map(move |y| Ray::new([x, y, 0], 9)))
        .collect();
    let slab = KTree::from_rays(&RaySet::from_rays(5, slab).unwrap());
    let dots = KTree::from_rays(
        &RaySet::from_rays(4, [Ray::new([1, 2, 3], 4), Ray::new([9, 9, 9], 10)]).unwrap(),
    );
    vec![("ball", ball), ("slab", slab), ("dots", dots)]
}

fn write(dir: &Path, name: &str, tree: &KTree<3>) -> String {
    let path = dir.join(format!("{name}.ktree"));
    write_tree(&path, &AnyTree::K3(tree.clone()), &WriteOptions::default()).unwrap();
    path.display().to_string()
}

#[test]
fn pyopenvdb_reads_the_level_set_with_the_band_values() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for (name, tree) in objects() {
        let (band, size) = (2.5, 0.25);
        let src = write(dir.path(), name, &tree);
        let out = dir.path().join(format!("{name}.vdb"));
        let (ok, _, err) = ktree(&[
            "distance",
            &src,
            "--band",
            &band.to_string(),
            "--out",
            &out.display().to_string(),
            "--voxel-size",
            &size.to_string(),
        ]);
        assert!(ok, "{err}");
        // Sampled voxels: every 3rd along each axis, plus every band voxel.
        let side = tree.universe().side() as u32;
        let mut points: Vec<[u32; 3]> = Vec::new();
        for x in (0..side).step_by(3) {
            for y in (0..side).step_by(3) {
                for z in (0..side).step_by(3) {
                    points.push([x, y, z]);
                }
            }
        }
        let nb = tree.narrow_band(band).unwrap();
        points.extend(nb.voxels.iter().copied());
        let list: Vec<String> = points
            .iter()
            .map(|p| format!("({},{},{})", p[0], p[1], p[2]))
            .collect();
        let script = format!(
            "g = vdb.read({:?}, 'ktree')\na = g.getConstAccessor()\n\
             print(type(g).__name__, g.gridClass, g.background, g.activeVoxelCount(), g.transform.voxelSize()[0])\n\
             for p in [{}]:\n    print(repr(a.getValue(p)), int(a.isValueOn(p)))",
            out.display().to_string(),
            list.join(",")
        );
        let text = run_openvdb(&python, &script);
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
        assert_eq!(head[0], "FloatGrid");
        assert_eq!(head[1..3], ["level", "set"], "{name}");
        assert_eq!(head[3].parse::<f64>().unwrap(), band * size);
        assert_eq!(head[4].parse::<usize>().unwrap(), nb.len(), "{name}");
        assert_eq!(head[5].parse::<f64>().unwrap(), size);
        let sd = tree.signed_distance_at(&points).unwrap();
        for (p, (line, d)) in points.iter().zip(lines.zip(sd)) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let value: f64 = w[0].parse().unwrap();
            let on = w[1] == "1";
            assert_eq!(on, d.abs() <= band, "{name} {p:?}");
            let want = if on {
                (d * size) as f32
            } else {
                (band * size).copysign(d) as f32
            };
            assert_eq!(value as f32, want, "{name} {p:?}");
        }
    }
}

/// Builds `vdb_level_set_check` against the installed OpenVDB into `dir`; `None` after [`tools::missing`]
/// without `g++` or OpenVDB's headers. Built once a test run: the tests running side by side share the
/// program.
///
/// # Panics
/// If it does not build with both there.
fn level_set_check(dir: &Path) -> Option<PathBuf> {
    static BUILT: OnceLock<Option<PathBuf>> = OnceLock::new();
    BUILT
        .get_or_init(|| {
            let src = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("tests/interop/vdb_level_set_check.cpp");
            tools::build_openvdb_program(dir, &src)
        })
        .clone()
}

#[test]
fn openvdb_takes_the_inside_of_the_level_set_as_the_trees_voxels() {
    let dir = tempfile::tempdir().unwrap();
    // The build goes to the target dir, kept between runs as the tests' other tools are.
    let build_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let Some(check) = level_set_check(&build_dir) else {
        return;
    };
    for (name, tree) in objects() {
        let src = write(dir.path(), name, &tree);
        let out = dir.path().join(format!("{name}.vdb"));
        let (ok, _, err) = ktree(&[
            "distance",
            &src,
            "--band",
            "3",
            "--out",
            &out.display().to_string(),
        ]);
        assert!(ok, "{err}");
        let run = Command::new(&check).arg(&out).output().unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = String::from_utf8(run.stdout).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("class level set"));
        assert_eq!(lines.next(), Some("background 3"));
        let active: usize = lines.next().unwrap()["active ".len()..].parse().unwrap();
        assert_eq!(active, tree.narrow_band(3.0).unwrap().len(), "{name}");
        let interior: u128 = lines.next().unwrap()["interior ".len()..].parse().unwrap();
        assert_eq!(interior, tree.voxel_count(), "{name}");
        let mut voxels: Vec<[u32; 3]> = lines
            .map(|l| {
                let c: Vec<u32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [c[0], c[1], c[2]]
            })
            .collect();
        voxels.sort();
        let mut want: Vec<[u32; 3]> = Vec::new();
        tree.for_each_leaf(|c, s| {
            if s == ktree::NodeState::Full {
                let o = c.origin();
                let n = c.side() as u32;
                for x in 0..n {
                    for y in 0..n {
                        for z in 0..n {
                            want.push([o[0] + x, o[1] + y, o[2] + z]);
                        }
                    }
                }
            }
        });
        want.sort();
        assert_eq!(voxels, want, "{name}");
    }
}

#[test]
fn bad_arguments_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let src = write(dir.path(), "ball", &objects()[0].1);
    let out = dir.path().join("x.vdb").display().to_string();
    for args in [
        vec!["distance", &src, "--band", "0.5", "--out", &out],
        vec!["distance", &src, "--voxel-size", "0", "--out", &out],
        vec!["distance", &src, "--out", "x.ktree"],
        vec!["distance", "missing.ktree", "--out", &out],
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok && err.trim().lines().count() == 1, "{args:?}: {err}");
    }
    assert!(!Path::new(&out).exists());
}

/// The voxels of a tree, sorted.
fn voxels_of(tree: &KTree<3>) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    tree.for_each_leaf(|c, s| {
        if s == ktree::NodeState::Full {
            let o = c.origin().map(i64::from);
            let n = c.side() as i64;
            for x in 0..n {
                for y in 0..n {
                    for z in 0..n {
                        out.push([o[0] + x, o[1] + y, o[2] + z]);
                    }
                }
            }
        }
    });
    out.sort();
    out
}

#[test]
fn a_level_set_written_by_ktree_converts_back_to_the_same_tree() {
    let dir = tempfile::tempdir().unwrap();
    for (name, tree) in objects() {
        let src = write(dir.path(), name, &tree);
        let sdf = dir.path().join(format!("{name}.vdb")).display().to_string();
        let back = dir.path().join(format!("{name}_back.ktree"));
        let (ok, _, err) = ktree(&["distance", &src, "--band", "3", "--out", &sdf]);
        assert!(ok, "{err}");
        let (ok, _, err) = ktree(&["convert", &sdf, &back.display().to_string()]);
        assert!(ok, "{err}");
        assert_eq!(KTree::<3>::load(&back).unwrap(), tree, "{name}");
        // Every command reading a .vdb takes it: the same statistics as the tree's own file.
        let (ok, from_vdb, err) = ktree(&["stats", &sdf, "--json"]);
        assert!(ok, "{err}");
        let (_, from_ktree, _) = ktree(&["stats", &src, "--json"]);
        assert_eq!(from_vdb, from_ktree, "{name}");
    }
    // A FloatGrid of another class than level set is read as its active voxels: the band.
    let ball = objects().into_iter().find(|(n, _)| *n == "ball").unwrap().1;
    let band = ball.narrow_band(3.0).unwrap().len();
    let fog = dir.path().join("fog.vdb");
    let mut bytes = std::fs::read(dir.path().join("ball.vdb")).unwrap();
    let at = bytes
        .windows(9)
        .position(|w| w == b"level set")
        .expect("the class");
    bytes.splice(at..at + 9, *b"fog  vol ");
    std::fs::write(&fog, bytes).unwrap();
    let (ok, out, err) = ktree(&["stats", &fog.display().to_string()]);
    assert!(ok, "{err}");
    assert!(out.contains(&format!("voxels   {band}\n")), "{out}");
}

/// Reads a `.vdb` with ktree (`ktree convert` at offset 16 in a level-6 universe): its voxels in OpenVDB's
/// indices.
fn ktree_voxels(vdb: &Path) -> Vec<[i64; 3]> {
    let out = vdb.with_extension("ktree");
    let (ok, _, err) = ktree(&[
        "convert",
        &vdb.display().to_string(),
        &out.display().to_string(),
        "--offset",
        "16,16,16",
        "--level",
        "6",
    ]);
    assert!(ok, "{}: {err}", vdb.display());
    voxels_of(&KTree::<3>::load(&out).unwrap())
        .into_iter()
        .map(|v| v.map(|c| c - 16))
        .collect()
}

/// The voxels a C++ check prints after its four report lines.
fn check_voxels(report: &str) -> Vec<[i64; 3]> {
    let mut v: Vec<[i64; 3]> = report
        .lines()
        .skip(4)
        .map(|l| {
            let c: Vec<i64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    v.sort();
    v
}

#[test]
fn level_sets_written_by_openvdb_read_as_their_interior() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // Two boxes of known voxels (faces halfway between voxel centres, far enough apart for their bands not
    // to meet: OpenVDB then signs a few voxels between them as inside) and a sphere, as pyopenvdb makes
    // them and writes them: Blosc and active-mask compression, and half floats.
    let boxes = [([0i64, 0, 0], [4i64, 3, 2]), ([-13, 2, -12], [-10, 5, -9])];
    let mut known: Vec<[i64; 3]> = Vec::new();
    for (lo, hi) in boxes {
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    known.push([x, y, z]);
                }
            }
        }
    }
    known.sort();
    let box_list: Vec<String> = boxes
        .iter()
        .map(|(lo, hi)| format!("({lo:?}, {hi:?})"))
        .collect();
    let d = |n: &str| dir.path().join(n);
    let script = format!(
        r#"
import numpy as np
points, quads = [], []
for lo, hi in [{boxes}]:
    b = len(points)
    for i in range(8):
        points.append([(hi if i >> a & 1 else lo)[a] + (0.5 if i >> a & 1 else -0.5) for a in range(3)])
    quads += [[b + q for q in f] for f in [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]]
grids = {{
    "boxes": vdb.FloatGrid.createLevelSetFromPolygons(np.array(points, dtype=np.float32), quads=np.array(quads, dtype=np.int32), halfWidth=3.0),
    "sphere": vdb.createLevelSetSphere(radius=6.3, center=(1.5, -2.0, 3.0), voxelSize=1.0, halfWidth=3.0),
}}
for name, g in grids.items():
    for half in [False, True]:
        g.name = name
        g.saveFloatAsHalf = half
        path = {dir:?} + "/" + name + ("_half" if half else "") + ".vdb"
        vdb.write(path, grids=[g])
        # The voxels below zero, active or not, by OpenVDB's accessor over the leaves' box.
        g = vdb.read(path, name)
        a = g.getConstAccessor()
        (x0, y0, z0), (x1, y1, z1) = g.evalLeafBoundingBox()
        inside = [(x, y, z) for x in range(x0, x1 + 1) for y in range(y0, y1 + 1) for z in range(z0, z1 + 1) if a.getValue((x, y, z)) < 0]
        print(name + ("_half" if half else ""), g.gridClass.replace(" ", "_"), len(inside), *[c for p in inside for c in p])
"#,
        boxes = box_list.join(", "),
        dir = dir.path().display().to_string(),
    );
    let text = run_openvdb(&python, &script);
    let mut files = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(w[1], "level_set", "{line}");
        let n: usize = w[2].parse().unwrap();
        let c: Vec<i64> = w[3..].iter().map(|x| x.parse().unwrap()).collect();
        let mut inside: Vec<[i64; 3]> = c.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
        inside.sort();
        assert_eq!(inside.len(), n);
        if w[0].starts_with("boxes") {
            assert_eq!(inside, known, "{}: OpenVDB's own voxels below zero", w[0]);
        }
        let path = d(&format!("{}.vdb", w[0]));
        assert_eq!(ktree_voxels(&path), inside, "{}", w[0]);
        files.push((path, inside));
    }
    assert_eq!(files.len(), 4);
    // OpenVDB's sdfInteriorMask agrees, and OpenVDB writing the level sets again with every compression
    // (zlib is not applied to level sets: it is tried on the interior written as a BoolGrid), as
    // DoubleGrids too, gives files ktree reads as the same voxels.
    let build_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let Some(check) = level_set_check(&build_dir) else {
        return;
    };
    let mut rewritten = 0;
    for (path, inside) in &files {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let variants: [(&str, &str, &[&str]); 7] = [
            ("none", "level-set", &["0"]),
            ("mask", "level-set", &["2"]),
            ("blosc", "level-set", &["4"]),
            ("double_none", "level-set", &["0", "double"]),
            ("double_blosc_mask", "level-set", &["6", "double"]),
            ("bool_zip", "mask", &["1"]),
            ("bool_zip_mask", "mask", &["3"]),
        ];
        for (suffix, mode, flags) in variants {
            let out = d(&format!("{stem}_{suffix}.vdb"));
            let run = Command::new(&check)
                .arg(path)
                .arg(mode)
                .arg(&out)
                .args(flags)
                .output()
                .unwrap();
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            let report = String::from_utf8(run.stdout).unwrap();
            assert_eq!(&check_voxels(&report), inside, "{stem}: sdfInteriorMask");
            assert_eq!(&ktree_voxels(&out), inside, "{stem}_{suffix}");
            rewritten += 1;
        }
    }
    assert_eq!(rewritten, 28);
}
